//! Tests of `tapsim::physics::contact::jkr` (src/physics/contact/jkr.rs).

use std::f64::consts::PI;
use tapsim::physics::contact::jkr::*;

#[test]
fn literal_constants_match_eq_8() {
    assert!((A_HAT_B - (2.0 * PI).cbrt()).abs() < 4e-16);
    assert!((A_HAT_C - PI.cbrt() / 2.0).abs() < 2e-16);
    // Literals from a 30-digit evaluation; f64 formulas agree to a few ulp.
    assert!((ALPHA_HAT_C - separation_hat(PI.cbrt() / 2.0)).abs() < 1e-15);
    assert!((ALPHA_HAT_C - 0.75 * PI.powf(2.0 / 3.0)).abs() < 1e-15);
    assert!((T_HAT_C - force_hat(A_HAT_C)).abs() < 1e-15);
}

#[test]
fn inverse_separation_round_trips() {
    for &a in &[0.75, 1.0, 1.845, 3.0, 10.0, 100.0] {
        let back = a_hat_from_separation(separation_hat(a)).unwrap();
        assert!((back - a).abs() < 1e-12 * a, "{a} -> {back}");
    }
    assert!(a_hat_from_separation(point_c().alpha_hat + 1e-6).is_none());
    assert!(a_hat_from_separation(f64::NAN).is_none());
}

#[test]
fn inverse_force_round_trips() {
    let po = pull_off_point().a_hat;
    for &a in &[1.6, 2.0, 5.0] {
        let back = a_hat_from_force(force_hat(a), ForceBranch::LoadStable).unwrap();
        assert!((back - a).abs() < 1e-12 * a);
    }
    for &a in &[0.01, 0.5, 1.0, 1.4] {
        assert!(a < po);
        let back = a_hat_from_force(force_hat(a), ForceBranch::SmallContact).unwrap();
        assert!((back - a).abs() < 1e-12, "{a} -> {back}");
    }
}
