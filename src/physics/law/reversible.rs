//! The hybrid law made reversible: its approach branch retraced on the way out. No force
//! down to α̂_A of eq. (17), the JKR contact branch (5) below it, and the jump out of
//! contact at α̂_A as well, where the hybrid law holds on along the contact branch to
//! α̂_C of (8). One curve both ways, so conservative. Beside `hybrid` it isolates what
//! the loop between α̂_A and α̂_C does to an observable: in FM-AFM, the part of the
//! frequency shift that hysteresis makes (Gotsmann & Fuchs, Appl. Phys. A 72, 2001).

use super::registry::not_applicable;
use super::{AdhesiveLaw, AnyLaw, Branch, DynLaw, ForceLaw, LawInfo};
use crate::physics::contact::hybrid::JumpIn;
use std::sync::Arc;

/// The registry's entry for the reversible hybrid law.
pub(super) const HYBRID_REVERSIBLE: LawInfo = LawInfo {
    name: "hybrid-reversible",
    help: "the hybrid law's approach branch both ways: force-free down to α̂_A of (17), \
           JKR contact branch (5) below it, jump-out at α̂_A too (not α̂_C); conservative: \
           beside hybrid, what its loop adds",
    build: |_, contact| {
        let mu = contact.tabor_mu();
        AdhesiveLaw::hybrid(mu, JumpIn::Fit)
            .map(|law| AnyLaw::Dyn(DynLaw(Arc::new(Reversible(law)))))
            .map_err(|e| not_applicable("hybrid-reversible", mu, e))
    },
    hertzian: false,
    touches_at_range: false,
};

/// An adhesive law whose contact branch is left where it was entered: the jump-out is
/// the jump-in separation, so the loop has no area.
#[derive(Debug, Clone)]
pub struct Reversible(pub AdhesiveLaw);

impl ForceLaw for Reversible {
    fn t_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        self.0.t_hat(alpha_hat, branch)
    }
    fn slope_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        self.0.slope_hat(alpha_hat, branch)
    }
    fn work_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        self.0.work_hat(alpha_hat, branch)
    }
    fn jump_in_alpha_hat(&self) -> f64 {
        self.0.jump_in_alpha_hat()
    }
    fn jump_out_alpha_hat(&self) -> f64 {
        self.0.jump_in_alpha_hat()
    }
    fn free_branch_is_force_free(&self) -> bool {
        self.0.free_branch_is_force_free()
    }
    fn loop_area_hat(&self) -> f64 {
        0.0
    }
}
