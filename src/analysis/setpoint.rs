//! Steady states at an amplitude setpoint A/A₀, as an AFM's z feedback holds it: the rest
//! separations z_c at which the tip's amplitude is the setpoint, on each branch.
//!
//! The stable period-1 orbit family is followed through z_c by continuation
//! ([`sweep::orbit_branch`]) from 1.2 A₀ in to deep contact; wherever two neighbouring
//! stable orbits of one piece bracket the setpoint, the rest separation is refined by
//! the Illinois method on A(z_c)/A₀ − setpoint, each steady state started from the
//! orbit next to it (so that it stays on its branch), until the amplitude is the
//! setpoint to [`AMPLITUDE_TOLERANCE`]. Each state is named by its branch: attractive
//! where its phase lag lies above the free oscillator's (90° at resonance), repulsive
//! below (García & San Paulo, PRB 60, 4961, 1999).

use crate::analysis::sweep::{self, BranchRecord};
use crate::dynamics::march::Phase;
use crate::dynamics::observables::TapObservables;
use crate::dynamics::setup::{Numerics, Prepared, TapSetup};
use crate::error::{Error, Result};
use serde::Serialize;

/// The branch a steady state of the tapping tip lies on, told by its phase: attractive
/// where φ lies above the free oscillator's phase (90° at resonance), repulsive below.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PhaseBranch {
    /// Net attractive tip–sample force over the cycle: φ above the free phase.
    Attractive,
    /// Net repulsive: φ below the free phase.
    Repulsive,
}

impl PhaseBranch {
    /// The branch of a state with phase lag `phase_deg` for a cantilever whose free phase
    /// is `free_phase_deg`.
    pub fn of(phase_deg: f64, free_phase_deg: f64) -> Self {
        if phase_deg > free_phase_deg {
            Self::Attractive
        } else {
            Self::Repulsive
        }
    }
}

impl std::fmt::Display for PhaseBranch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Attractive => "attractive",
            Self::Repulsive => "repulsive",
        })
    }
}

/// How close to the setpoint a state's A/A₀ is brought.
pub const AMPLITUDE_TOLERANCE: f64 = 1e-9;

/// One steady state at the setpoint.
#[derive(Debug, Clone, Serialize)]
pub struct SetpointState {
    /// Its branch.
    pub branch: PhaseBranch,
    /// The rest separation z_c at which the amplitude is the setpoint, in m.
    pub separation_m: f64,
    /// Every observable of the steady state there.
    #[serde(flatten)]
    pub observables: TapObservables,
    /// The oscillator's state on the orbit at the drive phase (to carry on from; not
    /// written out).
    #[serde(skip)]
    pub phase: Phase,
}

impl SetpointState {
    /// The thermal noise a lock-in reads on this state's orbit
    /// ([`crate::instrument::noise::NoiseRequest::on_orbit`]), `prepared` the setup and
    /// numerics it was found with.
    pub fn thermal_noise(
        &self,
        prepared: &Prepared,
        request: &crate::instrument::noise::NoiseRequest,
    ) -> Result<crate::instrument::noise::ThermalNoise> {
        request.on_orbit(
            prepared,
            &prepared.simulation_at(self.separation_m)?,
            &self.phase,
        )
    }
}

/// The free oscillator's phase lag in degrees, atan2(Ω/Q, 1 − Ω²) (the border between
/// the attractive and the repulsive branch).
pub fn free_phase_deg(setup: &TapSetup) -> f64 {
    let (w, q) = (setup.cantilever.omega_ratio(), setup.cantilever.quality);
    (w / q).atan2(1.0 - w * w).to_degrees()
}

/// Refuse an amplitude setpoint outside (0, 1) (what every command that takes one
/// checks before it runs anything).
pub fn check_ratio(ratio: f64) -> Result<()> {
    if ratio > 0.0 && ratio < 1.0 {
        return Ok(());
    }
    Err(Error::OutOfRange(format!(
        "amplitude setpoint A/A₀ = {} is outside (0, 1): the amplitude of a tip that \
         touches lies below the free amplitude",
        shown(ratio)
    )))
}

/// Every stable period-1 steady state whose amplitude is `ratio` × A₀ (0 < ratio < 1),
/// on `branch` (`None`: both), attractive ones first, each at the rest separation that
/// gives it: from each branch's harmonic estimate, else on the period-1 families
/// followed by continuation, else at the end of a ramp lowering the setpoint from far
/// ([`sweep_setpoints`]). None is an error saying what amplitudes the branches' stable
/// orbits reach and why the ramp does not hold the setpoint.
pub fn states_at_setpoint(
    setup: &TapSetup,
    numerics: &Numerics,
    ratio: f64,
    branch: Option<PhaseBranch>,
) -> Result<Vec<SetpointState>> {
    check_ratio(ratio)?;
    let p = Prepared::new(setup, numerics)?;
    let sides = branch.map_or(vec![PhaseBranch::Attractive, PhaseBranch::Repulsive], |b| {
        vec![b]
    });
    let mut out = Vec::new();
    for &side in &sides {
        out.extend(near_estimate(&p, numerics, ratio, side)?);
    }
    if out.len() == sides.len() {
        return Ok(out);
    }
    // A branch the estimate did not lead to: the whole search.
    let a0 = setup.cantilever.free_amplitude_m;
    let range = (1.2 * a0, (ratio - 0.35).max(0.02) * a0);
    let family = families(&p, numerics, range)?;
    out.extend(states_on(&p, &family, ratio, branch)?);
    let out = distinct(out, a0);
    if out.is_empty() {
        // Where the families hold no stable period-1 state: a ramp lowering the setpoint
        // from far, as a z feedback would.
        let free = free_phase_deg(setup);
        let ramp = hold(&p, &mut far_from_the_sample(&p)?, ratio)?;
        return match ramp {
            Ok(s) if branch.is_none_or(|b| b == s.branch) => Ok(vec![s]),
            ramp => {
                let mut why = unreached(&family, ratio, branch, free, range);
                if let Err(ramp_why) = ramp {
                    why += &format!(
                        ". Lowered from far as a z feedback lowers it, the setpoint is not \
                         held either: {ramp_why}"
                    );
                }
                why += ". An approach curve in setpoints (`tapsim approach`) shows what the motion does there";
                Err(Error::NotApplicable(why))
            }
        };
    }
    Ok(out)
}

/// An approach–retract curve in amplitude setpoints: what an AFM records while its z
/// feedback holds each setpoint of `ratios` in turn (A/A₀ with the ramp's direction),
/// carrying the oscillator from one to the next.
#[derive(Debug, Clone)]
pub struct SetpointSweep {
    /// The states, one per setpoint held (each at A/A₀ = its setpoint to
    /// [`AMPLITUDE_TOLERANCE`]), in the ramp's order.
    pub points: Vec<sweep::SweepPoint>,
    /// The setpoints not held, each with why (the amplitude jumps across it between two
    /// rest separations, or the motion around it is not period-1).
    pub not_held: Vec<(f64, sweep::Direction, String)>,
}

/// Most steady states one setpoint of a [`sweep_setpoints`] ramp may take to bracket it.
const WALK_STEPS: usize = 200;

/// The approach–retract curve at the setpoints `ratios` ((A/A₀, direction) in order):
/// from the free oscillation at 1.2 A₀, the rest separation is walked towards each
/// setpoint in turn as a z feedback moves it (steps of the amplitude error times A₀, a
/// unit slope dA/dz_c, at most 0.05 A₀), each steady state started from the one before,
/// until two neighbouring states bracket it; the rest separation is then refined between
/// them (Illinois, as [`states_on`]) to [`AMPLITUDE_TOLERANCE`]. The states carried are
/// those a z-sweep through the same rest separations reaches
/// ([`sweep::approach_curve`]). A setpoint bracketed by states that are not both stable
/// period-1 orbits of one branch (the amplitude jumps across it, or the motion there is
/// not period-1) is not held; it is listed with why, and the walk goes on from the
/// bracket's far end.
pub fn sweep_setpoints(
    setup: &TapSetup,
    numerics: &Numerics,
    ratios: &[(f64, sweep::Direction)],
    mut progress: impl FnMut(usize, usize),
) -> Result<SetpointSweep> {
    for &(r, _) in ratios {
        check_ratio(r)?;
    }
    let p = Prepared::new(setup, numerics)?;
    let mut here = far_from_the_sample(&p)?;
    let mut out = SetpointSweep {
        points: Vec::with_capacity(ratios.len()),
        not_held: Vec::new(),
    };
    for (i, &(ratio, direction)) in ratios.iter().enumerate() {
        match hold(&p, &mut here, ratio)? {
            Ok(s) => out.points.push(sweep::SweepPoint {
                separation_m: s.separation_m,
                direction,
                observables: s.observables,
                thermal_average: None,
            }),
            Err(why) => out.not_held.push((ratio, direction, why)),
        }
        progress(i + 1, ratios.len());
    }
    Ok(out)
}

/// The free oscillation settled at 1.2 A₀, where a ramp starts.
fn far_from_the_sample(p: &Prepared) -> Result<BranchRecord> {
    let mut phase = p.simulation().free_steady_start();
    settled(p, 1.2 * p.setup.cantilever.free_amplitude_m, &mut phase)
}

/// The steady state at rest separation `z_m` started from `phase` (left on it).
fn settled(p: &Prepared, z_m: f64, phase: &mut Phase) -> Result<BranchRecord> {
    let state = p.simulation_at(z_m)?.steady_state(phase, &p.steady)?;
    Ok(record(z_m, TapObservables::new(p, &state)?, phase.clone()))
}

/// A state found by settling or solving at `separation_m`, as an orbit of a family
/// (one piece, a regular point) for the bracketing and refining that follow.
fn record(separation_m: f64, observables: TapObservables, phase: Phase) -> BranchRecord {
    BranchRecord {
        separation_m,
        segment: 0,
        point: sweep::BranchPointKind::Regular,
        observables,
        phase,
    }
}

/// Walk the rest separation from the state `here` to the setpoint `ratio`, as a z
/// feedback moves it ([`sweep_setpoints`]), and solve the state there; `here` is left on
/// the state reached (the solved one, or the bracket's far end). `Err(why)` (inside the
/// `Ok`) where the setpoint is not held.
fn hold(
    p: &Prepared,
    here: &mut BranchRecord,
    ratio: f64,
) -> Result<std::result::Result<SetpointState, String>> {
    let a0 = p.setup.cantilever.free_amplitude_m;
    let free = free_phase_deg(&p.setup);
    let held =
        |b: &BranchRecord| b.observables.period == Some(1) && b.observables.stable == Some(true);
    let mut bracket = None;
    for _ in 0..WALK_STEPS {
        let error = here.observables.amplitude_ratio - ratio;
        if error == 0.0 {
            bracket = Some((here.clone(), here.clone()));
            break;
        }
        let step = (-error * a0).clamp(-0.05 * a0, 0.05 * a0);
        let step = if step.abs() < 1e-4 * a0 {
            1e-4 * a0 * step.signum()
        } else {
            step
        };
        if here.separation_m + step < -a0 {
            // A tip pressed in by more than A₀ at rest: no setpoint lies beyond.
            break;
        }
        let mut phase = here.phase.clone();
        let next = settled(p, here.separation_m + step, &mut phase)?;
        let crossed = (next.observables.amplitude_ratio - ratio) * error <= 0.0;
        let before = std::mem::replace(here, next);
        if crossed {
            bracket = Some((before, here.clone()));
            break;
        }
    }
    let Some((a, b)) = bracket else {
        return Ok(Err(format!(
            "the amplitude does not reach it (A/A₀ = {:.4} at z_c = {:.4} nm)",
            here.observables.amplitude_ratio,
            here.separation_m * 1e9
        )));
    };
    let side = PhaseBranch::of(a.observables.phase_deg, free);
    let other = PhaseBranch::of(b.observables.phase_deg, free);
    if held(&a) && held(&b) && other == side {
        if let Some(s) = refine(p, (&a, &b), ratio, side, free)? {
            // Carry on from the state at the setpoint.
            *here = record(s.separation_m, s.observables.clone(), s.phase.clone());
            return Ok(Ok(s));
        }
    }
    let describe = |o: &TapObservables| {
        // (A periodic orbit without a stability grazes a jump of the law.)
        if o.grazing || (o.period.is_some() && o.stable.is_none()) {
            format!("{} grazing a switch", o.regime)
        } else if o.stable == Some(false) {
            format!("an unstable {}", o.regime)
        } else {
            o.regime.clone()
        }
    };
    let (za, zb) = (a.separation_m * 1e9, b.separation_m * 1e9);
    Ok(Err(if !(held(&a) && held(&b)) {
        format!(
            "the states that bracket it (z_c = {za:.4} and {zb:.4} nm) are {} and {}; a \
             setpoint is solved between stable period-1 orbits only",
            describe(&a.observables),
            describe(&b.observables)
        )
    } else {
        format!(
            "the amplitude jumps across it between z_c = {za:.4} and {zb:.4} nm (A/A₀ \
             {:.4} to {:.4}, the {side} to the {other} branch)",
            a.observables.amplitude_ratio, b.observables.amplitude_ratio,
        )
    }))
}

/// The cells numbered `cells` of the adhesion × modulus map ([`sweep::map_cells`]) at the
/// amplitude setpoint `ratio` on `branch`: each cell's first state there
/// ([`states_at_setpoint`]) and the rest separation that holds it, with `noise` its
/// phase's thermal noise ([`SetpointState::thermal_noise`]); a cell whose law does not
/// apply or whose branch does not reach the setpoint carries the reason as its note.
#[allow(clippy::too_many_arguments)]
pub fn map_cells(
    setup: &TapSetup,
    numerics: &Numerics,
    axes: (&[f64], &[f64]),
    cells: &[usize],
    threads: usize,
    progress: impl Fn() + Sync,
    (ratio, branch): (f64, PhaseBranch),
    noise: Option<&crate::instrument::noise::NoiseRequest>,
) -> Result<Vec<sweep::MapCell>> {
    check_ratio(ratio)?;
    let solve = |s: &TapSetup| {
        let states = states_at_setpoint(s, numerics, ratio, Some(branch))?;
        let first = states.into_iter().next().expect("a list is never empty");
        let sigma = match noise {
            Some(request) => Some(
                first
                    .thermal_noise(&Prepared::new(s, numerics)?, request)?
                    .sigma_phase_deg,
            ),
            None => None,
        };
        Ok(sweep::CellState {
            observables: first.observables,
            separation_m: Some(first.separation_m),
            sigma_phase_deg: sigma,
            thermal_average: None,
        })
    };
    sweep::map_cells_with(setup, axes, cells, threads, progress, &solve)
}

/// The state at amplitude `ratio` on `side` found from the harmonic estimate of it, if
/// that leads to one. The estimate: the motion x = A cos(Ωτ − φ) with A = ratio·A₀ and,
/// from the balance of drive and damping with a conservative contact (García & San Paulo,
/// PRB 60, 4961, 1999), sin φ = ratio·sin φ_free (φ above 90° on the attractive branch,
/// below on the repulsive), at a rest separation z_c = A + 0.04 A₀ (attractive: the
/// tip reaches into the attraction) or A − 0.15 A₀ (repulsive: it indents and is pushed
/// back), then 0.1 A₀ deeper, 0.1 A₀ out and 0.2 A₀ deeper ([`seed_at`]: Newton's method
/// from the estimate, or the motion settled from it). From the first stable period-1
/// orbit on `side` its family is followed (0.02 A₀ steps) towards the rest separation at
/// which a unit slope dA/dz_c would put the setpoint, 0.05 A₀ beyond, and the state
/// refined between the stable orbits that bracket the setpoint ([`states_on`]). `None`
/// where the orbit found is not stable or on another branch, or the family is not
/// followed as far as the setpoint; the caller then searches the whole family.
fn near_estimate(
    p: &Prepared,
    numerics: &Numerics,
    ratio: f64,
    side: PhaseBranch,
) -> Result<Option<SetpointState>> {
    use crate::dynamics::continuation::{ContinuationOptions, follow_period_one};
    let a0 = p.setup.cantilever.free_amplitude_m;
    let free = free_phase_deg(&p.setup);
    let lag = (ratio * free.to_radians().sin()).clamp(-1.0, 1.0).asin();
    let (phi, q) = match side {
        PhaseBranch::Attractive => (std::f64::consts::PI - lag, ratio + 0.04),
        PhaseBranch::Repulsive => (lag, ratio - 0.15),
    };
    let tolerance = (1e-2 * numerics.tolerance).max(1e-12);
    // The estimate's rest separation first, then 0.1 A₀ deeper, out and 0.2 A₀ deeper
    // (a sample that pulls the tip in or gives under it moves the state inwards).
    let mut found = None;
    for q in [q, q - 0.1, q + 0.1, q - 0.2] {
        if q > 0.02 {
            found = seed_at(p, tolerance, (ratio, phi), side, q)?;
        }
        if found.is_some() {
            break;
        }
    }
    let Some((q, seed)) = found else {
        return Ok(None);
    };
    let sim = p.simulation_at(q * a0)?;
    let o = &seed.observables;
    // Towards the setpoint at unit slope, and 0.05 A₀ beyond.
    let shift = ratio - o.amplitude_ratio;
    let q_end = (q + shift + 0.05 * shift.signum()).max(0.02);
    let opts = ContinuationOptions {
        q_end,
        max_step: 0.02,
        tolerance,
        ..ContinuationOptions::default()
    };
    let Ok(followed) = follow_period_one(&sim, &seed.phase, &opts) else {
        return Ok(None);
    };
    let family = followed
        .points
        .iter()
        .map(|b| sweep::BranchRecord::new(p, b, 0))
        .collect::<Result<Vec<_>>>()?;
    Ok(states_on(p, &family, ratio, Some(side))?.into_iter().next())
}

/// A stable period-1 orbit on `side` at rest separation q·A₀ from the harmonic estimate
/// of amplitude ratio·A₀ and phase lag φ ([`near_estimate`]): Newton's method from it,
/// or, where that does not converge, the motion settled from it. `None` where neither
/// gives one.
fn seed_at(
    p: &Prepared,
    tolerance: f64,
    (ratio, phi): (f64, f64),
    side: PhaseBranch,
    q: f64,
) -> Result<Option<(f64, BranchRecord)>> {
    use crate::dynamics::continuation::{ContinuationOptions, follow_period_one};
    let a0 = p.setup.cantilever.free_amplitude_m;
    let sim = p.simulation_at(q * a0)?;
    let free = sim.free_steady_start();
    let omega = sim.osc.omega;
    let amplitude = free.x.hypot(free.v / omega);
    if amplitude == 0.0 {
        // A base drive: no harmonic estimate.
        return Ok(None);
    }
    let scale = ratio * amplitude;
    let (s, c) = phi.sin_cos();
    let start = Phase {
        x: scale * c,
        v: omega * scale * s,
        branch: sim.branch_at(0.0, scale * c),
        ..free
    };
    let first = ContinuationOptions {
        q_end: q - 0.1,
        max_points: 1,
        tolerance,
        ..ContinuationOptions::default()
    };
    let seed = match follow_period_one(&sim, &start, &first) {
        Ok(seed) => BranchRecord::new(p, &seed.points[0], 0)?,
        Err(_) => {
            let mut phase = start;
            let Ok(state) = sim.steady_state(&mut phase, &p.steady) else {
                return Ok(None);
            };
            record(q * a0, TapObservables::new(p, &state)?, phase)
        }
    };
    let o = &seed.observables;
    let on = o.period == Some(1)
        && o.stable == Some(true)
        && PhaseBranch::of(o.phase_deg, free_phase_deg(&p.setup)) == side;
    Ok(on.then_some((q, seed)))
}

/// `states` without repeats (the same branch within 1e-6 A₀ of rest separation),
/// attractive first, each branch in order of rest separation.
fn distinct(mut states: Vec<SetpointState>, a0: f64) -> Vec<SetpointState> {
    states.sort_by(|x, y| x.separation_m.total_cmp(&y.separation_m));
    states.dedup_by(|x, y| {
        x.branch == y.branch && (x.separation_m - y.separation_m).abs() < 1e-6 * a0
    });
    states.sort_by_key(|s| s.branch == PhaseBranch::Repulsive);
    states
}

/// The states at amplitude `ratio` on the stable period-1 `family` ([`families`]), on
/// `branch` (`None`: both), attractive first: wherever two neighbouring stable orbits of
/// one piece bracket the setpoint, the rest separation refined until the amplitude is
/// the setpoint to [`AMPLITUDE_TOLERANCE`].
pub fn states_on(
    p: &Prepared,
    family: &[BranchRecord],
    ratio: f64,
    branch: Option<PhaseBranch>,
) -> Result<Vec<SetpointState>> {
    let free = free_phase_deg(&p.setup);
    let stable = |b: &BranchRecord| b.observables.stable == Some(true);
    let mut out: Vec<SetpointState> = Vec::new();
    for w in family.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let (ra, rb) = (a.observables.amplitude_ratio, b.observables.amplitude_ratio);
        if a.segment != b.segment || !stable(a) || !stable(b) || (ra - ratio) * (rb - ratio) > 0.0 {
            continue;
        }
        let side = PhaseBranch::of(a.observables.phase_deg, free);
        if PhaseBranch::of(b.observables.phase_deg, free) != side
            || branch.is_some_and(|want| want != side)
        {
            continue;
        }
        if let Some(state) = refine(p, (a, b), ratio, side, free)? {
            out.push(state);
        }
    }
    // The same state reached along two families once.
    Ok(distinct(out, p.setup.cantilever.free_amplitude_m))
}

/// How far out and in a family is followed from a seed, in units of A₀.
const WINDOW: f64 = 0.15;

/// The stable period-1 families between the rest separations `far` and `deep`, as one
/// list whose pieces are told apart by `segment`: the one the free oscillation settles
/// on at `far` (over `p`, run with `numerics`), followed in to `deep`, and the one it
/// settles on at each seed z_c =
/// `deep` + 0.1 A₀, + 0.2 A₀, … where that is another family than those followed
/// already, followed `WINDOW` (0.15 A₀) out and in from there. In a bistable zone these are the attractive
/// and the repulsive branch: the free oscillation started close to the sample lands on
/// the repulsive one, started far on the attractive one.
pub fn families(
    p: &Prepared,
    numerics: &Numerics,
    (far, deep): (f64, f64),
) -> Result<Vec<BranchRecord>> {
    let setup = &p.setup;
    let a0 = setup.cantilever.free_amplitude_m;
    let step = 0.01 * a0;
    let free = free_phase_deg(setup);
    let mut all: Vec<BranchRecord> = Vec::new();
    let follow = |all: &mut Vec<BranchRecord>, from: f64, to: f64| {
        // A start where the motion is not period-1 only loses that family.
        // Motion that is not period-1 crossed in strides of 0.05 A₀.
        let gap = (5.0 * step).min((from - to).abs()).max(step);
        if let Ok(family) = sweep::orbit_branch_across_gaps(setup, numerics, (from, to), step, gap)
        {
            let offset = all.last().map_or(0, |b| b.segment + 1);
            all.extend(family.points.into_iter().map(|mut b| {
                b.segment += offset;
                b
            }));
        }
    };
    follow(&mut all, far, deep);
    let seeds = ((far - deep) / (0.1 * a0)).floor() as usize;
    for k in 1..=seeds {
        let seed = deep + 0.1 * a0 * k as f64;
        let mut phase = p.simulation().free_steady_start();
        let Ok(state) = p.simulation_at(seed)?.steady_state(&mut phase, &p.steady) else {
            continue;
        };
        let o = TapObservables::new(p, &state)?;
        if o.period != Some(1) || o.stable != Some(true) {
            continue;
        }
        let side = PhaseBranch::of(o.phase_deg, free);
        // Already followed: a stable orbit of the same branch and amplitude nearby.
        let known = all.iter().any(|b| {
            (b.separation_m - seed).abs() < 2.0 * step
                && b.observables.stable == Some(true)
                && PhaseBranch::of(b.observables.phase_deg, free) == side
                && (b.observables.amplitude_ratio - o.amplitude_ratio).abs() < 0.02
        });
        if !known {
            // A window around the seed: the next seed lies inside it, and a setpoint
            // near the seed's amplitude is bracketed within it.
            follow(&mut all, seed, (seed + WINDOW * a0).min(far));
            follow(&mut all, seed, (seed - WINDOW * a0).max(deep));
        }
    }
    Ok(all)
}

/// Why no state was found: the amplitudes each branch's stable period-1 orbits reach.
fn unreached(
    family: &[BranchRecord],
    ratio: f64,
    branch: Option<PhaseBranch>,
    free: f64,
    (far, deep): (f64, f64),
) -> String {
    let reach = |side: PhaseBranch| {
        let on: Vec<f64> = family
            .iter()
            .filter(|b| {
                b.observables.stable == Some(true)
                    && b.observables.jumps_in > 0.0
                    && PhaseBranch::of(b.observables.phase_deg, free) == side
            })
            .map(|b| b.observables.amplitude_ratio)
            .collect();
        match (
            on.iter().copied().reduce(f64::min),
            on.iter().copied().reduce(f64::max),
        ) {
            (Some(lo), Some(hi)) => format!("{side} from A/A₀ {lo:.4} to {hi:.4}"),
            _ => format!("none {side}"),
        }
    };
    let which = branch.map_or("any branch".to_string(), |b| format!("the {b} branch"));
    format!(
        "no stable period-1 steady state on {which} has A/A₀ = {} (between z_c = {:.3} \
         and {:.3} nm the stable period-1 orbits that touch reach: {}; {})",
        shown(ratio),
        far * 1e9,
        deep * 1e9,
        reach(PhaseBranch::Attractive),
        reach(PhaseBranch::Repulsive)
    )
}

/// A setpoint as a message shows it: plainly, or with an exponent where it is tiny or
/// huge.
fn shown(ratio: f64) -> String {
    if (1e-4..1e4).contains(&ratio.abs()) {
        format!("{ratio}")
    } else {
        format!("{ratio:e}")
    }
}

/// The steady state at amplitude `ratio` between the neighbouring stable orbits `a` and
/// `b` of one piece of the family on branch `side`: the Illinois method on the rest
/// separation, each steady state started from the bracketing orbit nearer to it. `None`
/// where a steady state leaves the branch or the period-1 family (the family is then not
/// smooth here).
fn refine(
    p: &Prepared,
    (a, b): (&BranchRecord, &BranchRecord),
    ratio: f64,
    side: PhaseBranch,
    free: f64,
) -> Result<Option<SetpointState>> {
    // (z_c, A/A₀ − ratio, the state's phase at the drive phase) at both ends.
    let end = |r: &BranchRecord| {
        (
            r.separation_m,
            r.observables.amplitude_ratio - ratio,
            r.phase.clone(),
        )
    };
    let (mut lo, mut hi) = (end(a), end(b));
    let mut best: Option<(f64, SetpointState)> = None;
    let mut side_moved: i32 = 0;
    for _ in 0..60 {
        let (z0, f0, _) = lo;
        let (z1, f1, _) = hi;
        let z = if f1 != f0 {
            z0 - f0 * (z1 - z0) / (f1 - f0)
        } else {
            0.5 * (z0 + z1)
        };
        let z = if (z - z0) * (z - z1) < 0.0 {
            z
        } else {
            0.5 * (z0 + z1)
        };
        let mut phase: Phase = if (z - z0).abs() < (z - z1).abs() {
            lo.2.clone()
        } else {
            hi.2.clone()
        };
        let sim = p.simulation_at(z)?;
        let state = sim.steady_state(&mut phase, &p.steady)?;
        let o = TapObservables::new(p, &state)?;
        if o.period != Some(1)
            || o.stable != Some(true)
            || PhaseBranch::of(o.phase_deg, free) != side
        {
            return Ok(None);
        }
        let f = o.amplitude_ratio - ratio;
        if best.as_ref().is_none_or(|(e, _)| f.abs() < *e) {
            best = Some((
                f.abs(),
                SetpointState {
                    branch: side,
                    separation_m: z,
                    observables: o,
                    phase: phase.clone(),
                },
            ));
        }
        if f.abs() <= AMPLITUDE_TOLERANCE {
            break;
        }
        // Illinois: halve the value kept at the end that stays twice running.
        if (f < 0.0) == (f0 < 0.0) {
            lo = (z, f, phase);
            if side_moved == -1 {
                hi.1 *= 0.5;
            }
            side_moved = -1;
        } else {
            hi = (z, f, phase);
            if side_moved == 1 {
                lo.1 *= 0.5;
            }
            side_moved = 1;
        }
        if (hi.0 - lo.0).abs() < 1e-15 * p.setup.cantilever.free_amplitude_m {
            break;
        }
    }
    Ok(best
        .filter(|(e, _)| *e <= 100.0 * AMPLITUDE_TOLERANCE)
        .map(|(_, s)| s))
}
