//! Rendering a [`Chart`] with plotters, to PNG and SVG, in one house style, with an
//! embedded font (DejaVu Sans) so no system font configuration is needed.

use super::chart::{Chart, Corner, Scale, Style};
use super::output;
use crate::error::{Error, Result};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// Size of every plot in pixels.
pub const SIZE: (u32, u32) = (960, 720);

/// Colour-blind-safe palette (Okabe–Ito).
const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 0, 0),
    RGBColor(213, 94, 0),
    RGBColor(0, 114, 178),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(240, 228, 66),
];

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are a valid TrueType font shipped by the `dejavu` crate.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// Render `chart` to a PNG file at `path` (written atomically).
pub fn render_png(chart: &Chart, path: &Path) -> Result<()> {
    render_stack_png(std::slice::from_ref(chart), path)
}

/// Render `chart` to an SVG file at `path` (written atomically).
pub fn render_svg(chart: &Chart, path: &Path) -> Result<()> {
    render_stack_svg(std::slice::from_ref(chart), path)
}

/// Draw `charts` one above the other on `root`.
fn draw_stack<DB: DrawingBackend>(
    charts: &[Chart],
    root: &DrawingArea<DB, Shift>,
) -> std::result::Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    for (chart, area) in charts
        .iter()
        .zip(root.split_evenly((charts.len().max(1), 1)))
    {
        draw(chart, &area)?;
    }
    Ok(())
}

fn stack_size(n: usize) -> (u32, u32) {
    if n <= 1 {
        SIZE
    } else {
        (SIZE.0, (SIZE.1 * 2 / 3) * n as u32)
    }
}

/// Drawn into memory and encoded there, then written like any other output: file
/// errors are told as such, and a PNG can go to a device or a FIFO like a CSV.
fn render_stack_png(charts: &[Chart], path: &Path) -> Result<()> {
    use image::ImageEncoder;
    register_font();
    let (width, height) = stack_size(charts.len());
    let mut pixels = vec![0u8; 3 * width as usize * height as usize];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (width, height)).into_drawing_area();
        draw_stack(charts, &root).map_err(|reason| fail(path, reason))?;
        root.present().map_err(|e| fail(path, e.to_string()))?;
    }
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(&pixels, width, height, image::ColorType::Rgb8)
        .map_err(|e| fail(path, format!("PNG encoding failed: {e}")))?;
    output::write_bytes(path, &bytes)
}

fn render_stack_svg(charts: &[Chart], path: &Path) -> Result<()> {
    register_font();
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, stack_size(charts.len())).into_drawing_area();
        draw_stack(charts, &root).map_err(|reason| fail(path, reason))?;
        root.present().map_err(|e| fail(path, e.to_string()))?;
    }
    output::write_bytes(path, text.as_bytes())
}

/// Render `charts` one above the other into `path`, PNG or SVG by its extension.
pub fn render_stack(charts: &[Chart], path: &Path) -> Result<()> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("png") => render_stack_png(charts, path),
        Some("svg") => render_stack_svg(charts, path),
        _ => Err(fail(path, "the plot file must end in .png or .svg".into())),
    }
}

fn fail(path: &Path, reason: String) -> Error {
    Error::Output {
        path: path.to_path_buf(),
        reason,
    }
}

/// Data range of one coordinate over all series, padded; positive-only for log axes.
fn data_range(chart: &Chart, pick: impl Fn(&(f64, f64)) -> f64, scale: Scale) -> (f64, f64) {
    let values = chart
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(&pick))
        .filter(|v| v.is_finite() && (scale == Scale::Linear || *v > 0.0));
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if !lo.is_finite() {
        return if scale == Scale::Log {
            (0.1, 10.0)
        } else {
            (0.0, 1.0)
        };
    }
    match scale {
        Scale::Linear => {
            let pad = if hi > lo { 0.05 * (hi - lo) } else { 0.5 };
            (lo - pad, hi + pad)
        }
        Scale::Log => {
            let pad = if hi > lo { (hi / lo).powf(0.05) } else { 2.0 };
            (lo / pad, hi * pad)
        }
    }
}

fn draw<DB: DrawingBackend>(
    chart: &Chart,
    root: &DrawingArea<DB, Shift>,
) -> std::result::Result<(), String> {
    let xr = chart
        .x
        .range
        .unwrap_or_else(|| data_range(chart, |p| p.0, chart.x.scale));
    let yr = chart
        .y
        .range
        .unwrap_or_else(|| data_range(chart, |p| p.1, chart.y.scale));
    match (chart.x.scale, chart.y.scale) {
        (Scale::Linear, Scale::Linear) => draw_in(chart, root, xr.0..xr.1, yr.0..yr.1),
        (Scale::Log, Scale::Linear) => draw_in(chart, root, (xr.0..xr.1).log_scale(), yr.0..yr.1),
        (Scale::Linear, Scale::Log) => draw_in(chart, root, xr.0..xr.1, (yr.0..yr.1).log_scale()),
        (Scale::Log, Scale::Log) => draw_in(
            chart,
            root,
            (xr.0..xr.1).log_scale(),
            (yr.0..yr.1).log_scale(),
        ),
    }
}

fn draw_in<DB, X, Y>(
    chart: &Chart,
    root: &DrawingArea<DB, Shift>,
    xr: X,
    yr: Y,
) -> std::result::Result<(), String>
where
    DB: DrawingBackend,
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let mut ctx = ChartBuilder::on(root)
        .caption(&chart.title, ("sans-serif", 26))
        .margin(18)
        .margin_right(40)
        .x_label_area_size(60)
        .y_label_area_size(80)
        .build_cartesian_2d(xr, yr)
        .map_err(|e| err(&e))?;
    ctx.configure_mesh()
        .x_desc(chart.x.label.as_str())
        .y_desc(chart.y.label.as_str())
        .axis_desc_style(("sans-serif", 22))
        .label_style(("sans-serif", 17))
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(210, 210, 210))
        .draw()
        .map_err(|e| err(&e))?;
    let (x_lo, x_hi) = (ctx.x_range().start, ctx.x_range().end);
    let (y_lo, y_hi) = (ctx.y_range().start, ctx.y_range().end);
    let clip = Clip::new(
        (x_lo, x_hi, chart.x.scale == Scale::Log),
        (y_lo, y_hi, chart.y.scale == Scale::Log),
    );
    for series in &chart.series {
        let color = PALETTE[series.color % PALETTE.len()];
        let style = color.stroke_width(2);
        match series.style {
            Style::Markers => {
                let inside = series.points.iter().copied().filter(|&p| clip.contains(p));
                let anno = ctx
                    .draw_series(inside.map(|p| Circle::new(p, 5, style)))
                    .map_err(|e| err(&e))?;
                if !series.name.is_empty() {
                    anno.label(series.name.as_str())
                        .legend(move |(x, y)| Circle::new((x + 10, y), 5, style));
                }
            }
            Style::Line | Style::Dashed | Style::Dotted => {
                let (dash, gap) = match series.style {
                    Style::Dashed => (12, 8),
                    _ => (3, 5),
                };
                for (i, run) in clip.runs(&series.points).into_iter().enumerate() {
                    let anno = if series.style == Style::Line {
                        ctx.draw_series(LineSeries::new(run, style))
                    } else {
                        ctx.draw_series(DashedLineSeries::new(run, dash, gap, style))
                    }
                    .map_err(|e| err(&e))?;
                    if i == 0 && !series.name.is_empty() {
                        let solid = series.style == Style::Line;
                        anno.label(series.name.as_str()).legend(move |(x, y)| {
                            let (d, g) = if solid { (24, 0) } else { (dash, gap) };
                            plotters::element::DashedPathElement::new(
                                vec![(x, y), (x + 24, y)],
                                d,
                                g,
                                style,
                            )
                        });
                    }
                }
            }
        }
    }
    for label in &chart.labels {
        ctx.draw_series(std::iter::once(Text::new(
            label.text.clone(),
            (label.x, label.y),
            ("sans-serif", 22).into_font().color(&BLACK),
        )))
        .map_err(|e| err(&e))?;
    }
    ctx.configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(160, 160, 160))
        .label_font(("sans-serif", 17))
        .position(match chart.legend {
            Corner::UpperLeft => SeriesLabelPosition::UpperLeft,
            Corner::UpperRight => SeriesLabelPosition::UpperRight,
            Corner::LowerLeft => SeriesLabelPosition::LowerLeft,
            Corner::LowerRight => SeriesLabelPosition::LowerRight,
        })
        .draw()
        .map_err(|e| err(&e))?;
    Ok(())
}

/// Clipping of polylines to the plotted box (plotters would clamp out-of-range points
/// onto the border, bending straight lines). Works in the axes' own coordinates:
/// log10 of the value on a log axis, so straight lines stay straight.
struct Clip {
    x: (f64, f64, bool),
    y: (f64, f64, bool),
}

impl Clip {
    fn new(x: (f64, f64, bool), y: (f64, f64, bool)) -> Self {
        Self { x, y }
    }

    fn data_to_axes(&self, (x, y): (f64, f64)) -> (f64, f64) {
        let t = |v: f64, log: bool| if log { v.log10() } else { v };
        (t(x, self.x.2), t(y, self.y.2))
    }

    fn axes_to_data(&self, (u, v): (f64, f64)) -> (f64, f64) {
        let t = |w: f64, log: bool| if log { 10f64.powf(w) } else { w };
        (t(u, self.x.2), t(v, self.y.2))
    }

    fn contains(&self, p: (f64, f64)) -> bool {
        let ok = |v: f64, (lo, hi, log): (f64, f64, bool)| {
            v.is_finite() && v >= lo && v <= hi && (!log || v > 0.0)
        };
        ok(p.0, self.x) && ok(p.1, self.y)
    }

    /// The parts of the polyline inside the box, each a run of connected points.
    fn runs(&self, points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
        let (x0, y0) = self.data_to_axes((self.x.0, self.y.0));
        let (x1, y1) = self.data_to_axes((self.x.1, self.y.1));
        let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
        let mut current: Vec<(f64, f64)> = Vec::new();
        for w in points.windows(2) {
            let (a, b) = (self.data_to_axes(w[0]), self.data_to_axes(w[1]));
            let clipped = if [a.0, a.1, b.0, b.1].iter().all(|v| v.is_finite()) {
                liang_barsky(a, b, (x0, x1), (y0, y1))
            } else {
                None
            };
            match clipped {
                Some((p, q)) => {
                    let (p, q) = (self.axes_to_data(p), self.axes_to_data(q));
                    if current.last() != Some(&p) {
                        if !current.is_empty() {
                            runs.push(std::mem::take(&mut current));
                        }
                        current.push(p);
                    }
                    current.push(q);
                }
                None => {
                    if !current.is_empty() {
                        runs.push(std::mem::take(&mut current));
                    }
                }
            }
        }
        if !current.is_empty() {
            runs.push(current);
        }
        runs
    }
}

/// The part of segment a→b inside the box, by the Liang–Barsky algorithm.
fn liang_barsky(
    a: (f64, f64),
    b: (f64, f64),
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-dx, a.0 - x0),
        (dx, x1 - a.0),
        (-dy, a.1 - y0),
        (dy, y1 - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    (t0 <= t1).then(|| {
        let at = |t: f64| (a.0 + t * dx, a.1 + t * dy);
        (at(t0), at(t1))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_keeps_log_lines_straight() {
        let clip = Clip::new((1.0, 100.0, true), (1.0, 100.0, true));
        // y = 1000/x from x = 1 to 1e4 crosses the box from (10, 100) to (100, 10).
        let runs = clip.runs(&[(1.0, 1000.0), (1e4, 0.1)]);
        assert_eq!(runs.len(), 1);
        let (p, q) = (runs[0][0], runs[0][1]);
        assert!((p.0 - 10.0).abs() < 1e-9 && (p.1 - 100.0).abs() < 1e-9);
        assert!((q.0 - 100.0).abs() < 1e-9 && (q.1 - 10.0).abs() < 1e-9);
    }

    #[test]
    fn clipping_splits_runs_that_leave_the_box() {
        let clip = Clip::new((0.0, 1.0, false), (0.0, 1.0, false));
        let runs = clip.runs(&[(0.1, 0.5), (0.5, 2.0), (0.9, 0.5), (0.95, 0.5)]);
        assert_eq!(runs.len(), 2);
    }
}
