//! `tapsim merge`: the parts of a sharded map, batch or image, checked and joined into the outputs one
//! whole run writes.

use crate::app::report::part::{self, Job, Part};
use crate::error::{Error, Result};
use clap::Args;
use std::path::PathBuf;

/// Join the part files of a sharded `tapsim map`, `tapsim batch` or `tapsim scan --lines
/// N` (tapping or --mode peakforce; --shard I/N, or a Slurm job array) into exactly the
/// outputs the whole run writes: the CSV, the JSON and a map's or an image's heat maps
/// are byte for byte those of one unsharded run.
///
/// A part file is checked like any input before anything is drawn from it: written by
/// this tapsim, its job one `map` or `batch` would run, its configuration hash recomputed
/// from the configuration it carries, exactly its items with the records each should
/// have, and a checksum of those records; a mismatch is refused, naming the file and the
/// field. Every part must come from the same configuration and the same split, and every
/// part 0 … N−1 must be there exactly once. A missing part is named in the form
/// `sbatch --array=` takes, to resubmit it:
///
///   tapsim merge parts/*.json --out map.csv --out map.png
///   error: 2 of 7 parts missing: 3,5 (rerun them with sbatch --array=3,5)
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct MergeArgs {
    /// The part files.
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// Write an output, by its extension: .csv (the CSV), .json (the JSON --json
    /// prints), .png or .svg (a map's or image's heat maps), .gwy or .gsf (an image's
    /// Gwyddion files, as `scan --gwy/--gsf` writes them). May be repeated.
    #[arg(long)]
    out: Vec<PathBuf>,
    #[command(flatten)]
    pub(super) output: super::SweepOutput,
}

/// The largest part file read, in bytes (a 200 × 200 map is some 60 MB whole).
const MAX_PART_BYTES: u64 = 1 << 30;

fn read(path: &std::path::Path) -> Result<Part> {
    let fail = |reason: String| Error::Parse {
        name: "part file",
        text: path.display().to_string(),
        reason,
    };
    let text = crate::app::config::read_input(path, MAX_PART_BYTES, fail)?;
    serde_json::from_slice(&text).map_err(|e| fail(format!("not a tapsim part file: {e}")))
}

/// Run the subcommand.
pub fn run(args: MergeArgs) -> Result<()> {
    for path in &args.out {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or_default()
            .to_ascii_lowercase();
        if !["csv", "json", "png", "svg", "gwy", "gsf"].contains(&ext.as_str()) {
            return Err(Error::NotApplicable(format!(
                "--out {}: give a .csv, .json, .png, .svg, or an image's .gwy or .gsf file",
                path.display()
            )));
        }
    }
    let parts = args
        .parts
        .iter()
        .map(|p| Ok((p.display().to_string(), read(p)?)))
        .collect::<Result<Vec<_>>>()?;
    let merged = part::merge(parts)?;
    let (files, _) = super::image::ImageFiles::among(&args.out)?;
    if files.any()
        && !matches!(
            merged.job,
            Job::Scan { .. } | Job::QnmScan { .. } | Job::FmScan { .. }
        )
    {
        return Err(files.no_image());
    }
    match &merged.job {
        Job::Map {
            law,
            work_of_adhesion_j_m2,
            modulus_pa,
            setpoint,
        } => super::map::emit(
            &args.output,
            &args.out,
            (law, setpoint.as_ref()),
            work_of_adhesion_j_m2,
            modulus_pa,
            &merged.records,
        ),
        Job::Batch { .. } => super::batch::emit(&args.output, &args.out, &merged.records),
        Job::Scan { .. } => {
            super::scan::emit(&args.output, &args.out, &merged.job, &merged.records)
        }
        Job::QnmMap {
            law,
            work_of_adhesion_j_m2,
            modulus_pa,
            peak_force_n,
        } => super::qnm::emit_map(
            &args.output,
            &args.out,
            (law, *peak_force_n),
            (work_of_adhesion_j_m2, modulus_pa),
            &merged.records,
        ),
        Job::FmScan {
            lines,
            pixels,
            frequency_shift_hz,
            image,
            ..
        } => super::fm_scan::emit_scan(
            &args.output,
            &args.out,
            ((*lines, *pixels, *frequency_shift_hz), image.as_ref()),
            &merged.records,
        ),
        Job::QnmScan {
            lines,
            pixels,
            peak_force_n,
            image,
            ..
        } => super::qnm::emit_scan(
            &args.output,
            &args.out,
            ((*lines, *pixels, *peak_force_n), image.as_ref()),
            &merged.records,
        ),
    }
}
