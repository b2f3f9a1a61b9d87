//! Free flight cut into equal steps of a held force (the thermal force's steps,
//! [`crate::instrument::thermal`]), each step taken from one precomputed transition
//! instead of a [`FreeFlight`] of its own.
//!
//! Over a step of length Δ the free oscillator x'' + 2γx' + x = f₀ cos Ωτ + ξ (ξ held)
//! is its steady drive response z_p(τ) = (a cos Ωτ + b sin Ωτ, its derivative) plus the
//! held force's (ξ, 0) plus a transient u that decays freely: u(τ₀ + s) = Φ(s)u(τ₀),
//! Φ the free oscillation's transition matrix ([`FreeFlight::transition`]). With
//! Φ(Δ) and the weights ∫₀^Δ Φ₀ₖ(s)(cos Ωs, sin Ωs) ds computed once, a step costs a
//! 2 × 2 product, a rotation of the drive's phasor (sin Ωτ, cos Ωτ) by ΩΔ and a few
//! products for the Fourier projections and the energies (the same closed forms as
//! `FreeFlight`'s own advance) — no sine, cosine or exponential. The motion is the
//! closed form's to round-off.
//!
//! A step is taken here only where nothing happens inside it that the march must
//! locate: with M a bound on |x''| over the step (below), the deflection stays above
//! the jump-in level by more than Δ²M/8 (the largest gap between x and its chord) and
//! the velocity keeps its sign (|x'| at both ends above ΔM), so there is no fall into
//! contact and no turning point for the grazing margins, and the lowest x is at an end.
//! Elsewhere the caller takes the step with [`Simulation::advance`]. Observers are shown
//! the step as an integrator's step ([`StepObserver::step`]): they read its cubic
//! Hermite interpolant, whose error is below Δ⁴max|x''''|/384 (2.4e-7 of the
//! amplitude at 64 steps a period), as they read the contact's Dormand–Prince steps.

use super::budget;
use super::free::FreeFlight;
use super::grazing::Margins;
use super::march::{CycleIntegrals, Phase, Simulation};
use super::model::{BASE, Coupling, Drive, Oscillator, State, V, X};
use super::observer::{StepEnd, StepObserver};
use crate::error::Result;
use crate::physics::law::{Branch, Exits, ForceLaw};
use nalgebra::Matrix2;

/// The largest step, as a fraction of the free period 2π, taken here: the bound on
/// |x''| below needs ½Δ(½Δ + 2γ) < 1, and a coarser step would rarely clear its margins.
const MAX_STEP: f64 = 0.1 * std::f64::consts::TAU;

/// One step's transition and weights, for a force-driven oscillator whose free branch is
/// force-free and ends only by falling into contact.
#[derive(Debug, Clone, Copy)]
pub struct FreeSteps {
    /// Δ.
    step: f64,
    omega: f64,
    gamma: f64,
    /// The drive force's amplitude f₀.
    f0: f64,
    /// The steady drive response x_p = a cos Ωτ + b sin Ωτ.
    a: f64,
    b: f64,
    /// Φ(Δ).
    transition: Matrix2<f64>,
    /// (sin ΩΔ, cos ΩΔ).
    turn: (f64, f64),
    /// ∫₀^Δ Φ₀ₖ(s) cos Ωs ds for k = x, x'.
    cos_weights: [f64; 2],
    /// ∫₀^Δ Φ₀ₖ(s) sin Ωs ds.
    sin_weights: [f64; 2],
    /// The deflection at the jump-in level.
    #[doc(hidden)]
    pub level_x: f64,
    /// 1/(1 − ½Δ(½Δ + 2γ)): the bound on |x''| from its values at the ends.
    bound_gain: f64,
    cpl: Coupling,
}

impl FreeSteps {
    /// The steps of `step` (τ) for `sim`; `None` where they do not apply (a law with
    /// a rate-dependent force, a force out of contact, a branch left other
    /// than by falling into contact, a base drive or a ramp, overdamping, a step
    /// above a tenth of the free period).
    pub fn new<L: ForceLaw>(sim: &Simulation<'_, L>, step: f64) -> Option<Self> {
        let Drive::Force { amplitude: f0 } = sim.osc.drive else {
            return None;
        };
        let Exits {
            below: Some((jump_in, Branch::Contact)),
            above: None,
        } = sim.law.exits(Branch::Free)
        else {
            return None;
        };
        let gamma = sim.osc.gamma;
        let applies = sim.law.free_branch_is_force_free()
            && !sim.law.is_rate_dependent()
            && step > 0.0
            && step <= MAX_STEP
            && jump_in.is_finite();
        if !applies {
            return None;
        }
        let (a, b) = FreeFlight::steady(&sim.osc)?;
        let unforced = Oscillator {
            drive: Drive::Force { amplitude: 0.0 },
            bias: 0.0,
            ..sim.osc
        };
        let from_x = FreeFlight::new(&unforced, 0.0, 1.0, 0.0)?;
        let from_v = FreeFlight::new(&unforced, 0.0, 0.0, 1.0)?;
        let (cx, sx) = from_x.fourier(0.0, step);
        let (cv, sv) = from_v.fourier(0.0, step);
        let gain = 1.0 - 0.5 * step * (0.5 * step + 2.0 * gamma);
        if gain <= 0.5 {
            return None;
        }
        Some(Self {
            step,
            omega: sim.osc.omega,
            gamma,
            f0,
            a,
            b,
            transition: from_x.transition(step),
            turn: (sim.osc.omega * step).sin_cos(),
            cos_weights: [cx, cv],
            sin_weights: [sx, sv],
            level_x: sim.cpl.x_at(jump_in),
            bound_gain: 1.0 / gain,
            cpl: sim.cpl,
        })
    }

    /// Δ.
    pub fn step(&self) -> f64 {
        self.step
    }

    /// The drive's phasor (sin Ωτ, cos Ωτ) moved on by one step.
    #[inline]
    pub fn turned(&self, (s, c): (f64, f64)) -> (f64, f64) {
        let (st, ct) = self.turn;
        (s * ct + c * st, c * ct - s * st)
    }

    /// Take one step from `phase` (out of contact, the drive's phasor at its τ
    /// `phasor`) under the held force `force`, showing it to `observer`; `None`, with
    /// `phase` untouched, where the step must be located by the march (see the module
    /// notes).
    pub fn advance<O: StepObserver>(
        &self,
        phase: &mut Phase,
        phasor: (f64, f64),
        force: f64,
        observer: &mut O,
    ) -> Result<Option<CycleIntegrals>> {
        if phase.branch != Branch::Free {
            return Ok(None);
        }
        let (w, h) = (self.omega, self.step);
        let (s0, c0) = phasor;
        let (s1, c1) = self.turned(phasor);
        let particular = |s: f64, c: f64| (self.a * c + self.b * s, w * (self.b * c - self.a * s));
        let (xp0, vp0) = particular(s0, c0);
        let (xp1, vp1) = particular(s1, c1);
        let (x0, v0) = (phase.x, phase.v);
        let u = (x0 - xp0 - force, v0 - vp0);
        let t = &self.transition;
        let x1 = xp1 + force + t[(0, 0)] * u.0 + t[(0, 1)] * u.1;
        let v1 = vp1 + t[(1, 0)] * u.0 + t[(1, 1)] * u.1;
        // x'' at the ends, and M ≥ max |x''| over the step: |x''| moves from its value
        // at the nearer end by at most ½Δ·max|x'''|, |x'''| ≤ |x'| + 2γ|x''| + f₀Ω, and
        // |x'| by at most ½Δ·M from its value there.
        let acc = |x: f64, v: f64, c: f64| -x - 2.0 * self.gamma * v + self.f0 * c + force;
        let (a0, a1) = (acc(x0, v0, c0), acc(x1, v1, c1));
        let bound = (a0.abs().max(a1.abs())
            + 0.5 * h * (v0.abs().max(v1.abs()) + self.f0.abs() * w))
            * self.bound_gain;
        let lowest = x0.min(x1);
        let clear = lowest - 0.125 * h * h * bound > self.level_x;
        let monotone = v0 * v1 > 0.0 && v0.abs().min(v1.abs()) > h * bound;
        if !(clear && monotone && bound.is_finite()) {
            return Ok(None);
        }
        budget::spend(1)?;
        // The Fourier projections: the drive response's and the held force's in closed
        // form, the transient's from the weights turned to the step's phase.
        let two_w = 2.0 * w;
        let (cross, squares) = (s1 * c1 - s0 * c0, s1 * s1 - s0 * s0);
        let (cw, sw) = (self.cos_weights, self.sin_weights);
        let (ic, is) = (cw[0] * u.0 + cw[1] * u.1, sw[0] * u.0 + sw[1] * u.1);
        let sc = self.a * (0.5 * h + cross / two_w)
            + self.b * squares / two_w
            + force * (s1 - s0) / w
            + c0 * ic
            - s0 * is;
        let ss = self.a * squares / two_w
            + self.b * (0.5 * h - cross / two_w)
            + force * (c0 - c1) / w
            + s0 * ic
            + c0 * is;
        let drive = self.f0 * (x1 * c1 - x0 * c0 + w * ss);
        let mechanical = 0.5 * (x1 * x1 + v1 * v1) - 0.5 * (x0 * x0 + v0 * v0);
        let end = |tau: f64, x: f64, v: f64, a: f64| {
            let (mut y, mut dy) = (State::<BASE>::zeros(), State::<BASE>::zeros());
            (y[X], y[V], dy[X], dy[V]) = (x, v, v, a);
            StepEnd { tau, y, dy }
        };
        let tau0 = phase.tau;
        observer.step(
            &end(tau0, x0, v0, a0),
            &end(tau0 + h, x1, v1, a1),
            Branch::Free,
        );
        phase.tau = tau0 + h;
        phase.x = x1;
        phase.v = v1;
        Ok(Some(CycleIntegrals {
            periods: 0,
            period: h,
            e_ts: 0.0,
            e_viscous: 0.0,
            e_capillary: 0.0,
            e_damp: drive + force * (x1 - x0) - mechanical,
            e_drive: drive,
            delta_mechanical: mechanical,
            sc,
            ss,
            f_int: 0.0,
            virial_int: 0.0,
            contact_time: 0.0,
            min_alpha_hat: self.cpl.alpha_hat(lowest, 0.0),
            max_force: 0.0,
            min_force: 0.0,
            grazing: Margins::NONE,
            jumps_in: 0,
            jumps_out: 0,
        }))
    }
}
