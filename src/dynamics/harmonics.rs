//! Higher harmonics of a steady orbit: amplitude and phase of harmonics 2…10 of the
//! deflection and of the tip–sample force, as an observer of the integration.
//!
//! Over whole drive periods the n-th Fourier coefficient of a signal s(τ) is
//! S_n = (2/T)∫ s e^{−inΩτ} dτ, so that s ≈ s̄ + Σ |S_n| cos(nΩτ − φ_n), φ_n = −arg S_n
//! (for n = 1 the lock-in amplitude and phase). Each accepted step is integrated by
//! 8-point Gauss–Legendre quadrature on the quintic Hermite interpolant of the deflection (its
//! value, velocity and acceleration at both step ends), the force taken from the law at
//! the interpolated separation; a closed-form free flight is sampled from its exact
//! motion. The two sets of coefficients are computed independently, so the equation of
//! motion checks them: for n ≥ 2 (no drive there) X_n = F_n/(1 − n²Ω² + 2iγnΩ).

use super::free::FreeFlight;
use super::model::{Coupling, Oscillator, V, X};
use super::numeric::{StepEnd, StepObserver};
use crate::numeric::GAUSS_LEGENDRE_8;
use crate::physics::law::{Branch, ForceLaw};
use nalgebra::Complex;
use serde::Serialize;

/// The highest harmonic observed.
pub const HIGHEST_HARMONIC: usize = 10;

/// Longest stretch of closed-form free flight integrated by one Gauss–Legendre rule, as a
/// fraction of the drive period (the 10th harmonic turns through a quarter of a cycle
/// over it).
const FREE_PIECES_PER_PERIOD: f64 = 40.0;

/// The value at step fraction t of the quintic Hermite interpolant with values p₀, p₁,
/// first derivatives m₀, m₁ and second derivatives c₀, c₁ at t = 0 and 1 (derivatives
/// with respect to t), and its derivative there.
#[inline]
#[doc(hidden)]
pub fn quintic_hermite(
    t: f64,
    (p0, m0, c0): (f64, f64, f64),
    (p1, m1, c1): (f64, f64, f64),
) -> (f64, f64) {
    let (t2, t3) = (t * t, t * t * t);
    let (t4, t5) = (t3 * t, t3 * t2);
    let value = p0 * (1.0 - 10.0 * t3 + 15.0 * t4 - 6.0 * t5)
        + m0 * (t - 6.0 * t3 + 8.0 * t4 - 3.0 * t5)
        + c0 * 0.5 * (t2 - 3.0 * t3 + 3.0 * t4 - t5)
        + c1 * 0.5 * (t3 - 2.0 * t4 + t5)
        + m1 * (-4.0 * t3 + 7.0 * t4 - 3.0 * t5)
        + p1 * (10.0 * t3 - 15.0 * t4 + 6.0 * t5);
    let slope = p0 * (-30.0 * t2 + 60.0 * t3 - 30.0 * t4)
        + m0 * (1.0 - 18.0 * t2 + 32.0 * t3 - 15.0 * t4)
        + c0 * 0.5 * (2.0 * t - 9.0 * t2 + 12.0 * t3 - 5.0 * t4)
        + c1 * 0.5 * (3.0 * t2 - 8.0 * t3 + 5.0 * t4)
        + m1 * (-12.0 * t2 + 28.0 * t3 - 15.0 * t4)
        + p1 * (30.0 * t2 - 60.0 * t3 + 30.0 * t4);
    (value, slope)
}

/// Accumulates ∫ x e^{−inΩτ} dτ and ∫ f_ts e^{−inΩτ} dτ for n = 1…[`HIGHEST_HARMONIC`]
/// over everything it observes.
pub struct HarmonicsObserver<'a, L: ForceLaw> {
    law: &'a L,
    cpl: Coupling,
    osc: Oscillator,
    deflection: [Complex<f64>; HIGHEST_HARMONIC],
    force: [Complex<f64>; HIGHEST_HARMONIC],
    span: f64,
}

impl<'a, L: ForceLaw> HarmonicsObserver<'a, L> {
    /// Nothing observed yet, for the law and model of a simulation.
    pub fn new(law: &'a L, cpl: Coupling, osc: Oscillator) -> Self {
        Self {
            law,
            cpl,
            osc,
            deflection: [Complex::default(); HIGHEST_HARMONIC],
            force: [Complex::default(); HIGHEST_HARMONIC],
            span: 0.0,
        }
    }

    /// Add weight·(x, f)·e^{−inΩτ} for every n.
    #[inline]
    fn add(&mut self, tau: f64, weight: f64, x: f64, f: f64) {
        let (s, c) = (self.osc.omega * tau).sin_cos();
        let step = Complex::new(c, -s);
        let mut turn = step;
        for n in 0..HIGHEST_HARMONIC {
            self.deflection[n] += turn * (weight * x);
            self.force[n] += turn * (weight * f);
            turn *= step;
        }
    }

    /// The coefficients X_n and F_n (units of L and kL) over the time observed, which
    /// must be whole drive periods of a periodic orbit.
    pub fn finish(&self) -> HarmonicCoefficients {
        let scale = 2.0 / self.span;
        HarmonicCoefficients {
            deflection: self.deflection.map(|z| z * scale),
            force: self.force.map(|z| z * scale),
        }
    }
}

impl<L: ForceLaw> StepObserver for HarmonicsObserver<'_, L> {
    fn step<const N: usize>(&mut self, from: &StepEnd<N>, to: &StepEnd<N>, branch: Branch) {
        let h = to.tau - from.tau;
        if h <= 0.0 {
            return;
        }
        let end = |e: &StepEnd<N>| (e.y[X], h * e.y[V], h * h * e.dy[V]);
        let (start, finish) = (end(from), end(to));
        for (x, w) in GAUSS_LEGENDRE_8 {
            // The rule on [−1, 1], mapped to the step fraction t ∈ [0, 1].
            let (t, w) = (0.5 * (1.0 + x), 0.5 * w);
            let tau = from.tau + t * h;
            let (x, dx_dt) = quintic_hermite(t, start, finish);
            let state = self
                .cpl
                .contact_state((x, dx_dt / h), self.osc.base_at(tau), branch);
            let f = -self.cpl.f_scale * self.law.force_hat(&state);
            self.add(tau, w * h, x, f);
        }
        self.span += h;
    }

    fn free_flight(&mut self, flight: &FreeFlight, from: f64, to: f64) {
        let pieces = ((to - from) / self.osc.period() * FREE_PIECES_PER_PERIOD)
            .ceil()
            .max(1.0);
        let h = (to - from) / pieces;
        for piece in 0..pieces as usize {
            let start = from + h * piece as f64;
            for (x, w) in GAUSS_LEGENDRE_8 {
                let (t, w) = (0.5 * (1.0 + x), 0.5 * w);
                let tau = start + t * h;
                // No force in free flight: it is only taken where the law has none.
                self.add(tau, w * h, flight.at(tau).0, 0.0);
            }
        }
        self.span += to - from;
    }
}

/// The Fourier coefficients of a periodic orbit's deflection and force, n = 1…10, in the
/// model's units (L and kL): index n − 1. For n ≥ 2 they obey X_n = F_n/(1 − n²Ω² +
/// 2iγnΩ) (the module's check).
#[derive(Debug, Clone, PartialEq)]
pub struct HarmonicCoefficients {
    /// X_n.
    pub deflection: [Complex<f64>; HIGHEST_HARMONIC],
    /// F_n.
    pub force: [Complex<f64>; HIGHEST_HARMONIC],
}

/// One harmonic of the deflection and the force, in SI units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Harmonic {
    /// n (the drive frequency times n).
    pub order: usize,
    /// Amplitude of the deflection's n-th harmonic in m.
    pub deflection_amplitude_m: f64,
    /// Its phase lag φ_n (z_n = A_n cos(nωt − φ_n)) in degrees, in (−180°, 180°].
    pub deflection_phase_deg: f64,
    /// Amplitude of the tip–sample force's n-th harmonic in N (repulsive positive).
    pub force_amplitude_n: f64,
    /// Its phase lag in degrees.
    pub force_phase_deg: f64,
}

impl Harmonic {
    /// Harmonics 2…[`HIGHEST_HARMONIC`] of `c` for a length unit of `length_m` and a
    /// force unit of `force_n`.
    pub fn list(c: &HarmonicCoefficients, length_m: f64, force_n: f64) -> Vec<Harmonic> {
        let lag = |z: Complex<f64>| -z.arg().to_degrees() + 0.0;
        (2..=HIGHEST_HARMONIC)
            .map(|n| Harmonic {
                order: n,
                deflection_amplitude_m: c.deflection[n - 1].norm() * length_m,
                deflection_phase_deg: lag(c.deflection[n - 1]),
                force_amplitude_n: c.force[n - 1].norm() * force_n,
                force_phase_deg: lag(c.force[n - 1]),
            })
            .collect()
    }
}
