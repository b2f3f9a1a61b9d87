//! `tapsim map`: dissipation and phase over a grid of work of adhesion and modulus.

use crate::config::{TapInputs, pressure, surface_energy};
use crate::error::{Error, Result};
use crate::report::part::{Job, Part};
use crate::report::{map as report, output, plot, records};
use crate::sweep;
use crate::sweep::Shard;
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
    /// Compute only part I (from 0) of N: the cells whose number (row by row over the
    /// grid, as the CSV lists them) is I mod N, written to a part file (--part) for
    /// `tapsim merge`. Inside a Slurm array task, I and N default to the task's
    /// SLURM_ARRAY_TASK_ID − SLURM_ARRAY_TASK_MIN and SLURM_ARRAY_TASK_COUNT.
    #[arg(long, value_name = "I/N")]
    shard: Option<String>,
    /// The part file of a sharded run [default: map-part-I-of-N.json]; written whole or
    /// not at all, with a header (tapsim version, configuration hash, N, I, the cells).
    #[arg(long)]
    part: Option<std::path::PathBuf>,
}

/// Which part of the map this run computes: `--shard I/N`, else inside a Slurm array
/// task SLURM_ARRAY_TASK_ID − SLURM_ARRAY_TASK_MIN of SLURM_ARRAY_TASK_COUNT, else the
/// whole map (`None`).
pub(super) fn shard(flag: Option<&str>) -> Result<Option<Shard>> {
    let number = |what: &str, text: &str| {
        text.trim().parse::<usize>().map_err(|_| Error::Parse {
            name: "shard",
            text: text.to_string(),
            reason: format!("{what} must be a whole number"),
        })
    };
    if let Some(text) = flag {
        let (i, n) = text.split_once('/').ok_or_else(|| Error::Parse {
            name: "shard",
            text: text.to_string(),
            reason: "expected I/N, part I (from 0) of N".into(),
        })?;
        return Ok(Some(Shard::new(number("I", i)?, number("N", n)?)?));
    }
    let var = |name: &str| std::env::var(name).ok();
    match (var("SLURM_ARRAY_TASK_ID"), var("SLURM_ARRAY_TASK_COUNT")) {
        (Some(id), Some(count)) => {
            let min = var("SLURM_ARRAY_TASK_MIN").unwrap_or_else(|| "0".into());
            let (id, min, count) = (
                number("SLURM_ARRAY_TASK_ID", &id)?,
                number("SLURM_ARRAY_TASK_MIN", &min)?,
                number("SLURM_ARRAY_TASK_COUNT", &count)?,
            );
            let index = id.checked_sub(min).ok_or_else(|| {
                Error::NotApplicable(format!(
                    "Slurm array task {id} is below the array's first, {min}"
                ))
            })?;
            Shard::new(index, count)
                .map_err(|_| {
                    Error::NotApplicable(format!(
                        "Slurm array task {id} of {count} starting at {min}: the array's \
                         task numbers must be consecutive (--array=0-{} or a range like it)",
                        count.saturating_sub(1)
                    ))
                })
                .map(Some)
        }
        _ => Ok(None),
    }
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
    let law = setup.law.to_string();
    let total = works.len() * moduli.len();
    let shard = shard(args.shard.as_deref())?;
    if shard.is_some() && (args.out.csv.is_some() || args.out.plot.is_some() || args.out.json) {
        return Err(Error::NotApplicable(
            "a sharded map writes only its part file (--part): merge the parts with `tapsim \
             merge` for the CSV, JSON and plot"
                .into(),
        ));
    }
    if shard.is_none() && args.part.is_some() {
        return Err(Error::NotApplicable(
            "--part writes one part of a sharded map: give --shard I/N (or run in a Slurm \
             array)"
                .into(),
        ));
    }
    let cells = shard.unwrap_or(Shard::WHOLE).items(total);
    let bar = args.out.progress_bar(cells.len());
    let computed = sweep::map_cells(
        &setup,
        &numerics,
        (&works, &moduli),
        &cells,
        args.threads,
        || bar.inc(1),
    )?;
    bar.finish_and_clear();
    let records = report::cell_records(&computed)?;
    match shard {
        Some(shard) => {
            let path = args.part.clone().unwrap_or_else(|| {
                format!("map-part-{}-of-{}.json", shard.index, shard.count).into()
            });
            let config = (&setup, &numerics, &works, &moduli);
            let job = Job::Map {
                law,
                work_of_adhesion_j_m2: works.clone(),
                modulus_pa: moduli.clone(),
            };
            let part = Part::new(
                shard,
                job,
                &config,
                cells,
                records.into_iter().map(|r| vec![r]).collect(),
            );
            let text = serde_json::to_string(&part).expect("a part serialises");
            output::write_bytes(&path, text.as_bytes())?;
            if !args.out.quiet {
                eprintln!(
                    "part {} of {}: {} of {total} cells written to {}",
                    shard.index,
                    shard.count,
                    part.items.len(),
                    path.display()
                );
            }
            Ok(())
        }
        None => emit(&args.out, &[], &law, &works, &moduli, &records),
    }
}

/// Write a whole map's outputs: CSV (--csv, or `csv_files`), the heat maps (--plot), the
/// grid as JSON (--json on stdout, or `json_files`); without any of them the CSV on
/// stdout. `tapsim merge` writes through this too, so its outputs are a whole run's.
pub(super) fn emit(
    out: &super::SweepOutput,
    extra: &[std::path::PathBuf],
    law: &str,
    works: &[f64],
    moduli: &[f64],
    records: &[serde_json::Map<String, serde_json::Value>],
) -> Result<()> {
    fn by_extension<'a>(
        extra: &'a [std::path::PathBuf],
        ext: &'static str,
    ) -> impl Iterator<Item = &'a std::path::PathBuf> {
        extra
            .iter()
            .filter(move |p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case(ext)))
    }
    let csv: Vec<_> = out.csv.iter().chain(by_extension(extra, "csv")).collect();
    let plots: Vec<_> = out
        .plot
        .iter()
        .chain(by_extension(extra, "png"))
        .chain(by_extension(extra, "svg"))
        .collect();
    let json_files: Vec<_> = by_extension(extra, "json").collect();
    for path in &csv {
        output::write_bytes(path, &records::records_csv(records)?)?;
    }
    for path in &plots {
        plot::render_heatmaps(&report::heat_maps(law, works, moduli, records), path)?;
    }
    let json = || -> Result<String> {
        Ok(
            serde_json::to_string_pretty(&report::map_json(law, works, moduli, records)?)
                .expect("serialises"),
        )
    };
    for path in &json_files {
        output::write_bytes(path, format!("{}\n", json()?).as_bytes())?;
    }
    if out.json {
        outln!("{}", json()?);
    } else if csv.is_empty() && plots.is_empty() && json_files.is_empty() {
        out!(
            "{}",
            String::from_utf8_lossy(&records::records_csv(records)?)
        );
    }
    Ok(())
}
