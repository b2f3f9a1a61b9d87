//! Tests of `tapsim::app::report::plot` (src/app/report/plot.rs).

use plotters::prelude::*;
use tapsim::app::report::chart::{Chart, Corner, Scale, Style};
use tapsim::app::report::heatmap::{Cell, HeatMap, viridis};
use tapsim::app::report::plot::*;

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

use tapsim::app::report::chart::{Axis, Series};

fn chart(x: Axis, y: Axis, series: Vec<Series>, legend: Corner) -> Chart {
    Chart {
        name: "test".into(),
        title: "test".into(),
        x,
        y,
        series,
        labels: Vec::new(),
        legend,
    }
}

/// Pixels of exactly `color` outside the drawn charts' plotting areas (grown by a
/// pixel for a line's half width).
fn strays(charts: &[Chart], color: RGBColor) -> usize {
    let (pixels, (width, _), drawn) = rasterize(charts, Arrange::Stack).unwrap();
    pixels
        .chunks(3)
        .enumerate()
        .filter(|(_, p)| (p[0], p[1], p[2]) == (color.0, color.1, color.2))
        .filter(|&(i, _)| {
            let (x, y) = ((i as u32 % width) as i32, (i as u32 / width) as i32);
            !drawn.iter().any(|d| {
                (d.area.0.start - 1..d.area.0.end + 1).contains(&x)
                    && (d.area.1.start - 1..d.area.1.end + 1).contains(&y)
            })
        })
        .count()
}

#[test]
fn no_drawn_pixel_of_a_series_leaves_its_plot_area() {
    // Thick lines that run far outside fixed ranges, solid and dashed, on linear and
    // log axes, one chart and a stack (the SVG does not clip: the series are clipped
    // before they are drawn).
    let wild = vec![(-5.0, 3.0), (0.5, 0.5), (5.0, -3.0), (0.2, 9.0), (0.9, 0.1)];
    let color = PALETTE[7];
    let lines = |style| Series::new("wild", wild.clone(), style, 7);
    let linear = chart(
        Axis::linear("x", "x").with_range(0.0, 1.0),
        Axis::linear("y", "y").with_range(0.0, 1.0),
        vec![lines(Style::Line), lines(Style::Dashed)],
        Corner::UpperRight,
    );
    let positive: Vec<(f64, f64)> = wild
        .iter()
        .map(|p| (p.0.abs() + 1e-3, p.1.abs() + 1e-3))
        .collect();
    let log = chart(
        Axis::log("x", "x").with_range(0.1, 1.0),
        Axis::log("y", "y").with_range(0.1, 1.0),
        vec![Series::new("wild", positive, Style::Dotted, 7)],
        Corner::LowerLeft,
    );
    assert!(strays(std::slice::from_ref(&linear), color) == 0);
    assert!(strays(&[linear.clone(), log.clone(), linear], color) == 0);
    // (Not vacuous: the series is drawn, in that colour.)
    let (pixels, _, _) = rasterize(&[log], Arrange::Stack).unwrap();
    assert!(
        pixels
            .chunks(3)
            .any(|p| (p[0], p[1], p[2]) == (color.0, color.1, color.2))
    );
}

#[test]
fn the_legend_goes_where_it_covers_no_data() {
    // A line through the preferred (upper right) corner and markers in the upper left.
    let diagonal: Vec<(f64, f64)> = (0..=50)
        .map(|i| (i as f64 / 50.0, i as f64 / 50.0))
        .collect();
    let upper_left: Vec<(f64, f64)> = (0..10)
        .map(|i| (0.02 * i as f64, 0.98 - 0.02 * i as f64))
        .collect();
    let busy = chart(
        Axis::linear("x", "x").with_range(0.0, 1.0),
        Axis::linear("y", "y").with_range(0.0, 1.0),
        vec![
            Series::new("diagonal", diagonal, Style::Line, 1),
            Series::new("corner", upper_left, Style::Markers, 2),
        ],
        Corner::UpperRight,
    );
    let (_, _, drawn) = rasterize(&[busy], Arrange::Stack).unwrap();
    assert_eq!(drawn[0].legend_covers, 0);
}

#[test]
fn tick_labels_read_as_people_write_them() {
    let log = |v| tick_label(v, Scale::Log);
    let lin = |v| tick_label(v, Scale::Linear);
    assert_eq!(
        [
            log(0.01),
            log(0.1),
            log(1.0),
            log(10.0),
            log(100.0),
            log(1e3),
            log(2e3)
        ],
        ["10⁻²", "0.1", "1", "10", "10²", "10³", "2000"]
    );
    assert_eq!(
        [
            lin(140.0),
            lin(0.25),
            lin(0.1 + 0.2),
            lin(-0.0),
            lin(-2.5),
            lin(2.5e-18)
        ],
        ["140", "0.25", "0.3", "0", "-2.5", "2.5e-18"]
    );
}

#[test]
fn a_heat_map_colours_cells_greys_the_inapplicable_and_marks_the_irregular() {
    let map = HeatMap {
        title: "t".into(),
        x_label: "x".into(),
        y_label: "y".into(),
        value_label: "v".into(),
        empty_label: "law n/a".into(),
        x: vec![1.0, 10.0],
        y: vec![1.0, 10.0],
        log_axes: true,
        cells: vec![
            vec![
                Cell::Value {
                    value: 0.0,
                    period_one: true,
                    grazing: false,
                },
                Cell::Value {
                    value: 1.0,
                    period_one: false,
                    grazing: false,
                },
            ],
            vec![
                Cell::NotApplicable,
                Cell::Value {
                    value: 0.5,
                    period_one: true,
                    grazing: false,
                },
            ],
        ],
    };
    let (pixels, (width, _), _) = rasterize_maps(&[map], Arrange::Stack).unwrap();
    let count = |c: (u8, u8, u8)| pixels.chunks(3).filter(|p| (p[0], p[1], p[2]) == c).count();
    // A quarter of a ~600 x 500 plot each, and the ends of the colour bar.
    assert!(count(viridis(0.0)) > 20_000, "{}", count(viridis(0.0)));
    assert!(count(viridis(1.0)) > 20_000);
    assert!(count(viridis(0.5)) > 20_000);
    assert!(count((225, 225, 225)) > 20_000);
    // The marked cell (the one of value 1) has a white disc in it (radius 6, in a
    // 2-pixel black ring): white pixels within the box its colour spans.
    let at = |i: usize| ((i as u32 % width) as i32, (i as u32 / width) as i32);
    let cell: Vec<(i32, i32)> = pixels
        .chunks(3)
        .enumerate()
        .filter(|(_, p)| (p[0], p[1], p[2]) == viridis(1.0))
        .map(|(i, _)| at(i))
        .collect();
    let (x0, x1) = (
        cell.iter().map(|p| p.0).min(),
        cell.iter().map(|p| p.0).max(),
    );
    let (y0, y1) = (
        cell.iter().map(|p| p.1).min(),
        cell.iter().map(|p| p.1).max(),
    );
    let (x0, x1, y0, y1) = (x0.unwrap(), x1.unwrap(), y0.unwrap(), y1.unwrap());
    let disc = pixels
        .chunks(3)
        .enumerate()
        .filter(|(_, p)| (p[0], p[1], p[2]) == (255, 255, 255))
        .filter(|&(i, _)| {
            let (x, y) = at(i);
            (x0..=x1).contains(&x) && (y0..=y1).contains(&y)
        })
        .count();
    assert!(
        (20..200).contains(&disc),
        "{disc} white pixels in the marked cell"
    );
    assert_eq!(log_ticks(0.017, 0.23), [0.02, 0.05, 0.1, 0.2]);
    assert_eq!(log_ticks(0.26, 3.5), [0.3, 0.5, 1.0, 2.0, 3.0]);
}

#[test]
fn clipping_splits_runs_that_leave_the_box() {
    let clip = Clip::new((0.0, 1.0, false), (0.0, 1.0, false));
    let runs = clip.runs(&[(0.1, 0.5), (0.5, 2.0), (0.9, 0.5), (0.95, 0.5)]);
    assert_eq!(runs.len(), 2);
}

/// The PNG's pixels are the crisp drawing's geometry, anti-aliased and with its text:
/// in the PNG the markers' rings' edges are blended into the white (the crisp drawing
/// puts a pixel in the colour or not at all), every pixel of the colour lies within two
/// pixels of where the crisp drawing put it, and the title is drawn (the embedded font
/// was found: without it resvg would draw no text at all).
#[test]
fn png_markers_are_anti_aliased_where_the_crisp_drawing_puts_them() {
    let points: Vec<(f64, f64)> = (1..20)
        .map(|i| (i as f64 / 20.0, 0.3 * i as f64 / 20.0 + 0.1))
        .collect();
    let c = chart(
        Axis::linear("x", "x").with_range(0.0, 1.0),
        Axis::linear("y", "y").with_range(0.0, 1.0),
        vec![Series::new("rings", points, Style::Markers, 2)],
        Corner::UpperRight,
    );
    let color = PALETTE[2];
    // The share t of the marker's colour over white in a pixel (None: another
    // colour, to within 3 levels).
    let coverage = |p: &[u8]| {
        let t = (255.0 - p[0] as f64) / (255.0 - color.0 as f64);
        let on_white = [color.0, color.1, color.2].iter().zip(p).all(|(&c, &v)| {
            let expect = t * c as f64 + (1.0 - t) * 255.0;
            (expect - v as f64).abs() <= 3.0
        });
        (t > 0.05 && on_white).then_some(t.min(1.0))
    };
    let (crisp, (width, height), _) = rasterize(std::slice::from_ref(&c), Arrange::Stack).unwrap();
    let (smooth, size, _) = rasterize_smooth(std::slice::from_ref(&c), Arrange::Stack).unwrap();
    assert_eq!(size, (width, height));
    let partial = |px: &[u8]| {
        px.chunks(3)
            .filter(|p| coverage(p).is_some_and(|t| (0.15..0.85).contains(&t)))
            .count()
    };
    let (soft, hard) = (partial(&smooth), partial(&crisp));
    assert!(soft > 2 * hard, "partly covered: {soft} PNG, {hard} crisp");
    let pixel = |x: usize, y: usize| &smooth[3 * (y * width as usize + x)..][..3];
    let title_ink = (0..40)
        .flat_map(|y| (300..660).map(move |x| (x, y)))
        .filter(|&(x, y)| pixel(x, y).iter().all(|&v| v < 80))
        .count();
    assert!(title_ink > 20, "no title: {title_ink} dark pixels");
    let line: Vec<(i64, i64)> = crisp
        .chunks(3)
        .enumerate()
        .filter(|(_, p)| coverage(p).is_some())
        .map(|(i, _)| ((i as u32 % width) as i64, (i as u32 / width) as i64))
        .collect();
    for (i, p) in smooth.chunks(3).enumerate() {
        if coverage(p).is_some_and(|t| t > 0.3) {
            let (x, y) = ((i as u32 % width) as i64, (i as u32 / width) as i64);
            assert!(
                line.iter()
                    .any(|&(u, v)| (u - x).abs() <= 2 && (v - y).abs() <= 2),
                "a pixel of a ring at ({x}, {y}) far from the crisp drawing's"
            );
        }
    }
}
