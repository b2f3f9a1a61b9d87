//! A Kelvin–Voigt viscous sample on top of any contact law.
//!
//! While the tip indents the sample (δ = −α > 0, on the contact branch) the sample
//! resists the indentation rate with F_v = η√(Rδ)·dδ/dt, repulsive while δ grows and
//! attractive while it shrinks: the form dForce 2.0 and pyDAMPF use (pyDAMPF writes it
//! −η√(R(a₀ − d))·ż for d < a₀, ż the tip's velocity away from the sample, force
//! positive when repulsive). It is not in the paper; the elastic part is the wrapped law,
//! unchanged.
//!
//! In the contact's scales (α̂ = α/(με), T̂ = T/(RΔγ) tensile positive, τ = ω₀t):
//! T̂_d = c·√(−α̂)·dα̂/dτ with c = ηω₀(με)^{3/2}/(√R·Δγ). Its work per cycle,
//! ∮ T̂_d dα̂ = c∮√(−α̂)(dα̂/dτ)² dτ ≥ 0, is what the sample dissipates.

use super::{Branch, ContactState, ForceLaw};
use crate::error::{Result, positive};
use crate::physics::params::Contact;

/// A law with a Kelvin–Voigt viscous sample.
#[derive(Debug, Clone)]
pub struct KelvinVoigt<L> {
    elastic: L,
    /// c = ηω₀(με)^{3/2}/(√R·Δγ).
    coefficient: f64,
}

/// √(−α̂) below which the slope ∂T̂_d/∂α̂ (∝ 1/√(−α̂)) is capped: the force itself is
/// continuous at the contact's edge, its derivative is not.
const SLOPE_FLOOR: f64 = 1e-6;

impl<L: ForceLaw> KelvinVoigt<L> {
    /// The contact law under the sample.
    #[inline]
    pub fn elastic_law(&self) -> &L {
        &self.elastic
    }

    /// `elastic` with a sample of viscosity `viscosity_pa_s` (Pa·s) under the tip of
    /// `contact`, for a cantilever resonating at `resonance_hz` (the time unit 1/ω₀).
    pub fn new(
        elastic: L,
        viscosity_pa_s: f64,
        contact: &Contact,
        resonance_hz: f64,
    ) -> Result<Self> {
        positive("viscosity", viscosity_pa_s)?;
        positive("resonance frequency", resonance_hz)?;
        let omega0 = 2.0 * std::f64::consts::PI * resonance_hz;
        let coefficient = viscosity_pa_s * omega0 * contact.separation_scale_m().powf(1.5)
            / (contact.radius_m.sqrt() * contact.work_of_adhesion_j_m2);
        Ok(Self {
            elastic,
            coefficient,
        })
    }

    /// c, the viscous force T̂_d per unit √(−α̂)·dα̂/dτ.
    pub fn coefficient(&self) -> f64 {
        self.coefficient
    }

    /// √(−α̂) where the tip indents on the contact branch, else `None`.
    #[inline]
    fn indentation_root(state: &ContactState) -> Option<f64> {
        (state.branch == Branch::Contact && state.alpha_hat < 0.0)
            .then(|| (-state.alpha_hat).sqrt())
    }
}

impl<L: ForceLaw> ForceLaw for KelvinVoigt<L> {
    elastic_part_from_inside!();
    fn is_rate_dependent(&self) -> bool {
        true
    }
    #[inline]
    fn dissipative_t_hat(&self, state: &ContactState) -> f64 {
        Self::indentation_root(state).map_or(0.0, |root| self.coefficient * root * state.rate_hat)
    }
    fn dissipative_slopes_hat(&self, state: &ContactState) -> (f64, f64) {
        Self::indentation_root(state).map_or((0.0, 0.0), |root| {
            (
                -0.5 * self.coefficient * state.rate_hat / root.max(SLOPE_FLOOR),
                self.coefficient * root,
            )
        })
    }
}
