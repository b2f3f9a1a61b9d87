//! `tapsim bifurcation`: Poincaré samples of the settled motion along an approach.

use crate::analysis::sweep;
use crate::app::config::TapInputs;
use crate::app::report::bifurcation as report;
use crate::error::Result;
use clap::Args;

/// A bifurcation diagram: along an approach ramp (the oscillator carried from point to
/// point), settle the motion at each rest separation z_c and record a number of drive
/// periods of it — the deflection at drive phase 0 and the smallest tip–sample
/// separation of each period. A period-n orbit shows n distinct values, irregular motion
/// a cloud, so the period doublings, mode locking and irregular windows near the onset
/// of contact are seen in one picture. Every `tapsim tap` option applies.
///
/// Output: a summary on stdout (the kind of motion at each z_c), or --json (one object
/// of equal-length arrays: separation_m, regime, deflection_m, min_separation_m, one
/// entry per sample), --csv FILE (one row per sample), --plot FILE.png|svg.
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct BifurcationArgs {
    #[command(flatten)]
    inputs: TapInputs,
    #[command(flatten)]
    pub(super) out: super::SweepOutput,
    #[command(flatten)]
    range: super::SeparationRange,
    /// Rest separations on the ramp.
    #[arg(long, allow_hyphen_values = true, default_value_t = 120)]
    points: usize,
    /// Periods sampled at each rest separation.
    #[arg(long, allow_hyphen_values = true, default_value_t = 32)]
    samples: usize,
}

/// Run the subcommand.
pub fn run(args: BifurcationArgs) -> Result<()> {
    let start = super::SweepStart::new("bifurcation", args.inputs, &args.range)?;
    let (setup, numerics, (from, to)) = (&start.setup, &start.sweep_numerics, start.range);
    let ramp = sweep::ramp(from, to, args.points, false)?;
    let separations: Vec<f64> = ramp.iter().map(|r| r.0).collect();
    let bar = args.out.progress("bifurcation", separations.len());
    let samples = sweep::bifurcation(setup, numerics, &separations, args.samples, |done, _| {
        bar.set_position(done as u64)
    })?;
    bar.finish_and_clear();
    args.out.write_files(&samples, || {
        report::bifurcation_charts(&samples, &format!("{} law", setup.law))
    })?;
    if args.out.json {
        args.out.print_json(&samples)?;
        return Ok(());
    }
    outln!("{:>10} {:>12}", "z_c (nm)", "motion");
    for chunk in samples.chunks(args.samples) {
        outln!(
            "{:>10.4} {:>12}",
            chunk[0].separation_m * 1e9,
            chunk[0].regime
        );
    }
    Ok(())
}
