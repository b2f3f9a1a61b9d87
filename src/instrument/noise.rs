//! Thermal noise through the lock-in: how much the demodulated amplitude and phase of a
//! tapping (or free) cantilever fluctuate under the thermal force
//! ([`super::thermal`]) at a given filter order and time constant — two ways.
//!
//! **Linear theory** ([`linear_noise`]). Around a stable periodic orbit the thermal
//! force ξ (white, intensity D̂) moves the state by δz, which obeys the variational
//! equations with ξ entering the velocity: δz' = A(τ)δz + e₂ξ, with the saltation
//! matrices at the switches. Sampled once a drive period, δz_{k+1} = Mδz_k + w_k (M the
//! monodromy matrix), and the period's Fourier projections (sc, ss) — what the lock-in
//! averages — move by δp_k = Cδz_k + v_k. With Φ(s) = ∂z(s)/∂z(0) along the orbit and
//! G(s) = ∫₀ˢ (cos Ωu, sin Ωu)ᵀ Φ_x(u) du (Φ_x: the deflection's row),
//! C = G(T), and an impulse of force at s moves z(T) by MΦ(s)⁻¹e₂ and p by
//! (G(T) − G(s))Φ(s)⁻¹e₂, so (w_k, v_k) are Gaussian with covariance
//! D̂∫₀ᵀ r(s)r(s)ᵀds, r = (MΦ(s)⁻¹e₂, (G(T) − G(s))Φ(s)⁻¹e₂), independent from period to
//! period. Φ comes from the exact period map's derivative over K parts of the period
//! ([`crate::dynamics::march::Simulation::advance_with_derivative`]); the integrals are
//! trapezoids on those parts. The lock-in's filter (n RC stages of time constant T_f) is
//! fed the period average (2/T)(sc, ss) held over each period, propagated exactly
//! period to period; the stationary covariance of the orbit's deviation and the
//! filter's states solves a discrete Lyapunov equation, and δA, δφ follow from the
//! filter outputs (X, Y) = (A cos φ, A sin φ) to first order. Valid while the filter
//! is slow against a period (T_f ≫ T) and the noise small against the distance to the
//! nearest switch level (no grazing).
//!
//! **Monte Carlo** ([`monte_carlo_noise`]): the marcher under the thermal force, watched
//! by the lock-in itself, its outputs read at windows far apart.

use super::lockin::{LockIn, step_response};
use super::thermal::ThermalForce;
use crate::dynamics::march::{Phase, Simulation};
use crate::dynamics::setup::{Numerics, Prepared, TapSetup};
use crate::error::{Error, Result};
use crate::numeric::mean_and_variance;
use crate::physics::law::ForceLaw;
use nalgebra::DMatrix;

/// Parts of a drive period the linear theory samples the orbit's Φ at unless told
/// otherwise.
pub const PARTS_PER_PERIOD: usize = 256;

/// The equivalent noise bandwidth of an n-stage RC filter of time constant
/// `time_constant_s`, in Hz: 1/(4T), 1/(8T), 3/(32T), 5/(64T) for n = 1…4
/// (∫₀^∞ |H(f)|² df, H = (1 + 2πifT)⁻ⁿ).
pub fn enbw_hz(order: usize, time_constant_s: f64) -> f64 {
    enbw_factor(order) / time_constant_s
}

/// The time constant giving an n-stage filter the bandwidth `enbw_hz`, s.
pub fn time_constant_for_enbw(order: usize, enbw_hz: f64) -> f64 {
    enbw_factor(order) / enbw_hz
}

/// ENBW·T of an n-stage RC filter: Γ(n − ½)/(4√π Γ(n)).
fn enbw_factor(order: usize) -> f64 {
    match order {
        1 => 1.0 / 4.0,
        2 => 1.0 / 8.0,
        3 => 3.0 / 32.0,
        _ => 5.0 / 64.0,
    }
}

/// What the lock-in reads of an orbit and how much it fluctuates (dimensionless
/// amplitudes, in units of L; phases in rad, `tap`'s convention).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct LockInNoise {
    /// The orbit's amplitude A.
    pub amplitude_hat: f64,
    /// The orbit's phase φ.
    pub phase_rad: f64,
    /// Standard deviation of the demodulated amplitude.
    pub sigma_amplitude_hat: f64,
    /// Standard deviation of the demodulated phase.
    pub sigma_phase_rad: f64,
}

/// The linear theory's noise on the demodulated amplitude and phase of the stable
/// periodic orbit through `phase` (any point of it; period 1), under a thermal force of
/// intensity D̂ = `intensity_hat`, read by a lock-in of filter order `order` and time
/// constant `time_constant_hat` (T_f·ω₀), Φ sampled at `parts` parts of the period.
pub fn linear_noise<L: ForceLaw>(
    sim: &Simulation<'_, L>,
    phase: &Phase,
    intensity_hat: f64,
    (order, time_constant_hat): (usize, f64),
    parts: usize,
) -> Result<LockInNoise> {
    if !(1..=super::lockin::MAX_ORDER).contains(&order) {
        return Err(Error::NotApplicable(format!(
            "a lock-in filter has order 1 to 4, not {order}"
        )));
    }
    crate::error::positive("lock-in time constant", time_constant_hat)?;
    if !(16..=1 << 16).contains(&parts) {
        return Err(Error::NotApplicable(format!(
            "the linear theory samples 16 to 65536 parts of a period, not {parts}"
        )));
    }
    let period = sim.osc.period();
    let h = period / parts as f64;
    let d = sim.section_dim();
    let omega = sim.osc.omega;
    let mut at = phase.clone();
    let tau0 = at.tau;
    // Φ(s_j) and G(s_j) on the grid s_j = j·h.
    let mut phi = vec![DMatrix::<f64>::identity(d, d)];
    let mut g = vec![DMatrix::<f64>::zeros(2, d)];
    let reference = |s: f64| ((omega * (tau0 + s)).cos(), (omega * (tau0 + s)).sin());
    let (mut sc, mut ss) = (0.0, 0.0);
    for j in 1..=parts {
        let span = if j == parts {
            tau0 + period - at.tau
        } else {
            h
        };
        let (integrals, derivative) = sim.advance_with_derivative(&mut at, span)?;
        sc += integrals.sc;
        ss += integrals.ss;
        let step = derivative.columns(0, d).into_owned();
        let next = &step * &phi[j - 1];
        let mut gj = g[j - 1].clone();
        let (c0, s0) = reference((j - 1) as f64 * h);
        let (c1, s1) = reference(j as f64 * h);
        for col in 0..d {
            gj[(0, col)] += 0.5 * h * (c0 * phi[j - 1][(0, col)] + c1 * next[(0, col)]);
            gj[(1, col)] += 0.5 * h * (s0 * phi[j - 1][(0, col)] + s1 * next[(0, col)]);
        }
        phi.push(next);
        g.push(gj);
    }
    let monodromy = phi[parts].clone();
    if let Some(m) = monodromy
        .clone()
        .complex_eigenvalues()
        .iter()
        .map(|e| e.norm())
        .reduce(f64::max)
        && m >= 1.0
    {
        return Err(Error::NotApplicable(format!(
            "the orbit is not stable (largest Floquet multiplier {m:.4}): the linear noise \
             theory needs a stable periodic orbit"
        )));
    }
    let c = g[parts].clone();
    // Σ = D̂ ∫ r rᵀ ds, r = (MΦ(s)⁻¹e₂, (G(T) − G(s))Φ(s)⁻¹e₂) (d + 2 components).
    let r = |j: usize| -> Result<DMatrix<f64>> {
        let inv = phi[j].clone().try_inverse().ok_or_else(|| {
            Error::Numerical("the orbit's Φ is singular: its noise cannot be followed".into())
        })?;
        let kick = inv.column(1).into_owned();
        let mut out = DMatrix::zeros(d + 2, 1);
        out.view_mut((0, 0), (d, 1))
            .copy_from(&(&monodromy * &kick));
        out.view_mut((d, 0), (2, 1))
            .copy_from(&((&c - &g[j]) * &kick));
        Ok(out)
    };
    let mut sigma = DMatrix::<f64>::zeros(d + 2, d + 2);
    for j in 0..=parts {
        let rj = r(j)?;
        let w = if j == 0 || j == parts { 0.5 * h } else { h };
        sigma += &rj * rj.transpose() * (w * intensity_hat);
    }
    // The filter over one period with the input held: stage k (0-based) decays as
    // e^{−ρ}ρ^i/i! from stage k − i, and takes P(k + 1, ρ) of the input, ρ = T/T_f.
    let rho = period / time_constant_hat;
    let mut f = DMatrix::<f64>::zeros(order, order);
    let mut term = (-rho).exp();
    for i in 0..order {
        for k in i..order {
            f[(k, k - i)] = term;
        }
        term *= rho / (i + 1) as f64;
    }
    let gain: Vec<f64> = (0..order)
        .map(|k| step_response(k + 1, rho) * 2.0 / period)
        .collect();
    // ζ = (δz, X stages, Y stages).
    let dim = d + 2 * order;
    let mut a = DMatrix::<f64>::zeros(dim, dim);
    let mut b = DMatrix::<f64>::zeros(dim, d + 2);
    a.view_mut((0, 0), (d, d)).copy_from(&monodromy);
    for i in 0..d {
        b[(i, i)] = 1.0;
    }
    for (channel, first) in [(0, d), (1, d + order)] {
        a.view_mut((first, first), (order, order)).copy_from(&f);
        for k in 0..order {
            for col in 0..d {
                a[(first + k, col)] = gain[k] * c[(channel, col)];
            }
            b[(first + k, d + channel)] = gain[k];
        }
    }
    let q = &b * &sigma * b.transpose();
    let p = discrete_lyapunov(&a, &q)?;
    let (x, y) = (2.0 * sc / period, 2.0 * ss / period);
    let amplitude = x.hypot(y);
    let (ix, iy) = (d + order - 1, d + 2 * order - 1);
    let var = |gx: f64, gy: f64| {
        gx * gx * p[(ix, ix)] + 2.0 * gx * gy * p[(ix, iy)] + gy * gy * p[(iy, iy)]
    };
    Ok(LockInNoise {
        amplitude_hat: amplitude,
        phase_rad: y.atan2(x),
        sigma_amplitude_hat: var(x / amplitude, y / amplitude).max(0.0).sqrt(),
        sigma_phase_rad: var(-y / (amplitude * amplitude), x / (amplitude * amplitude))
            .max(0.0)
            .sqrt(),
    })
}

/// The stationary covariance P = APAᵀ + Q of ζ_{k+1} = Aζ_k + ν_k (Cov ν = Q), A's
/// eigenvalues inside the unit circle: vec(P) = (I − A⊗A)⁻¹vec(Q).
fn discrete_lyapunov(a: &DMatrix<f64>, q: &DMatrix<f64>) -> Result<DMatrix<f64>> {
    let n = a.nrows();
    let kron = a.kronecker(a);
    let lhs = DMatrix::<f64>::identity(n * n, n * n) - kron;
    let rhs = nalgebra::DVector::from_column_slice(q.as_slice());
    let vec = lhs
        .lu()
        .solve(&rhs)
        .ok_or_else(|| Error::Numerical("the noise covariance has no stationary state".into()))?;
    let p = DMatrix::from_column_slice(n, n, vec.as_slice());
    Ok((&p + p.transpose()) * 0.5)
}

/// The Monte Carlo's noise: the spread of the lock-in's outputs over windows.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SampledNoise {
    /// Mean demodulated amplitude (units of L).
    pub amplitude_hat: f64,
    /// Mean demodulated phase, rad.
    pub phase_rad: f64,
    /// Standard deviation of the amplitude over the windows.
    pub sigma_amplitude_hat: f64,
    /// Standard deviation of the phase over the windows.
    pub sigma_phase_rad: f64,
    /// Windows read.
    pub windows: usize,
}

/// The lock-in `lockin` watching the marcher under the thermal force (intensity D̂ =
/// `intensity_hat`, `steps` a period) from `phase`, on `streams` independent streams of
/// `seed` (run in parallel; the same result on any thread count): on each, `settle`
/// drive periods to let the filter and the motion reach their noisy steady state,
/// then `windows / streams` readings of the filter's outputs `spacing` periods apart,
/// all pooled.
pub fn monte_carlo_noise<L: ForceLaw + Sync>(
    sim: &Simulation<'_, L>,
    phase: &Phase,
    (intensity_hat, steps): (f64, usize),
    lockin: LockIn,
    (settle, windows, spacing): (usize, usize, usize),
    (seed, streams): (u64, usize),
) -> Result<SampledNoise> {
    use rayon::prelude::*;
    if streams == 0 || windows < 2 * streams || spacing == 0 {
        return Err(Error::NotApplicable(
            "a Monte Carlo reads at least two windows a stream, at least a period apart".into(),
        ));
    }
    let per_stream = windows / streams;
    let reads: Vec<Vec<(f64, f64)>> = (0..streams)
        .into_par_iter()
        .map(|stream| -> Result<Vec<(f64, f64)>> {
            let mut force = ThermalForce::new(intensity_hat, steps, seed, stream as u64)?;
            let (mut at, mut lockin) = (phase.clone(), lockin);
            force.march(sim, &mut at, settle, &mut lockin)?;
            let mut out = Vec::with_capacity(per_stream);
            for _ in 0..per_stream {
                force.march(sim, &mut at, spacing, &mut lockin)?;
                out.push(lockin.output());
            }
            Ok(out)
        })
        .collect::<Result<_>>()?;
    let reads: Vec<(f64, f64)> = reads.into_iter().flatten().collect();
    let n = reads.len() as f64;
    let (mx, my) = reads
        .iter()
        .fold((0.0, 0.0), |(a, b), r| (a + r.0 / n, b + r.1 / n));
    let amplitude = mx.hypot(my);
    let centre = my.atan2(mx);
    let amps: Vec<f64> = reads.iter().map(|r| r.0.hypot(r.1)).collect();
    // Phases unwrapped about the mean's.
    let phases: Vec<f64> = reads
        .iter()
        .map(|r| {
            let p = r.1.atan2(r.0) - centre;
            (p + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI
        })
        .collect();
    let sd = |v: &[f64]| mean_and_variance(v.iter().copied()).1.sqrt();
    Ok(SampledNoise {
        amplitude_hat: amplitude,
        phase_rad: centre,
        sigma_amplitude_hat: sd(&amps),
        sigma_phase_rad: sd(&phases),
        windows: reads.len(),
    })
}

/// What thermal noise to read, and through what lock-in: the temperature, the filter's
/// order and its equivalent noise bandwidth.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct NoiseRequest {
    /// Temperature, K.
    pub temperature_k: f64,
    /// The lock-in's filter order (1–4).
    pub lockin_order: usize,
    /// Its equivalent noise bandwidth, Hz.
    pub enbw_hz: f64,
}

impl NoiseRequest {
    /// Refuse a negative temperature, an order outside 1–4, and a bandwidth above a
    /// thirtieth of the drive frequency `drive_hz` (the linear theory feeds the filter
    /// period averages: its time constant must span periods — two at 10 kHz on 300 kHz,
    /// fourth order, where the theory still equals a free cantilever's spectrum to 1e-4).
    pub fn check(&self, drive_hz: f64) -> Result<()> {
        super::thermal::check_temperature(self.temperature_k)?;
        if !(1..=super::lockin::MAX_ORDER).contains(&self.lockin_order) {
            return Err(Error::OutOfRange(format!(
                "a lock-in filter has order 1 to 4, not {}",
                self.lockin_order
            )));
        }
        crate::error::positive("lock-in bandwidth (ENBW)", self.enbw_hz)?;
        if self.enbw_hz > drive_hz / 30.0 {
            return Err(Error::OutOfRange(format!(
                "the lock-in's bandwidth ({} Hz) is at most a thirtieth of the drive \
                 frequency ({drive_hz} Hz): the linear theory takes its filter to average \
                 over periods",
                self.enbw_hz
            )));
        }
        Ok(())
    }

    /// The lock-in's time constant, s.
    pub fn time_constant_s(&self) -> f64 {
        time_constant_for_enbw(self.lockin_order, self.enbw_hz)
    }

    /// [`linear_noise`] in SI units on the stable period-1 orbit of `sim` through
    /// `phase`, the simulation of `prepared` (its cantilever).
    pub fn on_orbit<L: ForceLaw>(
        &self,
        prepared: &Prepared,
        sim: &Simulation<'_, L>,
        phase: &Phase,
    ) -> Result<ThermalNoise> {
        let c = prepared.setup.cantilever;
        self.check(c.drive_frequency_hz)?;
        let a0 = c.free_amplitude_m;
        let noise = linear_noise(
            sim,
            phase,
            super::thermal::intensity_hat(self.temperature_k, c.stiffness_n_m, c.quality, a0),
            (
                self.lockin_order,
                self.time_constant_s() * 2.0 * std::f64::consts::PI * c.resonance_hz,
            ),
            PARTS_PER_PERIOD,
        )?;
        Ok(ThermalNoise {
            temperature_k: self.temperature_k,
            lockin_order: self.lockin_order,
            enbw_hz: self.enbw_hz,
            time_constant_s: self.time_constant_s(),
            sigma_amplitude_m: noise.sigma_amplitude_hat * a0,
            sigma_phase_deg: noise.sigma_phase_rad.to_degrees(),
        })
    }
}

/// The thermal noise a lock-in reads on a stable period-1 orbit: the linear theory's σ
/// of its amplitude and phase, in SI units.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ThermalNoise {
    /// Temperature, K.
    pub temperature_k: f64,
    /// The lock-in's filter order.
    pub lockin_order: usize,
    /// Its equivalent noise bandwidth, Hz.
    pub enbw_hz: f64,
    /// Its time constant, s.
    pub time_constant_s: f64,
    /// Standard deviation of the demodulated amplitude, m.
    pub sigma_amplitude_m: f64,
    /// Standard deviation of the demodulated phase, degrees.
    pub sigma_phase_deg: f64,
}

/// [`NoiseRequest::on_orbit`] on the steady state `setup` settles on from the free
/// oscillation. `None` where that state is not a stable period-1 orbit (the linear
/// theory needs one).
pub fn thermal_noise_at(
    setup: &TapSetup,
    numerics: &Numerics,
    request: &NoiseRequest,
) -> Result<Option<ThermalNoise>> {
    let p = Prepared::new(setup, numerics)?;
    request.check(p.setup.cantilever.drive_frequency_hz)?;
    let sim = p.simulation();
    let mut phase = sim.free_steady_start();
    let state = sim.steady_state(&mut phase, &p.steady)?;
    if state.motion.period() != Some(1) || state.motion.stable() != Some(true) {
        return Ok(None);
    }
    request.on_orbit(&p, &sim, &phase).map(Some)
}
