//! What a scanned image is written as beyond CSV, JSON and heat maps: Gwyddion's files
//! (every channel, trace and retrace, topography raw and levelled), their metadata, and
//! the summary printed in place of an image's table. Shared by both imaging modes.

use crate::dynamics::setup::significant;
use crate::error::{Error, Result};

/// The image in Gwyddion's formats.
#[derive(Debug, clap::Args)]
pub(super) struct ImageFiles {
    /// Write every channel of the image (trace and retrace: topography raw and
    /// levelled, and the mode's channels) into one Gwyddion file (.gwy), with real x/y
    /// extents, SI units, titles and the run's parameters as metadata; the first row is
    /// the top of the image (the largest y).
    #[arg(long, value_name = "FILE.gwy")]
    gwy: Option<std::path::PathBuf>,
    /// Write each channel as a Gwyddion Simple Field file: FILE.gsf gives FILE_<channel>.gsf
    /// (topography_trace, phase_trace, …).
    #[arg(long, value_name = "FILE.gsf")]
    gsf: Option<std::path::PathBuf>,
}

impl ImageFiles {
    /// Refuse before any work a file of the wrong kind, or whose directory is missing.
    pub(super) fn check(&self) -> Result<()> {
        for (path, ext) in [(&self.gwy, "gwy"), (&self.gsf, "gsf")] {
            if let Some(path) = path {
                if !path
                    .extension()
                    .is_some_and(|e| e.eq_ignore_ascii_case(ext))
                {
                    return Err(Error::NotApplicable(format!(
                        "--{ext} {}: give a .{ext} file",
                        path.display()
                    )));
                }
                super::check_targets([Some(path.as_path())])?;
            }
        }
        Ok(())
    }

    /// The Gwyddion files among `merge --out` paths (by extension), and the others.
    pub(super) fn among(paths: &[std::path::PathBuf]) -> Result<(Self, Vec<std::path::PathBuf>)> {
        let of = |ext: &str| {
            let mut it = paths
                .iter()
                .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case(ext)));
            let first = it.next().cloned();
            match it.next() {
                Some(second) => Err(Error::NotApplicable(format!(
                    "--out {} and {}: one .{ext} file is written",
                    first
                        .as_ref()
                        .map_or(String::new(), |p| p.display().to_string()),
                    second.display()
                ))),
                None => Ok(first),
            }
        };
        let files = ImageFiles {
            gwy: of("gwy")?,
            gsf: of("gsf")?,
        };
        files.check()?;
        let rest = paths
            .iter()
            .filter(|p| {
                !p.extension()
                    .is_some_and(|e| e.eq_ignore_ascii_case("gwy") || e.eq_ignore_ascii_case("gsf"))
            })
            .cloned()
            .collect();
        Ok((files, rest))
    }

    /// The refusal of Gwyddion files for parts that carry no image (a map's, or a scan's
    /// written by a tapsim before images had them).
    pub(super) fn no_image(&self) -> Error {
        Error::NotApplicable(
            "a .gwy or .gsf file is a scanned image's: these parts carry none (a map's or \
             batch's, or a scan's from an older tapsim: scan again)"
                .into(),
        )
    }

    /// Whether any was asked for.
    pub(super) fn any(&self) -> bool {
        self.gwy.is_some() || self.gsf.is_some()
    }

    /// Write `channels` (with `meta`) where asked.
    pub(super) fn write(
        &self,
        channels: &[crate::app::report::gwyddion::Channel],
        meta: &[(String, String)],
    ) -> Result<()> {
        use crate::app::report::{gwyddion, output};
        if let Some(path) = &self.gwy {
            output::write_bytes(path, &gwyddion::gwy(channels, meta))?;
        }
        if let Some(path) = &self.gsf {
            let stem = path.with_extension("");
            for c in channels {
                let slug: String = c
                    .title
                    .to_lowercase()
                    .chars()
                    .map(|ch| if ch.is_ascii_alphanumeric() { ch } else { '_' })
                    .collect::<String>()
                    .split('_')
                    .filter(|w| !w.is_empty())
                    .collect::<Vec<_>>()
                    .join("_");
                let file = format!("{}_{slug}.gsf", stem.display());
                output::write_bytes(std::path::Path::new(&file), &gwyddion::gsf(c, meta))?;
            }
        }
        Ok(())
    }
}

/// The channels of an image whose records `rows` give each pixel's (trace?, line, x in
/// m) and values, named and in units by `names` ((title, unit) per value): trace and
/// retrace, each a grid with the top line first and x ascending, and a topography
/// (the first value) levelled too.
pub(super) fn channels(
    rows: &[(bool, usize, f64, Vec<f64>)],
    (lines, pixels): (usize, usize),
    size_m: (f64, f64),
    names: &[(&str, &str)],
) -> Vec<crate::app::report::gwyddion::Channel> {
    use crate::app::report::gwyddion::{Channel, plane_levelled};
    let mut out = Vec::new();
    for (trace, direction) in [(true, "trace"), (false, "retrace")] {
        let mine: Vec<&(bool, usize, f64, Vec<f64>)> =
            rows.iter().filter(|r| r.0 == trace).collect();
        if mine.len() != lines * pixels {
            continue;
        }
        // Lines top first (largest y), pixels by x.
        let mut grid: Vec<&(bool, usize, f64, Vec<f64>)> = mine;
        grid.sort_by(|a, b| b.1.cmp(&a.1).then(a.2.total_cmp(&b.2)));
        for (k, (title, unit)) in names.iter().enumerate() {
            let values: Vec<f64> = grid.iter().map(|r| r.3[k]).collect();
            let levelled = (k == 0).then(|| plane_levelled(&values, pixels));
            out.push(Channel {
                title: format!("{title} ({direction})"),
                unit: unit.to_string(),
                xres: pixels,
                yres: lines,
                size_m,
                values,
            });
            if let Some(values) = levelled {
                out.push(Channel {
                    title: format!("{title} levelled ({direction})"),
                    unit: unit.to_string(),
                    xres: pixels,
                    yres: lines,
                    size_m,
                    values,
                });
            }
        }
    }
    out
}

/// An image's summary in place of its table: each channel's least, mean and largest
/// over the trace (`values`: a row of channel values per trace pixel, named by
/// `names`), and where the `records` pixel records are.
pub(super) fn summary(names: &[&str], values: &[Vec<f64>], records: usize) -> Result<()> {
    outln!(
        "{:>26} {:>14} {:>14} {:>14}",
        "over the trace",
        "least",
        "mean",
        "largest"
    );
    for (k, name) in names.iter().enumerate() {
        let column: Vec<f64> = values
            .iter()
            .map(|v| v[k])
            .filter(|v| v.is_finite())
            .collect();
        if column.is_empty() {
            outln!("{name:>26} {:>14}", "none");
            continue;
        }
        let (lo, hi) = column
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let mean = column.iter().sum::<f64>() / column.len() as f64;
        outln!(
            "{name:>26} {:>14} {:>14} {:>14}",
            significant(lo),
            significant(mean),
            significant(hi)
        );
    }
    outln!("{records} pixel records: --csv FILE or --json for every one, --plot for heat maps");
    Ok(())
}

/// The run's parameters as an image file's metadata.
pub(super) fn meta(
    mode: &str,
    setup: &crate::dynamics::setup::TapSetup,
    sample: &Option<std::path::PathBuf>,
    (lines, pixels, line_rate): (usize, usize, f64),
    setpoint: String,
    feedback: &str,
) -> Vec<(String, String)> {
    let c = &setup.cantilever;
    vec![
        (
            "Software".into(),
            format!("tapsim {}", env!("CARGO_PKG_VERSION")),
        ),
        ("Mode".into(), mode.into()),
        ("Setpoint".into(), setpoint),
        ("Feedback".into(), feedback.into()),
        ("Law".into(), setup.law.to_string()),
        (
            "Sample".into(),
            sample
                .as_ref()
                .map_or("built-in two-polymer blend".into(), |p| {
                    p.display().to_string()
                }),
        ),
        (
            "Cantilever".into(),
            format!(
                "{} N/m, {} kHz, Q {}",
                c.stiffness_n_m,
                c.resonance_hz * 1e-3,
                c.quality
            ),
        ),
        ("Lines".into(), lines.to_string()),
        ("Pixels".into(), pixels.to_string()),
        ("Line rate".into(), format!("{line_rate} lines/s")),
    ]
}
