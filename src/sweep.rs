//! Sweeps over setpoints: approach–retract curves, carrying the oscillator from point to
//! point as a slow piezo ramp does, so the attractive/repulsive bistability and its
//! hysteresis appear.

use crate::dynamics::observables::TapObservables;
use crate::dynamics::setup::{Numerics, Prepared, TapSetup};
use crate::error::{Error, Result, finite};
use serde::Serialize;

/// Default steady-state tolerance per setpoint of a sweep: A, φ and E_ts settled to
/// ~1e-5 (the transient left after a change < 1e-7 per cycle is < 1e-7·Q/π).
pub const SETPOINT_TOLERANCE: f64 = 1e-7;

/// Default cap on the periods integrated per setpoint of a sweep (near the onset of
/// contact the motion can be period-doubled or chaotic and never settle; such points are
/// reported with `converged: false`).
pub const SETPOINT_MAX_CYCLES: usize = 4000;

/// The numerics of a sweep: `numerics` with the sweep defaults for whatever `inputs` left
/// unset (tolerance and cycle cap per setpoint).
pub fn sweep_numerics(inputs: &crate::config::TapInputs, mut numerics: Numerics) -> Numerics {
    if inputs.tolerance.is_none() {
        numerics.tolerance = SETPOINT_TOLERANCE;
    }
    if inputs.max_cycles.is_none() {
        numerics.max_cycles = SETPOINT_MAX_CYCLES;
    }
    numerics
}

/// Which way the ramp is moving.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Direction {
    /// Rest separation decreasing.
    Approach,
    /// Rest separation increasing.
    Retract,
}

/// One point of an approach curve.
#[derive(Debug, Clone, Serialize)]
pub struct SweepPoint {
    /// Rest separation z_c in m.
    pub separation_m: f64,
    /// Ramp direction.
    pub direction: Direction,
    /// Steady-state observables there.
    #[serde(flatten)]
    pub observables: TapObservables,
}

/// Rest separations of an approach from `from_m` down to `to_m` in `points` steps, and
/// back up unless `retract` is false.
pub fn ramp(from_m: f64, to_m: f64, points: usize, retract: bool) -> Result<Vec<(f64, Direction)>> {
    finite("--from", from_m)?;
    finite("--to", to_m)?;
    if points < 2 {
        return Err(Error::InvalidParameter {
            name: "points",
            value: points as f64,
            reason: "must be at least 2",
        });
    }
    if to_m >= from_m {
        return Err(Error::NotApplicable(format!(
            "an approach runs from far to near: --from ({from_m:e} m) must exceed --to ({to_m:e} m)"
        )));
    }
    let at = |i: usize| from_m + (to_m - from_m) * i as f64 / (points - 1) as f64;
    let mut out: Vec<(f64, Direction)> =
        (0..points).map(|i| (at(i), Direction::Approach)).collect();
    if retract {
        out.extend((0..points).rev().map(|i| (at(i), Direction::Retract)));
    }
    Ok(out)
}

/// Simulate the steady state at every setpoint of `ramp` in order, each starting from the
/// state the previous one ended in (the first from the free steady state). `progress` is
/// called after each point with (done, total).
pub fn approach_curve(
    setup: &TapSetup,
    numerics: &Numerics,
    ramp: &[(f64, Direction)],
    mut progress: impl FnMut(usize, usize),
) -> Result<Vec<SweepPoint>> {
    let p = Prepared::new(setup, numerics)?;
    let mut phase = p.simulation().free_steady_start();
    let mut out = Vec::with_capacity(ramp.len());
    for (i, &(separation_m, direction)) in ramp.iter().enumerate() {
        let sim = p.simulation_at(separation_m)?;
        let state = sim.steady_state(&mut phase, &p.steady)?;
        out.push(SweepPoint {
            separation_m,
            direction,
            observables: TapObservables::new(&p, &state),
        });
        progress(i + 1, ramp.len());
    }
    Ok(out)
}

/// One cell of a parameter map.
#[derive(Debug, Clone, Serialize)]
pub struct MapCell {
    /// Work of adhesion Δγ in J/m².
    pub work_of_adhesion_j_m2: f64,
    /// Composite modulus E* in Pa.
    pub modulus_pa: f64,
    /// Tabor parameter μ of the cell.
    pub tabor_mu: f64,
    /// Steady-state observables; `None` where the law does not apply.
    #[serde(flatten)]
    pub observables: Option<TapObservables>,
    /// Why the cell is empty, when it is.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// `n` values from `lo` to `hi`, evenly spaced on a log scale.
pub fn log_grid(name: &'static str, lo: f64, hi: f64, n: usize) -> Result<Vec<f64>> {
    crate::error::positive(name, lo)?;
    crate::error::positive(name, hi)?;
    if n < 2 || hi <= lo {
        return Err(Error::NotApplicable(format!(
            "{name}: need at least 2 points and an upper end above the lower one"
        )));
    }
    Ok((0..n)
        .map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64))
        .collect())
}

/// E_ts and φ over a grid of (Δγ, E*) at the setup's setpoint, one independent steady
/// state per cell (each from the free steady state), computed in parallel on `threads`
/// threads (0: all cores). Cells are independent, so the result does not depend on the
/// thread count. `progress` is called (from any thread) after each cell.
pub fn adhesion_modulus_map(
    setup: &TapSetup,
    numerics: &Numerics,
    works_j_m2: &[f64],
    moduli_pa: &[f64],
    threads: usize,
    progress: impl Fn() + Sync,
) -> Result<Vec<MapCell>> {
    use rayon::prelude::*;
    let cells: Vec<(f64, f64)> = moduli_pa
        .iter()
        .flat_map(|&e| works_j_m2.iter().map(move |&w| (w, e)))
        .collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::NotApplicable(format!("cannot start {threads} threads: {e}")))?;
    pool.install(|| {
        cells
            .par_iter()
            .map(|&(w, e)| {
                let mut s = setup.clone();
                s.contact.work_of_adhesion_j_m2 = w;
                s.contact.modulus_pa = e;
                let tabor_mu = s.contact.tabor_mu();
                let cell = match crate::dynamics::observables::tap(&s, numerics, 0) {
                    Ok(run) => MapCell {
                        work_of_adhesion_j_m2: w,
                        modulus_pa: e,
                        tabor_mu,
                        observables: Some(run.observables),
                        note: None,
                    },
                    Err(Error::NotApplicable(why)) => MapCell {
                        work_of_adhesion_j_m2: w,
                        modulus_pa: e,
                        tabor_mu,
                        observables: None,
                        note: Some(why),
                    },
                    Err(other) => return Err(other),
                };
                progress();
                Ok(cell)
            })
            .collect()
    })
}
