//! `tapsim reproduce`: regenerate results/.

use crate::error::Result;
use clap::Args;
use std::path::PathBuf;

/// Regenerate the paper's Figs. 1-6 (CSV + PNG + SVG), tapping figures (a trajectory,
/// approach curves for the jkr, hybrid and lj laws, phase contrast between two polymers)
/// and a generated README.md listing every file with the headline numbers.
///
/// The Lennard-Jones solutions are cached (first run: about 20 s).
///
/// Prints the files written, one per line; with --json one object instead: files (file,
/// what), w_hat_jkr, w_hat_hybrid_mu5, pull_off_over_jkr_mu5, default_tap (every
/// `tapsim tap --json` key) and lj_mu5 (every `tapsim lj --mu 5 --json` key; the
/// deprecated w_hat_lj_mu5 {value, error} holds its w_hat and w_hat_error for one more
/// release).
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct ReproduceArgs {
    /// Output directory.
    #[arg(long, default_value = "results")]
    out: PathBuf,
    /// Do not report progress on stderr.
    #[arg(long, short = 'q')]
    pub(super) quiet: bool,
    /// Print the manifest as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// Run the subcommand.
pub fn run(args: ReproduceArgs) -> Result<()> {
    let quiet = args.quiet;
    let manifest = crate::app::reproduce::reproduce(&args.out, |what| {
        if !quiet {
            eprintln!("making {what} ...");
        }
    })?;
    if args.json {
        outln!("{}", crate::app::report::records::document(&manifest)?);
    } else {
        for f in &manifest.files {
            outln!("{}", args.out.join(&f.file).display());
        }
    }
    Ok(())
}
