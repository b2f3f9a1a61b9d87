//! Sweeps over setpoints: approach–retract curves, carrying the oscillator from point to
//! point as a slow piezo ramp does, so the attractive/repulsive bistability and its
//! hysteresis appear.

use crate::dynamics::observables::TapObservables;
use crate::dynamics::setup::{Numerics, Prepared, TapSetup};
use crate::error::{Error, Result, finite};
use crate::instrument::average::{
    AverageRequest, ThermalAverage, reads_as_average, thermal_average, thermal_average_from,
};
use serde::Serialize;

/// Default steady-state tolerance per setpoint of a sweep: A, φ and E_ts settled to
/// ~1e-5 (the transient left after a change < 1e-7 per cycle is < 1e-7·Q/π).
pub const SETPOINT_TOLERANCE: f64 = 1e-7;

/// Default cap on the periods integrated per setpoint of a sweep. A periodic orbit takes
/// a few dozen; irregular motion (near the onset of contact) is averaged over windows of
/// thousands, and a ramp that has just left a fold may take thousands to settle.
pub const SETPOINT_MAX_CYCLES: usize = 20_000;

/// The numerics of a sweep: `numerics` with the sweep defaults (tolerance and cycle cap
/// per setpoint, [`SETPOINT_TOLERANCE`], [`SETPOINT_MAX_CYCLES`]) where `keep` does not
/// say the caller set them: `(tolerance, max_cycles)` kept as given when true.
pub fn sweep_numerics(mut numerics: Numerics, keep: (bool, bool)) -> Numerics {
    if !keep.0 {
        numerics.tolerance = SETPOINT_TOLERANCE;
    }
    if !keep.1 {
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
    /// Where a temperature was given and the state is read only as a thermal average
    /// ([`reads_as_average`]: it grazes a switch, or is not a stable period-1 orbit):
    /// that average, started from the sweep's state there.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub thermal_average: Option<ThermalAverage>,
}

/// Most setpoints of a sweep in each direction (each is a steady state of its own).
pub const MAX_SWEEP_POINTS: usize = 2000;

/// Most values along each axis of a map (the map has the square of this many cells).
pub const MAX_MAP_STEPS: usize = 200;

/// Most Poincaré samples of a bifurcation diagram (setpoints × samples per setpoint).
pub const MAX_POINCARE_SAMPLES: usize = 200_000;

/// Most worker threads of a map.
pub const MAX_THREADS: usize = 256;

/// Rest separations of an approach from `from_m` down to `to_m` in `points` steps, and
/// back up unless `retract` is false.
pub fn ramp(from_m: f64, to_m: f64, points: usize, retract: bool) -> Result<Vec<(f64, Direction)>> {
    finite("start separation (from)", from_m)?;
    finite("end separation (to)", to_m)?;
    if !(2..=MAX_SWEEP_POINTS).contains(&points) {
        return Err(Error::InvalidParameter {
            name: "points",
            value: points as f64,
            reason: "must be from 2 to 2000",
        });
    }
    if to_m >= from_m {
        return Err(Error::NotApplicable(format!(
            "an approach runs from far to near: the start separation ({from_m:e} m) must exceed \
             the end separation ({to_m:e} m)"
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
    progress: impl FnMut(usize, usize),
) -> Result<Vec<SweepPoint>> {
    approach_curve_at(setup, numerics, ramp, None, progress)
}

/// [`approach_curve`], with each point an instrument reads only as a thermal average
/// ([`reads_as_average`]) averaged over the thermal motion at `thermal`'s temperature
/// ([`thermal_average_from`], from the sweep's state there; the sweep itself goes on
/// from the deterministic state, as without it). `None`: [`approach_curve`].
pub fn approach_curve_at(
    setup: &TapSetup,
    numerics: &Numerics,
    ramp: &[(f64, Direction)],
    thermal: Option<&AverageRequest>,
    mut progress: impl FnMut(usize, usize),
) -> Result<Vec<SweepPoint>> {
    sweep_points(setup, numerics, ramp, thermal, &mut |i, _| {
        progress(i + 1, ramp.len());
        true
    })
}

/// [`approach_curve_at`] that stops after the first point `keep` (given its index and
/// the point) refuses: the points up to and including that one. A fit screening a
/// parameter set stops a curve once it is out of the running.
pub fn approach_curve_while(
    setup: &TapSetup,
    numerics: &Numerics,
    ramp: &[(f64, Direction)],
    thermal: Option<&AverageRequest>,
    mut keep: impl FnMut(usize, &SweepPoint) -> bool,
) -> Result<Vec<SweepPoint>> {
    sweep_points(setup, numerics, ramp, thermal, &mut keep)
}

/// The sweep behind [`approach_curve_at`] and [`approach_curve_while`], compiled once:
/// `keep` is a trait object, so a caller's closure does not copy the sweep and the
/// marcher beneath it into the caller's program.
fn sweep_points(
    setup: &TapSetup,
    numerics: &Numerics,
    ramp: &[(f64, Direction)],
    thermal: Option<&AverageRequest>,
    keep: &mut dyn FnMut(usize, &SweepPoint) -> bool,
) -> Result<Vec<SweepPoint>> {
    if let Some(request) = thermal {
        request.check(setup.cantilever.quality)?;
    }
    let p = Prepared::new(setup, numerics)?;
    let mut phase = p.simulation().free_steady_start();
    let mut out = Vec::with_capacity(ramp.len());
    for (i, &(separation_m, direction)) in ramp.iter().enumerate() {
        crate::interrupt::check()?;
        let sim = p.simulation_at(separation_m)?;
        let state = sim.steady_state(&mut phase, &p.steady)?;
        let observables = TapObservables::new(&p, &state)?;
        let thermal_average = match thermal {
            Some(request) if reads_as_average(&observables) => {
                // Each point its own noise (its place along the curve).
                let request = request.at(&[i as u64]);
                Some(thermal_average_from(&p, &sim, &phase, &request)?)
            }
            _ => None,
        };
        out.push(SweepPoint {
            separation_m,
            direction,
            observables,
            thermal_average,
        });
        if !keep(i, out.last().expect("just pushed")) {
            break;
        }
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
    /// With an amplitude setpoint: the rest separation z_c at which the cell holds it, in
    /// m (a map at one z_c leaves it out).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub separation_m: Option<f64>,
    /// Steady-state observables; `None` where the law does not apply.
    #[serde(flatten)]
    pub observables: Option<TapObservables>,
    /// Why the cell is empty, when it is.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// The thermal noise of the cell's lock-in phase in degrees, where it was asked for
    /// (a map at an amplitude setpoint: the linear theory about the cell's orbit).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_phase_deg: Option<f64>,
    /// Where a temperature was given and the cell's state is read only as a thermal
    /// average ([`reads_as_average`]): that average (a map at one z_c).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub thermal_average: Option<ThermalAverage>,
}

/// `n` values from `lo` to `hi`, evenly spaced on a log scale.
pub fn log_grid(name: &'static str, lo: f64, hi: f64, n: usize) -> Result<Vec<f64>> {
    crate::error::positive(name, lo)?;
    crate::error::positive(name, hi)?;
    if !(2..=MAX_MAP_STEPS).contains(&n) || hi <= lo {
        return Err(Error::NotApplicable(format!(
            "{name}: need from 2 to {MAX_MAP_STEPS} points and an upper end above the lower \
             one"
        )));
    }
    Ok((0..n)
        .map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64))
        .collect())
}

/// One of `count` parts of a job whose items are numbered 0, 1, 2, …: the part numbered
/// `index` takes every item whose number ≡ `index` (mod `count`), so neighbouring
/// items, which cost about the same, are spread over the parts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// I, from 0.
    pub index: usize,
    /// N ≥ 1.
    pub count: usize,
}

/// The most parts a job can be split into.
pub const MAX_SHARDS: usize = 100_000;

impl Shard {
    /// The whole job as one part.
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// Part `index` of `count`, checked.
    pub fn new(index: usize, count: usize) -> Result<Self> {
        if count == 0 || count > MAX_SHARDS || index >= count {
            return Err(Error::NotApplicable(format!(
                "shard {index} of {count}: the part number runs from 0 to the number of \
                 parts less one, and there are from 1 to {MAX_SHARDS} parts"
            )));
        }
        Ok(Self { index, count })
    }

    /// The numbers of this part's items among `total`.
    pub fn items(&self, total: usize) -> Vec<usize> {
        (self.index..total).step_by(self.count).collect()
    }
}

/// A pool of `threads` worker threads (0: one per core, at most [`MAX_THREADS`]) for
/// independent runs.
pub fn thread_pool(threads: usize) -> Result<rayon::ThreadPool> {
    if threads > MAX_THREADS {
        return Err(Error::InvalidParameter {
            name: "threads",
            value: threads as f64,
            reason: "must be at most 256 (0: one per core)",
        });
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::NotApplicable(format!("cannot start {threads} threads: {e}")))
}

/// E_ts and φ over a grid of (Δγ, E*) at the setup's setpoint, one independent steady
/// state per cell (each from the free steady state), computed in parallel on `threads`
/// threads (0: all cores). Cells are independent, so the result does not depend on the
/// thread count. `progress` is called (from any thread) after each cell. The cells come
/// row by row: for each modulus in turn, every work of adhesion.
pub fn adhesion_modulus_map(
    setup: &TapSetup,
    numerics: &Numerics,
    works_j_m2: &[f64],
    moduli_pa: &[f64],
    threads: usize,
    progress: impl Fn() + Sync,
) -> Result<Vec<MapCell>> {
    let all: Vec<usize> = (0..works_j_m2.len() * moduli_pa.len()).collect();
    map_cells(
        setup,
        numerics,
        (works_j_m2, moduli_pa),
        &all,
        threads,
        progress,
        None,
    )
}

/// What a map cell's solver finds ([`CellSolver`]).
#[derive(Debug, Clone)]
pub struct CellState {
    /// The steady state of the cell's setup.
    pub observables: TapObservables,
    /// The rest separation it was found at, m, where that is solved for (an amplitude
    /// setpoint).
    pub separation_m: Option<f64>,
    /// Its phase's thermal noise, degrees, where that was asked for (at a setpoint).
    pub sigma_phase_deg: Option<f64>,
    /// Its thermal average, where a temperature was given and the state is read only as
    /// one ([`reads_as_average`]).
    pub thermal_average: Option<ThermalAverage>,
}

/// What a map cell solves: the state of a cell's setup; an [`Error::NotApplicable`]
/// becomes the cell's note.
pub type CellSolver<'a> = dyn Fn(&TapSetup) -> Result<CellState> + Sync + 'a;

/// The cells numbered `cells` of the map [`adhesion_modulus_map`] computes (numbered in
/// its order: cell k has modulus k / (number of works), work k mod (number of works)),
/// in the order given: a part of a map split over machines ([`Shard`]). Each cell is
/// exactly what the whole map gives for it.
pub fn map_cells(
    setup: &TapSetup,
    numerics: &Numerics,
    axes: (&[f64], &[f64]),
    cells: &[usize],
    threads: usize,
    progress: impl Fn() + Sync,
    thermal: Option<&AverageRequest>,
) -> Result<Vec<MapCell>> {
    if let Some(request) = thermal {
        request.check(setup.cantilever.quality)?;
    }
    let at_separation = |s: &TapSetup| {
        let run = crate::dynamics::observables::tap(
            s,
            numerics,
            crate::dynamics::observables::Observe::default(),
        )?;
        let thermal_average = match thermal {
            Some(request) if reads_as_average(&run.observables) => {
                // Each cell its own noise (its place: its parameters).
                Some(thermal_average(s, numerics, &request.for_state(s))?)
            }
            _ => None,
        };
        Ok(CellState {
            observables: run.observables,
            separation_m: None,
            sigma_phase_deg: None,
            thermal_average,
        })
    };
    map_cells_with(setup, axes, cells, threads, progress, &at_separation)
}

/// [`map_cells`] with each cell's steady state found by `solve` (a map at an amplitude
/// setpoint: [`crate::analysis::setpoint`]).
pub fn map_cells_with(
    setup: &TapSetup,
    (works_j_m2, moduli_pa): (&[f64], &[f64]),
    cells: &[usize],
    threads: usize,
    progress: impl Fn() + Sync,
    solve: &CellSolver<'_>,
) -> Result<Vec<MapCell>> {
    let total = works_j_m2.len() * moduli_pa.len();
    if let Some(&k) = cells.iter().find(|&&k| k >= total) {
        return Err(Error::NotApplicable(format!(
            "cell {k} is not on the {} × {} grid",
            works_j_m2.len(),
            moduli_pa.len()
        )));
    }
    over_grid(
        setup,
        (works_j_m2, moduli_pa),
        cells,
        threads,
        progress,
        |s, (w, e)| {
            let tabor_mu = s.contact.tabor_mu();
            Ok(match solve(s) {
                Ok(state) => MapCell {
                    work_of_adhesion_j_m2: w,
                    modulus_pa: e,
                    tabor_mu,
                    separation_m: state.separation_m,
                    observables: Some(state.observables),
                    note: None,
                    sigma_phase_deg: state.sigma_phase_deg,
                    thermal_average: state.thermal_average,
                },
                Err(Error::NotApplicable(why)) => MapCell {
                    work_of_adhesion_j_m2: w,
                    modulus_pa: e,
                    tabor_mu,
                    separation_m: None,
                    observables: None,
                    note: Some(why),
                    sigma_phase_deg: None,
                    thermal_average: None,
                },
                Err(other) => return Err(other),
            })
        },
    )
}

/// `cell` of each of `cells` (indices into the grid, the work of adhesion fastest) on
/// `threads` (0: every core): the setup with the cell's Δγ and E*, and (Δγ, E*). The
/// results in the order of `cells`; each is counted by `progress`, and an interruption
/// ends the grid.
pub fn over_grid<T: Send>(
    setup: &TapSetup,
    (works_j_m2, moduli_pa): (&[f64], &[f64]),
    cells: &[usize],
    threads: usize,
    progress: impl Fn() + Sync,
    cell: impl Fn(&TapSetup, (f64, f64)) -> Result<T> + Sync,
) -> Result<Vec<T>> {
    use rayon::prelude::*;
    let pool = thread_pool(threads)?;
    let cells: Vec<(f64, f64)> = cells
        .iter()
        .map(|&k| {
            (
                works_j_m2[k % works_j_m2.len()],
                moduli_pa[k / works_j_m2.len()],
            )
        })
        .collect();
    pool.install(|| {
        cells
            .par_iter()
            .map(|&(w, e)| {
                crate::interrupt::check()?;
                let mut s = setup.clone();
                s.contact.work_of_adhesion_j_m2 = w;
                s.contact.modulus_pa = e;
                let done = cell(&s, (w, e))?;
                progress();
                Ok(done)
            })
            .collect()
    })
}

/// What a point of an orbit branch is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BranchPointKind {
    /// A point of the branch.
    Regular,
    /// A fold: a Floquet multiplier at +1, where the branch turns back.
    Fold,
    /// A period doubling: a Floquet multiplier at −1.
    PeriodDoubling,
}

/// One orbit of the period-1 family.
#[derive(Debug, Clone, Serialize)]
pub struct BranchRecord {
    /// Rest separation z_c in m.
    pub separation_m: f64,
    /// The continuous piece of the branch the orbit lies on (0, 1, …; the period map
    /// jumps between pieces where an orbit starts to touch the sample).
    pub segment: usize,
    /// What the point is.
    pub point: BranchPointKind,
    /// The orbit's observables (`stable` and `floquet_multipliers` among them).
    #[serde(flatten)]
    pub observables: TapObservables,
    /// The oscillator's state on the orbit at the drive phase (to start a neighbouring
    /// steady state from; not written out).
    #[serde(skip)]
    pub phase: crate::dynamics::march::Phase,
}

impl BranchRecord {
    /// The record of the continuation's point `b` of piece `segment` over `p`.
    pub(crate) fn new(
        p: &Prepared,
        b: &crate::dynamics::continuation::BranchPoint,
        segment: usize,
    ) -> Result<Self> {
        use crate::dynamics::continuation::PointKind;
        use crate::dynamics::steady::{Motion, SteadyState};
        use crate::dynamics::window::StdErr;
        let state = SteadyState {
            window: b.integrals,
            cycles: 1,
            converged: true,
            motion: Motion::Periodic {
                period: 1,
                multipliers: b.multipliers,
            },
            std_err: StdErr::default(),
        };
        Ok(Self {
            separation_m: b.q * p.setup.cantilever.free_amplitude_m,
            segment,
            point: match b.kind {
                PointKind::Regular => BranchPointKind::Regular,
                PointKind::Fold => BranchPointKind::Fold,
                PointKind::PeriodDoubling => BranchPointKind::PeriodDoubling,
            },
            observables: TapObservables::new(p, &state)?,
            phase: b.phase.clone(),
        })
    }
}

/// The period-1 orbit family followed from one rest separation to another.
#[derive(Debug, Clone)]
pub struct OrbitBranch {
    /// The orbits in order along the branch (folds and period doublings where they lie).
    pub points: Vec<BranchRecord>,
    /// How the branch went: where pieces ended and the next began, and why it ends.
    pub notes: Vec<String>,
}

/// Follow the period-1 orbit family through the rest separation from `from_m` to `to_m`
/// by pseudo-arclength continuation ([`crate::dynamics::continuation`]), stable and
/// unstable orbits alike, with folds and period doublings located. It starts on the orbit
/// the free steady state settles on at `from_m` (if that is a stable period-1 orbit;
/// else as below, where a piece ends). `max_step_m`
/// bounds the step along the branch (in m of the (z, ż/ω₀, z_c) arclength).
///
/// Where a piece of the family ends at a grazing orbit (for a hysteretic law the period
/// map jumps there: touching the sample dissipates a whole loop), the rest separation is
/// moved on by `max_step_m` at a time, carrying the oscillator, until the motion settles
/// on a stable period-1 orbit again, and the next piece is followed from there.
pub fn orbit_branch(
    setup: &TapSetup,
    numerics: &Numerics,
    range_m: (f64, f64),
    max_step_m: f64,
) -> Result<OrbitBranch> {
    orbit_branch_across_gaps(setup, numerics, range_m, max_step_m, max_step_m)
}

/// [`orbit_branch`], moving the rest separation on by `gap_step_m` (≥ `max_step_m`) at a
/// time where the motion is not on a stable period-1 orbit. Where a piece starts after
/// such a stride longer than `max_step_m`, the family is first followed back from there
/// towards the last separation the motion was not period-1 at, so that no stable orbit of
/// the stride is left out; a coarse stride only saves the settling of motion that is not
/// period-1 (the costly part of crossing a wide window of it).
pub fn orbit_branch_across_gaps(
    setup: &TapSetup,
    numerics: &Numerics,
    (from_m, to_m): (f64, f64),
    max_step_m: f64,
    gap_step_m: f64,
) -> Result<OrbitBranch> {
    use crate::dynamics::continuation::{ContinuationOptions, Stop, follow_period_one};
    finite("start separation (from)", from_m)?;
    finite("end separation (to)", to_m)?;
    crate::error::positive("largest step (max step)", max_step_m)?;
    let range = (from_m - to_m).abs();
    if range == 0.0 {
        return Err(Error::NotApplicable(
            "the start and end separations must differ: the branch is followed between them".into(),
        ));
    }
    if !(max_step_m <= range && max_step_m >= 1e-4 * range) {
        return Err(Error::NotApplicable(format!(
            "the largest step (max step, {:e} m) must lie between 1e-4 of the range from the \
             start to the end separation \
             and the whole of it ({:e} m)",
            max_step_m, range
        )));
    }
    let p = Prepared::new(setup, numerics)?;
    let a0 = p.setup.cantilever.free_amplitude_m;
    let nm = |m: f64| m * 1e9;
    let toward = (to_m - from_m).signum();
    let mut phase = p.simulation().free_steady_start();
    let mut points: Vec<BranchRecord> = Vec::new();
    let mut notes = Vec::new();
    if !(gap_step_m >= max_step_m && gap_step_m <= range) {
        return Err(Error::NotApplicable(format!(
            "the stride across motion that is not period-1 ({gap_step_m:e} m) must lie \
             between the largest step ({max_step_m:e} m) and the range ({range:e} m)"
        )));
    }
    let mut at = from_m;
    let mut segment = 0;
    // The last separation where the motion was not on a stable period-1 orbit.
    let mut not_period_one: Option<f64> = None;
    loop {
        // Settle at `at`; a piece of the family starts on a stable period-1 orbit.
        let sim = p.simulation_at(at)?;
        let settled = sim.steady_state(&mut phase, &p.steady)?;
        if settled.motion.period() != Some(1) || !settled.converged {
            if segment == 0 && points.is_empty() && at == from_m {
                notes.push(format!(
                    "at the start separation ({:.4} nm) the motion settles as {}, not on a period-1 orbit",
                    nm(at),
                    settled.motion.regime()
                ));
            }
            not_period_one = Some(at);
            at += toward * gap_step_m;
            if (at - to_m) * toward > 0.0 {
                notes.push(format!(
                    "no stable period-1 orbit from there to the end separation ({:.4} nm)",
                    nm(to_m)
                ));
                break;
            }
            continue;
        }
        if !points.is_empty() {
            notes.push(format!(
                "piece {segment} starts at {:.4} nm, where the motion settles on a stable \
                 period-1 orbit again",
                nm(at)
            ));
        }
        let opts = ContinuationOptions {
            q_end: to_m / a0,
            max_step: max_step_m / a0,
            tolerance: (1e-2 * numerics.tolerance).max(1e-12),
            ..ContinuationOptions::default()
        };
        // Back across the stride first, in the order of the branch.
        if let Some(behind) = not_period_one.take().filter(|_| gap_step_m > max_step_m) {
            let back = ContinuationOptions {
                q_end: behind / a0,
                ..opts
            };
            if let Ok(branch) = follow_period_one(&sim, &phase, &back) {
                for b in branch.points.iter().skip(1).rev() {
                    points.push(BranchRecord::new(&p, b, segment)?);
                }
            }
        }
        let branch = follow_period_one(&sim, &phase, &opts)?;
        for b in &branch.points {
            points.push(BranchRecord::new(&p, b, segment)?);
        }
        match branch.stop {
            Stop::Reached => {
                notes.push(format!("reached the end separation ({:.4} nm)", nm(to_m)));
                break;
            }
            Stop::TurnedBack => {
                notes.push("turned back past the start separation".into());
                break;
            }
            Stop::PointCap => {
                notes.push("stopped at the point cap (raise the largest step)".into());
                break;
            }
            Stop::NotSmooth(q) => {
                notes.push(format!(
                    "piece {segment} ends at {:.4} nm, where the period map is not smooth \
                     (an orbit grazing a switch of the force law)",
                    nm(q * a0)
                ));
                let last = branch.points.last().expect("a piece has points");
                phase = last.phase.clone();
                at = q * a0 + toward * max_step_m;
                segment += 1;
                if (at - to_m) * toward > 0.0 {
                    break;
                }
            }
        }
    }
    Ok(OrbitBranch { points, notes })
}

/// Poincaré samples of the settled motion at one rest separation.
#[derive(Debug, Clone, Serialize)]
pub struct PoincareSample {
    /// Rest separation z_c in m.
    pub separation_m: f64,
    /// How the settled motion repeats there ("period-2", "irregular", …).
    pub regime: String,
    /// Deflection z at drive phase 0 (the start of a drive period) in m.
    pub deflection_m: f64,
    /// Smallest tip–sample separation during that period in m.
    pub min_separation_m: f64,
}

/// A bifurcation diagram: along an approach ramp (`separations_m`, carrying the
/// oscillator from point to point), settle the motion at each rest separation, then
/// record `samples` drive periods of it: the deflection at drive phase 0 and the smallest
/// separation of each period. A period-n orbit shows n distinct values; irregular motion
/// a cloud. `progress` is called after each separation with (done, total).
pub fn bifurcation(
    setup: &TapSetup,
    numerics: &Numerics,
    separations_m: &[f64],
    samples: usize,
    mut progress: impl FnMut(usize, usize),
) -> Result<Vec<PoincareSample>> {
    use crate::dynamics::numeric::Ignore;
    if !(1..=10_000).contains(&samples) {
        return Err(Error::InvalidParameter {
            name: "samples",
            value: samples as f64,
            reason: "must be from 1 to 10000",
        });
    }
    if separations_m.len().saturating_mul(samples) > MAX_POINCARE_SAMPLES {
        return Err(Error::NotApplicable(format!(
            "{} setpoints × {samples} samples is more than the {MAX_POINCARE_SAMPLES} \
             Poincaré samples a diagram holds: fewer points or samples",
            separations_m.len()
        )));
    }
    let p = Prepared::new(setup, numerics)?;
    let scale = p.setup.contact.separation_scale_m();
    let a0 = p.setup.cantilever.free_amplitude_m;
    let mut phase = p.simulation().free_steady_start();
    let mut out = Vec::with_capacity(separations_m.len() * samples);
    for (i, &z) in separations_m.iter().enumerate() {
        let sim = p.simulation_at(z)?;
        crate::dynamics::budget::budgeted(p.steady.max_steps, || {
            let state = sim.steady_state(&mut phase, &p.steady)?;
            let regime = state.motion.regime();
            for _ in 0..samples {
                let deflection_m = phase.x * a0;
                let c = sim.cycle(&mut phase, &mut Ignore)?;
                out.push(PoincareSample {
                    separation_m: z,
                    regime: regime.clone(),
                    deflection_m,
                    min_separation_m: c.min_alpha_hat * scale,
                });
            }
            Ok(())
        })?;
        progress(i + 1, separations_m.len());
    }
    Ok(out)
}
