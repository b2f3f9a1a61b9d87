//! Tests of `tapsim::instrument::thermal` (src/instrument/thermal.rs).

use tapsim::instrument::thermal::*;

#[test]
fn the_step_variance_tends_to_equipartition_as_the_step_shrinks() {
    let (q, d) = (30.0, 1e-3);
    let equipartition = d * q / 2.0;
    let mut last = f64::INFINITY;
    for n in [16.0, 64.0, 256.0] {
        let step = 2.0 * std::f64::consts::PI / n;
        let p = free_variance_hat(q, step, d);
        let shortfall = 1.0 - p / equipartition;
        // About (πf₀Δ)²/3 = (π/n)²/3.
        let expected = (std::f64::consts::PI / n).powi(2) / 3.0;
        assert!(
            (shortfall / expected - 1.0).abs() < 0.05,
            "n = {n}: {shortfall:e} vs {expected:e}"
        );
        assert!(shortfall < last);
        last = shortfall;
    }
}

#[test]
fn bad_settings_are_refused() {
    assert!(ThermalForce::new(-1.0, 64, 1, 0).is_err());
    assert!(ThermalForce::new(f64::NAN, 64, 1, 0).is_err());
    assert!(ThermalForce::new(1.0, 0, 1, 0).is_err());
    assert!(ThermalForce::new(1.0, MAX_STEPS_PER_PERIOD + 1, 1, 0).is_err());
}
