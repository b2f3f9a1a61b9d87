//! The JKR closed forms, eqs. (5)–(9).

use std::f64::consts::PI;
use tapsim::contact::jkr::{self, ForceBranch};

#[test]
fn points_b_and_c_match_eq_8() {
    let b = jkr::point_b();
    let c = jkr::point_c();
    // (7): α̂_B = 0 and dα̂/dâ = 0 at C (so dα̂/dT̂ = 0).
    assert!(b.alpha_hat.abs() < 1e-12, "alpha_B = {}", b.alpha_hat);
    assert!(jkr::d_separation_d_a(c.a_hat).abs() < 1e-12);
    // (8)
    assert!((b.a_hat - (2.0 * PI).cbrt()).abs() < 1e-12);
    assert!(
        (b.t_hat - 4.0 * PI / 3.0).abs() < 1e-12,
        "T_B = {}",
        b.t_hat
    );
    assert!((c.alpha_hat - 3.0 * PI.powf(2.0 / 3.0) / 4.0).abs() < 1e-12);
    assert!((c.a_hat - PI.cbrt() / 2.0).abs() < 1e-12);
    assert!(
        (c.t_hat - 5.0 * PI / 6.0).abs() < 1e-12,
        "T_C = {}",
        c.t_hat
    );
}

#[test]
fn load_control_pull_off_is_three_pi_over_two() {
    let p = jkr::pull_off_point();
    assert!(jkr::d_force_d_a(p.a_hat).abs() < 1e-12);
    assert!((p.t_hat - 1.5 * PI).abs() < 1e-12);
    // It is the maximum of T̂ along the curve.
    for i in 0..=1000 {
        let a = 3.0 * i as f64 / 1000.0;
        assert!(jkr::force_hat(a) <= p.t_hat + 1e-12);
    }
}

#[test]
fn w_hat_jkr_is_7_0922() {
    let w = jkr::w_hat_jkr();
    assert_eq!(format!("{w:.4}"), "7.0922", "W_JKR = {w}");
}

#[test]
fn work_integral_eq_6_is_the_antiderivative_of_t_dalpha() {
    // dŴ/dâ must equal T̂ dα̂/dâ everywhere on the curve (central differences).
    for &a in &[0.3, 0.7322, 1.0, 1.8, 2.5] {
        let h = 1e-5;
        let dw = (jkr::work_hat(a + h) - jkr::work_hat(a - h)) / (2.0 * h);
        let expect = jkr::force_hat(a) * jkr::d_separation_d_a(a);
        assert!(
            (dw - expect).abs() < 1e-7 * (1.0 + expect.abs()),
            "a = {a}: {dw} vs {expect}"
        );
    }
    // And the loop area (9) agrees with direct quadrature of ∫ T̂ dα̂ from B to C.
    let (b, c) = (jkr::point_b().a_hat, jkr::point_c().a_hat);
    let n = 20_000;
    let area: f64 = (0..n)
        .map(|i| {
            let (a0, a1) = (
                b + (c - b) * i as f64 / n as f64,
                b + (c - b) * (i + 1) as f64 / n as f64,
            );
            let am = 0.5 * (a0 + a1);
            jkr::force_hat(am) * jkr::d_separation_d_a(am) * (a1 - a0)
        })
        .sum();
    assert!((area - jkr::w_hat_jkr()).abs() < 1e-7, "{area}");
}

#[test]
fn closed_form_inverse_separation_solves_eq_5_on_the_stable_branch() {
    let c = jkr::point_c();
    let mut alpha = c.alpha_hat;
    while alpha > -50.0 {
        let a = jkr::a_hat_from_separation(alpha).expect("on the branch");
        assert!(a >= c.a_hat - 1e-6, "alpha {alpha}: a = {a} below a_C");
        let residual = jkr::separation_hat(a) - alpha;
        assert!(
            residual.abs() < 1e-11 * (1.0 + alpha.abs()),
            "alpha {alpha}: residual {residual}"
        );
        alpha -= 0.0137;
    }
    assert!(jkr::a_hat_from_separation(c.alpha_hat + 1e-3).is_none());
}

#[test]
fn inverse_force_solves_eq_5_on_both_branches() {
    let p = jkr::pull_off_point();
    for i in 0..200 {
        let t = -20.0 + 24.7 * i as f64 / 200.0;
        let a = jkr::a_hat_from_force(t, ForceBranch::LoadStable).unwrap();
        assert!(a >= p.a_hat - 1e-9);
        assert!((jkr::force_hat(a) - t).abs() < 1e-10 * (1.0 + t.abs()));
        if t >= 0.0 {
            let a = jkr::a_hat_from_force(t, ForceBranch::SmallContact).unwrap();
            assert!(a <= p.a_hat + 1e-9);
            assert!((jkr::force_hat(a) - t).abs() < 1e-10 * (1.0 + t.abs()));
        }
    }
    assert!(jkr::a_hat_from_force(1.5 * PI + 1e-6, ForceBranch::LoadStable).is_none());
}
