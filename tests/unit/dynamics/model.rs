//! Tests of `tapsim::dynamics::model` (src/dynamics/model.rs).

use tapsim::dynamics::model::*;

/// Simpson's rule with `n` (even) intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let inner: f64 = (1..n)
        .map(|i| f(a + h * i as f64) * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    h / 3.0 * (f(a) + inner + f(b))
}

#[test]
fn drive_work_matches_its_defining_integrals() {
    // Any smooth path will do: the force drive's formula is pure integration by
    // parts, the base drive's uses f_ts = x'' + 2γx' + x along the path.
    let x = |t: f64| 0.3 * (1.7 * t).sin() + 0.1 * t * t;
    let v = |t: f64| 0.51 * (1.7 * t).cos() + 0.2 * t;
    let a = |t: f64| -0.867 * (1.7 * t).sin() + 0.2;
    let (t0, t1, n) = (0.2, 2.5, 20_000);
    for drive in [
        Drive::Force { amplitude: 0.7 },
        Drive::Base { amplitude: 0.4 },
        Drive::Ramp {
            position: 0.4,
            speed: -0.03,
        },
    ] {
        let osc = Oscillator {
            gamma: 0.05,
            omega: 1.3,
            drive,
            bias: 0.0,
        };
        let w = osc.omega;
        let f_ts = |t: f64| a(t) + 2.0 * osc.gamma * v(t) + x(t);
        let sc = simpson(|t| x(t) * (w * t).cos(), t0, t1, n);
        let ss = simpson(|t| x(t) * (w * t).sin(), t0, t1, n);
        let direct = match drive {
            Drive::Force { amplitude } => simpson(|t| amplitude * (w * t).cos() * v(t), t0, t1, n),
            Drive::Base { amplitude } => {
                // −∫ f_ts x_b' dτ with x_b = b cos Ωτ.
                simpson(|t| f_ts(t) * amplitude * w * (w * t).sin(), t0, t1, n)
            }
            Drive::Ramp { speed, .. } => -simpson(|t| f_ts(t) * speed, t0, t1, n),
        };
        let force = simpson(f_ts, t0, t1, n);
        let work = osc.drive_work((t0, x(t0), v(t0)), (t1, x(t1), v(t1)), (sc, ss), force);
        assert!(
            (work - direct).abs() < 1e-12,
            "{drive:?}: {work} vs {direct}"
        );
    }
}
