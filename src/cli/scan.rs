//! `tapsim scan`: a line scanned over a sample with the z feedback closed.

use crate::config::{TapInputs, number};
use crate::dynamics::setup::Prepared;
use crate::error::{Error, Result};
use crate::instrument::feedback::{PiController, hold};
use crate::instrument::lockin::LockIn;
use crate::instrument::scan::{Pixel, line, mirrored};
use crate::report::chart::{Axis, Chart, Corner, Series, Style};
use crate::sample::{BLEND, Sample};
use clap::Args;

/// Scan one line over a sample as an AFM images it: a lock-in reads the amplitude and
/// phase at the drive frequency, a PI controller moves the z piezo to hold the amplitude
/// at the setpoint, and the tip moves along the line at the line rate, trace then
/// retrace. Per pixel: the topography (the piezo position), the amplitude error and the
/// lock-in phase, each the mean over the pixel's drive periods.
///
/// The built-in sample is a flat blend of two polymers on a 1 µm line (A: E = 0.5 GPa,
/// Δγ = 0.1 J/m², the defaults, on the first half; B: E = 1 GPa, Δγ = 0.08 J/m²): the
/// image shows a step that is not there (the two materials hold the setpoint at
/// different rest separations) and the phase contrast between them. --sample FILE.toml
/// describes another: its materials (any of tap's sample and law parameters) and their
/// layout along the line, each region with a surface height (see examples/samples/).
///
/// The loop is engaged over the first region from the free oscillation at 1.2 A₀ (10 000
/// drive periods), so it sits on the branch a falling setpoint stays on (attractive on
/// the defaults). A slow scan (the default: 4 lines/s, 32 pixels, about 2 300 drive
/// periods a pixel at 300 kHz; seconds of computing) lets the loop settle in each
/// pixel; a fast one shows the feedback's artefacts: overshoot after a step up, the
/// amplitude running away after a step down (the tip loses the sample).
///
/// Output: a table, --json (arrays per pixel: x_m, direction, topography_m,
/// amplitude_ratio, error, phase_deg), --csv, --plot (topography and phase profiles,
/// trace and retrace).
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct ScanArgs {
    #[command(flatten)]
    inputs: TapInputs,
    #[command(flatten)]
    out: super::SweepOutput,
    /// The sample (TOML; default: the built-in two-polymer blend).
    #[arg(long)]
    sample: Option<std::path::PathBuf>,
    /// Amplitude setpoint A/A₀ the feedback holds.
    #[arg(long, value_name = "A/A0", allow_hyphen_values = true, value_parser = number,
          default_value_t = 0.8)]
    setpoint: f64,
    /// Pixels along the line.
    #[arg(long, allow_hyphen_values = true, default_value_t = 32)]
    pixels: usize,
    /// Lines per second (each direction).
    #[arg(long, allow_hyphen_values = true, value_parser = number, default_value_t = 4.0)]
    line_rate: f64,
    /// Integral gain K_i of the z feedback (A₀ per unit of A/A₀ error per drive period).
    #[arg(long, allow_hyphen_values = true, value_parser = number, default_value_t = 0.002)]
    integral_gain: f64,
    /// Proportional gain K_p (A₀ per unit of A/A₀ error).
    #[arg(long, allow_hyphen_values = true, value_parser = number, default_value_t = 0.0)]
    proportional_gain: f64,
    /// Lock-in filter order (1–4).
    #[arg(long, allow_hyphen_values = true, default_value_t = 4)]
    lockin_order: usize,
    /// Lock-in time constant, in drive periods (at most 1000).
    #[arg(long, allow_hyphen_values = true, value_parser = number, default_value_t = 2.0)]
    lockin_periods: f64,
    /// Trace only.
    #[arg(long)]
    no_retrace: bool,
}

/// A pixel with its direction.
#[derive(serde::Serialize)]
struct Row {
    direction: &'static str,
    #[serde(flatten)]
    pixel: Pixel,
}

/// The most drive periods one scan marches (both directions).
const MAX_PERIODS: f64 = 2e7;

/// The loop's engagement over the first region, in drive periods.
const ENGAGE_PERIODS: usize = 10_000;

/// Run the subcommand.
pub fn run(args: ScanArgs) -> Result<()> {
    let base = args.inputs.clone().with_config()?;
    base.no_setpoint("scan")?;
    if base.separation.is_some() {
        return Err(Error::NotApplicable(
            "a scan holds the setpoint (--setpoint); the feedback sets the separation".into(),
        ));
    }
    let sample = match &args.sample {
        Some(path) => Sample::from_file(path, &base)?,
        None => Sample::from_toml(BLEND, &base)?,
    };
    if !(1..=4096).contains(&args.pixels) {
        return Err(Error::OutOfRange(format!(
            "--pixels is from 1 to 4096, not {}",
            args.pixels
        )));
    }
    crate::error::positive("line rate", args.line_rate)?;
    if !(args.lockin_periods > 0.0 && args.lockin_periods <= 1000.0) {
        return Err(Error::OutOfRange(format!(
            "--lockin-periods is from above 0 to 1000 drive periods, not {}",
            args.lockin_periods
        )));
    }
    let (_, numerics) = base.resolve()?;
    let prepared = sample
        .materials
        .iter()
        .map(|(_, s)| Prepared::new(s, &numerics))
        .collect::<Result<Vec<_>>>()?;
    let first = &prepared[sample.regions[0].material];
    let sim = first.simulation();
    let omega = sim.osc.omega;
    let period_hat = sim.osc.period();
    let drive_hz = first.setup.cantilever.drive_frequency_hz;
    let per_pixel = (drive_hz / (args.pixels as f64 * args.line_rate)).round();
    let directions = if args.no_retrace { 1.0 } else { 2.0 };
    let total = per_pixel * args.pixels as f64 * directions;
    if !(per_pixel >= 1.0 && total <= MAX_PERIODS) {
        return Err(Error::OutOfRange(format!(
            "{} pixels at {} lines/s is {per_pixel:e} drive periods a pixel, {total:.3e} in \
             all: from 1 a pixel to {MAX_PERIODS:e} in all",
            args.pixels,
            if (1e-3..1e6).contains(&args.line_rate) {
                args.line_rate.to_string()
            } else {
                format!("{:e}", args.line_rate)
            }
        )));
    }
    let per_pixel = per_pixel as usize;
    let mut lockin = LockIn::new(args.lockin_order, args.lockin_periods * period_hat, omega)?;
    let mut controller =
        PiController::new(args.setpoint, args.proportional_gain, args.integral_gain)?;
    let a0 = first.setup.cantilever.free_amplitude_m;
    let bar = args.out.progress_bar(args.pixels * directions as usize + 1);
    let mut phase = sim.free_steady_start();
    // The loop holds the rest separation; the piezo stands that much above the surface.
    let (_, rest) = hold(
        first,
        (1.2 * a0, &mut phase),
        &mut lockin,
        &mut controller,
        ENGAGE_PERIODS,
    )?;
    let mut z = rest + sample.regions[0].height_m;
    bar.inc(1);
    let mut rows = Vec::new();
    let mut layouts = vec![("trace", sample.regions.clone())];
    if !args.no_retrace {
        layouts.push(("retrace", mirrored(&sample.regions, sample.length_m)));
    }
    for (direction, regions) in layouts {
        let (pixels, end) = line(
            &prepared,
            &regions,
            (sample.length_m, args.pixels, per_pixel),
            (&mut lockin, &mut controller),
            z,
            &mut phase,
            |_| bar.inc(1),
        )?;
        z = end;
        rows.extend(pixels.into_iter().map(|mut pixel| {
            if direction == "retrace" {
                pixel.x_m = sample.length_m - pixel.x_m;
            }
            Row { direction, pixel }
        }));
    }
    bar.finish_and_clear();
    args.out.write_files(&rows, || charts(&rows))?;
    if args.out.json {
        return args.out.print_json(&rows);
    }
    outln!(
        "line scan at A/A₀ = {}: {} pixels, {per_pixel} drive periods each",
        args.setpoint,
        args.pixels
    );
    outln!(
        "{:>10} {:>8} {:>12} {:>10} {:>10} {:>10}",
        "x (nm)",
        "dir",
        "height (nm)",
        "A/A0",
        "error",
        "phi (deg)"
    );
    for r in &rows {
        let p = &r.pixel;
        outln!(
            "{:>10.2} {:>8} {:>12.4} {:>10.6} {:>10.2e} {:>10.4}",
            p.x_m * 1e9,
            r.direction,
            p.topography_m * 1e9,
            p.amplitude_ratio,
            p.error,
            p.phase_deg
        );
    }
    Ok(())
}

/// Topography and phase profiles, trace and retrace.
fn charts(rows: &[Row]) -> Vec<Chart> {
    let profile = |name: &str, title: &str, label: &str, pick: fn(&Pixel) -> f64| {
        let series: Vec<Series> = [("trace", Style::Line, 1), ("retrace", Style::Dashed, 2)]
            .into_iter()
            .filter_map(|(dir, style, color)| {
                let points: Vec<(f64, f64)> = rows
                    .iter()
                    .filter(|r| r.direction == dir)
                    .map(|r| (r.pixel.x_m * 1e9, pick(&r.pixel)))
                    .collect();
                (!points.is_empty()).then(|| Series::new(dir, points, style, color))
            })
            .collect();
        Chart {
            name: name.into(),
            title: title.into(),
            x: Axis::linear("position along the line x (nm)", "x_nm"),
            y: Axis::linear(label, name),
            legend: Corner::quietest(&series),
            series,
            labels: vec![],
        }
    };
    vec![
        profile(
            "topography_nm",
            "topography (z piezo)",
            "height (nm)",
            |p| p.topography_m * 1e9,
        ),
        profile("phase_deg", "lock-in phase", "phase lag φ (deg)", |p| {
            p.phase_deg
        }),
    ]
}
