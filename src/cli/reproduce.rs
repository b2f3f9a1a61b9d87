//! `tapsim reproduce`: regenerate results/.

use crate::error::Result;
use clap::Args;
use std::path::PathBuf;

/// Regenerate the paper's Figs. 1-6 (CSV + PNG + SVG), tapping figures (a trajectory,
/// approach curves for the jkr, hybrid and lj laws, phase contrast between two polymers)
/// and a generated README.md listing every file with the headline numbers.
///
/// The Lennard-Jones solutions are cached (first run: about a minute).
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct ReproduceArgs {
    /// Output directory.
    #[arg(long, default_value = "results")]
    out: PathBuf,
    /// Do not report progress on stderr.
    #[arg(long)]
    quiet: bool,
}

/// Run the subcommand.
pub fn run(args: ReproduceArgs) -> Result<()> {
    let quiet = args.quiet;
    let files = crate::reproduce::reproduce(&args.out, |what| {
        if !quiet {
            eprintln!("making {what} ...");
        }
    })?;
    for f in files {
        outln!("{}", f.display());
    }
    Ok(())
}
