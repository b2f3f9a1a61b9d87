//! Rendering a [`Chart`] with plotters, to PNG and SVG, in one house style, with an
//! embedded font (DejaVu Sans) so no system font configuration is needed.

use super::chart::{Chart, Corner, Scale, Style};
use super::heatmap::{Cell, HeatMap, viridis};
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
#[doc(hidden)]
pub const PALETTE: [RGBColor; 8] = [
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

impl Chart {
    /// Write `<dir>/<name>.csv`, `.png` and `.svg`; returns the paths written.
    pub fn write_all(&self, dir: &Path) -> Result<Vec<std::path::PathBuf>> {
        let csv_path = dir.join(format!("{}.csv", self.name));
        output::write_bytes(&csv_path, &self.to_csv()?)?;
        let png = dir.join(format!("{}.png", self.name));
        let svg = dir.join(format!("{}.svg", self.name));
        render_png(self, &png)?;
        render_svg(self, &svg)?;
        Ok(vec![csv_path, png, svg])
    }
}

/// Render `chart` to a PNG file at `path` (written atomically).
pub fn render_png(chart: &Chart, path: &Path) -> Result<()> {
    render_stack_png(std::slice::from_ref(chart), path, Arrange::Stack)
}

/// Render `chart` to an SVG file at `path` (written atomically).
pub fn render_svg(chart: &Chart, path: &Path) -> Result<()> {
    render_stack_svg(std::slice::from_ref(chart), path, Arrange::Stack)
}

/// Where a panel was drawn: its plotting area (backend pixels, x and y ranges) and how
/// much of its data its legend covers (0: none).
#[derive(Debug, Clone, PartialEq)]
#[doc(hidden)]
pub struct Drawn {
    pub area: (std::ops::Range<i32>, std::ops::Range<i32>),
    pub legend_covers: usize,
}

/// One panel of a figure: a chart or a heat map.
#[doc(hidden)]
pub trait Panel {
    /// Draw into `area`; where the plotting area went.
    fn draw_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
    ) -> std::result::Result<Drawn, String>;
}

impl Panel for Chart {
    fn draw_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
    ) -> std::result::Result<Drawn, String> {
        draw(self, area)
    }
}

impl Panel for HeatMap {
    fn draw_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
    ) -> std::result::Result<Drawn, String> {
        draw_heatmap(self, area)
    }
}

/// Draw `panels` on `root`: one above the other up to three, else row by row in two
/// columns ([`grid`]).
fn draw_stack<DB: DrawingBackend, P: Panel>(
    panels: &[P],
    root: &DrawingArea<DB, Shift>,
    arrange: Arrange,
) -> std::result::Result<Vec<Drawn>, String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    panels
        .iter()
        .zip(root.split_evenly(grid(panels.len(), arrange)))
        .map(|(panel, area)| panel.draw_panel(&area))
        .collect()
}

/// Rows and columns of a figure of `n` charts.
fn grid(n: usize, arrange: Arrange) -> (usize, usize) {
    if arrange == Arrange::SideBySide {
        (1, n.max(1))
    } else if n <= 3 {
        (n.max(1), 1)
    } else {
        (n.div_ceil(2), 2)
    }
}

fn stack_size(n: usize, arrange: Arrange) -> (u32, u32) {
    let (rows, columns) = grid(n, arrange);
    if n <= 1 {
        SIZE
    } else if arrange == Arrange::SideBySide {
        (SIZE.0 * columns as u32 * 3 / 4, SIZE.1 * 3 / 4)
    } else {
        (SIZE.0 * columns as u32, (SIZE.1 * 2 / 3) * rows as u32)
    }
}

/// Drawn into memory and encoded there, then written like any other output: file
/// errors are told as such, and a PNG can go to a device or a FIFO like a CSV. The
/// pixels are the SVG's, anti-aliased ([`raster`]).
fn render_stack_png<P: Panel>(panels: &[P], path: &Path, arrange: Arrange) -> Result<()> {
    use image::ImageEncoder;
    let (pixels, (width, height), _) =
        raster(panels, arrange, true).map_err(|reason| fail(path, reason))?;
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(&pixels, width, height, image::ColorType::Rgb8)
        .map_err(|e| fail(path, format!("PNG encoding failed: {e}")))?;
    output::write_bytes(path, &bytes)
}

/// RGB pixels, their width and height, and where each panel went.
#[doc(hidden)]
pub type Raster = (Vec<u8>, (u32, u32), Vec<Drawn>);

/// How many data points the legend of `chart`, drawn alone, covers (for the tests of
/// the charts other modules build).
#[doc(hidden)]
pub fn legend_covers(chart: &Chart) -> usize {
    let (_, drawn) =
        svg_text(std::slice::from_ref(chart), Arrange::Stack).expect("the chart draws");
    drawn[0].legend_covers
}

/// `charts` drawn into RGB pixels as the PNGs are, from the figure's SVG, but without
/// anti-aliasing (`shape-rendering: crispEdges`), so that every pixel of a series is
/// exactly its colour (what the layout tests count). Not generic, so that the tests
/// link the library's one compiled copy of the drawing.
#[doc(hidden)]
pub fn rasterize(charts: &[Chart], arrange: Arrange) -> std::result::Result<Raster, String> {
    raster(charts, arrange, false)
}

/// Heat maps drawn as [`rasterize`] draws charts.
#[doc(hidden)]
pub fn rasterize_maps(maps: &[HeatMap], arrange: Arrange) -> std::result::Result<Raster, String> {
    raster(maps, arrange, false)
}

/// `charts` as anti-aliased RGB pixels, as their PNG has them ([`raster`]).
#[doc(hidden)]
pub fn rasterize_smooth(charts: &[Chart], arrange: Arrange) -> std::result::Result<Raster, String> {
    raster(charts, arrange, true)
}

/// The figure's SVG text and where each panel went ([`draw_stack`] into plotters' SVG
/// backend).
fn svg_text<P: Panel>(
    panels: &[P],
    arrange: Arrange,
) -> std::result::Result<(String, Vec<Drawn>), String> {
    register_font();
    let mut text = String::new();
    let drawn = {
        let root = SVGBackend::with_string(&mut text, stack_size(panels.len(), arrange))
            .into_drawing_area();
        let drawn = draw_stack(panels, &root, arrange)?;
        root.present().map_err(|e| e.to_string())?;
        drawn
    };
    Ok((text, drawn))
}

/// `panels` as RGB pixels: the figure's SVG drawn by resvg on white, anti-aliased if
/// `smooth`, its text in the embedded DejaVu Sans (plotters writes `sans-serif`).
fn raster<P: Panel>(
    panels: &[P],
    arrange: Arrange,
    smooth: bool,
) -> std::result::Result<Raster, String> {
    use resvg::{tiny_skia, usvg};
    // The embedded font's database, built once for every figure of the run.
    static FONTS: std::sync::OnceLock<std::sync::Arc<usvg::fontdb::Database>> =
        std::sync::OnceLock::new();
    let fonts = FONTS.get_or_init(|| {
        let mut fonts = usvg::fontdb::Database::new();
        fonts.load_font_data(dejavu::sans::regular().to_vec());
        fonts.set_sans_serif_family("DejaVu Sans");
        std::sync::Arc::new(fonts)
    });
    let (svg, drawn) = svg_text(panels, arrange)?;
    let mut options = usvg::Options {
        font_family: "DejaVu Sans".into(),
        fontdb: fonts.clone(),
        ..Default::default()
    };
    if !smooth {
        options.shape_rendering = usvg::ShapeRendering::CrispEdges;
        options.text_rendering = usvg::TextRendering::OptimizeSpeed;
    }
    let tree = usvg::Tree::from_str(&svg, &options).map_err(|e| e.to_string())?;
    let (width, height) = stack_size(panels.len(), arrange);
    let mut pixmap = tiny_skia::Pixmap::new(width, height).ok_or("an empty figure")?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        tiny_skia::Transform::identity(),
        &mut pixmap.as_mut(),
    );
    // Opaque (drawn on white): the premultiplied RGBA is the RGB.
    let rgb = pixmap
        .data()
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    Ok((rgb, (width, height), drawn))
}

fn render_stack_svg<P: Panel>(panels: &[P], path: &Path, arrange: Arrange) -> Result<()> {
    let (text, _) = svg_text(panels, arrange).map_err(|reason| fail(path, reason))?;
    output::write_bytes(path, text.as_bytes())
}

/// Render `charts` one above the other into `path`, PNG or SVG by its extension.
pub fn render_stack(charts: &[Chart], path: &Path) -> Result<()> {
    render(charts, path, Arrange::Stack)
}

/// Render heat maps one above the other into `path`, PNG or SVG by its extension.
pub fn render_heatmaps(maps: &[HeatMap], path: &Path) -> Result<()> {
    render(maps, path, Arrange::Stack)
}

/// Render heat maps side by side into `path` (an image's channels), PNG or SVG by its
/// extension.
pub fn render_side_by_side(maps: &[HeatMap], path: &Path) -> Result<()> {
    render(maps, path, Arrange::SideBySide)
}

/// How the panels of a figure are laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[doc(hidden)]
pub enum Arrange {
    /// One above the other up to three, else row by row in two columns.
    Stack,
    /// In one row.
    SideBySide,
}

/// `panels` into `path`, PNG or SVG by its extension.
fn render<P: Panel>(panels: &[P], path: &Path, arrange: Arrange) -> Result<()> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("png") => render_stack_png(panels, path, arrange),
        Some("svg") => render_stack_svg(panels, path, arrange),
        _ => Err(fail(path, "the plot file must end in .png or .svg".into())),
    }
}

/// Ticks of a log axis over [lo, hi]: 1, 2 and 5 times each power of ten inside, or
/// 1, 2, 3 and 5 times, or every integer multiple, the first that gives four or more.
#[doc(hidden)]
pub fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let within = |multiples: &[f64]| -> Vec<f64> {
        let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        (first..=last)
            .flat_map(|d| {
                // (3/10, not 3·0.1: the tick is the decimal number.)
                multiples.iter().map(move |m| {
                    if d < 0 {
                        m / 10f64.powi(-d)
                    } else {
                        m * 10f64.powi(d)
                    }
                })
            })
            .filter(|v| (lo..=hi).contains(v))
            .collect()
    };
    let mut ticks = Vec::new();
    for multiples in [
        &[1.0, 2.0, 5.0][..],
        &[1.0, 2.0, 3.0, 5.0],
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
    ] {
        ticks = within(multiples);
        if ticks.len() >= 4 {
            break;
        }
    }
    ticks
}

/// One heat map: the cells on log axes (a parameter grid) or linear ones (an image), and
/// beside them the colour bar with a key to the grey (the law does not apply) and the
/// marked (not period-1) cells, where there is such a key ([`HeatMap::empty_label`]).
fn draw_heatmap<DB: DrawingBackend>(
    map: &HeatMap,
    area: &DrawingArea<DB, Shift>,
) -> std::result::Result<Drawn, String> {
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let (width, _) = area.dim_in_pixel();
    let (main, side) = area.split_horizontally(width as i32 * 4 / 5);
    let (xe, ye) = map.cell_edges();
    if xe.len() < 2 || ye.len() < 2 {
        return Err("a heat map needs at least one cell".into());
    }
    let (lo, hi) = map.value_range().unwrap_or((0.0, 1.0));
    let span = if hi > lo { hi - lo } else { 1.0 };
    let colour = |v: f64| {
        let (r, g, b) = viridis((v - lo) / span);
        RGBColor(r, g, b)
    };
    let grey = RGBColor(225, 225, 225);
    let (x_range, y_range) = (xe[0]..xe[xe.len() - 1], ye[0]..ye[ye.len() - 1]);
    let cells: (&[f64], &[f64], &dyn Fn(f64) -> RGBColor, RGBColor) = (&xe, &ye, &colour, grey);
    let plotted = if map.log_axes {
        let x_ticks = log_ticks(x_range.start, x_range.end);
        let y_ticks = log_ticks(y_range.start, y_range.end);
        draw_cells(
            map,
            &main,
            (
                x_range.log_scale().with_key_points(x_ticks),
                y_range.log_scale().with_key_points(y_ticks),
            ),
            Scale::Log,
            cells,
        )?
    } else {
        draw_cells(map, &main, (x_range, y_range), Scale::Linear, cells)?
    };
    // The colour bar, level with the plotting area, and the key below it.
    let top = plotted.1.start - area.get_base_pixel().1;
    let bottom = plotted.1.end - area.get_base_pixel().1;
    let (_, side_height) = side.dim_in_pixel();
    let mut bar = ChartBuilder::on(&side)
        .margin_top(top.max(0) as u32)
        .margin_bottom((side_height as i32 - bottom).max(0) as u32)
        .margin_right(10)
        .y_label_area_size(90)
        .build_cartesian_2d(0.0..1.0, lo..lo + span)
        .map_err(|e| err(&e))?;
    let plain = |v: &f64| tick_label(*v, Scale::Linear);
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_label_formatter(&plain)
        .y_desc(map.value_label.as_str())
        .axis_desc_style(("sans-serif", 20))
        .label_style(("sans-serif", 17))
        .draw()
        .map_err(|e| err(&e))?;
    let steps = 100;
    bar.draw_series((0..steps).map(|k| {
        let (a, b) = (k as f64 / steps as f64, (k + 1) as f64 / steps as f64);
        Rectangle::new(
            [(0.0, lo + a * span), (1.0, lo + b * span)],
            colour(lo + 0.5 * (a + b) * span).filled(),
        )
    }))
    .map_err(|e| err(&e))?;
    if map.empty_label.is_empty() {
        return Ok(Drawn {
            area: plotted,
            legend_covers: 0,
        });
    }
    // The key names only what the map shows.
    let cells = map.cells.iter().flatten();
    let (mut marked, mut grazing, mut empty) = (false, false, false);
    for c in cells {
        match c {
            Cell::Value {
                period_one,
                grazing: g,
                ..
            } => {
                marked |= !period_one;
                grazing |= *g;
            }
            Cell::NotApplicable => empty = true,
        }
    }
    let key = ("sans-serif", 16).into_font().color(&BLACK);
    let mut dy = 0;
    let mut at = || {
        let here = (10, bottom + 14 + dy);
        dy += 24;
        here
    };
    if marked {
        let p = at();
        side.draw(&Circle::new((p.0, p.1 + 8), 6, BLACK.stroke_width(2)))
            .map_err(|e| err(&e))?;
        side.draw(&Text::new("not period-1", (p.0 + 14, p.1), key.clone()))
            .map_err(|e| err(&e))?;
    }
    if grazing {
        let p = at();
        side.draw(&Circle::new((p.0, p.1 + 8), 3, BLACK.filled()))
            .map_err(|e| err(&e))?;
        side.draw(&Text::new("grazes a switch", (p.0 + 14, p.1), key.clone()))
            .map_err(|e| err(&e))?;
    }
    if empty {
        let p = at();
        side.draw(&Rectangle::new([p, (p.0 + 12, p.1 + 12)], grey.filled()))
            .map_err(|e| err(&e))?;
        side.draw(&Text::new(map.empty_label.as_str(), (p.0 + 18, p.1), key))
            .map_err(|e| err(&e))?;
    }
    Ok(Drawn {
        area: plotted,
        legend_covers: 0,
    })
}

/// A heat map's axes and cells on `main` (`cells`: the edges along x and y, the colour
/// of a value, the grey of an empty cell); where the plotting area went.
fn draw_cells<DB, X, Y>(
    map: &HeatMap,
    main: &DrawingArea<DB, Shift>,
    (x, y): (X, Y),
    scale: Scale,
    (xe, ye, colour, grey): (&[f64], &[f64], &dyn Fn(f64) -> RGBColor, RGBColor),
) -> std::result::Result<(std::ops::Range<i32>, std::ops::Range<i32>), String>
where
    DB: DrawingBackend,
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let mut ctx = ChartBuilder::on(main)
        .caption(&map.title, ("sans-serif", 26))
        .margin(18)
        .x_label_area_size(60)
        .y_label_area_size(80)
        .build_cartesian_2d(x, y)
        .map_err(|e| err(&e))?;
    let label = |v: &f64| tick_label(*v, scale);
    ctx.configure_mesh()
        .disable_mesh()
        .x_label_formatter(&label)
        .y_label_formatter(&label)
        .x_desc(map.x_label.as_str())
        .y_desc(map.y_label.as_str())
        .axis_desc_style(("sans-serif", 22))
        .label_style(("sans-serif", 17))
        .draw()
        .map_err(|e| err(&e))?;
    for (j, row) in map.cells.iter().enumerate() {
        for (i, cell) in row.iter().enumerate() {
            let corners = [(xe[i], ye[j]), (xe[i + 1], ye[j + 1])];
            let fill = match *cell {
                Cell::Value { value, .. } => colour(value),
                Cell::NotApplicable => grey,
            };
            ctx.draw_series(std::iter::once(Rectangle::new(corners, fill.filled())))
                .map_err(|e| err(&e))?;
            let centre = (map.x[i], map.y[j]);
            if let Cell::Value {
                period_one: false, ..
            } = cell
            {
                ctx.draw_series([
                    Circle::new(centre, 6, WHITE.filled()),
                    Circle::new(centre, 6, BLACK.stroke_width(2)),
                ])
                .map_err(|e| err(&e))?;
            }
            if let Cell::Value { grazing: true, .. } = cell {
                ctx.draw_series([Circle::new(centre, 3, BLACK.filled())])
                    .map_err(|e| err(&e))?;
            }
        }
    }
    Ok(ctx.plotting_area().get_pixel_range())
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
            // A spread below 1e-6 of the values is below what the numbers resolve (a
            // quantity constant along the curve, up to round-off): not zoomed into.
            let floor = 1e-6 * lo.abs().max(hi.abs());
            if hi - lo > floor {
                let pad = 0.05 * (hi - lo);
                (lo - pad, hi + pad)
            } else {
                let mid = 0.5 * (lo + hi);
                let half = if mid == 0.0 { 0.5 } else { 0.05 * mid.abs() };
                (mid - half, mid + half)
            }
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
) -> std::result::Result<Drawn, String> {
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
) -> std::result::Result<Drawn, String>
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
    // A tick at zero reached by adding steps reads as round-off (-5.551e-17): zero.
    let snap = |v: f64, (lo, hi): (f64, f64), scale: Scale| {
        if scale == Scale::Linear && v.abs() < 1e-9 * (hi - lo).abs() {
            0.0
        } else {
            v
        }
    };
    let (x_span, y_span) = (
        (ctx.x_range().start, ctx.x_range().end),
        (ctx.y_range().start, ctx.y_range().end),
    );
    let fx = |v: &f64| tick_label(snap(*v, x_span, chart.x.scale), chart.x.scale);
    let fy = |v: &f64| tick_label(snap(*v, y_span, chart.y.scale), chart.y.scale);
    ctx.configure_mesh()
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
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
        // A marker style: each point inside the axes drawn by `$at`, the legend entry
        // (for a named series) by `$legend`.
        macro_rules! marks {
            ($at:expr, $legend:expr) => {{
                let inside = series.points.iter().copied().filter(|&p| clip.contains(p));
                let anno = ctx.draw_series(inside.map($at)).map_err(|e| err(&e))?;
                if !series.name.is_empty() {
                    anno.label(series.name.as_str()).legend($legend);
                }
            }};
        }
        match series.style {
            Style::Markers => marks!(|p| Circle::new(p, 5, style), move |(x, y)| Circle::new(
                (x + 10, y),
                5,
                style
            )),
            Style::Squares => marks!(
                move |p| EmptyElement::at(p) + Rectangle::new([(-7, -7), (7, 7)], style),
                move |(x, y)| Rectangle::new([(x + 3, y - 7), (x + 17, y + 7)], style)
            ),
            Style::Crosses => marks!(|p| Cross::new(p, 5, style), move |(x, y)| Cross::new(
                (x + 10, y),
                5,
                style
            )),
            Style::Dots => {
                let filled = color.filled();
                marks!(|p| Circle::new(p, 2, filled), move |(x, y)| Circle::new(
                    (x + 10, y),
                    4,
                    filled
                ))
            }
            Style::Triangles => {
                let filled = color.filled();
                marks!(|p| TriangleMarker::new(p, 7, filled), move |(x, y)| {
                    TriangleMarker::new((x + 10, y), 7, filled)
                })
            }
            Style::Line | Style::Dashed | Style::Dotted => {
                let (dash, gap) = match series.style {
                    Style::Dashed => (12, 8),
                    _ => (3, 5),
                };
                // A named series with no points is a legend entry alone (a curve whose
                // every point is drawn as a marker).
                let mut runs = clip.runs(&series.points);
                if series.points.is_empty() && !series.name.is_empty() {
                    runs.push(Vec::new());
                }
                for (i, run) in runs.into_iter().enumerate() {
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
    let mut legend_covers = 0;
    if chart.legend != Corner::Hidden {
        let legend = place_legend(&ctx, chart, &clip)?;
        ctx.configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(160, 160, 160))
            .label_font(("sans-serif", LEGEND_FONT))
            .position(SeriesLabelPosition::Coordinate(legend.0, legend.1))
            .draw()
            .map_err(|e| err(&e))?;
        legend_covers = legend.2;
    }
    let area = ctx.plotting_area().get_pixel_range();
    Ok(Drawn {
        area,
        legend_covers,
    })
}

/// A tick label: decades of a log axis as 0.1, 1, 10, then 10², 10³, … (10⁻², …);
/// anything else with up to six decimals, trailing zeros dropped ("140", "0.25"), or
/// far from 1 as a mantissa and exponent ("2.5e-18").
#[doc(hidden)]
pub fn tick_label(v: f64, scale: Scale) -> String {
    if scale == Scale::Log && v > 0.0 {
        let k = v.log10().round();
        if (v.log10() - k).abs() < 1e-9 && !(-1.0..=1.0).contains(&k) {
            const DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
            let exponent: String = (k.abs() as i64)
                .to_string()
                .chars()
                .map(|c| DIGITS[c.to_digit(10).unwrap_or(0) as usize])
                .collect();
            return format!("10{}{exponent}", if k < 0.0 { "⁻" } else { "" });
        }
    }
    if v != 0.0 && !(1e-3..1e7).contains(&v.abs()) {
        // Far from 1: a mantissa with its exponent ("2.5e-18").
        let text = format!("{v:.4e}");
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        return format!("{mantissa}e{exponent}");
    }
    let text = format!("{v:.6}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".into()
    } else {
        text.into()
    }
}

/// Font size of legend entries.
const LEGEND_FONT: u32 = 17;

/// Where the legend goes, in the plotting area's pixels, and how many markers and line
/// segments of the data its box covers: of the positions along the plot's edges (the
/// chart's preferred corner first, then the other corners, then the middles of the
/// edges), the first that covers nothing, else the one that covers least. The box is
/// measured as plotters will draw it (the same text layout, a 30-pixel key, 10-pixel
/// margins).
fn place_legend<DB, X, Y>(
    ctx: &ChartContext<DB, Cartesian2d<X, Y>>,
    chart: &Chart,
    clip: &Clip,
) -> std::result::Result<(i32, i32, usize), String>
where
    DB: DrawingBackend,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let style: TextStyle = ("sans-serif", LEGEND_FONT).into_font().into();
    let mut text = MultiLineText::<_, &str>::new((0, 0), &style);
    // Labelled as drawn: a line only if some of it is inside the box.
    for series in chart.series.iter().filter(|s| !s.name.is_empty()) {
        if series.style.is_marker()
            || series.points.is_empty()
            || !clip.runs(&series.points).is_empty()
        {
            text.push_line(series.name.as_str());
        }
    }
    let (w, h) = text.estimate_dimension().map_err(|e| e.to_string())?;
    let (w, h) = (w + 30 + 20, h + 20);
    let area = ctx.plotting_area();
    let (aw, ah) = area.dim_in_pixel();
    let (aw, ah) = (aw as i32, ah as i32);
    let base = area.get_base_pixel();
    let local = |p: (f64, f64)| {
        let (x, y) = ctx.backend_coord(&p);
        ((x - base.0) as f64, (y - base.1) as f64)
    };
    let markers: Vec<(f64, f64)> = chart
        .series
        .iter()
        .filter(|s| s.style.is_marker())
        .flat_map(|s| s.points.iter().copied().filter(|&p| clip.contains(p)))
        .map(local)
        .collect();
    let segments: Vec<((f64, f64), (f64, f64))> = chart
        .series
        .iter()
        .filter(|s| !s.style.is_marker())
        .flat_map(|s| clip.runs(&s.points))
        .flat_map(|run| {
            let px: Vec<_> = run.into_iter().map(local).collect();
            px.windows(2).map(|w| (w[0], w[1])).collect::<Vec<_>>()
        })
        .collect();
    let covers = |(x, y): (i32, i32)| {
        // The box grown by a marker's radius and a line's half width.
        let (x0, x1, y0, y1) = (x as f64, (x + w) as f64, y as f64, (y + h) as f64);
        let m = markers
            .iter()
            .filter(|p| p.0 >= x0 - 7.0 && p.0 <= x1 + 7.0 && p.1 >= y0 - 7.0 && p.1 <= y1 + 7.0)
            .count();
        let l = segments
            .iter()
            .filter(|(a, b)| {
                liang_barsky(*a, *b, (x0 - 2.0, x1 + 2.0), (y0 - 2.0, y1 + 2.0)).is_some()
            })
            .count();
        m + l
    };
    let (left, right, mid_x) = (5, aw - w - 5, (aw - w) / 2);
    let (top, bottom, mid_y) = (5, ah - h - 5, (ah - h) / 2);
    let corners = [
        (Corner::UpperRight, (right, top)),
        (Corner::UpperLeft, (left, top)),
        (Corner::LowerRight, (right, bottom)),
        (Corner::LowerLeft, (left, bottom)),
    ];
    let preferred = corners.iter().filter(|c| c.0 == chart.legend);
    let others = corners.iter().filter(|c| c.0 != chart.legend);
    let candidates = preferred.chain(others).map(|c| c.1).chain([
        (right, mid_y),
        (left, mid_y),
        (mid_x, top),
        (mid_x, bottom),
    ]);
    let mut best = (right, top, usize::MAX);
    for at in candidates {
        let n = covers(at);
        if n < best.2 {
            best = (at.0, at.1, n);
        }
        if n == 0 {
            break;
        }
    }
    Ok(best)
}

/// Clipping of polylines to the plotted box (plotters would clamp out-of-range points
/// onto the border, bending straight lines). Works in the axes' own coordinates:
/// log10 of the value on a log axis, so straight lines stay straight.
#[doc(hidden)]
pub struct Clip {
    x: (f64, f64, bool),
    y: (f64, f64, bool),
}

impl Clip {
    pub fn new(x: (f64, f64, bool), y: (f64, f64, bool)) -> Self {
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
    pub fn runs(&self, points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
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
