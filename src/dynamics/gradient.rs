//! The tip–sample force gradient averaged over a periodic orbit, ⟨∂F_ts/∂z⟩, as an
//! observer of the integration: what a second cantilever eigenmode, oscillating with a
//! small amplitude on top of the orbit, feels as a change of its stiffness (bimodal AFM
//! in the small-A₂ limit). Driven at its free resonance, such a mode lags by φ₂ with
//! cot φ₂ = −(Q₂/k₂)⟨∂F_ts/∂z⟩ (Lozano & García, PRL 100, 076102, 2008;
//! [`second_mode_phase_deg`]); sidebands at f₂ ± n f₁ lie off its resonance.
//!
//! Over each accepted step the law's elastic slope is integrated by 8-point
//! Gauss–Legendre quadrature on the step's quintic Hermite interpolant, as the harmonics
//! are ([`super::harmonics`]). Where the law switches branch at τ_j the force steps by
//! Δf_j; the small oscillation q₂ moves that instant by −q₂/ẋ_j, which acts on the
//! mode as a force Δf_j δ(τ − τ_j) q₂/ẋ_j: the average gains Σ Δf_j/(ẋ_j T). Only the
//! elastic part of the law enters (a rate-dependent sample's force adds a loss, not a
//! stiffness, to the second mode).

use super::free::FreeFlight;
use super::model::{Coupling, Oscillator, V, X};
use super::numeric::{StepEnd, StepObserver};
use crate::numeric::GAUSS_LEGENDRE_8;
use crate::physics::law::{Branch, ForceLaw};

/// Accumulates ∫ ∂f_ts/∂x dτ and the switches' steps over everything it observes (model
/// units: f in kL, x in L, so the average is in units of k).
pub struct GradientObserver<'a, L: ForceLaw> {
    law: &'a L,
    cpl: Coupling,
    osc: Oscillator,
    integral: f64,
    span: f64,
    /// The branch, elastic force and velocity where the last observed piece ended.
    last: Option<(Branch, f64, f64)>,
}

impl<'a, L: ForceLaw> GradientObserver<'a, L> {
    /// Nothing observed yet, for the law and model of a simulation.
    pub fn new(law: &'a L, cpl: Coupling, osc: Oscillator) -> Self {
        Self {
            law,
            cpl,
            osc,
            integral: 0.0,
            span: 0.0,
            last: None,
        }
    }

    /// The elastic force f = −f_scale·T̂ at deflection `x` on `branch` at τ.
    fn force(&self, tau: f64, x: f64, branch: Branch) -> f64 {
        let alpha = self.cpl.alpha_hat(x, self.osc.base_at(tau).0);
        -self.cpl.f_scale * self.law.t_hat(alpha, branch)
    }

    /// A piece starting on `branch` with elastic force `f` and velocity `v`: the step of
    /// the force where the branch changed since the last piece.
    fn begin(&mut self, branch: Branch, f: f64, v: f64) {
        if let Some((was, before, _)) = self.last {
            if was != branch && v != 0.0 {
                self.integral += (f - before) / v;
            }
        }
    }

    /// ⟨∂f_ts/∂x⟩ over the time observed (whole periods of a periodic orbit), in units
    /// of the cantilever's stiffness k; ⟨∂F_ts/∂z⟩ = k times it.
    pub fn finish(&self) -> f64 {
        self.integral / self.span
    }
}

impl<L: ForceLaw> StepObserver for GradientObserver<'_, L> {
    fn step<const N: usize>(&mut self, from: &StepEnd<N>, to: &StepEnd<N>, branch: Branch) {
        let h = to.tau - from.tau;
        if h <= 0.0 {
            return;
        }
        self.begin(branch, self.force(from.tau, from.y[X], branch), from.y[V]);
        let end = |e: &StepEnd<N>| (e.y[X], h * e.y[V], h * h * e.dy[V]);
        let (start, finish) = (end(from), end(to));
        for (x, w) in GAUSS_LEGENDRE_8 {
            let (t, w) = (0.5 * (1.0 + x), 0.5 * w);
            let tau = from.tau + t * h;
            let (x, _) = super::harmonics::quintic_hermite(t, start, finish);
            let alpha = self.cpl.alpha_hat(x, self.osc.base_at(tau).0);
            // ∂f/∂x = −f_scale · dT̂/dα̂ · dα̂/dx.
            let slope = -self.cpl.f_scale * self.law.slope_hat(alpha, branch) * self.cpl.a1;
            self.integral += w * h * slope;
        }
        self.span += h;
        self.last = Some((branch, self.force(to.tau, to.y[X], branch), to.y[V]));
    }

    fn free_flight(&mut self, flight: &FreeFlight, from: f64, to: f64) {
        // No force in free flight (it is only taken where the law has none): no slope.
        self.begin(Branch::Free, 0.0, flight.at(from).1);
        self.span += to - from;
        self.last = Some((Branch::Free, 0.0, flight.at(to).1));
    }
}

/// The phase lag φ₂ (degrees, 0–180°) of a second eigenmode of stiffness `k2_n_m` and
/// quality factor `q2`, driven at its free resonance with a small amplitude, over an orbit
/// whose averaged force gradient is `gradient_n_m` (⟨∂F_ts/∂z⟩, repulsive force
/// positive): cot φ₂ = −(Q₂/k₂)⟨∂F_ts/∂z⟩ (Lozano & García, PRL 100, 076102, 2008).
/// 90° with no force; below 90° where the contact stiffens the mode.
pub fn second_mode_phase_deg(gradient_n_m: f64, k2_n_m: f64, q2: f64) -> f64 {
    let cot = -q2 * gradient_n_m / k2_n_m;
    1.0f64.atan2(cot).to_degrees()
}
