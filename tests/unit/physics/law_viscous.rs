//! Tests of `tapsim::physics::law::viscous` (src/physics/law/viscous.rs).

use tapsim::physics::law::HertzLaw;
use tapsim::physics::law::viscous::*;
use tapsim::physics::law::{Branch, ContactState, ForceLaw};
use tapsim::physics::params::Contact;

#[test]
fn the_viscous_force_opposes_the_indentation_rate_and_acts_only_in_contact() {
    let contact = Contact::new(20e-9, 1e9, 0.1, 0.3e-9).unwrap();
    let law = KelvinVoigt::new(HertzLaw, 50.0, &contact, 300e3).unwrap();
    let at = |alpha_hat, rate_hat, branch| ContactState {
        alpha_hat,
        rate_hat,
        branch,
    };
    // Indenting (α̂ falling): repulsive, T̂ < 0; withdrawing: attractive.
    assert!(law.dissipative_t_hat(&at(-0.5, -2.0, Branch::Contact)) < 0.0);
    assert!(law.dissipative_t_hat(&at(-0.5, 2.0, Branch::Contact)) > 0.0);
    assert_eq!(law.dissipative_t_hat(&at(0.5, -2.0, Branch::Contact)), 0.0);
    assert_eq!(law.dissipative_t_hat(&at(-0.5, -2.0, Branch::Free)), 0.0);
    // c√(−α̂)α̂' with c from η, ω₀ and the contact's scales.
    let c = 50.0 * 2.0 * std::f64::consts::PI * 300e3 * contact.separation_scale_m().powf(1.5)
        / ((20e-9f64).sqrt() * 0.1);
    let t = law.dissipative_t_hat(&at(-0.25, 3.0, Branch::Contact));
    assert!(
        (t - c * 0.5 * 3.0).abs() < 1e-12 * t.abs(),
        "{t} vs {}",
        c * 1.5
    );
    // The slopes are the derivatives.
    let s = at(-0.3, -1.7, Branch::Contact);
    let (da, dr) = law.dissipative_slopes_hat(&s);
    let h = 1e-6;
    let num_a = (law.dissipative_t_hat(&at(-0.3 + h, -1.7, Branch::Contact))
        - law.dissipative_t_hat(&at(-0.3 - h, -1.7, Branch::Contact)))
        / (2.0 * h);
    let num_r = (law.dissipative_t_hat(&at(-0.3, -1.7 + h, Branch::Contact))
        - law.dissipative_t_hat(&at(-0.3, -1.7 - h, Branch::Contact)))
        / (2.0 * h);
    assert!((da - num_a).abs() < 1e-6 * num_a.abs(), "{da} {num_a}");
    assert!((dr - num_r).abs() < 1e-6 * num_r.abs(), "{dr} {num_r}");
}
