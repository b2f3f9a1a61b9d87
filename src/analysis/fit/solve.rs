//! The fit: a global stage ([`super::search`]) whose best design points start
//! Levenberg–Marquardt runs (the private `local` module), every distinct local minimum
//! kept; at the best one the Jacobian's account of the parameters
//! ([`super::identifiability`]) and the verdict on whether the fit describes the data
//! ([`super::diagnose`]).

use super::diagnose::{Diagnosis, STALL_DECREASE, diagnose, gauss_newton_step};
use super::identifiability::{Identifiability, ParameterEstimate, assess};
use super::local::{self, LocalRun};
use super::model::{Curve, Measured, Nuisance, Parameter};
use super::progress::{Progress, Stage, Tracker};
use super::search::{self, Search};
use crate::dynamics::setup::{Numerics, TapSetup};
use crate::error::{Error, Result};
use nalgebra::DVector;
use serde::Serialize;

/// χ²/dof at or below which residuals are the simulation's own round-off and
/// tolerance, not a measurement's noise (at the default weights, 1e-6 of 0.02 nm).
const RESOLVED_CHI_SQUARE: f64 = 1e-6;

/// Two local runs ended on one minimum where every coordinate agrees to this (a
/// relative 2e-3 in a scale, 2e-3 of an offset's unit).
const SAME_MINIMUM: f64 = 2e-3;

/// Levenberg–Marquardt iterations (each a Jacobian and a trial curve) every start gets
/// before any goes on, where there are several: a run from a good start ends on its
/// minimum in fewer (13 from the best-ranked start that reaches the truth on the
/// branch-jumping curve), one headed for a wrong minimum would take three times as many.
const FIRST_PASS_ITERATIONS: usize = 15;

/// What to fit and how hard to try.
#[derive(Debug, Clone, PartialEq)]
pub struct FitOptions {
    /// The parameters adjusted (at least one, each once); the setup gives their
    /// starting values and the values of all others.
    pub parameters: Vec<Parameter>,
    /// The piezo offset, sensitivity and phase offset to start from (each stays there
    /// unless fitted).
    pub start: Nuisance,
    /// Whether the data's standard deviations are estimated from the residuals (the
    /// covariance scaled by χ²/dof) rather than taken as given.
    pub estimate_sigma: bool,
    /// Most simulated curves of each local run (each residual or Jacobian column is
    /// one).
    pub max_curves: usize,
    /// How the minimum is looked for.
    pub search: Search,
    /// Fit the points whose state at the fitted parameters grazes a switch too. By
    /// default they are left out (and the fit is run again without them): such a
    /// point's state is one draw among coexisting states, its value a step in the
    /// parameters that the intervals cannot see.
    pub keep_grazing: bool,
}

impl FitOptions {
    /// Fit `parameters` from the setup's values, the offset from `offset_start_m`, the
    /// calibration holding, the standard deviations as given, the global search on
    /// its defaults and 400 curves a local run.
    pub fn new(parameters: Vec<Parameter>, offset_start_m: f64) -> Self {
        Self {
            parameters,
            start: Nuisance::offset(offset_start_m),
            estimate_sigma: false,
            max_curves: 400,
            search: Search::default(),
            keep_grazing: false,
        }
    }
}

/// A local minimum the fit found.
#[derive(Debug, Clone, Serialize)]
pub struct Minimum {
    /// The fitted parameters' values there, in the options' order (SI).
    pub values: Vec<f64>,
    /// χ² there.
    pub chi_square: f64,
    /// χ² over the degrees of freedom.
    pub reduced_chi_square: f64,
    /// How many local runs ended there.
    pub runs: usize,
    /// Why the optimiser stopped (the first run that ended there).
    pub termination: String,
    /// Whether every run that ended there was cut short by its budget (a run left at
    /// its first share once another start had found a minimum describing the data):
    /// where it stopped, not a minimum.
    pub cut_short: bool,
}

/// The standard deviations the residuals imply, per channel (where they are estimated).
#[derive(Debug, Clone, Serialize)]
pub struct SigmaEstimate {
    /// The channel (amplitude_m, phase_deg, amplitude2_m, phase2_deg).
    pub channel: &'static str,
    /// The standard deviation its residuals imply (its unit).
    pub sigma: f64,
    /// The relative weight it was fitted with.
    pub weight_sigma: f64,
}

/// A fit's outcome.
#[derive(Debug, Clone, Serialize)]
pub struct FitReport {
    /// Each parameter adjusted.
    pub parameters: Vec<ParameterEstimate>,
    /// What the Jacobian says of them.
    pub identifiability: Identifiability,
    /// Σ r², the weighted residuals' squares.
    pub chi_square: f64,
    /// Residuals less parameters.
    pub degrees_of_freedom: usize,
    /// χ²/dof (about 1 where the standard deviations are right and the model fits).
    pub reduced_chi_square: f64,
    /// Whether the standard deviations were estimated from the residuals.
    pub sigma_estimated: bool,
    /// Where they were: what each channel's residuals imply.
    pub sigma_estimates: Vec<SigmaEstimate>,
    /// Whether the fit ended at a minimum that describes the data: the optimiser's
    /// convergence test passed, no Gauss–Newton step would still lower χ², and the
    /// diagnosis finds no misfit.
    pub converged: bool,
    /// Why the optimiser stopped, in words (and why it is not called converged).
    pub termination: String,
    /// The decrease of χ² a Gauss–Newton step from the end would still bring.
    pub remaining_decrease: f64,
    /// Whether the fitted curve describes the data, and where it does not.
    pub diagnosis: Diagnosis,
    /// Every distinct local minimum the local runs ended on, best first.
    pub minima: Vec<Minimum>,
    /// How the minimum was looked for.
    pub search: Search,
    /// Simulated curves in all (design, local runs, Jacobian).
    pub curves: usize,
    /// The fitted curve at the measured positions.
    pub fitted: Curve,
    /// Weighted residuals (model − measured)/σ, amplitudes first.
    pub residuals: Vec<f64>,
    /// The data's points (indices) left out because their state at the fitted
    /// parameters grazes a switch ([`FitOptions::keep_grazing`]); `fitted` and
    /// `residuals` are over the others.
    pub left_out: Vec<usize>,
}

/// Refuse options that cannot fit `data`.
fn check(data: &Measured, options: &FitOptions) -> Result<()> {
    let params = &options.parameters;
    if params.is_empty() {
        return Err(Error::NotApplicable(
            "nothing to fit: no parameter chosen".into(),
        ));
    }
    if let Some(p) = params
        .iter()
        .enumerate()
        .find(|(i, p)| params[..*i].contains(p))
    {
        return Err(Error::NotApplicable(format!(
            "{} is chosen twice",
            p.1.key()
        )));
    }
    crate::error::finite("offset start", options.start.offset_m)?;
    crate::error::finite("phase offset start", options.start.phase_offset_deg)?;
    crate::error::positive("sensitivity start", options.start.sensitivity)?;
    if data.setpoint_ratio.is_some() && params.contains(&Parameter::ZOffset) {
        return Err(Error::NotApplicable(
            "setpoint data have no piezo positions: there is no offset to fit".into(),
        ));
    }
    if params.contains(&Parameter::PhaseOffset) && data.phase_deg.is_none() {
        return Err(Error::NotApplicable(
            "a phase offset needs a phase channel to fit".into(),
        ));
    }
    let m = data.channels() * data.len();
    if m <= params.len() {
        return Err(Error::NotApplicable(format!(
            "{m} measured values cannot fix {} parameters",
            params.len()
        )));
    }
    if let Search::Global {
        factor,
        points,
        starts,
    } = options.search
    {
        if !(factor.is_finite() && factor > 1.0 && factor <= 1e3) {
            return Err(Error::OutOfRange(format!(
                "the search factor must lie in (1, 1000], not {factor}"
            )));
        }
        if points > 10_000 || !(1..=100).contains(&starts) {
            return Err(Error::OutOfRange(format!(
                "the search takes at most 10 000 design points and 1 to 100 starts, not \
                 {points} and {starts}"
            )));
        }
    }
    Ok(())
}

/// Fit `options.parameters` of `setup` (starting values; every other parameter fixed as
/// it gives it) to `data` by weighted least squares; `progress` hears of each simulated
/// curve and stage.
pub fn fit(
    setup: &TapSetup,
    numerics: &Numerics,
    data: &Measured,
    options: &FitOptions,
    progress: impl Fn(&Progress) + Sync,
) -> Result<FitReport> {
    fit_reporting(setup, numerics, data, options, &progress)
}

/// [`fit`] compiled once: a caller's progress closure does not make a copy of the whole
/// fit (the tests' closures made 28, with their iterators and closures a fifth of the
/// test program's LLVM IR).
fn fit_reporting(
    setup: &TapSetup,
    numerics: &Numerics,
    data: &Measured,
    options: &FitOptions,
    progress: &(dyn Fn(&Progress) + Sync),
) -> Result<FitReport> {
    let mut data = data.clone().validated()?;
    check(&data, options)?;
    let params = &options.parameters;
    let starts: Vec<f64> = params
        .iter()
        .map(|p| p.start(setup, &options.start))
        .collect::<Result<_>>()?;
    let tracker = Tracker::new(progress);
    // Each point on the branch the data show while searching; the approach as it goes
    // (jumping where the model jumps) for the verdict.
    let mut split = data.split_at_branch_jump();
    let working = split.as_ref().unwrap_or(&data);
    let candidates = search::starts(
        setup,
        &options.start,
        numerics,
        working,
        params,
        &options.search,
        &tracker,
    );
    let mut m = data.channels() * data.len();
    let mut dof = m - params.len();
    // Levenberg–Marquardt from each start; every run's end kept. With several starts
    // each first gets a share of the budget, so that a run on its way to a wrong
    // minimum costs no more than that; only where none of them ends on a minimum that
    // describes the data do the runs cut short go on, the best first.
    let mut runs: Vec<LocalRun> = Vec::new();
    let mut first_error = None;
    let per_run = 10 * (params.len() + 1);
    let share = if candidates.len() > 1 {
        options
            .max_curves
            .min(FIRST_PASS_ITERATIONS * (params.len() + 1))
    } else {
        options.max_curves
    };
    // Whether a curve with these weighted residuals describes the data (residuals at
    // the simulation's precision do, whatever pattern their round-off makes).
    let describes = |c: &Curve, r: &[f64]| {
        let reduced = r.iter().map(|v| v * v).sum::<f64>() / dof as f64;
        reduced <= RESOLVED_CHI_SQUARE
            || diagnose(working, c, r, dof, options.estimate_sigma).describes_data
    };
    // Whether a local run ended on a minimum that describes the data.
    let judge = |r: &LocalRun| {
        r.lm_converged && r.chi_square().is_finite() && describes(&r.curve, r.residuals.as_slice())
    };
    // A local run from `setup` and `nuisance` on at most `budget` curves (in the first
    // pass over several starts, cut where it crawls far from the data); a run that
    // fails keeps its error (the first one is said if no run succeeds).
    let attempt = |setup: &TapSetup,
                   nuisance: Nuisance,
                   budget: usize,
                   cut_crawling: bool,
                   first_error: &mut Option<Error>| {
        let budget = local::Budget {
            max_curves: budget,
            describes: cut_crawling.then_some(&describes as local::Describes),
        };
        local::run(setup, nuisance, numerics, working, params, budget, &tracker)
            .map_err(|e| {
                first_error.get_or_insert(e);
            })
            .ok()
    };
    let mut found = false;
    for (i, c) in candidates.iter().enumerate() {
        tracker.stage(
            Stage::Local {
                index: i + 1,
                of: candidates.len(),
            },
            per_run,
            (candidates.len() - i - 1) * per_run + params.len(),
        );
        let several = candidates.len() > 1;
        if let Some(r) = attempt(&c.setup, c.nuisance, share, several, &mut first_error) {
            // A minimum that describes the data ends the search (later starts are
            // worse by the screening): it is the answer, and no other can fit better
            // than the noise.
            found = judge(&r);
            runs.push(r);
            if found {
                break;
            }
        }
    }
    if !found && share < options.max_curves {
        let mut cut: Vec<usize> = (0..runs.len()).filter(|&k| runs[k].out_of_budget).collect();
        cut.sort_by(|&a, &b| runs[a].chi_square().total_cmp(&runs[b].chi_square()));
        for (n, &k) in cut.iter().enumerate() {
            tracker.stage(
                Stage::Continue {
                    index: n + 1,
                    of: cut.len(),
                },
                per_run,
                (cut.len() - n - 1) * per_run + params.len(),
            );
            let budget = options.max_curves - share;
            let (setup, nuisance) = (runs[k].setup.clone(), runs[k].nuisance);
            if let Some(r) = attempt(&setup, nuisance, budget, false, &mut first_error) {
                let fine = judge(&r);
                runs[k] = r;
                if fine {
                    break;
                }
            }
        }
    }
    if runs.is_empty() {
        return Err(first_error.expect("a run that failed says why"));
    }
    runs.sort_by(|a, b| a.chi_square().total_cmp(&b.chi_square()));
    let mut best = runs.remove(0);
    // A local run from a point already found, on `working` data.
    let run_from = |setup: &TapSetup, nuisance: Nuisance, working: &Measured| {
        local::run(
            setup,
            nuisance,
            numerics,
            working,
            params,
            local::Budget::curves(options.max_curves),
            &tracker,
        )
    };
    // Points whose state at the best parameters grazes a switch: left out, and the fit
    // run again from there without them (the other runs' ends re-read on those data).
    // More than a quarter of the curve grazing is not a few draws to set aside but a
    // curve of mode locks (or a minimum far from the data's): kept, and said.
    let grazing: Vec<usize> = (0..best.curve.grazing.len())
        .filter(|&i| best.curve.grazing[i])
        .collect();
    let grazing_count = grazing.len();
    let too_many = 4 * grazing_count > data.len()
        || data.channels() * (data.len() - grazing_count) <= params.len();
    let left_out = if options.keep_grazing || too_many {
        Vec::new()
    } else {
        grazing
    };
    if !left_out.is_empty() {
        data = data.without(&left_out);
        split = data.split_at_branch_jump();
        m = data.channels() * data.len();
        dof = m - params.len();
        let working = split.as_ref().unwrap_or(&data);
        tracker.stage(
            Stage::WithoutGrazing {
                left_out: left_out.len(),
            },
            per_run,
            params.len(),
        );
        best = run_from(&best.setup, best.nuisance, working)?;
        for r in &mut runs {
            if let Ok(c) = working.simulate(&r.setup, numerics, &r.nuisance) {
                r.residuals = DVector::from_vec(working.residuals(&c));
                r.curve = c;
            }
            tracker.curve(None);
        }
    }
    let working = split.as_ref().unwrap_or(&data);
    // Is the end a minimum? Try the Gauss–Newton step from it: where it lowers χ² by
    // more than the variance factor the optimiser stalled (a step refused at a kink,
    // say) — go on from there, twice at most; where it does not (the prediction met a
    // switch in the forward differences), the end stands.
    let factor_of = |r: &LocalRun| {
        if options.estimate_sigma {
            // (Residuals at the simulation's precision estimate no noise: a step
            // gaining less than that precision is no stall.)
            (r.chi_square() / dof as f64).max(RESOLVED_CHI_SQUARE)
        } else {
            1.0
        }
    };
    let mut continuations = 0;
    let (remaining, stalled, jacobian) = loop {
        tracker.stage(Stage::Assess, params.len() + 2, 0);
        let jacobian = local::jacobian(&best, numerics, working, params, &tracker)?;
        let (step, predicted) = gauss_newton_step(&jacobian, &best.residuals);
        let chi = best.chi_square();
        if predicted <= STALL_DECREASE * factor_of(&best) {
            break (predicted, false, jacobian);
        }
        let (s, n) = local::stepped(&best, params, &step);
        let found = data_chi_square(working, &s, numerics, &n);
        tracker.curve(found);
        let gained = found.map_or(0.0, |c| chi - c).max(0.0);
        let stalled = gained > STALL_DECREASE * factor_of(&best);
        if !stalled || continuations == 2 {
            break (gained, stalled, jacobian);
        }
        continuations += 1;
        best = run_from(&s, n, working)?;
    };
    let minima = distinct_minima(std::iter::once(&best).chain(&runs), params, dof);
    let best = &best;
    // The approach as it goes at the best parameters: where it jumps where the data
    // do, the same curve (to the steady states' tolerance); where not, the verdict
    // says so.
    let fitted = match split {
        Some(_) => {
            let c = data.simulate(&best.setup, numerics, &best.nuisance)?;
            tracker.curve(None);
            c
        }
        None => best.curve.clone(),
    };
    let residuals = &DVector::from_vec(data.residuals(&fitted));
    let chi_square = residuals.norm_squared();
    let reduced = chi_square / dof as f64;
    let resolved = reduced <= RESOLVED_CHI_SQUARE;
    let residual_list: Vec<f64> = residuals.iter().copied().collect();
    let mut diagnosis = diagnose(&data, &fitted, &residual_list, dof, options.estimate_sigma);
    if resolved {
        // Residuals at the simulation's precision have no noise to test for runs.
        diagnosis = Diagnosis {
            describes_data: true,
            reasons: Vec::new(),
            ..diagnosis
        };
    }
    let stalled = stalled && !resolved;
    // Points whose state at the best parameters is not a stable period-1 orbit clear of
    // the law's switches (mode locks, grazing touches) step as the parameters move:
    // past a quarter of the curve the linearised intervals would claim a precision the
    // fit does not have.
    let unsettled = fitted.unsettled();
    let locked = fitted.mostly_unsettled();
    // Likewise thermal averages: each carries noise that changes as the parameters move
    // (the same seeds, other trajectories), a χ² surface rippled at the scale of their
    // standard errors. On the defaults' JKR approach at 300 K (9 of 12 points averaged,
    // 2000 periods each) a fit from 5 % off ended at +9 % in E* and Δγ with χ²/dof 1.4
    // in such a ripple, its intervals 5 σ from the truth.
    let averaged = fitted.averaged.iter().filter(|a| **a).count();
    let rippled = !locked && 4 * averaged > data.len();
    let locked = locked || rippled;
    let variance_factor = match (diagnosis.describes_data, options.estimate_sigma, resolved) {
        _ if locked => None,
        (false, _, _) => None,
        (true, false, _) => Some(1.0),
        (true, true, false) => Some(reduced),
        (true, true, true) => None,
    };
    let (estimates, mut identifiability) =
        assess(params, &jacobian, variance_factor, &best.values, &starts);
    if rippled {
        identifiability.notes.push(format!(
            "{averaged} of the {} points are thermal averages at the fitted parameters: \
             their noise moves with the parameters and ripples χ² at the scale of their \
             standard errors, which linearised intervals cannot see, so none are given; \
             other values may fit these data as well (compare fits from other starts, or \
             longer averages)",
            data.len()
        ));
    } else if locked {
        identifiability.notes.push(format!(
            "{unsettled} of the {} points are mode locks or graze a switch of the law at \
             the fitted parameters ({grazing_count} grazing{}): their values step as the \
             parameters move, which linearised intervals cannot see, so none are given; \
             other values may fit these data as well (compare fits from other starts)",
            data.len(),
            if too_many && !options.keep_grazing {
                ", too many to leave out"
            } else {
                ""
            }
        ));
    }
    if options.estimate_sigma && resolved {
        identifiability.notes.push(format!(
            "the residuals are at the simulation's own precision (χ²/dof = {reduced:.1e}): \
             the data carry no noise to estimate their standard deviations from, so no \
             intervals are given (give the standard deviations to have them)"
        ));
    }
    let sigma_estimates = if options.estimate_sigma && !resolved {
        sigma_estimates(&data, &residual_list, dof, m)
    } else {
        Vec::new()
    };
    let mut termination = best.termination.clone();
    if stalled {
        termination = format!(
            "{termination}, but a Gauss–Newton step from there still lowers χ² by \
             {remaining:.3e}: the search stalled short of a minimum (the curve may be \
             switching between states as the parameters move)"
        );
    }
    if !diagnosis.describes_data {
        termination = format!("{termination}; the fit does not describe the data");
    }
    Ok(FitReport {
        parameters: estimates,
        identifiability,
        chi_square,
        degrees_of_freedom: dof,
        reduced_chi_square: reduced,
        sigma_estimated: options.estimate_sigma,
        sigma_estimates,
        converged: best.lm_converged && !stalled && diagnosis.describes_data,
        termination,
        remaining_decrease: remaining,
        diagnosis,
        minima,
        search: options.search,
        curves: tracker.curves(),
        fitted,
        residuals: residual_list,
        left_out,
    })
}

/// χ² of `data` simulated with `setup` and `nuisance` (None where it cannot be).
fn data_chi_square(
    data: &Measured,
    setup: &TapSetup,
    numerics: &Numerics,
    nuisance: &Nuisance,
) -> Option<f64> {
    let c = data.simulate(setup, numerics, nuisance).ok()?;
    Some(data.chi_square(&c))
}

/// The distinct minima of `runs` (sorted by χ²): runs whose coordinates agree to
/// [`SAME_MINIMUM`] are one.
#[doc(hidden)]
pub fn distinct_minima<'a>(
    runs: impl Iterator<Item = &'a LocalRun>,
    params: &[Parameter],
    dof: usize,
) -> Vec<Minimum> {
    let mut out: Vec<Minimum> = Vec::new();
    for r in runs {
        let same = out.iter_mut().find(|m| {
            params
                .iter()
                .zip(m.values.iter().zip(&r.values))
                .all(|(p, (&a, &b))| p.coordinate_gap(a, b) < SAME_MINIMUM)
        });
        match same {
            Some(m) => {
                m.runs += 1;
                m.cut_short &= r.out_of_budget;
            }
            None => {
                let chi = r.chi_square();
                out.push(Minimum {
                    values: r.values.clone(),
                    chi_square: chi,
                    reduced_chi_square: chi / dof as f64,
                    runs: 1,
                    termination: r.termination.clone(),
                    cut_short: r.out_of_budget,
                });
            }
        }
    }
    out
}

/// Each channel's standard deviation as its residuals imply it: the weight it was
/// fitted with times the rms of its weighted residuals, over its share of the degrees
/// of freedom.
fn sigma_estimates(data: &Measured, residuals: &[f64], dof: usize, m: usize) -> Vec<SigmaEstimate> {
    let n = data.len();
    let share = dof as f64 / m as f64;
    data.channel_names()
        .into_iter()
        .zip(data.channel_values(&Curve::default()))
        .enumerate()
        .map(|(c, (channel, values))| {
            let weight = values.sigma;
            let r = &residuals[c * n..(c + 1) * n];
            let ss: f64 = r.iter().map(|v| v * v).sum();
            SigmaEstimate {
                channel,
                sigma: weight * (ss / (n as f64 * share)).sqrt(),
                weight_sigma: weight,
            }
        })
        .collect()
}

/// A parameter's profile: the best χ² with it held at each value and the others
/// refitted, and the intervals where χ² rises by 1 and 3.84 over the minimum (Venzon &
/// Moolgavkar, Appl. Statist. 37, 87, 1988) — exact where the linearised intervals
/// assume the model straight.
#[derive(Debug, Clone, Serialize)]
pub struct Profile {
    /// The parameter's key.
    pub name: &'static str,
    /// The values it was held at (SI), in increasing order, the estimate among them.
    pub values: Vec<f64>,
    /// χ² − χ²_min there (over χ²/dof where the standard deviations are estimated).
    pub delta_chi_square: Vec<f64>,
    /// Where Δχ² = 1 on each side (null on a side the profile does not reach it: the
    /// data do not bound the parameter there).
    pub interval_68: [Option<f64>; 2],
    /// Where Δχ² = 3.84.
    pub interval_95: [Option<f64>; 2],
    /// Values at which the held fit could not be simulated (a trial outside the law's
    /// range): points without a value, where that side of the profile stops.
    pub unavailable: Vec<f64>,
}

/// Put the values `fitted` found for `parameters` into `setup` and `nuisance` (a
/// parameter given no value keeps its own).
fn apply(
    parameters: &[Parameter],
    fitted: &FitReport,
    setup: &mut TapSetup,
    nuisance: &mut Nuisance,
) {
    for (p, e) in parameters.iter().zip(&fitted.parameters) {
        if let Some(v) = e.value {
            p.set(setup, nuisance, v);
        }
    }
}

/// Steps of a profile on each side, in linearised standard errors.
const PROFILE_STEP: f64 = 0.75;
/// Most steps on each side (4.5 standard errors).
const PROFILE_STEPS: usize = 6;

/// The profile of `which` about the fit `best` of `options.parameters` to `data` (the
/// setup `setup` and options as given to [`fit`]).
pub fn profile(
    setup: &TapSetup,
    numerics: &Numerics,
    data: &Measured,
    options: &FitOptions,
    best: &FitReport,
    which: Parameter,
    progress: impl Fn(&Progress) + Sync,
) -> Result<Profile> {
    profile_reporting(setup, numerics, data, options, best, which, &progress)
}

/// [`profile`] compiled once, as [`fit_reporting`] is.
fn profile_reporting(
    setup: &TapSetup,
    numerics: &Numerics,
    data: &Measured,
    options: &FitOptions,
    best: &FitReport,
    which: Parameter,
    progress: &(dyn Fn(&Progress) + Sync),
) -> Result<Profile> {
    let k = options
        .parameters
        .iter()
        .position(|&p| p == which)
        .ok_or_else(|| Error::NotApplicable(format!("{} was not fitted", which.key())))?;
    let est = &best.parameters[k];
    let (Some(value), Some(std_err)) = (est.value, est.std_err) else {
        return Err(Error::NotApplicable(format!(
            "{} has no estimate with an error to profile about",
            which.key()
        )));
    };
    // The best fit's setup and offset: every fitted value in place.
    let mut at_best = setup.clone();
    let mut nuisance = options.start;
    apply(&options.parameters, best, &mut at_best, &mut nuisance);
    let others: Vec<Parameter> = options
        .parameters
        .iter()
        .copied()
        .filter(|&p| p != which)
        .collect();
    let factor = if best.sigma_estimated {
        best.reduced_chi_square
    } else {
        1.0
    };
    let tracker = Tracker::new(progress);
    tracker.stage(
        Stage::Profile,
        2 * PROFILE_STEPS * 4 * (others.len() + 1),
        0,
    );
    // χ² with `which` held at `v`, the others refitted from `start` (setup and nuisance
    // values).
    let held = |v: f64, start: &(TapSetup, Nuisance)| -> Result<(f64, (TapSetup, Nuisance))> {
        let (mut s, mut n) = start.clone();
        which.set(&mut s, &mut n, v);
        if others.is_empty() {
            let chi = data.chi_square(&data.simulate(&s, numerics, &n)?);
            tracker.curve(Some(chi));
            return Ok((chi, (s, n)));
        }
        let r = local::run(
            &s,
            n,
            numerics,
            data,
            &others,
            local::Budget::curves(options.max_curves),
            &tracker,
        )?;
        Ok((r.chi_square(), (r.setup, r.nuisance)))
    };
    let step = |i: f64| {
        if which.is_scale() {
            value * (i * PROFILE_STEP * std_err / value).exp()
        } else {
            value + i * PROFILE_STEP * std_err
        }
    };
    let mut points = vec![(value, 0.0)];
    let mut unavailable = Vec::new();
    for side in [-1.0, 1.0] {
        let mut start = (at_best.clone(), nuisance);
        for i in 1..=PROFILE_STEPS {
            let v = step(side * i as f64);
            let Ok((chi, next)) = held(v, &start) else {
                // A trial the law cannot take (or a curve that cannot be simulated): a
                // point without a value; this side stops here.
                unavailable.push(v);
                break;
            };
            let delta = ((chi - best.chi_square) / factor).max(0.0);
            points.push((v, delta));
            start = next;
            if delta > 3.84 * 1.5 {
                break;
            }
        }
    }
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Each crossing by linear interpolation of the signed root √Δχ², nearly straight
    // in the parameter where the model is nearly linear.
    let crossing = |level: f64, side: f64| -> Option<f64> {
        let mut run: Vec<&(f64, f64)> = points
            .iter()
            .filter(|(v, _)| (v - value) * side >= 0.0)
            .collect();
        if side < 0.0 {
            run.reverse();
        }
        run.windows(2).find_map(|w| {
            let (a, b) = (w[0], w[1]);
            let (ra, rb) = (a.1.sqrt(), b.1.sqrt());
            (ra <= level && rb > level).then(|| a.0 + (b.0 - a.0) * (level - ra) / (rb - ra))
        })
    };
    Ok(Profile {
        name: which.key(),
        values: points.iter().map(|p| p.0).collect(),
        delta_chi_square: points.iter().map(|p| p.1).collect(),
        interval_68: [crossing(1.0, -1.0), crossing(1.0, 1.0)],
        interval_95: [crossing(1.96, -1.0), crossing(1.96, 1.0)],
        unavailable,
    })
}
