//! Tests of `tapsim::dynamics::free` (src/dynamics/free.rs).

use tapsim::dynamics::free::*;
use tapsim::dynamics::model::{BASE, Coupling, rhs};
use tapsim::dynamics::model::{Carried, Drive, Oscillator, State, V, X};
use tapsim::physics::law::{Branch, NoForce};

fn osc() -> Oscillator {
    Oscillator {
        gamma: 1.0 / 40.0,
        omega: 0.97,
        drive: Drive::Force { amplitude: 0.05 },
        bias: 0.0,
    }
}

/// With and without a constant force (the thermal force's step).
fn oscs() -> [Oscillator; 2] {
    [osc(), Oscillator { bias: 0.3, ..osc() }]
}

#[test]
fn under_a_base_drive_or_a_ramp_the_separation_adds_the_support() {
    for drive in [
        Drive::Base { amplitude: 7.5 },
        Drive::Ramp {
            position: 7.5,
            speed: -0.02,
        },
    ] {
        let base = Oscillator {
            gamma: 1.0 / 800.0,
            omega: 2.0 / 300.0,
            drive,
            bias: 0.0,
        };
        under_a_moving_support(&base);
    }
}

fn under_a_moving_support(base: &Oscillator) {
    let flight = FreeFlight::new(base, 3.0, 0.01, -0.02).unwrap();
    let separation = flight.separation();
    for tau in [3.0, 4.7, 30.0, 500.0] {
        let (x, v) = flight.at(tau);
        let (x_b, v_b) = base.base_at(tau);
        let (y, w) = separation.at(tau);
        assert!((y - (x + x_b)).abs() < 1e-12 && (w - (v + v_b)).abs() < 1e-12);
        // The deflection rings freely: x'' = −2γx' − x.
        let h = 1e-5;
        let acc = (flight.at(tau + h).1 - flight.at(tau - h).1) / (2.0 * h);
        assert!((acc + 2.0 * base.gamma * v + x).abs() < 1e-8, "{acc}");
        // The separation's acceleration, as Newton on its turning points uses it.
        let (w2, a2) = separation.velocity_and_acceleration(tau);
        let fd = (separation.at(tau + h).1 - separation.at(tau - h).1) / (2.0 * h);
        assert!(
            (w2 - w).abs() < 1e-12 && (a2 - fd).abs() < 1e-8,
            "{a2} vs {fd}"
        );
    }
    // A fall of the separation to a level below the deflection's reach is found
    // where the support brings it there.
    let level = -7.0;
    let fall = separation.first_fall_to(
        level,
        3.0,
        3.0 + base.period(),
        2.0 * std::f64::consts::PI / 8.0,
    );
    let hit = fall.hit.expect("the support carries the tip down");
    assert!((separation.at(hit).0 - level).abs() < 1e-10);
    assert!(
        flight
            .first_fall_to(level, 3.0, 3.0 + base.period(), 1.0)
            .hit
            .is_none()
    );
}

#[test]
fn closed_form_solves_the_ode() {
    for osc in oscs() {
        let f = FreeFlight::new(&osc, 0.3, 0.2, -0.4).unwrap();
        let cpl = Coupling {
            a0: 0.0,
            a1: 1.0,
            f_scale: 0.0,
        };
        for i in 0..50 {
            let t = 0.3 + 0.37 * i as f64;
            let (x, v) = f.at(t);
            let h = 1e-4;
            let (xp, vp) = f.at(t + h);
            let (xm, vm) = f.at(t - h);
            let acc = (vp - vm) / (2.0 * h);
            let mut y = State::<BASE>::zeros();
            y[X] = x;
            y[V] = v;
            tapsim::dynamics::model::set_phasor(&osc, t, &mut y);
            let mut dy = State::<BASE>::zeros();
            rhs(&NoForce, &osc, &cpl, Branch::Free, t, &y, &mut dy, None);
            assert!((acc - dy[V]).abs() < 1e-7, "{acc} vs {}", dy[V]);
            assert!(((xp - xm) / (2.0 * h) - v).abs() < 1e-7);
        }
        let (x0, v0) = f.at(0.3);
        assert!((x0 - 0.2).abs() < 1e-14 && (v0 + 0.4).abs() < 1e-14);
    }
}

#[test]
fn closed_form_integrals_match_quadrature() {
    for osc in oscs() {
        let f = FreeFlight::new(&osc, 0.3, 0.2, -0.4).unwrap();
        let (a, b) = (0.7, 9.1);
        let n = 200_000;
        let h = (b - a) / n as f64;
        let (mut sc, mut ss, mut damp) = (0.0, 0.0, 0.0);
        for i in 0..n {
            let t = a + h * (i as f64 + 0.5);
            let (x, v) = f.at(t);
            sc += h * x * (osc.omega * t).cos();
            ss += h * x * (osc.omega * t).sin();
            damp += h * 2.0 * osc.gamma * v * v;
        }
        let mut y = State::<BASE>::zeros();
        f.advance(&mut y, a, b);
        assert!(
            (y[Carried::CosProjection] - sc).abs() < 1e-9,
            "{} {sc}",
            y[Carried::CosProjection]
        );
        assert!(
            (y[Carried::SinProjection] - ss).abs() < 1e-9,
            "{} {ss}",
            y[Carried::SinProjection]
        );
        assert!(
            (y[Carried::Damping] - damp).abs() < 1e-9,
            "{} {damp}",
            y[Carried::Damping]
        );
    }
}

#[test]
fn rotated_samples_match_the_closed_form() {
    let f = FreeFlight::new(&osc(), 6000.3, 0.2, -0.4).unwrap();
    let h = 0.77;
    for (k, (x, v)) in f.samples(6000.5, h).take(12).enumerate() {
        let (xe, ve) = f.at(6000.5 + h * k as f64);
        // Both carry the rounding of Ωτ ≈ 6e3 (~1e-12) in their phase.
        assert!(
            (x - xe).abs() < 1e-11 && (v - ve).abs() < 1e-11,
            "{k}: {x} {xe}"
        );
    }
}

#[test]
fn finds_a_grazing_minimum() {
    let osc = osc();
    let (a, b) = FreeFlight::steady(&osc).unwrap();
    let f = FreeFlight::new(&osc, 0.0, a, b * osc.omega).unwrap();
    let amp = (a * a + b * b).sqrt();
    // A level just above the lowest point is reached; one just below is not.
    let hit = f.first_fall_to(-amp + 1e-9, 0.0, osc.period(), 1.0);
    assert!(hit.hit.is_some());
    let miss = f.first_fall_to(-amp - 1e-9, 0.0, osc.period(), 1.0);
    assert!(miss.hit.is_none());
    assert!((miss.min_x + amp).abs() < 1e-12);
    // Both turning points of the period are found, at the steady amplitude.
    assert!((miss.lowest_turn + amp).abs() < 1e-12);
    assert!((miss.highest_turn - amp).abs() < 1e-12);
}
