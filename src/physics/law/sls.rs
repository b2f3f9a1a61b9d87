//! A standard-linear-solid (Zener) sample under the tip: the first law with internal
//! state carried by the integrator.
//!
//! The sample's relaxation modulus is the SLS's, E(t) = E_∞ + (E₀ − E∞)e^{−t/τ_r}
//! (relaxed modulus E_∞, unrelaxed E₀, relaxation time τ_r), and the force is Lee &
//! Radok's (1960) hereditary Hertz integral with it,
//!
//!   F(t) = (4√R/3) ∫ E(t − s) d(δ^{3/2})/ds ds,
//!
//! the form viscoelastic AFM indentation is analysed with (Ting's 1966 correction for a
//! shrinking contact is not applied: the integral runs through unloading too). Its
//! relaxed part is the Hertz force with E_∞ — the contact's own modulus E*, so the
//! wrapped law is unchanged — and its relaxing part a Maxwell arm whose force obeys a
//! first-order equation. In the contact's scales (α̂ = α/(με), T̂ = T/(RΔγ) tensile
//! positive, τ = ω₀t), with T̂_H(α̂) = −(4/3)(−α̂)^{3/2} the Hertz force at E*:
//!
//!   T̂_d = r·m̂ in contact,  dm̂/dτ = (dT̂_H/dα̂)(dα̂/dτ) − m̂/τ̂_r,
//!   r = (E₀ − E_∞)/E_∞,  τ̂_r = ω₀τ_r.
//!
//! The integrator carries m̂ as its relaxed part w = m̂ − T̂_H(α̂), the law's internal
//! state, whose equation dw/dτ = −(w + T̂_H(α̂))/τ̂_r is smooth where the contact
//! begins (m̂'s own is not: dT̂_H/dα̂ ∝ √(−α̂), and its variational equation would need
//! steps down to round-off there); out of contact w = m̂ and relaxes. Limits: τ_r → 0 leaves
//! the relaxed (elastic) law; τ_r → ∞ an elastic law with the unrelaxed modulus (and, on
//! a steady orbit, the mean Maxwell force relaxed away); neither loses energy. Taking
//! τ_r → 0 with (E₀ − E_∞)τ_r fixed turns the Maxwell arm into a dashpot,
//! m̂ → τ̂_r dT̂_H/dτ, which is Kelvin–Voigt's η√(Rδ)dδ/dt with η = 2(E₀ − E_∞)τ_r
//! ([`super::KelvinVoigt`]). The loss per cycle is the work against T̂_d, ∮ r m̂ dα̂.
//! Not in the paper.

use super::conservative::{hertz_slope_hat, hertz_t_hat};
use super::{Branch, ContactState, ForceLaw, InternalSlopes, MAX_INTERNAL};
use crate::error::{Error, Result, positive};
use crate::physics::params::Contact;

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

impl<L: ForceLaw> ForceLaw for StandardLinearSolid<L> {
    elastic_part_from_inside!();
    fn is_rate_dependent(&self) -> bool {
        true
    }
    fn internal_states(&self) -> usize {
        1
    }
    #[inline]
    fn dissipative_t_hat(&self, state: &ContactState) -> f64 {
        match state.branch {
            Branch::Contact => {
                self.modulus_ratio * (state.internal[0] + hertz_t_hat(state.alpha_hat))
            }
            Branch::Free | Branch::Necked => 0.0,
        }
    }
    fn dissipative_slopes_hat(&self, state: &ContactState) -> (f64, f64) {
        match state.branch {
            Branch::Contact => (self.modulus_ratio * hertz_slope_hat(state.alpha_hat), 0.0),
            Branch::Free | Branch::Necked => (0.0, 0.0),
        }
    }
    #[inline]
    fn internal_rates_hat(&self, state: &ContactState) -> [f64; MAX_INTERNAL] {
        [-(state.internal[0] + hertz_t_hat(state.alpha_hat)) / self.relaxation_hat]
    }
    fn free_relaxation_rates(&self) -> Option<[f64; MAX_INTERNAL]> {
        // Out of contact T̂_H = 0: dw/dτ = −w/τ̂_r.
        Some([1.0 / self.relaxation_hat])
    }
    fn internal_slopes_hat(&self, state: &ContactState) -> InternalSlopes {
        InternalSlopes {
            rate_d_alpha: [-hertz_slope_hat(state.alpha_hat) / self.relaxation_hat],
            rate_d_rate: [0.0],
            rate_d_internal: [[-1.0 / self.relaxation_hat]],
            force_d_internal: [match state.branch {
                Branch::Contact => self.modulus_ratio,
                Branch::Free | Branch::Necked => 0.0,
            }],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::law::{HertzLaw, Internal};

    fn law() -> StandardLinearSolid<HertzLaw> {
        let contact = Contact::new(20e-9, 1e9, 0.1, 0.3e-9).unwrap();
        StandardLinearSolid::new(HertzLaw, 3e9, 1e-7, &contact, 300e3).unwrap()
    }

    fn at(alpha_hat: f64, rate_hat: f64, m: f64, branch: Branch) -> ContactState {
        ContactState {
            alpha_hat,
            rate_hat,
            branch,
            internal: Internal([m]),
        }
    }

    #[test]
    fn the_maxwell_arm_follows_the_hertz_force_and_relaxes() {
        let l = law();
        assert!((l.modulus_ratio() - 2.0).abs() < 1e-12);
        let tau = 2.0 * std::f64::consts::PI * 300e3 * 1e-7;
        assert!((l.relaxation_hat() - tau).abs() < 1e-12 * tau);
        // Out of contact: no force, pure relaxation of m̂ = w.
        let free = at(0.5, -1.0, 0.3, Branch::Free);
        assert_eq!(l.dissipative_t_hat(&free), 0.0);
        assert!((l.internal_rates_hat(&free)[0] + 0.3 / tau).abs() < 1e-12);
        // In contact: T̂_d = r m̂ = r (w + T̂_H), and m̂ = w + T̂_H changes at
        // dT̂_H/dτ − m̂/τ̂_r (the Maxwell arm follows the Hertz force and relaxes).
        let (alpha, rate, w) = (-0.25, -2.0, 0.4);
        let t_h = -4.0 / 3.0 * 0.125;
        let m = w + t_h;
        let s = at(alpha, rate, w, Branch::Contact);
        assert!((l.dissipative_t_hat(&s) - 2.0 * m).abs() < 1e-12);
        let m_rate = l.internal_rates_hat(&s)[0] + 2.0 * 0.5 * rate;
        assert!(
            (m_rate - (2.0 * 0.5 * rate - m / tau)).abs() < 1e-9,
            "{m_rate}"
        );
        // The slopes are the derivatives.
        let s = at(-0.3, -1.7, 0.4, Branch::Contact);
        let d = l.internal_slopes_hat(&s);
        let (force_d_alpha, force_d_rate) = l.dissipative_slopes_hat(&s);
        let h = 1e-6;
        let rate = |a: f64, r: f64, w: f64| l.internal_rates_hat(&at(a, r, w, Branch::Contact))[0];
        let force = |a: f64, w: f64| l.dissipative_t_hat(&at(a, -1.7, w, Branch::Contact));
        let fd = |f: &dyn Fn(f64) -> f64, x: f64| (f(x + h) - f(x - h)) / (2.0 * h);
        let close = |a: f64, b: f64| (a - b).abs() < 1e-6 * (1.0 + b.abs());
        assert!(close(d.rate_d_alpha[0], fd(&|a| rate(a, -1.7, 0.4), -0.3)));
        assert!(close(d.rate_d_rate[0], fd(&|r| rate(-0.3, r, 0.4), -1.7)));
        assert!(close(
            d.rate_d_internal[0][0],
            fd(&|w| rate(-0.3, -1.7, w), 0.4)
        ));
        assert!(close(d.force_d_internal[0], fd(&|w| force(-0.3, w), 0.4)));
        assert!(close(force_d_alpha, fd(&|a| force(a, 0.4), -0.3)));
        assert_eq!(force_d_rate, 0.0);
    }

    #[test]
    fn refuses_a_sample_that_would_soften() {
        let contact = Contact::new(20e-9, 1e9, 0.1, 0.3e-9).unwrap();
        for (e0, tau) in [
            (1e9, 1e-7),
            (0.5e9, 1e-7),
            (3e9, 0.0),
            (3e9, -1.0),
            (f64::NAN, 1e-7),
        ] {
            assert!(StandardLinearSolid::new(HertzLaw, e0, tau, &contact, 300e3).is_err());
        }
    }
}
