//! `tapsim lj`: the full Lennard-Jones numerical solution for one μ.

use crate::app::config::number;
use crate::app::report::{lj as report, output};
use crate::error::Result;
use crate::physics::contact::lj::Reach;
use crate::physics::summary::{LjSummary, NoLoopSummary};
use clap::Args;
use std::path::PathBuf;

/// Solve the adhesive sphere with the Lennard-Jones law (10) numerically (the paper's
/// §3.1): trace the S-shaped curve T̂(α̂) by natural-parameter continuation on a mesh
/// that moves with the contact edge (the approach branch in the central gap through
/// the jump-in fold A; the contact branch in the contact radius, from deep contact
/// back through the pull-off and the jump-out fold C; the unstable branch between
/// them only for --curve), locate the folds, and integrate the hysteresis loss
/// Ŵ_LJ = ∫ (T̂_contact − T̂_approach) dα̂ over [α̂_A, α̂_C]. Range: 0.5 <= mu <= 50.
///
/// The discretisation converges at second order: every value is extrapolated
/// (Richardson) from the production mesh and one with every spacing 1.5 times larger,
/// and carries an error estimate from a third mesh 2.25 times coarser (about 2 to 3
/// times the true error where checked against finer meshes, mu = 1 to 30). The loss
/// with a spring (--k-hat, any k̂ > 0; far out, where a soft spring lands, the approach
/// branch is the rigid sphere's) is the production mesh's, not extrapolated. Results are
/// cached, keyed by mu, the traced range, the mesh and the solver's source (see the guide, docs/src/reference/output.md:
/// $TAPSIM_CACHE, else ~/.cache/tapsim); --no-cache recomputes.
///
/// JSON keys (--json): tabor_mu, hysteresis (false: no loop, and then only w_hat = 0,
/// w_hat_error and note follow), alpha_hat_a, t_hat_a, alpha_hat_c, t_hat_c,
/// pull_off_hat, w_hat, w_hat_error (and an _error for each), nodes, w_hat_hybrid,
/// hybrid_rel_error, alpha_hat_a_fit, fit_rel_error; with --k-hat also k_hat,
/// w_hat_spring, w_hat_spring_hybrid.
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct LjArgs {
    /// Tabor parameter μ, eq. (2) [0.5 to 50; 0.2 s at 3, 0.3 s at 5, 1.3 s at 50;
    /// below the critical μ ≈ 0.70 the curve has no loop: "no hysteresis", Ŵ_LJ = 0].
    #[arg(long, allow_hyphen_values = true, value_parser = number)]
    mu: f64,
    /// Support stiffness k̂ = μεk/(RΔγ), eq. (22), any k̂ > 0: adds the loss with the
    /// support in series (JSON key w_hat_spring) beside the hybrid (26).
    #[arg(long, allow_hyphen_values = true, value_parser = number)]
    k_hat: Option<f64>,
    /// Write the whole traced curve as CSV (s, alpha_hat, t_hat, central_gap): approach
    /// branch, A, unstable branch, C, contact branch, in order (tracing the unstable
    /// branch, which no result needs, takes longer: 1.5 to 3 times at mu >= 5).
    #[arg(long)]
    curve: Option<PathBuf>,
    /// Recompute even if a cached result exists.
    #[arg(long)]
    no_cache: bool,
    /// Print one JSON object on stdout instead of the table.
    #[arg(long)]
    json: bool,
    /// No notes of files written on stderr.
    #[arg(long, short = 'q')]
    pub(super) quiet: bool,
}

/// Print `report` as JSON or as the table `text`.
fn print(report: &impl serde::Serialize, json: bool, text: String) -> Result<()> {
    if json {
        outln!("{}", crate::app::report::records::document(report)?);
    } else {
        out!("{text}");
    }
    Ok(())
}

/// Run the subcommand.
pub fn run(args: LjArgs) -> Result<()> {
    // A spring's loss needs the curve traced further than the rigid loop does, and a
    // curve to draw needs the unstable branch as well.
    let reach = if args.curve.is_some() {
        Reach::Whole
    } else if args.k_hat.is_some() {
        Reach::Springs
    } else {
        Reach::Rigid
    };
    let solution = match crate::app::lj_cache::solve(args.mu, reach, !args.no_cache) {
        Err(crate::Error::NoHysteresis(why)) => {
            // Below the critical μ nothing is lost: a result, not an error.
            let r = NoLoopSummary::new(args.mu, why);
            return print(&r, args.json, r.to_text());
        }
        other => other?,
    };
    if let Some(path) = &args.curve {
        output::write_bytes(path, &report::curve_csv(&solution)?)?;
    }
    let mut r = LjSummary::new(&solution);
    if let Some(k) = args.k_hat {
        r = r.with_spring(&solution, k)?;
    }
    print(&r, args.json, r.to_text())
}
