//! The fit: Levenberg–Marquardt over the chosen parameters, each scale fitted as its
//! logarithm and the piezo offset in nm, the Jacobian by forward differences of whole
//! simulated curves (each point a converged steady state, started from the last).

use super::identifiability::{Identifiability, ParameterEstimate, assess};
use super::model::{Curve, Measured, Nuisance, Parameter};
use crate::dynamics::setup::{Numerics, TapSetup};
use crate::error::{Error, Result};
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Owned};
use serde::Serialize;
use std::cell::{Cell, RefCell};

/// Forward-difference steps: 1e-4 in the logarithm of a scale (a relative change of
/// 1e-4), 1e-3 nm in the offset — far above the steady states' own error (their orbits
/// are converged to 1e-7 of A₀ and better), far below the data's resolution.
const LOG_STEP: f64 = 1e-4;
const OFFSET_STEP_NM: f64 = 1e-3;

/// χ²/dof at or below which residuals are the simulation's own round-off and
/// tolerance, not a measurement's noise (at the default weights, 1e-6 of 0.02 nm).
const RESOLVED_CHI_SQUARE: f64 = 1e-6;

/// What to fit and how hard to try.
#[derive(Debug, Clone, PartialEq)]
pub struct FitOptions {
    /// The parameters adjusted (at least one, each once); the setup gives their
    /// starting values and the values of all others.
    pub parameters: Vec<Parameter>,
    /// The offset's starting value, m (z_c = position + offset).
    pub offset_start_m: f64,
    /// The detector sensitivity's starting value (1: the calibration holds); it stays
    /// there unless [`Parameter::Sensitivity`] is fitted.
    pub sensitivity_start: f64,
    /// Whether the data's standard deviations are estimated from the residuals (the
    /// covariance scaled by χ²/dof) rather than taken as given.
    pub estimate_sigma: bool,
    /// Most simulated curves (each residual or Jacobian column is one).
    pub max_curves: usize,
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
    /// Whether Levenberg–Marquardt ended on a convergence test.
    pub converged: bool,
    /// Why it ended.
    pub termination: String,
    /// Simulated curves.
    pub curves: usize,
    /// The fitted curve at the measured positions.
    pub fitted: Curve,
    /// Weighted residuals (model − measured)/σ, amplitudes first.
    pub residuals: Vec<f64>,
}

/// Fit `options.parameters` of `setup` (starting values; every other parameter fixed as
/// it gives it) to `data` by weighted least squares; `progress` is called after each
/// simulated curve with the number so far.
pub fn fit(
    setup: &TapSetup,
    numerics: &Numerics,
    data: &Measured,
    options: &FitOptions,
    progress: impl Fn(usize),
) -> Result<FitReport> {
    let data = data.clone().validated()?;
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
    crate::error::finite("offset start", options.offset_start_m)?;
    if data.setpoint_ratio.is_some() && params.contains(&Parameter::ZOffset) {
        return Err(Error::NotApplicable(
            "setpoint data have no piezo positions: there is no offset to fit".into(),
        ));
    }
    let m = data.channels() * data.len();
    if m <= params.len() {
        return Err(Error::NotApplicable(format!(
            "{m} measured values cannot fix {} parameters",
            params.len()
        )));
    }
    crate::error::positive("sensitivity start", options.sensitivity_start)?;
    // What the fit does not adjust stays at its start: the offset too (z_c = position
    // + the offset given).
    let base = Nuisance {
        offset_m: options.offset_start_m,
        sensitivity: options.sensitivity_start,
    };
    let starts: Vec<f64> = params
        .iter()
        .map(|p| p.start(setup, &base))
        .collect::<Result<_>>()?;
    let problem = Problem {
        setup,
        base,
        numerics,
        data: &data,
        params,
        starts: &starts,
        x: DVector::zeros(params.len()),
        curves: Cell::new(0),
        max_curves: options.max_curves,
        failure: RefCell::new(None),
        cache: RefCell::new(None),
        progress: &progress,
    };
    let (mut problem, report) = LevenbergMarquardt::new()
        .with_patience(options.max_curves.div_ceil(params.len() + 1).max(1))
        .minimize(problem);
    // The solution's curve and Jacobian, beyond the optimiser's budget.
    problem.max_curves = usize::MAX - params.len() - 2;
    if let Some(e) = problem.failure.borrow_mut().take() {
        return Err(Error::NotApplicable(format!(
            "the fit stopped where a trial curve could not be simulated ({e}). Such a step \
             means the data pull the parameters far from the start: the law or the fixed \
             parameters may not describe these data, or the start is far off"
        )));
    }
    let x = problem.x.clone();
    let residuals = problem
        .evaluate(&x)
        .ok_or_else(|| Error::Numerical("the fitted curve could not be simulated".into()))?;
    // The fitted curve is the one just evaluated (the Jacobian's columns replace it).
    let fitted = problem
        .cache
        .borrow()
        .as_ref()
        .map(|(_, c, _)| c.clone())
        .expect("the solution was just evaluated");
    let jacobian = problem
        .jacobian_at(&x, &residuals)
        .ok_or_else(|| Error::Numerical("the fit's Jacobian could not be simulated".into()))?;
    if let Some(e) = problem.failure.borrow_mut().take() {
        return Err(e);
    }
    let chi_square = residuals.norm_squared();
    let dof = m - params.len();
    let reduced = chi_square / dof as f64;
    let (fitted_setup, nuisance) = problem.physical(&x);
    let physical: Vec<f64> = params
        .iter()
        .map(|p| p.value(&fitted_setup, &nuisance))
        .collect();
    let scales: Vec<bool> = params.iter().map(|p| p.is_scale()).collect();
    let (estimates, identifiability) = assess(
        params,
        &jacobian,
        match (options.estimate_sigma, reduced > RESOLVED_CHI_SQUARE) {
            (false, _) => Some(1.0),
            (true, true) => Some(reduced),
            (true, false) => None,
        },
        &scales,
        &physical,
        &starts,
    );
    let mut identifiability = identifiability;
    if options.estimate_sigma && reduced <= RESOLVED_CHI_SQUARE {
        identifiability.notes.push(format!(
            "the residuals are at the simulation's own precision (χ²/dof = {reduced:.1e}): \
             the data carry no noise to estimate their standard deviations from, so no \
             intervals are given (give the standard deviations to have them)"
        ));
    }
    // χ² beyond five standard deviations of its distribution (mean dof, variance 2 dof)
    // where the standard deviations are given: the model does not describe the data.
    if !options.estimate_sigma && chi_square > dof as f64 + 5.0 * (2.0 * dof as f64).sqrt() {
        identifiability.notes.push(format!(
            "χ²/dof = {reduced:.3} is far above 1: the fitted curve does not describe the \
             data (a local minimum reached from this start, a law or fixed parameters that \
             cannot describe them, or standard deviations set too small); the intervals \
             assume a fit that does"
        ));
    }
    Ok(FitReport {
        parameters: estimates,
        identifiability,
        chi_square,
        degrees_of_freedom: dof,
        reduced_chi_square: reduced,
        sigma_estimated: options.estimate_sigma,
        converged: matches!(
            report.termination,
            levenberg_marquardt::TerminationReason::Converged { .. }
                | levenberg_marquardt::TerminationReason::Orthogonal
                | levenberg_marquardt::TerminationReason::ResidualsZero
        ),
        termination: format!("{:?}", report.termination),
        curves: problem.curves.get(),
        fitted,
        residuals: residuals.iter().copied().collect(),
    })
}

/// Coordinates, the curve simulated there and its weighted residuals.
type Evaluated = (DVector<f64>, Curve, DVector<f64>);

/// The least-squares problem the optimiser sees: x the fitted coordinates (0 at the
/// start), the residuals a simulated curve's.
struct Problem<'a, F: Fn(usize)> {
    setup: &'a TapSetup,
    /// The offset and sensitivity where the fit does not adjust them.
    base: Nuisance,
    numerics: &'a Numerics,
    data: &'a Measured,
    params: &'a [Parameter],
    starts: &'a [f64],
    x: DVector<f64>,
    curves: Cell<usize>,
    max_curves: usize,
    /// The first failure (a curve that could not be simulated), reported as the fit's.
    failure: RefCell<Option<Error>>,
    /// The last coordinates evaluated, their curve and its residuals.
    cache: RefCell<Option<Evaluated>>,
    progress: &'a F,
}

impl<F: Fn(usize)> Problem<'_, F> {
    /// The setup and the offset and sensitivity at coordinates `x`.
    fn physical(&self, x: &DVector<f64>) -> (TapSetup, Nuisance) {
        let mut setup = self.setup.clone();
        let mut nuisance = self.base;
        for ((p, &start), &xi) in self.params.iter().zip(self.starts).zip(x.iter()) {
            let value = if p.is_scale() {
                start * xi.exp()
            } else {
                start + xi * 1e-9
            };
            p.set(&mut setup, &mut nuisance, value);
        }
        (setup, nuisance)
    }

    /// The weighted residuals at `x` (None, with the failure kept, where the curve
    /// cannot be simulated or the budget of curves is spent).
    fn evaluate(&self, x: &DVector<f64>) -> Option<DVector<f64>> {
        if let Some((at, _, r)) = self.cache.borrow().as_ref() {
            if at == x {
                return Some(r.clone());
            }
        }
        if self.failure.borrow().is_some() {
            return None;
        }
        if self.curves.get() >= self.max_curves + self.params.len() + 2 {
            return None;
        }
        let (setup, nuisance) = self.physical(x);
        let simulated = self.data.simulate(&setup, self.numerics, &nuisance);
        self.curves.set(self.curves.get() + 1);
        (self.progress)(self.curves.get());
        match simulated {
            Ok(c) => {
                let r = DVector::from_vec(self.data.residuals(&c));
                *self.cache.borrow_mut() = Some((x.clone(), c, r.clone()));
                Some(r)
            }
            Err(e) => {
                *self.failure.borrow_mut() = Some(e);
                None
            }
        }
    }

    /// Forward differences of the residuals at `x` (whose residuals are `r0`).
    fn jacobian_at(&self, x: &DVector<f64>, r0: &DVector<f64>) -> Option<DMatrix<f64>> {
        let mut j = DMatrix::zeros(r0.len(), self.params.len());
        for (col, p) in self.params.iter().enumerate() {
            let h = if p.is_scale() {
                LOG_STEP
            } else {
                OFFSET_STEP_NM
            };
            let mut shifted = x.clone();
            shifted[col] += h;
            let r = self.evaluate(&shifted)?;
            j.set_column(col, &((r - r0) / h));
        }
        Some(j)
    }
}

impl<F: Fn(usize)> LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_, F> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.x.copy_from(x);
    }

    fn params(&self) -> DVector<f64> {
        self.x.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        self.evaluate(&self.x)
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let r0 = self.evaluate(&self.x)?;
        self.jacobian_at(&self.x, &r0)
    }
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
    progress: impl Fn(usize),
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
    let mut nuisance = Nuisance::offset(options.offset_start_m);
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
    let curves = Cell::new(0usize);
    // χ² with `which` held at `v`, the others refitted from `start` (setup, offset and
    // sensitivity).
    let held = |v: f64, start: &(TapSetup, Nuisance)| -> Result<(f64, (TapSetup, Nuisance))> {
        let (mut s, mut n) = start.clone();
        which.set(&mut s, &mut n, v);
        let r = if others.is_empty() {
            let c = data.simulate(&s, numerics, &n)?;
            curves.set(curves.get() + 1);
            progress(curves.get());
            let chi: f64 = data.residuals(&c).iter().map(|r| r * r).sum();
            return Ok((chi, (s, n)));
        } else {
            let done = curves.get();
            fit(
                &s,
                numerics,
                data,
                &FitOptions {
                    parameters: others.clone(),
                    offset_start_m: n.offset_m,
                    sensitivity_start: n.sensitivity,
                    estimate_sigma: false,
                    max_curves: options.max_curves,
                },
                |n| progress(done + n),
            )?
        };
        curves.set(curves.get() + r.curves);
        apply(&others, &r, &mut s, &mut n);
        Ok((r.chi_square, (s, n)))
    };
    let step = |i: f64| {
        if which.is_scale() {
            value * (i * PROFILE_STEP * std_err / value).exp()
        } else {
            value + i * PROFILE_STEP * std_err
        }
    };
    let mut points = vec![(value, 0.0)];
    for side in [-1.0, 1.0] {
        let mut start = (at_best.clone(), nuisance);
        for i in 1..=PROFILE_STEPS {
            let v = step(side * i as f64);
            let (chi, next) = held(v, &start)?;
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
    })
}
