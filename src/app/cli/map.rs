//! `tapsim map`: dissipation and phase over a grid of work of adhesion and modulus.

use crate::analysis::sweep;
use crate::analysis::sweep::Shard;
use crate::app::config::{BranchChoice, TapInputs, number, pressure, surface_energy};
use crate::app::report::part::{self, Job, MapSetpoint};
use crate::app::report::{map as report, plot};
use crate::error::{Error, Result};
use crate::instrument::average::AverageRequest;
use clap::Args;

/// E_ts and phase over a grid of work of adhesion Δγ and composite modulus E* (log
/// spaced): every cell an independent `tapsim tap`, computed in parallel. With
/// --setpoint A/A₀ (as an AFM images: the phase image at constant amplitude setpoint)
/// every cell is solved where its amplitude is the setpoint on --branch (repulsive by
/// default), and the third heat map is the apparent height Δz_c (the cell's rest
/// separation less the first cell's: the topography a flat sample of these materials
/// shows); without it, every cell sits at one rest separation. The result is the same whatever the number of threads. Every `tapsim tap`
/// option applies (--modulus and --work-of-adhesion are replaced by the grid).
///
/// With --modes 2 (or 3): every cell the several-mode state (`tapsim tap --modes`) at
/// the rest separation, or with --setpoint at the first mode's A₁/A₀₁ on --branch
/// (repulsive by default); one row per cell (work_of_adhesion_j_m2, modulus_pa, tabor_mu,
/// separation_m, amplitude1_ratio, phase1_deg, amplitude2_ratio, phase2_deg, e_ts_j,
/// stable, note), JSON as columns, heat maps of φ₂, φ₁, A₂/A₀₂ and E_ts. Not sharded.
///
/// With --mode peakforce: every cell off-resonance tapping at the peak-force setpoint
/// (--peak-force, 5 nN; the rest separation solved for, as `tapsim peakforce` does), one
/// row per cell (work_of_adhesion_j_m2, modulus_pa, tabor_mu, separation_m, regime,
/// peak_force_n, adhesion_n, dissipation_j, deformation_m, dmt_modulus_pa, note), heat
/// maps of adhesion, dissipation, DMT modulus and deformation: the QNM images a blend of
/// these materials would give. Sharded and merged as the tapping map is.
///
/// Output: CSV (--csv, one row per cell; without --csv, --json or --plot it goes to
/// stdout) with work_of_adhesion_j_m2, modulus_pa, tabor_mu and the tap observables
/// per cell (empty where the law does not apply, with a note). JSON (--json): law, the
/// two axes work_of_adhesion_j_m2 and modulus_pa, and grid: per column of the CSV an
/// array of rows, one per modulus, each with one value per work of adhesion (null
/// where the law does not apply); --plot draws heat maps of E_ts, φ and A/A₀ (and, for
/// a viscous sample, of E_ts's viscous share) over the grid (log axes, a viridis colour
/// bar each; grey where the law does not apply, cells that are not period-1 marked with
/// a circle).
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct MapArgs {
    #[command(flatten)]
    inputs: TapInputs,
    #[command(flatten)]
    pub(super) out: super::SweepOutput,
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
    /// Solve every cell at this amplitude setpoint A/A₀ (between 0 and 1) on --branch,
    /// as an AFM images, instead of at one rest separation: the phase image at constant
    /// setpoint, with the apparent height (z_c less the first cell's) in place of A/A₀.
    /// Cells the branch does not reach stay empty, with a note. Not with --separation.
    #[arg(long, value_name = "A/A0", allow_hyphen_values = true, value_parser = number,
          conflicts_with = "amplitude_setpoint")]
    setpoint: Option<f64>,
    /// The amplitude setpoint as an amplitude (e.g. 16nm): --setpoint A_sp/A₀.
    #[arg(hide_short_help = true, long, allow_hyphen_values = true, value_parser = crate::app::config::length)]
    amplitude_setpoint: Option<f64>,
    /// The branch every cell is solved on at a setpoint [default: repulsive].
    #[arg(long, value_enum, ignore_case = true)]
    branch: Option<BranchChoice>,
    /// With a setpoint, --temperature adds each cell's thermal phase noise σ_φ through
    /// the lock-in (the linear theory about its orbit; column sigma_phase_deg) and heat
    /// maps of σ_φ and of each cell's phase contrast with the first cell over the noise
    /// of the two readings, |φ − φ₀|/√(σ² + σ₀²). At one z_c it averages each cell that
    /// grazes a switch or is not a stable period-1 orbit over the thermal motion, as an
    /// instrument reads it (thermal_average fields), and adds heat maps of E_ts and φ as
    /// read: the average where there is one, the steady state elsewhere.
    #[command(flatten)]
    pub(super) noise: super::NoiseArgs,
    /// Drive periods of each thermal average (--temperature at one z_c): eight
    /// independent records of an eighth each, whose spread gives the standard errors.
    /// Each cell draws noise of its own (a seed derived from its parameters, as `tap
    /// --temperature` at them draws: JSON thermal_average.seed), so the errors of
    /// neighbouring cells are independent.
    #[arg(hide_short_help = true, long, default_value_t = super::DEFAULT_THERMAL_PERIODS, help_heading = "Thermal noise")]
    thermal_periods: usize,
    #[command(flatten)]
    split: super::shard::ShardArgs,
    #[command(flatten)]
    modes: crate::app::config::ModeInputs,
    #[command(flatten)]
    qnm: super::qnm::QnmArgs,
}

/// Run the subcommand.
pub fn run(args: MapArgs) -> Result<()> {
    let mut inputs =
        args.inputs
            .clone()
            .holding(args.setpoint, args.amplitude_setpoint, args.branch)?;
    if inputs.holds_setpoint() && inputs.separation.is_some() {
        return Err(super::separation_and_setpoint());
    }
    inputs.takes_modes = true;
    let (setup, numerics) = inputs.resolve()?;
    let works = sweep::log_grid(
        "work of adhesion",
        args.adhesion_from,
        args.adhesion_to,
        args.steps,
    )?;
    let moduli = sweep::log_grid("modulus", args.modulus_from, args.modulus_to, args.steps)?;
    if args.qnm.mode == super::qnm::Mode::Fm {
        return Err(Error::NotApplicable(
            "map --mode fm: FM is imaged with `tapsim scan --mode fm`; `tapsim fm` gives \
             the settled FM state of one material"
                .into(),
        ));
    }
    if let Some(q) = args.qnm.resolve()? {
        super::qnm::refuse_in_mode(
            "peakforce",
            &[
                ("--setpoint", args.setpoint.is_some()),
                ("--amplitude-setpoint", args.amplitude_setpoint.is_some()),
                ("--branch", args.branch.is_some()),
                ("--temperature", args.noise.temperature.is_some()),
                ("--modes", args.modes.modes.is_some()),
            ],
        )?;
        return super::qnm::map(
            &q,
            (&setup, &numerics),
            (&works, &moduli),
            args.threads,
            (&args.out, &args.split),
        );
    }
    if let Some(set) = args.modes.mode_set(&inputs.mode_file, &setup.cantilever)? {
        use super::modal::refuse;
        refuse(args.noise.temperature.is_some(), "--temperature")?;
        refuse(
            args.split.resolve("map", false)?.is_some(),
            "--shard (and a Slurm array)",
        )?;
        let setpoint = match inputs.setpoint_ratio(setup.cantilever.free_amplitude_m) {
            None => None,
            Some(ratio) => {
                crate::analysis::setpoint::check_ratio(ratio)?;
                Some((ratio, one_branch(inputs.branch)?))
            }
        };
        let numerics = if setpoint.is_some() {
            inputs.sweep_numerics(numerics)
        } else {
            numerics
        };
        return super::modal::map(
            (&setup, &numerics, &set),
            (&works, &moduli),
            args.threads,
            setpoint,
            &args.out,
        );
    }
    let setpoint = match inputs.setpoint_ratio(setup.cantilever.free_amplitude_m) {
        None => None,
        Some(amplitude_ratio) => {
            crate::analysis::setpoint::check_ratio(amplitude_ratio)?;
            Some(MapSetpoint {
                amplitude_ratio,
                branch: one_branch(inputs.branch)?,
            })
        }
    };
    let law = setup.law.to_string();
    let total = works.len() * moduli.len();
    let whole_outputs = args.out.csv.is_some() || args.out.plot.is_some() || args.out.json;
    let shard = args.split.resolve("map", whole_outputs)?;
    let cells = shard.unwrap_or(Shard::WHOLE).items(total);
    let noise = args.noise.request().filter(|_| setpoint.is_some());
    if let Some(request) = &noise {
        request.check(setup.cantilever.drive_frequency_hz)?;
    }
    let thermal = match (setpoint, args.noise.temperature) {
        (None, Some(temperature_k)) => {
            if args.noise.enbw.is_some() || args.noise.lockin_order.is_some() {
                return Err(Error::NotApplicable(
                    "--enbw and --lockin-order set the lock-in that reads σ_φ at an amplitude \
                     setpoint (--setpoint); a map at one z_c averages its grazing cells over \
                     the thermal motion and reads no lock-in noise"
                        .into(),
                ));
            }
            // (Checked by the map before any cell is solved.)
            Some(AverageRequest {
                temperature_k,
                periods: args.thermal_periods,
                seed: 1,
            })
        }
        _ => None,
    };
    let bar = args.out.progress("map", cells.len());
    let computed = match setpoint {
        None => sweep::map_cells(
            &setup,
            &numerics,
            (&works, &moduli),
            &cells,
            args.threads,
            || bar.inc(1),
            thermal.as_ref(),
        )?,
        Some(sp) => crate::analysis::setpoint::map_cells(
            &setup,
            &numerics,
            (&works, &moduli),
            &cells,
            args.threads,
            || bar.inc(1),
            (sp.amplitude_ratio, sp.branch),
            noise.as_ref(),
        )?,
    };
    bar.finish_and_clear();
    match shard {
        Some(shard) => args.split.write(
            ("map", shard, args.out.quiet),
            Job::Map {
                law,
                work_of_adhesion_j_m2: works.clone(),
                modulus_pa: moduli.clone(),
                setpoint,
            },
            &part::Config::Whole(
                serde_json::to_value((&setup, &numerics, &works, &moduli, &noise, &thermal))
                    .expect("a configuration serialises"),
            ),
            cells,
            computed
                .iter()
                .map(|c| part::raw_records(std::slice::from_ref(c)))
                .collect::<Result<_>>()?,
        ),
        None => emit(
            &args.out,
            &[],
            (&law, setpoint.as_ref()),
            &works,
            &moduli,
            &computed,
        ),
    }
}

/// Write a whole map's outputs ([`super::SweepOutput::emit`]): the CSV, the heat maps,
/// the grid as JSON. `tapsim merge` writes through this too.
pub(super) fn emit<T: report::MapRecord>(
    out: &super::SweepOutput,
    extra: &[std::path::PathBuf],
    (law, setpoint): (&str, Option<&MapSetpoint>),
    works: &[f64],
    moduli: &[f64],
    records: &[T],
) -> Result<()> {
    let caption = setpoint.map(MapSetpoint::caption);
    out.emit(
        ("map", extra),
        records,
        || report::map_json(law, setpoint, works, moduli, records),
        Some(&|path| {
            let maps = report::heat_maps(law, caption.as_deref(), works, moduli, records);
            plot::render_heatmaps(&maps, path)
        }),
    )?;
    let grazing = report::grazing_cells(records);
    if grazing > 0 && !out.quiet {
        eprintln!(
            "note: {grazing} of {} cells graze a switch (column grazing, a dot on the heat \
             maps): there the touch pattern is set by perturbations below the thermal \
             motion and other attractors may coexist (`tapsim tap` at such a cell lists them)",
            records.len()
        );
    }
    Ok(())
}

/// The one branch a map at a setpoint is solved on (repulsive unless told).
fn one_branch(choice: Option<BranchChoice>) -> Result<crate::analysis::setpoint::PhaseBranch> {
    choice
        .unwrap_or(BranchChoice::Repulsive)
        .only()
        .ok_or_else(|| {
            Error::NotApplicable(
                "a map is solved on one branch: --branch attractive or repulsive".into(),
            )
        })
}
