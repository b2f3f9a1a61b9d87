//! Tests of `tapsim::physics::law::rigid` (src/physics/law/rigid.rs).

use std::f64::consts::PI;
use tapsim::physics::law::rigid::*;
use tapsim::physics::law::{Branch, ForceLaw};

/// Derjaguin's approximation for rigid bodies: the force at gap h₀ is 2πR times the
/// interaction energy per area there, ∫_{h₀}^∞ σ dh; for eq. (10)'s traction,
/// σ(h) = (8Δγ/3ε)((ε/h)³ − (ε/h)⁹), that energy at contact is Δγ, so the greatest
/// pull is 2πRΔγ (Bradley), at contact; and the work function's difference between
/// two gaps is the traction integrated twice, by quadrature.
#[test]
fn the_pull_off_is_bradleys_and_the_work_is_the_force_integrated() {
    let law = RigidLaw::new(1.7);
    let peak = (0..20_001)
        .map(|i| law.t_hat(-0.2 + 1e-4 * f64::from(i) / 1.7, Branch::Free))
        .fold(f64::NEG_INFINITY, f64::max);
    assert!((peak - 2.0 * PI).abs() < 1e-9 * 2.0 * PI, "{peak}");
    // Energy per area from the traction of eq. (10), by the midpoint rule in ε/h.
    let energy_per_area = |h0: f64| {
        let n = 200_000;
        (0..n)
            .map(|i| {
                // h = h0/u, dh = h0/u² du over u in (0, 1].
                let u = (f64::from(i) + 0.5) / f64::from(n);
                let h = h0 / u;
                8.0 / 3.0 * (h.powi(-3) - h.powi(-9)) * h0 / (u * u) / f64::from(n)
            })
            .sum::<f64>()
    };
    assert!((energy_per_area(1.0) - 1.0).abs() < 1e-8);
    for alpha_hat in [-0.1, 0.0, 0.3, 2.0] {
        let h = law.h_bar(alpha_hat);
        let t = law.t_hat(alpha_hat, Branch::Contact);
        assert!(
            (t - 2.0 * PI * energy_per_area(h)).abs() < 1e-7 * t.abs().max(1.0),
            "{alpha_hat}: {t}"
        );
    }
    // dΦ/dα̂ = T̂, checked by central differences, on both sides of the tangent's
    // start.
    for alpha_hat in [-0.5, -0.35, 0.0, 0.8] {
        let d = 1e-6;
        let dw = (law.work_hat(alpha_hat + d, Branch::Free)
            - law.work_hat(alpha_hat - d, Branch::Free))
            / (2.0 * d);
        let t = law.t_hat(alpha_hat, Branch::Free);
        assert!(
            (dw - t).abs() < 1e-6 * t.abs().max(1.0),
            "{alpha_hat}: {dw} vs {t}"
        );
        let ds = (law.t_hat(alpha_hat + d, Branch::Free) - law.t_hat(alpha_hat - d, Branch::Free))
            / (2.0 * d);
        let s = law.slope_hat(alpha_hat, Branch::Free);
        assert!(
            (ds - s).abs() < 1e-5 * s.abs().max(1.0),
            "{alpha_hat}: {ds} vs {s}"
        );
    }
}
