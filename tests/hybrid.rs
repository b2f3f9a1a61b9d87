//! The hybrid theory, eq. (18), and the adhesive length scale, eqs. (19)–(21).

use tapsim::contact::hybrid::{self, JumpIn};
use tapsim::contact::jkr;
use tapsim::contact::length_scale;

const PAPER_W_LJ_MU5: f64 = 3.2482;

#[test]
fn hybrid_at_mu_5_is_1_3_percent_below_the_paper_numerical_value() {
    let h = hybrid::hysteresis(5.0, JumpIn::Fit).unwrap();
    let below = (PAPER_W_LJ_MU5 - h.w_hat) / PAPER_W_LJ_MU5 * 100.0;
    assert!(
        (below - 1.3).abs() <= 0.05,
        "W_hybrid(5) = {}, {below:.3} % below",
        h.w_hat
    );
}

#[test]
fn landing_point_solves_eq_18_on_the_stable_branch() {
    for &mu in &[1.5, 2.0, 5.0, 20.0, 1e3] {
        for jump_in in [JumpIn::Fit, JumpIn::ClosedForm, JumpIn::SemiRigid] {
            let h = hybrid::hysteresis(mu, jump_in).unwrap();
            let a = h.alpha_hat_a.unwrap();
            let land = h.landing.expect("hysteretic for mu >= 1.5");
            assert!((jkr::separation_hat(land.a_hat) - a).abs() < 1e-12);
            assert!(land.a_hat > jkr::point_c().a_hat);
            let w = jkr::work_hat(jkr::point_c().a_hat) - jkr::work_hat(land.a_hat);
            assert!((h.w_hat - w).abs() < 1e-12);
        }
    }
}

#[test]
fn hybrid_rises_monotonically_to_jkr_as_mu_grows() {
    let w_jkr = jkr::w_hat_jkr();
    let mut last = 0.0;
    for &mu in &[1.2, 2.0, 5.0, 10.0, 100.0, 1e4, 1e6] {
        let w = hybrid::hysteresis(mu, JumpIn::Fit).unwrap().w_hat;
        assert!(w > last && w < w_jkr, "mu {mu}: {w}");
        last = w;
    }
    assert!((w_jkr - last) / w_jkr < 0.01, "mu 1e6: {last}");
    // JKR overestimates badly even at large mu: at mu = 10 the hybrid is below 2/3 of it.
    assert!(hybrid::hysteresis(10.0, JumpIn::Fit).unwrap().w_hat < 2.0 / 3.0 * w_jkr);
}

#[test]
fn small_mu_predicts_no_hysteresis_and_says_why() {
    let threshold = hybrid::min_hysteretic_mu(JumpIn::Fit).unwrap();
    assert!((threshold - 1.075).abs() < 0.001, "threshold {threshold}");
    // At the threshold the jump-in separation reaches alpha_C.
    let a = JumpIn::Fit.alpha_hat_a(threshold).unwrap().unwrap();
    assert!((a - jkr::point_c().alpha_hat).abs() < 1e-9);
    for &mu in &[0.05, 0.3, 1.0, 1.07] {
        let h = hybrid::hysteresis(mu, JumpIn::Fit).unwrap();
        assert_eq!(h.w_hat, 0.0, "mu {mu}");
        assert!(h.landing.is_none());
        let why = h.no_hysteresis_reason.expect("a reason");
        assert!(why.contains("no hysteresis"), "{why}");
    }
    assert!(hybrid::hysteresis(1.08, JumpIn::Fit).unwrap().w_hat > 0.0);
    // The semi-rigid variant has no jump-in at all for small mu.
    let h = hybrid::hysteresis(0.3, JumpIn::SemiRigid).unwrap();
    assert!(h.alpha_hat_a.is_none() && h.w_hat == 0.0);
}

#[test]
fn fast_path_equals_the_full_computation() {
    for i in 0..500 {
        let mu = 0.01 * 1.03f64.powi(i);
        let full = hybrid::hysteresis(mu, JumpIn::Fit).unwrap().w_hat;
        assert_eq!(hybrid::w_hat_fit(mu), full, "mu {mu}");
    }
    assert_eq!(hybrid::w_hat_fit(f64::NAN), 0.0);
}

#[test]
fn bad_mu_is_an_error() {
    for mu in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(hybrid::hysteresis(mu, JumpIn::Fit).is_err(), "mu {mu}");
    }
}

#[test]
fn adhesive_length_scale_eqs_19_to_21() {
    assert_eq!(
        format!("{:.4}", length_scale::lj_peak_traction_coeff()),
        "1.0264"
    );
    let crit = length_scale::pull_off_criterion_mu_squared();
    assert_eq!(format!("{crit:.2}"), "0.43");
    // The paper prints 0.44 for 2/π^{4/3} = 0.4347; (21) follows from a_C/s₀ = 1.
    let c = jkr::point_c();
    let mu = crit.sqrt();
    assert!((length_scale::contact_radius_over_s0(c.a_hat, mu) - 1.0).abs() < 1e-12);
}

#[test]
fn si_length_scale_matches_the_dimensionless_ratio() {
    let contact = tapsim::params::Contact::new(20e-9, 2e9, 0.04, 0.3e-9).unwrap();
    let mu = contact.tabor_mu();
    let a_hat = 1.3;
    let a_m = a_hat * contact.contact_radius_scale_m();
    let ratio = a_m / contact.s0_m();
    assert!((ratio - length_scale::contact_radius_over_s0(a_hat, mu)).abs() < 1e-10 * ratio);
}
