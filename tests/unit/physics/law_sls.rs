//! Tests of `tapsim::physics::law::sls` (src/physics/law/sls.rs).

use tapsim::physics::law::HertzLaw;
use tapsim::physics::law::sls::*;
use tapsim::physics::law::{Branch, ContactState, ForceLaw};
use tapsim::physics::params::Contact;

fn law() -> StandardLinearSolid<HertzLaw> {
    let contact = Contact::new(20e-9, 1e9, 0.1, 0.3e-9).unwrap();
    StandardLinearSolid::new(HertzLaw, 3e9, 1e-7, &contact, 300e3).unwrap()
}

fn at(alpha_hat: f64, rate_hat: f64, branch: Branch) -> ContactState {
    ContactState {
        alpha_hat,
        rate_hat,
        branch,
    }
}

#[test]
fn the_force_is_the_surfaces() {
    let l = law();
    assert!((l.modulus_ratio() - 2.0).abs() < 1e-12);
    let tau = 2.0 * std::f64::consts::PI * 300e3 * 1e-7;
    assert!((l.relaxation_hat() - tau).abs() < 1e-12 * tau);
    // The whole force is the surface's, in contact whatever the wrapped Hertz holds.
    for (alpha, branch) in [(-0.25, Branch::Contact), (0.3, Branch::Free)] {
        let s = at(alpha, -1.0, branch);
        let f = 0.37;
        let whole = l.t_hat(alpha, branch) + l.surface_t_hat(&s, f);
        assert!((whole + f).abs() < 1e-15, "{whole}");
    }
    let s = at(-0.25, -1.0, Branch::Contact);
    // Without the surface the rate-dependent force is not a number (never a wrong
    // one), and a fresh surface is flat: at first touch it answers with the
    // unrelaxed modulus, (1 + r)(4/3)δ̂^{3/2}.
    assert!(l.dissipative_t_hat(&s).is_nan());
    let surface = l.surface(1.0).unwrap();
    let unrelaxed = 3.0 * 4.0 / 3.0 * 0.25f64.powf(1.5);
    assert!((surface.force_hat(0.25) / unrelaxed - 1.0).abs() < 1e-6);
    assert_eq!(surface.cells(), SURFACE_CELLS);
}

#[test]
fn refuses_a_sample_that_would_soften() {
    let contact = Contact::new(20e-9, 1e9, 0.1, 0.3e-9).unwrap();
    for (e0, tau) in [
        (1e9, 1e-7),
        (0.5e9, 1e-7),
        (3e9, 0.0),
        (3e9, -1.0),
        (f64::NAN, 1e-7),
        // Faster than round-off tells from the relaxed contact (τ̂_r < 1e-8), slower
        // than the marching settles (a retardation of 900 periods).
        (3e9, 1e-15),
        (3e9, 1e-3),
    ] {
        assert!(StandardLinearSolid::new(HertzLaw, e0, tau, &contact, 300e3).is_err());
    }
}
