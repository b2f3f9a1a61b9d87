//! Tip–sample force laws for the dynamics, behind one trait.
//!
//! Every law works in the contact's dimensionless variables: separation α̂ = α/(με) and
//! force T̂ = T/(RΔγ) (tensile positive), so inner loops never touch SI units. A law has
//! two branches — out of contact ([`Branch::Free`]) and in contact ([`Branch::Contact`]) —
//! and switches from Free to Contact when α̂ falls to [`ForceLaw::jump_in_alpha_hat`], and
//! back when α̂ rises to [`ForceLaw::jump_out_alpha_hat`]. Conservative laws switch both
//! ways at the same separation; hysteretic laws enclose [`ForceLaw::loop_area_hat`].
//!
//! May import: the foundation, [`crate::physics::params`] and
//! [`crate::physics::contact`]. A new law: a file here (its force and its [`LawInfo`])
//! and its line in the registry, [`LAWS`] (the rigid law, `law/rigid.rs`, was added
//! that way).

/// The methods of a wrapper around a contact law (`elastic_law()`) that leaves the
/// law's elastic part as it is: force, slope and work function per branch, the
/// capillary share, the switches and the loop. A wrapper that adds a rate-dependent
/// force (a viscous or relaxing sample) writes only what it adds.
macro_rules! elastic_part_from_inside {
    () => {
        #[inline]
        fn t_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
            self.elastic_law().t_hat(alpha_hat, branch)
        }
        #[inline]
        fn slope_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
            self.elastic_law().slope_hat(alpha_hat, branch)
        }
        #[inline]
        fn t_and_slope_hat(&self, alpha_hat: f64, branch: Branch) -> (f64, f64) {
            self.elastic_law().t_and_slope_hat(alpha_hat, branch)
        }
        fn work_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
            self.elastic_law().work_hat(alpha_hat, branch)
        }
        fn capillary_work_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
            self.elastic_law().capillary_work_hat(alpha_hat, branch)
        }
        fn jump_in_alpha_hat(&self) -> f64 {
            self.elastic_law().jump_in_alpha_hat()
        }
        fn jump_out_alpha_hat(&self) -> f64 {
            self.elastic_law().jump_out_alpha_hat()
        }
        fn exits(&self, branch: Branch) -> $crate::physics::law::Exits {
            self.elastic_law().exits(branch)
        }
        /// The added force acts only in contact.
        fn free_branch_is_force_free(&self) -> bool {
            self.elastic_law().free_branch_is_force_free()
        }
        /// The elastic law's own loop (what the added force loses depends on the motion).
        fn loop_area_hat(&self) -> f64 {
            self.elastic_law().loop_area_hat()
        }
    };
}

/// A [`ForceLaw`] whose every method is the one of the law in `self.0` (a law behind a
/// box or a pointer); the hot calls out of line, so that the dispatch of [`AnyLaw`]
/// keeps the other laws' calls inlined.
macro_rules! forward_to_inner {
    () => {
        #[inline(never)]
        fn t_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
            self.0.t_hat(alpha_hat, branch)
        }
        #[inline(never)]
        fn slope_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
            self.0.slope_hat(alpha_hat, branch)
        }
        #[inline(never)]
        fn t_and_slope_hat(&self, alpha_hat: f64, branch: Branch) -> (f64, f64) {
            self.0.t_and_slope_hat(alpha_hat, branch)
        }
        fn work_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
            self.0.work_hat(alpha_hat, branch)
        }
        fn jump_in_alpha_hat(&self) -> f64 {
            self.0.jump_in_alpha_hat()
        }
        fn jump_out_alpha_hat(&self) -> f64 {
            self.0.jump_out_alpha_hat()
        }
        fn exits(&self, branch: Branch) -> Exits {
            self.0.exits(branch)
        }
        fn free_branch_is_force_free(&self) -> bool {
            self.0.free_branch_is_force_free()
        }
        fn loop_area_hat(&self) -> f64 {
            self.0.loop_area_hat()
        }
        fn capillary_work_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
            self.0.capillary_work_hat(alpha_hat, branch)
        }
        fn is_rate_dependent(&self) -> bool {
            self.0.is_rate_dependent()
        }
        #[inline(never)]
        fn dissipative_t_hat(&self, state: &ContactState) -> f64 {
            self.0.dissipative_t_hat(state)
        }
        #[inline(never)]
        fn dissipative_slopes_hat(&self, state: &ContactState) -> (f64, f64) {
            self.0.dissipative_slopes_hat(state)
        }
        fn surface(&self, reach_hat: f64) -> Option<RelaxingHalfSpace> {
            self.0.surface(reach_hat)
        }
        fn surface_t_hat(&self, state: &ContactState, surface_force_hat: f64) -> f64 {
            self.0.surface_t_hat(state, surface_force_hat)
        }
    };
}

#[doc(hidden)]
pub mod adhesive;
#[doc(hidden)]
pub mod capillary;
#[doc(hidden)]
pub mod conservative;
#[doc(hidden)]
pub mod fold_branch;
#[doc(hidden)]
pub mod registry;
#[doc(hidden)]
pub mod reversible;
#[doc(hidden)]
pub mod rigid;
#[doc(hidden)]
pub mod sls;
#[doc(hidden)]
pub mod table;
#[doc(hidden)]
pub mod viscous;

/// The registry: every law, in the order of the help. A new law is a file here (its
/// force, implementing [`ForceLaw`], and its [`LawInfo`]), its `mod` line above and its
/// line here; nothing else changes (a law with no variant of its own in [`AnyLaw`] is
/// called through [`AnyLaw::Dyn`], as the rigid law's is).
pub const LAWS: [&LawInfo; 9] = [
    &adhesive::HYBRID,
    &reversible::HYBRID_REVERSIBLE,
    &adhesive::HYBRID_ATTRACTIVE,
    &adhesive::JKR,
    &conservative::DMT,
    &conservative::HERTZ,
    &adhesive::LJ,
    &rigid::RIGID,
    &conservative::NONE,
];

pub use adhesive::AdhesiveLaw;
pub use capillary::{Capillary, Neck};
pub use conservative::{DmtLaw, HertzLaw, NoForce};
pub use fold_branch::{FarField, FoldBranch, Side};
pub use registry::{
    CONTACT_ANGLE, HAMAKER, LAW_PARAMS, LawInfo, LawKind, LawParam, LawSpec, RELAXATION_TIME,
    RUPTURE_DISTANCE, SURFACE_TENSION, UNRELAXED_MODULUS, VISCOSITY,
};
pub use sls::StandardLinearSolid;
pub use table::UniformTable;
pub use viscous::KelvinVoigt;

use crate::error::Result;
use crate::physics::contact::viscoelastic::RelaxingHalfSpace;
use crate::physics::params::Contact;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::sync::Arc;

/// The state of the contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Branch {
    /// Out of contact (approach branch).
    Free,
    /// In contact.
    Contact,
    /// Out of contact with a capillary neck still attached: a neck on a hysteretic
    /// contact law outlives the contact (no other law enters it).
    Necked,
}

impl Branch {
    /// How many there are (the integrator keeps a first step per branch).
    pub const COUNT: usize = 3;
}

/// Where a branch ends and which branch follows: α̂ falling to `below.0` enters
/// `below.1`, α̂ rising to `above.0` enters `above.1` (none: the branch runs on that way).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exits {
    /// The level α̂ falls to and the branch entered there.
    pub below: Option<(f64, Branch)>,
    /// The level α̂ rises to and the branch entered there.
    pub above: Option<(f64, Branch)>,
}

/// What a law sees of the contact at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactState {
    /// Separation α̂.
    pub alpha_hat: f64,
    /// Its rate dα̂/dτ (τ = ω₀t).
    pub rate_hat: f64,
    /// The branch.
    pub branch: Branch,
}

/// A two-branch tip–sample force law in dimensionless variables.
///
/// The force is T̂(α̂, branch) + T̂_d(state): an elastic (possibly hysteretic) part with a
/// work function per branch, and a rate-dependent part, zero unless the law says
/// otherwise, whose work the integrator carries as an integral (a viscous sample has no
/// work function). A relaxing sample's rate-dependent part comes from a surface that
/// remembers ([`ForceLaw::surface`]), which the integrator carries beside the state.
pub trait ForceLaw: Send + Sync {
    /// Force T̂ (tensile positive) at separation α̂ on `branch`. Finite for every finite
    /// α̂, including past a branch's own end (integrator trial stages overshoot).
    fn t_hat(&self, alpha_hat: f64, branch: Branch) -> f64;
    /// Slope dT̂/dα̂ on `branch`, for the variational equations of the one-period map.
    /// Finite everywhere (where T̂ has a square-root fold, capped very near it).
    fn slope_hat(&self, alpha_hat: f64, branch: Branch) -> f64;
    /// T̂ and dT̂/dα̂ together (what the variational equations need at every stage); a
    /// tabulated law finds its interval once for both.
    #[inline]
    fn t_and_slope_hat(&self, alpha_hat: f64, branch: Branch) -> (f64, f64) {
        (
            self.t_hat(alpha_hat, branch),
            self.slope_hat(alpha_hat, branch),
        )
    }
    /// Work function of a branch: an antiderivative Φ with dΦ/dα̂ = T̂(α̂, branch), so the
    /// work done along a branch between two separations is a difference of Φ (each branch
    /// is conservative; the loss comes from switching).
    fn work_hat(&self, alpha_hat: f64, branch: Branch) -> f64;
    /// Separation at which the Free branch gives way to Contact on the way down.
    fn jump_in_alpha_hat(&self) -> f64;
    /// Separation at which the Contact branch gives way to Free on the way up.
    fn jump_out_alpha_hat(&self) -> f64;
    /// Where `branch` ends and which branch follows. By default the two-branch law of
    /// [`ForceLaw::jump_in_alpha_hat`] and [`ForceLaw::jump_out_alpha_hat`]: Free ends
    /// falling to the jump-in separation (into Contact), Contact rising to the jump-out
    /// one (into Free); a law that never enters [`Branch::Necked`] gives it Free's.
    fn exits(&self, branch: Branch) -> Exits {
        match branch {
            Branch::Free | Branch::Necked => Exits {
                below: Some((self.jump_in_alpha_hat(), Branch::Contact)),
                above: None,
            },
            Branch::Contact => Exits {
                below: None,
                above: Some((self.jump_out_alpha_hat(), Branch::Free)),
            },
        }
    }
    /// Whether T̂ is identically zero on the Free branch above the jump-in separation
    /// (motion there is then a linear oscillator with a closed-form solution).
    fn free_branch_is_force_free(&self) -> bool;
    /// Area of the force loop, ∮ T̂ dα̂ over one full traversal (Ŵ; 0 if conservative).
    fn loop_area_hat(&self) -> f64;
    /// The part of [`ForceLaw::work_hat`] that a capillary neck contributes (0 by
    /// default), so its loss is told apart from the contact law's own hysteresis.
    fn capillary_work_hat(&self, _alpha_hat: f64, _branch: Branch) -> f64 {
        0.0
    }
    /// Whether the force has a rate-dependent part (if not, the integrator never asks
    /// for it).
    fn is_rate_dependent(&self) -> bool {
        false
    }
    /// The rate-dependent part T̂_d of the force at `state` (0 by default). Zero at
    /// zero rate, and continuous across the branch switches.
    fn dissipative_t_hat(&self, _state: &ContactState) -> f64 {
        0.0
    }
    /// ∂T̂_d/∂α̂ and ∂T̂_d/∂(dα̂/dτ) at `state`, for the variational equations (finite
    /// everywhere).
    fn dissipative_slopes_hat(&self, _state: &ContactState) -> (f64, f64) {
        (0.0, 0.0)
    }
    /// A fresh surface, relaxed and flat, whose nodes reach the indentation
    /// `reach_hat`, for a law whose sample remembers its deformation from one contact to
    /// the next (Ting's receding contact on a relaxing half-space,
    /// [`StandardLinearSolid`]); `None` (the default) for every other law. The
    /// integrator carries the surface beside the state, and the rate-dependent force
    /// comes from it ([`ForceLaw::surface_t_hat`]), not from
    /// [`ForceLaw::dissipative_t_hat`].
    fn surface(&self, _reach_hat: f64) -> Option<RelaxingHalfSpace> {
        None
    }
    /// Whether the sample has a surface that remembers ([`ForceLaw::surface`]).
    fn has_surface(&self) -> bool {
        self.surface(1.0).is_some()
    }
    /// The rate-dependent force T̂_d at `state` of a law with a surface
    /// ([`ForceLaw::surface`]), where the surface pushes on the tip with F̂
    /// (`surface_force_hat`, compressive positive, the contact's units).
    fn surface_t_hat(&self, state: &ContactState, _surface_force_hat: f64) -> f64 {
        self.dissipative_t_hat(state)
    }
    /// The whole force T̂ + T̂_d at `state`.
    #[inline]
    fn force_hat(&self, state: &ContactState) -> f64 {
        let elastic = self.t_hat(state.alpha_hat, state.branch);
        if self.is_rate_dependent() {
            elastic + self.dissipative_t_hat(state)
        } else {
            elastic
        }
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
    /// Any of the above on a rate-dependent sample (Kelvin–Voigt or standard linear
    /// solid).
    Viscous(Box<Rheology>),
    /// Any of the above with a capillary neck.
    Capillary(Necked),
    /// A law with no variant of its own, called through a pointer (one indirect call
    /// per evaluation): how a law a file adds joins without touching this enum.
    Dyn(DynLaw),
}

/// A law behind a shared pointer, for [`AnyLaw::Dyn`].
#[derive(Clone)]
pub struct DynLaw(pub Arc<dyn ForceLaw>);

impl fmt::Debug for DynLaw {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("DynLaw(..)")
    }
}

impl ForceLaw for DynLaw {
    forward_to_inner!();
}

/// A law with a capillary neck, behind a call: its methods inlined into the hot dispatch
/// of [`AnyLaw`] pushed the other laws' calls out of line (a whole Hertz run took 2.5 %
/// more instructions under callgrind, a viscous one 9 %); behind the call a neck pays
/// one call per evaluation and the rest 1–3 % (the extra variant and channel).
#[derive(Debug, Clone)]
pub struct Necked(Box<Capillary<AnyLaw>>);

impl ForceLaw for Necked {
    forward_to_inner!();
}

/// A law on a sample with a rate-dependent response. One variant of [`AnyLaw`] holds
/// both models: each variant of the law dispatch is code inlined into the integrator's
/// right-hand side, and a variant of its own for the relaxing sample cost every other
/// law 1–4 % more instructions per run (callgrind).
#[derive(Debug, Clone)]
pub enum Rheology {
    /// A Kelvin–Voigt viscous sample.
    KelvinVoigt(KelvinVoigt<AnyLaw>),
    /// A standard-linear-solid sample (Hertz or DMT only).
    Relaxing(StandardLinearSolid<AnyLaw>),
}

/// Forward a method to the law inside [`Rheology`].
macro_rules! rheology {
    ($self:ident, $l:ident => $e:expr) => {
        match $self {
            Rheology::KelvinVoigt($l) => $e,
            Rheology::Relaxing($l) => $e,
        }
    };
}

impl Rheology {
    /// The contact law under the sample, whichever model the sample follows: one
    /// forwarding call for the elastic part, not one per model.
    #[inline]
    fn elastic_law(&self) -> &AnyLaw {
        rheology!(self, l => l.elastic_law())
    }
}

impl ForceLaw for Rheology {
    elastic_part_from_inside!();
    fn is_rate_dependent(&self) -> bool {
        true
    }
    #[inline]
    fn dissipative_t_hat(&self, state: &ContactState) -> f64 {
        rheology!(self, l => l.dissipative_t_hat(state))
    }
    fn dissipative_slopes_hat(&self, state: &ContactState) -> (f64, f64) {
        rheology!(self, l => l.dissipative_slopes_hat(state))
    }
    fn surface(&self, reach_hat: f64) -> Option<RelaxingHalfSpace> {
        rheology!(self, l => l.surface(reach_hat))
    }
    fn surface_t_hat(&self, state: &ContactState, surface_force_hat: f64) -> f64 {
        rheology!(self, l => l.surface_t_hat(state, surface_force_hat))
    }
}

impl AnyLaw {
    /// Build the law `spec` asks for on `contact`, for a cantilever resonating at
    /// `resonance_hz` (the time scale of a rate-dependent force). Refuses, naming a law
    /// that applies, where the law does not apply, and names a parameter the law does
    /// not take.
    pub fn new(spec: &LawSpec, contact: &Contact, resonance_hz: f64) -> Result<Self> {
        spec.check()?;
        let info = spec.kind.info();
        let elastic = (info.build)(spec, contact)?;
        let elastic = match spec.neck() {
            Some(neck) => {
                // The gap at contact: DMT's d = α + ε, the other laws' d = α.
                let contact_gap_m = if info.touches_at_range {
                    contact.range_m
                } else {
                    0.0
                };
                let capillary = Capillary::new(elastic, &neck, contact, contact_gap_m)?;
                // A relaxing sample's Maxwell force acts in contact only, so the neck
                // takes a state of its own beyond it.
                AnyLaw::Capillary(Necked(Box::new(if spec.relaxing().is_some() {
                    capillary.outliving_contact()
                } else {
                    capillary
                })))
            }
            None => elastic,
        };
        if let Some((unrelaxed_pa, relaxation_s)) = spec.relaxing() {
            return Ok(AnyLaw::Viscous(Box::new(Rheology::Relaxing(
                StandardLinearSolid::new(
                    elastic,
                    unrelaxed_pa,
                    relaxation_s,
                    contact,
                    resonance_hz,
                )?,
            ))));
        }
        Ok(match spec.viscosity_pa_s {
            Some(eta) => AnyLaw::Viscous(Box::new(Rheology::KelvinVoigt(KelvinVoigt::new(
                elastic,
                eta,
                contact,
                resonance_hz,
            )?))),
            None => elastic,
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
            AnyLaw::Capillary($l) => $e,
            AnyLaw::Viscous($l) => $e,
            AnyLaw::Dyn($l) => $e,
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
    #[inline]
    fn t_and_slope_hat(&self, alpha_hat: f64, branch: Branch) -> (f64, f64) {
        dispatch!(self, l => l.t_and_slope_hat(alpha_hat, branch))
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
    fn exits(&self, branch: Branch) -> Exits {
        dispatch!(self, l => l.exits(branch))
    }
    fn free_branch_is_force_free(&self) -> bool {
        dispatch!(self, l => l.free_branch_is_force_free())
    }
    fn loop_area_hat(&self) -> f64 {
        dispatch!(self, l => l.loop_area_hat())
    }
    fn capillary_work_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        dispatch!(self, l => l.capillary_work_hat(alpha_hat, branch))
    }
    #[inline]
    fn is_rate_dependent(&self) -> bool {
        match self {
            AnyLaw::Viscous(_) => true,
            AnyLaw::Dyn(l) => l.is_rate_dependent(),
            _ => false,
        }
    }
    #[inline]
    fn dissipative_t_hat(&self, state: &ContactState) -> f64 {
        dispatch!(self, l => l.dissipative_t_hat(state))
    }
    fn dissipative_slopes_hat(&self, state: &ContactState) -> (f64, f64) {
        dispatch!(self, l => l.dissipative_slopes_hat(state))
    }
    fn surface(&self, reach_hat: f64) -> Option<RelaxingHalfSpace> {
        match self {
            AnyLaw::Viscous(l) => l.surface(reach_hat),
            AnyLaw::Dyn(l) => l.surface(reach_hat),
            _ => None,
        }
    }
    fn surface_t_hat(&self, state: &ContactState, surface_force_hat: f64) -> f64 {
        dispatch!(self, l => l.surface_t_hat(state, surface_force_hat))
    }
}
