//! Observables of one steady-state cycle in SI units, and the whole tapping run.

use super::free::FreeFlight;
use super::model::F_INT;
use super::numeric::{StepEnd, StepObserver};
use super::setup::{Numerics, Prepared, TapSetup};
use super::steady::{CycleIntegrals, SteadyState};
use crate::error::Result;
use crate::law::{Branch, ForceLaw};
use crate::params::ELECTRONVOLT_J;
use serde::Serialize;
use std::f64::consts::PI;

/// What one steady tapping cycle shows (DESIGN.md §2).
#[derive(Debug, Clone, Serialize)]
pub struct TapObservables {
    /// Tip–sample law.
    pub law: String,
    /// Tabor parameter μ of the contact, eq. (2).
    pub tabor_mu: f64,
    /// Amplitude A of the fundamental in m.
    pub amplitude_m: f64,
    /// A/A₀.
    pub amplitude_ratio: f64,
    /// Phase lag φ of the fundamental (z ≈ A cos(ωt − φ)) in degrees; 90° free at
    /// resonance, above 90° attractive, below repulsive.
    pub phase_deg: f64,
    /// Phase from the energy relation π F₀ A sin φ = π k (ω/ω₀) A²/Q + E_ts, quadrant from
    /// the virial, in degrees.
    pub phase_from_energy_deg: f64,
    /// Energy dissipated in the contact per cycle, ∮ T dα, in J.
    pub e_ts_j: f64,
    /// The same in eV.
    pub e_ts_ev: f64,
    /// Energy dissipated by the cantilever's damping per cycle in J.
    pub e_damp_j: f64,
    /// Energy put in by the drive per cycle in J.
    pub e_drive_j: f64,
    /// |E_drive − E_damp − E_ts − ΔE_osc| / E_drive: the integration's energy error.
    pub energy_balance_rel: f64,
    /// Virial ⟨F_ts z⟩ over the cycle in J.
    pub virial_j: f64,
    /// Mean tip–sample force ⟨F_ts⟩ in N (repulsive positive).
    pub mean_force_n: f64,
    /// Peak repulsive tip–sample force in N (negative if the force is attractive
    /// throughout).
    pub peak_force_n: f64,
    /// Peak attractive tip–sample force in N (as a negative number).
    pub peak_attractive_force_n: f64,
    /// Smallest tip–sample separation α in m (negative: indentation).
    pub min_separation_m: f64,
    /// Largest indentation max(0, −α) in m.
    pub max_indentation_m: f64,
    /// Fraction of the period spent in contact.
    pub contact_fraction: f64,
    /// Jumps into contact during the cycle.
    pub jumps_in: u32,
    /// The law's own loop area (the loss of one full traversal) in J.
    pub loop_area_j: f64,
    /// The law's loop area, dimensionless (Ŵ).
    pub loop_area_hat: f64,
    /// Drive frequency over resonance.
    pub frequency_ratio: f64,
    /// Cycles integrated in all.
    pub cycles: usize,
    /// Whether the steady state was reached within the cycle cap.
    pub converged: bool,
}

impl TapObservables {
    /// Observables of `state`'s reported cycle for the prepared experiment `p`.
    pub fn new(p: &Prepared, state: &SteadyState) -> Self {
        let c: &CycleIntegrals = &state.cycle;
        let cant = &p.setup.cantilever;
        let contact = &p.setup.contact;
        let (k, a0) = (cant.stiffness_n_m, cant.free_amplitude_m);
        let energy = k * a0 * a0;
        let amp = c.amplitude();
        let omega = p.osc.omega;
        let q = cant.quality;
        let f0 = cant.drive_over_k_a0();
        let mean_f = c.f_int / c.period;
        let virial = c.virial_int / c.period;
        // π F₀ A sin φ = π k Ω A²/Q + E_ts (units kA₀²).
        let sin_phi = (omega * amp / q + c.e_ts / (PI * amp)) / f0;
        // ⟨(F_ts)(z − z̄)⟩ with k z̄ = ⟨F_ts⟩ fixes the sign of cos φ.
        let cos_phi = amp * (1.0 - omega * omega) - 2.0 * (virial - mean_f * mean_f) / amp;
        let asin = sin_phi.clamp(-1.0, 1.0).asin().to_degrees();
        let phase_from_energy_deg = if cos_phi >= 0.0 { asin } else { 180.0 - asin };
        let balance = (c.e_drive - c.e_damp - c.e_ts - c.delta_mechanical).abs() / c.e_drive.abs();
        let scale = contact.separation_scale_m();
        let min_sep = c.min_alpha_hat * scale;
        Self {
            law: p.setup.law.to_string(),
            tabor_mu: contact.tabor_mu(),
            amplitude_m: amp * a0,
            amplitude_ratio: amp,
            phase_deg: c.phase().to_degrees(),
            phase_from_energy_deg,
            e_ts_j: c.e_ts * energy,
            e_ts_ev: c.e_ts * energy / ELECTRONVOLT_J,
            e_damp_j: c.e_damp * energy,
            e_drive_j: c.e_drive * energy,
            energy_balance_rel: balance,
            virial_j: virial * energy,
            mean_force_n: mean_f * k * a0,
            peak_force_n: c.max_force * k * a0,
            peak_attractive_force_n: c.min_force.min(0.0) * k * a0,
            min_separation_m: min_sep,
            max_indentation_m: (-min_sep).max(0.0),
            contact_fraction: c.contact_time / c.period,
            jumps_in: c.jumps_in,
            loop_area_j: p.law.loop_area_hat() * contact.energy_scale_j(),
            loop_area_hat: p.law.loop_area_hat(),
            frequency_ratio: omega,
            cycles: state.cycles,
            converged: state.converged,
        }
    }
}

/// One recorded point of the trajectory (SI).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct TrajectorySample {
    /// Time in s.
    pub t_s: f64,
    /// Deflection z in m.
    pub z_m: f64,
    /// Velocity ż in m/s.
    pub v_m_s: f64,
    /// Tip–sample separation α in m.
    pub alpha_m: f64,
    /// Tip–sample force F_ts in N (repulsive positive).
    pub force_n: f64,
    /// Contact branch.
    pub branch: Branch,
}

/// Records the trajectory of the reported cycle (dimensionless samples, converted later).
#[derive(Debug, Default)]
pub struct Recorder {
    /// (τ, x, x', α̂, f_ts, branch).
    pub samples: Vec<(f64, f64, f64, f64, f64, Branch)>,
    /// Samples per period in free flight.
    pub free_samples_per_period: usize,
    /// Coupling offsets (a₀, a₁) for α̂.
    pub a: (f64, f64),
    /// Period in τ.
    pub period: f64,
}

impl StepObserver for Recorder {
    fn step(&mut self, from: &StepEnd, to: &StepEnd, branch: Branch) {
        if self.samples.is_empty() {
            self.push(from.tau, from.y[0], from.y[1], from.dy[F_INT], branch);
        }
        self.push(to.tau, to.y[0], to.y[1], to.dy[F_INT], branch);
    }

    fn free_flight(&mut self, flight: &FreeFlight, from: f64, to: f64) {
        let n = ((to - from) / self.period * self.free_samples_per_period as f64)
            .ceil()
            .max(1.0) as usize;
        for i in 0..=n {
            let tau = from + (to - from) * i as f64 / n as f64;
            let (x, v) = flight.at(tau);
            self.push(tau, x, v, 0.0, Branch::Free);
        }
    }
}

impl Recorder {
    fn push(&mut self, tau: f64, x: f64, v: f64, f: f64, branch: Branch) {
        let alpha = self.a.0 + self.a.1 * x;
        self.samples.push((tau, x, v, alpha, f, branch));
    }

    /// The samples in SI units for the prepared experiment `p`.
    pub fn to_si(&self, p: &Prepared) -> Vec<TrajectorySample> {
        let cant = &p.setup.cantilever;
        let w0 = 2.0 * PI * cant.resonance_hz;
        let a0 = cant.free_amplitude_m;
        let scale = p.setup.contact.separation_scale_m();
        let t0 = self.samples.first().map_or(0.0, |s| s.0);
        self.samples
            .iter()
            .map(|&(tau, x, v, alpha, f, branch)| TrajectorySample {
                t_s: (tau - t0) / w0,
                z_m: x * a0,
                v_m_s: v * a0 * w0,
                alpha_m: alpha * scale,
                force_n: f * cant.stiffness_n_m * a0,
                branch,
            })
            .collect()
    }
}

/// A complete tapping run: observables and, if asked for, the trajectory of the last
/// `record_cycles` cycles.
#[derive(Debug, Clone, Serialize)]
pub struct TapRun {
    /// Observables of the reported cycle.
    pub observables: TapObservables,
    /// Trajectory samples (empty unless recorded).
    #[serde(skip)]
    pub trajectory: Vec<TrajectorySample>,
}

/// Simulate `setup` to its steady state; record the trajectory of the reported cycle and
/// `extra_cycles` more when `record` is set.
pub fn tap(setup: &TapSetup, numerics: &Numerics, record: bool) -> Result<TapRun> {
    let p = Prepared::new(setup, numerics)?;
    let sim = p.simulation();
    let mut phase = sim.free_steady_start();
    let mut recorder = Recorder {
        samples: Vec::new(),
        free_samples_per_period: if record { 400 } else { 0 },
        a: (p.cpl.a0, p.cpl.a1),
        period: p.osc.period(),
    };
    let state = if record {
        sim.steady_state(&mut phase, &p.steady, &mut recorder)?
    } else {
        sim.steady_state(&mut phase, &p.steady, &mut super::numeric::Ignore)?
    };
    Ok(TapRun {
        observables: TapObservables::new(&p, &state),
        trajectory: recorder.to_si(&p),
    })
}
