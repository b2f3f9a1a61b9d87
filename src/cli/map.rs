//! `tapsim map`: dissipation and phase over a grid of work of adhesion and modulus.

use crate::config::{TapInputs, pressure, surface_energy};
use crate::error::Result;
use crate::report::{map as report, output, plot, records};
use crate::sweep;
use clap::Args;

/// E_ts and phase over a grid of work of adhesion Δγ and composite modulus E* (log
/// spaced), at one setpoint: every cell an independent `tapsim tap`, computed in
/// parallel. The result is the same whatever the number of threads. Every `tapsim tap`
/// option applies (--modulus and --work-of-adhesion are replaced by the grid).
///
/// Output: CSV (--csv, one row per cell; without --csv, --json or --plot it goes to
/// stdout) with work_of_adhesion_j_m2, modulus_pa, tabor_mu and the tap observables
/// per cell (empty where the law does not apply, with a note). JSON (--json): law, the
/// two axes work_of_adhesion_j_m2 and modulus_pa, and grid: per column of the CSV an
/// array of rows, one per modulus, each with one value per work of adhesion (null
/// where the law does not apply); --plot draws heat maps of E_ts, φ and A/A₀ over the
/// grid (log axes, a viridis colour bar each; grey where the law does not apply, cells
/// that are not period-1 marked with a circle).
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct MapArgs {
    #[command(flatten)]
    inputs: TapInputs,
    #[command(flatten)]
    out: super::SweepOutput,
    /// Smallest work of adhesion [J/m²].
    #[arg(long, allow_hyphen_values = true, value_parser = surface_energy, default_value = "0.02")]
    adhesion_from: f64,
    /// Largest work of adhesion [J/m²].
    #[arg(long, allow_hyphen_values = true, value_parser = surface_energy, default_value = "0.2")]
    adhesion_to: f64,
    /// Smallest composite modulus [Pa].
    #[arg(long, allow_hyphen_values = true, value_parser = pressure, default_value = "0.3GPa")]
    modulus_from: f64,
    /// Largest composite modulus [Pa].
    #[arg(long, allow_hyphen_values = true, value_parser = pressure, default_value = "3GPa")]
    modulus_to: f64,
    /// Grid points along each axis.
    #[arg(long, allow_hyphen_values = true, default_value_t = 8)]
    steps: usize,
    /// Worker threads (0: all cores).
    #[arg(long, allow_hyphen_values = true, default_value_t = 0)]
    threads: usize,
}

/// Run the subcommand.
pub fn run(args: MapArgs) -> Result<()> {
    let (setup, numerics) = args.inputs.with_config()?.resolve()?;
    let works = sweep::log_grid(
        "work of adhesion",
        args.adhesion_from,
        args.adhesion_to,
        args.steps,
    )?;
    let moduli = sweep::log_grid("modulus", args.modulus_from, args.modulus_to, args.steps)?;
    let bar = args.out.progress_bar(works.len() * moduli.len());
    let cells =
        sweep::adhesion_modulus_map(&setup, &numerics, &works, &moduli, args.threads, || {
            bar.inc(1)
        })?;
    bar.finish_and_clear();
    if let Some(path) = &args.out.csv {
        output::write_bytes(path, &records::records_csv(&cells)?)?;
    }
    if let Some(path) = &args.out.plot {
        let law = setup.law.to_string();
        plot::render_heatmaps(&report::heat_maps(&law, &works, &moduli, &cells), path)?;
    }
    if args.out.json {
        let json = report::map_json(&setup.law.to_string(), &works, &moduli, &cells)?;
        outln!(
            "{}",
            serde_json::to_string_pretty(&json).expect("serialises")
        );
    } else if args.out.csv.is_none() && args.out.plot.is_none() {
        out!(
            "{}",
            String::from_utf8_lossy(&records::records_csv(&cells)?)
        );
    }
    Ok(())
}
