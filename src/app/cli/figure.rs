//! `tapsim figure`: regenerate the paper's figures as CSV, PNG and SVG.

use crate::app::config::number;
use crate::app::figures::{self, FigureOptions};
use crate::app::report::output;
use crate::error::{Error, Result};
use crate::physics::contact::hybrid::JumpIn;
use clap::Args;
use std::path::PathBuf;

/// Regenerate a figure of the paper (CSV data + PNG + SVG plot).
///
/// FIGURE is 1 (JKR cycle, eqs. 5, 8, 9), 2 (Lennard-Jones curve for μ = 5, numerical),
/// 3 (jump-in separation vs μ, eqs. 14-17, with numerical points), 4 (hysteresis vs μ,
/// eq. 18, with numerical points), 5 (cycle with a compliant support, eqs. 22-26),
/// 6 (hysteresis vs support stiffness, eqs. 26-27), or `all`.
/// Figures 2-4 and 6 need the Lennard-Jones solutions for μ = 1 ... 50: about 15 s
/// the first time, then instant from the cache.
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct FigureArgs {
    /// Figure number (1 to 6) or `all`.
    figure: String,
    /// Output directory (created if missing; its parent must exist). `tapsim reproduce`
    /// writes the committed results/.
    #[arg(long, default_value = "figures")]
    out: PathBuf,
    /// Tabor parameter μ of figure 5.
    #[arg(long, allow_hyphen_values = true, value_parser = number, default_value_t = 5.0)]
    mu: f64,
    /// Support stiffness k̂ of figure 5.
    #[arg(long, allow_hyphen_values = true, value_parser = number, default_value_t = 2.0)]
    k_hat: f64,
    /// Jump-in variant for figures 4-6.
    #[arg(long, value_enum, ignore_case = true, default_value_t = JumpIn::Fit)]
    jump_in: JumpIn,
    /// Print a manifest as JSON on stdout (per figure: number, title, files) instead of
    /// the paths written.
    #[arg(long)]
    json: bool,
    /// No notes of files written on stderr.
    #[arg(long, short = 'q')]
    pub(super) quiet: bool,
}

/// Run the subcommand.
pub fn run(args: FigureArgs) -> Result<()> {
    let numbers: Vec<u32> = if args.figure.eq_ignore_ascii_case("all") {
        figures::AVAILABLE.to_vec()
    } else {
        vec![args.figure.trim().parse().map_err(|_| Error::Parse {
            name: "figure",
            text: args.figure.clone(),
            reason: "expected a figure number (1-6) or `all`".into(),
        })?]
    };
    let opts = FigureOptions {
        fig5_mu: args.mu,
        fig5_k_hat: args.k_hat,
        jump_in: args.jump_in,
    };
    if let Some(n) = numbers.iter().find(|n| !figures::AVAILABLE.contains(n)) {
        return Err(Error::Parse {
            name: "figure",
            text: n.to_string(),
            reason: "expected a figure number (1-6) or `all`".into(),
        });
    }
    output::ensure_dir(&args.out)?;
    let mut manifest = Vec::new();
    for n in numbers {
        let chart = figures::figure(n, &opts)?;
        let mut files = chart.write_all(&args.out)?;
        if n == 3 {
            let path = args.out.join("fig3_lj_vs_fit.csv");
            output::write_bytes(&path, &figures::lj_fit_table(&figures::lj_solutions()?)?)?;
            files.push(path);
        }
        if args.json {
            manifest.push(serde_json::json!({
                "number": n,
                "title": chart.title,
                "files": files,
            }));
        } else {
            for path in files {
                outln!("{}", path.display());
            }
        }
    }
    if args.json {
        outln!(
            "{}",
            crate::app::report::records::document(&serde_json::json!({ "figures": manifest }))?
        );
    }
    Ok(())
}
