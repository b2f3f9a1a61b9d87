//! `tapsim scan --mode fm`: FM-AFM images — the topography at a constant frequency
//! shift and the dissipation channel.

use super::qnm::Mode;
use super::scan_lines::{Channel, Located, Row};
use crate::analysis::fm::engagement;
use crate::analysis::sweep::Shard;
use crate::app::config::{frequency, time};
use crate::app::report::part::{self, Job};
use crate::dynamics::setup::{Numerics, Prepared, TapSetup};
use crate::error::{Error, Result};
use crate::instrument::fm::Engagement;
use crate::instrument::fm_scan::{FmPixel, FmScanner, ShiftFeedback};
use crate::instrument::scan::Region;
use crate::physics::params::ELECTRONVOLT_J;
use clap::Args;

/// The frequency-shift setpoint by default, Hz: on the built-in blend both polymers
/// hold it on the attractive side of their Δf(z) (A from −184 Hz at first touch down to
/// −375 Hz, B from −88 Hz to −244 Hz).
pub(super) const DEFAULT_SHIFT_HZ: f64 = -200.0;

/// The flags of FM imaging.
#[derive(Debug, Args)]
#[command(next_help_heading = "FM imaging (--mode fm)")]
pub(super) struct FmScanArgs {
    /// The frequency shift the z feedback holds [Hz; default -200Hz]; negative on the
    /// attractive side of Δf(z), where FM images are usually taken.
    #[arg(long, allow_hyphen_values = true, value_parser = frequency)]
    frequency_shift: Option<f64>,
    /// The z feedback's time constant [s; default Q/f₀: 400 drive periods on the
    /// built-in lever]: its gain is set from the steepest Δf(z) among the materials at
    /// the setpoint.
    #[arg(long, allow_hyphen_values = true, value_parser = time)]
    z_time_constant: Option<f64>,
}

/// What a run in FM mode needs, checked.
pub(super) struct Fm {
    setpoint_hz: f64,
    time_constant_s: Option<f64>,
}

impl Fm {
    /// The frequency-shift setpoint, Hz.
    pub(super) fn setpoint_hz(&self) -> f64 {
        self.setpoint_hz
    }
}

impl FmScanArgs {
    /// FM imaging's settings, if the mode is fm; else a refusal of its flags.
    pub(super) fn resolve(&self, mode: Mode) -> Result<Option<Fm>> {
        if mode != Mode::Fm {
            let given = [
                ("--frequency-shift", self.frequency_shift.is_some()),
                ("--z-time-constant", self.z_time_constant.is_some()),
            ];
            if let Some((flag, _)) = given.iter().find(|g| g.1) {
                return Err(Error::NotApplicable(format!(
                    "{flag} sets FM imaging: add --mode fm"
                )));
            }
            return Ok(None);
        }
        if let Some(t) = self.z_time_constant {
            crate::error::positive("z feedback time constant", t)?;
        }
        Ok(Some(Fm {
            setpoint_hz: self.frequency_shift.unwrap_or(DEFAULT_SHIFT_HZ),
            time_constant_s: self.z_time_constant,
        }))
    }
}

impl Located for FmPixel {
    fn x_m(&self) -> f64 {
        self.x_m
    }
    fn x_m_mut(&mut self) -> &mut f64 {
        &mut self.x_m
    }
}

/// The most drive periods one FM scan marches (every line, both directions), before
/// repeats are taken: some 20 minutes on one core at 12 µs a period if none repeat.
const MAX_PERIODS: f64 = 1e8;

/// Where the loops engage over each material, and the z feedback: every material must
/// hold the setpoint on the way in from 1.2 A (else the loop would run the tip into it
/// there), the gain set from the steepest slope of Δf(z) among them.
fn engagements(
    fm: &Fm,
    materials: &[(String, TapSetup)],
    numerics: &Numerics,
) -> Result<(Vec<Engagement>, ShiftFeedback)> {
    // The settled states are found at the steady-state solver's tolerance, whatever the
    // march's: the loops take them up and settle on the march's own within a few periods.
    let settling = Numerics {
        rtol: Numerics::default().rtol,
        atol: Numerics::default().atol,
        ..*numerics
    };
    let mut out = Vec::with_capacity(materials.len());
    let mut steepest: f64 = 0.0;
    for (name, setup) in materials {
        let a = setup.cantilever.free_amplitude_m;
        let (at, slope) = engagement(setup, &settling, fm.setpoint_hz, (1.2 * a, 0.4 * a), 40)
            .map_err(|e| {
                Error::NotApplicable(format!(
                    "material {name} does not hold the frequency shift {} Hz: {e}",
                    fm.setpoint_hz
                ))
            })?;
        if steepest != 0.0 && slope.signum() != steepest.signum() {
            return Err(Error::NotApplicable(format!(
                "the frequency shift {} Hz lies where Δf falls with z on one material and \
                 rises on another (material {name}): no z feedback holds both; choose a \
                 setpoint on one side of every material's Δf(z) (tapsim fm shows them)",
                fm.setpoint_hz
            )));
        }
        if slope.abs() > steepest.abs() {
            steepest = slope;
        }
        out.push(at);
    }
    let c = &materials[0].1.cantilever;
    let periods = fm.time_constant_s.map_or(c.quality, |t| t * c.resonance_hz);
    Ok((
        out,
        ShiftFeedback::with_time_constant(fm.setpoint_hz, steepest, periods)?,
    ))
}

/// An FM line scan or image of `lines` (y and regions each) over the `materials`
/// (`prepared` from them): each line engaged on its first region's settled state, then
/// traced (and retraced).
#[allow(clippy::too_many_arguments)]
pub(super) fn scan(
    fm: &Fm,
    (materials, prepared): (&[(String, TapSetup)], &[Prepared]),
    numerics: &Numerics,
    lines: &[(f64, Vec<Region>)],
    (length_m, pixels, line_rate): (f64, usize, f64),
    (threads, retrace, exact): (usize, bool, bool),
    (out, split, sample): (
        &super::SweepOutput,
        &super::shard::ShardArgs,
        serde_json::Value,
    ),
    (files, meta, size_m): (&super::image::ImageFiles, Vec<(String, String)>, (f64, f64)),
) -> Result<()> {
    let whole_outputs = out.csv.is_some() || out.plot.is_some() || out.json || files.any();
    let shard = split.resolve("scan", whole_outputs)?;
    let mine = shard.unwrap_or(Shard::WHOLE).items(lines.len());
    let cantilever = &prepared[0].setup.cantilever;
    let per_pixel = (cantilever.resonance_hz / (pixels as f64 * line_rate)).round();
    let directions = if retrace { 2 } else { 1 };
    let total = per_pixel * (pixels * lines.len() * directions) as f64;
    if !(per_pixel >= 1.0 && total <= MAX_PERIODS) {
        return Err(Error::OutOfRange(format!(
            "{} lines of {pixels} pixels at {line_rate} lines/s is {per_pixel:e} drive periods \
             a pixel, {total:.3e} in all: from 1 a pixel to {MAX_PERIODS:e} in all (a faster \
             line rate, fewer pixels or lines)",
            lines.len(),
        )));
    }
    let per_pixel = per_pixel as usize;
    let (engaged, feedback) = engagements(fm, materials, numerics)?;
    let bar = out.progress("scan", mine.len() * (pixels * directions + 1));
    let scanned = super::scan_lines::trace_and_retrace(
        (&mine, lines, length_m),
        (threads, retrace, &bar),
        |regions| {
            let mut s = FmScanner::new(prepared, feedback)?;
            if exact {
                s = s.exact();
            }
            let first = regions[0];
            s.engage(&engaged[first.material], first.height_m);
            Ok(s)
        },
        |s, regions, done| s.line(regions, (length_m, pixels, per_pixel), |_| done()),
    )?;
    bar.finish_and_clear();
    if let Some(shard) = shard {
        return split.write(
            ("scan", shard, out.quiet),
            Job::FmScan {
                lines: lines.len(),
                pixels,
                retrace,
                frequency_shift_hz: fm.setpoint_hz,
                image: Some(part::ImageInfo { size_m, meta }),
            },
            &part::Config::Whole(
                serde_json::to_value((
                    sample,
                    numerics,
                    per_pixel,
                    fm.setpoint_hz,
                    feedback,
                    exact,
                ))
                .expect("a configuration serialises"),
            ),
            mine,
            scanned
                .iter()
                .map(|rows| part::raw_records(rows))
                .collect::<Result<_>>()?,
        );
    }
    let rows: Vec<Row<FmPixel>> = scanned.into_iter().flatten().collect();
    let image = lines.len() > 1;
    let shape = (lines.len(), pixels, fm.setpoint_hz);
    out.write_files_drawn(&rows, |path| draw(shape, &rows, path))?;
    if files.any() {
        files.write(&image_channels(&rows, (lines.len(), pixels), size_m), &meta)?;
    }
    if out.json {
        return out.print_json(&rows);
    }
    outln!(
        "{} in FM at Δf = {} Hz: {pixels} pixels a line, {per_pixel} drive periods each; z \
         feedback I gain {:.4e} m/(Hz·s) (time constant {:.4} ms)",
        if image {
            format!("image of {} lines", lines.len())
        } else {
            "line scan".into()
        },
        fm.setpoint_hz,
        feedback.integral_gain_m_per_hz_s(cantilever.resonance_hz),
        fm.time_constant_s
            .unwrap_or(cantilever.quality / cantilever.resonance_hz)
            * 1e3
    );
    let values = |p: &FmPixel| {
        vec![
            p.topography_m * 1e9,
            p.frequency_shift_hz,
            p.error_hz,
            p.excitation_ratio,
            p.dissipation_j / ELECTRONVOLT_J,
        ]
    };
    if image {
        let values: Vec<Vec<f64>> = rows
            .iter()
            .filter(|r| r.direction == "trace")
            .map(|r| values(&r.pixel))
            .collect();
        return super::image::summary(
            &[
                "height (nm)",
                "Δf (Hz)",
                "Δf error (Hz)",
                "F/F₀",
                "dissipation (eV)",
            ],
            &values,
            rows.len(),
        );
    }
    outln!(
        "{:>10} {:>8} {:>12} {:>12} {:>12} {:>12} {:>12}",
        "x (nm)",
        "dir",
        "height (nm)",
        "Δf (Hz)",
        "error (Hz)",
        "F/F₀",
        "E_ts (eV)"
    );
    for r in &rows {
        let v = values(&r.pixel);
        outln!(
            "{:>10.2} {:>8} {:>12.4} {:>12.4} {:>12.4} {:>12.8} {:>12.4}",
            r.pixel.x_m * 1e9,
            r.direction,
            v[0],
            v[1],
            v[2],
            v[3],
            v[4]
        );
    }
    Ok(())
}

/// The Gwyddion channels of an FM image's `rows` ([`super::image::channels`]).
fn image_channels(
    rows: &[Row<FmPixel>],
    shape: (usize, usize),
    size_m: (f64, f64),
) -> Vec<crate::app::report::gwyddion::Channel> {
    let values: Vec<(bool, usize, f64, Vec<f64>)> = rows
        .iter()
        .map(|r| {
            let p = &r.pixel;
            let v = vec![
                p.topography_m,
                p.frequency_shift_hz,
                p.error_hz,
                p.excitation_ratio,
                p.dissipation_j,
                p.amplitude_ratio,
            ];
            (r.direction == "trace", r.line, p.x_m, v)
        })
        .collect();
    let names = [
        ("Topography", "m"),
        ("Frequency shift", "Hz"),
        ("Frequency shift error", "Hz"),
        ("Excitation F/F0", ""),
        ("Dissipation", "J"),
        ("Amplitude A/A0", ""),
    ];
    super::image::channels(&values, shape, size_m, &names)
}

/// Write a whole FM scan's outputs from its records: `tapsim merge` writes a sharded
/// image's through this, its Gwyddion files among them.
pub(super) fn emit_scan<T: serde::Serialize>(
    out: &super::SweepOutput,
    extra: &[std::path::PathBuf],
    (shape, image): ((usize, usize, f64), Option<&part::ImageInfo>),
    records: &[T],
) -> Result<()> {
    super::scan_lines::emit_scan(
        (out, extra),
        ("FM", image),
        records,
        |rows, path| draw(shape, rows, path),
        |rows, size_m| image_channels(rows, (shape.0, shape.1), size_m),
    )
}

/// The channels plotted: name, label, value.
const CHANNELS: [Channel<FmPixel>; 3] = [
    ("topography", "z piezo height (nm)", |p| {
        Some(p.topography_m * 1e9)
    }),
    ("frequency shift", "frequency shift Δf (Hz)", |p| {
        Some(p.frequency_shift_hz)
    }),
    ("dissipation", "dissipation per cycle (eV)", |p| {
        Some(p.dissipation_j / ELECTRONVOLT_J)
    }),
];

/// The plot of an FM scan of (lines, pixels) at the frequency-shift setpoint.
fn draw(
    (lines, pixels, setpoint_hz): (usize, usize, f64),
    rows: &[Row<FmPixel>],
    path: &std::path::Path,
) -> Result<()> {
    super::scan_lines::draw(
        (lines, pixels),
        rows,
        &CHANNELS,
        (
            &format!("FM at Δf = {setpoint_hz} Hz"),
            &format!("Δf = {setpoint_hz} Hz"),
            "none",
        ),
        path,
    )
}
