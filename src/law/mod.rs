//! Tip–sample force laws for the dynamics, behind one trait.
//!
//! Every law works in the contact's dimensionless variables: separation α̂ = α/(με) and
//! force T̂ = T/(RΔγ) (tensile positive), so inner loops never touch SI units. A law has
//! two branches — out of contact ([`Branch::Free`]) and in contact ([`Branch::Contact`]) —
//! and switches from Free to Contact when α̂ falls to [`ForceLaw::jump_in_alpha_hat`], and
//! back when α̂ rises to [`ForceLaw::jump_out_alpha_hat`]. Conservative laws switch both
//! ways at the same separation; hysteretic laws enclose [`ForceLaw::loop_area_hat`].

mod adhesive;
mod conservative;
mod fold_branch;
mod table;

pub use adhesive::AdhesiveLaw;
pub use conservative::{DmtLaw, HertzLaw, NoForce};
pub use fold_branch::{FarField, FoldBranch, Side};
pub use table::UniformTable;

use crate::contact::hybrid::JumpIn;
use crate::contact::lj::Reach;
use crate::error::{Error, Result};
use crate::params::Contact;
use serde::{Deserialize, Serialize};
use std::fmt;

/// The state of the contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Branch {
    /// Out of contact (approach branch).
    Free,
    /// In contact.
    Contact,
}

/// A two-branch tip–sample force law in dimensionless variables.
pub trait ForceLaw: Send + Sync {
    /// Force T̂ (tensile positive) at separation α̂ on `branch`. Finite for every finite
    /// α̂, including past a branch's own end (integrator trial stages overshoot).
    fn t_hat(&self, alpha_hat: f64, branch: Branch) -> f64;
    /// Slope dT̂/dα̂ on `branch`, for the variational equations of the one-period map.
    /// Finite everywhere (where T̂ has a square-root fold, capped very near it).
    fn slope_hat(&self, alpha_hat: f64, branch: Branch) -> f64;
    /// Work function of a branch: an antiderivative Φ with dΦ/dα̂ = T̂(α̂, branch), so the
    /// work done along a branch between two separations is a difference of Φ (each branch
    /// is conservative; the loss comes from switching).
    fn work_hat(&self, alpha_hat: f64, branch: Branch) -> f64;
    /// Separation at which the Free branch gives way to Contact on the way down.
    fn jump_in_alpha_hat(&self) -> f64;
    /// Separation at which the Contact branch gives way to Free on the way up.
    fn jump_out_alpha_hat(&self) -> f64;
    /// Whether T̂ is identically zero on the Free branch above the jump-in separation
    /// (motion there is then a linear oscillator with a closed-form solution).
    fn free_branch_is_force_free(&self) -> bool;
    /// Area of the force loop, ∮ T̂ dα̂ over one full traversal (Ŵ; 0 if conservative).
    fn loop_area_hat(&self) -> f64;
}

/// The laws on offer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "app", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum LawKind {
    /// The paper's hybrid law: force-free approach, jump-in at α̂_A from (17), JKR contact
    /// branch (5), jump-out at α̂_C (8). Loop area Ŵ_hybrid (18).
    #[default]
    Hybrid,
    /// The hybrid law with Greenwood's semi-rigid attraction (12), (14) on the approach
    /// branch, jumping in at that curve's own fold (15).
    HybridAttractive,
    /// Classic JKR: no force before contact, jump-in at α̂ = 0, jump-out at α̂_C.
    Jkr,
    /// DMT as VEDA and dForce define it: −HR/(6d²) outside, Hertz plus constant adhesion
    /// inside, d = α + a₀, a₀ = ε. Conservative.
    Dmt,
    /// Hertz: repulsion (4/3)E*√R δ^{3/2} for indentation δ = −α > 0. Conservative.
    Hertz,
    /// The Lennard-Jones law (10), tabulated from the full numerical solution (both
    /// branches, jumps at its folds A and C; first use per μ solves it, then cached).
    Lj,
    /// No tip–sample force (free cantilever).
    None,
}

impl LawKind {
    /// Every law, in the order of the help.
    pub const ALL: [LawKind; 7] = [
        LawKind::Hybrid,
        LawKind::HybridAttractive,
        LawKind::Jkr,
        LawKind::Dmt,
        LawKind::Hertz,
        LawKind::Lj,
        LawKind::None,
    ];

    /// The names of every law as a user types them.
    pub fn names() -> Vec<String> {
        Self::ALL.iter().map(ToString::to_string).collect()
    }
}

impl fmt::Display for LawKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            LawKind::Hybrid => "hybrid",
            LawKind::HybridAttractive => "hybrid-attractive",
            LawKind::Jkr => "jkr",
            LawKind::Dmt => "dmt",
            LawKind::Hertz => "hertz",
            LawKind::Lj => "lj",
            LawKind::None => "none",
        })
    }
}

/// One of the laws, chosen at run time.
#[derive(Debug, Clone)]
#[allow(
    clippy::large_enum_variant,
    reason = "built once per simulation and read on every right-hand-side evaluation: \
              a box would add a pointer chase to the hot path for no saving"
)]
pub enum AnyLaw {
    /// hybrid, hybrid-attractive or jkr.
    Adhesive(AdhesiveLaw),
    /// dmt.
    Dmt(DmtLaw),
    /// hertz.
    Hertz(HertzLaw),
    /// none.
    None(NoForce),
}

impl AnyLaw {
    /// Build law `kind` for `contact`; `hamaker_j` overrides the DMT Hamaker constant
    /// H = 12πε²Δγ. Refuses, naming a law that applies, where `kind` does not apply.
    pub fn new(kind: LawKind, contact: &Contact, hamaker_j: Option<f64>) -> Result<Self> {
        let mu = contact.tabor_mu();
        let refuse = |why: String| {
            Error::NotApplicable(format!(
                "the {kind} law does not apply at Tabor parameter mu = {mu:.4}: {why}; \
                 use the DMT law (small mu) or JKR"
            ))
        };
        Ok(match kind {
            LawKind::Hybrid => AnyLaw::Adhesive(
                AdhesiveLaw::hybrid(mu, JumpIn::Fit).map_err(|e| refuse(e.to_string()))?,
            ),
            LawKind::HybridAttractive => AnyLaw::Adhesive(
                AdhesiveLaw::hybrid_attractive(mu).map_err(|e| refuse(e.to_string()))?,
            ),
            LawKind::Jkr => AnyLaw::Adhesive(AdhesiveLaw::jkr()),
            LawKind::Dmt => AnyLaw::Dmt(DmtLaw::new(contact, hamaker_j)?),
            LawKind::Hertz => AnyLaw::Hertz(HertzLaw),
            LawKind::Lj => AnyLaw::Adhesive(
                AdhesiveLaw::lennard_jones(
                    &crate::contact::lj::obtain(mu, Reach::Springs).map_err(|e| match e {
                        // No loop: no hysteretic law to tabulate (a cell a map skips).
                        Error::NoHysteresis(why) => Error::NotApplicable(why),
                        other => other,
                    })?,
                )
                .map_err(|e| refuse(e.to_string()))?,
            ),
            LawKind::None => AnyLaw::None(NoForce),
        })
    }
}

/// Forward a method to the law inside [`AnyLaw`].
macro_rules! dispatch {
    ($self:ident, $l:ident => $e:expr) => {
        match $self {
            AnyLaw::Adhesive($l) => $e,
            AnyLaw::Dmt($l) => $e,
            AnyLaw::Hertz($l) => $e,
            AnyLaw::None($l) => $e,
        }
    };
}

impl ForceLaw for AnyLaw {
    #[inline]
    fn t_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        dispatch!(self, l => l.t_hat(alpha_hat, branch))
    }
    #[inline]
    fn slope_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        dispatch!(self, l => l.slope_hat(alpha_hat, branch))
    }
    fn work_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        dispatch!(self, l => l.work_hat(alpha_hat, branch))
    }
    fn jump_in_alpha_hat(&self) -> f64 {
        dispatch!(self, l => l.jump_in_alpha_hat())
    }
    fn jump_out_alpha_hat(&self) -> f64 {
        dispatch!(self, l => l.jump_out_alpha_hat())
    }
    fn free_branch_is_force_free(&self) -> bool {
        dispatch!(self, l => l.free_branch_is_force_free())
    }
    fn loop_area_hat(&self) -> f64 {
        dispatch!(self, l => l.loop_area_hat())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[cfg(feature = "app")]
    fn every_law_is_listed_once() {
        use clap::ValueEnum;
        assert_eq!(LawKind::ALL.to_vec(), LawKind::value_variants().to_vec());
    }
}
