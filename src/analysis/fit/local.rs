//! The local stage of a fit: Levenberg–Marquardt (the `levenberg-marquardt` crate, a
//! port of MINPACK's lmder; Moré, 1978) from one start, each scale fitted as its
//! logarithm and each offset in its unit, the Jacobian by forward differences of whole
//! simulated curves (each point a converged steady state, started from the last).

use super::model::{Curve, Measured, Nuisance, Parameter};
use super::progress::Tracker;
use crate::dynamics::setup::{Numerics, TapSetup};
use crate::error::Error;
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt, TerminationReason};
use nalgebra::{DMatrix, DVector, Dyn, Owned};
use std::cell::{Cell, RefCell};

/// Forward-difference steps: 1e-4 in the logarithm of a scale (a relative change of
/// 1e-4), 1e-3 of an offset's unit (1 pm, 0.001°) — far above the steady states' own
/// error (their orbits are converged to 1e-7 of A₀ and better), far below the data's
/// resolution.
#[doc(hidden)]
pub const LOG_STEP: f64 = 1e-4;
const OFFSET_STEP: f64 = 1e-3;
/// The steps where the curve holds thermal averages ([`Measured::thermal`]): under the
/// same noise (each point's seed fixed) an average still moves by about its standard
/// error when a parameter moves at all — on the defaults' JKR approach at 300 K, 2000
/// periods, a step of 1e-4 in log E* moved the averaged phases by up to 0.01° (their
/// standard errors 0.007–0.035°) where the change the step makes is 5e-4°; a step of
/// 1e-2 changes them by 0.045°, above that noise. 30 pm moves the phase there by 0.1°.
///
/// The same steps where more than a quarter of the curve's points are mode locks or
/// graze a switch (not [`Curve::well_defined`]): their values step as a parameter moves,
/// and a difference of 1e-4 sees a flat tread or a riser, not the slope of the stairs.
/// A local run from far off can meet such a curve on its way (the hybrid defaults'
/// approach from 0.7 E* and 1.2 Δγ passes E* ≈ 0.4 GPa, Δγ ≈ 0.12 J/m², where the
/// tip jumps in only on some periods at every point): with the short step the run
/// stalled there at χ²/dof 2 829 or crossed it in 76 curves, depending on the last bits
/// of E_ts; with the wide one it reaches the minimum in 28 curves either way.
const AVERAGED_LOG_STEP: f64 = 1e-2;
const AVERAGED_OFFSET_STEP: f64 = 3e-2;
/// The largest change of a weighted residual below which a difference step counts as
/// having moved nothing (its column of the Jacobian is zero): 1e-8 of a standard
/// deviation. Round-off alone moves a converged curve by less: a step of 1e-4 in
/// the log of a viscosity the tip never meets moved the hybrid defaults' attractive
/// approach by up to 1e-21 m and 1.3e-11° (5e-11 and 2.6e-10 of the 0.02 nm and
/// 0.05° the test gives), and a parameter that moved the data by 1e-8 σ over that
/// step would have a standard error in its logarithm in the thousands: no value either
/// way. Without it, whether such a column counted as a null direction turned on its
/// round-off staying below 1e-8 of the largest singular value.
const UNRESOLVED: f64 = 1e-8;
/// A local run keeps each material parameter within this of its start in the
/// logarithm (a factor 100 either way): beyond, a trial is refused like one that cannot
/// be simulated (without the bound a fit of a law that cannot describe the data walks
/// to absurd values, 1 kPa say).
const MAX_LOG_STEP: f64 = 4.605_170_185_988_091;
/// A run cut when it crawls ([`run`]'s `describes`): χ² fell by less than this fraction
/// over the last [`CRAWL_ITERATIONS`] iterations. On issue 43's branch-jumping curve
/// the best-ranked start heads for a minimum at χ²/dof 134 and spends 60 curves
/// lowering χ² from 10 051 to 10 034; the start that reaches the truth falls by orders
/// of magnitude in five iterations.
const CRAWL_FRACTION: f64 = 0.01;
const CRAWL_ITERATIONS: usize = 3;
/// The length of the residual vector a trial that cannot be simulated is given: larger
/// than any curve's, finite.
const UNSIMULATED: f64 = 1e100;

/// Where one local run ended.
#[doc(hidden)]
pub struct LocalRun {
    /// The setup and nuisance values at the end.
    pub setup: TapSetup,
    pub nuisance: Nuisance,
    /// The fitted parameters' values there (SI).
    pub values: Vec<f64>,
    /// The curve there and its weighted residuals.
    pub curve: Curve,
    pub residuals: DVector<f64>,
    /// Why the optimiser stopped, and whether that was one of its convergence tests.
    pub termination: String,
    pub lm_converged: bool,
    /// Whether it stopped because its budget of curves ran out (it may go on).
    pub out_of_budget: bool,
}

impl LocalRun {
    /// χ² at the end.
    pub fn chi_square(&self) -> f64 {
        self.residuals.norm_squared()
    }
}

/// What the optimiser's reason to stop means, in words.
fn termination_words(t: &TerminationReason) -> String {
    match t {
        TerminationReason::Converged { ftol, xtol } => match (ftol, xtol) {
            (true, true) => "χ² and the steps both stopped changing".into(),
            (true, false) => "χ² stopped changing".into(),
            _ => "the steps became smaller than their tolerance".into(),
        },
        TerminationReason::Orthogonal => {
            "the residuals are orthogonal to every direction the parameters move them".into()
        }
        TerminationReason::ResidualsZero => "the residuals are zero".into(),
        TerminationReason::LostPatience => "the budget of simulated curves ran out".into(),
        TerminationReason::NoImprovementPossible(what) => {
            format!("no step lowers χ² any further ({what} at round-off)")
        }
        TerminationReason::User(_) => "a trial curve could not be simulated".into(),
        TerminationReason::Numerical(what) => format!("a non-finite {what} was met"),
        other => format!("{other:?}"),
    }
}

/// Whether a curve and its weighted residuals describe the data.
pub(crate) type Describes<'a> = &'a dyn Fn(&Curve, &[f64]) -> bool;

/// What a local run may spend: at most `max_curves` simulated curves besides the
/// final curve's, and, with `describes`, no crawling far from the data ([`run`]).
#[derive(Clone, Copy)]
#[doc(hidden)]
pub struct Budget<'a> {
    pub max_curves: usize,
    pub describes: Option<Describes<'a>>,
}

impl Budget<'_> {
    /// `max_curves` curves, no cut for crawling.
    pub fn curves(max_curves: usize) -> Self {
        Self {
            max_curves,
            describes: None,
        }
    }
}

/// Levenberg–Marquardt over `params` from `setup` and `nuisance` (the start) within
/// `budget`; an error where a trial curve could not be simulated. With the budget's
/// `describes`, a run that crawls — χ² down by less than [`CRAWL_FRACTION`] over
/// [`CRAWL_ITERATIONS`] iterations — where its curve does not describe the data is cut
/// there (as if its budget had run out: it may go on).
pub(crate) fn run(
    setup: &TapSetup,
    nuisance: Nuisance,
    numerics: &Numerics,
    data: &Measured,
    params: &[Parameter],
    budget: Budget,
    tracker: &Tracker,
) -> crate::error::Result<LocalRun> {
    let max_curves = budget.max_curves;
    let starts: Vec<f64> = params.iter().map(|p| p.value(setup, &nuisance)).collect();
    let problem = Problem::new(
        (setup, nuisance, &starts),
        numerics,
        data,
        params,
        budget,
        tracker,
    );
    let (problem, report) = LevenbergMarquardt::new()
        .with_patience(max_curves.div_ceil(params.len() + 1).max(1))
        .minimize(problem);
    if let Some(e) = problem.failure.borrow_mut().take() {
        return Err(Error::NotApplicable(format!(
            "the fit stopped where a trial curve could not be simulated ({e}). Such a step \
             means the data pull the parameters far from the start: the law or the fixed \
             parameters may not describe these data, or the start is far off"
        )));
    }
    let spent = problem.curves.get() >= max_curves + params.len() + 2;
    let crawled = problem.crawled.get();
    let termination = match report.termination {
        TerminationReason::User(_) if spent || crawled => TerminationReason::LostPatience,
        t => t,
    };
    let x = problem.x.clone();
    let (setup, nuisance) = problem.physical(&x);
    // The curve at the end (cached where the optimiser evaluated it last).
    let mut p = problem;
    p.max_curves = usize::MAX / 2;
    p.evaluate(&x)
        .ok_or_else(|| Error::Numerical("the fitted curve could not be simulated".into()))?;
    let curve = p
        .cache
        .borrow()
        .as_ref()
        .map(|(_, c, _)| c.clone())
        .expect("the solution was just evaluated");
    let residuals = DVector::from_vec(data.residuals(&curve));
    Ok(LocalRun {
        values: params.iter().map(|q| q.value(&setup, &nuisance)).collect(),
        setup,
        nuisance,
        curve,
        residuals,
        termination: if crawled {
            format!(
                "cut: χ² fell by less than {} % over {CRAWL_ITERATIONS} iterations where the \
                 curve does not describe the data",
                100.0 * CRAWL_FRACTION
            )
        } else {
            termination_words(&termination)
        },
        lm_converged: termination.was_successful(),
        out_of_budget: matches!(termination, TerminationReason::LostPatience),
    })
}

/// The weighted Jacobian in the fitted coordinates at the end of `run` (forward
/// differences of simulated curves), and the curves it took.
pub(crate) fn jacobian(
    run: &LocalRun,
    numerics: &Numerics,
    data: &Measured,
    params: &[Parameter],
    tracker: &Tracker,
) -> crate::error::Result<DMatrix<f64>> {
    let starts = run.values.clone();
    let problem = Problem::new(
        (&run.setup, run.nuisance, &starts),
        numerics,
        data,
        params,
        Budget::curves(usize::MAX / 2),
        tracker,
    );
    let j = problem.jacobian_at(&problem.x, &run.residuals, &run.curve);
    if let Some(e) = problem.failure.borrow_mut().take() {
        return Err(e);
    }
    j.ok_or_else(|| Error::Numerical("the fit's Jacobian could not be simulated".into()))
}

/// The setup and nuisance values `step` (in the fitted coordinates) away from the end
/// of `run`.
pub(crate) fn stepped(
    run: &LocalRun,
    params: &[Parameter],
    step: &DVector<f64>,
) -> (TapSetup, Nuisance) {
    at_coordinates(&run.setup, run.nuisance, params, &run.values, step)
}

/// `setup` and `nuisance` with each of `params` `x` away from its value in `starts`
/// (in the fitted coordinates).
fn at_coordinates(
    setup: &TapSetup,
    nuisance: Nuisance,
    params: &[Parameter],
    starts: &[f64],
    x: &DVector<f64>,
) -> (TapSetup, Nuisance) {
    let (mut setup, mut nuisance) = (setup.clone(), nuisance);
    for ((p, &start), &xi) in params.iter().zip(starts).zip(x.iter()) {
        p.set(&mut setup, &mut nuisance, p.shifted(start, xi));
    }
    (setup, nuisance)
}

/// Coordinates, the curve simulated there and its weighted residuals.
type Evaluated = (DVector<f64>, Curve, DVector<f64>);

/// The least-squares problem the optimiser sees: x the fitted coordinates (0 at the
/// start), the residuals a simulated curve's.
#[doc(hidden)]
pub struct Problem<'a> {
    setup: &'a TapSetup,
    /// The nuisance values where the fit does not adjust them.
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
    /// Where given, a run that crawls far from the data is cut ([`run`]).
    describes: Option<Describes<'a>>,
    /// χ² at each iteration's point (each Jacobian's).
    chi_squares: RefCell<Vec<f64>>,
    /// Whether the run was cut for crawling.
    crawled: Cell<bool>,
    /// The last coordinates evaluated, their curve and its residuals.
    cache: RefCell<Option<Evaluated>>,
    tracker: &'a Tracker<'a>,
}

impl<'a> Problem<'a> {
    /// The problem of fitting `params` to `data` from `start` (the setup, the nuisance
    /// values and the fitted parameters' values there: the origin of the coordinates),
    /// within `budget`.
    #[doc(hidden)]
    pub fn new(
        (setup, base, starts): (&'a TapSetup, Nuisance, &'a [f64]),
        numerics: &'a Numerics,
        data: &'a Measured,
        params: &'a [Parameter],
        budget: Budget<'a>,
        tracker: &'a Tracker<'a>,
    ) -> Self {
        Self {
            setup,
            base,
            numerics,
            data,
            params,
            starts,
            x: DVector::zeros(params.len()),
            curves: Cell::new(0),
            max_curves: budget.max_curves,
            failure: RefCell::new(None),
            describes: budget.describes,
            chi_squares: RefCell::new(Vec::new()),
            crawled: Cell::new(false),
            cache: RefCell::new(None),
            tracker,
        }
    }

    /// The setup and the nuisance values at coordinates `x`.
    fn physical(&self, x: &DVector<f64>) -> (TapSetup, Nuisance) {
        at_coordinates(self.setup, self.base, self.params, self.starts, x)
    }

    /// The weighted residuals at `x` (None, with the failure kept, where the curve
    /// cannot be simulated or the budget of curves is spent).
    #[doc(hidden)]
    pub fn evaluate(&self, x: &DVector<f64>) -> Option<DVector<f64>> {
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
        if x.iter()
            .zip(self.params)
            .any(|(&xi, p)| p.is_material() && xi.abs() > MAX_LOG_STEP)
        {
            // Beyond any plausible value: refused like a trial that cannot be simulated.
            self.tracker.curve(None);
            let m = self.data.channels() * self.data.len();
            return Some(DVector::from_element(m, UNSIMULATED / (m as f64).sqrt()));
        }
        let (setup, nuisance) = self.physical(x);
        let simulated = self.data.simulate(&setup, self.numerics, &nuisance);
        self.curves.set(self.curves.get() + 1);
        match simulated {
            Ok(c) => {
                let r = DVector::from_vec(self.data.residuals(&c));
                self.tracker.curve(Some(r.norm_squared()));
                *self.cache.borrow_mut() = Some((x.clone(), c, r.clone()));
                Some(r)
            }
            Err(e) if !matches!(e, Error::Interrupted) && self.cache.borrow().is_some() => {
                // A trial the law cannot take (outside its range of μ, say): a step the
                // optimiser must refuse, not the end of the fit — residuals larger than
                // any curve's. (The start itself must simulate: see below.)
                self.tracker.curve(None);
                let m = self.data.channels() * self.data.len();
                Some(DVector::from_element(m, UNSIMULATED / (m as f64).sqrt()))
            }
            Err(e) => {
                self.tracker.curve(None);
                *self.failure.borrow_mut() = Some(e);
                None
            }
        }
    }

    /// The curve last evaluated (at the coordinates given last to [`Problem::evaluate`]).
    fn last_curve(&self) -> Option<Curve> {
        self.cache.borrow().as_ref().map(|(_, c, _)| c.clone())
    }

    /// Forward differences of the residuals at `x` (whose residuals are `r0`, whose
    /// curve is `at`); backward where the forward step moves a point across a branch
    /// switch and the backward step does not (a difference across the switch is a
    /// jump, not a slope: the intervals would come out as narrow as the step).
    #[doc(hidden)]
    pub fn jacobian_at(
        &self,
        x: &DVector<f64>,
        r0: &DVector<f64>,
        at: &Curve,
    ) -> Option<DMatrix<f64>> {
        let wide = at.averaged.contains(&true) || at.mostly_unsettled();
        let side = |x: &DVector<f64>, c: &Curve| branch_sides(&self.physical(x), c);
        let sides = side(x, at);
        let mut j = DMatrix::zeros(r0.len(), self.params.len());
        for (col, p) in self.params.iter().enumerate() {
            let h = match (p.is_scale(), wide) {
                (true, false) => LOG_STEP,
                (false, false) => OFFSET_STEP,
                (true, true) => AVERAGED_LOG_STEP,
                (false, true) => AVERAGED_OFFSET_STEP,
            };
            let mut shifted = x.clone();
            shifted[col] += h;
            let mut r = self.evaluate(&shifted)?;
            let mut step = h;
            // Whether a point changes branch at `at` (whose residuals `r` the curve last
            // evaluated gave); None where the curve could not be simulated.
            let crossing = |r: &DVector<f64>, at: &DVector<f64>| {
                (r.norm() < UNSIMULATED * 0.5).then(|| {
                    self.last_curve()
                        .is_some_and(|c| crosses_switch(&sides, &side(at, &c)))
                })
            };
            let forward = crossing(&r, &shifted);
            if forward != Some(false) {
                // The law's range ends within the step, or a point changes branch:
                // difference backward where that is simulated and, for a crossing,
                // crosses nothing.
                let mut back = x.clone();
                back[col] -= h;
                let rb = self.evaluate(&back)?;
                match (forward, crossing(&rb, &back)) {
                    (None, None) => return None,
                    (None, Some(_)) | (Some(true), Some(false)) => (r, step) = (rb, -h),
                    _ => {}
                }
            }
            // A step that moves no point by UNRESOLVED of its standard deviation moved
            // it by round-off: the parameter does not change the data.
            let change = r - r0;
            if change.amax() >= UNRESOLVED {
                j.set_column(col, &(change / step));
            }
        }
        Some(j)
    }
}

/// The phase's distance from the free phase within which a point counts as on neither
/// branch, degrees: a point leaving the free oscillation moves off it smoothly, a
/// branch switch jumps by degrees to tens of degrees.
const BRANCH_BAND_DEG: f64 = 0.1;

/// Each point's branch in `curve` simulated at `at` (a setup and its nuisance values):
/// +1 where its phase lies above the free phase by more than [`BRANCH_BAND_DEG`] (the
/// attractive branch), −1 below (the repulsive one), 0 near it.
#[doc(hidden)]
pub fn branch_sides(at: &(TapSetup, Nuisance), curve: &Curve) -> Vec<i8> {
    let free = crate::analysis::setpoint::free_phase_deg(&at.0) + at.1.phase_offset_deg;
    curve
        .phase_deg
        .iter()
        .map(|&p| {
            if p > free + BRANCH_BAND_DEG {
                1
            } else if p < free - BRANCH_BAND_DEG {
                -1
            } else {
                0
            }
        })
        .collect()
}

/// Whether some point lies on one branch in `a` and on the other in `b`.
#[doc(hidden)]
pub fn crosses_switch(a: &[i8], b: &[i8]) -> bool {
    a.len() != b.len() || a.iter().zip(b).any(|(&x, &y)| x * y < 0)
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
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
        let at = self.last_curve()?;
        if let Some(describes) = self.describes {
            let mut history = self.chi_squares.borrow_mut();
            history.push(r0.norm_squared());
            let n = history.len();
            let crawls = n > CRAWL_ITERATIONS
                && history[n - 1 - CRAWL_ITERATIONS] - history[n - 1]
                    < CRAWL_FRACTION * history[n - 1];
            if crawls && !describes(&at, r0.as_slice()) {
                self.crawled.set(true);
                return None;
            }
        }
        self.jacobian_at(&self.x, &r0, &at)
    }
}
