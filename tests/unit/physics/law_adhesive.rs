//! Tests of `tapsim::physics::law::adhesive` (src/physics/law/adhesive.rs).

use tapsim::physics::contact::hybrid;
use tapsim::physics::contact::hybrid::JumpIn;
use tapsim::physics::contact::jkr;
use tapsim::physics::contact::semi_rigid::{self, EighthPower};
use tapsim::physics::law::adhesive::*;
use tapsim::physics::law::{Branch, ForceLaw};

#[test]
fn loop_areas_match_the_closed_forms() {
    let h = AdhesiveLaw::hybrid(5.0, JumpIn::Fit).unwrap();
    assert!((h.loop_area_hat() - hybrid::w_hat_fit(5.0)).abs() < 1e-10);
    assert!((AdhesiveLaw::jkr().loop_area_hat() - jkr::w_hat_jkr()).abs() < 1e-10);
}

#[test]
fn contact_table_matches_the_closed_form() {
    let l = AdhesiveLaw::jkr();
    let mut worst: f64 = 0.0;
    // From 1e-6 below C (nearer, the closed form itself is ill-conditioned).
    for i in 0..20_000 {
        let alpha = jkr::ALPHA_HAT_C - 1e-6 - 70.0 * (i as f64 / 20_000.0).powi(2);
        let exact = jkr::force_hat(jkr::a_hat_from_separation(alpha).unwrap());
        worst = worst.max((l.t_hat(alpha, Branch::Contact) - exact).abs() / (1.0 + exact.abs()));
    }
    assert!(worst < 1e-12, "{worst:e}");
}

#[test]
fn work_functions_are_antiderivatives_of_the_force() {
    let laws = [
        AdhesiveLaw::jkr(),
        AdhesiveLaw::hybrid_attractive(5.0).unwrap(),
    ];
    for l in &laws {
        for branch in [Branch::Free, Branch::Contact] {
            for &alpha in &[-70.0, -3.0, -0.5, 0.3, 0.9, 1.2, 1.6, 1.7, 2.5, 40.0, 80.0] {
                let h = 1e-5;
                let dw =
                    (l.work_hat(alpha + h, branch) - l.work_hat(alpha - h, branch)) / (2.0 * h);
                let t = l.t_hat(alpha, branch);
                assert!(
                    (dw - t).abs() < 1e-6 * (1.0 + t.abs()),
                    "{branch:?} {alpha}: {dw} vs {t}"
                );
            }
        }
    }
}

#[test]
fn contact_branch_is_continuous_through_c() {
    let l = AdhesiveLaw::jkr();
    let c = jkr::point_c();
    for eps in [1e-3, 1e-6, 1e-9] {
        let below = l.t_hat(c.alpha_hat - eps, Branch::Contact);
        let above = l.t_hat(c.alpha_hat + eps, Branch::Contact);
        assert!((below - c.t_hat).abs() < 10.0 * eps.sqrt());
        assert!((above - c.t_hat).abs() < 10.0 * eps.sqrt());
    }
    assert!(l.t_hat(100.0, Branch::Contact).is_finite());
}

#[test]
fn attractive_approach_follows_the_semi_rigid_curve() {
    let mu = 5.0;
    let l = AdhesiveLaw::hybrid_attractive(mu).unwrap();
    let fold = semi_rigid::jump_in_exact(mu, EighthPower::Keep)
        .unwrap()
        .unwrap();
    for &dh in &[1e-3, 0.1, 0.5, 2.0, 8.0, 50.0] {
        let h = fold.h0_bar + dh;
        let alpha = semi_rigid::separation_over_range(h, mu, EighthPower::Keep) / mu;
        let t = l.t_hat(alpha, Branch::Free);
        let expect = semi_rigid::force_hat(h);
        assert!((t - expect).abs() < 1e-6 * expect, "h {h}: {t} vs {expect}");
    }
    assert!(l.loop_area_hat() > 0.0);
}
