//! The global stage of a fit: starts spread over the plausible ranges, each with the
//! piezo offset that puts the simulated curve's features where the data's are, screened
//! by χ²; Levenberg–Marquardt then starts from the best few.
//!
//! An approach curve's residuals are smooth in the parameters only while the simulated
//! curve jumps where the data jump: a start whose curve stays on the attractive branch
//! where the data fell to the repulsive one sits in another piece of the χ² landscape,
//! and a local optimiser cannot leave it. The design is a Halton sequence (Halton, Numer.
//! Math. 2, 84, 1960) in the logarithms of the material parameters; the offset of each
//! design point is set by aligning the phase's features — the branch jump (its steepest
//! fall, where it crosses the free phase) or else the onset of the interaction — which
//! fixes it to a fraction of the points' spacing before any optimiser runs.

use super::features::{Features, first_end, onset};
use super::model::{Curve, Measured, Nuisance, Parameter, curve_while, weighted_residual};
use super::progress::{Stage, Tracker};
use crate::dynamics::setup::{Numerics, TapSetup};
use rayon::prelude::*;
use serde::Serialize;

/// How a fit looks for its minimum.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Search {
    /// Levenberg–Marquardt from the start alone.
    Local,
    /// A design over the plausible ranges first, then Levenberg–Marquardt from the best
    /// `starts` of its points.
    Global {
        /// Each material parameter ranges over [start/factor, start·factor].
        factor: f64,
        /// Design points (the start is one more).
        points: usize,
        /// Local runs, from the best distinct design points.
        starts: usize,
    },
}

impl Default for Search {
    fn default() -> Self {
        Search::Global {
            factor: 4.0,
            points: 48,
            starts: 3,
        }
    }
}

/// Most alignments of a design point's offset.
const ALIGNMENTS: usize = 3;
/// Cycles at most per steady state while screening (the local stage uses the fit's own
/// numerics: screening only ranks the design points).
const SCREEN_MAX_CYCLES: usize = 500;
/// Where the data have no feature to align, the offset joins the design over ± this
/// fraction of the free amplitude about its start.
const OFFSET_SPAN: f64 = 0.5;

/// A design point after screening.
#[derive(Debug, Clone)]
#[doc(hidden)]
pub struct Candidate {
    pub setup: TapSetup,
    pub nuisance: Nuisance,
    /// Its χ² (infinite where its curve could not be simulated).
    pub chi_square: f64,
}

/// The shift of the offset that moves `model`'s features onto `data`'s (positions,
/// both), if both show the same one: the jump first, else the onset.
fn shift(positions: &[f64], data: &Features, model: &Features) -> Option<f64> {
    let mid = |i: usize| 0.5 * (positions[i] + positions[i + 1]);
    match (data.jump, model.jump, data.onset_m, model.onset_m) {
        (Some(d), Some(m), _, _) => Some(mid(m) - mid(d)),
        (_, _, Some(d), Some(m)) => Some(m - d),
        _ => None,
    }
}

/// The `i`-th element (from 1) of the van der Corput sequence in `base`, in (0, 1).
fn radical_inverse(mut i: usize, base: usize) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= base as f64;
        r += f * (i % base) as f64;
        i /= base;
    }
    r
}

const PRIMES: [usize; 8] = [2, 3, 5, 7, 11, 13, 17, 19];

/// The fit's design points: the start, then `points` Halton points over the material
/// parameters' log-ranges (and the offset's span, where the data show no feature to
/// align it by).
fn design(
    setup: &TapSetup,
    nuisance: &Nuisance,
    params: &[Parameter],
    factor: f64,
    points: usize,
    offset_in_design: bool,
) -> Vec<(TapSetup, Nuisance)> {
    let mut dims: Vec<Parameter> = params.iter().copied().filter(|p| p.is_material()).collect();
    if offset_in_design {
        dims.push(Parameter::ZOffset);
    }
    let mut out = vec![(setup.clone(), *nuisance)];
    if dims.is_empty() {
        return out;
    }
    let span = OFFSET_SPAN * setup.cantilever.free_amplitude_m;
    for i in 1..=points {
        let (mut s, mut n) = (setup.clone(), *nuisance);
        for (d, p) in dims.iter().enumerate() {
            let u = 2.0 * radical_inverse(i, PRIMES[d % PRIMES.len()]) - 1.0;
            let start = p.value(setup, nuisance);
            let v = if p.is_scale() {
                start * factor.powf(u)
            } else {
                start + u * span
            };
            p.set(&mut s, &mut n, v);
        }
        out.push((s, n));
    }
    out
}

/// The weighted χ² of `curve` against `data`, with the phase offset (where fitted) set
/// to the mean difference it leaves, which is its least-squares value.
fn screened_chi_square(
    data: &Measured,
    curve: &mut Curve,
    nuisance: &mut Nuisance,
    phase_offset: bool,
) -> f64 {
    if let (true, Some(p)) = (phase_offset, &data.phase_deg) {
        let mean = p
            .iter()
            .zip(&curve.phase_deg)
            .map(|(m, s)| m - s)
            .sum::<f64>()
            / p.len() as f64;
        for s in curve.phase_deg.iter_mut() {
            *s += mean;
        }
        nuisance.phase_offset_deg += mean;
    }
    data.chi_square(curve)
}

/// Screen one design point: simulate, align the offset on the data's features (where
/// the offset is fitted and both show one), and take χ²; where the data allow it
/// ([`screen_plain`]) point by point, giving up once χ² passes `bound`.
fn screen(
    data: &Measured,
    numerics: &Numerics,
    params: &[Parameter],
    wanted: &Features,
    point: (TapSetup, Nuisance),
    bound: f64,
    tracker: &Tracker,
) -> Candidate {
    let plain = data.second_mode.is_none()
        && data.setpoint_ratio.is_none()
        && point.1.sensitivity == 1.0
        && wanted.jump.is_none();
    let c = if plain {
        screen_plain(data, numerics, params, wanted, point, bound, tracker)
    } else {
        screen_whole(data, numerics, params, wanted, point, tracker)
    };
    tracker.design_point();
    c
}

/// [`screen`] by whole curves, aligning a jump or onset up to [`ALIGNMENTS`] times.
fn screen_whole(
    data: &Measured,
    numerics: &Numerics,
    params: &[Parameter],
    wanted: &Features,
    point: (TapSetup, Nuisance),
    tracker: &Tracker,
) -> Candidate {
    let (setup, mut nuisance) = point;
    let phase_offset = params.contains(&Parameter::PhaseOffset);
    let align = params.contains(&Parameter::ZOffset) && data.setpoint_ratio.is_none();
    let mut best = Candidate {
        setup: setup.clone(),
        nuisance,
        chi_square: f64::INFINITY,
    };
    for _ in 0..ALIGNMENTS {
        let Ok(mut curve) = data.simulate(&setup, numerics, &nuisance) else {
            tracker.curve(None);
            break;
        };
        let model = Features::of(
            data,
            data.phase_deg.as_ref().map(|_| curve.phase_deg.as_slice()),
            data.amplitude_m
                .as_ref()
                .map(|_| curve.amplitude_m.as_slice()),
        );
        let mut n = nuisance;
        let chi = screened_chi_square(data, &mut curve, &mut n, phase_offset);
        tracker.curve(Some(chi));
        if chi < best.chi_square {
            best = Candidate {
                setup: setup.clone(),
                nuisance: n,
                chi_square: chi,
            };
        }
        let Some(dz) = align
            .then(|| shift(&data.position_m, wanted, &model))
            .flatten()
        else {
            break;
        };
        if dz == 0.0 {
            break;
        }
        nuisance.offset_m += dz;
    }
    best
}

/// [`screen`] for one mode at positions, the calibration holding: the first approach
/// simulated only until the model's onset shows (which sets the offset, and the phase
/// offset where fitted: the first points are free in both), then the whole data point
/// by point, given up as soon as χ² passes `bound`.
#[doc(hidden)]
pub fn screen_plain(
    data: &Measured,
    numerics: &Numerics,
    params: &[Parameter],
    wanted: &Features,
    point: (TapSetup, Nuisance),
    bound: f64,
    tracker: &Tracker,
) -> Candidate {
    let (setup, mut nuisance) = point;
    let fail = |nuisance| {
        tracker.curve(None);
        Candidate {
            setup: setup.clone(),
            nuisance,
            chi_square: f64::INFINITY,
        }
    };
    let align = params.contains(&Parameter::ZOffset);
    let end = first_end(data);
    let z = &data.position_m[..end];
    // The onset: the channel the data's features are read from.
    if let (true, Some(at)) = (align, wanted.onset_m) {
        let phase = data.phase_deg.is_some();
        let threshold = if phase {
            (10.0 * data.sigma_phase_deg).max(1.0)
        } else {
            let a0 = data.amplitude_m.as_ref().map_or(0.0, |a| a[0].abs());
            (10.0 * data.sigma_amplitude_m).max(5e-3 * a0)
        };
        let mut first = None;
        let thermal = data.thermal.as_ref();
        let Ok(head) = curve_while(&setup, numerics, z, nuisance.offset_m, thermal, |_, r| {
            let v = if phase { r.phase_deg } else { r.amplitude_m };
            let f = *first.get_or_insert(v);
            (v - f).abs() <= threshold
        }) else {
            return fail(nuisance);
        };
        tracker.curve(None);
        let v = if phase {
            &head.phase_deg
        } else {
            &head.amplitude_m
        };
        if let Some(m) = onset(&z[..v.len()], v, threshold) {
            nuisance.offset_m += m - at;
        }
        if let (true, Some(p), Some(&f)) = (
            params.contains(&Parameter::PhaseOffset),
            &data.phase_deg,
            head.phase_deg.first(),
        ) {
            nuisance.phase_offset_deg = p[0] - f;
        }
    }
    // The whole data, χ² summed as it comes.
    let mut chi = 0.0;
    let mut out_of_running = false;
    for (k, &start) in data.segments.iter().enumerate() {
        let stop = data.segments.get(k + 1).copied().unwrap_or(data.len());
        let Ok(_) = curve_while(
            &setup,
            numerics,
            &data.position_m[start..stop],
            nuisance.offset_m,
            data.segment_thermal(k).as_ref(),
            |i, r| {
                let i = start + i;
                if let Some(m) = &data.amplitude_m {
                    chi += weighted_residual(
                        r.amplitude_m,
                        m[i],
                        data.sigma_amplitude_m,
                        r.amplitude_std_err_m,
                    )
                    .powi(2);
                }
                if let Some(m) = &data.phase_deg {
                    chi += weighted_residual(
                        r.phase_deg + nuisance.phase_offset_deg,
                        m[i],
                        data.sigma_phase_deg,
                        r.phase_std_err_deg,
                    )
                    .powi(2);
                }
                chi <= bound
            },
        ) else {
            return fail(nuisance);
        };
        if chi > bound {
            out_of_running = true;
            break;
        }
    }
    tracker.curve(Some(chi));
    Candidate {
        setup,
        nuisance,
        chi_square: if out_of_running { f64::INFINITY } else { chi },
    }
}

/// Design points screened at once before the best χ² among them bounds the rest.
const FIRST_BATCH: usize = 8;
/// A design point is given up once its χ² passes this many times the best so far.
const BOUND_FACTOR: f64 = 3.0;

/// The starts for the local stage: the design's points screened (in parallel) and the
/// best `starts` distinct ones, best first (the start itself alone with
/// [`Search::Local`]).
pub(crate) fn starts(
    setup: &TapSetup,
    nuisance: &Nuisance,
    numerics: &Numerics,
    data: &Measured,
    params: &[Parameter],
    search: &Search,
    tracker: &Tracker,
) -> Vec<Candidate> {
    let Search::Global {
        factor,
        points,
        starts,
    } = *search
    else {
        return vec![Candidate {
            setup: setup.clone(),
            nuisance: *nuisance,
            chi_square: f64::NAN,
        }];
    };
    let wanted = if data.setpoint_ratio.is_none() {
        Features::of(data, data.phase_deg.as_deref(), data.amplitude_m.as_deref())
    } else {
        Features {
            jump: None,
            onset_m: None,
        }
    };
    let featureless = wanted.jump.is_none() && wanted.onset_m.is_none();
    let offset_in_design = featureless && params.contains(&Parameter::ZOffset);
    let design = design(setup, nuisance, params, factor, points, offset_in_design);
    let screening = Numerics {
        max_cycles: numerics.max_cycles.min(SCREEN_MAX_CYCLES),
        ..*numerics
    };
    tracker.stage(
        Stage::Design {
            done: 0,
            total: design.len(),
        },
        2 * design.len(),
        starts * 10 * (params.len() + 1),
    );
    // The first batch unbounded, the rest in batches bounded by the best so far (the
    // outcome does not depend on the threads' timing).
    let mut screened: Vec<Candidate> = Vec::with_capacity(design.len());
    for batch in design.chunks(FIRST_BATCH) {
        let best = screened
            .iter()
            .map(|c| c.chi_square)
            .fold(f64::INFINITY, f64::min);
        let bound = BOUND_FACTOR * best;
        screened.par_extend(batch.par_iter().map(|point| {
            screen(
                data,
                &screening,
                params,
                &wanted,
                point.clone(),
                bound,
                tracker,
            )
        }));
    }
    screened.sort_by(|a, b| a.chi_square.total_cmp(&b.chi_square));
    let mut chosen: Vec<Candidate> = Vec::new();
    for c in screened {
        if chosen.len() == starts.max(1) || !c.chi_square.is_finite() {
            break;
        }
        let distinct = chosen.iter().all(|d| {
            params.iter().any(|p| {
                let (a, b) = (
                    p.value(&c.setup, &c.nuisance),
                    p.value(&d.setup, &d.nuisance),
                );
                p.coordinate_gap(a, b) > 1e-3
            })
        });
        if distinct {
            chosen.push(c);
        }
    }
    if chosen.is_empty() {
        // No design point could be simulated: the local stage tries the start itself,
        // and says why it fails.
        chosen.push(Candidate {
            setup: setup.clone(),
            nuisance: *nuisance,
            chi_square: f64::NAN,
        });
    }
    chosen
}
