//! What the scans of the modes that are not tapping (`scan --mode peakforce`, `scan
//! --mode fm`) share: the lines of an image scanned in parallel, each engaged then traced
//! and retraced, their pixels tagged with direction and line, and the plots of a
//! channel table — profiles along one line, heat maps of an image.

use super::progress::Progress;
use crate::app::report::chart::{Axis, Chart, Corner, Series, Style};
use crate::app::report::heatmap::HeatMap;
use crate::error::Result;
use crate::instrument::scan::{Region, mirrored};

/// A pixel with its direction and line.
#[derive(serde::Serialize, serde::Deserialize)]
pub(super) struct Row<P> {
    pub(super) direction: String,
    /// The line's index (0 first) and its position across the sample, in m.
    pub(super) line: usize,
    pub(super) y_m: f64,
    #[serde(flatten)]
    pub(super) pixel: P,
}

/// A pixel that knows where along the line it lies.
pub(super) trait Located {
    /// Its centre along the line, m.
    fn x_m(&self) -> f64;
    /// The same, to move it.
    fn x_m_mut(&mut self) -> &mut f64;
}

/// The lines `mine` of `lines` (each y and its regions), each scanned on its own on
/// `threads` threads: `engage` gives a scanner engaged over the line's regions, `scan`
/// runs it over regions (told each pixel), trace then, if `retrace`, the line mirrored
/// back (its pixels' x put back on the line). `bar` counts an engagement and each pixel.
/// The rows of each line, in the order of `mine`.
pub(super) fn trace_and_retrace<S, P: Located + Send>(
    (mine, lines, length_m): (&[usize], &Lines, f64),
    (threads, retrace, bar): (usize, bool, &Progress),
    engage: impl Fn(&[Region]) -> Result<S> + Sync,
    scan: impl Fn(&mut S, &[Region], &dyn Fn()) -> Result<Vec<P>> + Sync,
) -> Result<Vec<Vec<Row<P>>>> {
    use rayon::prelude::*;
    crate::analysis::sweep::thread_pool(threads)?.install(|| {
        mine.par_iter()
            .map(|&j| {
                let (y_m, regions) = &lines[j];
                crate::interrupt::check()?;
                let mut s = engage(regions)?;
                bar.inc(1);
                let tag = |direction: &'static str, pixels: Vec<P>| {
                    pixels.into_iter().map(move |pixel| Row {
                        direction: direction.into(),
                        line: j,
                        y_m: *y_m,
                        pixel,
                    })
                };
                let trace = scan(&mut s, regions, &|| bar.inc(1))?;
                let mut rows: Vec<Row<P>> = tag("trace", trace).collect();
                if retrace {
                    let back = mirrored(regions, length_m);
                    let mut pixels = scan(&mut s, &back, &|| bar.inc(1))?;
                    for p in &mut pixels {
                        *p.x_m_mut() = length_m - p.x_m();
                    }
                    rows.extend(tag("retrace", pixels));
                }
                Ok(rows)
            })
            .collect::<Result<Vec<_>>>()
    })
}

/// The lines of a scan: each line's y (m) and the regions it crosses.
pub(super) type Lines = [(f64, Vec<Region>)];

/// A channel a plot shows: its name, its axis label and its value in a pixel (none:
/// not there).
pub(super) type Channel<P> = (&'static str, &'static str, fn(&P) -> Option<f64>);

/// One line's `channels` along x, trace and retrace.
pub(super) fn profiles<P>(rows: &[Row<P>], channels: &[Channel<P>], caption: &str) -> Vec<Chart>
where
    P: Located,
{
    channels
        .iter()
        .map(|&(name, label, pick)| {
            let series: Vec<Series> = [("trace", Style::Line, 1), ("retrace", Style::Dashed, 2)]
                .into_iter()
                .filter_map(|(dir, style, color)| {
                    let points: Vec<(f64, f64)> = rows
                        .iter()
                        .filter(|r| r.direction == dir)
                        .filter_map(|r| Some((r.pixel.x_m() * 1e9, pick(&r.pixel)?)))
                        .collect();
                    (!points.is_empty()).then(|| Series::new(dir, points, style, color))
                })
                .collect();
            Chart {
                name: name.replace(' ', "_"),
                title: format!("{name}, {caption}"),
                x: Axis::linear("position along the line x (nm)", "x_nm"),
                y: Axis::linear(label, name),
                legend: Corner::quietest(&series),
                series,
                labels: vec![],
            }
        })
        .collect()
}

/// Heat maps of the trace's `channels` over an image of `lines` lines of `pixels`
/// pixels (`missing` names what a pixel without a value lacks).
pub(super) fn images<P>(
    rows: &[Row<P>],
    (lines, pixels): (usize, usize),
    channels: &[Channel<P>],
    (caption, missing): (&str, &str),
) -> Vec<HeatMap>
where
    P: Located,
{
    let trace: Vec<&Row<P>> = rows.iter().filter(|r| r.direction == "trace").collect();
    let x: Vec<f64> = trace
        .iter()
        .take(pixels)
        .map(|r| r.pixel.x_m() * 1e9)
        .collect();
    let y: Vec<f64> = trace.iter().step_by(pixels).map(|r| r.y_m * 1e9).collect();
    channels
        .iter()
        .map(|&(name, label, pick)| {
            HeatMap::image(
                (format!("{name}, {caption} (trace)"), label, missing),
                (x.clone(), y.clone()),
                trace
                    .chunks(pixels)
                    .take(lines)
                    .map(|line| line.iter().map(|r| pick(&r.pixel)).collect())
                    .collect(),
            )
        })
        .collect()
}

/// The plot of a scan of (lines, pixels): profiles of one line (`line_caption`), heat
/// maps of an image (`image_caption`, `missing` for pixels without a value).
pub(super) fn draw<P: Located>(
    (lines, pixels): (usize, usize),
    rows: &[Row<P>],
    channels: &[Channel<P>],
    (line_caption, image_caption, missing): (&str, &str, &str),
    path: &std::path::Path,
) -> Result<()> {
    if lines > 1 {
        crate::app::report::plot::render_side_by_side(
            &images(rows, (lines, pixels), channels, (image_caption, missing)),
            path,
        )
    } else {
        crate::app::report::plot::render_stack(&profiles(rows, channels, line_caption), path)
    }
}

/// Write a whole scan's outputs from its records (`tapsim merge` writes a sharded
/// image's through this): the CSV, JSON and plot (`draw`) as `out` and `extra` ask, and
/// the Gwyddion files among `extra` from the channels `channels` gives for the `image`
/// the parts carry (refused without one). `kind` names the rows in a message.
pub(super) fn emit_scan<T: serde::Serialize, P: serde::de::DeserializeOwned>(
    (out, extra): (&super::SweepOutput, &[std::path::PathBuf]),
    (kind, image): (&str, Option<&crate::app::report::part::ImageInfo>),
    records: &[T],
    draw: impl Fn(&[Row<P>], &std::path::Path) -> Result<()>,
    channels: impl Fn(&[Row<P>], (f64, f64)) -> Vec<crate::app::report::gwyddion::Channel>,
) -> Result<()> {
    let rows: Vec<Row<P>> = crate::app::report::records::typed(records, kind)?;
    let (files, extra) = super::image::ImageFiles::among(extra)?;
    if files.any() && image.is_none() {
        return Err(files.no_image());
    }
    out.emit(
        ("scan", &extra),
        records,
        || crate::app::report::records::columns_json(records),
        Some(&|path| draw(&rows, path)),
    )?;
    match image {
        Some(image) if files.any() => files.write(&channels(&rows, image.size_m), &image.meta),
        _ => Ok(()),
    }
}
