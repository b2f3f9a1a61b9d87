//! The Lennard-Jones results for one μ with their discretisation errors. Pure: no file
//! or environment access (the application keeps a cache, `crate::app::lj_cache`, and may
//! hand it to the laws through [`set_source`]).

use super::curve::{CurvePoint, Hysteresis};
use super::moving::{self, MovingOptions, MovingSpec, Reach};
use crate::error::{Error, Result, positive};
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// Elements across the tensile annulus (at the largest contact radius traced) in the
/// production mesh.
pub const ELEMENTS_PER_ANNULUS: f64 = 7.0;

/// Smallest Tabor parameter traced: the loop closes at μ ≈ 0.70, and below this every
/// μ has none.
pub const MIN_TABOR_MU: f64 = 0.5;

/// Largest Tabor parameter accepted: a solve takes 1.3 s at μ = 50 (the thin tensile
/// annulus needs ~670 nodes); the hybrid law is within 0.2 % of Ŵ_LJ from μ = 10 on.
pub const MAX_TABOR_MU: f64 = 50.0;

/// Spacing ratio between the three similar meshes of the error estimate (spacings 1, r
/// and r² times the production mesh's).
pub const MESH_RATIO: f64 = 1.5;

/// A value with its estimated discretisation error.
///
/// The meshes of one family are similar (every spacing, the grading included, scales
/// together), and the results converge at second order in the spacing: observed orders
/// 1.91–1.94 for Ŵ, α̂_C, T̂_C and the pull-off at μ = 2 and 5 on meshes 2.25, 1.5, 1
/// and 0.67 times the production spacing. The value is the Richardson extrapolation
/// (order 2) from the production mesh and the one r = 1.5 times coarser; the error is
/// its distance from the same extrapolation one mesh coarser (r and r²), which, the
/// remainder being of higher order, is 1.5^q − 1 ≈ 2 times the error itself. Where the
/// three meshes do not show an order between 1.6 and 2.4 (outside the asymptotic range)
/// the error is at least the whole fine–coarse difference.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// The extrapolated value.
    pub value: f64,
    /// Its estimated error (absolute).
    pub error: f64,
}

impl Estimate {
    /// From the values on the production mesh, one 1.5 times coarser and one 2.25
    /// times coarser.
    pub fn extrapolated(fine: f64, coarse: f64, coarser: f64) -> Self {
        let richardson = |f: f64, c: f64| f + (f - c) / (MESH_RATIO.powi(2) - 1.0);
        let value = richardson(fine, coarse);
        let mut error = (value - richardson(coarse, coarser)).abs();
        if !(1.6..=2.4).contains(&observed_order(fine, coarse, coarser)) {
            error = error.max((fine - coarse).abs());
        }
        Self { value, error }
    }
}

/// The convergence order shown by values on three meshes with spacings 1, r, r² (r =
/// [`MESH_RATIO`]); NaN where the differences do not shrink monotonically.
pub fn observed_order(fine: f64, coarse: f64, coarser: f64) -> f64 {
    let ratio = (coarser - coarse) / (coarse - fine);
    if ratio > 0.0 {
        ratio.ln() / MESH_RATIO.ln()
    } else {
        f64::NAN
    }
}

/// The numerical solution for one Tabor parameter.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct LjSolution {
    /// Tabor parameter μ.
    pub tabor_mu: f64,
    /// How much of the curve was traced.
    pub reach: Reach,
    /// Jump-in fold A: separation.
    pub alpha_hat_a: Estimate,
    /// Jump-in fold A: force.
    pub t_hat_a: Estimate,
    /// Jump-out fold C: separation.
    pub alpha_hat_c: Estimate,
    /// Jump-out fold C: force.
    pub t_hat_c: Estimate,
    /// Load-control pull-off force (largest T̂ on the contact branch).
    pub pull_off_hat: Estimate,
    /// Hysteresis loss Ŵ_LJ.
    pub w_hat: Estimate,
    /// Nodes of the production mesh.
    pub nodes: usize,
    /// Nodes of the coarse mesh (the coarser one has fewer still).
    pub nodes_coarse: usize,
    /// Continuation steps on the production mesh.
    pub steps: usize,
    /// The traced curve (production mesh): with the unstable branch for
    /// [`Reach::Whole`], else with a gap between the folds.
    pub curve: Vec<CurvePoint>,
    /// Arclength of the fold A on `curve`.
    pub s_a: f64,
    /// Arclength of the fold C on `curve` (the contact branch follows it).
    pub s_c: f64,
}

impl LjSolution {
    /// The loop seen through a support spring of stiffness k̂ in series, for any k̂ > 0
    /// (eqs. (22)–(23); the Lennard-Jones counterpart of (26)): the traced curve in the
    /// support separation α̂ + T̂/k̂ ([`Hysteresis::with_spring`]). A soft spring lets go
    /// near the pull-off and lands far out on the approach branch, beyond where it was
    /// traced: there the sphere is as good as rigid, and the branch continues as the
    /// rigid sphere's force (`rigid_sphere_t_hat`), scaled to meet the traced branch.
    /// Its landing on the contact branch lies where T̂ > 0, which a trace of
    /// [`Reach::Springs`] passes.
    pub fn spring_loop(&self, k_hat: f64) -> Result<Hysteresis> {
        positive("k_hat", k_hat)?;
        let first = self.curve[0];
        let far = self
            .curve
            .iter()
            .map(|p| p.alpha_hat + p.t_hat / k_hat)
            .fold(f64::NEG_INFINITY, f64::max);
        // (The fold lies between samples, a little beyond the largest.)
        let far = far + 0.01 * far.abs() + 1.0;
        if !far.is_finite() {
            return Err(Error::NotApplicable(format!(
                "k_hat = {k_hat} is too soft: the support moves further than a float holds"
            )));
        }
        if far <= first.alpha_hat {
            return Hysteresis::with_spring(&self.curve, k_hat);
        }
        // From `far` in to the first traced point, evenly in ln(α̂ + 1/μ) (T̂ falls as
        // its −2nd power), 2 % apart.
        let mu = self.tabor_mu;
        let scale = first.t_hat / rigid_sphere_t_hat(first.alpha_hat, mu);
        let (from, to) = ((far + 1.0 / mu).ln(), (first.alpha_hat + 1.0 / mu).ln());
        let count = ((from - to) / 0.02).ceil() as usize;
        let mut curve: Vec<CurvePoint> = (0..count)
            .map(|i| {
                let alpha_hat = (from + (to - from) * i as f64 / count as f64).exp() - 1.0 / mu;
                CurvePoint {
                    s: 0.0,
                    alpha_hat,
                    t_hat: scale * rigid_sphere_t_hat(alpha_hat, mu),
                    central_gap: mu * alpha_hat + 1.0,
                }
            })
            .collect();
        // Arclength continues backwards from the first traced point.
        let mut s = first.s;
        let mut next = first;
        for p in curve.iter_mut().rev() {
            s -= (next.alpha_hat - p.alpha_hat).hypot(next.t_hat - p.t_hat);
            p.s = s;
            next = *p;
        }
        curve.extend_from_slice(&self.curve);
        Hysteresis::with_spring(&curve, k_hat)
    }

    /// The approach branch: the points before the fold A.
    pub(crate) fn approach_branch(&self) -> &[CurvePoint] {
        let k = self.curve.partition_point(|p| p.s < self.s_a);
        &self.curve[..k]
    }

    /// The contact branch: the points after the fold C.
    pub fn contact_branch(&self) -> &[CurvePoint] {
        let k = self.curve.partition_point(|p| p.s <= self.s_c);
        &self.curve[k..]
    }

    /// T̂ on `branch` (approach or contact, from the two methods above) at separation α̂,
    /// by linear interpolation between traced points; `None` outside the traced range.
    pub fn force_on(branch: &[CurvePoint], alpha_hat: f64) -> Option<f64> {
        branch
            .windows(2)
            .find(|w| (w[0].alpha_hat - alpha_hat) * (w[1].alpha_hat - alpha_hat) <= 0.0)
            .map(|w| {
                let d = w[0].alpha_hat - w[1].alpha_hat;
                let f = if d == 0.0 {
                    0.0
                } else {
                    (w[0].alpha_hat - alpha_hat) / d
                };
                w[0].t_hat + f * (w[1].t_hat - w[0].t_hat)
            })
    }
}

/// T̂ of a rigid sphere at separation α̂: the traction (10) over the parabolic gap
/// h̄ = μα̂ + 1 + x²/2, ∫ f(h̄) x dx = h̄₀⁻²/2 − h̄₀⁻⁸/8, times 16π/3 (the solver's
/// normalisation). The far approach branch, where the deformation no longer matters.
pub(crate) fn rigid_sphere_t_hat(alpha_hat: f64, tabor_mu: f64) -> f64 {
    let h0 = tabor_mu * alpha_hat + 1.0;
    16.0 * std::f64::consts::PI / 3.0 * (0.5 * h0.powi(-2) - 0.125 * h0.powi(-8))
}

/// Solve the Lennard-Jones problem for `tabor_mu` on the production mesh family (the
/// production mesh and the ones 1.5 and 2.25 times coarser), tracing as much of the
/// curve as `reach` asks for. Below [`MIN_TABOR_MU`] there is no loop
/// ([`Error::NoHysteresis`]); above [`MAX_TABOR_MU`] the solver does not go.
///
/// ```
/// use tapsim::contact::lj::{Reach, solve};
///
/// // The paper's case μ = 5 (it prints 3.2482; the converged value is 3.2493).
/// let s = solve(5.0, Reach::Rigid)?;
/// assert!((s.w_hat.value - 3.2493).abs() < 2e-4 && s.w_hat.error < 2e-4);
/// assert!(s.alpha_hat_c.value > s.alpha_hat_a.value);
/// # Ok::<(), tapsim::Error>(())
/// ```
pub fn solve(tabor_mu: f64, reach: Reach) -> Result<LjSolution> {
    positive("Tabor parameter mu", tabor_mu)?;
    if tabor_mu < MIN_TABOR_MU {
        return Err(Error::NoHysteresis(format!(
            "the Lennard-Jones loop closes at mu ~ 0.70 (traced down to there), so \
             mu = {tabor_mu} has none; below {MIN_TABOR_MU} the curve is not traced"
        )));
    }
    if tabor_mu > MAX_TABOR_MU {
        return Err(Error::NotApplicable(format!(
            "the Lennard-Jones solver covers {MIN_TABOR_MU} <= mu <= {MAX_TABOR_MU} \
             (mu = {tabor_mu}); from mu = 10 on the hybrid law is within \
             0.2 % of the numerical loss, and closer as mu grows"
        )));
    }
    let spec = MovingSpec::for_tabor(tabor_mu, ELEMENTS_PER_ANNULUS);
    solve_with(&spec, &MovingOptions::reaching(reach))
}

/// Where solutions come from for those who do not solve themselves (the tabulated law):
/// [`solve`], unless the application has installed another source with [`set_source`].
pub type Source = fn(f64, Reach) -> Result<LjSolution>;

static SOURCE: OnceLock<Source> = OnceLock::new();

/// Install the source of solutions (e.g. a cache in front of [`solve`]) for the rest of
/// the process; a second call is ignored.
pub fn set_source(source: Source) {
    let _ = SOURCE.set(source);
}

/// The solution for `tabor_mu` and `reach` from the installed source ([`set_source`]),
/// else computed.
pub(crate) fn obtain(tabor_mu: f64, reach: Reach) -> Result<LjSolution> {
    SOURCE.get().copied().unwrap_or(solve)(tabor_mu, reach)
}

/// Solve on the mesh family of `spec` (`spec` itself and the meshes 1.5 and 2.25 times
/// coarser) with the continuation settings `opts`, extrapolating every value
/// ([`Estimate`]); no cache.
pub fn solve_with(spec: &MovingSpec, opts: &MovingOptions) -> Result<LjSolution> {
    // The meshes are independent: the fine one on one core, the two coarse ones (together
    // about as costly) on the other.
    let (fine, (coarse, coarser)) = rayon::join(
        || moving::trace(spec, opts),
        || {
            (
                moving::trace(&spec.scaled(MESH_RATIO), opts),
                moving::trace(&spec.scaled(MESH_RATIO * MESH_RATIO), opts),
            )
        },
    );
    let (fine, coarse, coarser) = (fine?, coarse?, coarser?);
    let r = |pick: fn(&super::curve::Curve) -> f64| {
        Estimate::extrapolated(pick(&fine), pick(&coarse), pick(&coarser))
    };
    Ok(LjSolution {
        tabor_mu: spec.tabor_mu,
        reach: opts.reach(),
        alpha_hat_a: r(|c| c.fold_a.alpha_hat),
        t_hat_a: r(|c| c.fold_a.t_hat),
        alpha_hat_c: r(|c| c.fold_c.alpha_hat),
        t_hat_c: r(|c| c.fold_c.t_hat),
        pull_off_hat: r(|c| c.pull_off_hat),
        w_hat: r(|c| c.w_hat),
        nodes: fine.nodes,
        nodes_coarse: coarse.nodes,
        steps: fine.steps,
        s_a: fine.fold_a.s,
        s_c: fine.fold_c.s,
        curve: fine.points,
    })
}
