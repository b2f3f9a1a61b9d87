//! Two rigid bodies with the Lennard-Jones surface interaction: the paper's eq. (12),
//! T̂ = (8π/3)(1/h̄₀² − 1/(4h̄₀⁸)) at the central gap h̄₀ = h₀/ε = 1 + μα̂ (the bodies
//! touch at h₀ = ε, α = 0), the limit μ → 0 of every adhesive law here: its greatest
//! pull, 2π at contact, is Bradley's 2πRΔγ. Conservative (one curve, both ways) and
//! without elastic deformation: the modulus enters only through the scales of α̂.
//!
//! The law was added as the registry says a law is: this file and its line in
//! [`super::LAWS`], called through [`super::AnyLaw::Dyn`].

use super::{AnyLaw, Branch, DynLaw, ForceLaw, LawInfo};
use crate::physics::contact::semi_rigid;
use std::f64::consts::PI;
use std::sync::Arc;

/// The registry's entry for the rigid law.
pub(super) const RIGID: LawInfo = LawInfo {
    name: "rigid",
    help: "two rigid bodies with the Lennard-Jones surface interaction, eq. (12): \
           (8πRΔγ/3)(1/h̄² − 1/(4h̄⁸)) at the gap h = α + ε, pull-off 2πRΔγ (Bradley); no \
           elastic deformation, the small-μ limit; conservative",
    build: |_, contact| {
        Ok(AnyLaw::Dyn(DynLaw(Arc::new(RigidLaw::new(
            contact.tabor_mu(),
        )))))
    },
    hertzian: false,
    touches_at_range: true,
};

/// Below this gap h̄₀ (an overlap no orbit reaches: the repulsion there is some 10⁴
/// times the pull-off) the force continues along its tangent, so that integrator trial
/// stages past it stay finite.
const H_BAR_MIN: f64 = 0.3;

/// The rigid-body law of eq. (12) in the scales of eq. (3).
#[derive(Debug, Clone, Copy)]
pub struct RigidLaw {
    tabor_mu: f64,
}

impl RigidLaw {
    /// The law at Tabor parameter `tabor_mu` (which sets the scale of α̂ only).
    pub fn new(tabor_mu: f64) -> Self {
        Self { tabor_mu }
    }

    /// The gap h̄₀ = 1 + μα̂ at separation α̂.
    fn h_bar(&self, alpha_hat: f64) -> f64 {
        1.0 + self.tabor_mu * alpha_hat
    }

    /// dT̂/dh̄₀ of eq. (12): (8π/3)(−2/h̄₀³ + 2/h̄₀⁹).
    fn d_force_d_h(h: f64) -> f64 {
        8.0 * PI / 3.0 * (-2.0 / h.powi(3) + 2.0 / h.powi(9))
    }

    /// An antiderivative of eq. (12) in h̄₀: (8π/3)(−1/h̄₀ + 1/(28h̄₀⁷)).
    fn work_in_h(h: f64) -> f64 {
        8.0 * PI / 3.0 * (-1.0 / h + 1.0 / (28.0 * h.powi(7)))
    }
}

impl ForceLaw for RigidLaw {
    fn t_hat(&self, alpha_hat: f64, _branch: Branch) -> f64 {
        let h = self.h_bar(alpha_hat);
        if h >= H_BAR_MIN {
            semi_rigid::force_hat(h)
        } else {
            semi_rigid::force_hat(H_BAR_MIN) + Self::d_force_d_h(H_BAR_MIN) * (h - H_BAR_MIN)
        }
    }
    fn slope_hat(&self, alpha_hat: f64, _branch: Branch) -> f64 {
        self.tabor_mu * Self::d_force_d_h(self.h_bar(alpha_hat).max(H_BAR_MIN))
    }
    fn work_hat(&self, alpha_hat: f64, _branch: Branch) -> f64 {
        let h = self.h_bar(alpha_hat);
        let in_h = if h >= H_BAR_MIN {
            Self::work_in_h(h)
        } else {
            let dh = h - H_BAR_MIN;
            Self::work_in_h(H_BAR_MIN)
                + semi_rigid::force_hat(H_BAR_MIN) * dh
                + Self::d_force_d_h(H_BAR_MIN) * dh * dh / 2.0
        };
        // dα̂ = dh̄₀/μ.
        in_h / self.tabor_mu
    }
    fn jump_in_alpha_hat(&self) -> f64 {
        0.0
    }
    fn jump_out_alpha_hat(&self) -> f64 {
        0.0
    }
    fn free_branch_is_force_free(&self) -> bool {
        false
    }
    fn loop_area_hat(&self) -> f64 {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
            let ds = (law.t_hat(alpha_hat + d, Branch::Free)
                - law.t_hat(alpha_hat - d, Branch::Free))
                / (2.0 * d);
            let s = law.slope_hat(alpha_hat, Branch::Free);
            assert!(
                (ds - s).abs() < 1e-5 * s.abs().max(1.0),
                "{alpha_hat}: {ds} vs {s}"
            );
        }
    }
}
