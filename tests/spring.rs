//! Finite support stiffness, eqs. (22)–(27), and the quasi-static cycle of Fig. 5.

use std::f64::consts::PI;
use tapsim::contact::hybrid::{self, JumpIn};
use tapsim::contact::jkr;
use tapsim::contact::spring;
use tapsim::quasistatic;

#[test]
fn jump_out_satisfies_eq_24_between_the_two_limits() {
    let (c, p) = (jkr::point_c().a_hat, jkr::pull_off_point().a_hat);
    for &k in &[1e-4, 0.1, 1.0, 10.0, 1e4] {
        let j = spring::jump_out(k).unwrap();
        assert!(j.a_hat > c && j.a_hat < p, "k {k}: a = {}", j.a_hat);
        let slope = jkr::d_separation_d_a(j.a_hat) / jkr::d_force_d_a(j.a_hat);
        assert!(
            (slope + 1.0 / k).abs() < 1e-9 * (1.0 + 1.0 / k),
            "k {k}: {slope}"
        );
    }
}

#[test]
fn landing_has_the_support_where_the_jump_started() {
    for &(mu, k) in &[(2.0, 0.5), (5.0, 2.0), (20.0, 50.0)] {
        let s = spring::hysteresis(mu, k, JumpIn::Fit).unwrap();
        let b = s.landing.unwrap();
        let a = s.alpha_hat_a.unwrap();
        assert!((spring::support_separation_hat(&b, k) - a).abs() < 1e-12);
        // On the stable branch: dα̂_S/dâ < 0 at B.
        assert!(jkr::d_separation_d_a(b.a_hat) + jkr::d_force_d_a(b.a_hat) / k < 0.0);
    }
}

#[test]
fn stiff_support_tends_to_the_rigid_hybrid_value() {
    for &mu in &[2.0, 5.0, 10.0, 20.0] {
        let rigid = hybrid::hysteresis(mu, JumpIn::Fit).unwrap().w_hat;
        let mut last_gap = f64::INFINITY;
        for &k in &[1e2, 1e4, 1e6, 1e8] {
            let w = spring::hysteresis(mu, k, JumpIn::Fit).unwrap().w_hat;
            let gap = (w - rigid) / rigid;
            assert!(
                gap > 0.0 && gap < last_gap,
                "mu {mu}, k {k}: {w} vs {rigid}"
            );
            last_gap = gap;
        }
        assert!(last_gap < 1e-6, "mu {mu}: {last_gap:e}");
    }
}

#[test]
fn soft_support_tends_to_eq_27() {
    let limit = (1.5 * PI).powi(2) / 2.0;
    for &mu in &[2.0, 5.0, 20.0] {
        let mut last_gap = f64::INFINITY;
        for &k in &[1e-2, 1e-4, 1e-6] {
            let w = spring::hysteresis(mu, k, JumpIn::Fit).unwrap().w_hat;
            let gap = (k * w - limit).abs() / limit;
            assert!(gap < last_gap, "mu {mu}, k {k}");
            last_gap = gap;
            assert!((spring::w_hat_soft_limit(k) * k - limit).abs() < 1e-12 * limit);
        }
        assert!(
            last_gap < 1e-5,
            "mu {mu}: k·W deviates {last_gap:e} from (3π/2)²/2"
        );
    }
}

#[test]
fn loss_falls_as_the_support_stiffens() {
    let mut last = f64::INFINITY;
    for i in 0..60 {
        let k = 1e-2 * 10f64.powf(i as f64 / 10.0);
        let w = spring::hysteresis(5.0, k, JumpIn::Fit).unwrap().w_hat;
        assert!(w < last, "k {k}");
        last = w;
    }
}

#[test]
fn bad_stiffness_is_an_error() {
    for k in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(spring::hysteresis(5.0, k, JumpIn::Fit).is_err(), "k {k}");
        assert!(spring::jump_out(k).is_err());
    }
}

#[test]
fn fig5_path_encloses_exactly_the_loss_of_eq_26() {
    for &(mu, k) in &[(2.0, 0.3), (5.0, 2.0), (10.0, 1.0), (20.0, 100.0)] {
        let cycle = quasistatic::cycle(mu, k, JumpIn::Fit, 20_000).unwrap();
        let area = cycle.enclosed_area();
        let w = cycle.hysteresis.w_hat;
        assert!(
            (area - w).abs() < 1e-6 * w,
            "mu {mu}, k {k}: path {area} vs (26) {w}"
        );
    }
}

#[test]
fn fig5_path_visits_a_b_c_d_in_order() {
    use quasistatic::Segment::*;
    let cycle = quasistatic::cycle(5.0, 2.0, JumpIn::Fit, 100).unwrap();
    let segments: Vec<_> = cycle.points.iter().map(|p| p.segment).collect();
    let mut order = segments.clone();
    order.dedup();
    assert_eq!(order, vec![Approach, Loading, Unloading, Retract]);
    let h = &cycle.hysteresis;
    let b = h.landing.unwrap();
    let first_loading = cycle.points.iter().find(|p| p.segment == Loading).unwrap();
    assert_eq!(first_loading.t_hat, b.t_hat);
    let last_unloading = cycle
        .points
        .iter()
        .rfind(|p| p.segment == Unloading)
        .unwrap();
    assert!((last_unloading.t_hat - h.jump_out.t_hat).abs() < 1e-12);
    // Jumps happen at fixed support position.
    let a = cycle
        .points
        .iter()
        .rfind(|p| p.segment == Approach)
        .unwrap();
    assert!((a.support_alpha_hat - first_loading.support_alpha_hat).abs() < 1e-12);
    let d = cycle.points.iter().find(|p| p.segment == Retract).unwrap();
    assert!((d.support_alpha_hat - last_unloading.support_alpha_hat).abs() < 1e-12);
}

#[test]
fn no_cycle_without_hysteresis() {
    // Below the maximum of the power law (17) there is no jump-in at all.
    assert!(quasistatic::cycle(0.3, 1.0, JumpIn::Fit, 100).is_err());
    // At mu = 1 the rigid hybrid has no loop (alpha_A > alpha_C); a stiff support has none
    // either, but a compliant one moves the jump-out out to alpha_S,C > alpha_A: a loop.
    assert!(quasistatic::cycle(1.0, 1e6, JumpIn::Fit, 100).is_err());
    let soft = spring::hysteresis(1.0, 1.0, JumpIn::Fit).unwrap();
    assert!(soft.w_hat > 0.0 && soft.support_alpha_hat_c > soft.alpha_hat_a.unwrap());
}
