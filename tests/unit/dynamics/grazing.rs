//! Tests of `tapsim::dynamics::grazing` (src/dynamics/grazing.rs).

use tapsim::dynamics::grazing::*;
use tapsim::physics::law::{AdhesiveLaw, HertzLaw, NoForce};
use tapsim::physics::law::{Branch, ForceLaw};

#[test]
fn a_cantilever_of_40_n_per_m_moves_10_pm_rms_at_room_temperature() {
    let rms = thermal_rms_m(40.0, ROOM_TEMPERATURE_K);
    assert!((rms - 1.0176e-11).abs() < 1e-14, "{rms}");
}

#[test]
fn levels_are_the_exits_of_a_branch_and_the_entries_into_it() {
    // JKR: the free branch ends at the jump-in α̂_A and is entered at the jump-out
    // α̂_C; the contact branch the other way round: both matter on both.
    let jkr = AdhesiveLaw::jkr();
    let (a, c) = (jkr.jump_in_alpha_hat(), jkr.jump_out_alpha_hat());
    assert!(c > a);
    let levels = SwitchLevels::of(&jkr);
    for branch in [Branch::Free, Branch::Contact] {
        // Nearest level below a point between them, above one beyond both; the
        // force jumps at both.
        let between = a + 0.25 * (c - a);
        let m = levels.margins(branch, between);
        assert_eq!((m.any, m.jump), (between - a, between - a));
        assert!((levels.margins(branch, c + 2.0).any - 2.0).abs() < 1e-15);
        assert!((levels.margins(branch, a - 0.5).jump - 0.5).abs() < 1e-15);
    }
    // Hertz switches at contact, α̂ = 0, both ways, with no jump of the force.
    let hertz = SwitchLevels::of(&HertzLaw);
    assert_eq!(hertz.margins(Branch::Free, 0.3).any, 0.3);
    assert_eq!(hertz.margins(Branch::Contact, -0.2).any, 0.2);
    assert_eq!(hertz.margins(Branch::Contact, -0.2).jump, f64::INFINITY);
    // No force: no level, no margin.
    assert_eq!(
        SwitchLevels::of(&NoForce).margins(Branch::Free, 0.0),
        Margins::NONE
    );
}
