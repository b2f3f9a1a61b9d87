//! Bimodal AFM as an instrument uses it: approach curves of several eigenmodes (each
//! point continued from the last), the rest separation at which the first mode holds an
//! amplitude setpoint, and the second mode's phase contrast between materials there
//! (Lozano & García, PRL 100, 076102, 2008: φ₂ at a fixed A₁/A₀₁ tells materials
//! apart that φ₁ does not).

use crate::analysis::contrast::Material;
pub use crate::analysis::setpoint::PhaseBranch;
use crate::dynamics::modes::orbit::{ModalOrbit, free_section};
use crate::dynamics::modes::{Modal, ModalObservables, ModeSet, modal_steady, prepare};
use crate::dynamics::setup::{Numerics, Prepared, TapSetup};
use crate::error::{Error, Result};
use crate::physics::law::LawKind;
use rayon::prelude::*;
use serde::Serialize;

/// One point of a several-mode approach curve.
#[derive(Debug, Clone, Serialize)]
pub struct ModalPoint {
    /// Rest separation z_c, m.
    pub separation_m: f64,
    /// The steady state there (none: not found, see `note`).
    pub state: Option<ModalObservables>,
    /// Why there is no state.
    pub note: Option<String>,
}

/// The prepared setup moved to rest separation `separation_m`.
fn at_separation(p: &Prepared, separation_m: f64) -> Result<Prepared> {
    let a0 = p.setup.cantilever.free_amplitude_m;
    if !(separation_m.is_finite() && separation_m > -a0 && separation_m < 100.0 * a0) {
        return Err(Error::OutOfRange(format!(
            "rest separation {separation_m:e} m is outside −A₀ … 100 A₀"
        )));
    }
    let mut q = p.clone();
    q.cpl.a0 = separation_m / p.setup.contact.separation_scale_m();
    q.setup.separation_m = separation_m;
    Ok(q)
}

/// The steady state at `separation_m`, continued from `from` where given (and started
/// afresh if that fails).
fn solve_at(
    p: &Prepared,
    modal: &Modal,
    numerics: &Numerics,
    separation_m: f64,
    from: Option<&ModalOrbit>,
) -> Result<(ModalObservables, ModalOrbit)> {
    crate::interrupt::check()?;
    let q = at_separation(p, separation_m)?;
    if let Some(o) = from {
        if let Ok(found) = modal_steady(&q, modal, numerics, Some((&o.section, o.branch))) {
            return Ok(found);
        }
    }
    modal_steady(&q, modal, numerics, None)
}

/// The approach curve over `separations_m` (taken in the order given, each point started
/// from the last one's orbit: what a slow approach follows).
pub fn approach(
    p: &Prepared,
    modal: &Modal,
    numerics: &Numerics,
    separations_m: &[f64],
    mut progress: impl FnMut(),
) -> Result<Vec<ModalPoint>> {
    modal.common_period()?;
    let mut last: Option<ModalOrbit> = None;
    let mut points = Vec::with_capacity(separations_m.len());
    for &z in separations_m {
        let found = solve_at(p, modal, numerics, z, last.as_ref());
        progress();
        points.push(match found {
            Ok((state, orbit)) => {
                last = Some(orbit);
                ModalPoint {
                    separation_m: z,
                    state: Some(state),
                    note: None,
                }
            }
            Err(Error::Interrupted) => return Err(Error::Interrupted),
            Err(e) => {
                last = None;
                ModalPoint {
                    separation_m: z,
                    state: None,
                    note: Some(e.to_string()),
                }
            }
        });
    }
    Ok(points)
}

/// The first mode's amplitude ratio A₁/A₀₁ of a state.
pub fn first_ratio(s: &ModalObservables) -> f64 {
    s.modes[0].amplitude_ratio.unwrap_or(f64::NAN)
}

/// A steady state of the modes at a first-mode amplitude setpoint, on its branch.
#[derive(Debug, Clone, Serialize)]
pub struct ModalSetpointState {
    /// The first mode's branch (attractive: φ₁ above the free phase).
    pub branch: PhaseBranch,
    /// The state.
    #[serde(flatten)]
    pub observables: ModalObservables,
}

/// The step along z_c (units of A₀₁) from a one-mode state to the modes' state at the
/// same setpoint, and the most steps taken.
const WALK: f64 = 0.005;
const WALK_STEPS: usize = 200;

/// The several-mode steady states whose first-mode amplitude is `setpoint` × A₀₁, on
/// `branch` (`None`: both; attractive first), each with why where the modes keep none.
/// Where one mode holds a setpoint on two branches (coexisting attractors: which one an
/// AFM images on depends on its history) so may the modes; and on one branch the higher
/// modes may hold more than one state (a second mode of high Q can itself be bistable).
/// Each branch's states are seeded at the one-mode state there
/// ([`crate::analysis::setpoint::states_at_setpoint`]) with the higher modes started from
/// [`SEEDS`] (their free oscillation, inverted, at rest); each distinct one is followed
/// along z_c to the setpoint (to 1e-7 of A₁/A₀₁). A branch may then list several
/// states, the one from the free oscillation first; a state whose φ₁ crosses to the other
/// side of the free phase on the way is not the branch's and is refused.
pub fn states_at_setpoint(
    setup: &TapSetup,
    set: &ModeSet,
    numerics: &Numerics,
    setpoint: f64,
    branch: Option<PhaseBranch>,
) -> Result<Vec<(PhaseBranch, Result<ModalSetpointState>)>> {
    let (p, modal) = prepare(setup, set, numerics)?;
    modal.common_period()?;
    let one = crate::analysis::setpoint::states_at_setpoint(setup, numerics, setpoint, branch)?;
    from_one_mode((&p, &modal, numerics), setpoint, one)
}

/// The modes' states at `setpoint` seeded at the one-mode states `one` that hold it
/// ([`states_at_setpoint`]), `p` and `modal` the setup prepared ([`prepare`]).
fn from_one_mode(
    (p, modal, numerics): (&Prepared, &Modal, &Numerics),
    setpoint: f64,
    one: Vec<crate::analysis::setpoint::SetpointState>,
) -> Result<Vec<(PhaseBranch, Result<ModalSetpointState>)>> {
    let free_phase = crate::analysis::setpoint::free_phase_deg(&p.setup);
    let mut out = Vec::new();
    for s in one {
        let side = s.branch;
        let q = at_separation(p, s.separation_m)?;
        let mut seeds: Vec<(ModalObservables, ModalOrbit)> = Vec::new();
        let mut failure = None;
        for (k, scale) in SEEDS.into_iter().enumerate() {
            let mut start = free_section(&modal.modes, Some((s.phase.x, s.phase.v)));
            start[2..].iter_mut().for_each(|z| *z *= scale);
            // The other seeds look for other states nearby: Newton's method and a short
            // march only (a long march from them finds what the first one's finds).
            let seed_numerics = Numerics {
                max_cycles: if k == 0 {
                    numerics.max_cycles
                } else {
                    SEED_MARCH * modal.common_period()?.0 as usize
                },
                ..*numerics
            };
            match modal_steady(&q, modal, &seed_numerics, Some((&start, s.phase.branch))) {
                Ok((state, orbit)) => {
                    if PhaseBranch::of(state.modes[0].phase_deg, free_phase) != side {
                        failure = Some(crossed(side, setpoint, s.separation_m));
                    } else if !seeds.iter().any(|(o, _)| same_state(o, &state)) {
                        seeds.push((state, orbit));
                    }
                }
                Err(Error::Interrupted) => return Err(Error::Interrupted),
                Err(e) => failure = failure.or(Some(e)),
            }
        }
        let mut found: Vec<ModalSetpointState> = Vec::new();
        for (state, orbit) in seeds {
            let followed = follow(
                (p, modal, numerics),
                (setpoint, side, free_phase),
                (s.separation_m, state, orbit),
            );
            match followed {
                Ok(f)
                    if found
                        .iter()
                        .any(|g| same_state(&g.observables, &f.observables)) => {}
                Ok(f) => found.push(f),
                Err(Error::Interrupted) => return Err(Error::Interrupted),
                Err(e) => failure = Some(e),
            }
        }
        if found.is_empty() {
            out.push((side, Err(failure.expect("every seed failed, and said why"))));
        }
        out.extend(found.into_iter().map(|f| (side, Ok(f))));
    }
    Ok(out)
}

/// The scales of the higher modes' free oscillation the states at a setpoint are seeded
/// with ([`states_at_setpoint`]).
pub const SEEDS: [f64; 3] = [1.0, -1.0, 0.0];

/// Common periods a seed other than the first is marched at most where Newton's method
/// does not converge from it.
const SEED_MARCH: usize = 10;

/// Whether two states are one (their z_c and every mode's amplitude and phase agree).
fn same_state(a: &ModalObservables, b: &ModalObservables) -> bool {
    (a.separation_m - b.separation_m).abs() <= 1e-6 * a.separation_m.abs().max(1e-9)
        && a.modes.iter().zip(&b.modes).all(|(x, y)| {
            (x.phase_deg - y.phase_deg).abs() <= 0.01
                && (x.amplitude_m - y.amplitude_m).abs() <= 1e-4 * x.free_amplitude_m.max(1e-12)
        })
}

/// Why a state is not the branch's.
fn crossed(side: PhaseBranch, setpoint: f64, z: f64) -> Error {
    Error::NotApplicable(format!(
        "the {side} state of one mode at A/A₀ = {setpoint} is not kept with the higher \
         modes: φ₁ crosses to the other side of the free phase near z_c = {:.4} nm",
        z * 1e9
    ))
}

/// The state of `side` holding `setpoint`, followed from `state` (with its orbit) at
/// z_c = `z0`: along z_c towards the setpoint in steps of [`WALK`] A₀₁, each continued
/// from the last, to the first crossing; then regula falsi inside it.
fn follow(
    (p, modal, numerics): (&Prepared, &Modal, &Numerics),
    (setpoint, side, free_phase): (f64, PhaseBranch, f64),
    (z0, state, orbit): (f64, ModalObservables, ModalOrbit),
) -> Result<ModalSetpointState> {
    let a0 = p.setup.cantilever.free_amplitude_m;
    let crossed = |z: f64| crossed(side, setpoint, z);
    // A₁ grows with z_c. (It can turn steep near the end of a branch, and more than
    // one state of a branch may hold a setpoint: this is the one joined to `state`.)
    let miss0 = first_ratio(&state) - setpoint;
    let dir = if miss0 > 0.0 { -1.0 } else { 1.0 };
    let mut near = (z0, miss0, state, orbit);
    let mut far: Option<(f64, f64)> = None;
    for k in 1..=WALK_STEPS {
        if near.1.abs() <= 1e-7 {
            break;
        }
        let z = z0 + dir * WALK * a0 * k as f64;
        let (state, orbit) = solve_at(p, modal, numerics, z, Some(&near.3))?;
        if PhaseBranch::of(state.modes[0].phase_deg, free_phase) != side {
            return Err(crossed(z));
        }
        let miss = first_ratio(&state) - setpoint;
        if miss * near.1 <= 0.0 {
            far = Some((z, miss));
            break;
        }
        near = (z, miss, state, orbit);
    }
    if near.1.abs() <= 1e-7 {
        return Ok(ModalSetpointState {
            branch: side,
            observables: near.2,
        });
    }
    let Some(mut far) = far else {
        return Err(Error::NotApplicable(format!(
            "the modes' {side} branch does not reach A₁/A₀₁ = {setpoint} within \
                 {} A₀ of the one-mode state (A₁/A₀₁ = {:.6} at z_c = {:.4} nm)",
            WALK * WALK_STEPS as f64,
            near.1 + setpoint,
            near.0 * 1e9
        )));
    };
    // Regula falsi (Illinois) between `near` (with its orbit) and `far`.
    let mut side_moved = 0i8;
    for _ in 0..60 {
        let (z0, m0, z1, m1) = (near.0, near.1, far.0, far.1);
        let z = if m0 != m1 {
            z0 - m0 * (z1 - z0) / (m1 - m0)
        } else {
            0.5 * (z0 + z1)
        };
        let (state, orbit) = solve_at(p, modal, numerics, z, Some(&near.3))?;
        if PhaseBranch::of(state.modes[0].phase_deg, free_phase) != side {
            return Err(crossed(z));
        }
        let miss = first_ratio(&state) - setpoint;
        if miss.abs() <= 1e-7 || (z1 - z0).abs() <= 1e-9 * a0 {
            if miss.abs() > 1e-5 {
                return Err(Error::NotApplicable(format!(
                    "the first mode's amplitude jumps across A₁/A₀₁ = \
                         {setpoint} near z_c = {:.4} nm on the modes' {side} branch",
                    z * 1e9
                )));
            }
            return Ok(ModalSetpointState {
                branch: side,
                observables: state,
            });
        }
        if miss * m0 > 0.0 {
            near = (z, miss, state, orbit);
            if side_moved == 1 {
                far.1 *= 0.5;
            }
            side_moved = 1;
        } else {
            far = (z, miss);
            if side_moved == -1 {
                near.1 *= 0.5;
            }
            side_moved = -1;
        }
    }
    Err(Error::NotApplicable(format!(
        "regula falsi on z_c did not reach A₁/A₀₁ = {setpoint} on the modes' \
             {side} branch"
    )))
}

/// The bimodal phase contrast at one setpoint for one law: each material's state.
#[derive(Debug, Clone, Serialize)]
pub struct BimodalRow {
    /// The law.
    pub law: String,
    /// The materials.
    pub materials: Vec<String>,
    /// A₁/A₀₁ held.
    pub setpoint: f64,
    /// The first mode's branch every state of the row is on.
    pub branch: PhaseBranch,
    /// φ₁ of each material (degrees; null where no state holds the setpoint).
    pub phase1_deg: Vec<Option<f64>>,
    /// φ₂ of each material (degrees).
    pub phase2_deg: Vec<Option<f64>>,
    /// A₂/A₀₂ of each material.
    pub amplitude2_ratio: Vec<Option<f64>>,
    /// E_ts per first-mode period of each material (J).
    pub e_ts_j: Vec<Option<f64>>,
    /// z_c of each (m).
    pub separation_m: Vec<Option<f64>>,
    /// Whether each state is a stable orbit.
    pub stable: Vec<Option<bool>>,
    /// φ₁(last) − φ₁(first), degrees.
    pub delta_phase1_deg: Option<f64>,
    /// φ₂(last) − φ₂(first), degrees: the bimodal contrast.
    pub delta_phase2_deg: Option<f64>,
    /// Why a material has no state: none holds the setpoint, or several coexist.
    pub notes: Vec<Option<String>>,
}

/// What one material has at one setpoint: each branch's state or why not, or why it has
/// none at all.
type Held = Result<Vec<(PhaseBranch, Result<ModalSetpointState>)>>;

/// φ₁ and φ₂ of every material at each first-mode setpoint under each law of `laws`
/// (each law and material in parallel, each counted by `progress` when done), rows by
/// law, setpoint and branch: where a setpoint is bistable both branches get a row, and
/// a contrast is taken only between states on the same branch.
pub fn contrast(
    materials: &[Material],
    set: &ModeSet,
    laws: &[LawKind],
    setpoints: &[f64],
    progress: impl Fn() + Sync,
) -> Result<Vec<BimodalRow>> {
    let jobs: Vec<(usize, usize)> = (0..laws.len())
        .flat_map(|l| (0..materials.len()).map(move |m| (l, m)))
        .collect();
    let results: Vec<Result<Vec<Held>>> = jobs
        .par_iter()
        .map(|&(l, m)| {
            let mut setup = materials[m].setup.clone();
            setup.law = laws[l].into();
            let numerics = &materials[m].numerics;
            let (one, modal) = prepare(&setup, set, numerics)?;
            modal.common_period()?;
            // The one-mode families once for every setpoint (as one mode's contrast
            // takes them), the whole search only where they hold none.
            let a0 = setup.cantilever.free_amplitude_m;
            let lowest = setpoints.iter().copied().fold(1.0f64, f64::min);
            let family = crate::analysis::setpoint::families(
                &one,
                numerics,
                (1.2 * a0, (lowest - 0.35).max(0.02) * a0),
            )?;
            let held = setpoints
                .iter()
                .map(|&r| {
                    let found = crate::analysis::setpoint::check_ratio(r)
                        .and_then(|()| crate::analysis::setpoint::states_on(&one, &family, r, None))
                        .and_then(|on| match on.is_empty() {
                            true => crate::analysis::setpoint::states_at_setpoint(
                                &setup, numerics, r, None,
                            ),
                            false => Ok(on),
                        })
                        .and_then(|on| from_one_mode((&one, &modal, numerics), r, on));
                    match found {
                        Err(Error::Interrupted) => Err(Error::Interrupted),
                        found => Ok(found),
                    }
                })
                .collect::<Result<Vec<Held>>>();
            progress();
            held
        })
        .collect();
    let mut states = Vec::with_capacity(results.len());
    for r in results {
        states.push(r?);
    }
    let mut rows = Vec::new();
    for (l, law) in laws.iter().enumerate() {
        for (k, &setpoint) in setpoints.iter().enumerate() {
            for branch in [PhaseBranch::Attractive, PhaseBranch::Repulsive] {
                // Each material's entry on this branch: its state, why the modes keep
                // none, or (None) no state of one mode there either.
                // Each material's state on this branch; or why it has none, or the
                // coexisting states of the modes it holds the setpoint in (then no one of
                // them is the material's).
                let entry = |m: usize| -> std::result::Result<&ModalObservables, String> {
                    let found = match &states[l * materials.len() + m][k] {
                        Err(e) => return Err(e.to_string()),
                        Ok(found) => found,
                    };
                    let on: Vec<&Result<ModalSetpointState>> = found
                        .iter()
                        .filter(|(b, _)| *b == branch)
                        .map(|(_, s)| s)
                        .collect();
                    match on.as_slice() {
                        [] => Err(format!(
                            "no stable state of the first mode holds A₁/A₀₁ = {setpoint} on \
                             the {branch} branch"
                        )),
                        [Ok(s)] => Ok(&s.observables),
                        [Err(e)] => Err(e.to_string()),
                        several => Err(format!(
                            "the modes hold the setpoint here in {} coexisting states ({}): \
                             which one an AFM images on depends on its history, so no phase \
                             is given",
                            several.len(),
                            several
                                .iter()
                                .filter_map(|s| s.as_ref().ok())
                                .map(|s| {
                                    let o = &s.observables;
                                    format!(
                                        "φ₁ = {:.4}°, φ₂ = {:.4}° at z_c = {:.4} nm",
                                        o.modes[0].phase_deg,
                                        o.modes.get(1).map_or(f64::NAN, |m| m.phase_deg),
                                        o.separation_m * 1e9
                                    )
                                })
                                .collect::<Vec<_>>()
                                .join("; ")
                        )),
                    }
                };
                let on_branch = (0..materials.len()).any(|m| {
                    matches!(&states[l * materials.len() + m][k],
                        Ok(found) if found.iter().any(|(b, _)| *b == branch))
                });
                if !on_branch {
                    continue;
                }
                let each = |f: &dyn Fn(&ModalObservables) -> Option<f64>| {
                    (0..materials.len())
                        .map(|m| entry(m).ok().and_then(f))
                        .collect::<Vec<_>>()
                };
                let phase1 = each(&|s| Some(s.modes[0].phase_deg));
                let phase2 = each(&|s| s.modes.get(1).map(|m| m.phase_deg));
                let delta = |v: &[Option<f64>]| match (v.first(), v.last()) {
                    (Some(Some(a)), Some(Some(b))) if v.len() > 1 => Some(b - a),
                    _ => None,
                };
                rows.push(BimodalRow {
                    law: law.to_string(),
                    materials: materials.iter().map(|m| m.name.clone()).collect(),
                    setpoint,
                    branch,
                    delta_phase1_deg: delta(&phase1),
                    delta_phase2_deg: delta(&phase2),
                    phase1_deg: phase1,
                    phase2_deg: phase2,
                    amplitude2_ratio: each(&|s| s.modes.get(1).and_then(|m| m.amplitude_ratio)),
                    e_ts_j: each(&|s| Some(s.e_ts_j)),
                    separation_m: each(&|s| Some(s.separation_m)),
                    stable: (0..materials.len())
                        .map(|m| entry(m).ok().map(|s| s.stable))
                        .collect(),
                    notes: (0..materials.len()).map(|m| entry(m).err()).collect(),
                });
            }
        }
    }
    Ok(rows)
}

/// One cell of a several-mode map over (Δγ, E*).
#[derive(Debug, Clone, Serialize)]
pub struct ModalCell {
    /// Work of adhesion, J/m².
    pub work_of_adhesion_j_m2: f64,
    /// Composite modulus, Pa.
    pub modulus_pa: f64,
    /// Tabor parameter.
    pub tabor_mu: f64,
    /// The rest separation of the state (m; at a first-mode setpoint, where the state
    /// holds it).
    pub separation_m: Option<f64>,
    /// A₁/A₀₁.
    pub amplitude1_ratio: Option<f64>,
    /// φ₁, degrees.
    pub phase1_deg: Option<f64>,
    /// A₂/A₀₂.
    pub amplitude2_ratio: Option<f64>,
    /// φ₂, degrees.
    pub phase2_deg: Option<f64>,
    /// E_ts per first-mode period, J.
    pub e_ts_j: Option<f64>,
    /// Whether the orbit is stable.
    pub stable: Option<bool>,
    /// Why the cell has no state.
    pub note: Option<String>,
}

/// The several-mode state of every cell of the (Δγ, E*) grid (cells in parallel on
/// `threads`, 0: every core): at the setup's rest separation, or at the first-mode
/// setpoint on the branch given ([`states_at_setpoint`]; a cell whose modes hold it in
/// several states lists that instead). A cell without a periodic state is listed with why.
pub fn map_cells(
    setup: &crate::dynamics::setup::TapSetup,
    set: &ModeSet,
    numerics: &Numerics,
    (works_j_m2, moduli_pa): (&[f64], &[f64]),
    threads: usize,
    progress: impl Fn() + Sync,
    setpoint: Option<(f64, PhaseBranch)>,
) -> Result<Vec<ModalCell>> {
    let every: Vec<usize> = (0..works_j_m2.len() * moduli_pa.len()).collect();
    Modal::new(&setup.cantilever, set)?.common_period()?;
    crate::analysis::sweep::over_grid(
        setup,
        (works_j_m2, moduli_pa),
        &every,
        threads,
        progress,
        |s, (w, e)| {
            let found = prepare(s, set, numerics).and_then(|(p, modal)| match setpoint {
                None => Ok(modal_steady(&p, &modal, numerics, None)?.0),
                Some((r, branch)) => {
                    let mut found = states_at_setpoint(s, set, numerics, r, Some(branch))?;
                    match found.len() {
                        0 => Err(Error::NotApplicable(format!(
                            "no stable state of the first mode holds A₁/A₀₁ = {r} on the \
                             {branch} branch"
                        ))),
                        1 => found.remove(0).1.map(|s| s.observables),
                        n => Err(Error::NotApplicable(format!(
                            "the modes hold A₁/A₀₁ = {r} on the {branch} branch in {n} \
                             coexisting states (the several-mode `tap` lists them): which one \
                             an AFM images on depends on its history"
                        ))),
                    }
                }
            });
            let mode = |s: &ModalObservables, i: usize| s.modes.get(i).cloned();
            Ok(match found {
                Ok(state) => ModalCell {
                    work_of_adhesion_j_m2: w,
                    modulus_pa: e,
                    tabor_mu: state.tabor_mu,
                    separation_m: Some(state.separation_m),
                    amplitude1_ratio: mode(&state, 0).and_then(|m| m.amplitude_ratio),
                    phase1_deg: mode(&state, 0).map(|m| m.phase_deg),
                    amplitude2_ratio: mode(&state, 1).and_then(|m| m.amplitude_ratio),
                    phase2_deg: mode(&state, 1).map(|m| m.phase_deg),
                    e_ts_j: Some(state.e_ts_j),
                    stable: Some(state.stable),
                    note: None,
                },
                Err(why @ (Error::NotApplicable(_) | Error::Numerical(_))) => ModalCell {
                    work_of_adhesion_j_m2: w,
                    modulus_pa: e,
                    tabor_mu: s.contact.tabor_mu(),
                    separation_m: None,
                    amplitude1_ratio: None,
                    phase1_deg: None,
                    amplitude2_ratio: None,
                    phase2_deg: None,
                    e_ts_j: None,
                    stable: None,
                    note: Some(why.to_string()),
                },
                Err(other) => return Err(other),
            })
        },
    )
}
