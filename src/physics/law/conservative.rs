//! Conservative reference laws: Hertz, DMT (as VEDA and dForce define it), and no force.

use super::{AnyLaw, Branch, ForceLaw, LawInfo};
use crate::error::{Result, positive};
use crate::physics::params::Contact;
use std::f64::consts::PI;

/// The registry's entry for DMT.
pub(super) const DMT: LawInfo = LawInfo {
    name: "dmt",
    help: "DMT as VEDA and dForce define it: −HR/(6d²) outside, Hertz plus constant \
           adhesion inside, d = α + ε; conservative",
    build: |spec, contact| Ok(AnyLaw::Dmt(DmtLaw::new(contact, spec.hamaker_j)?)),
    hertzian: true,
    touches_at_range: true,
};

/// The registry's entry for Hertz.
pub(super) const HERTZ: LawInfo = LawInfo {
    name: "hertz",
    help: "Hertz repulsion (4/3)E*√R δ^{3/2} for indentation δ = −α > 0; conservative",
    build: |_, _| Ok(AnyLaw::Hertz(HertzLaw)),
    hertzian: true,
    touches_at_range: false,
};

/// The registry's entry for no force.
pub(super) const NONE: LawInfo = LawInfo {
    name: "none",
    help: "no tip–sample force (a free cantilever)",
    build: |_, _| Ok(AnyLaw::None(NoForce)),
    hertzian: false,
    touches_at_range: false,
};

/// Hertz repulsion T̂ = −(4/3)(−α̂)^{3/2} for α̂ < 0, zero otherwise: (4/3)E*√R δ^{3/2}
/// in the scales of eq. (3) (the large-â limit of eq. (5)).
#[derive(Debug, Clone, Copy, Default)]
pub struct HertzLaw;

#[inline]
#[doc(hidden)]
pub fn hertz_t_hat(alpha_hat: f64) -> f64 {
    if alpha_hat < 0.0 {
        let d = -alpha_hat;
        -4.0 / 3.0 * d * d.sqrt()
    } else {
        0.0
    }
}

/// dT̂/dα̂ of the Hertz law: 2√(−α̂) for α̂ < 0.
#[inline]
pub(super) fn hertz_slope_hat(alpha_hat: f64) -> f64 {
    if alpha_hat < 0.0 {
        2.0 * (-alpha_hat).sqrt()
    } else {
        0.0
    }
}

/// Work function of the Hertz law: (8/15)(−α̂)^{5/2} for α̂ < 0.
#[inline]
fn hertz_work_hat(alpha_hat: f64) -> f64 {
    if alpha_hat < 0.0 {
        let d = -alpha_hat;
        8.0 / 15.0 * d * d * d.sqrt()
    } else {
        0.0
    }
}

impl ForceLaw for HertzLaw {
    #[inline]
    fn t_hat(&self, alpha_hat: f64, _branch: Branch) -> f64 {
        hertz_t_hat(alpha_hat)
    }
    #[inline]
    fn slope_hat(&self, alpha_hat: f64, _branch: Branch) -> f64 {
        hertz_slope_hat(alpha_hat)
    }
    fn work_hat(&self, alpha_hat: f64, _branch: Branch) -> f64 {
        hertz_work_hat(alpha_hat)
    }
    fn jump_in_alpha_hat(&self) -> f64 {
        0.0
    }
    fn jump_out_alpha_hat(&self) -> f64 {
        0.0
    }
    fn free_branch_is_force_free(&self) -> bool {
        true
    }
    fn loop_area_hat(&self) -> f64 {
        0.0
    }
}

/// DMT: F = −HR/(6d²) for d > a₀ and −HR/(6a₀²) + (4/3)E*√R(a₀ − d)^{3/2} for d ≤ a₀,
/// with d = α + a₀, a₀ = ε and Hamaker constant H (default 12πε²Δγ, whose pull-off
/// force is the DMT value 2πRΔγ). In the scales of eq. (3):
/// T̂ = c/(1 + μα̂)² outside, c − (4/3)(−α̂)^{3/2} inside, c = H/(6Δγε²).
#[derive(Debug, Clone, Copy)]
pub struct DmtLaw {
    tabor_mu: f64,
    adhesion_t_hat: f64,
}

impl DmtLaw {
    /// The DMT law of `contact`, with Hamaker constant `hamaker_j` (J) if given.
    pub fn new(contact: &Contact, hamaker_j: Option<f64>) -> Result<Self> {
        let h = match hamaker_j {
            Some(h) => positive("Hamaker constant", h)?,
            None => 12.0 * PI * contact.range_m.powi(2) * contact.work_of_adhesion_j_m2,
        };
        Ok(Self {
            tabor_mu: contact.tabor_mu(),
            adhesion_t_hat: h / (6.0 * contact.work_of_adhesion_j_m2 * contact.range_m.powi(2)),
        })
    }

    /// Pull-off force T̂ at contact, H/(6Δγε²) (2π by default).
    pub fn adhesion_t_hat(&self) -> f64 {
        self.adhesion_t_hat
    }
}

impl ForceLaw for DmtLaw {
    #[inline]
    fn t_hat(&self, alpha_hat: f64, _branch: Branch) -> f64 {
        if alpha_hat > 0.0 {
            let d = 1.0 + self.tabor_mu * alpha_hat;
            self.adhesion_t_hat / (d * d)
        } else {
            self.adhesion_t_hat + hertz_t_hat(alpha_hat)
        }
    }
    #[inline]
    fn slope_hat(&self, alpha_hat: f64, _branch: Branch) -> f64 {
        if alpha_hat > 0.0 {
            let d = 1.0 + self.tabor_mu * alpha_hat;
            -2.0 * self.adhesion_t_hat * self.tabor_mu / (d * d * d)
        } else {
            hertz_slope_hat(alpha_hat)
        }
    }
    fn work_hat(&self, alpha_hat: f64, _branch: Branch) -> f64 {
        let c = self.adhesion_t_hat;
        if alpha_hat > 0.0 {
            -c / (self.tabor_mu * (1.0 + self.tabor_mu * alpha_hat))
        } else {
            c * alpha_hat + hertz_work_hat(alpha_hat) - c / self.tabor_mu
        }
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

/// No tip–sample force at all.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoForce;

impl ForceLaw for NoForce {
    #[inline]
    fn t_hat(&self, _alpha_hat: f64, _branch: Branch) -> f64 {
        0.0
    }
    fn slope_hat(&self, _alpha_hat: f64, _branch: Branch) -> f64 {
        0.0
    }
    fn work_hat(&self, _alpha_hat: f64, _branch: Branch) -> f64 {
        0.0
    }
    fn jump_in_alpha_hat(&self) -> f64 {
        f64::NEG_INFINITY
    }
    fn jump_out_alpha_hat(&self) -> f64 {
        f64::INFINITY
    }
    fn free_branch_is_force_free(&self) -> bool {
        true
    }
    fn loop_area_hat(&self) -> f64 {
        0.0
    }
}
