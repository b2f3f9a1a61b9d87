//! The Lennard-Jones results for one μ with their discretisation errors, cached on disk.

use super::curve::CurvePoint;
use super::moving::{self, MovingOptions, MovingSpec};
use crate::error::{Error, Result, positive};
use crate::report::output;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Version of the cached data: bump when the numerics change.
const CACHE_VERSION: u32 = 3;

/// Elements across the tensile annulus (at the largest contact radius traced) in the
/// production mesh.
pub const ELEMENTS_PER_ANNULUS: f64 = 7.0;

/// Largest Tabor parameter accepted (the continuation stalls near the fold A from μ = 13
/// on; at μ = 12 it takes ~9 s).
pub const MAX_TABOR_MU: f64 = 12.0;

/// Spacing ratio of the coarse mesh of the error estimate to the production mesh.
pub const COARSE_RATIO: f64 = 1.5;

/// A value with its estimated discretisation error (Richardson, from the production
/// mesh and one with every spacing 1.5 times larger). The moving-mesh results converge
/// at first order in the edge spacing (Ŵ(5) on meshes 1.5, 1, 0.67 and 0.44 times the
/// old production spacing: 3.25528, 3.25367, 3.25260, 3.25186 — differences in
/// proportion to the spacing differences), so the estimate assumes first order.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// The production-mesh value.
    pub value: f64,
    /// |value − coarse| / (1.5 − 1).
    pub error: f64,
}

impl Estimate {
    fn richardson(fine: f64, coarse: f64) -> Self {
        Self {
            value: fine,
            error: (fine - coarse).abs() / (COARSE_RATIO - 1.0),
        }
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
    /// Nodes of the coarse mesh.
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

fn cache_path(tabor_mu: f64, per_annulus: f64) -> PathBuf {
    cache_dir().join(format!(
        "lj-v{CACHE_VERSION}-mu{:016x}-q{:016x}.json",
        tabor_mu.to_bits(),
        per_annulus.to_bits()
    ))
}

/// Solve the Lennard-Jones problem for `tabor_mu` on the production mesh and a coarse
/// one, or read the result from the cache. `use_cache = false` always computes (and
/// still refreshes the cache).
pub fn solve(tabor_mu: f64, use_cache: bool) -> Result<LjSolution> {
    positive("Tabor parameter mu", tabor_mu)?;
    if !(0.5..=MAX_TABOR_MU).contains(&tabor_mu) {
        return Err(Error::NotApplicable(format!(
            "the Lennard-Jones solver covers 0.5 <= mu <= {MAX_TABOR_MU} (mu = {tabor_mu}); \
             below, the curve has no hysteresis loop; above, the jump onto the contact \
             branch at A is too abrupt for the continuation (it stalls from mu = 13); \
             the hybrid law (--law hybrid) approaches the numerical loss as mu grows"
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
    let opts = MovingOptions::default();
    // The two meshes are independent: trace them on both cores.
    let (fine, coarse) = rayon::join(
        || moving::trace(&spec, &opts),
        || moving::trace(&spec.scaled(COARSE_RATIO), &opts),
    );
    let (fine, coarse) = (fine?, coarse?);
    let r = Estimate::richardson;
    let solution = LjSolution {
        tabor_mu,
        alpha_hat_a: r(fine.fold_a.alpha_hat, coarse.fold_a.alpha_hat),
        t_hat_a: r(fine.fold_a.t_hat, coarse.fold_a.t_hat),
        alpha_hat_c: r(fine.fold_c.alpha_hat, coarse.fold_c.alpha_hat),
        t_hat_c: r(fine.fold_c.t_hat, coarse.fold_c.t_hat),
        pull_off_hat: r(fine.pull_off_hat, coarse.pull_off_hat),
        w_hat: r(fine.w_hat, coarse.w_hat),
        nodes: fine.nodes,
        nodes_coarse: coarse.nodes,
        steps: fine.steps,
        s_a: fine.fold_a.s,
        s_c: fine.fold_c.s,
        curve: fine.points,
    };
    // A cache that cannot be written only costs time later.
    if let Ok(text) = serde_json::to_string(&solution) {
        let _ = std::fs::create_dir_all(cache_dir());
        let _ = output::write_bytes(&path, text.as_bytes());
    }
    Ok(solution)
}
