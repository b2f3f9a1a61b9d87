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
    #[doc(hidden)]
    pub fn h_bar(&self, alpha_hat: f64) -> f64 {
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
