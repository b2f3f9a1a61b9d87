//! `tapsim map`: dissipation and phase over a grid of work of adhesion and modulus.

use crate::config::{TapInputs, pressure, surface_energy};
use crate::dynamics::observables::TapObservables;
use crate::error::Result;
use crate::report::chart::{Axis, Chart, Corner, Series, Style};
use crate::report::{records, sweep as sweep_report};
use crate::sweep;
use clap::Args;

/// E_ts and phase over a grid of work of adhesion Δγ and composite modulus E* (log
/// spaced), at one setpoint: every cell an independent `tapsim tap`, computed in
/// parallel. The result is the same whatever the number of threads. Every `tapsim tap`
/// option applies (--modulus and --work-of-adhesion are replaced by the grid).
///
/// Output: CSV (--csv) and JSON (--json: one object of equal-length arrays) with
/// work_of_adhesion_j_m2, modulus_pa, tabor_mu and the tap observables per cell (empty
/// where the law does not apply, with a note); --plot draws E_ts and φ against Δγ, one
/// line per modulus.
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
    args.out.write_files(&cells, || {
        // Per modulus, lines through the period-1 cells; other cells marked.
        let lines = |y: fn(&TapObservables) -> f64| -> Vec<Series> {
            let located = |e: Option<f64>| -> Vec<sweep_report::Located> {
                cells
                    .iter()
                    .filter(|c| e.is_none_or(|e| c.modulus_pa == e))
                    .filter_map(|c| {
                        let o = c.observables.as_ref()?;
                        Some((o.period, (c.work_of_adhesion_j_m2, y(o))))
                    })
                    .collect()
            };
            let mut series: Vec<Series> = moduli
                .iter()
                .enumerate()
                .flat_map(|(i, &e)| {
                    let name = format!("E* = {:.2} GPa", e * 1e-9);
                    sweep_report::period_one_lines(&located(Some(e)), &name, Style::Line, i + 1)
                })
                .collect();
            series.extend(sweep_report::not_period_one(&located(None)));
            series
        };
        vec![
            Chart {
                name: "map_e_ts".into(),
                title: format!("{} law: dissipation per cycle", setup.law),
                x: Axis::log("work of adhesion Δγ (J/m²)", "work_of_adhesion"),
                y: Axis::linear("E_ts per cycle (eV)", "e_ts_ev"),
                series: lines(|o| o.e_ts_ev),
                labels: vec![],
                legend: Corner::UpperLeft,
            },
            Chart {
                name: "map_phase".into(),
                title: format!("{} law: phase", setup.law),
                x: Axis::log("work of adhesion Δγ (J/m²)", "work_of_adhesion"),
                y: Axis::linear("phase lag φ (deg)", "phase_deg"),
                series: lines(|o| o.phase_deg),
                labels: vec![],
                legend: Corner::UpperLeft,
            },
        ]
    })?;
    if args.out.json {
        args.out.print_json(&cells)?;
    } else if args.out.csv.is_none() && args.out.plot.is_none() {
        out!(
            "{}",
            String::from_utf8_lossy(&records::records_csv(&cells)?)
        );
    }
    Ok(())
}
