//! Tests of `tapsim::physics::params` (src/physics/params.rs).

use tapsim::physics::params::*;

#[test]
fn beta_squared_is_r_over_mu_epsilon() {
    let c = Contact::new(10e-9, 1e9, 0.05, 0.3e-9).unwrap();
    let b = c.beta();
    assert!((b * b - c.radius_m / c.separation_scale_m()).abs() < 1e-12 * b * b);
}

#[test]
fn composite_modulus_of_equal_bodies() {
    let e = composite_modulus(1e9, 0.0, 1e9, 0.0).unwrap();
    assert!((e - 0.5e9).abs() < 1e-3);
    assert!(composite_modulus(1e9, 0.7, 1e9, 0.3).is_err());
}
