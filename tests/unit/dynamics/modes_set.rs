//! Tests of `tapsim::dynamics::modes::set` (src/dynamics/modes/set.rs).

use tapsim::dynamics::modes::set::*;

#[test]
fn the_beam_roots_solve_the_clamped_free_equation() {
    for b in EULER_BERNOULLI_ROOTS {
        assert!((b.cos() * b.cosh() + 1.0).abs() < 1e-12 * b.cosh(), "{b}");
    }
}

#[test]
fn the_common_denominator_is_the_smallest_within_tolerance() {
    // f₂/f₁ of a rectangular beam, 6.2669: 25/4 within 0.5 %, 94/15 within 1e-4.
    let r = (EULER_BERNOULLI_ROOTS[1] / EULER_BERNOULLI_ROOTS[0]).powi(2);
    assert_eq!(common_denominator(&[r], 5e-3), Some((4, vec![25])));
    assert_eq!(common_denominator(&[r], 1e-4), Some((15, vec![94])));
    assert_eq!(common_denominator(&[6.0], 1e-12), Some((1, vec![6])));
    assert_eq!(common_denominator(&[std::f64::consts::PI], 1e-12), None);
}

#[test]
fn a_mode_driven_by_its_drive_oscillates_at_its_free_amplitude() {
    // Linear response |c f / (r² − Ω² + i rΩ/Q)| at the drive.
    let m = ModeModel::new(6.25, 1000.0, 39.06, 6.2, 0.03);
    let response = m.gain * m.drive / (m.r * m.r - m.omega * m.omega).hypot(m.r * m.omega / 1000.0);
    assert!((response - 0.03).abs() < 1e-15);
}
