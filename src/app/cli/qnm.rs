//! `tapsim map --mode peakforce` and `tapsim scan --mode peakforce`: off-resonance
//! tapping over a grid of materials and over a sample, the QNM channels as heat maps.

use super::peakforce::{DEFAULT_PEAK_FORCE_N, FitWindowArgs, ModulationArgs};
use crate::analysis::qnm_map::{QnmCell, map_cells};
use crate::analysis::sweep::Shard;
use crate::app::config::{force, number};
use crate::app::report::heatmap::HeatMap;
use crate::app::report::part::{self, Job};
use crate::app::report::records::typed;
use crate::dynamics::setup::{Numerics, Prepared, TapSetup};
use crate::error::{Error, Result};
use crate::instrument::peakforce::{Modulation, PeakForceFeedback, check_setpoint};
use crate::instrument::peakforce_scan::{QnmPixel, Scanner};
use crate::instrument::qnm::Analysis;
use crate::instrument::scan::Region;
use crate::physics::params::ELECTRONVOLT_J;
use clap::Args;

/// How the sample is imaged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Mode {
    /// Tapping (amplitude modulation): the lock-in's amplitude held at a setpoint.
    #[default]
    Tapping,
    /// Off-resonance tapping (PeakForce-type): the peak force of each modulation cycle
    /// held at a setpoint, the QNM channels read from each pixel's force curve.
    Peakforce,
    /// Frequency modulation (scan only): the cantilever self-excited at its shifted
    /// resonance, the frequency shift held at a setpoint, the dissipation read from the
    /// excitation.
    Fm,
}

/// The imaging mode and, for off-resonance tapping, its flags.
#[derive(Debug, Args)]
#[command(next_help_heading = "Off-resonance tapping (--mode peakforce)")]
pub(super) struct QnmArgs {
    /// The imaging mode: tapping (the amplitude held at a setpoint; the default),
    /// peakforce (off-resonance tapping: the peak force held at --peak-force; the maps
    /// are the QNM channels — adhesion, dissipation, DMT modulus, deformation) or fm
    /// (scan only: the frequency shift held at --frequency-shift; topography, Δf and
    /// dissipation).
    #[arg(long, value_enum, ignore_case = true, default_value_t = Mode::Tapping)]
    pub(super) mode: Mode,
    /// The peak-force setpoint [N; default 5nN].
    #[arg(long, allow_hyphen_values = true, value_parser = force)]
    peak_force: Option<f64>,
    #[command(flatten)]
    modulation: ModulationArgs,
    #[command(flatten)]
    window: FitWindowArgs,
    /// The peak-force feedback's gain per cycle (0 < g ≤ 1) [default 0.5] (scan).
    #[arg(long, allow_hyphen_values = true, value_parser = number)]
    peak_force_gain: Option<f64>,
}

/// What a run in peakforce mode needs, checked.
pub(super) struct Qnm {
    pub(super) setpoint_n: f64,
    pub(super) modulation: Modulation,
    pub(super) analysis: Analysis,
    pub(super) gain: f64,
}

impl Qnm {
    /// What determines the results beyond the setup, for a part file's configuration.
    fn settings(&self) -> serde_json::Value {
        serde_json::json!({
            "peak_force_n": self.setpoint_n,
            "modulation": self.modulation,
            "analysis": self.analysis,
            "gain": self.gain,
        })
    }
}

impl QnmArgs {
    /// Off-resonance tapping's settings, if the mode is peakforce; else a refusal of
    /// its flags.
    pub(super) fn resolve(&self) -> Result<Option<Qnm>> {
        if self.mode != Mode::Peakforce {
            let given = [
                ("--peak-force", self.peak_force.is_some()),
                (
                    "--modulation-frequency",
                    self.modulation.modulation_frequency.is_some(),
                ),
                (
                    "--modulation-amplitude",
                    self.modulation.modulation_amplitude.is_some(),
                ),
                ("--fit-from", self.window.fit_from.is_some()),
                ("--fit-to", self.window.fit_to.is_some()),
                ("--peak-force-gain", self.peak_force_gain.is_some()),
            ];
            if let Some((flag, _)) = given.iter().find(|g| g.1) {
                return Err(Error::NotApplicable(format!(
                    "{flag} sets off-resonance tapping: add --mode peakforce"
                )));
            }
            return Ok(None);
        }
        let setpoint_n = self.peak_force.unwrap_or(DEFAULT_PEAK_FORCE_N);
        check_setpoint(setpoint_n)?;
        let gain = self.peak_force_gain.unwrap_or(0.5);
        if !(gain > 0.0 && gain <= 1.0) {
            return Err(Error::InvalidParameter {
                name: "peak-force gain",
                value: gain,
                reason: "must be above 0 and at most 1 (per cycle)",
            });
        }
        Ok(Some(Qnm {
            setpoint_n,
            modulation: self.modulation.modulation(),
            analysis: self.window.analysis()?,
            gain,
        }))
    }
}

/// Refuse, in `mode` (peakforce or fm), a flag of the tapping loop that was given.
pub(super) fn refuse_in_mode(mode: &str, given: &[(&str, bool)]) -> Result<()> {
    let holds = if mode == "fm" {
        "the frequency shift (--frequency-shift)"
    } else {
        "the peak force (--peak-force)"
    };
    match given.iter().find(|g| g.1) {
        Some((flag, _)) => Err(Error::NotApplicable(format!(
            "{flag} is tapping's (the amplitude loop); --mode {mode} holds {holds}"
        ))),
        None => Ok(()),
    }
}

/// A QNM map over (Δγ, E*) at the peak-force setpoint: every cell (or a shard's) solved,
/// then the CSV, JSON and heat maps of adhesion, dissipation, DMT modulus and
/// deformation, or the shard's part file.
pub(super) fn map(
    q: &Qnm,
    (setup, numerics): (&TapSetup, &Numerics),
    (works, moduli): (&[f64], &[f64]),
    threads: usize,
    (out, split): (&super::SweepOutput, &super::shard::ShardArgs),
) -> Result<()> {
    q.modulation.check(&setup.cantilever)?;
    let whole_outputs = out.csv.is_some() || out.plot.is_some() || out.json;
    let shard = split.resolve("map", whole_outputs)?;
    let mine = shard
        .unwrap_or(Shard::WHOLE)
        .items(works.len() * moduli.len());
    let bar = out.progress("map", mine.len());
    let cells = map_cells(
        setup,
        numerics,
        (works, moduli),
        &mine,
        threads,
        || bar.inc(1),
        &q.modulation,
        &q.analysis,
        q.setpoint_n,
    );
    bar.finish_and_clear();
    let cells = cells?;
    let law = setup.law.to_string();
    if let Some(shard) = shard {
        return split.write(
            ("map", shard, out.quiet),
            Job::QnmMap {
                law,
                work_of_adhesion_j_m2: works.to_vec(),
                modulus_pa: moduli.to_vec(),
                peak_force_n: q.setpoint_n,
            },
            &part::Config::Whole(
                serde_json::to_value((setup, numerics, works, moduli, q.settings()))
                    .expect("a configuration serialises"),
            ),
            mine,
            cells
                .iter()
                .map(|c| part::raw_records(std::slice::from_ref(c)))
                .collect::<Result<_>>()?,
        );
    }
    emit_map(out, &[], (&law, q.setpoint_n), (works, moduli), &cells)
}

/// Write a whole QNM map's outputs from its records (`tapsim merge` writes a sharded
/// one's through this): the CSV, the JSON columns, the heat maps.
pub(super) fn emit_map<T: serde::Serialize>(
    out: &super::SweepOutput,
    extra: &[std::path::PathBuf],
    (law, setpoint_n): (&str, f64),
    (works, moduli): (&[f64], &[f64]),
    records: &[T],
) -> Result<()> {
    let cells: Vec<QnmCell> = typed(records, "QNM")?;
    let title = format!("{law} law, peak force {} nN", setpoint_n * 1e9);
    out.emit(
        ("map", extra),
        records,
        || crate::app::report::records::columns_json(records),
        Some(&|path| {
            crate::app::report::plot::render_heatmaps(
                &map_heat_maps(&title, works, moduli, &cells),
                path,
            )
        }),
    )?;
    let empty = cells.iter().filter(|c| c.note.is_some()).count();
    if empty > 0 && !out.quiet {
        eprintln!(
            "note: {empty} of {} cells hold no peak force at the setpoint (column note; grey \
             on the heat maps)",
            cells.len()
        );
    }
    Ok(())
}

/// The QNM channels over the grid.
fn map_heat_maps(title: &str, works: &[f64], moduli: &[f64], cells: &[QnmCell]) -> Vec<HeatMap> {
    let panel = |what: &str, label: &str, value: &dyn Fn(&QnmCell) -> Option<f64>| {
        HeatMap::parameter_grid(
            (format!("{what} ({title})"), label, "not held or n/a"),
            (works, moduli),
            cells
                .chunks(works.len())
                .map(|row| {
                    row.iter()
                        .map(|c| value(c).map(|v| (v, c.regime.as_deref() == Some("period-1"))))
                        .collect()
                })
                .collect(),
        )
    };
    vec![
        panel("adhesion", "adhesion (nN)", &|c| {
            c.adhesion_n.map(|f| f * 1e9)
        }),
        panel("dissipation", "dissipation per cycle (eV)", &|c| {
            c.dissipation_j.map(|e| e / ELECTRONVOLT_J)
        }),
        panel("DMT modulus", "DMT modulus fitted (GPa)", &|c| {
            c.dmt_modulus_pa.map(|e| e * 1e-9)
        }),
        panel("deformation", "deformation (nm)", &|c| {
            c.deformation_m.map(|d| d * 1e9)
        }),
    ]
}

type Row = super::scan_lines::Row<QnmPixel>;

impl super::scan_lines::Located for QnmPixel {
    fn x_m(&self) -> f64 {
        self.x_m
    }
    fn x_m_mut(&mut self) -> &mut f64 {
        &mut self.x_m
    }
}

/// The most modulation cycles one QNM scan marches (every line, both directions), before
/// repeats are taken: some 15 minutes on one core at 0.44 ms a cycle if none repeat.
const MAX_CYCLES: f64 = 2e6;

/// A QNM line scan or image of `lines` (y and regions each) over `prepared` materials:
/// each line engaged over its first region, then traced (and retraced).
#[allow(clippy::too_many_arguments)]
pub(super) fn scan(
    q: &Qnm,
    prepared: &[Prepared],
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
    q.modulation.check(cantilever)?;
    let per_pixel = (q.modulation.frequency_hz / (pixels as f64 * line_rate)).round();
    let directions = if retrace { 2 } else { 1 };
    let total = per_pixel * (pixels * lines.len() * directions) as f64;
    if !(per_pixel >= 1.0 && total <= MAX_CYCLES) {
        return Err(Error::OutOfRange(format!(
            "{} lines of {pixels} pixels at {line_rate} lines/s is {per_pixel:e} modulation \
             cycles a pixel at {} kHz, {total:.3e} in all: from 1 a pixel to {MAX_CYCLES:e} \
             in all (a faster line rate, fewer pixels or lines)",
            lines.len(),
            q.modulation.frequency_hz * 1e-3
        )));
    }
    let per_pixel = per_pixel as usize;
    let loop_ = PeakForceFeedback {
        setpoint_n: q.setpoint_n,
        gain: q.gain,
    };
    let bar = out.progress("scan", mine.len() * (pixels * directions + 1));
    let scanned = super::scan_lines::trace_and_retrace(
        (&mine, lines, length_m),
        (threads, retrace, &bar),
        |regions| {
            let mut s = Scanner::new(prepared, &q.modulation, q.analysis, loop_, numerics)?;
            if exact {
                s = s.exact();
            }
            let first = regions[0];
            s.engage(first.material, first.height_m, q.modulation.amplitude_m)?;
            Ok(s)
        },
        |s, regions, done| s.line(regions, (length_m, pixels, per_pixel), |_| done()),
    )?;
    bar.finish_and_clear();
    if let Some(shard) = shard {
        return split.write(
            ("scan", shard, out.quiet),
            Job::QnmScan {
                lines: lines.len(),
                pixels,
                retrace,
                peak_force_n: q.setpoint_n,
                image: Some(part::ImageInfo { size_m, meta }),
            },
            &part::Config::Whole(
                serde_json::to_value((sample, numerics, per_pixel, q.settings(), exact))
                    .expect("a configuration serialises"),
            ),
            mine,
            scanned
                .iter()
                .map(|rows| part::raw_records(rows))
                .collect::<Result<_>>()?,
        );
    }
    let rows: Vec<Row> = scanned.into_iter().flatten().collect();
    let image = lines.len() > 1;
    let shape = (lines.len(), pixels, q.setpoint_n);
    out.write_files_drawn(&rows, |path| draw(shape, &rows, path))?;
    if files.any() {
        files.write(&image_channels(&rows, (lines.len(), pixels), size_m), &meta)?;
    }
    if out.json {
        return out.print_json(&rows);
    }
    outln!(
        "{} in off-resonance tapping at a peak force of {} nN: {pixels} pixels a line, \
         {per_pixel} modulation cycles each (the channels from each pixel's last)",
        if image {
            format!("image of {} lines", lines.len())
        } else {
            "line scan".into()
        },
        q.setpoint_n * 1e9
    );
    if image {
        let values: Vec<Vec<f64>> = rows
            .iter()
            .filter(|r| r.direction == "trace")
            .map(|r| {
                let p = &r.pixel;
                vec![
                    p.topography_m * 1e9,
                    p.peak_force_n * 1e9,
                    p.adhesion_n * 1e9,
                    p.dissipation_j / ELECTRONVOLT_J,
                    p.deformation_m * 1e9,
                    p.dmt_modulus_pa.map_or(f64::NAN, |e| e * 1e-9),
                ]
            })
            .collect();
        return super::image::summary(
            &[
                "height (nm)",
                "peak force (nN)",
                "adhesion (nN)",
                "dissipation (eV)",
                "deformation (nm)",
                "DMT modulus (GPa)",
            ],
            &values,
            rows.len(),
        );
    }
    outln!(
        "{:>10} {:>10} {:>8} {:>12} {:>10} {:>10} {:>12} {:>10} {:>10}",
        "y (nm)",
        "x (nm)",
        "dir",
        "height (nm)",
        "peak (nN)",
        "adh. (nN)",
        "dissip. (eV)",
        "deform (nm)",
        "E* (GPa)"
    );
    for r in &rows {
        let p = &r.pixel;
        outln!(
            "{:>10.2} {:>10.2} {:>8} {:>12.4} {:>10.4} {:>10.4} {:>12.4} {:>10.4} {:>10}",
            r.y_m * 1e9,
            p.x_m * 1e9,
            r.direction,
            p.topography_m * 1e9,
            p.peak_force_n * 1e9,
            p.adhesion_n * 1e9,
            p.dissipation_j / ELECTRONVOLT_J,
            p.deformation_m * 1e9,
            p.dmt_modulus_pa
                .map_or("no fit".into(), |e| format!("{:.4}", e * 1e-9))
        );
    }
    Ok(())
}

/// The Gwyddion channels of a QNM image's `rows` ([`super::image::channels`]).
fn image_channels(
    rows: &[Row],
    shape: (usize, usize),
    size_m: (f64, f64),
) -> Vec<crate::app::report::gwyddion::Channel> {
    let values: Vec<(bool, usize, f64, Vec<f64>)> = rows
        .iter()
        .map(|r| {
            let p = &r.pixel;
            let v = vec![
                p.topography_m,
                p.peak_force_n,
                p.error_n,
                p.adhesion_n,
                p.dissipation_j,
                p.deformation_m,
                p.dmt_modulus_pa.unwrap_or(f64::NAN),
            ];
            (r.direction == "trace", r.line, p.x_m, v)
        })
        .collect();
    let names = [
        ("Topography", "m"),
        ("Peak force", "N"),
        ("Peak force error", "N"),
        ("Adhesion", "N"),
        ("Dissipation", "J"),
        ("Deformation", "m"),
        ("DMT modulus", "Pa"),
    ];
    super::image::channels(&values, shape, size_m, &names)
}

/// Write a whole QNM scan's outputs from its records: `tapsim merge` writes a sharded
/// image's through this, its Gwyddion files among them (from the `image` the parts
/// carry).
pub(super) fn emit_scan<T: serde::Serialize>(
    out: &super::SweepOutput,
    extra: &[std::path::PathBuf],
    (shape, image): ((usize, usize, f64), Option<&part::ImageInfo>),
    records: &[T],
) -> Result<()> {
    super::scan_lines::emit_scan(
        (out, extra),
        ("QNM", image),
        records,
        |rows, path| draw(shape, rows, path),
        |rows, size_m| image_channels(rows, (shape.0, shape.1), size_m),
    )
}

/// The plot of a QNM scan of (lines, pixels) at the peak force setpoint: profiles of
/// one line, heat maps of an image.
fn draw(
    (lines, pixels, setpoint_n): (usize, usize, f64),
    rows: &[Row],
    path: &std::path::Path,
) -> Result<()> {
    super::scan_lines::draw(
        (lines, pixels),
        rows,
        &CHANNELS,
        (
            &format!("off-resonance tapping at {} nN", setpoint_n * 1e9),
            &format!("peak force {} nN", setpoint_n * 1e9),
            "no DMT fit",
        ),
        path,
    )
}

/// The channels plotted: name, label, value.
const CHANNELS: [super::scan_lines::Channel<QnmPixel>; 4] = [
    ("topography", "z piezo height (nm)", |p| {
        Some(p.topography_m * 1e9)
    }),
    ("adhesion", "adhesion (nN)", |p| Some(p.adhesion_n * 1e9)),
    ("dissipation", "dissipation per cycle (eV)", |p| {
        Some(p.dissipation_j / ELECTRONVOLT_J)
    }),
    ("DMT modulus", "DMT modulus fitted (GPa)", |p| {
        p.dmt_modulus_pa.map(|e| e * 1e-9)
    }),
];
