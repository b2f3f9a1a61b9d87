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
