//! Tests of `tapsim::physics::law::capillary` (src/physics/law/capillary.rs).

use tapsim::physics::law::HertzLaw;
use tapsim::physics::law::capillary::*;
use tapsim::physics::law::{Branch, ForceLaw};
use tapsim::physics::params::Contact;

fn neck() -> Capillary<HertzLaw> {
    // The built-in defaults' contact: a 20 nm silicon tip on a 0.5 GPa polymer.
    let modulus = tapsim::physics::params::composite_modulus(169e9, 0.28, 0.5e9, 0.4).unwrap();
    let contact = Contact::new(20e-9, modulus, 0.1, 0.3e-9).unwrap();
    let neck = Neck {
        surface_tension_j_m2: 0.072,
        contact_angle_deg: 30.0,
        rupture_distance_m: 2e-9,
    };
    Capillary::new(HertzLaw, &neck, &contact, 0.0).unwrap()
}

#[test]
fn the_work_function_is_the_antiderivative_of_the_neck_and_gives_its_loop() {
    let law = neck();
    let h = 1e-6;
    for alpha in [
        -0.7,
        -0.1,
        0.2,
        0.5 * law.rupture_alpha_hat(),
        0.99 * law.rupture_alpha_hat(),
    ] {
        // Each of work → force → slope is the derivative of the one before.
        let derivative = |f: &dyn Fn(f64) -> f64| (f(alpha + h) - f(alpha - h)) / (2.0 * h);
        let work = |a: f64| law.work_hat(a, Branch::Contact);
        let force = |a: f64| law.t_hat(a, Branch::Contact);
        for (numeric, exact, tolerance) in [
            (derivative(&work), force(alpha), 1e-6),
            (
                derivative(&force),
                law.slope_hat(alpha, Branch::Contact),
                1e-5,
            ),
        ] {
            assert!(
                (numeric - exact).abs() < tolerance * exact.abs().max(1.0),
                "{alpha}: {numeric} vs {exact}"
            );
        }
    }
    // Formed at α̂ = 0, broken at α̂_r, nothing on the way down: the loop.
    let r = law.rupture_alpha_hat();
    let lost = law.work_hat(r, Branch::Contact) - law.work_hat(0.0, Branch::Contact);
    assert!((lost - law.loop_area_hat()).abs() < 1e-14 * lost);
    // And the neck lets go at zero force.
    assert!(law.t_hat(r, Branch::Contact).abs() < 1e-12);
}

#[test]
fn a_neck_refuses_bad_parameters_and_a_rupture_before_the_contact_lets_go() {
    // The built-in defaults' contact: a 20 nm silicon tip on a 0.5 GPa polymer.
    let modulus = tapsim::physics::params::composite_modulus(169e9, 0.28, 0.5e9, 0.4).unwrap();
    let contact = Contact::new(20e-9, modulus, 0.1, 0.3e-9).unwrap();
    let good = Neck {
        surface_tension_j_m2: 0.072,
        contact_angle_deg: 0.0,
        rupture_distance_m: 2e-9,
    };
    // On JKR the neck must break beyond the contact's own let-go, α̂_C.
    let jkr = tapsim::physics::law::AdhesiveLaw::jkr;
    assert!(Capillary::new(jkr(), &good, &contact, 0.0).is_ok());
    let inside = Neck {
        rupture_distance_m: 0.5 * jkr().jump_out_alpha_hat() * contact.separation_scale_m(),
        ..good
    };
    assert!(Capillary::new(jkr(), &inside, &contact, 0.0).is_err());
    for bad in [
        Neck {
            contact_angle_deg: 95.0,
            ..good
        },
        Neck {
            surface_tension_j_m2: -1.0,
            ..good
        },
        Neck {
            rupture_distance_m: 0.1e-9,
            ..good
        },
    ] {
        assert!(
            Capillary::new(HertzLaw, &bad, &contact, 0.3e-9).is_err(),
            "{bad:?}"
        );
    }
}
