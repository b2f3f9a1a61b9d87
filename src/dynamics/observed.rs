//! What an instrument reads from one steady state: the observables of its reported
//! cycle in SI units ([`TapObservables`]), and the recorder of its trajectory. The tap
//! job that finds the state and its coexisting attractors is [`super::observables`].

use super::free::FreeFlight;
use super::march::CycleIntegrals;
use super::model::{Carried, Coupling, Drive, Oscillator, V, X};
use super::numeric::{StepEnd, StepObserver, hermite};
use super::setup::Prepared;
use super::steady::{Motion, SteadyState};
use crate::error::{Error, Result};
use crate::physics::law::{Branch, ForceLaw};
use crate::physics::params::ELECTRONVOLT_J;
use serde::Serialize;
use std::f64::consts::PI;

/// What the steady tapping motion shows, as an instrument reads it: for a period-n orbit
/// the lock-in values (fundamental projected over the n periods) and every energy, force
/// and time per drive period averaged over them, extremes over them; for irregular motion
/// the same over the averaging window, with standard errors.
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
    /// the virial, in degrees. Over a window of irregular motion the relation also counts
    /// what the oscillator stored between the window's ends (its energy change and the
    /// drive's end term); both vanish on a periodic orbit. It differs from the lock-in
    /// phase by the damping of the higher harmonics, which the relation leaves out.
    pub phase_from_energy_deg: f64,
    /// Energy dissipated in the contact per cycle, ∮ T dα, in J (0 where below 1e-12 of
    /// the drive's energy per cycle: the round-off of a loop that cancels, as a
    /// conservative law's does; likewise each part by mechanism, whose sum it is).
    pub e_ts_j: f64,
    /// The same in eV.
    pub e_ts_ev: f64,
    /// The part of E_ts lost to adhesion hysteresis: the elastic law's own loop, summed
    /// from its branch work functions, in J.
    pub e_ts_adhesion_j: f64,
    /// The part of E_ts lost in a viscous sample (Kelvin–Voigt), from its carried
    /// integral ∮ T_d dα, in J; 0 for an elastic sample.
    pub e_ts_viscous_j: f64,
    /// The part of E_ts lost to a capillary neck (formed and broken), from its share of
    /// the branch work functions, in J; 0 without a neck.
    pub e_ts_capillary_j: f64,
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
    /// Jumps into contact per drive period (0.75: three periods in four touch).
    pub jumps_in: f64,
    /// The law's own loop area (the loss of one full traversal) in J.
    pub loop_area_j: f64,
    /// The law's loop area, dimensionless (Ŵ).
    pub loop_area_hat: f64,
    /// Drive frequency over resonance.
    pub frequency_ratio: f64,
    /// Cycles integrated in all.
    pub cycles: usize,
    /// Whether the reported values meet their tolerance (a periodic orbit closed to
    /// `tolerance`, or irregular averages with standard errors below
    /// `average_tolerance`).
    pub converged: bool,
    /// "period-1", "period-2", … or "irregular".
    pub regime: String,
    /// n of a period-n orbit; null for irregular motion.
    pub period: Option<usize>,
    /// Drive periods the reported values are averaged over.
    pub periods_averaged: u32,
    /// Whether the periodic orbit is stable (every Floquet multiplier inside the unit
    /// circle); null for irregular motion and for an orbit that grazes a switch
    /// (`grazing`), whose stability rests on the grazing contact.
    pub stable: Option<bool>,
    /// Floquet multipliers of the periodic orbit, [re, im] each; empty for irregular
    /// motion.
    pub floquet_multipliers: Vec<[f64; 2]>,
    /// Whether the state grazes a switch ([`super::grazing`]): a turning point of the
    /// separation lies closer to a level where the law switches branch than the
    /// cantilever's thermal rms deflection at 300 K or the integration's resolution of
    /// the state. Which touch pattern such motion follows is then decided by
    /// perturbations below what an instrument or the integrator controls. Where the
    /// force jumps at that level (a hysteretic law's jump-in or jump-out) the
    /// deterministic answer is not well defined, and a periodic orbit's stability
    /// rests on the grazing contact (`stable` is then null).
    pub grazing: bool,
    /// The grazing margin in m: the smallest distance from a turning point of the
    /// separation to a switch level that matters on its branch; null where no turning
    /// point comes near a level (or the law never switches).
    pub grazing_margin_m: Option<f64>,
    /// Standard error of the amplitude in m (0 for a periodic orbit; null where the
    /// window was too short to estimate it).
    pub amplitude_std_err_m: Option<f64>,
    /// Standard error of the lock-in phase in degrees (0 for a periodic orbit).
    pub phase_std_err_deg: Option<f64>,
    /// Standard error of E_ts per cycle in J (0 for a periodic orbit).
    pub e_ts_std_err_j: Option<f64>,
}

impl TapObservables {
    /// Observables of `state` for the prepared experiment `p`; an error, never a NaN or
    /// an infinity, where one of them could not be computed.
    pub fn new(p: &Prepared, state: &SteadyState) -> Result<Self> {
        Self::from_state(p, state).finite()
    }

    /// Every number finite, else an error naming the first that is not.
    fn finite(self) -> Result<Self> {
        let numbers = [
            ("tabor_mu", self.tabor_mu),
            ("amplitude_m", self.amplitude_m),
            ("amplitude_ratio", self.amplitude_ratio),
            ("phase_deg", self.phase_deg),
            ("phase_from_energy_deg", self.phase_from_energy_deg),
            ("e_ts_j", self.e_ts_j),
            ("e_ts_ev", self.e_ts_ev),
            ("e_ts_adhesion_j", self.e_ts_adhesion_j),
            ("e_ts_viscous_j", self.e_ts_viscous_j),
            ("e_ts_capillary_j", self.e_ts_capillary_j),
            ("e_damp_j", self.e_damp_j),
            ("e_drive_j", self.e_drive_j),
            ("energy_balance_rel", self.energy_balance_rel),
            ("virial_j", self.virial_j),
            ("mean_force_n", self.mean_force_n),
            ("peak_force_n", self.peak_force_n),
            ("peak_attractive_force_n", self.peak_attractive_force_n),
            ("min_separation_m", self.min_separation_m),
            ("max_indentation_m", self.max_indentation_m),
            ("contact_fraction", self.contact_fraction),
            ("jumps_in", self.jumps_in),
            ("loop_area_j", self.loop_area_j),
            ("loop_area_hat", self.loop_area_hat),
            ("frequency_ratio", self.frequency_ratio),
        ];
        let multipliers = self.floquet_multipliers.iter().flatten();
        let bad = numbers
            .iter()
            .find(|(_, x)| !x.is_finite())
            .map(|(name, _)| *name)
            .or_else(|| {
                multipliers
                    .clone()
                    .any(|x| !x.is_finite())
                    .then_some("floquet_multipliers")
            });
        match bad {
            None => Ok(self),
            Some(name) => Err(Error::Numerical(format!(
                "the steady state gave a non-finite {name}: these parameters are outside \
                 what the integration can resolve"
            ))),
        }
    }

    fn from_state(p: &Prepared, state: &SteadyState) -> Self {
        let c: &CycleIntegrals = &state.window;
        let periods = f64::from(c.periods);
        let cant = &p.setup.cantilever;
        let contact = &p.setup.contact;
        let (k, a0) = (cant.stiffness_n_m, cant.free_amplitude_m);
        let energy = k * a0 * a0;
        let amp = c.amplitude();
        let omega = p.osc.omega;
        let q = cant.quality;
        // The drive the motion felt (a loop may have set it apart from the setup's).
        let f0 = match p.osc.drive {
            Drive::Force { amplitude } => amplitude,
            _ => cant.drive_over_k_a0(),
        };
        let mean_f = c.f_int / c.period;
        let virial = c.virial_int / c.period;
        // π F₀ A sin φ = π k Ω A²/Q + E_ts (units kA₀², per period), plus, per period of
        // the window, the oscillator's energy change and the drive's end term
        // E_drive − F₀Ω∫x sin Ωτ dτ (whole periods of a lock-in read the rest).
        let stored = (c.delta_mechanical - (c.e_drive - f0 * omega * c.ss)) / periods;
        let sin_phi = (omega * amp / q + (c.e_ts_per_period() + stored) / (PI * amp)) / f0;
        // ⟨(F_ts)(z − z̄)⟩ with k z̄ = ⟨F_ts⟩ fixes the sign of cos φ.
        let cos_phi = amp * (1.0 - omega * omega) - 2.0 * (virial - mean_f * mean_f) / amp;
        let asin = sin_phi.clamp(-1.0, 1.0).asin().to_degrees();
        let phase_from_energy_deg = if cos_phi >= 0.0 { asin } else { 180.0 - asin };
        let balance = (c.e_drive - c.e_damp - c.e_ts - c.delta_mechanical).abs() / c.e_drive.abs();
        // An energy per period below 1e-12 of the drive's is the round-off of a loop
        // integral that cancels (a conservative law's): zero, not a signed remainder.
        let resolved = |e: f64| {
            if e.abs() <= 1e-12 * c.e_drive_per_period().abs() {
                0.0
            } else {
                e
            }
        };
        let (viscous, capillary) = (
            resolved(c.e_viscous / periods),
            resolved(c.e_capillary / periods),
        );
        let adhesion = resolved((c.e_ts - c.e_viscous - c.e_capillary) / periods);
        // The whole is the sum of its resolved parts.
        let e_ts = adhesion + viscous + capillary;
        let scale = contact.separation_scale_m();
        let min_sep = c.min_alpha_hat * scale;
        let margin = c.grazing.any * scale;
        let sim = p.simulation();
        let grazing = sim.grazing(&p.steady, state);
        Self {
            law: p.setup.law.to_string(),
            tabor_mu: contact.tabor_mu(),
            amplitude_m: amp * a0,
            amplitude_ratio: amp,
            phase_deg: c.phase().to_degrees(),
            phase_from_energy_deg,
            e_ts_j: e_ts * energy,
            e_ts_ev: e_ts * energy / ELECTRONVOLT_J,
            e_ts_adhesion_j: adhesion * energy,
            e_ts_viscous_j: viscous * energy,
            e_ts_capillary_j: capillary * energy,
            e_damp_j: c.e_damp / periods * energy,
            e_drive_j: c.e_drive_per_period() * energy,
            energy_balance_rel: balance,
            virial_j: virial * energy,
            mean_force_n: mean_f * k * a0,
            peak_force_n: c.max_force * k * a0,
            peak_attractive_force_n: c.min_force.min(0.0) * k * a0,
            min_separation_m: min_sep,
            max_indentation_m: (-min_sep).max(0.0),
            contact_fraction: c.contact_time / c.period,
            jumps_in: f64::from(c.jumps_in) / periods,
            loop_area_j: p.law.loop_area_hat() * contact.energy_scale_j(),
            loop_area_hat: p.law.loop_area_hat(),
            frequency_ratio: omega,
            cycles: state.cycles,
            converged: state.converged,
            regime: state.motion.regime(),
            period: state.motion.period(),
            periods_averaged: c.periods,
            stable: state.motion.stable().filter(|_| !grazing.jump),
            floquet_multipliers: match state.motion {
                Motion::Periodic { multipliers, .. } => {
                    multipliers.iter().map(|m| [m.re, m.im]).collect()
                }
                Motion::Irregular => Vec::new(),
            },
            grazing: grazing.any,
            grazing_margin_m: known(margin),
            amplitude_std_err_m: known(state.std_err.amplitude * a0),
            phase_std_err_deg: known(state.std_err.phase.to_degrees()),
            e_ts_std_err_j: known(state.std_err.e_ts * energy),
        }
    }
}

/// `x` if it is finite (an error estimate that could be made), else `None`.
fn known(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
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

/// One recorded point of the motion: (τ, x, x', α̂, f_ts, branch).
pub type Sample = (f64, f64, f64, f64, f64, Branch);

/// Records the trajectory (dimensionless samples, converted by [`Recorder::to_si`]):
/// step ends plus points on each step's Hermite interpolant, and closed-form free flight
/// sampled evenly, as densely as its [`Sampling`] says. On a relaxing sample, whose
/// force lives in a surface only the integrator's open step knows
/// ([`super::surface`]), at the step ends alone, with the force the integrator found
/// there.
pub(crate) struct Recorder<'a, L: ForceLaw> {
    /// The samples recorded.
    pub samples: Vec<Sample>,
    /// Whether samples were dropped at the sampling's `max_samples`.
    pub overflowed: bool,
    law: &'a L,
    cpl: Coupling,
    osc: Oscillator,
    sampling: Sampling,
    /// Whether the law's force comes from a surface (sampled at step ends only).
    surface: bool,
}

/// How densely a [`Recorder`] samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Sampling {
    /// Points on each integrator step (its end and points on its interpolant).
    pub points_per_step: usize,
    /// Free flight: this many samples per `free_period` of τ.
    pub free_samples: f64,
    /// The span of τ `free_samples` fall on.
    pub free_period: f64,
    /// Whether a step or a flight that begins on another branch than the last sample's
    /// records its start too (the force jumps there at one separation: a force curve
    /// integrated over the separation needs both sides); else a step's start is taken
    /// as the last sample and a flight's start is recorded again.
    pub switch_starts: bool,
    /// The most samples kept (a record that would need more is marked overflowed).
    pub max_samples: usize,
}

impl Sampling {
    /// A tapping trajectory: six points a step, 400 samples a drive period in free flight,
    /// and both sides of each switch (the force jumps there at one instant).
    pub fn trajectory(osc: &Oscillator) -> Self {
        Self {
            points_per_step: 6,
            free_samples: 400.0,
            free_period: osc.period(),
            switch_starts: true,
            max_samples: MAX_TRAJECTORY_SAMPLES,
        }
    }
}

/// Most cycles a run records.
pub const MAX_RECORD_CYCLES: usize = 1000;

/// Most trajectory samples a run records (about 200 bytes each from recording to CSV
/// or plot, so some 40 MB).
pub const MAX_TRAJECTORY_SAMPLES: usize = 200_000;

impl<L: ForceLaw> StepObserver for Recorder<'_, L> {
    fn step<const N: usize>(&mut self, from: &StepEnd<N>, to: &StepEnd<N>, branch: Branch) {
        if self.surface {
            for end in &[from, to][self.first(branch, 1)..] {
                let alpha = self.cpl.alpha_hat(end.y[X], self.osc.base_at(end.tau).0);
                let f = end.dy[Carried::Force] + 0.0;
                self.record(end.tau, (end.y[X], end.y[V]), alpha, f, branch);
            }
            return;
        }
        let start = self.first(branch, 1);
        let points = self.sampling.points_per_step;
        for i in start..=points {
            let tau = from.tau + (to.tau - from.tau) * i as f64 / points as f64;
            let x = hermite(from, to, X, tau);
            let v = hermite(from, to, V, tau);
            self.push(tau, (x, v), branch);
        }
    }

    fn free_flight(&mut self, flight: &FreeFlight, from: f64, to: f64) {
        let s = self.sampling;
        let n = ((to - from) / s.free_period * s.free_samples)
            .ceil()
            .max(1.0) as usize;
        for i in self.first(Branch::Free, 0)..=n {
            let tau = from + (to - from) * i as f64 / n as f64;
            self.push(tau, flight.at(tau), Branch::Free);
        }
    }
}

impl<'a, L: ForceLaw> Recorder<'a, L> {
    /// An empty recorder for the law and model of a simulation, sampling a tapping
    /// trajectory ([`Sampling::trajectory`]).
    pub fn new(law: &'a L, cpl: Coupling, osc: Oscillator) -> Self {
        Self::sampling(law, cpl, osc, Sampling::trajectory(&osc))
    }

    /// An empty recorder sampling as `sampling` says.
    pub fn sampling(law: &'a L, cpl: Coupling, osc: Oscillator, sampling: Sampling) -> Self {
        Self {
            samples: Vec::new(),
            overflowed: false,
            law,
            cpl,
            osc,
            sampling,
            surface: law.has_surface(),
        }
    }

    /// The first point of a step or flight on `branch` to record: its start where the
    /// record begins, or (with `switch_starts`) where the branch has just switched;
    /// else `otherwise`.
    fn first(&self, branch: Branch, otherwise: usize) -> usize {
        match self.samples.last() {
            None => 0,
            Some(last) if self.sampling.switch_starts && last.5 != branch => 0,
            Some(_) if self.sampling.switch_starts => 1,
            Some(_) => otherwise,
        }
    }

    fn push(&mut self, tau: f64, (x, v): (f64, f64), branch: Branch) {
        let state = self
            .cpl
            .contact_state((x, v), self.osc.base_at(tau), branch);
        // (+ 0.0 turns the −0 of a force-free branch into 0; a surface's law is
        // force-free in the free flights sampled here.)
        let f = if self.surface && branch == Branch::Free {
            0.0
        } else {
            -self.cpl.f_scale * self.law.force_hat(&state) + 0.0
        };
        self.record(tau, (x, v), state.alpha_hat, f, branch);
    }

    fn record(&mut self, tau: f64, (x, v): (f64, f64), alpha: f64, f: f64, branch: Branch) {
        if self.samples.len() >= self.sampling.max_samples {
            self.overflowed = true;
            return;
        }
        self.samples.push((tau, x, v, alpha, f, branch));
    }

    /// The samples in SI units for the prepared experiment `p`.
    pub(crate) fn to_si(&self, p: &Prepared) -> Vec<TrajectorySample> {
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
