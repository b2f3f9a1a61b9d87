//! Coexisting attractors: the steady states reached from several documented starts.
//!
//! Where a steady state grazes a switch ([`super::grazing`]) which attractor the motion
//! settles on can be decided by perturbations far below the thermal motion, even by the
//! integrator's round-off. What can be said honestly there is the list of attractors
//! reached from a set of documented starts, at the production tolerance and 100× below
//! it, with how many starts reached each.

use super::march::{Phase, Simulation};
use super::observed::TapObservables;
use super::setup::{Numerics, Prepared, TapSetup};
use crate::error::Result;
use crate::physics::law::AnyLaw;
use rayon::prelude::*;
use serde::Serialize;

/// Starts used for a state that grazes a switch when no number is asked for: the first
/// five of [`Start::list`] and one more phase of the free oscillation.
pub const DEFAULT_STARTS: usize = 6;

/// The most starts one run may march from.
pub const MAX_STARTS: usize = 64;

/// Where a steady-state search starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Start {
    /// The free oscillation (the cantilever oscillating far from the sample when the
    /// rest separation is set): what `tap` reports.
    Free,
    /// The same at 100× tighter integrator, orbit and marching tolerances.
    FreeTighter,
    /// The cantilever at rest at the rest separation.
    Rest,
    /// An approach: the steady state 0.1 A₀ farther out, carried to z_c in four steps.
    RampFromAbove,
    /// A retract: the steady state 0.1 A₀ closer in, carried to z_c in four steps.
    RampFromBelow,
    /// The free oscillation's state a phase θ (degrees) further along its orbit.
    FreePhase(f64),
}

impl Start {
    /// The first `n` documented starts: free, free at tighter tolerances, rest, ramps
    /// from above and below, then phases θ = 360°·j/(m + 1), j = 1…m, of the free
    /// oscillation for the m that remain.
    pub fn list(n: usize) -> Vec<Start> {
        let fixed = [
            Start::Free,
            Start::FreeTighter,
            Start::Rest,
            Start::RampFromAbove,
            Start::RampFromBelow,
        ];
        let m = n.saturating_sub(fixed.len());
        fixed
            .into_iter()
            .take(n)
            .chain((1..=m).map(|j| Start::FreePhase(360.0 * j as f64 / (m + 1) as f64)))
            .collect()
    }

    /// Its name in reports.
    pub fn name(&self) -> String {
        match self {
            Start::Free => "free oscillation".into(),
            Start::FreeTighter => "free oscillation, tolerances / 100".into(),
            Start::Rest => "rest".into(),
            Start::RampFromAbove => "ramp from z_c + 0.1 A₀".into(),
            Start::RampFromBelow => "ramp from z_c − 0.1 A₀".into(),
            Start::FreePhase(theta) => format!("free oscillation + {theta:.0}°"),
        }
    }
}

/// One attractor and the starts that reached it.
#[derive(Debug, Clone, Serialize)]
pub struct Attractor {
    /// "period-n" or "irregular".
    pub regime: String,
    /// n of a period-n orbit.
    pub period: Option<usize>,
    /// Jumps into contact per drive period.
    pub touch_fraction: f64,
    /// A/A₀.
    pub amplitude_ratio: f64,
    /// Lock-in phase in degrees.
    pub phase_deg: f64,
    /// E_ts per cycle in J.
    pub e_ts_j: f64,
    /// Whether it grazes a switch.
    pub grazing: bool,
    /// How many starts reached it.
    pub count: usize,
    /// Which.
    pub starts: Vec<String>,
    /// The observables of the first start that reached it.
    #[serde(skip)]
    pub observables: TapObservables,
}

/// The attractors reached from `starts` (the first listed is the first start's), each
/// with the starts that reached it. Two results are one attractor when their regime and
/// touch fraction agree and A/A₀, φ and E_ts agree within four combined standard errors
/// plus 10⁻⁶ (A/A₀; rad for φ; E_ts relative to E_drive). The starts run in parallel;
/// the list is the same on any number of threads.
pub fn attractors(
    setup: &TapSetup,
    numerics: &Numerics,
    starts: &[Start],
) -> Result<Vec<Attractor>> {
    let reached: Vec<(Start, TapObservables)> = starts
        .par_iter()
        .map(|&start| Ok((start, reach(setup, numerics, start)?)))
        .collect::<Result<_>>()?;
    let mut out: Vec<Attractor> = Vec::new();
    for (start, o) in reached {
        match out.iter_mut().find(|a| same(&a.observables, &o)) {
            Some(a) => {
                a.count += 1;
                a.starts.push(start.name());
            }
            None => out.push(Attractor {
                regime: o.regime.clone(),
                period: o.period,
                touch_fraction: o.jumps_in,
                amplitude_ratio: o.amplitude_ratio,
                phase_deg: o.phase_deg,
                e_ts_j: o.e_ts_j,
                grazing: o.grazing,
                count: 1,
                starts: vec![start.name()],
                observables: o,
            }),
        }
    }
    Ok(out)
}

/// The steady state reached from `start`.
fn reach(setup: &TapSetup, numerics: &Numerics, start: Start) -> Result<TapObservables> {
    let numerics = match start {
        Start::FreeTighter => Numerics {
            rtol: (numerics.rtol / 100.0).max(1e-13),
            atol: numerics.atol / 100.0,
            tolerance: (numerics.tolerance / 100.0).max(1e-12),
            average_tolerance: numerics.average_tolerance,
            ..*numerics
        },
        _ => *numerics,
    };
    let mut p = Prepared::new(setup, &numerics)?;
    if start == Start::FreeTighter {
        // Marched periods (irregular motion) 100× tighter too.
        p.steady.marching_fraction /= 100.0;
    }
    let sim = p.simulation();
    let mut phase = match start {
        Start::Free | Start::FreeTighter => sim.free_steady_start(),
        Start::Rest => Phase::at_rest(),
        Start::FreePhase(theta) => free_at_phase(&sim, theta.to_radians()),
        Start::RampFromAbove | Start::RampFromBelow => {
            let sign = if start == Start::RampFromAbove {
                1.0
            } else {
                -1.0
            };
            let reach = sign * 0.1 * setup.cantilever.free_amplitude_m;
            let mut phase = sim.free_steady_start();
            for j in 0..4 {
                let at = setup.separation_m + reach * (1.0 - f64::from(j) / 4.0);
                p.simulation_at(at)?.steady_state(&mut phase, &p.steady)?;
            }
            phase
        }
    };
    let state = sim.steady_state(&mut phase, &p.steady)?;
    TapObservables::new(&p, &state)
}

/// The free oscillation's state at the drive phase, moved a phase `theta` along its
/// orbit: (x, x') = (A cos(θ₀ + θ), −ΩA sin(θ₀ + θ)) where the free start is at θ₀.
fn free_at_phase(sim: &Simulation<'_, AnyLaw>, theta: f64) -> Phase {
    let free = sim.free_steady_start();
    let omega = sim.osc.omega;
    let (s, c) = theta.sin_cos();
    // Rotating (x, x'/Ω) by θ advances the harmonic motion by θ.
    let (x, w) = (free.x, free.v / omega);
    Phase {
        x: x * c + w * s,
        v: omega * (w * c - x * s),
        ..free
    }
}

/// Whether two steady states are the same attractor.
fn same(a: &TapObservables, b: &TapObservables) -> bool {
    let err = |x: Option<f64>| x.unwrap_or(0.0);
    let within = |d: f64, ea: f64, eb: f64, floor: f64| d.abs() <= 4.0 * ea.hypot(eb) + floor;
    let a0 = a.amplitude_m / a.amplitude_ratio.max(f64::MIN_POSITIVE);
    a.regime == b.regime
        && (a.period.is_none() || (a.jumps_in - b.jumps_in).abs() <= 1e-9)
        && within(
            a.amplitude_m - b.amplitude_m,
            err(a.amplitude_std_err_m),
            err(b.amplitude_std_err_m),
            1e-6 * a0,
        )
        && within(
            a.phase_deg - b.phase_deg,
            err(a.phase_std_err_deg),
            err(b.phase_std_err_deg),
            1e-6f64.to_degrees(),
        )
        && within(
            a.e_ts_j - b.e_ts_j,
            err(a.e_ts_std_err_j),
            err(b.e_ts_std_err_j),
            1e-6 * a.e_drive_j.abs(),
        )
}
