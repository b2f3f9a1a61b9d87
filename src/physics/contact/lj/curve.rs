//! Continuation of the S-shaped force–separation curve T̂(α̂) of the Lennard-Jones
//! problem, its folds A (jump-in) and C (jump-out), and the hysteresis loss Ŵ_LJ.

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
    /// The points in order: approach, A, unstable branch (traced for drawing only:
    /// otherwise, or where it stopped short, a gap), C, contact branch.
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

/// ∫ T̂ dα̂ along the curve between arclengths a < b, on the cubic through the four
/// points around each interval, by 4-point Gauss–Legendre on every interval.
#[doc(hidden)]
pub fn work_between(points: &[CurvePoint], a: f64, b: f64) -> f64 {
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

/// The point where `field` is stationary between the samples around index k (a local
/// extremum there), on the cubic through the samples.
fn locate_extremum(
    points: &[CurvePoint],
    k: usize,
    field: impl Fn(&CurvePoint) -> f64 + Copy,
) -> Result<Fold> {
    let (lo, hi) = (points[k - 1].s, points[k + 1].s);
    let slope = |s: f64| cubic(points, interval(points, s), s, field).1;
    // Where the interpolating cubics do not turn between the neighbours (a shallow
    // fold near the critical μ), the sample itself.
    let s = bracketed_root("LJ fold", slope, lo, hi, 1e-14).unwrap_or(points[k].s);
    let kk = interval(points, s);
    Ok(Fold {
        s,
        alpha_hat: cubic(points, kk, s, |p| p.alpha_hat).0,
        t_hat: cubic(points, kk, s, |p| p.t_hat).0,
    })
}

/// The fold around sample index k (a local extremum of α̂ there).
fn locate_fold(points: &[CurvePoint], k: usize) -> Result<Fold> {
    locate_extremum(points, k, |p| p.alpha_hat)
}

/// The load-control pull-off: the largest T̂ on the contact branch, the points after
/// index `from` (the fold C), interpolated between the samples around the largest one
/// (a sampled maximum alone would be low by O(chord²)); `None` if there are no points
/// after `from`.
pub fn pull_off(points: &[CurvePoint], from: usize) -> Option<f64> {
    let k = (from..points.len()).max_by(|&i, &j| points[i].t_hat.total_cmp(&points[j].t_hat))?;
    let sampled = points[k].t_hat;
    if k == 0 || k + 1 >= points.len() {
        return Some(sampled);
    }
    Some(locate_extremum(points, k, |p| p.t_hat).map_or(sampled, |f| f.t_hat.max(sampled)))
}

/// First arclength after index `from` (before index `to`) where α̂ = `level`.
#[doc(hidden)]
pub fn crossing(points: &[CurvePoint], from: usize, to: usize, level: f64) -> Result<f64> {
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
            .ok_or_else(|| {
                Error::NoHysteresis(
                    "the force-separation curve has no jump-in fold: approach and retraction \
                     follow one curve (the Lennard-Jones loop closes at mu ~ 0.70)"
                        .into(),
                )
            })?;
        // C: the largest separation after A (small wiggles of the unstable branch, where
        // the contact edge crosses the coarser mesh near the axis, are not folds of
        // interest).
        let k_c = (k_a + 1..n - 1)
            .max_by(|&i, &j| points[i].alpha_hat.total_cmp(&points[j].alpha_hat))
            .filter(|&k| k + 1 < n - 1)
            .ok_or_else(|| Error::Numerical("no jump-out fold found".into()))?;
        let fold_a = locate_fold(points, k_a)?;
        let fold_c = locate_fold(points, k_c)?;
        Self::between(points, fold_a, fold_c)
    }

    /// The loop of `points` between the folds `fold_a` and `fold_c` (located on the
    /// curve or more precisely elsewhere): Ŵ = ∫_{α̂_A}^{α̂_C} (T̂_contact − T̂_approach)
    /// dα̂, the contact branch from C to where it reaches α̂_A and the approach branch
    /// from where it passes α̂_C to A. The levels matter: T̂ is large where the contact
    /// branch crosses α̂_A, so an error δ in α̂_A moves Ŵ by about T̂·δ.
    pub fn between(points: &[CurvePoint], fold_a: Fold, fold_c: Fold) -> Result<Self> {
        let n = points.len();
        let k_a = points.partition_point(|p| p.s < fold_a.s).min(n - 1);
        let k_c = points
            .partition_point(|p| p.s <= fold_c.s)
            .saturating_sub(1);
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
                 a trace for springs (Reach::Springs, LjSolution::spring_loop) does"
            ))
        })
    }
}
