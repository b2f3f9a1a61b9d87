//! Continuation of the S-shaped force–separation curve T̂(α̂) of the Lennard-Jones
//! problem, its folds A (jump-in) and C (jump-out), and the hysteresis loss Ŵ_LJ.

use super::solver::{Problem, Solution};
use crate::contact::hybrid::JumpIn;
use crate::error::{Error, Result};
use crate::numeric::{GAUSS_LEGENDRE_4, bracketed_root};
use serde::{Deserialize, Serialize};

/// One point of the traced curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CurvePoint {
    /// Arclength in the (α̂, T̂) plane.
    pub s: f64,
    /// Separation α̂.
    pub alpha_hat: f64,
    /// Force T̂ (tensile positive).
    pub t_hat: f64,
    /// Central gap h̄(0).
    pub central_gap: f64,
}

/// A fold of the curve (a turning point of α̂).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Fold {
    /// Arclength.
    pub s: f64,
    /// α̂ at the fold.
    pub alpha_hat: f64,
    /// T̂ at the fold.
    pub t_hat: f64,
}

/// The traced curve with its folds and the loop integral.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Curve {
    /// Tabor parameter μ.
    pub tabor_mu: f64,
    /// Mesh nodes.
    pub nodes: usize,
    /// The points in order: approach, A, unstable branch, C, contact branch.
    pub points: Vec<CurvePoint>,
    /// Jump-in fold A.
    pub fold_a: Fold,
    /// Jump-out fold C.
    pub fold_c: Fold,
    /// Load-control pull-off: the largest T̂ on the contact branch (beyond C).
    pub pull_off_hat: f64,
    /// Ŵ_LJ = ∫_{α̂_A}^{α̂_C} (T̂_contact − T̂_approach) dα̂.
    pub w_hat: f64,
    /// Continuation steps taken (accepted).
    pub steps: usize,
    /// Matrix factorisations done.
    pub factorisations: usize,
    /// Newton iterations in all.
    pub iterations: usize,
}

/// Cubic through the four points around interval k (clamped at the ends) evaluated with
/// its derivative at arclength s, for the field picked by `field`.
fn cubic(
    points: &[CurvePoint],
    k: usize,
    s: f64,
    field: impl Fn(&CurvePoint) -> f64,
) -> (f64, f64) {
    let n = points.len();
    let start = k.saturating_sub(1).min(n.saturating_sub(4));
    let p = &points[start..(start + 4).min(n)];
    // Lagrange form and its derivative.
    let mut value = 0.0;
    let mut slope = 0.0;
    for i in 0..p.len() {
        let mut li = 1.0;
        let mut dli = 0.0;
        for j in 0..p.len() {
            if j == i {
                continue;
            }
            let denom = p[i].s - p[j].s;
            // d/ds Π (s − s_j)/(s_i − s_j) by the product rule.
            dli = dli * (s - p[j].s) / denom + li / denom;
            li *= (s - p[j].s) / denom;
        }
        value += li * field(&p[i]);
        slope += dli * field(&p[i]);
    }
    (value, slope)
}

/// Index of the interval containing s.
fn interval(points: &[CurvePoint], s: f64) -> usize {
    points
        .windows(2)
        .position(|w| s <= w[1].s)
        .unwrap_or(points.len() - 2)
}

/// ∫ T̂ dα̂ along the curve between arclengths a < b.
fn work_between(points: &[CurvePoint], a: f64, b: f64) -> f64 {
    let mut total = 0.0;
    let (ka, kb) = (interval(points, a), interval(points, b));
    for k in ka..=kb {
        let lo = a.max(points[k].s);
        let hi = b.min(points[k + 1].s);
        if hi <= lo {
            continue;
        }
        let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        for (x, w) in GAUSS_LEGENDRE_4 {
            let s = mid + half * x;
            let (t, _) = cubic(points, k, s, |p| p.t_hat);
            let (_, da) = cubic(points, k, s, |p| p.alpha_hat);
            total += w * half * t * da;
        }
    }
    total
}

/// The fold in interval range around sample index k (a local extremum of α̂ there).
fn locate_fold(points: &[CurvePoint], k: usize) -> Result<Fold> {
    let (lo, hi) = (points[k - 1].s, points[k + 1].s);
    let slope = |s: f64| cubic(points, interval(points, s), s, |p| p.alpha_hat).1;
    let s = bracketed_root("LJ fold", slope, lo, hi, 1e-14)?;
    let kk = interval(points, s);
    Ok(Fold {
        s,
        alpha_hat: cubic(points, kk, s, |p| p.alpha_hat).0,
        t_hat: cubic(points, kk, s, |p| p.t_hat).0,
    })
}

/// First arclength after `from` (within the sampled range) where α̂ = `level`.
fn crossing(points: &[CurvePoint], from: usize, to: usize, level: f64) -> Result<f64> {
    for k in from..to {
        let (a, b) = (points[k].alpha_hat - level, points[k + 1].alpha_hat - level);
        if a == 0.0 {
            return Ok(points[k].s);
        }
        if a.signum() != b.signum() {
            return bracketed_root(
                "LJ level crossing",
                |s| cubic(points, k, s, |p| p.alpha_hat).0 - level,
                points[k].s,
                points[k + 1].s,
                1e-14,
            );
        }
    }
    Err(Error::Numerical(format!(
        "the traced curve never reaches alpha_hat = {level}"
    )))
}

/// The hysteresis loop of a traced S-curve: its folds and enclosed area.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hysteresis {
    /// Jump-in fold (first local minimum of α̂).
    pub fold_a: Fold,
    /// Jump-out fold (the largest α̂ after A).
    pub fold_c: Fold,
    /// ∫_{α̂_A}^{α̂_C} (T̂_contact − T̂_approach) dα̂.
    pub w_hat: f64,
}

impl Hysteresis {
    /// The loop of `points` (in curve order).
    pub fn of(points: &[CurvePoint]) -> Result<Self> {
        let n = points.len();
        let k_a = (1..n - 1)
            .find(|&k| {
                points[k].alpha_hat < points[k - 1].alpha_hat
                    && points[k].alpha_hat <= points[k + 1].alpha_hat
            })
            .ok_or_else(|| Error::Numerical("no jump-in fold found".into()))?;
        // C: the largest separation after A (small wiggles of the unstable branch, where
        // the contact edge crosses the coarser mesh near the axis, are not folds of
        // interest).
        let k_c = (k_a + 1..n - 1)
            .max_by(|&i, &j| points[i].alpha_hat.total_cmp(&points[j].alpha_hat))
            .filter(|&k| k + 1 < n - 1)
            .ok_or_else(|| Error::Numerical("no jump-out fold found".into()))?;
        let fold_a = locate_fold(points, k_a)?;
        let fold_c = locate_fold(points, k_c)?;
        let s_land = crossing(points, k_c, n - 1, fold_a.alpha_hat)?;
        let s_app = crossing(points, 0, k_a, fold_c.alpha_hat)?;
        // Along s both pieces run from α̂_C to α̂_A.
        let w_hat = work_between(points, s_app, fold_a.s) - work_between(points, fold_c.s, s_land);
        Ok(Self {
            fold_a,
            fold_c,
            w_hat,
        })
    }

    /// The loop seen through a support of stiffness k̂ in series: the same curve in the
    /// support separation α̂_S = α̂ + T̂/k̂ of eq. (22), whose folds are the spring's jump
    /// points (23) and whose area is the loss with spring losses included (the LJ
    /// counterpart of eq. (26)).
    pub fn with_spring(points: &[CurvePoint], k_hat: f64) -> Result<Self> {
        let support: Vec<CurvePoint> = points
            .iter()
            .map(|p| CurvePoint {
                alpha_hat: p.alpha_hat + p.t_hat / k_hat,
                ..*p
            })
            .collect();
        Self::of(&support).map_err(|e| {
            Error::NotApplicable(format!(
                "with k_hat = {k_hat} the traced curve does not contain the whole loop ({e}); \
                 a softer support lands deeper in contact than the solver traces"
            ))
        })
    }
}

/// Settings of the continuation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TraceOptions {
    /// Newton tolerance on the gap residual.
    pub tolerance: f64,
    /// Largest arclength step in the (α̂, T̂) plane.
    pub max_step: f64,
    /// Most continuation steps.
    pub max_steps: usize,
}

impl Default for TraceOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            max_step: 0.1,
            max_steps: 5000,
        }
    }
}

/// Trace the whole S-curve of `problem` by pseudo-arclength continuation: from far out on
/// the approach branch through the fold A, the unstable branch, the fold C, and down the
/// contact branch past the jump-in separation; then locate the folds and integrate Ŵ.
pub fn trace(problem: &Problem, opts: &TraceOptions) -> Result<Curve> {
    let mu = problem.tabor_mu;
    let guess_a = JumpIn::SemiRigid.alpha_hat_a(mu)?.unwrap_or(2.0);
    let alpha_start = (2.0 * guess_a).max(2.5);
    let point = |s: f64, sol: &Solution| CurvePoint {
        s,
        alpha_hat: sol.alpha_bar / mu,
        t_hat: problem.force(&sol.gap).0,
        central_gap: sol.gap[0],
    };
    let tol = opts.tolerance;
    let (first, _) = problem.solve_fixed_alpha(&problem.rigid(alpha_start * mu), tol)?;
    let (second, _) = problem.solve_fixed_alpha(&problem.rigid((alpha_start - 0.01) * mu), tol)?;
    let p1 = point(0.0, &first);
    let d = ((p1.alpha_hat - point(0.0, &second).alpha_hat).powi(2)
        + (p1.t_hat - point(0.0, &second).t_hat).powi(2))
    .sqrt();
    let mut points = vec![p1, point(d, &second)];
    let mut history = std::collections::VecDeque::from(vec![(0.0, first), (d, second)]);
    let mut ds = 0.01;
    let mut lu = None;
    let mut seen_c = false;
    let mut iterations_total = 0;
    let mut steps = 0;
    while steps < opts.max_steps {
        let (pp, p) = (points[points.len() - 2], points[points.len() - 1]);
        let chord = ((p.alpha_hat - pp.alpha_hat).powi(2) + (p.t_hat - pp.t_hat).powi(2)).sqrt();
        let tangent = (
            (p.alpha_hat - pp.alpha_hat) / chord,
            (p.t_hat - pp.t_hat) / chord,
        );
        // Predictor: Lagrange extrapolation in s through the last (up to) three solutions.
        let target = p.s + ds;
        let m = history.len();
        let weights: Vec<f64> = (0..m)
            .map(|i| {
                (0..m)
                    .filter(|&j| j != i)
                    .map(|j| (target - history[j].0) / (history[i].0 - history[j].0))
                    .product()
            })
            .collect();
        let mut guess = Solution {
            gap: history[0].1.gap.scale(weights[0]),
            alpha_bar: weights[0] * history[0].1.alpha_bar,
        };
        for (w, (_, sol)) in weights.iter().zip(&history).skip(1) {
            guess.gap.axpy(*w, &sol.gap, 1.0);
            guess.alpha_bar += w * sol.alpha_bar;
        }
        let step = problem
            .arclength_step(&guess, (p.alpha_hat, p.t_hat), tangent, ds, tol, &mut lu)
            .and_then(|(sol, iterations)| {
                // The corrector must land ahead along the curve, near the predictor: a
                // solution that turned back or jumped branch is refused.
                let q = point(p.s + ds, &sol);
                let along =
                    (q.alpha_hat - p.alpha_hat) * tangent.0 + (q.t_hat - p.t_hat) * tangent.1;
                let across = ((q.alpha_hat - p.alpha_hat).powi(2) + (q.t_hat - p.t_hat).powi(2)
                    - along * along)
                    .max(0.0)
                    .sqrt();
                if along > 0.5 * ds && across < 0.5 * ds {
                    Ok((sol, iterations))
                } else {
                    Err(Error::Numerical("continuation step left the branch".into()))
                }
            });
        match step {
            Ok((sol, iterations)) => {
                iterations_total += iterations;
                if iterations > 12 {
                    // A stale Jacobian: refactorise at the next step.
                    lu = None;
                }
                let q = point(p.s + ds, &sol);
                points.push(q);
                history.push_back((q.s, sol));
                if history.len() > 3 {
                    history.pop_front();
                }
                steps += 1;
                // Chord iterations are cheap (one matrix–vector product and one
                // triangular solve each): grow the step while they stay few.
                ds = match iterations {
                    0..=6 => (ds * 1.3).min(opts.max_step),
                    7..=12 => ds,
                    _ => ds * 0.7,
                };
                // Past C once α̂ has risen above the semi-rigid jump-in and come back
                // down below it on the contact branch (with a margin for the landing).
                if q.alpha_hat > guess_a + 0.3 {
                    seen_c = true;
                }
                if seen_c && q.alpha_hat < guess_a - 0.5 {
                    break;
                }
            }
            Err(_) => {
                lu = None;
                ds *= 0.5;
                if ds < 1e-6 {
                    return Err(Error::Numerical(format!(
                        "LJ continuation stalled at alpha_hat = {:.4}, T_hat = {:.4}",
                        p.alpha_hat, p.t_hat
                    )));
                }
            }
        }
    }
    let hysteresis = Hysteresis::of(&points)?;
    let (fold_a, fold_c, w_hat) = (hysteresis.fold_a, hysteresis.fold_c, hysteresis.w_hat);
    let k_c = interval(&points, fold_c.s);
    let pull_off_hat = points[k_c..]
        .iter()
        .map(|p| p.t_hat)
        .fold(fold_c.t_hat, f64::max);
    Ok(Curve {
        tabor_mu: mu,
        nodes: problem.len(),
        points,
        fold_a,
        fold_c,
        pull_off_hat,
        w_hat,
        steps,
        factorisations: problem.factorisations(),
        iterations: iterations_total,
    })
}
