//! `tapsim fm`: an FM-AFM approach curve at constant amplitude.

use super::progress::Progress;
use super::{SeparationRange, SweepOutput, SweepStart};
use crate::analysis::fm::{FmPoint, approach, at_shift};
use crate::app::config::TapInputs;
use crate::app::report::chart::{Axis, Chart, Corner, Series, Style};
use crate::dynamics::setup::significant;
use crate::dynamics::setup::{Numerics, Prepared, TapSetup};
use crate::error::Result;
use crate::instrument::average::AverageRequest;
use crate::instrument::fm::{FmAverage, thermal_average};
use crate::physics::params::ELECTRONVOLT_J;
use clap::Args;

/// FM-AFM approach: the frequency shift and the dissipation at constant amplitude.
///
/// In frequency-modulation AFM the cantilever is self-excited at its own, shifted
/// resonance: a phase-locked loop keeps the drive 90° ahead of the motion and an
/// amplitude controller holds the amplitude at its setpoint — here the free amplitude
/// (--free-amplitude, 20 nm by default). Two channels come out at each rest separation
/// z_c: the frequency shift Δf (the conservative forces, to first order
/// Δf = −f₀⟨F_ts q⟩/(kA²)) and the excitation F over its free value F₀ = kA/Q, whose
/// rise is the energy the sample takes per cycle, E_ts = (πkA²/Q)(F/F₀ − f/f₀) — the
/// paper's hysteresis, read cycle by cycle. Printed per point: z_c, Δf, F/F₀, that E_ts,
/// the least tip–sample separation and the peak force; where the loops find no
/// period-1 orbit near the last point's, why.
///
/// The loops are taken as settled: the orbit they hold is found directly (Newton's
/// method on the orbit and the two loop conditions), each point from the last, from
/// --from (1.2 A by default) to --to (0.4 A).
///
/// With --setpoint (a frequency shift, e.g. -300Hz) the state the z feedback holds
/// there is printed instead: the approach goes in until Δf first crosses the setpoint,
/// and z_c is closed on to 1e-9 of it.
///
/// Examples:
///   tapsim fm                                        # hybrid law, A = 20 nm
///   tapsim fm --setpoint -300Hz                      # the state at Δf = −300 Hz
///   tapsim fm --law jkr --from 20nm --to 17nm --plot fm.png
///   tapsim fm --law dmt --free-amplitude 1nm --from 2nm --to 0.5nm --csv fm.csv
///
/// JSON keys (--json): law, amplitude_m, and one array per column, an entry per point:
/// separation_m, frequency_shift_hz, frequency_ratio, excitation_ratio,
/// e_ts_from_excitation_j, e_ts_ev, min_separation_m, peak_force_n, mean_force_n,
/// jumps_in, loop_loss_j (the law's loop per touch times the touches, from the orbit),
/// grazing and note (null where the point has a state). --csv FILE: the same columns
/// (`tapsim reconstruct FILE --mode fm` inverts them); --plot FILE.png|svg: Δf and E_ts
/// against z_c.
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct FmArgs {
    #[command(flatten)]
    pub(super) inputs: TapInputs,
    #[command(flatten)]
    range: SeparationRange,
    /// A frequency-shift setpoint the z feedback holds (e.g. -20Hz): print the state
    /// there, the first on the way in from --from, instead of the approach [Hz].
    #[arg(long, allow_hyphen_values = true, value_parser = crate::app::config::frequency)]
    setpoint: Option<f64>,
    /// Points of the approach [default 40].
    #[arg(long, value_parser = clap::value_parser!(u32).range(2..=10_000))]
    points: Option<u32>,
    /// Temperature [K; off unless given]: each settled point read again with the loops
    /// running in time under the thermal force of the cantilever's damping
    /// (S_F = 4k_BT·k/(ω₀Q)): the mean Δf and E_ts from the excitation, with standard
    /// errors from eight independent records (JSON/CSV thermal_*).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::app::config::temperature,
          help_heading = "Thermal noise")]
    temperature: Option<f64>,
    /// Drive periods of each thermal average: eight records of an eighth each, after
    /// ten decay times of settling; each point draws noise of its own (a seed derived
    /// from its place along the curve).
    #[arg(hide_short_help = true, long, default_value_t = super::DEFAULT_THERMAL_PERIODS,
          help_heading = "Thermal noise")]
    thermal_periods: usize,
    #[command(flatten)]
    pub(super) out: SweepOutput,
}

/// What a point whose orbit grazes a switch is marked with.
const GRAZING: &str = "grazing: the orbit passes a switch within the thermal motion";

/// [`GRAZING`] after `separator` for a grazing point, nothing otherwise.
fn grazing_mark(grazing: Option<bool>, separator: &str) -> String {
    if grazing == Some(true) {
        format!("{separator}{GRAZING}")
    } else {
        String::new()
    }
}

/// One point as written (CSV, JSON).
#[derive(serde::Serialize)]
struct Row {
    separation_m: f64,
    frequency_shift_hz: Option<f64>,
    frequency_ratio: Option<f64>,
    excitation_ratio: Option<f64>,
    e_ts_from_excitation_j: Option<f64>,
    e_ts_ev: Option<f64>,
    min_separation_m: Option<f64>,
    peak_force_n: Option<f64>,
    mean_force_n: Option<f64>,
    jumps_in: Option<f64>,
    loop_loss_j: Option<f64>,
    grazing: Option<bool>,
    note: Option<String>,
    /// Under --temperature: the channels averaged under the thermal force.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    thermal: Option<Thermal>,
}

/// The thermal averages of a point, as written.
#[derive(serde::Serialize)]
struct Thermal {
    thermal_frequency_shift_hz: f64,
    thermal_frequency_shift_std_err_hz: f64,
    thermal_excitation_ratio: f64,
    thermal_e_ts_j: f64,
    thermal_e_ts_std_err_j: f64,
    thermal_seed: u64,
}

impl Thermal {
    fn of(a: &FmAverage) -> Self {
        Self {
            thermal_frequency_shift_hz: a.frequency_shift_hz,
            thermal_frequency_shift_std_err_hz: a.frequency_shift_std_err_hz,
            thermal_excitation_ratio: a.excitation_ratio,
            thermal_e_ts_j: a.e_ts_from_excitation_j,
            thermal_e_ts_std_err_j: a.e_ts_std_err_j,
            thermal_seed: a.seed,
        }
    }
}

/// The thermal average of each settled point of `points` of `setup` at `temperature`
/// (none where a point has no state), each with a seed of its own.
fn thermal_averages(
    (setup, numerics): (&TapSetup, &Numerics),
    points: &[FmPoint],
    (temperature_k, periods): (f64, usize),
    quiet: bool,
) -> Result<Vec<Option<FmAverage>>> {
    let request = AverageRequest {
        temperature_k,
        periods,
        seed: 1,
    };
    request.check(setup.cantilever.quality)?;
    let bar = Progress::counted("fm: thermal averages", points.len(), quiet);
    let out = points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let Some(state) = &p.state else {
                bar.inc(1);
                return Ok(None);
            };
            let at = TapSetup {
                separation_m: state.separation_m,
                ..setup.clone()
            };
            let prepared = Prepared::new(&at, numerics)?;
            let average = thermal_average(&prepared, &state.engagement(), &request.at(&[i as u64]));
            bar.inc(1);
            average.map(Some)
        })
        .collect();
    bar.finish_and_clear();
    out
}

impl Row {
    fn of(p: &FmPoint, thermal: Option<&FmAverage>) -> Self {
        let s = p.state.as_ref();
        Self {
            thermal: thermal.map(Thermal::of),
            separation_m: p.separation_m,
            frequency_shift_hz: s.map(|s| s.frequency_shift_hz),
            frequency_ratio: s.map(|s| s.frequency_ratio),
            excitation_ratio: s.map(|s| s.excitation_ratio),
            e_ts_from_excitation_j: s.map(|s| s.e_ts_from_excitation_j),
            e_ts_ev: s.map(|s| s.e_ts_from_excitation_j / ELECTRONVOLT_J),
            min_separation_m: s.map(|s| s.observables.min_separation_m),
            peak_force_n: s.map(|s| s.observables.peak_force_n),
            mean_force_n: s.map(|s| s.observables.mean_force_n),
            jumps_in: s.map(|s| s.observables.jumps_in),
            loop_loss_j: s.map(|s| s.observables.loop_area_j * s.observables.jumps_in),
            grazing: s.map(|s| s.observables.grazing),
            note: p.note.clone(),
        }
    }
}

/// Run the subcommand.
pub fn run(args: FmArgs) -> Result<()> {
    let start = SweepStart::new("fm", args.inputs.clone(), &args.range)?;
    let setup = &start.setup;
    let n = args.points.unwrap_or(40) as usize;
    let (from, to) = start.range;
    let separations: Vec<f64> = (0..n)
        .map(|i| from + (to - from) * i as f64 / (n - 1) as f64)
        .collect();
    if let Some(shift_hz) = args.setpoint {
        args.out
            .refuse_plots("state at a frequency-shift setpoint", &[])?;
        let busy = super::progress::Busy::new("fm: approaching the setpoint", args.out.quiet);
        let state = at_shift(setup, &start.numerics, shift_hz, (from, to), n - 1);
        busy.finish_and_clear();
        let state = state?;
        let point = FmPoint {
            separation_m: state.separation_m,
            state: Some(state),
            note: None,
        };
        let thermal = match args.temperature {
            Some(t) => thermal_averages(
                (setup, &start.numerics),
                std::slice::from_ref(&point),
                (t, args.thermal_periods),
                args.out.quiet,
            )?
            .pop()
            .flatten(),
            None => None,
        };
        let row = Row::of(&point, thermal.as_ref());
        args.out.write_files(std::slice::from_ref(&row), Vec::new)?;
        if args.out.json {
            outln!("{}", crate::app::report::records::document(&row)?);
            return Ok(());
        }
        outln!(
            "FM, {} law: Δf = {} Hz held at z_c = {:.4} nm (amplitude {} nm): F/F₀ = {:.9}, \
             E_ts from the excitation {:.4} eV, least separation {:.4} nm, peak force {:.4} nN{}",
            setup.law,
            significant(shift_hz),
            row.separation_m * 1e9,
            significant(setup.cantilever.free_amplitude_m * 1e9),
            row.excitation_ratio.unwrap_or(f64::NAN),
            row.e_ts_ev.unwrap_or(f64::NAN) + 0.0,
            row.min_separation_m.unwrap_or(f64::NAN) * 1e9 + 0.0,
            row.peak_force_n.unwrap_or(f64::NAN) * 1e9 + 0.0,
            grazing_mark(row.grazing, "; ")
        );
        if let Some(a) = &thermal {
            outln!("{}", thermal_line(a));
        }
        return Ok(());
    }
    let progress = Progress::counted("fm", n, args.out.quiet);
    let points = approach(setup, &start.numerics, &separations, || progress.inc(1));
    progress.finish_and_clear();
    let points = points?;
    let thermal = match args.temperature {
        Some(t) => thermal_averages(
            (setup, &start.numerics),
            &points,
            (t, args.thermal_periods),
            args.out.quiet,
        )?,
        None => vec![None; points.len()],
    };
    let rows: Vec<Row> = points
        .iter()
        .zip(&thermal)
        .map(|(p, a)| Row::of(p, a.as_ref()))
        .collect();
    let amplitude_m = setup.cantilever.free_amplitude_m;
    let law = setup.law.to_string();
    args.out
        .write_files(&rows, || charts(&law, amplitude_m, &rows))?;
    if args.out.json {
        use crate::app::report::records::{columns_json, document};
        let mut doc = columns_json(&rows)?;
        if let serde_json::Value::Object(map) = &mut doc {
            map.insert("law".into(), law.into());
            map.insert("amplitude_m".into(), amplitude_m.into());
        }
        outln!("{}", document(&doc)?);
        return Ok(());
    }
    let cant = &setup.cantilever;
    outln!(
        "FM approach, {law} law: amplitude held at {} nm, drive 90° ahead, on a {} N/m lever \
         resonating at {} kHz (Q {})",
        significant(amplitude_m * 1e9),
        significant(cant.stiffness_n_m),
        significant(cant.resonance_hz * 1e-3),
        significant(cant.quality)
    );
    outln!(
        "{:>9}  {:>11}  {:>12}  {:>10}  {:>10}  {:>10}",
        "z_c (nm)",
        "Δf (Hz)",
        "F/F₀",
        "E_ts (eV)",
        "min α (nm)",
        "peak (nN)"
    );
    for r in &rows {
        match (
            r.frequency_shift_hz,
            r.excitation_ratio,
            r.e_ts_ev,
            r.min_separation_m,
            r.peak_force_n,
        ) {
            (Some(df), Some(x), Some(e), Some(min), Some(peak)) => outln!(
                "{:>9.4}  {:>11.4}  {:>12.9}  {:>10.4}  {:>10.4}  {:>10.4}{}{}",
                r.separation_m * 1e9,
                df + 0.0,
                x,
                e + 0.0,
                min * 1e9 + 0.0,
                peak * 1e9 + 0.0,
                grazing_mark(r.grazing, "  "),
                r.thermal.as_ref().map_or(String::new(), |t| format!(
                    "  at {} K: Δf {:.4} ± {:.4} Hz, E_ts {:.4} ± {:.4} eV",
                    significant(args.temperature.unwrap_or(0.0)),
                    t.thermal_frequency_shift_hz,
                    t.thermal_frequency_shift_std_err_hz,
                    t.thermal_e_ts_j / ELECTRONVOLT_J,
                    t.thermal_e_ts_std_err_j / ELECTRONVOLT_J
                ))
            ),
            _ => outln!(
                "{:>9.4}  {}",
                r.separation_m * 1e9,
                r.note.as_deref().unwrap_or("no state")
            ),
        }
    }
    Ok(())
}

/// A thermal average in a line.
fn thermal_line(a: &FmAverage) -> String {
    format!(
        "at {} K, the loops running under the thermal force ({} periods in {} records): Δf \
         {:.4} ± {:.4} Hz, F/F₀ {:.9} ± {:.1e}, E_ts from the excitation {:.4} ± {:.4} eV",
        significant(a.temperature_k),
        a.periods,
        a.records,
        a.frequency_shift_hz,
        a.frequency_shift_std_err_hz,
        a.excitation_ratio,
        a.excitation_ratio_std_err,
        a.e_ts_from_excitation_j / ELECTRONVOLT_J,
        a.e_ts_std_err_j / ELECTRONVOLT_J
    )
}

/// Δf and E_ts against z_c.
fn charts(law: &str, amplitude_m: f64, rows: &[Row]) -> Vec<Chart> {
    let title = format!(
        "{law} law, FM approach at A = {} nm",
        significant(amplitude_m * 1e9)
    );
    let points = |y: fn(&Row) -> Option<f64>| -> Vec<(f64, f64)> {
        rows.iter()
            .filter_map(|r| y(r).map(|v| (r.separation_m * 1e9, v)))
            .collect()
    };
    // From zero: the loss per touch is nearly constant along an approach, and an
    // automatic range would magnify the higher harmonics' share of the damping.
    let most = rows
        .iter()
        .flat_map(|r| [r.e_ts_ev, r.loop_loss_j.map(|e| e / ELECTRONVOLT_J)])
        .flatten()
        .fold(0.0, f64::max);
    vec![
        Chart {
            name: "fm_frequency_shift".into(),
            title: title.clone(),
            x: Axis::linear("rest separation z_c (nm)", "separation_nm"),
            y: Axis::linear("frequency shift Δf (Hz)", "frequency_shift_hz"),
            legend: Corner::LowerRight,
            series: vec![Series::new(
                "Δf (simulated, loops settled)",
                points(|r| r.frequency_shift_hz),
                Style::Markers,
                0,
            )],
            labels: Vec::new(),
        },
        Chart {
            name: "fm_dissipation".into(),
            title,
            x: Axis::linear("rest separation z_c (nm)", "separation_nm"),
            y: Axis {
                range: Some((0.0, if most > 0.0 { 1.15 * most } else { 1.0 })),
                ..Axis::linear("energy lost per cycle E_ts (eV)", "e_ts_ev")
            },
            legend: Corner::LowerRight,
            series: vec![
                Series::new(
                    "read from the excitation, (πkA²/Q)(F/F₀ − f/f₀)",
                    points(|r| r.e_ts_ev),
                    Style::Markers,
                    0,
                ),
                Series::new(
                    "the law's loop per touch (the orbit)",
                    points(|r| r.loop_loss_j.map(|e| e / ELECTRONVOLT_J)),
                    Style::Crosses,
                    1,
                ),
            ],
            labels: Vec::new(),
        },
    ]
}
