//! A lock-in amplifier: the deflection demodulated at the drive frequency through a
//! low-pass filter of order n (n cascaded RC stages of time constant T, as commercial
//! lock-ins build it: H(ω) = (1 + iωT)⁻ⁿ).
//!
//! As a digital lock-in does, it samples the deflection on a clock locked to the drive,
//! [`SAMPLES_PER_PERIOD`] times a period (at τ_k = k·T_d/S), mixes each sample with the
//! reference, u_k = (2x cos Ωτ_k, 2x sin Ωτ_k) (a table: Ωτ_k = 2πk/S), and filters the
//! mixer output. The filter is the continuous RC cascade driven by the mixer output
//! interpolated linearly between samples, propagated exactly from sample to sample
//! (y′_k = (y_{k−1} − y_k)/T, y₀ the input): over an interval h, r = h/T,
//!
//!   y_k ← e^{−r} Σ_{j<k} r^j/j! · y_{k−j} + (k/r)·P(k+1, r)·u_prev
//!         + (P(k, r) − (k/r)·P(k+1, r))·u_next,
//!
//! P(k, r) = 1 − e^{−r} Σ_{j<k} r^j/j! the regularised incomplete gamma function (the
//! k-stage step response, [`step_response`]); the weights are computed once. For
//! x = A cos(Ωτ − φ) the outputs settle on (A cos φ, A sin φ), so A and φ are read with
//! `tap`'s convention (φ = 90° free at resonance). Sampling at S per period the average of
//! the mixer output over a period is exact up to harmonics S ± 1 of the deflection (which
//! alias onto it); a step input gives the closed-form step response exactly.
//!
//! The deflection at the sample times comes from the integrator's steps (the cubic
//! Hermite interpolant of each accepted step) and the closed-form free flight (its
//! phasors rotated from sample to sample). Per sample the lock-in costs a few tens of
//! multiplications and no transcendental function.

use crate::dynamics::free::FreeFlight;
use crate::dynamics::model::X;
use crate::dynamics::numeric::{StepEnd, StepObserver, hermite};
use crate::error::{Error, Result};
use crate::physics::law::Branch;

/// The highest filter order.
pub const MAX_ORDER: usize = 4;

/// Samples per drive period (a power of two: the sample clock divides the period
/// exactly).
pub const SAMPLES_PER_PERIOD: usize = 64;

/// A lock-in amplifier referenced to the drive: its sample clock, its filter state for
/// the in-phase and the quadrature channel, and the propagation weights.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LockIn {
    order: usize,
    /// Filter time constant T in units of 1/ω₀.
    time_constant: f64,
    /// Reference frequency Ω = ω/ω₀.
    omega: f64,
    /// Sample interval h = 2π/(ΩS).
    interval: f64,
    /// Stage outputs of the in-phase (x cos) and quadrature (x sin) channels.
    in_phase: [f64; MAX_ORDER],
    quadrature: [f64; MAX_ORDER],
    /// e^{−r} r^j/j!, j < n: the filter's own decay over one interval.
    decay: [f64; MAX_ORDER],
    /// Weights of the interval's first and last input sample in each stage.
    weight_prev: [f64; MAX_ORDER],
    weight_next: [f64; MAX_ORDER],
    /// cos and sin of 2πk/S.
    reference: [(f64, f64); SAMPLES_PER_PERIOD],
    /// The last mixer output (none before the first sample).
    last_input: Option<(f64, f64)>,
    /// The index of the next sample in the observed τ's frame and the end of the last
    /// step observed (to follow the marcher's rewinds of τ by whole periods).
    next: i64,
    seen_until: Option<f64>,
    /// How many modes' deflections it demodulates the sum of (the deflection x = Σqᵢ, at
    /// state indices 0, 2, 4, …: the signal an instrument's lock-in sees).
    deflections: usize,
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
        let interval = 2.0 * std::f64::consts::PI / (omega * SAMPLES_PER_PERIOD as f64);
        let r = interval / time_constant_hat;
        let (mut decay, mut weight_prev, mut weight_next) =
            ([0.0; MAX_ORDER], [0.0; MAX_ORDER], [0.0; MAX_ORDER]);
        let mut term = (-r).exp();
        for k in 1..=MAX_ORDER {
            decay[k - 1] = term;
            term *= r / k as f64;
            let shifted = k as f64 / r * incomplete_gamma(k + 1, r);
            weight_prev[k - 1] = shifted;
            weight_next[k - 1] = incomplete_gamma(k, r) - shifted;
        }
        let reference = std::array::from_fn(|k| {
            let (s, c) =
                (2.0 * std::f64::consts::PI * k as f64 / SAMPLES_PER_PERIOD as f64).sin_cos();
            (c, s)
        });
        Ok(Self {
            order,
            time_constant: time_constant_hat,
            omega,
            interval,
            in_phase: [0.0; MAX_ORDER],
            quadrature: [0.0; MAX_ORDER],
            decay,
            weight_prev,
            weight_next,
            reference,
            last_input: None,
            next: 0,
            seen_until: None,
            deflections: 1,
        })
    }

    /// The lock-in reading the cantilever's deflection as the sum of the first `modes`
    /// eigenmodes' deflections Σqᵢ ([`crate::dynamics::modes`]): what an instrument's
    /// lock-in sees, each mode's at its own reference frequency.
    pub fn summing(self, modes: usize) -> Self {
        Self {
            deflections: modes.max(1),
            ..self
        }
    }

    /// The filter order n.
    pub fn order(&self) -> usize {
        self.order
    }

    /// The filter time constant T·ω₀.
    pub fn time_constant_hat(&self) -> f64 {
        self.time_constant
    }

    /// The sample interval in τ: a drive period over [`SAMPLES_PER_PERIOD`].
    pub fn sample_interval_hat(&self) -> f64 {
        self.interval
    }

    /// The filtered (in-phase, quadrature) pair: (A cos φ, A sin φ) once settled.
    pub fn output(&self) -> (f64, f64) {
        (
            self.in_phase[self.order - 1],
            self.quadrature[self.order - 1],
        )
    }

    /// Its state: the filter stages of both channels and the last mixer output (zero
    /// before the first), what the next samples are filtered from.
    pub fn state(&self) -> impl Iterator<Item = f64> + '_ {
        let (i, q) = self.last_input.unwrap_or((0.0, 0.0));
        self.in_phase[..self.order]
            .iter()
            .chain(&self.quadrature[..self.order])
            .copied()
            .chain([i, q])
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

    /// Feed one sample of the mixer output (in-phase, quadrature), one sample interval
    /// after the previous one; the first sample only starts the clock.
    pub fn feed(&mut self, (i_next, q_next): (f64, f64)) {
        let Some((i_prev, q_prev)) = self.last_input.replace((i_next, q_next)) else {
            return;
        };
        let (old_i, old_q) = (self.in_phase, self.quadrature);
        for k in 0..self.order {
            let mut i = self.weight_prev[k] * i_prev + self.weight_next[k] * i_next;
            let mut q = self.weight_prev[k] * q_prev + self.weight_next[k] * q_next;
            for j in 0..=k {
                i += self.decay[j] * old_i[k - j];
                q += self.decay[j] * old_q[k - j];
            }
            self.in_phase[k] = i;
            self.quadrature[k] = q;
        }
    }

    /// Mix deflection `x` sampled at the sample of index `k` and feed it.
    #[inline]
    fn sample(&mut self, k: i64, x: f64) {
        let (c, s) = self.reference[k.rem_euclid(SAMPLES_PER_PERIOD as i64) as usize];
        self.feed((2.0 * x * c, 2.0 * x * s));
    }

    /// The indices of the samples in (a, b] (in [a, b] for the first span observed), the
    /// clock moved by whole periods where the marcher moved τ back.
    #[doc(hidden)]
    pub fn samples_in(&mut self, a: f64, b: f64) -> std::ops::Range<i64> {
        let per_period = SAMPLES_PER_PERIOD as i64;
        let first = match self.seen_until {
            Some(until) if (a - until).abs() <= 0.5 * self.interval => self.next,
            // τ moved back (or on) by whole drive periods: the same instant of the drive.
            Some(until) => {
                let periods = ((until - a) * self.omega / (2.0 * std::f64::consts::PI)).round();
                if (a - until + periods * self.interval * per_period as f64).abs()
                    <= 0.5 * self.interval
                {
                    self.next - periods as i64 * per_period
                } else {
                    (a / self.interval).ceil() as i64
                }
            }
            None => (a / self.interval).ceil() as i64,
        };
        let last = (b / self.interval).floor() as i64;
        self.seen_until = Some(b);
        self.next = first.max(last + 1);
        first..last + 1
    }
}

/// P(k, r) = e^{−r} Σ_{j≥k} r^j/j!, the regularised lower incomplete gamma function of
/// integer order k (by its series: no cancellation for small r). For the sample intervals
/// of a lock-in, r ≤ a few.
#[doc(hidden)]
pub fn incomplete_gamma(k: usize, r: f64) -> f64 {
    let mut term = (-r).exp();
    for j in 1..=k {
        term *= r / j as f64;
    }
    let (mut sum, mut j) = (0.0, k);
    while term > 1e-18 * sum || sum == 0.0 {
        sum += term;
        j += 1;
        term *= r / j as f64;
        if j > k + 500 {
            break;
        }
    }
    sum
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
        for k in self.samples_in(a.tau, b.tau) {
            let tau = k as f64 * self.interval;
            let x = (0..self.deflections)
                .map(|j| hermite(a, b, X.index() + 2 * j, tau))
                .sum();
            self.sample(k, x);
        }
    }

    fn free_flight(&mut self, flight: &FreeFlight, from: f64, to: f64) {
        let samples = self.samples_in(from, to);
        let first = samples.start as f64 * self.interval;
        for (k, (x, _)) in samples.zip(flight.samples(first, self.interval)) {
            self.sample(k, x);
        }
    }
}

/// Several lock-ins watching one integration (one per eigenmode, each reading the
/// deflection, the sum of the modes, at its mode's drive frequency: [`LockIn::summing`]).
pub struct LockIns<'a>(pub &'a mut [LockIn]);

impl StepObserver for LockIns<'_> {
    fn step<const N: usize>(&mut self, a: &StepEnd<N>, b: &StepEnd<N>, branch: Branch) {
        for l in self.0.iter_mut() {
            l.step(a, b, branch);
        }
    }
}
