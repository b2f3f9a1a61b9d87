//! Bimodal AFM as an instrument uses it: approach curves of several eigenmodes (each
//! point continued from the last), the rest separation at which the first mode holds an
//! amplitude setpoint, and the second mode's phase contrast between materials there
//! (Lozano & García, PRL 100, 076102, 2008: φ₂ at a fixed A₁/A₀₁ tells materials
//! apart that φ₁ does not).

use crate::contrast::Material;
use crate::dynamics::modes::orbit::ModalOrbit;
use crate::dynamics::modes::{Modal, ModalObservables, ModeSet, modal_steady, prepare};
use crate::dynamics::setup::{Numerics, Prepared};
use crate::error::{Error, Result};
use crate::law::LawKind;
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

/// Points of the coarse approach that brackets the setpoints.
pub const SETPOINT_SCAN: usize = 24;

/// The states at which the first mode's amplitude is each of `setpoints` (times A₀₁) on a
/// slow approach from z_c = A₀₁(1 + the largest setpoint) (the free oscillation, just
/// out of reach) towards the sample: a coarse approach of [`SETPOINT_SCAN`] points
/// brackets each, and regula falsi on z_c (each point continued from the bracket's far
/// end) finds it to 1e-7 of A₁/A₀₁. A setpoint the amplitude jumps across has no state.
pub fn at_setpoints(
    p: &Prepared,
    modal: &Modal,
    numerics: &Numerics,
    setpoints: &[f64],
) -> Result<Vec<Result<ModalObservables>>> {
    if let Some(&bad) = setpoints.iter().find(|&&s| !(s > 0.0 && s < 1.0)) {
        return Err(Error::InvalidParameter {
            name: "setpoint",
            value: bad,
            reason: "must lie between 0 and 1 (A₁/A₀₁)",
        });
    }
    let top = setpoints.iter().copied().fold(0.0f64, f64::max);
    let bottom = setpoints.iter().copied().fold(1.0f64, f64::min);
    let a0 = p.setup.cantilever.free_amplitude_m;
    let (far, near) = (a0 * (1.0 + top), a0 * (bottom - 0.5).min(0.0));
    let mut scan: Vec<(f64, f64, ModalOrbit)> = Vec::new();
    let mut last: Option<ModalOrbit> = None;
    for k in 0..SETPOINT_SCAN {
        let z = far + (near - far) * k as f64 / (SETPOINT_SCAN - 1) as f64;
        match solve_at(p, modal, numerics, z, last.as_ref()) {
            Ok((state, orbit)) => {
                scan.push((z, first_ratio(&state), orbit.clone()));
                last = Some(orbit);
            }
            Err(Error::Interrupted) => return Err(Error::Interrupted),
            Err(_) => last = None,
        }
    }
    Ok(setpoints
        .iter()
        .map(|&setpoint| {
            let bracket = scan
                .windows(2)
                .find(|w| w[0].1 > setpoint && w[1].1 <= setpoint)
                .ok_or_else(|| {
                    Error::NotApplicable(format!(
                        "the first mode's amplitude does not fall through A₁/A₀₁ = \
                         {setpoint} on an approach from {:.4} nm to {:.4} nm",
                        far * 1e9,
                        near * 1e9
                    ))
                })?;
            let (hi, lo) = (&bracket[0], &bracket[1]);
            falsi(
                p,
                modal,
                numerics,
                setpoint,
                (hi.0, hi.1, hi.2.clone()),
                (lo.0, lo.1),
            )
        })
        .collect())
}

/// Regula falsi (Illinois) on z_c for A₁/A₀₁ = `setpoint` between `hi` (above it, with
/// its orbit) and `lo` (at or below).
fn falsi(
    p: &Prepared,
    modal: &Modal,
    numerics: &Numerics,
    setpoint: f64,
    (mut z_hi, mut r_hi, mut orbit_hi): (f64, f64, ModalOrbit),
    (mut z_lo, mut r_lo): (f64, f64),
) -> Result<ModalObservables> {
    let mut side = 0i8;
    let mut best: Option<ModalObservables> = None;
    for _ in 0..60 {
        let (f_hi, f_lo) = (r_hi - setpoint, r_lo - setpoint);
        let z = if f_hi != f_lo {
            z_hi - f_hi * (z_lo - z_hi) / (f_lo - f_hi)
        } else {
            0.5 * (z_hi + z_lo)
        };
        let (state, orbit) = solve_at(p, modal, numerics, z, Some(&orbit_hi))?;
        let ratio = first_ratio(&state);
        let done = (ratio - setpoint).abs() <= 1e-7;
        if ratio > setpoint {
            (z_hi, r_hi, orbit_hi) = (z, ratio, orbit);
            if side == 1 {
                r_lo = setpoint + 0.5 * (r_lo - setpoint);
            }
            side = 1;
        } else {
            (z_lo, r_lo) = (z, ratio);
            if side == -1 {
                r_hi = setpoint + 0.5 * (r_hi - setpoint);
            }
            side = -1;
        }
        best = Some(state);
        if done || (z_hi - z_lo).abs() <= 1e-9 * p.setup.cantilever.free_amplitude_m {
            break;
        }
    }
    let state = best.expect("regula falsi ran");
    if (first_ratio(&state) - setpoint).abs() > 1e-5 {
        return Err(Error::NotApplicable(format!(
            "the first mode's amplitude jumps across A₁/A₀₁ = {setpoint} (to {:.5} near \
             z_c = {:.4} nm): no steady state of the approach holds it",
            first_ratio(&state),
            z_hi * 1e9
        )));
    }
    Ok(state)
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
    /// Why a material has no state.
    pub notes: Vec<Option<String>>,
}

/// φ₁ and φ₂ of every material at each first-mode setpoint under each law of `laws`
/// (each law and material in parallel, each counted by `progress` when done), rows by
/// law then setpoint.
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
    let results: Vec<Result<Vec<Result<ModalObservables>>>> = jobs
        .par_iter()
        .map(|&(l, m)| {
            let mut setup = materials[m].setup.clone();
            setup.law = laws[l].into();
            let (p, modal) = prepare(&setup, set, &materials[m].numerics)?;
            let states = at_setpoints(&p, &modal, &materials[m].numerics, setpoints);
            progress();
            states
        })
        .collect();
    let mut states = Vec::with_capacity(results.len());
    for r in results {
        states.push(r?);
    }
    let mut rows = Vec::new();
    for (l, law) in laws.iter().enumerate() {
        for (k, &setpoint) in setpoints.iter().enumerate() {
            let of = |m: usize| states[l * materials.len() + m][k].as_ref().ok();
            let each = |f: &dyn Fn(&ModalObservables) -> Option<f64>| {
                (0..materials.len())
                    .map(|m| of(m).and_then(f))
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
                delta_phase1_deg: delta(&phase1),
                delta_phase2_deg: delta(&phase2),
                phase1_deg: phase1,
                phase2_deg: phase2,
                amplitude2_ratio: each(&|s| s.modes.get(1).and_then(|m| m.amplitude_ratio)),
                e_ts_j: each(&|s| Some(s.e_ts_j)),
                separation_m: each(&|s| Some(s.separation_m)),
                stable: (0..materials.len())
                    .map(|m| of(m).map(|s| s.stable))
                    .collect(),
                notes: (0..materials.len())
                    .map(|m| {
                        states[l * materials.len() + m][k]
                            .as_ref()
                            .err()
                            .map(|e| e.to_string())
                    })
                    .collect(),
            });
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
    /// The rest separation of the state (m; at a first-mode setpoint, where the approach
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
/// setpoint `setpoint` as a slow approach reaches it. A cell without a periodic state
/// is listed with why.
pub fn map_cells(
    setup: &crate::dynamics::setup::TapSetup,
    set: &ModeSet,
    numerics: &Numerics,
    (works_j_m2, moduli_pa): (&[f64], &[f64]),
    threads: usize,
    progress: impl Fn() + Sync,
    setpoint: Option<f64>,
) -> Result<Vec<ModalCell>> {
    let every: Vec<usize> = (0..works_j_m2.len() * moduli_pa.len()).collect();
    crate::sweep::over_grid(
        setup,
        (works_j_m2, moduli_pa),
        &every,
        threads,
        progress,
        |s, (w, e)| {
            let found = prepare(s, set, numerics).and_then(|(p, modal)| match setpoint {
                None => Ok(modal_steady(&p, &modal, numerics, None)?.0),
                Some(r) => at_setpoints(&p, &modal, numerics, &[r])?
                    .pop()
                    .expect("one setpoint asked"),
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
