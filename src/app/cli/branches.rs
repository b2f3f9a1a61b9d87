//! `tapsim branches`: the period-1 orbit family through the rest separation.

use crate::analysis::sweep::{self, BranchPointKind};
use crate::app::config::{TapInputs, length};
use crate::app::report::{branches as report, records};
use crate::error::{Error, Result};
use clap::Args;

/// Follow the period-1 orbit family through the rest separation z_c by pseudo-arclength
/// continuation of the shooting equations P(z; z_c) = z, with the period map's exact
/// derivative: stable and unstable orbits alike, through folds (a Floquet multiplier
/// through +1: where an approach or retract ramp jumps between the attractive and the
/// repulsive regime) and period doublings (through −1: where a period-2 orbit takes
/// over). Every `tapsim tap` option applies. The branch starts on the orbit the free
/// oscillation settles on at --from (or, if that is not a stable period-1 orbit, a
/// --max-step further on at a time until it is).
///
/// Where an orbit just grazes a switch of a hysteretic force law (it starts to touch the
/// sample) the period map jumps: touching dissipates a whole loop. The family is then
/// picked up again a --max-step further on, where the carried motion settles on a stable
/// period-1 orbit; the output lists the pieces and the gaps between them.
///
/// Output: a table of the folds and period doublings on stdout, or --json (one object
/// of equal-length arrays: separation_m, point (regular, fold, period-doubling), stable,
/// floquet_multipliers, segment, amplitude_ratio, phase_deg, e_ts_j, …, plus notes),
/// --csv FILE
/// (one row per orbit), --plot FILE.png|svg (A/A₀, φ, E_ts against z_c: stable solid,
/// unstable dashed, folds and period doublings marked; with --overlay N, an N-point
/// approach–retract ramp drawn over them).
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct BranchesArgs {
    #[command(flatten)]
    inputs: TapInputs,
    #[command(flatten)]
    pub(super) out: super::SweepOutput,
    #[command(flatten)]
    range: super::SeparationRange,
    /// Largest step along the branch [m; default 0.01 A₀].
    #[arg(long, allow_hyphen_values = true, value_parser = length)]
    max_step: Option<f64>,
    /// Also run an approach–retract ramp of this many points over the same range and
    /// draw it on the plot (with --plot only).
    #[arg(long)]
    overlay: Option<usize>,
}

/// Run the subcommand.
pub fn run(args: BranchesArgs) -> Result<()> {
    // The overlay is drawn, never printed: without a plot it would be computed for
    // nothing.
    if args.overlay.is_some() && args.out.plot.is_none() {
        return Err(Error::NotApplicable(
            "--overlay draws an approach–retract ramp on the plot: give --plot too".into(),
        ));
    }
    let start = super::SweepStart::new("branches", args.inputs, &args.range)?;
    let (setup, (from, to)) = (&start.setup, start.range);
    let a0 = setup.cantilever.free_amplitude_m;
    let branch = sweep::orbit_branch(
        setup,
        &start.numerics,
        (from, to),
        args.max_step.unwrap_or(0.01 * a0),
    )?;
    let ramp = match args.overlay {
        Some(points) => {
            let ramp = sweep::ramp(from.max(to), from.min(to), points, true)?;
            let bar = args.out.progress("branches", ramp.len());
            let curve = sweep::approach_curve(setup, &start.sweep_numerics, &ramp, |done, _| {
                bar.set_position(done as u64)
            })?;
            bar.finish_and_clear();
            curve
        }
        None => Vec::new(),
    };
    args.out.write_files(&branch.points, || {
        let title = format!("{} law, period-1 orbits", setup.law);
        report::branch_charts(&branch.points, &ramp, &title)
    })?;
    if args.out.json {
        let mut v = records::columns_json(&branch.points)?;
        if let serde_json::Value::Object(m) = &mut v {
            m.insert("notes".into(), branch.notes.clone().into());
        }
        outln!("{}", crate::app::report::records::document(&v)?);
        return Ok(());
    }
    let stable = branch
        .points
        .iter()
        .filter(|p| p.observables.stable == Some(true))
        .count();
    let grazing = branch
        .points
        .iter()
        .filter(|p| p.observables.grazing)
        .count();
    outln!(
        "period-1 orbits of the {} law: {} points ({} stable{})",
        setup.law,
        branch.points.len(),
        stable,
        if grazing > 0 {
            format!(
                "; {grazing} graze a switch: whether they touch is decided by less than the \
                 thermal motion, their stability not defined"
            )
        } else {
            String::new()
        },
    );
    for note in &branch.notes {
        outln!("  {note}");
    }
    let events: Vec<_> = branch
        .points
        .iter()
        .filter(|p| p.point != BranchPointKind::Regular)
        .collect();
    if events.is_empty() {
        outln!("no fold and no period doubling on the way");
        return Ok(());
    }
    outln!(
        "{:>16} {:>10} {:>9} {:>10} {:>11}",
        "",
        "z_c (nm)",
        "A/A0",
        "phi (deg)",
        "E_ts (eV)"
    );
    for p in events {
        let o = &p.observables;
        outln!(
            "{:>16} {:>10.5} {:>9.5} {:>10.4} {:>11.4}",
            match p.point {
                BranchPointKind::Fold => "fold",
                _ => "period doubling",
            },
            p.separation_m * 1e9,
            o.amplitude_ratio,
            o.phase_deg,
            o.e_ts_ev
        );
    }
    Ok(())
}
