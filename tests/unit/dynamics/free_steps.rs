//! Tests of `tapsim::dynamics::free_steps` (src/dynamics/free_steps.rs).

use tapsim::dynamics::free::FreeFlight;
use tapsim::dynamics::free_steps::*;
use tapsim::dynamics::march::Phase;
use tapsim::dynamics::model::Carried;
use tapsim::dynamics::model::{BASE, Oscillator, State, V, X};
use tapsim::dynamics::observer::Ignore;
use tapsim::dynamics::setup::{Numerics, Prepared, default_setup};

/// A step from the precomputed transition is the closed-form flight under the held
/// force ([`FreeFlight`], built afresh at the step's start): the state, the Fourier
/// projections and the energy damped, to round-off; a step that would turn or come
/// within reach of the jump-in level is left to the march.
#[test]
fn a_step_is_the_closed_form_flight_and_the_located_ones_are_refused() {
    let p = Prepared::new(&default_setup(), &Numerics::default()).unwrap();
    let sim = p.simulation();
    let step = sim.osc.period() / 64.0;
    let steps = FreeSteps::new(&sim, step).expect("the hybrid's free branch is force-free");
    let force = 3e-3;
    let held = Oscillator {
        bias: force,
        ..sim.osc
    };
    let tau = 1.234;
    let phasor = (sim.osc.omega * tau).sin_cos();
    // Falling fast through the middle of the swing, far above the contact.
    let mut phase = Phase {
        tau,
        x: 0.1,
        v: -0.9,
        ..Phase::at_rest()
    };
    let start = phase.clone();
    let part = steps
        .advance(&mut phase, phasor, force, &mut Ignore)
        .unwrap()
        .expect("nothing to locate in this step");
    let flight = FreeFlight::new(&held, tau, start.x, start.v).unwrap();
    let (x, v) = flight.at(tau + step);
    assert!((phase.x - x).abs() < 1e-13 && (phase.v - v).abs() < 1e-13);
    assert!((phase.tau - (tau + step)).abs() < 1e-15);
    let mut y = State::<BASE>::zeros();
    (y[X], y[V]) = (start.x, start.v);
    flight.advance(&mut y, tau, tau + step);
    for (ours, closed) in [
        (part.sc, y[Carried::CosProjection]),
        (part.ss, y[Carried::SinProjection]),
        (part.e_damp, y[Carried::Damping]),
    ] {
        assert!((ours - closed).abs() < 1e-13, "{ours:e} vs {closed:e}");
    }
    let drive = held.drive_work(
        (tau, start.x, start.v),
        (tau + step, x, v),
        (y[Carried::CosProjection], y[Carried::SinProjection]),
        0.0,
    );
    assert!((part.e_drive - drive).abs() < 1e-13);
    // Near the bottom of the swing (turning within the step), and falling onto the
    // jump-in level: both left to the march, the phase untouched.
    let level = steps.level_x;
    for (x, v) in [(0.5, -0.01), (level + 1e-3, -0.5)] {
        let mut phase = Phase {
            x,
            v,
            ..start.clone()
        };
        let before = phase.clone();
        let taken = steps
            .advance(&mut phase, phasor, force, &mut Ignore)
            .unwrap();
        assert!(taken.is_none(), "({x}, {v}) must be located");
        assert_eq!(phase, before);
    }
}
