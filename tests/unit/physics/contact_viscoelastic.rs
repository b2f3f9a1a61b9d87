//! Tests of `tapsim::physics::contact::viscoelastic` (src/physics/contact/viscoelastic.rs).

use tapsim::physics::contact::viscoelastic::*;

/// Ting's (1966) solution for the indentation δ̂ = t on [0, 1], 2 − t on [1, 2]
/// (relaxation modulus E(t)/E_∞ = 1 + r e^{−t/τ̂}), from his formulas and nothing of
/// the element model: t₁ from ∫_{t₁}^{t} E(t − s) dδ̂(s) = 0 in closed form (root by
/// bisection), the force F̂ = ∫₀^{t₁} E(t − s) d((4/3)δ̂^{3/2}) by Simpson's rule in
/// w = √s. Returns (F̂, t₁).
fn ting_triangle(r: f64, tau: f64, t: f64) -> (f64, f64) {
    let t1 = if t <= 1.0 {
        t
    } else {
        let h = |t1: f64| {
            (1.0 - t1) + r * tau * ((-(t - 1.0) / tau).exp() - (-(t - t1) / tau).exp())
                - (t - 1.0)
                - r * tau * (1.0 - (-(t - 1.0) / tau).exp())
        };
        if h(0.0) <= 0.0 {
            return (0.0, 0.0);
        }
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if h(mid) > 0.0 { lo = mid } else { hi = mid }
        }
        0.5 * (lo + hi)
    };
    let top = t1.sqrt();
    let f = |w: f64| 4.0 * w * w * r * (-(t - w * w) / tau).exp();
    let panels = 4000;
    let dw = top / panels as f64;
    let simpson: f64 = (0..panels)
        .map(|i| {
            let a = i as f64 * dw;
            dw / 6.0 * (f(a) + 4.0 * f(a + 0.5 * dw) + f(a + dw))
        })
        .sum();
    (4.0 / 3.0 * t1.powf(1.5) + simpson, t1)
}

/// The element model over the same history, sampled every `every` of its steps.
fn elements_triangle(r: f64, tau: f64, nodes: usize, times: &[f64]) -> Vec<(f64, f64)> {
    let mut s = RelaxingHalfSpace::new(r, tau, 1.0, nodes).unwrap();
    let dt = 1e-3;
    let depth = |t: f64| if t <= 1.0 { t } else { (2.0 - t).max(0.0) };
    let mut out = Vec::new();
    let mut t = 0.0;
    for &at in times {
        while t < at - 1e-12 {
            let next = (t + dt).min(at);
            s.advance(depth(t), depth(next), next - t).unwrap();
            t = next;
        }
        out.push((s.force_hat(depth(t)), s.contact_radius_hat(depth(t))));
    }
    out
}

#[test]
fn the_element_model_is_tings_receding_contact() {
    // Loading over 1, unloading over 1, relaxation time 0.3: the contact recedes
    // through the unloading and ends before the indentation is back at zero.
    let (r, tau) = (2.0, 0.3);
    let times: Vec<f64> = (1..=38).map(|i| 0.05 * i as f64).collect();
    let ting: Vec<(f64, f64)> = times.iter().map(|&t| ting_triangle(r, tau, t)).collect();
    let peak = ting[19].0;
    let mut worst = [0.0f64; 2];
    for (k, nodes) in [200, 400].into_iter().enumerate() {
        let model = elements_triangle(r, tau, nodes, &times);
        let spacing = 1.0 / nodes as f64;
        for ((&t, &(f, radius)), &(f_ting, t1)) in times.iter().zip(&model).zip(&ting) {
            worst[k] = worst[k].max((f - f_ting).abs() / peak);
            // In contact exactly where Ting's is (t₁ > 0), and never pulling.
            assert_eq!(f > 0.0, t1 > 0.0, "t = {t}: F̂ {f} against Ting's {f_ting}");
            // The contact radius is the one the contact had at t₁ (â² = δ̂(t₁) = t₁).
            // (within 0.020 and 0.011 of a spacing at 200 and 400 nodes: second order)
            assert!(
                (radius - t1.sqrt()).abs() <= 0.03 * spacing,
                "t = {t}: â {radius} against {}",
                t1.sqrt()
            );
        }
    }
    // Lee & Radok's integral through the unloading would pull here: Ting's does not,
    // and the contact ends before the tip is back at the surface's level.
    let lee_radok_at = |t: f64| {
        let mut sum = 0.0;
        let n = 20000;
        for i in 0..n {
            let s = (i as f64 + 0.5) * t / n as f64;
            let rate = if s < 1.0 {
                2.0 * s.sqrt()
            } else {
                -2.0 * (2.0 - s).sqrt()
            };
            sum += (1.0 + r * (-(t - s) / tau).exp()) * rate * t / n as f64;
        }
        sum
    };
    assert!(lee_radok_at(1.8) < -0.05 * peak, "{}", lee_radok_at(1.8));
    let end = ting.iter().position(|&(f, _)| f == 0.0).unwrap();
    assert!(times[end] < 1.7, "the contact ends at {}", times[end]);
    // Second order in the node spacing, and within 1.5e-6 of the peak force at 400.
    assert!(
        worst[1] < 1.5e-6 && (3.5..4.5).contains(&(worst[0] / worst[1])),
        "{worst:?}"
    );
    // The loss of the cycle, ∮F̂ dδ̂ = ∫₀¹F̂ dt − ∫₁²F̂ dt, the model's at 400 nodes
    // against Ting's, the same trapezoidal rule on 400 intervals for both (measured
    // 2.2e-6 apart).
    let fine: Vec<f64> = (0..=400).map(|i| i as f64 * 0.005).collect();
    let loss = |force: &[f64]| -> f64 {
        (0..400)
            .map(|i| {
                let sign = if fine[i] < 1.0 - 1e-12 { 1.0 } else { -1.0 };
                sign * 0.5 * (force[i] + force[i + 1]) * 0.005
            })
            .sum()
    };
    let ting_loss = loss(
        &fine
            .iter()
            .map(|&t| ting_triangle(r, tau, t).0)
            .collect::<Vec<_>>(),
    );
    let model_loss = loss(
        &elements_triangle(r, tau, 400, &fine)
            .iter()
            .map(|&(f, _)| f)
            .collect::<Vec<_>>(),
    );
    assert!(
        ting_loss > 0.1 * peak && (model_loss / ting_loss - 1.0).abs() < 1e-5,
        "{model_loss} against Ting's {ting_loss}"
    );
}

/// δ̂(t) = 0.5 − 0.8 cos(2πt): two contacts a period, loading and unloading.
fn tapping(s: &mut RelaxingHalfSpace, periods: usize, steps: usize) -> Vec<(f64, f64)> {
    let depth = |t: f64| 0.5 - 0.8 * (2.0 * std::f64::consts::PI * t).cos();
    let mut out = Vec::new();
    let dt = 1.0 / steps as f64;
    for i in 0..periods * steps {
        let (t0, t1) = (i as f64 * dt, (i + 1) as f64 * dt);
        let (d0, d1) = (depth(t0).max(-1.0), depth(t1).max(-1.0));
        s.advance(d0, d1, dt).unwrap();
        out.push((d1, s.force_hat(d1)));
    }
    out
}

#[test]
fn fast_and_slow_relaxation_are_the_elastic_contacts() {
    // τ̂_r → 0: Hertz on E_∞; τ̂_r → ∞: Hertz on E₀ = 3E_∞, through two periods
    // of touching and letting go, exact between the nodes (50 cells).
    let hertz = |d: f64| 4.0 / 3.0 * d.max(0.0).powf(1.5);
    for (tau, modulus) in [(1e-9, 1.0), (1e9, 3.0)] {
        // (measured 1.7e-8 and 2.7e-9: the lag τ̂_r·dδ̂/dτ and its converse)
        let mut s = RelaxingHalfSpace::new(2.0, tau, 1.69, 50).unwrap();
        for (d, f) in tapping(&mut s, 2, 500) {
            assert!(
                (f - modulus * hertz(d)).abs() < 1e-7,
                "τ̂ {tau}: δ̂ {d} F̂ {f}"
            );
        }
    }
}

#[test]
fn a_free_surface_creeps_back_with_the_retardation_time() {
    // After a contact the surface under the axis is still depressed; free, it comes
    // back as e^{−t/((1 + r)τ̂_r)} (an SLS under no load creeps with its retardation
    // time τ_r E₀/E_∞).
    let (r, tau) = (2.0, 0.3);
    let mut s = RelaxingHalfSpace::new(r, tau, 1.0, 100).unwrap();
    s.advance(0.0, 1.0, 1.0).unwrap();
    s.advance(1.0, -1.0, 2.0).unwrap();
    let (depth, later) = (s.surface_depth_hat(), {
        s.advance(-1.0, -1.0, 0.5).unwrap();
        s.surface_depth_hat()
    });
    assert!(depth > 0.0 && s.force_hat(-1.0) == 0.0, "{depth}");
    let expected = depth * (-0.5 / ((1.0 + r) * tau)).exp();
    assert!(
        (later - expected).abs() < 1e-12 * depth,
        "{later} against {expected}"
    );
}

/// An integrator's steps through two taps: at each step's middle and end,
/// [`RelaxingHalfSpace::force_in_step_hat`] (given the exact indentation and rate
/// there) against the elements advanced in fine steps. Returns the largest
/// difference over the peak force.
fn stepped_error(tau: f64, step: f64) -> f64 {
    let w = 2.0 * std::f64::consts::PI;
    let depth = |t: f64| 0.5 - 0.8 * (w * t).cos();
    let rate = |t: f64| 0.8 * w * (w * t).sin();
    let mut fine = RelaxingHalfSpace::new(2.0, tau, 1.69, 60).unwrap();
    let mut stepped = fine.clone();
    let fine_steps = 800;
    let mut advance_fine = |from: f64, to: f64| {
        let dt = (to - from) / fine_steps as f64;
        for i in 0..fine_steps {
            let (a, b) = (from + i as f64 * dt, from + (i + 1) as f64 * dt);
            fine.advance(depth(a), depth(b), dt).unwrap();
        }
        fine.force_hat(depth(to))
    };
    let (mut worst, mut peak) = (0.0f64, 0.0f64);
    let steps = (2.0 / step).round() as usize;
    for k in 0..steps {
        let t = k as f64 * step;
        stepped.begin_step(depth(t), rate(t)).unwrap();
        for (at, done) in [(t + 0.5 * step, false), (t + step, true)] {
            let reference = advance_fine(if done { t + 0.5 * step } else { t }, at);
            let f = stepped.force_in_step_hat(depth(at), rate(at), at - t);
            worst = worst.max((f - reference).abs());
            peak = peak.max(reference);
        }
        stepped.end_step(depth(t + step), rate(t + step), step);
    }
    worst / peak
}

#[test]
fn a_step_sees_the_force_its_elements_would_have() {
    // Relaxation fast, near the contact time, slow against the period (the surface
    // then remembers the last tap): fourth order in the step, a few 1e-9 of the
    // peak at 200 steps a period (measured: 1.7e-7 to 5.7e-7 at 50 steps, 6.5e-10
    // to 2.4e-9 at 200).
    for tau in [0.01, 0.05, 0.3] {
        let (coarse, fine) = (stepped_error(tau, 0.02), stepped_error(tau, 0.005));
        assert!(
            fine < 4e-9 && coarse > 100.0 * fine,
            "τ̂ {tau}: {coarse:e} → {fine:e}"
        );
    }
    // Far faster than a step, where an explicit integrator of the memory would be
    // unstable: the relaxed contact's force within 1e-9 already at 50 steps a period
    // (measured 4.5e-11 at τ̂_r = 1e-7, 7.2e-10 at 1e-4).
    for tau in [1e-7, 1e-4] {
        let coarse = stepped_error(tau, 0.02);
        assert!(coarse < 1e-9, "τ̂ {tau}: {coarse:e}");
    }
}

#[test]
fn the_memory_of_a_cubic_indentation_is_its_relaxing_integral() {
    // Against Simpson's rule on the integral itself, from far slower relaxation
    // than the step to far faster, across the switch between series and
    // recurrence at λ = 1; and the limits: nothing at λ = 0, δ̂(Δ) as λ → ∞.
    let a = [0.3, -1.1, 2.5, -0.7];
    let cubic = |s: f64| a[0] + s * (a[1] + s * (a[2] + s * a[3]));
    for lambda in [1e-6, 0.01, 0.5, 0.999_999, 1.0, 1.000_001, 3.0, 40.0] {
        let n = 20_000;
        let h = 1.0 / n as f64;
        let quadrature: f64 = (0..=n)
            .map(|i| {
                let s = i as f64 * h;
                let weight = if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                weight * (-lambda * (1.0 - s)).exp() * cubic(s)
            })
            .sum::<f64>()
            * h
            / 3.0
            * lambda;
        let memory = relaxing_memory(a, lambda);
        assert!(
            (memory - quadrature).abs() < 1e-12 * quadrature.abs().max(lambda),
            "λ {lambda}: {memory} against {quadrature}"
        );
    }
    assert_eq!(relaxing_memory(a, 0.0), 0.0);
    assert!((relaxing_memory(a, 1e12) - cubic(1.0)).abs() < 1e-11);
    assert_eq!(relaxing_memory(a, f64::INFINITY), cubic(1.0));
}

#[test]
fn bad_input_is_refused() {
    assert!(RelaxingHalfSpace::new(0.0, 1.0, 1.0, 10).is_err());
    assert!(RelaxingHalfSpace::new(1.0, f64::NAN, 1.0, 10).is_err());
    assert!(RelaxingHalfSpace::new(1.0, 1.0, 1.0, 1).is_err());
    let mut s = RelaxingHalfSpace::new(1.0, 1.0, 1.0, 10).unwrap();
    assert!(s.advance(0.0, 1.1, 1.0).is_err());
    assert!(s.advance(0.0, f64::INFINITY, 1.0).is_err());
    assert!(s.advance(0.0, 0.5, -1.0).is_err());
    assert!(s.advance(0.0, 0.5, f64::INFINITY).is_err());
    assert!(s.begin_step(1.1, 0.0).is_err());
    assert!(s.begin_step(0.5, f64::NAN).is_err());
}
