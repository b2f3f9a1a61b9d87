//! Small numerical helpers shared by the closed-form modules.
//!
//! Only used off the hot path (set-up of jump points, figure sampling); inner loops
//! use closed forms.

use crate::error::{Error, Result};

/// Gauss–Legendre nodes and weights on [−1, 1], 4 points (exact to degree 7).
#[doc(hidden)]
pub const GAUSS_LEGENDRE_4: [(f64, f64); 4] = [
    (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
];

/// Gauss–Legendre nodes and weights on [−1, 1], 8 points (exact to degree 15).
#[doc(hidden)]
pub const GAUSS_LEGENDRE_8: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
];

/// The mean of `values` and their sample variance (n − 1 in the denominator; at least
/// two values for a finite one).
pub(crate) fn mean_and_variance(values: impl Iterator<Item = f64> + Clone) -> (f64, f64) {
    let n = values.clone().count() as f64;
    let mean = values.clone().sum::<f64>() / n;
    let var = values.map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var)
}

/// How many leading values of a series of batch means `ys` are a transient, by the
/// marginal standard error rule (MSER; White, Simulation 69, 323, 1997): the cut d ≤ n/2
/// that minimises the variance of the remaining values over (n − d)², taken only where
/// it at least halves that of the whole series (a stationary series' minimum is at
/// d = 0 but for chance) and where dropping the d values moves the mean by more than
/// `moves_by` (a cut that changes nothing reported is chance, or a transient too small
/// to matter). Fewer than 4 values: none.
pub(crate) fn transient_cut(ys: &[f64], moves_by: f64) -> usize {
    let n = ys.len();
    if n < 4 {
        return 0;
    }
    let mean = |d: usize| ys[d..].iter().sum::<f64>() / (n - d) as f64;
    let mser = |d: usize| {
        let (rest, m) = (&ys[d..], mean(d));
        rest.iter().map(|y| (y - m).powi(2)).sum::<f64>() / ((n - d) as f64).powi(3)
    };
    let whole = mser(0);
    let (best, at) = (1..=n / 2)
        .map(|d| (d, mser(d)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("n >= 4");
    let moves = (mean(best) - mean(0)).abs() > moves_by;
    if at < 0.5 * whole && moves { best } else { 0 }
}

/// An angle difference brought into (−π, π].
pub(crate) fn wrap_angle(d: f64) -> f64 {
    use std::f64::consts::PI;
    PI - (PI - d).rem_euclid(2.0 * PI)
}

/// The polynomial through `points` (distinct abscissae) at `x`, in Lagrange form.
#[doc(hidden)]
pub fn lagrange(points: &[(f64, f64)], x: f64) -> f64 {
    (0..points.len())
        .map(|i| {
            let weight: f64 = (0..points.len())
                .filter(|&j| j != i)
                .map(|j| (x - points[j].0) / (points[i].0 - points[j].0))
                .product();
            weight * points[i].1
        })
        .sum()
}

/// Distance from `x` to the interval [lo, hi] (0 inside it).
#[inline]
#[doc(hidden)]
pub fn distance_to_interval(x: f64, lo: f64, hi: f64) -> f64 {
    (lo - x).max(x - hi).max(0.0)
}

/// Root of `f` in the bracket `[lo, hi]` (signs of `f(lo)` and `f(hi)` must differ),
/// by the Illinois variant of regula falsi: bracketing like bisection, superlinear
/// like the secant method. Stops when the bracket is below `x_tol`·(1 + |x|) or
/// `f` is exactly zero.
#[doc(hidden)]
pub fn bracketed_root(
    what: &str,
    mut f: impl FnMut(f64) -> f64,
    mut lo: f64,
    mut hi: f64,
    x_tol: f64,
) -> Result<f64> {
    let mut f_lo = f(lo);
    let mut f_hi = f(hi);
    if f_lo == 0.0 {
        return Ok(lo);
    }
    if f_hi == 0.0 {
        return Ok(hi);
    }
    if !(f_lo.is_finite() && f_hi.is_finite()) || f_lo.signum() == f_hi.signum() {
        return Err(Error::Numerical(format!(
            "{what}: no sign change in [{lo}, {hi}] (f = {f_lo}, {f_hi})"
        )));
    }
    // 200 iterations: bisection alone would reach 2^-200 of the bracket.
    let mut side = 0i8;
    for _ in 0..200 {
        let x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
        // Fall back to bisection if the secant step leaves the bracket (round-off).
        let x = if x > lo.min(hi) && x < lo.max(hi) {
            x
        } else {
            0.5 * (lo + hi)
        };
        let fx = f(x);
        if fx == 0.0 {
            return Ok(x);
        }
        if fx.signum() == f_hi.signum() {
            hi = x;
            f_hi = fx;
            if side == 1 {
                f_lo *= 0.5;
            }
            side = 1;
        } else {
            lo = x;
            f_lo = fx;
            if side == -1 {
                f_hi *= 0.5;
            }
            side = -1;
        }
        if (hi - lo).abs() <= x_tol * (1.0 + x.abs()) {
            return Ok(0.5 * (lo + hi));
        }
    }
    Err(Error::Numerical(format!("{what}: no convergence")))
}

/// Root of `f` in `[lo, hi]` (signs of f at the ends must differ) by Newton's method
/// safeguarded with bisection; `f` returns the value and its derivative. Quadratic once
/// close, never leaves the bracket. Ends at a step below `x_tol` (absolute) or after 100
/// iterations, returning the best estimate.
#[doc(hidden)]
pub fn newton_bracketed(
    f: impl Fn(f64) -> (f64, f64),
    mut lo: f64,
    mut hi: f64,
    x_tol: f64,
) -> f64 {
    let (f_lo, _) = f(lo);
    if f_lo == 0.0 {
        return lo;
    }
    let lo_negative = f_lo < 0.0;
    let mut x = 0.5 * (lo + hi);
    for _ in 0..100 {
        let (fx, dfx) = f(x);
        if fx == 0.0 {
            return x;
        }
        if (fx < 0.0) == lo_negative {
            lo = x;
        } else {
            hi = x;
        }
        let newton = x - fx / dfx;
        // Below a few ulps of x the iteration can only cycle between neighbours.
        let tol = x_tol.max(4.0 * f64::EPSILON * x.abs());
        let (a, b) = (lo.min(hi), lo.max(hi));
        if (newton - x).abs() <= tol {
            // Converged (a last step that lands on the bracket's end is not a reason to
            // fall back to bisection).
            return newton.clamp(a, b);
        }
        let next = if newton > a && newton < b && newton.is_finite() {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if (next - x).abs() <= tol {
            return next;
        }
        x = next;
    }
    x
}
