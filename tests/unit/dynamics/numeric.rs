//! Tests of `tapsim::dynamics::numeric` (src/dynamics/numeric.rs).

use tapsim::dynamics::dopri5::System;
use tapsim::dynamics::model::{BASE, Coupling, Oscillator, Part, State, V, X};
use tapsim::dynamics::model::{Carried, Drive};
use tapsim::dynamics::numeric::*;
use tapsim::dynamics::observer::Ignore;
use tapsim::physics::law::{Branch, ForceLaw};

/// Free branch force-free; contact branch with a square-root fold at α̂ = LEVEL,
/// continued past it by point reflection, like the JKR branch at C.
struct Cusp;
const LEVEL: f64 = 0.5;
impl ForceLaw for Cusp {
    fn t_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        match branch {
            Branch::Free | Branch::Necked => 0.0,
            Branch::Contact => {
                let d = LEVEL - alpha_hat;
                1.0 - d.signum() * d.abs().sqrt()
            }
        }
    }
    fn slope_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        match branch {
            Branch::Free | Branch::Necked => 0.0,
            Branch::Contact => 0.5 / (LEVEL - alpha_hat).abs().sqrt().max(1e-8),
        }
    }
    fn work_hat(&self, _: f64, _: Branch) -> f64 {
        0.0
    }
    fn jump_in_alpha_hat(&self) -> f64 {
        -1.0
    }
    fn jump_out_alpha_hat(&self) -> f64 {
        LEVEL
    }
    fn free_branch_is_force_free(&self) -> bool {
        true
    }
    fn loop_area_hat(&self) -> f64 {
        0.0
    }
}

fn setup() -> (Oscillator, Coupling, Tolerances) {
    let osc = Oscillator {
        gamma: 0.01,
        omega: 1.0,
        drive: Drive::Force { amplitude: 0.02 },
        bias: 0.0,
    };
    let cpl = Coupling {
        a0: 0.0,
        a1: 1.0,
        f_scale: 0.1,
    };
    let tol = Tolerances {
        rtol: 1e-10,
        atol: 1e-12,
        h_max: 0.2,
    };
    (osc, cpl, tol)
}

fn to_switch(v0: f64, land_on_switch: bool) -> SegmentEnd {
    let events = Events {
        below: None,
        above: Some(LEVEL),
    };
    between(events, v0, land_on_switch)
}

/// The contact branch of [`Cusp`] from x = 0 at velocity `v0`, ending at `events`.
fn between(events: Events, v0: f64, land_on_switch: bool) -> SegmentEnd {
    let (osc, cpl, tol) = setup();
    let span = Span {
        law: &Cusp,
        osc: &osc,
        cpl: &cpl,
        branch: Branch::Contact,
        events,
        tau_end: 4.0,
        tol: &tol,
    };
    let mut y = State::<BASE>::zeros();
    y[V] = v0;
    span.integrate_landing(0.0, y, 0.0, land_on_switch, None, &mut Ignore)
        .expect("integrates")
}

#[test]
fn a_branch_bounded_both_ways_ends_at_the_level_it_meets_first() {
    // Bounded below at −0.3 and above at the fold: heading down it ends below,
    // heading up at the fold, landed on or located alike.
    let events = Events {
        below: Some(-0.3),
        above: Some(LEVEL),
    };
    for land_on_switch in [true, false] {
        let down = between(events, -0.6, land_on_switch);
        assert_eq!(down.switched, Some(Crossing::Down));
        assert!((down.y[X] + 0.3).abs() < 2e-8, "{}", down.y[X]);
        let up = between(events, 0.8, land_on_switch);
        assert_eq!(up.switched, Some(Crossing::Up));
        assert!((up.y[X] - LEVEL).abs() < 2e-8, "{}", up.y[X]);
        // The same end as with that level alone.
        let alone = between(
            Events {
                below: None,
                above: Some(LEVEL),
            },
            0.8,
            land_on_switch,
        );
        assert_eq!(up.tau, alone.tau);
    }
}

#[test]
fn landing_on_a_fold_matches_locating_its_crossing() {
    // v₀ = 0.5435 barely makes it (0.5431 does not): the landing starts while the
    // tip decelerates hard towards the fold.
    for v0 in [0.5435, 0.6, 0.8] {
        let landed = to_switch(v0, true);
        let located = to_switch(v0, false);
        assert_eq!(landed.switched, Some(Crossing::Up));
        assert_eq!(located.switched, Some(Crossing::Up));
        // Landing ends exactly on the level; locating polishes to 1e-8 in α̂.
        assert!((landed.y[X] - LEVEL).abs() < 1e-14, "{}", landed.y[X]);
        assert!((located.y[X] - LEVEL).abs() < 2e-8, "{}", located.y[X]);
        let (t1, t2) = (landed.tau, located.tau);
        assert!((t1 - t2).abs() < 1e-7, "{v0}: {t1} {t2}");
        for i in [
            V,
            Part::Carried(Carried::Damping),
            Part::Carried(Carried::CosProjection),
            Part::Carried(Carried::SinProjection),
        ] {
            let (a, b) = (landed.y[i], located.y[i]);
            assert!((a - b).abs() < 1e-7, "{v0}, {i:?}: {a} {b}");
        }
    }
}

#[test]
fn an_integration_failure_is_told_in_words() {
    // x' = 1/(1 − τ)²: the step must shrink to nothing at τ = 1.
    struct Blows;
    impl System<BASE> for Blows {
        fn system(&self, tau: f64, _: &State, dy: &mut State) {
            *dy = State::zeros();
            dy[X] = 1.0 / ((1.0 - tau) * (1.0 - tau));
        }
    }
    let tol = Tolerances {
        rtol: 1e-10,
        atol: 1e-12,
        h_max: 0.1,
    };
    let err = run(Blows, 0.0, 2.0, State::zeros(), 0.0, &tol, Branch::Contact)
        .expect_err("no step gets past the pole")
        .to_string();
    assert!(err.contains("contact branch"), "{err}");
    assert!(!err.contains('{') && !err.contains("Contact"), "{err}");
}

#[test]
fn a_tip_turning_short_of_the_level_does_not_switch() {
    // Held back by f = −0.1·T̂, the tip turns a hair below the fold for v₀ = 0.542.
    for land_on_switch in [true, false] {
        let end = to_switch(0.542, land_on_switch);
        assert_eq!(end.switched, None);
        assert_eq!(end.tau, 4.0);
        assert!(end.y[X] < LEVEL);
    }
}
