//! Small numerical helpers shared by the closed-form modules.
//!
//! Only used off the hot path (set-up of jump points, figure sampling); inner loops
//! use closed forms.

use crate::error::{Error, Result};

/// Root of `f` in the bracket `[lo, hi]` (signs of `f(lo)` and `f(hi)` must differ),
/// by the Illinois variant of regula falsi: bracketing like bisection, superlinear
/// like the secant method. Stops when the bracket is below `x_tol` (absolute) or
/// `f` is exactly zero.
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_cube_root_of_two() {
        let r = bracketed_root("t", |x| x * x * x - 2.0, 0.0, 2.0, 1e-15).unwrap();
        assert!((r - 2f64.cbrt()).abs() < 1e-14);
    }

    #[test]
    fn rejects_bracket_without_sign_change() {
        assert!(bracketed_root("t", |x| x * x + 1.0, -1.0, 1.0, 1e-12).is_err());
    }
}
