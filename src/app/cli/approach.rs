//! `tapsim approach`: an approach–retract curve.

use crate::analysis::identification::{self, Normalized};
use crate::analysis::setpoint;
use crate::analysis::sweep::{self, Direction, SweepPoint};
use crate::app::config::TapInputs;
use crate::app::report::sweep as report;
use crate::error::{Error, Result};
use crate::instrument::average::AverageRequest;
use clap::Args;

/// Sweep the rest separation z_c down (approach) and back up (retract), carrying the
/// oscillator from point to point as a slow piezo ramp does, so the attractive/repulsive
/// bistability and its hysteresis appear; or, with --sweep setpoint, lower and raise the
/// amplitude setpoint A/A₀ as a z feedback holds it (`tapsim approach --sweep setpoint
/// --from 0.95 --to 0.4`): each point the state at its setpoint and the z_c that gives
/// it. Every `tapsim tap` option applies.
///
/// With --temperature 300K, each point the deterministic answer does not pin down —
/// one that grazes a switch (a touch pattern decided by perturbations below the thermal
/// motion) or is not a stable period-1 orbit — is also averaged over the thermal motion
/// there, as an instrument reads it (`tapsim tap --temperature` at that z_c, started
/// from the sweep's state): E_ts, φ, A/A₀ and the touch fraction with standard errors.
///
/// With --modes 2 (or 3), each point is the several-mode orbit (`tapsim tap --modes`),
/// continued from the last: columns amplitude1_ratio, phase1_deg, amplitude2_ratio,
/// phase2_deg, e_ts_j, e_tip1_j, e_tip2_j, contact_fraction, stable, note; --plot draws
/// φ₁ and φ₂ against A₁/A₀₁ (Lozano & García's plot), the amplitudes and E_ts against
/// z_c, with gaps where the modes have no orbit of their common period.
///
/// Per point: the steady-state observables of `tapsim tap`. Output: a table on stdout,
/// or --json (one object of equal-length arrays: separation_m, direction, amplitude_m,
/// amplitude_ratio, phase_deg, e_ts_j, virial_j, mean_force_n, peak_force_n, converged,
/// regime, period, periods_averaged, stable, floquet_multipliers, *_std_err_*, ...),
/// --csv FILE, and --plot FILE.png|svg (A/A₀, φ, E_ts, virial, peak force vs z_c, and
/// φ, E_ts, virial, peak force vs A/A₀; approach and retract distinct; lines join
/// period-1 points only, period-n and irregular points are marked).
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct ApproachArgs {
    #[command(flatten)]
    inputs: TapInputs,
    #[command(flatten)]
    pub(super) out: super::SweepOutput,
    #[command(flatten)]
    range: super::SeparationRange,
    /// Points on the approach (the retract has as many).
    #[arg(long, allow_hyphen_values = true, default_value_t = DEFAULT_POINTS)]
    points: usize,
    /// Approach only.
    #[arg(long)]
    no_retract: bool,
    /// Identification curves (García et al., PRL 97, 016103, 2006): add each
    /// mechanism's dissipation over its largest in the sweep (columns e_ts_norm,
    /// e_ts_adhesion_norm, e_ts_viscous_norm, e_ts_capillary_norm; null for a mechanism
    /// that dissipates
    /// nothing) and plot them against A/A₀ on the approach, first. Adhesion hysteresis
    /// steps up to a plateau once the loop is traversed; a viscous sample peaks inside.
    #[arg(long)]
    normalize: bool,
    /// What the ramp sweeps. separation: the rest separation z_c (--from, --to in m;
    /// default 1.2 A₀ down to 0.4 A₀). setpoint: the amplitude setpoint A/A₀ a z
    /// feedback holds (--from, --to as A/A₀, bare numbers; default 0.95 down to 0.4),
    /// each point the state at its setpoint (to 1e-9) and the z_c that gives it; a
    /// setpoint the amplitude jumps across, or where the motion is not period-1, is not
    /// held and is listed with why.
    #[arg(long, value_enum, ignore_case = true, default_value_t = Sweep::Separation)]
    sweep: Sweep,
    /// Temperature [K; off unless given, 300K is room temperature]: average each point
    /// that grazes a switch or is not a stable period-1 orbit over the thermal motion
    /// (the Langevin force of the cantilever's damping), as an instrument reads it;
    /// reported beside the deterministic state (table, JSON and CSV thermal_average
    /// fields, triangles on the plot).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::app::config::temperature, help_heading = "Thermal noise")]
    temperature: Option<f64>,
    /// Drive periods of each thermal average: eight independent records of an eighth
    /// each (after ten decay times of settling), whose spread gives the standard errors.
    /// Each point draws noise of its own (a seed derived from its place along the
    /// curve, JSON thermal_average.seed): the errors of neighbouring points are
    /// independent.
    #[arg(hide_short_help = true, long, default_value_t = super::DEFAULT_THERMAL_PERIODS, help_heading = "Thermal noise")]
    thermal_periods: usize,
    #[command(flatten)]
    modes: crate::app::config::ModeInputs,
}

/// `--sweep`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Sweep {
    /// The rest separation z_c.
    Separation,
    /// The amplitude setpoint A/A₀.
    Setpoint,
}

/// A setpoint with its identification values (`--normalize`).
#[derive(serde::Serialize)]
struct Identified<'a> {
    #[serde(flatten)]
    point: &'a SweepPoint,
    #[serde(flatten)]
    normalized: Normalized,
}

/// Setpoints of an approach unless told otherwise (`batch` rows too).
pub(super) const DEFAULT_POINTS: usize = 60;

/// Run the subcommand.
pub fn run(mut args: ApproachArgs) -> Result<()> {
    args.inputs.takes_modes = true;
    let start = super::SweepStart::new("approach", args.inputs, &args.range)?;
    let (setup, numerics, (from, to)) = (&start.setup, &start.sweep_numerics, start.range);
    if let Some(set) = args.modes.mode_set(&start.mode_file, &setup.cantilever)? {
        use super::modal::refuse;
        refuse(args.sweep == Sweep::Setpoint, "--sweep setpoint")?;
        refuse(args.normalize, "--normalize")?;
        refuse(args.temperature.is_some(), "--temperature")?;
        let ramp = sweep::ramp(from, to, args.points, !args.no_retract)?;
        return super::modal::approach(&start, &set, &ramp, &args.out);
    }
    let thermal = args.temperature.map(|temperature_k| AverageRequest {
        temperature_k,
        periods: args.thermal_periods,
        seed: 1,
    });
    let (points, not_held) = match args.sweep {
        Sweep::Separation => {
            let ramp = sweep::ramp(from, to, args.points, !args.no_retract)?;
            let bar = args.out.progress("approach", ramp.len());
            let points =
                sweep::approach_curve_at(setup, numerics, &ramp, thermal.as_ref(), |done, _| {
                    bar.set_position(done as u64)
                })?;
            bar.finish_and_clear();
            (points, Vec::new())
        }
        Sweep::Setpoint => {
            if thermal.is_some() {
                return Err(Error::NotApplicable(
                    "--temperature averages the states of a separation sweep that graze a \
                     switch or are not period-1; a setpoint sweep holds only stable \
                     period-1 states (`tapsim tap --setpoint S --temperature T` gives their \
                     thermal noise)"
                        .into(),
                ));
            }
            let from = args.range.from.unwrap_or(0.95);
            let to = args.range.to.unwrap_or(0.4);
            for (flag, r) in [("--from", from), ("--to", to)] {
                if !(0.01..1.0).contains(&r) {
                    return Err(Error::OutOfRange(format!(
                        "with --sweep setpoint, {flag} is an amplitude setpoint A/A₀ from \
                         0.01 to below 1 (a bare number), not {r}"
                    )));
                }
            }
            if to >= from {
                return Err(Error::OutOfRange(format!(
                    "an approach lowers the setpoint: --from ({from}) must exceed --to ({to})"
                )));
            }
            let ramp = sweep::ramp(from, to, args.points, !args.no_retract)?;
            let bar = args.out.progress("approach", ramp.len());
            let swept = setpoint::sweep_setpoints(setup, numerics, &ramp, |done, _| {
                bar.set_position(done as u64)
            })?;
            bar.finish_and_clear();
            (swept.points, swept.not_held)
        }
    };
    for (r, direction, why) in &not_held {
        let dir = direction_name(*direction);
        eprintln!("note: setpoint A/A₀ = {r:.4} ({dir}) not held: {why}");
    }
    let title = format!("{} law", setup.law);
    if args.out.plot.is_some()
        && !args.out.quiet
        && points.iter().all(|p| p.observables.peak_force_n == 0.0)
    {
        eprintln!(
            "note: the plot has no peak-force panels: the tip never presses into the sample \
             anywhere on this sweep (no repulsive force at any point)"
        );
    }
    let normalized = args.normalize.then(|| identification::normalize(&points));
    if let Some(normalized) = &normalized {
        let rows: Vec<Identified> = points
            .iter()
            .zip(normalized)
            .map(|(point, &normalized)| Identified { point, normalized })
            .collect();
        args.out.write_files(&rows, || {
            let mut charts = vec![report::identification_chart(
                "identification",
                &format!("{title}: identification curves (approach)"),
                &[("", &points, normalized)],
            )];
            charts.extend(report::approach_charts(&points, &title));
            charts
        })?;
        if args.out.json {
            return args.out.print_json(&rows);
        }
    } else {
        args.out
            .write_files(&points, || report::approach_charts(&points, &title))?;
        if args.out.json {
            return args.out.print_json(&points);
        }
    }
    outln!(
        "{:>9} {:>9} {:>10} {:>9} {:>10} {:>11} {:>10} {:>5} {:>6}{}",
        "z_c (nm)",
        "dir",
        "motion",
        "A/A0",
        "phi (deg)",
        "E_ts (eV)",
        "F_pk (nN)",
        "conv",
        "grazes",
        if normalized.is_some() {
            "  E_ts/E_max"
        } else {
            ""
        }
    );
    for (i, p) in points.iter().enumerate() {
        let o = &p.observables;
        let share = normalized
            .as_ref()
            .map(|n| {
                n[i].e_ts_norm
                    .map_or("        -".into(), |e| format!("{e:>11.5}"))
            })
            .unwrap_or_default();
        outln!(
            "{:>9.3} {:>9} {:>10} {:>9.5} {:>10.4} {:>11.4} {:>10.4} {:>5} {:>6}{share}",
            p.separation_m * 1e9,
            direction_name(p.direction),
            o.regime,
            o.amplitude_ratio,
            o.phase_deg,
            o.e_ts_ev,
            o.peak_force_n * 1e9,
            if o.converged { "yes" } else { "NO" },
            if o.grazing { "yes" } else { "" }
        );
    }
    let grazing = points.iter().filter(|p| p.observables.grazing).count();
    if grazing > 0 {
        outln!(
            "note: {grazing} of {} points graze a switch: a turning point of the separation \
             lies closer to where the law switches than the thermal motion, so the touch \
             pattern there is set by perturbations nothing controls and other states may \
             coexist (`tapsim tap --separation Z` lists them)",
            points.len()
        );
    }
    let averaged: Vec<&SweepPoint> = points
        .iter()
        .filter(|p| p.thermal_average.is_some())
        .collect();
    if let Some(first) = averaged.first().and_then(|p| p.thermal_average) {
        outln!(
            "thermal averages at {} K over {} periods each (what an instrument reads where \
             the deterministic state grazes or is not period-1; standard errors from {} \
             independent records):",
            first.temperature_k,
            first.periods,
            first.records
        );
        outln!(
            "{:>9} {:>9} {:>22} {:>22} {:>20} {:>15}",
            "z_c (nm)",
            "dir",
            "E_ts (eV)",
            "phi (deg)",
            "A/A0",
            "touches (%)"
        );
        let ev = crate::physics::params::ELECTRONVOLT_J;
        for p in averaged {
            let a = p.thermal_average.expect("filtered");
            outln!(
                "{:>9.3} {:>9} {:>22} {:>22} {:>20} {:>15}",
                p.separation_m * 1e9,
                direction_name(p.direction),
                format!("{:.3} ± {:.3}", a.e_ts_j / ev, a.e_ts_std_err_j / ev),
                format!("{:.3} ± {:.3}", a.phase_deg, a.phase_std_err_deg),
                format!(
                    "{:.6} ± {:.1e}",
                    a.amplitude_ratio, a.amplitude_ratio_std_err
                ),
                format!(
                    "{:.1} ± {:.1}",
                    100.0 * a.touch_fraction,
                    100.0 * a.touch_fraction_std_err
                )
            );
        }
    }
    Ok(())
}

/// A ramp direction as the table prints it.
fn direction_name(direction: Direction) -> &'static str {
    match direction {
        Direction::Approach => "approach",
        Direction::Retract => "retract",
    }
}
