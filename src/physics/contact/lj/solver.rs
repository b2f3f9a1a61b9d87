//! The discretised Lennard-Jones problem and its Newton solver.
//!
//! Unknowns: the gap h̄_i at the mesh nodes (and ᾱ on a continuation step). Residual
//! R_i = h̄_i − ᾱ − 1 − x_i²/2 + c Σ_j M_ij f(h̄_j), c = (32/(3π)) μ^{3/2},
//! f(h̄) = h̄⁻³ − h̄⁻⁹; force T̂ = (16π/3)(Σ_j W_j f_j + tail), the tail being the
//! exact integral of a parabolic gap beyond the last node.

use super::kernel::{influence_matrix, moment_weights};
use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;

/// Lennard-Jones traction (10) in units of 8Δγ/(3ε), and its derivative.
#[inline]
pub fn traction(h: f64) -> (f64, f64) {
    let i = 1.0 / h;
    let i3 = i * i * i;
    let i9 = i3 * i3 * i3;
    (i3 - i9, (-3.0 * i3 + 9.0 * i9) * i)
}

/// The discretised problem for one μ and one mesh.
#[derive(Debug)]
#[doc(hidden)]
// Public for its tests (tests/unit) alone; a mesh is never empty.
#[allow(clippy::len_without_is_empty)]
pub struct Problem {
    /// Mesh nodes x_i (x = r/√(Rε)).
    pub nodes: Vec<f64>,
    /// Influence matrix, pre-multiplied by c = (32/(3π)) μ^{3/2}.
    cm: DMatrix<f64>,
    /// ∫ φ_j x dx.
    moments: Vec<f64>,
    /// LU factorisations done so far (a cost measure).
    factorisations: std::sync::atomic::AtomicUsize,
}

/// A solution: the gap at the nodes and the rigid approach ᾱ = μα̂.
#[derive(Debug, Clone, PartialEq)]
#[doc(hidden)]
pub struct Solution {
    /// h̄ at the nodes.
    pub gap: DVector<f64>,
    /// ᾱ = α/ε.
    pub alpha_bar: f64,
}

impl Problem {
    /// Assemble the problem for `tabor_mu` on `nodes`.
    pub fn new(tabor_mu: f64, nodes: Vec<f64>) -> Self {
        let c = 32.0 / (3.0 * PI) * tabor_mu.powf(1.5);
        let cm = influence_matrix(&nodes) * c;
        let moments = moment_weights(&nodes);
        Self {
            nodes,
            cm,
            moments,
            factorisations: Default::default(),
        }
    }

    /// LU factorisations done so far.
    pub(crate) fn factorisations(&self) -> usize {
        self.factorisations
            .load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Tractions and their derivatives at the nodes.
    fn tractions(&self, gap: &DVector<f64>) -> (DVector<f64>, DVector<f64>) {
        let mut f = DVector::zeros(gap.len());
        let mut df = DVector::zeros(gap.len());
        for (i, &h) in gap.iter().enumerate() {
            let (v, d) = traction(h);
            f[i] = v;
            df[i] = d;
        }
        (f, df)
    }

    /// The residual's size relative to the gap (far nodes have gaps of ~10³, where an
    /// absolute tolerance would ask for more digits than double precision has).
    fn residual_norm(r: &DVector<f64>, gap: &DVector<f64>) -> f64 {
        r.iter()
            .zip(gap.iter())
            .map(|(r, h)| r.abs() / h.abs().max(1.0))
            .fold(0.0, f64::max)
    }

    /// Residual of the gap equation on the mesh stretched by `a` (nodes a·x_i): the influence matrix of a
    /// stretched mesh is a times the original (the kernel G(x, y) dy is homogeneous of
    /// degree one; a reassembled matrix differs only by its element quadrature error), so
    /// a moving mesh needs no reassembly.
    #[doc(hidden)]
    pub fn residual_scaled(&self, s: &Solution, a: f64) -> DVector<f64> {
        let (f, _) = self.tractions(&s.gap);
        let mut r = &self.cm * f;
        r *= a;
        for (i, &x) in self.nodes.iter().enumerate() {
            let x = a * x;
            r[i] += s.gap[i] - s.alpha_bar - 1.0 - 0.5 * x * x;
        }
        r
    }

    /// Force T̂ and its gradient with respect to the nodal gaps, on the mesh stretched by `a` (moments scale as a²; the
    /// tail beyond the last node does not depend on where that node is).
    #[doc(hidden)]
    pub fn force_scaled(&self, gap: &DVector<f64>, a: f64) -> (f64, DVector<f64>) {
        let (f, df) = self.tractions(gap);
        let k = 16.0 * PI / 3.0;
        let a2 = a * a;
        let n = gap.len();
        let mut t = 0.0;
        let mut grad = DVector::zeros(n);
        for j in 0..n {
            t += a2 * self.moments[j] * f[j];
            grad[j] = k * a2 * self.moments[j] * df[j];
        }
        // Beyond the last node the gap continues as h_N + (x² − X²)/2:
        // ∫ f x dx = ∫_{h_N}^∞ f dh = h_N⁻²/2 − h_N⁻⁸/8.
        let h = gap[n - 1];
        t += 0.5 * h.powi(-2) - 0.125 * h.powi(-8);
        grad[n - 1] += k * (-h.powi(-3) + h.powi(-9));
        (k * t, grad)
    }

    /// Jacobian on the mesh stretched by `a`: I + a·cM diag(f').
    fn jacobian_scaled(&self, gap: &DVector<f64>, a: f64) -> DMatrix<f64> {
        let (_, df) = self.tractions(gap);
        let mut j = self.cm.clone();
        for (col, d) in df.iter().enumerate() {
            j.column_mut(col).scale_mut(a * d);
        }
        for i in 0..gap.len() {
            j[(i, i)] += 1.0;
        }
        j
    }

    /// Solve on the mesh stretched by `a` with the gap at node `node` pinned to
    /// `target` and ᾱ free (bordered system [[J, −1], [e_nodeᵀ, 0]]), by Newton from
    /// `guess` in at most `max_iterations`, reusing `lu` while it converges fast
    /// (refactorised otherwise). Returns the solution and the iterations taken.
    pub(crate) fn solve_pinned(
        &self,
        guess: &Solution,
        a: f64,
        (node, target): (usize, f64),
        tol: f64,
        lu: &mut Option<nalgebra::linalg::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
        max_iterations: usize,
    ) -> Result<(Solution, usize)> {
        let n = self.len();
        let mut s = guess.clone();
        s.gap[node] = target;
        let mut last_norm = f64::INFINITY;
        let mut fresh = false;
        for it in 1..=max_iterations {
            let r = self.residual_scaled(&s, a);
            let norm = Self::residual_norm(&r, &s.gap);
            if norm < tol {
                return Ok((s, it - 1));
            }
            if lu.is_none() || (norm > 0.7 * last_norm && !fresh) {
                let mut big = DMatrix::zeros(n + 1, n + 1);
                big.view_mut((0, 0), (n, n))
                    .copy_from(&self.jacobian_scaled(&s.gap, a));
                for i in 0..n {
                    big[(i, n)] = -1.0;
                }
                big[(n, node)] = 1.0;
                *lu = Some(big.lu());
                self.factorisations
                    .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                fresh = true;
            } else {
                fresh = false;
            }
            last_norm = norm;
            let mut rhs = DVector::zeros(n + 1);
            rhs.rows_mut(0, n).copy_from(&(-r));
            rhs[n] = target - s.gap[node];
            let dx = lu
                .as_ref()
                .expect("factorised above")
                .solve(&rhs)
                .ok_or_else(|| Error::Numerical("singular pinned Jacobian".into()))?;
            let scale = apply_damped(&mut s.gap, &dx.rows(0, n).into_owned());
            s.alpha_bar += scale * dx[n];
            if s.gap.iter().any(|h| !h.is_finite() || *h <= 0.0) {
                return Err(Error::Numerical("LJ gap left the physical range".into()));
            }
        }
        Err(Error::Numerical(
            "LJ pinned Newton iteration did not converge".into(),
        ))
    }
}

/// Add a Newton update, scaled down so no gap shrinks by more than half; the scale used.
fn apply_damped(gap: &mut DVector<f64>, dx: &DVector<f64>) -> f64 {
    let mut scale: f64 = 1.0;
    for (h, d) in gap.iter().zip(dx.iter()) {
        if *d < -0.5 * h {
            scale = scale.min(-0.5 * h / d);
        }
    }
    gap.axpy(scale, dx, 1.0);
    scale
}
