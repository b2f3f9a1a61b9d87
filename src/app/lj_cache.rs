//! Application layer: the on-disk cache of Lennard-Jones solutions. A solve takes
//! seconds; a map or a figure asks for the same μ again and again, and so do later
//! runs. The physics library stays pure: [`install`] hands the cache to it as the
//! source the tabulated law draws from.

use crate::app::report::output;
use crate::error::Result;
use crate::physics::contact::lj::moving::{MovingOptions, Reach};
use crate::physics::contact::lj::result::{self, ELEMENTS_PER_ANNULUS, LjSolution};
use std::path::PathBuf;

/// Layout version of the cached data: bump when [`LjSolution`] changes shape.
const CACHE_VERSION: u32 = 6;

/// Every source file a solution depends on: the cache key carries their fingerprint, so
/// a cache written by a build with other numerics is never read.
const SOLVER_SOURCES: [&str; 9] = [
    include_str!("../physics/contact/lj/curve.rs"),
    include_str!("../physics/contact/lj/kernel.rs"),
    include_str!("../physics/contact/lj/moving.rs"),
    include_str!("../physics/contact/lj/result.rs"),
    include_str!("../physics/contact/lj/solver.rs"),
    include_str!("../physics/contact/jkr.rs"),
    include_str!("../physics/contact/hybrid.rs"),
    include_str!("../physics/contact/semi_rigid.rs"),
    include_str!("../numeric.rs"),
];

/// FNV-1a over [`SOLVER_SOURCES`], computed at compile time.
const SOLVER_FINGERPRINT: u64 = {
    let mut hash = crate::app::fnv::OFFSET;
    let mut f = 0;
    while f < SOLVER_SOURCES.len() {
        hash = crate::app::fnv::continued(hash, SOLVER_SOURCES[f].as_bytes());
        f += 1;
    }
    hash
};

/// The largest cache file read (the largest solutions, μ = 50 traced whole, are a few
/// hundred kB).
const MAX_ENTRY_BYTES: u64 = 64 << 20;

/// A cache file: the solution and a checksum of it (FNV-1a of the solver's fingerprint
/// and the solution's canonical JSON), so that a file changed after it was written is
/// never used.
#[derive(serde::Serialize, serde::Deserialize)]
struct Entry {
    checksum: String,
    solution: serde_json::Value,
}

/// The checksum a cache file carries for `solution` (its JSON): FNV-1a of the solver's
/// fingerprint and the solution's canonical JSON.
pub fn checksum(solution: &serde_json::Value) -> String {
    let h = crate::app::fnv::continued(
        crate::app::fnv::hash(&SOLVER_FINGERPRINT.to_le_bytes()),
        solution.to_string().as_bytes(),
    );
    format!("{h:016x}")
}

/// Whether a solution read back is one the solver could have given for `tabor_mu` and
/// `reach`: its own μ and reach, every number finite, errors and the loop not negative,
/// and the folds where the traced curve has them (its α̂ at their arclengths within 1 %
/// of theirs: the curve is the production mesh's, the folds extrapolated from it). `Err` says what is wrong.
fn plausible(s: &LjSolution, tabor_mu: f64, reach: Reach) -> std::result::Result<(), String> {
    if s.tabor_mu.to_bits() != tabor_mu.to_bits() || s.reach != reach {
        return Err(format!(
            "it holds μ = {} ({:?}), not μ = {tabor_mu} ({reach:?})",
            s.tabor_mu, s.reach
        ));
    }
    let estimates = [
        ("alpha_hat_a", s.alpha_hat_a),
        ("t_hat_a", s.t_hat_a),
        ("alpha_hat_c", s.alpha_hat_c),
        ("t_hat_c", s.t_hat_c),
        ("pull_off_hat", s.pull_off_hat),
        ("w_hat", s.w_hat),
    ];
    for (name, e) in estimates {
        if !e.value.is_finite() || !e.error.is_finite() || e.error < 0.0 {
            return Err(format!("{name} is {} ± {}", e.value, e.error));
        }
    }
    if s.w_hat.value < 0.0 {
        return Err(format!("the loss w_hat is negative ({})", s.w_hat.value));
    }
    let curve_ok = !s.curve.is_empty()
        && s.curve.windows(2).all(|w| w[1].s >= w[0].s)
        && s.curve.iter().all(|p| {
            p.s.is_finite()
                && p.alpha_hat.is_finite()
                && p.t_hat.is_finite()
                && p.central_gap.is_finite()
        });
    let span = s.curve.first().map_or(0.0, |p| p.s)..=s.curve.last().map_or(0.0, |p| p.s);
    if !curve_ok || !span.contains(&s.s_a) || !span.contains(&s.s_c) || s.nodes == 0 {
        return Err("its traced curve is not one the solver gives".into());
    }
    // α̂ on the curve at arclength `at`, by linear interpolation.
    let alpha_at = |at: f64| {
        let k = s
            .curve
            .partition_point(|p| p.s < at)
            .clamp(1, s.curve.len() - 1);
        let (p, q) = (&s.curve[k - 1], &s.curve[k]);
        let t = if q.s > p.s {
            (at - p.s) / (q.s - p.s)
        } else {
            0.0
        };
        p.alpha_hat + t * (q.alpha_hat - p.alpha_hat)
    };
    for (name, fold, at) in [
        ("alpha_hat_a", s.alpha_hat_a.value, s.s_a),
        ("alpha_hat_c", s.alpha_hat_c.value, s.s_c),
    ] {
        let on_curve = if s.curve.len() > 1 {
            alpha_at(at)
        } else {
            fold
        };
        if (on_curve - fold).abs() > 1e-2 * (1.0 + fold.abs()) {
            return Err(format!(
                "{name} is {fold}, where its curve has α̂ = {on_curve}"
            ));
        }
    }
    Ok(())
}

/// The solution cached at `path`, if the file is there and sound; `Err` says why a file
/// that is there cannot be used.
fn read(
    path: &std::path::Path,
    tabor_mu: f64,
    reach: Reach,
) -> std::result::Result<Option<LjSolution>, String> {
    if std::fs::symlink_metadata(path).is_err() {
        return Ok(None);
    }
    // A regular file of a sane size only: a FIFO put there would block the read.
    let text = crate::app::config::read_input(path, MAX_ENTRY_BYTES, crate::Error::NotApplicable)
        .map_err(|e| e.to_string())?;
    let entry: Entry = serde_json::from_slice(&text).map_err(|e| format!("unreadable: {e}"))?;
    if checksum(&entry.solution) != entry.checksum {
        return Err("its checksum does not match its content: it was changed".into());
    }
    let solution: LjSolution =
        serde_json::from_value(entry.solution).map_err(|e| format!("unreadable: {e}"))?;
    plausible(&solution, tabor_mu, reach)?;
    Ok(Some(solution))
}

/// Whether this process has used a cached solution (a numerical failure then names the
/// cache, which may be the cause).
static READ_FROM_CACHE: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Whether a cached Lennard-Jones solution was used in this run.
pub fn cache_was_read() -> bool {
    READ_FROM_CACHE.load(std::sync::atomic::Ordering::Relaxed)
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
/// cannot be written only costs time later). A cache file that fails its checksum or
/// holds a solution the solver could not have given (`plausible`) is treated as
/// missing: recomputed and replaced, with a note on stderr.
pub fn solve(tabor_mu: f64, reach: Reach, use_cache: bool) -> Result<LjSolution> {
    let path = cache_path(tabor_mu, reach);
    if use_cache {
        match read(&path, tabor_mu, reach) {
            Ok(Some(cached)) => {
                READ_FROM_CACHE.store(true, std::sync::atomic::Ordering::Relaxed);
                return Ok(cached);
            }
            Ok(None) => {}
            Err(why) => eprintln!(
                "note: the cached Lennard-Jones solution {} is not used ({why}); solving \
                 again",
                path.display()
            ),
        }
    }
    let solution = result::solve(tabor_mu, reach)?;
    if let Ok(value) = serde_json::to_value(&solution) {
        let entry = Entry {
            checksum: checksum(&value),
            solution: value,
        };
        // Into a new file or over a regular one only: whatever else sits there (a FIFO,
        // a device, a link) is left alone, and the solution not cached.
        let replaceable = match std::fs::symlink_metadata(&path) {
            Ok(meta) => meta.is_file(),
            Err(_) => true,
        };
        if let (true, Ok(text)) = (replaceable, serde_json::to_string(&entry)) {
            let _ = std::fs::create_dir_all(cache_dir());
            let _ = output::write_unannounced(&path, text.as_bytes());
        }
    }
    Ok(solution)
}

/// Make the cache the source of the solutions the tabulated law uses.
pub fn install() {
    result::set_source(|mu, reach| solve(mu, reach, true));
}
