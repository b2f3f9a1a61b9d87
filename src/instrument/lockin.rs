//! A lock-in amplifier: the deflection demodulated at the drive frequency through a
//! low-pass filter of order n (n cascaded RC stages of time constant T, as commercial
//! lock-ins build it: H(ω) = (1 + iωT)⁻ⁿ).
//!
//! The deflection x(τ) is mixed with the reference, 2x cos Ωτ and 2x sin Ωτ, and each
//! product filtered; for x = A cos(Ωτ − φ) the outputs settle on (A cos φ, A sin φ), so
//! A and φ are read with `tap`'s convention (φ = 90° free at resonance). Time is the
//! dimensionless τ = ω₀t. The filter is propagated exactly over each integrator step or
//! closed-form free flight: with y′ = (y_{k−1} − y_k)/T (y₀ the mixer output u),
//!
//!   y_k(b) = e^{−h/T} Σ_{j<k} (h/T)^j/j! · y_{k−j}(a) + ∫_a^b g_k(b − s) u(s) ds,
//!   g_k(r) = e^{−r/T} (r/T)^{k−1} / ((k−1)! T),
//!
//! the integral by 6-point Gauss–Legendre quadrature on pieces of at most 1/32 of a
//! drive period, with x from the step's cubic Hermite interpolant or the free flight's
//! closed form. A step input gives the closed-form step response
//! 1 − e^{−t/T} Σ_{j<n} (t/T)^j/j! ([`step_response`]).

use crate::dynamics::free::FreeFlight;
use crate::dynamics::model::X;
use crate::dynamics::numeric::{StepEnd, StepObserver, hermite};
use crate::error::{Error, Result};
use crate::law::Branch;

/// The highest filter order.
pub const MAX_ORDER: usize = 4;

/// Gauss–Legendre nodes on [−1, 1] (6 points) and their weights.
const NODES: [f64; 6] = [
    -0.932_469_514_203_152,
    -0.661_209_386_466_264_5,
    -0.238_619_186_083_196_9,
    0.238_619_186_083_196_9,
    0.661_209_386_466_264_5,
    0.932_469_514_203_152,
];
const WEIGHTS: [f64; 6] = [
    0.171_324_492_379_170_3,
    0.360_761_573_048_138_6,
    0.467_913_934_572_691,
    0.467_913_934_572_691,
    0.360_761_573_048_138_6,
    0.171_324_492_379_170_3,
];

/// A lock-in amplifier referenced to the drive: its filter state for the in-phase and
/// the quadrature channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LockIn {
    order: usize,
    /// Filter time constant T in units of 1/ω₀.
    time_constant: f64,
    /// Reference frequency Ω = ω/ω₀.
    omega: f64,
    /// Stage outputs of the in-phase (x cos) and quadrature (x sin) channels.
    in_phase: [f64; MAX_ORDER],
    quadrature: [f64; MAX_ORDER],
}

impl LockIn {
    /// A lock-in of filter order `order` (1–4) and time constant `time_constant_hat`
    /// (T·ω₀) at the reference frequency `omega` (Ω = ω/ω₀), its filters at rest.
    pub fn new(order: usize, time_constant_hat: f64, omega: f64) -> Result<Self> {
        if !(1..=MAX_ORDER).contains(&order) {
            return Err(Error::InvalidParameter {
                name: "lock-in filter order",
                value: order as f64,
                reason: "must be from 1 to 4",
            });
        }
        crate::error::positive("lock-in time constant", time_constant_hat)?;
        crate::error::positive("reference frequency", omega)?;
        Ok(Self {
            order,
            time_constant: time_constant_hat,
            omega,
            in_phase: [0.0; MAX_ORDER],
            quadrature: [0.0; MAX_ORDER],
        })
    }

    /// The filter order n.
    pub fn order(&self) -> usize {
        self.order
    }

    /// The filter time constant T·ω₀.
    pub fn time_constant_hat(&self) -> f64 {
        self.time_constant
    }

    /// The filtered (in-phase, quadrature) pair: (A cos φ, A sin φ) once settled.
    pub fn output(&self) -> (f64, f64) {
        (
            self.in_phase[self.order - 1],
            self.quadrature[self.order - 1],
        )
    }

    /// The amplitude read, in the deflection's units.
    pub fn amplitude(&self) -> f64 {
        let (x, y) = self.output();
        x.hypot(y)
    }

    /// The phase lag read, in degrees (`tap`'s convention: x ≈ A cos(Ωτ − φ)).
    pub fn phase_deg(&self) -> f64 {
        let (x, y) = self.output();
        y.atan2(x).to_degrees()
    }

    /// Filter the mixer outputs `mixed(τ)` = (in-phase, quadrature) over [a, b].
    pub fn filter(&mut self, a: f64, b: f64, mixed: impl Fn(f64) -> (f64, f64)) {
        let t = self.time_constant;
        let piece = (self.period() / 32.0).min(t);
        let pieces = ((b - a) / piece).ceil().max(1.0) as usize;
        let h = (b - a) / pieces as f64;
        for i in 0..pieces {
            let (from, to) = (a + h * i as f64, a + h * (i + 1) as f64);
            self.propagate(h, |k| {
                // ∫ g_k(to − s) u(s) ds over [from, to].
                let mut sum = (0.0, 0.0);
                for (node, weight) in NODES.iter().zip(WEIGHTS) {
                    let s = 0.5 * (from + to) + 0.5 * h * node;
                    let g = kernel(k, (to - s) / t) / t;
                    let (u, v) = mixed(s);
                    sum.0 += weight * g * u;
                    sum.1 += weight * g * v;
                }
                (0.5 * h * sum.0, 0.5 * h * sum.1)
            });
        }
    }

    /// The drive period in τ.
    fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.omega
    }

    /// Advance the filter states by `h`, `driven(k)` being the input's contribution to
    /// stage k (1-based) over the interval.
    fn propagate(&mut self, h: f64, driven: impl Fn(usize) -> (f64, f64)) {
        let r = h / self.time_constant;
        let decay = (-r).exp();
        let (old_i, old_q) = (self.in_phase, self.quadrature);
        for k in 1..=self.order {
            let (mut i, mut q) = driven(k);
            // e^{−r} Σ_{j<k} r^j/j! y_{k−j}(a).
            let mut term = decay;
            for j in 0..k {
                i += term * old_i[k - 1 - j];
                q += term * old_q[k - 1 - j];
                term *= r / (j + 1) as f64;
            }
            self.in_phase[k - 1] = i;
            self.quadrature[k - 1] = q;
        }
    }

    /// The mixer outputs 2x cos Ωτ and 2x sin Ωτ of deflection `x` at τ.
    fn mix(&self, tau: f64, x: f64) -> (f64, f64) {
        let (s, c) = (self.omega * tau).sin_cos();
        (2.0 * x * c, 2.0 * x * s)
    }
}

/// e^{−r} r^{k−1}/(k−1)!: the k-stage cascade's impulse response times T at r = t/T.
fn kernel(k: usize, r: f64) -> f64 {
    let mut v = (-r).exp();
    for j in 1..k {
        v *= r / j as f64;
    }
    v
}

/// The closed-form step response of an n-stage RC cascade at t/T = `r`:
/// 1 − e^{−r} Σ_{j<n} r^j/j! (the regularised incomplete gamma function P(n, r)).
pub fn step_response(order: usize, r: f64) -> f64 {
    let mut sum = 0.0;
    let mut term = 1.0;
    for j in 0..order {
        sum += term;
        term *= r / (j + 1) as f64;
    }
    1.0 - (-r).exp() * sum
}

impl StepObserver for LockIn {
    fn step<const N: usize>(&mut self, a: &StepEnd<N>, b: &StepEnd<N>, _: Branch) {
        let this = *self;
        self.filter(a.tau, b.tau, |tau| this.mix(tau, hermite(a, b, X, tau)));
    }

    fn free_flight(&mut self, flight: &FreeFlight, from: f64, to: f64) {
        let this = *self;
        self.filter(from, to, |tau| this.mix(tau, flight.at(tau).0));
    }
}
