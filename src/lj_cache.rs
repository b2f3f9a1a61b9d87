//! Application layer: the on-disk cache of Lennard-Jones solutions. A solve takes
//! seconds; a map or a figure asks for the same μ again and again, and so do later
//! runs. The physics library stays pure: [`install`] hands the cache to it as the
//! source the tabulated law draws from.

use crate::contact::lj::moving::{MovingOptions, Reach};
use crate::contact::lj::result::{self, ELEMENTS_PER_ANNULUS, LjSolution};
use crate::error::Result;
use crate::report::output;
use std::path::PathBuf;

/// Layout version of the cached data: bump when [`LjSolution`] changes shape.
const CACHE_VERSION: u32 = 5;

/// Every source file a solution depends on: the cache key carries their fingerprint, so
/// a cache written by a build with other numerics is never read.
const SOLVER_SOURCES: [&str; 9] = [
    include_str!("contact/lj/curve.rs"),
    include_str!("contact/lj/kernel.rs"),
    include_str!("contact/lj/moving.rs"),
    include_str!("contact/lj/result.rs"),
    include_str!("contact/lj/solver.rs"),
    include_str!("contact/jkr.rs"),
    include_str!("contact/hybrid.rs"),
    include_str!("contact/semi_rigid.rs"),
    include_str!("numeric.rs"),
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

/// The cache file of a solution: keyed by everything that determines it (μ, the reach,
/// the mesh, the continuation settings and the solver's source).
fn cache_path(tabor_mu: f64, reach: Reach) -> PathBuf {
    let opts = MovingOptions::reaching(reach);
    cache_dir().join(format!(
        "lj-v{CACHE_VERSION}-{SOLVER_FINGERPRINT:016x}-mu{:016x}-{}-q{:016x}-t{:016x}-c{:016x}.json",
        tabor_mu.to_bits(),
        match reach {
            Reach::Rigid => "rigid",
            Reach::Springs => "springs",
            Reach::Whole => "whole",
        },
        ELEMENTS_PER_ANNULUS.to_bits(),
        opts.tolerance.to_bits(),
        opts.max_chord.to_bits()
    ))
}

/// The solution for `tabor_mu` and `reach`: read from the cache when `use_cache` and
/// there, else computed ([`result::solve`]) and written to the cache (a cache that
/// cannot be written only costs time later).
pub fn solve(tabor_mu: f64, reach: Reach, use_cache: bool) -> Result<LjSolution> {
    let path = cache_path(tabor_mu, reach);
    if use_cache {
        if let Ok(text) = std::fs::read_to_string(&path) {
            if let Ok(cached) = serde_json::from_str::<LjSolution>(&text) {
                return Ok(cached);
            }
        }
    }
    let solution = result::solve(tabor_mu, reach)?;
    if let Ok(text) = serde_json::to_string(&solution) {
        let _ = std::fs::create_dir_all(cache_dir());
        let _ = output::write_bytes(&path, text.as_bytes());
    }
    Ok(solution)
}

/// Make the cache the source of the solutions the tabulated law uses.
pub fn install() {
    result::set_source(|mu, reach| solve(mu, reach, true));
}
