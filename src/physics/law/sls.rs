//! A standard-linear-solid (Zener) sample under the tip, with Ting's receding contact:
//! the law whose sample remembers its deformation from one contact to the next.
//!
//! The sample's relaxation modulus is the SLS's, E(t) = E_∞ + (E₀ − E∞)e^{−t/τ_r}
//! (relaxed modulus E_∞, unrelaxed E₀, relaxation time τ_r). While the contact grows,
//! the force is Lee & Radok's (1960) hereditary Hertz integral; once it shrinks, Ting's
//! (J. Appl. Mech. 33, 845, 1966): the contact radius follows its own history, the
//! surface lags behind a retreating tip, and a non-adhesive contact never pulls. The
//! surface's memory is [`RelaxingHalfSpace`] (the method of dimensionality reduction,
//! checked there against Ting's formulas), which the integrator carries beside its
//! state ([`ForceLaw::surface`]); between contacts it creeps back with the retardation
//! time (1 + r)τ_r, so a tap meets the surface the last one left.
//!
//! In the contact's scales (α̂ = α/(με), T̂ = T/(RΔγ) tensile positive, τ = ω₀t,
//! indentation δ̂ = −α̂), with F̂ the surface's force (compressive positive) and
//! T̂_H(α̂) = −(4/3)(−α̂)^{3/2} the Hertz force at E* = E_∞ that the wrapped law already
//! holds, the rate-dependent part is
//!
//!   T̂_d = −F̂ − T̂_H(α̂)  in contact,  −F̂ out of it,   r = (E₀ − E_∞)/E_∞,
//!
//! so that the whole force is −F̂ plus whatever the wrapped law adds to Hertz (DMT's
//! adhesion, a capillary neck). The law carries no state of its own: the surface holds
//! the memory, and within an integrator's step it takes each element's relaxation in
//! closed form (τ̂_r = ω₀τ_r), so however fast the sample relaxes no stiff equation is
//! left to the integrator. Limits: τ_r → 0 the elastic contact on E_∞; τ_r → ∞ the
//! elastic contact on E₀ = (1 + r)E_∞ — on a surface that has sunk under the mean
//! tapping force, which a steady orbit reaches however slow the relaxation (see the
//! design notes). The loss per cycle is the work against T̂_d, ∮ T̂_d dα̂.
//! Not in the paper.

use super::conservative::hertz_t_hat;
use super::{Branch, ContactState, ForceLaw};
use crate::error::{Error, Result, positive};
use crate::physics::contact::viscoelastic::RelaxingHalfSpace;
use crate::physics::params::Contact;

/// The longest retardation time (1 + r)τ_r accepted, in periods of the cantilever: the
/// surface's slowest memory, which the steady-state search marches through.
pub const MAX_RETARDATION_PERIODS: f64 = 100.0;

/// A time in s, for messages.
fn seconds(seconds: f64) -> String {
    format!("{seconds:.3e} s")
}

/// A time in s as µs, for messages.
fn microseconds(seconds: f64) -> String {
    format!("{:.4} µs", seconds * 1e6)
}

/// The shortest relaxation time accepted, τ̂_r = ω₀τ_r: below it the rates at which
/// elements touch and let go, found from their lag behind the tip divided by τ̂_r, carry
/// round-off of 1e-16/τ̂_r, and the sample is the relaxed elastic contact to within
/// τ̂_r anyway (its departure from it is proportional to τ̂_r).
pub const MIN_RELAXATION_HAT: f64 = 1e-8;

/// A law with a standard-linear-solid sample.
#[derive(Debug, Clone)]
pub struct StandardLinearSolid<L> {
    elastic: L,
    /// r = (E₀ − E_∞)/E_∞.
    modulus_ratio: f64,
    /// τ̂_r = ω₀τ_r.
    relaxation_hat: f64,
}

impl<L: ForceLaw> StandardLinearSolid<L> {
    /// The contact law under the sample.
    #[inline]
    pub fn elastic_law(&self) -> &L {
        &self.elastic
    }

    /// `elastic` (a Hertzian contact whose modulus, the contact's E*, is the relaxed
    /// one) with a sample whose unrelaxed composite modulus is `unrelaxed_modulus_pa`
    /// (Pa, above the contact's) and relaxation time `relaxation_time_s` (s), for a
    /// cantilever resonating at `resonance_hz` (the time unit 1/ω₀).
    pub fn new(
        elastic: L,
        unrelaxed_modulus_pa: f64,
        relaxation_time_s: f64,
        contact: &Contact,
        resonance_hz: f64,
    ) -> Result<Self> {
        positive("unrelaxed modulus", unrelaxed_modulus_pa)?;
        positive("relaxation time", relaxation_time_s)?;
        positive("resonance frequency", resonance_hz)?;
        if unrelaxed_modulus_pa <= contact.modulus_pa {
            return Err(Error::NotApplicable(format!(
                "the unrelaxed modulus {:.4} GPa must exceed the relaxed one, the contact's \
                 composite modulus E* = {:.4} GPa (a relaxing sample is stiffer at high rates)",
                unrelaxed_modulus_pa * 1e-9,
                contact.modulus_pa * 1e-9
            )));
        }
        let modulus_ratio = unrelaxed_modulus_pa / contact.modulus_pa - 1.0;
        let relaxation_hat = 2.0 * std::f64::consts::PI * resonance_hz * relaxation_time_s;
        if !(modulus_ratio.is_finite() && relaxation_hat.is_finite()) {
            return Err(Error::NotApplicable(
                "the relaxing sample's modulus ratio or relaxation time is out of range".into(),
            ));
        }
        if relaxation_hat < MIN_RELAXATION_HAT {
            return Err(Error::NotApplicable(format!(
                "the relaxing sample's relaxation time {} is below {} ({MIN_RELAXATION_HAT:e} \
                 of the cantilever's 1/ω₀), where round-off would be all that distinguishes it: \
                 a sample that relaxes this fast is the relaxed elastic contact on its E∞ \
                 (the loss falls in proportion to τ_r); give its relaxed modulus alone",
                seconds(relaxation_time_s),
                seconds(MIN_RELAXATION_HAT / (2.0 * std::f64::consts::PI * resonance_hz))
            )));
        }
        let retardation_periods = (1.0 + modulus_ratio) * relaxation_time_s * resonance_hz;
        if retardation_periods > MAX_RETARDATION_PERIODS {
            return Err(Error::NotApplicable(format!(
                "the relaxing sample's retardation time (E₀/E∞)τ_r = {} spans {:.0} periods \
                 of the cantilever, more than {MAX_RETARDATION_PERIODS:.0}: its surface takes \
                 that long to settle under the taps (it sinks under the mean tapping force), \
                 and tapsim finds that settling by marching every period. Give a relaxation \
                 time up to {} here; a slower sample is, on the tapping orbit, the unrelaxed \
                 elastic contact (at E0 = {:.4} GPa) on a surface sunk under the mean force \
                 (see the design notes)",
                microseconds(relaxation_time_s * (1.0 + modulus_ratio)),
                retardation_periods,
                microseconds(MAX_RETARDATION_PERIODS / ((1.0 + modulus_ratio) * resonance_hz)),
                unrelaxed_modulus_pa * 1e-9
            )));
        }
        Ok(Self {
            elastic,
            modulus_ratio,
            relaxation_hat,
        })
    }

    /// r = (E₀ − E_∞)/E_∞.
    pub fn modulus_ratio(&self) -> f64 {
        self.modulus_ratio
    }

    /// τ̂_r = ω₀τ_r.
    pub fn relaxation_hat(&self) -> f64 {
        self.relaxation_hat
    }
}

/// Cells the surface's nodes span across their reach ([`RelaxingHalfSpace`]): the
/// contact covers two thirds of them or more once the reach has grown to the deepest
/// indentation (the march grows it by half whenever the tip comes within 70 % of it).
/// The surface's error is second order in the spacing; tests/relaxing.rs measures what
/// it moves on a steady orbit against twice as many.
pub const SURFACE_CELLS: usize = 192;

impl<L: ForceLaw> ForceLaw for StandardLinearSolid<L> {
    elastic_part_from_inside!();
    fn is_rate_dependent(&self) -> bool {
        true
    }
    /// Needs the surface ([`ForceLaw::surface_t_hat`]): without it not a number, so
    /// that a path that forgot the surface fails instead of reading a wrong force.
    #[inline]
    fn dissipative_t_hat(&self, _state: &ContactState) -> f64 {
        f64::NAN
    }
    fn dissipative_slopes_hat(&self, _state: &ContactState) -> (f64, f64) {
        (f64::NAN, f64::NAN)
    }
    fn surface(&self, reach_hat: f64) -> Option<RelaxingHalfSpace> {
        RelaxingHalfSpace::new(
            self.modulus_ratio,
            self.relaxation_hat,
            reach_hat,
            SURFACE_CELLS,
        )
        .ok()
    }
    /// T̂_d = −F̂ − T̂_H(α̂) in contact (the wrapped law holds T̂_H), −F̂ out of it.
    #[inline]
    fn surface_t_hat(&self, state: &ContactState, surface_force_hat: f64) -> f64 {
        match state.branch {
            Branch::Contact => -surface_force_hat - hertz_t_hat(state.alpha_hat),
            Branch::Free | Branch::Necked => -surface_force_hat,
        }
    }
}
