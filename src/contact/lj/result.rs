//! The Lennard-Jones results for one μ with their discretisation errors, cached on disk.

use super::curve::CurvePoint;
use super::moving::{self, MovingOptions, MovingSpec};
use crate::error::{Error, Result, positive};
use crate::report::output;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Layout version of the cached data: bump when [`LjSolution`] changes shape.
const CACHE_VERSION: u32 = 4;

/// Every source file a solution depends on: the cache key carries their fingerprint, so
/// a cache written by a build with other numerics is never read.
const SOLVER_SOURCES: [&str; 9] = [
    include_str!("curve.rs"),
    include_str!("kernel.rs"),
    include_str!("moving.rs"),
    include_str!("result.rs"),
    include_str!("solver.rs"),
    include_str!("../jkr.rs"),
    include_str!("../hybrid.rs"),
    include_str!("../semi_rigid.rs"),
    include_str!("../../numeric.rs"),
];

/// FNV-1a over [`SOLVER_SOURCES`], computed at compile time.
const SOLVER_FINGERPRINT: u64 = {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut f = 0;
    while f < SOLVER_SOURCES.len() {
        let bytes = SOLVER_SOURCES[f].as_bytes();
        let mut i = 0;
        while i < bytes.len() {
            hash ^= bytes[i] as u64;
            hash = hash.wrapping_mul(0x0100_0000_01b3);
            i += 1;
        }
        f += 1;
    }
    hash
};

/// Elements across the tensile annulus (at the largest contact radius traced) in the
/// production mesh.
pub const ELEMENTS_PER_ANNULUS: f64 = 7.0;

/// Smallest Tabor parameter traced: the loop closes at μ ≈ 0.70, and below this every
/// μ has none.
pub const MIN_TABOR_MU: f64 = 0.5;

/// Largest Tabor parameter accepted: at μ = 20 a solve takes ~50 s (10 s at μ = 12,
/// 5 s at μ = 10) and the continuation needs ~1100 steps; from μ = 30 it needs more
/// than its 2000.
pub const MAX_TABOR_MU: f64 = 20.0;

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
    /// The traced curve (production mesh).
    pub curve: Vec<CurvePoint>,
    /// Arclength of the fold A on `curve`.
    pub s_a: f64,
    /// Arclength of the fold C on `curve` (the contact branch follows it).
    pub s_c: f64,
}

impl LjSolution {
    /// The approach branch: the points before the fold A.
    pub fn approach_branch(&self) -> &[CurvePoint] {
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

/// Where cached solutions live: `$TAPSIM_CACHE`, else `$XDG_CACHE_HOME/tapsim`, else
/// `$HOME/.cache/tapsim`, else `.tapsim-cache`.
pub fn cache_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("TAPSIM_CACHE") {
        return PathBuf::from(dir);
    }
    if let Some(dir) = std::env::var_os("XDG_CACHE_HOME") {
        return PathBuf::from(dir).join("tapsim");
    }
    if let Some(home) = std::env::var_os("HOME") {
        return PathBuf::from(home).join(".cache").join("tapsim");
    }
    PathBuf::from(".tapsim-cache")
}

/// The cache file of a solution: keyed by everything that determines it (μ, the mesh,
/// the continuation settings and the solver's source).
fn cache_path(tabor_mu: f64, per_annulus: f64) -> PathBuf {
    let opts = MovingOptions::default();
    cache_dir().join(format!(
        "lj-v{CACHE_VERSION}-{SOLVER_FINGERPRINT:016x}-mu{:016x}-q{:016x}-t{:016x}-c{:016x}.json",
        tabor_mu.to_bits(),
        per_annulus.to_bits(),
        opts.tolerance.to_bits(),
        opts.max_chord.to_bits()
    ))
}

/// Solve the Lennard-Jones problem for `tabor_mu` on the production mesh and a coarse
/// one, or read the result from the cache. `use_cache = false` always computes (and
/// still refreshes the cache).
pub fn solve(tabor_mu: f64, use_cache: bool) -> Result<LjSolution> {
    positive("Tabor parameter mu", tabor_mu)?;
    if tabor_mu < MIN_TABOR_MU {
        return Err(Error::NoHysteresis(format!(
            "the Lennard-Jones loop closes at mu ~ 0.70 (traced down to there), so \
             mu = {tabor_mu} has none; below {MIN_TABOR_MU} the curve is not traced"
        )));
    }
    if tabor_mu > MAX_TABOR_MU {
        return Err(Error::NotApplicable(format!(
            "the Lennard-Jones solver covers mu <= {MAX_TABOR_MU} (mu = {tabor_mu}): above, \
             the continuation takes too long; the hybrid law (--law hybrid) is within \
             0.03 % of the numerical loss from mu = 12 on"
        )));
    }
    let path = cache_path(tabor_mu, ELEMENTS_PER_ANNULUS);
    if use_cache {
        if let Ok(text) = std::fs::read_to_string(&path) {
            if let Ok(cached) = serde_json::from_str::<LjSolution>(&text) {
                return Ok(cached);
            }
        }
    }
    let spec = MovingSpec::for_tabor(tabor_mu, ELEMENTS_PER_ANNULUS);
    let solution = solve_with(&spec, &MovingOptions::default())?;
    // A cache that cannot be written only costs time later.
    if let Ok(text) = serde_json::to_string(&solution) {
        let _ = std::fs::create_dir_all(cache_dir());
        let _ = output::write_bytes(&path, text.as_bytes());
    }
    Ok(solution)
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
