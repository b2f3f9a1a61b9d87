//! The thermal force on the cantilever: a Langevin force of one-sided power spectral
//! density S_F = 4k_BT·k/(ω₀Q) (fluctuation–dissipation; in terms of the mass,
//! 4k_BT·mω₀/Q), held constant over steps of Δ = T/n (n steps a drive period) and
//! drawn afresh, Gaussian, for each.
//!
//! In the dimensionless equation of motion (τ = ω₀t, x in units of L, forces in units
//! of kL) the white force ξ has ⟨ξ(τ)ξ(τ')⟩ = D̂·δ(τ − τ'), D̂ = 2k_BT/(kL²Q), so that
//! the free oscillator holds ⟨x²⟩ = D̂Q/2 = k_BT/(kL²): equipartition. Held constant
//! over Δ, a step's force has variance D̂/Δ; its spectrum is the white one times
//! sinc²(πfΔ), so the free ⟨x²⟩ falls short of equipartition by about (πf₀Δ)²/3
//! (8e-4 at n = 64 and f = f₀; [`free_variance_hat`] gives it exactly). Within a step
//! the force is a constant the marcher integrates exactly (closed-form free flight,
//! located switches: [`crate::dynamics::march::Simulation::advance`]); a step of free
//! flight that cannot meet the contact or turn is taken from one precomputed transition
//! ([`crate::dynamics::free_steps`]; [`ThermalForce::exact`] locates every step).
//!
//! The forces are drawn from a ChaCha8 stream of a seed: the same seed and stream give
//! the same bytes on any machine and thread count.

use super::spectrum::{Calibration, Psd, Welch, calibrate};
use crate::dynamics::free::FreeFlight;
use crate::dynamics::free_steps::FreeSteps;
use crate::dynamics::grazing::BOLTZMANN_J_K;
use crate::dynamics::march::{CycleIntegrals, Phase, Simulation};
use crate::dynamics::model::{Drive, Oscillator};
use crate::dynamics::numeric::StepObserver;
use crate::error::{Error, Result};
use crate::physics::law::ForceLaw;
use nalgebra::{Matrix2, Matrix4, Vector2, Vector4};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// Force steps a drive period unless told otherwise.
pub const STEPS_PER_PERIOD: usize = 64;

/// The most force steps a drive period.
pub const MAX_STEPS_PER_PERIOD: usize = 4096;

/// Refuse a temperature that is negative or not finite.
pub fn check_temperature(temperature_k: f64) -> Result<()> {
    if temperature_k >= 0.0 && temperature_k.is_finite() {
        Ok(())
    } else {
        Err(Error::OutOfRange(format!(
            "a temperature is finite and not negative, not {temperature_k} K"
        )))
    }
}

/// D̂ = 2k_BT/(kL²Q): the intensity of the dimensionless thermal force,
/// ⟨ξ(τ)ξ(τ')⟩ = D̂δ(τ − τ') (from S_F = 4k_BT·k/(ω₀Q), Hutter & Bechhoefer, RSI 64,
/// 1868, 1993, with F = kLξ and t = τ/ω₀).
pub fn intensity_hat(temperature_k: f64, stiffness_n_m: f64, quality: f64, length_m: f64) -> f64 {
    2.0 * BOLTZMANN_J_K * temperature_k / (stiffness_n_m * length_m * length_m * quality)
}

/// The Langevin force: its intensity, its step and the random stream it is drawn from.
#[derive(Debug, Clone)]
pub struct ThermalForce {
    /// D̂ ([`intensity_hat`]).
    intensity_hat: f64,
    /// Force steps a drive period.
    steps_per_period: usize,
    /// The random stream.
    rng: ChaCha8Rng,
    /// Whether every step is marched as [`Simulation::advance`] marches it, none taken
    /// from [`FreeSteps`]' precomputed transition.
    exact: bool,
}

impl ThermalForce {
    /// A force of intensity D̂ = `intensity_hat` held over `steps_per_period` steps a
    /// drive period, drawn from stream `stream` of `seed`.
    pub fn new(
        intensity_hat: f64,
        steps_per_period: usize,
        seed: u64,
        stream: u64,
    ) -> Result<Self> {
        if !(intensity_hat >= 0.0 && intensity_hat.is_finite()) {
            return Err(Error::NotApplicable(format!(
                "the thermal force's intensity ({intensity_hat:e}) is finite and not negative"
            )));
        }
        if !(1..=MAX_STEPS_PER_PERIOD).contains(&steps_per_period) {
            return Err(Error::NotApplicable(format!(
                "the thermal force is held over 1 to {MAX_STEPS_PER_PERIOD} steps a drive \
                 period, not {steps_per_period}"
            )));
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(stream);
        Ok(Self {
            intensity_hat,
            steps_per_period,
            rng,
            exact: false,
        })
    }

    /// This force with every step marched as [`Simulation::advance`] marches it (the
    /// reference: by default a step in free flight that cannot meet the contact or turn
    /// is taken from [`FreeSteps`]' precomputed transition, the same motion to
    /// round-off, its observer reading the step's Hermite interpolant).
    pub fn exact(self) -> Self {
        Self {
            exact: true,
            ..self
        }
    }

    /// No force at all (D̂ = 0): a march under it is [`Simulation::march`]'s, bit for
    /// bit.
    pub fn none() -> Self {
        Self::new(0.0, STEPS_PER_PERIOD, 0, 0).expect("a zero force is valid")
    }

    /// D̂.
    pub fn intensity_hat(&self) -> f64 {
        self.intensity_hat
    }

    /// Force steps a drive period.
    pub fn steps_per_period(&self) -> usize {
        self.steps_per_period
    }

    /// The next step's force, in units of kL: Gaussian of variance D̂/Δ, Δ = `step`.
    pub fn draw(&mut self, step: f64) -> f64 {
        let n: f64 = StandardNormal.sample(&mut self.rng);
        n * (self.intensity_hat / step).sqrt()
    }

    /// March `periods` drive periods of `sim` from `phase` under this force, every step
    /// shown to `observer` (as [`Simulation::march`]); each period is cut into the
    /// force's steps, each integrated with its force held ([`Simulation::advance`], or
    /// [`FreeSteps`] where the step is free flight that cannot meet the contact or
    /// turn).
    /// Returns the integrals over the whole march and the work the thermal force did,
    /// Σ ξ_j·(x_{j+1} − x_j) (units of kL²). With D̂ = 0 the march is
    /// [`Simulation::march`]'s, bit for bit.
    pub fn march<L: ForceLaw, O: StepObserver>(
        &mut self,
        sim: &Simulation<'_, L>,
        phase: &mut Phase,
        periods: usize,
        observer: &mut O,
    ) -> Result<(Option<CycleIntegrals>, f64)> {
        if self.intensity_hat == 0.0 {
            let mut total: Option<CycleIntegrals> = None;
            for _ in 0..periods {
                sim.rewind(phase);
                let one = sim.cycle(phase, observer)?;
                total = Some(total.map_or(one, |t| t.then(&one)));
            }
            return Ok((total, 0.0));
        }
        let period = sim.osc.period();
        let step = period / self.steps_per_period as f64;
        let free_steps = (!self.exact).then(|| FreeSteps::new(sim, step)).flatten();
        let mut total: Option<CycleIntegrals> = None;
        let mut work = 0.0;
        for _ in 0..periods {
            sim.rewind(phase);
            let end = phase.tau + period;
            let mut this: Option<CycleIntegrals> = None;
            // The drive's phasor at each step's start (for the steps taken in closed
            // form), turned on step by step from the period's start.
            let mut phasor = (sim.osc.omega * phase.tau).sin_cos();
            for j in 0..self.steps_per_period {
                let force = self.draw(step);
                let last = j + 1 == self.steps_per_period;
                let span = if last { end - phase.tau } else { step };
                let x0 = phase.x;
                let fast = match &free_steps {
                    Some(steps) if !last => steps.advance(phase, phasor, force, observer)?,
                    _ => None,
                };
                let part = match fast {
                    Some(part) => part,
                    None => {
                        let held = Simulation {
                            osc: Oscillator {
                                bias: force,
                                ..sim.osc
                            },
                            ..*sim
                        };
                        held.advance(phase, span, observer)?
                    }
                };
                if let Some(steps) = &free_steps {
                    phasor = steps.turned(phasor);
                }
                work += force * (phase.x - x0);
                this = Some(this.map_or(part, |t| t.then(&part)));
            }
            let mut this = this.expect("at least one step a period");
            this.periods = 1;
            total = Some(total.map_or(this, |t| t.then(&this)));
        }
        Ok((total, work))
    }
}

/// The undriven, free cantilever (γ = 1/(2Q)) under a thermal force, stepped exactly:
/// over each force step Δ the free oscillator relaxes towards the held force,
/// z_{j+1} = M(Δ)(z_j − (ξ_j, 0)) + (ξ_j, 0). The same motion as the marcher's free
/// flight (`tests/thermal.rs` compares them), without its search for contact: what a
/// thermal spectrum is recorded from.
#[derive(Debug, Clone)]
pub struct FreeThermal {
    /// The transition over one step.
    transition: Matrix2<f64>,
    /// The step Δ, in τ.
    step: f64,
    /// (x, x').
    z: Vector2<f64>,
}

impl FreeThermal {
    /// At rest, quality factor `quality`, force steps of `step` (τ).
    pub fn new(quality: f64, step: f64) -> Self {
        Self {
            transition: free_transition(quality, step),
            step,
            z: Vector2::zeros(),
        }
    }

    /// The deflection after every `every`-th of the next `samples × every` steps
    /// under `force`.
    pub fn record(&mut self, samples: usize, every: usize, force: &mut ThermalForce) -> Vec<f64> {
        let mut out = Vec::with_capacity(samples);
        for _ in 0..samples {
            for _ in 0..every.max(1) {
                let xi = Vector2::new(force.draw(self.step), 0.0);
                self.z = self.transition * (self.z - xi) + xi;
            }
            out.push(self.z[0]);
        }
        out
    }
}

/// What [`thermal_spectrum`] records and fits.
#[derive(Debug, Clone)]
pub struct ThermalSpectrum {
    /// Welch's estimate of the deflection's PSD (m²/Hz).
    pub psd: Psd,
    /// The SHO fit and the spring constant it calibrates.
    pub calibration: Calibration,
    /// The record's rms deflection, m.
    pub rms_m: f64,
    /// Resonance periods recorded.
    pub periods: usize,
    /// Samples recorded a resonance period.
    pub samples_per_period: usize,
}

/// Samples of the deflection recorded a resonance period by [`thermal_spectrum`]
/// (Nyquist at 4f₀; the resonance's tail beyond is below 1e-7 of its peak at Q ≥ 10).
pub const SAMPLES_PER_PERIOD: usize = 8;

/// The largest quality factor whose thermal spectrum is recorded: the Welch segment that
/// resolves the resonance (16 bins a linewidth) grows with Q.
pub const MAX_THERMAL_QUALITY: f64 = 1e4;

/// Welch segment resolving a resonance of quality `quality` with 16 bins a linewidth.
pub fn thermal_segment(quality: f64) -> usize {
    ((16.0 * quality * SAMPLES_PER_PERIOD as f64).ceil() as usize).next_power_of_two()
}

/// The thermal calibration of a free, undriven cantilever (`stiffness_n_m`,
/// `resonance_hz`, `quality`) at `temperature_k`: `periods` resonance periods of its
/// motion under the thermal force (`steps` force steps a period, stream 0 of `seed`,
/// [`FreeThermal`]), recorded [`SAMPLES_PER_PERIOD`] times a period, Welch's estimate of
/// their PSD ([`thermal_segment`]) and the SHO fit to it (Hutter & Bechhoefer, RSI 64,
/// 1868, 1993: f₀, Q and k = k_BT/⟨z²⟩). `progress` is told the periods recorded.
pub fn thermal_spectrum(
    (stiffness_n_m, resonance_hz, quality): (f64, f64, f64),
    temperature_k: f64,
    (periods, steps): (usize, usize),
    seed: u64,
    mut progress: impl FnMut(usize),
) -> Result<ThermalSpectrum> {
    crate::error::positive("stiffness", stiffness_n_m)?;
    crate::error::positive("resonance frequency", resonance_hz)?;
    crate::error::positive("temperature", temperature_k)?;
    if !(10.0..=MAX_THERMAL_QUALITY).contains(&quality) {
        return Err(Error::OutOfRange(format!(
            "a thermal spectrum is recorded for Q from 10 to {MAX_THERMAL_QUALITY:e} (its \
             resonance resolved by segments that fit in memory), not {quality}"
        )));
    }
    if steps % SAMPLES_PER_PERIOD != 0
        || !(SAMPLES_PER_PERIOD..=MAX_STEPS_PER_PERIOD).contains(&steps)
    {
        return Err(Error::OutOfRange(format!(
            "the thermal force's steps a period are a multiple of {SAMPLES_PER_PERIOD} from \
             {SAMPLES_PER_PERIOD} to {MAX_STEPS_PER_PERIOD} (the record takes every \
             {SAMPLES_PER_PERIOD}th of a period), not {steps}"
        )));
    }
    let segment = thermal_segment(quality);
    let needed = 8 * segment / SAMPLES_PER_PERIOD / 2;
    if !(needed..=MAX_RECORD_PERIODS).contains(&periods) {
        return Err(Error::OutOfRange(format!(
            "a thermal record of Q = {quality} spans {needed} to {MAX_RECORD_PERIODS} \
             resonance periods (at least 8 Welch segments of {} periods, half overlapping), \
             not {periods}",
            segment / SAMPLES_PER_PERIOD
        )));
    }
    // Lengths in units of the equipartition rms, so that x is of order one.
    let length_m = (BOLTZMANN_J_K * temperature_k / stiffness_n_m).sqrt();
    let mut force = ThermalForce::new(
        intensity_hat(temperature_k, stiffness_n_m, quality, length_m),
        steps,
        seed,
        0,
    )?;
    let rate_hz = resonance_hz * SAMPLES_PER_PERIOD as f64;
    let mut welch = Welch::new(rate_hz, segment)?;
    let mut motion = FreeThermal::new(quality, 2.0 * std::f64::consts::PI / steps as f64);
    let every = steps / SAMPLES_PER_PERIOD;
    // A settling of 20 decay times (e^{−20}) before the record.
    let settle = (40.0 * quality / (2.0 * std::f64::consts::PI)).ceil() as usize;
    motion.record(settle * SAMPLES_PER_PERIOD, every, &mut force);
    let chunk = segment / SAMPLES_PER_PERIOD;
    let (mut done, mut square) = (0, 0.0);
    while done < periods {
        let n = chunk.min(periods - done);
        let mut x = motion.record(n * SAMPLES_PER_PERIOD, every, &mut force);
        for v in &mut x {
            *v *= length_m;
            square += *v * *v;
        }
        welch.push(&x);
        done += n;
        progress(done);
    }
    let psd = welch.psd()?;
    let calibration = calibrate(&psd, temperature_k)?;
    Ok(ThermalSpectrum {
        psd,
        calibration,
        rms_m: (square / (periods * SAMPLES_PER_PERIOD) as f64).sqrt(),
        periods,
        samples_per_period: SAMPLES_PER_PERIOD,
    })
}

/// The most resonance periods a thermal record spans.
pub const MAX_THERMAL_PERIODS: usize = 1_000_000_000;

/// The most resonance periods a free cantilever's thermal record spans: about two
/// minutes of computing (the default 8 000 Q at Q = 400, 3.2e6 periods, takes 4 s).
pub const MAX_RECORD_PERIODS: usize = 100_000_000;

/// The free oscillator's transition matrix over Δ ([`FreeFlight::transition`]).
fn free_transition(quality: f64, step: f64) -> Matrix2<f64> {
    let osc = Oscillator {
        gamma: 0.5 / quality,
        omega: 1.0,
        drive: Drive::Force { amplitude: 0.0 },
        bias: 0.0,
    };
    FreeFlight::new(&osc, 0.0, 0.0, 0.0)
        .expect("an undriven force-free oscillator with Q > 0.55 has a closed form")
        .transition(step)
}

/// ⟨x²⟩ of the free cantilever's stationary motion under a force of intensity D̂ held
/// over steps Δ, exactly: the stationary covariance P of the step recursion solves the
/// discrete Lyapunov equation P = MPMᵀ + (D̂/Δ)ggᵀ, g = (I − M)(1, 0)ᵀ. It tends to
/// equipartition, D̂Q/2, as Δ → 0.
pub fn free_variance_hat(quality: f64, step: f64, intensity_hat: f64) -> f64 {
    let m = free_transition(quality, step);
    let g = (Matrix2::identity() - m) * Vector2::new(1.0, 0.0);
    let q = g * g.transpose() * (intensity_hat / step);
    // vec(P) = (I − M ⊗ M)⁻¹ vec(Q), column-major.
    let kron = Matrix4::from_fn(|r, c| m[(r % 2, c % 2)] * m[(r / 2, c / 2)]);
    let rhs = Vector4::new(q[(0, 0)], q[(1, 0)], q[(0, 1)], q[(1, 1)]);
    let p = (Matrix4::identity() - kron)
        .lu()
        .solve(&rhs)
        .expect("a damped oscillator's transition has no unit eigenvalue");
    p[0]
}
