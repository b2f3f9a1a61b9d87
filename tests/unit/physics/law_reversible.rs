//! Tests of `tapsim::physics::law::reversible` (src/physics/law/reversible.rs).

use tapsim::physics::contact::hybrid::JumpIn;
use tapsim::physics::law::reversible::*;
use tapsim::physics::law::{AdhesiveLaw, Branch, ForceLaw};

/// Down and back up through α̂_A the work of the switches cancels: the work done
/// along any closed path is zero, and the forces are the hybrid law's on the way in.
#[test]
fn the_law_is_the_hybrid_approach_both_ways_and_loses_nothing() {
    let hybrid = AdhesiveLaw::hybrid(2.76, JumpIn::Fit).unwrap();
    let law = Reversible(hybrid.clone());
    let a = law.jump_in_alpha_hat();
    assert_eq!(law.jump_out_alpha_hat(), a);
    assert!(hybrid.jump_out_alpha_hat() > a);
    for alpha in [a - 3.0, a - 0.1, a + 0.1, a + 2.0] {
        for branch in [Branch::Free, Branch::Contact] {
            assert_eq!(law.t_hat(alpha, branch), hybrid.t_hat(alpha, branch));
        }
    }
    // Free from above a to the switch, contact down to the bottom and back up to a,
    // free again: the work of the two switches at a cancels.
    let bottom = a - 2.0;
    let work = (law.work_hat(a, Branch::Free) - law.work_hat(a + 1.0, Branch::Free))
        + (law.work_hat(bottom, Branch::Contact) - law.work_hat(a, Branch::Contact))
        + (law.work_hat(a, Branch::Contact) - law.work_hat(bottom, Branch::Contact))
        + (law.work_hat(a + 1.0, Branch::Free) - law.work_hat(a, Branch::Free));
    assert!(work.abs() < 1e-12, "{work}");
    assert_eq!(law.loop_area_hat(), 0.0);
    // The tensile force the contact branch still pulls with at a, which the hybrid
    // law keeps on to α̂_C and this one lets go of.
    assert!(law.t_hat(a, Branch::Contact) > 0.0);
}
