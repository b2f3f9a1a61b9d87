//! Tests of `tapsim::dynamics::march` (src/dynamics/march.rs).

use tapsim::dynamics::march::*;
use tapsim::dynamics::model::{BASE, State, V, X};
use tapsim::dynamics::numeric::StepEnd;

#[test]
fn hermite_turn_finds_the_turning_points_of_parabolas() {
    // x = (τ − 0.3)², sampled at τ = 0 and 1 with exact slopes: the cubic is exact.
    let end = |tau: f64| {
        let mut y = State::<BASE>::zeros();
        y[X] = (tau - 0.3) * (tau - 0.3);
        y[V] = 2.0 * (tau - 0.3);
        StepEnd {
            tau,
            y,
            dy: State::<BASE>::zeros(),
        }
    };
    let t = hermite_turn(&end(0.0), &end(1.0), true);
    assert!((t - 0.3).abs() < 1e-12, "{t}");
    // And the top of x = −(τ − 0.6)².
    let top = |tau: f64| {
        let mut e = end(tau + 0.3 - 0.6);
        e.tau = tau;
        e.y[X] = -e.y[X];
        e.y[V] = -e.y[V];
        e
    };
    let t = hermite_turn(&top(0.0), &top(1.0), false);
    assert!((t - 0.6).abs() < 1e-12, "{t}");
}
