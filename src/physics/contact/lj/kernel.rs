//! The axisymmetric influence kernel of the Lennard-Jones problem and its discretisation
//! for piecewise-linear tractions (docs/src/explanation/design.md §1).
//!
//! With h̄ = h/ε and x = r/√(Rε) the gap obeys
//! h̄(x) = ᾱ + 1 + x²/2 − (32/(3π)) μ^{3/2} ∫₀^∞ f(h̄(y)) G(x, y) dy,
//! G(x, y) = y/(x+y) · K(k), k = 2√(xy)/(x+y), K the complete elliptic integral of the
//! first kind (log-singular at y = x). On each element the kernel is split as
//! G = R − w ln|x − y| with w = y/(x+y): the regular part R is integrated by
//! Gauss–Legendre, the logarithmic part exactly against a quadratic interpolant of w·φ.

use crate::numeric::{GAUSS_LEGENDRE_8, distance_to_interval};
use nalgebra::DMatrix;
use rayon::prelude::*;
use std::f64::consts::PI;

/// K(k) from the complementary modulus k' = √(1 − k²) (Bulirsch's cel1, the AGM).
#[inline]
fn elliptic_k(kc: f64) -> f64 {
    ellip::cel1(kc).unwrap_or(f64::INFINITY)
}

/// The kernel G(x, y) = y/(x+y) K(2√(xy)/(x+y)); G(0, y) = π/2.
#[inline]
pub fn kernel(x: f64, y: f64) -> f64 {
    if x == 0.0 {
        return PI / 2.0;
    }
    let s = x + y;
    y / s * elliptic_k((x - y).abs() / s)
}

/// The regular part R = G + w ln|x − y| = w (K(k) − ln(4/k') + ln(4(x+y))), continuous at
/// y = x (K − ln(4/k') → 0 as k' → 0).
#[inline]
#[doc(hidden)]
pub fn regular(x: f64, y: f64) -> f64 {
    let s = x + y;
    let kc = (x - y).abs() / s;
    let excess = if kc < 1e-4 {
        // K = ln(4/k') + (k'²/4)(ln(4/k') − 1) + O(k'⁴ ln k').
        let l = (4.0 / kc).ln();
        if kc == 0.0 {
            0.0
        } else {
            0.25 * kc * kc * (l - 1.0)
        }
    } else {
        elliptic_k(kc) - (4.0 / kc).ln()
    };
    y / s * (excess + (4.0 * s).ln())
}

/// ∫ t^n ln|t| dt, n = 0, 1, 2 (zero at t = 0).
#[inline]
fn t_log_antiderivative(t: f64, n: usize) -> f64 {
    if t == 0.0 {
        return 0.0;
    }
    let l = t.abs().ln();
    match n {
        0 => t * l - t,
        1 => 0.5 * t * t * l - 0.25 * t * t,
        _ => t * t * t / 3.0 * l - t * t * t / 9.0,
    }
}

/// ∫_a^b g(y) ln|x − y| dy for g quadratic through (a, g_a), ((a+b)/2, g_m), (b, g_b).
#[doc(hidden)]
pub fn log_integral(x: f64, a: f64, b: f64, g_a: f64, g_m: f64, g_b: f64) -> f64 {
    // g as c0 + c1 t + c2 t² in t = y − x.
    let h = b - a;
    let m = 0.5 * (a + b);
    // Newton form in y, then shift to t.
    let d1 = (g_m - g_a) / (0.5 * h);
    let d2 = ((g_b - g_m) / (0.5 * h) - d1) / h;
    // g = g_a + d1 (y − a) + d2 (y − a)(y − m); with y = x + t.
    let (pa, pm) = (x - a, x - m);
    let c2 = d2;
    let c1 = d1 + d2 * (pa + pm);
    let c0 = g_a + d1 * pa + d2 * pa * pm;
    let (ta, tb) = (a - x, b - x);
    let f = |n: usize| t_log_antiderivative(tb, n) - t_log_antiderivative(ta, n);
    c0 * f(0) + c1 * f(1) + c2 * f(2)
}

/// Integrals of G(x, y) against the two hat functions of element [a, b]:
/// (∫ (b − y)/(b − a) G dy, ∫ (y − a)/(b − a) G dy).
pub(crate) fn element_integrals(x: f64, a: f64, b: f64) -> (f64, f64) {
    let h = b - a;
    if x == 0.0 {
        return (PI / 2.0 * h / 2.0, PI / 2.0 * h / 2.0);
    }
    let distance = distance_to_interval(x, a, b);
    let (mid, half) = (0.5 * (a + b), 0.5 * h);
    if distance > 2.0 * h {
        let (mut left, mut right) = (0.0, 0.0);
        for (node, weight) in GAUSS_LEGENDRE_8 {
            let y = mid + half * node;
            let g = weight * half * kernel(x, y);
            left += g * (b - y) / h;
            right += g * (y - a) / h;
        }
        return (left, right);
    }
    // Near or on the element: split off the logarithm. The regular part is continuous but
    // has a kink at y = x; integrate it on the two sides separately.
    let mut left = 0.0;
    let mut right = 0.0;
    let (pieces, count) = if x > a && x < b {
        ([(a, x), (x, b)], 2)
    } else {
        ([(a, b), (b, b)], 1)
    };
    for &(p, q) in &pieces[..count] {
        let (m, hh) = (0.5 * (p + q), 0.5 * (q - p));
        for (node, weight) in GAUSS_LEGENDRE_8 {
            let y = m + hh * node;
            let g = weight * hh * regular(x, y);
            left += g * (b - y) / h;
            right += g * (y - a) / h;
        }
    }
    let w = |y: f64| y / (x + y);
    let ym = mid;
    left -= log_integral(x, a, b, w(a), w(ym) * 0.5, 0.0);
    right -= log_integral(x, a, b, 0.0, w(ym) * 0.5, w(b));
    (left, right)
}

/// One row of the influence matrix: ∫ φ_j(y) G(x, y) dy for every node j.
pub fn influence_row(x: f64, nodes: &[f64]) -> Vec<f64> {
    let n = nodes.len();
    let mut row = vec![0.0; n];
    for e in 0..n - 1 {
        let (l, r) = element_integrals(x, nodes[e], nodes[e + 1]);
        row[e] += l;
        row[e + 1] += r;
    }
    row
}

/// Influence matrix M with M_ij = ∫ φ_j(y) G(x_i, y) dy for the hat functions φ_j of the
/// mesh `nodes` (collocation at the nodes), assembled in parallel.
pub fn influence_matrix(nodes: &[f64]) -> DMatrix<f64> {
    let n = nodes.len();
    let rows: Vec<Vec<f64>> = nodes.par_iter().map(|&x| influence_row(x, nodes)).collect();
    DMatrix::from_fn(n, n, |i, j| rows[i][j])
}

/// Weights W_j = ∫ φ_j(x) x dx, so that ∫₀^X f x dx = Σ W_j f_j for piecewise-linear f.
pub fn moment_weights(nodes: &[f64]) -> Vec<f64> {
    let mut w = vec![0.0; nodes.len()];
    for e in 0..nodes.len() - 1 {
        let (a, b) = (nodes[e], nodes[e + 1]);
        w[e] += (b - a) * (2.0 * a + b) / 6.0;
        w[e + 1] += (b - a) * (a + 2.0 * b) / 6.0;
    }
    w
}
