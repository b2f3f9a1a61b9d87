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
pub struct Problem {
    /// Tabor parameter μ.
    pub tabor_mu: f64,
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
            tabor_mu,
            nodes,
            cm,
            moments,
            factorisations: Default::default(),
        }
    }

    /// LU factorisations done so far.
    pub fn factorisations(&self) -> usize {
        self.factorisations
            .load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the mesh is empty (never for a built problem).
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
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

    /// Residual of the gap equation.
    pub fn residual(&self, s: &Solution) -> DVector<f64> {
        let (f, _) = self.tractions(&s.gap);
        let mut r = &self.cm * f;
        for (i, &x) in self.nodes.iter().enumerate() {
            r[i] += s.gap[i] - s.alpha_bar - 1.0 - 0.5 * x * x;
        }
        r
    }

    /// Force T̂ and its gradient with respect to the nodal gaps.
    pub fn force(&self, gap: &DVector<f64>) -> (f64, DVector<f64>) {
        let (f, df) = self.tractions(gap);
        let k = 16.0 * PI / 3.0;
        let n = gap.len();
        let mut t = 0.0;
        let mut grad = DVector::zeros(n);
        for j in 0..n {
            t += self.moments[j] * f[j];
            grad[j] = k * self.moments[j] * df[j];
        }
        // Beyond the last node the gap continues as h_N + (x² − X²)/2:
        // ∫ f x dx = ∫_{h_N}^∞ f dh = h_N⁻²/2 − h_N⁻⁸/8.
        let h = gap[n - 1];
        t += 0.5 * h.powi(-2) - 0.125 * h.powi(-8);
        grad[n - 1] += k * (-h.powi(-3) + h.powi(-9));
        (k * t, grad)
    }

    /// Jacobian of the residual with respect to the gaps: I + cM diag(f').
    fn jacobian(&self, gap: &DVector<f64>) -> DMatrix<f64> {
        let (_, df) = self.tractions(gap);
        let mut j = self.cm.clone();
        for (col, d) in df.iter().enumerate() {
            j.column_mut(col).scale_mut(*d);
        }
        for i in 0..gap.len() {
            j[(i, i)] += 1.0;
        }
        j
    }

    /// The rigid-body gap ᾱ + 1 + x²/2 (a starting guess far from the sample).
    pub fn rigid(&self, alpha_bar: f64) -> Solution {
        Solution {
            gap: DVector::from_iterator(
                self.len(),
                self.nodes.iter().map(|x| alpha_bar + 1.0 + 0.5 * x * x),
            ),
            alpha_bar,
        }
    }

    /// Solve at fixed ᾱ by damped Newton from `guess`.
    pub fn solve_fixed_alpha(&self, guess: &Solution, tol: f64) -> Result<(Solution, usize)> {
        let mut s = guess.clone();
        for it in 1..=50 {
            let r = self.residual(&s);
            if Self::residual_norm(&r, &s.gap) < tol {
                return Ok((s, it - 1));
            }
            let lu = self.jacobian(&s.gap).lu();
            let dx = lu
                .solve(&(-r))
                .ok_or_else(|| Error::Numerical("singular Jacobian in the LJ solver".into()))?;
            apply_damped(&mut s.gap, &dx);
        }
        Err(Error::Numerical(
            "LJ Newton iteration at fixed separation did not converge".into(),
        ))
    }

    /// One pseudo-arclength corrector: solve R = 0 together with
    /// τ_α(α̂ − α̂₀) + τ_T(T̂ − T̂₀) = Δs from the predictor `guess`, with a chord Newton
    /// iteration that reuses `lu` (refactorised when convergence slows).
    #[allow(clippy::too_many_arguments)]
    pub fn arclength_step(
        &self,
        guess: &Solution,
        anchor: (f64, f64),
        tangent: (f64, f64),
        ds: f64,
        tol: f64,
        lu: &mut Option<nalgebra::linalg::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
    ) -> Result<(Solution, usize)> {
        let n = self.len();
        let mu = self.tabor_mu;
        let mut s = guess.clone();
        let mut last_norm = f64::INFINITY;
        let mut fresh = false;
        for it in 1..=40 {
            let r = self.residual(&s);
            let (t, grad) = self.force(&s.gap);
            let g = tangent.0 * (s.alpha_bar / mu - anchor.0) + tangent.1 * (t - anchor.1) - ds;
            let norm = Self::residual_norm(&r, &s.gap).max(g.abs());

            if norm < tol {
                return Ok((s, it - 1));
            }
            if lu.is_none() || (norm > 0.8 * last_norm && !fresh) {
                // Bordered Jacobian [[J, −1], [τ_T ∇T̂ᵀ, τ_α/μ]].
                let mut big = DMatrix::zeros(n + 1, n + 1);
                big.view_mut((0, 0), (n, n))
                    .copy_from(&self.jacobian(&s.gap));
                for i in 0..n {
                    big[(i, n)] = -1.0;
                    big[(n, i)] = tangent.1 * grad[i];
                }
                big[(n, n)] = tangent.0 / mu;
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
            rhs[n] = -g;
            let dx = lu
                .as_ref()
                .expect("factorised above")
                .solve(&rhs)
                .ok_or_else(|| Error::Numerical("singular bordered Jacobian".into()))?;
            let scale = apply_damped(&mut s.gap, &dx.rows(0, n).into_owned());

            s.alpha_bar += scale * dx[n];
            if s.gap.iter().any(|h| !h.is_finite() || *h <= 0.0) {
                return Err(Error::Numerical("LJ gap left the physical range".into()));
            }
        }
        Err(Error::Numerical(
            "LJ continuation step did not converge".into(),
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
