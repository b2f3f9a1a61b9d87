//! A chart described as data — axes, series, point labels — independent of how it is
//! drawn. [`super::plot`] renders it to PNG and SVG; [`Chart::to_csv`] writes its data.

use crate::error::{Error, Result};
use serde::Serialize;

/// Linear or logarithmic axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Scale {
    /// Linear axis.
    Linear,
    /// Base-10 logarithmic axis (positive data only).
    Log,
}

/// One axis of a chart.
#[derive(Debug, Clone, Serialize)]
pub struct Axis {
    /// Label shown on the plot, with symbol and unit.
    pub label: String,
    /// Column name in the CSV file.
    pub column: String,
    /// Scale.
    pub scale: Scale,
    /// Fixed range; the data's range (padded) when `None`.
    pub range: Option<(f64, f64)>,
}

impl Axis {
    /// A linear axis with automatic range.
    pub fn linear(label: &str, column: &str) -> Self {
        Self {
            label: label.into(),
            column: column.into(),
            scale: Scale::Linear,
            range: None,
        }
    }

    /// A logarithmic axis with automatic range.
    pub fn log(label: &str, column: &str) -> Self {
        Self {
            scale: Scale::Log,
            ..Self::linear(label, column)
        }
    }

    /// The same axis with a fixed range.
    pub fn with_range(mut self, lo: f64, hi: f64) -> Self {
        self.range = Some((lo, hi));
        self
    }
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Style {
    /// Solid line.
    Line,
    /// Dashed line.
    Dashed,
    /// Dotted line (jumps, guides).
    Dotted,
    /// Circles at the points, no line.
    Markers,
    /// Squares at the points, no line (a second kind of marker, to tell coinciding
    /// sets apart).
    Squares,
    /// Crosses at the points, no line (a third kind of marker).
    Crosses,
    /// Filled triangles at the points, no line (a fourth kind: values of another kind
    /// of calculation, such as thermal averages beside deterministic states).
    Triangles,
    /// Small filled dots, no line: clouds of many samples (a bifurcation diagram), whose
    /// structure larger markers would hide.
    Dots,
}

impl Style {
    /// Whether points are marked rather than joined.
    pub fn is_marker(self) -> bool {
        matches!(
            self,
            Style::Markers | Style::Squares | Style::Crosses | Style::Triangles | Style::Dots
        )
    }
}

/// A named set of (x, y) points.
#[derive(Debug, Clone, Serialize)]
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// The data.
    pub points: Vec<(f64, f64)>,
    /// How it is drawn.
    pub style: Style,
    /// Palette index of its colour.
    pub color: usize,
}

impl Series {
    /// A series with the given style and palette colour.
    pub fn new(name: &str, points: Vec<(f64, f64)>, style: Style, color: usize) -> Self {
        Self {
            name: name.into(),
            points,
            style,
            color,
        }
    }
}

/// Where the legend sits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub enum Corner {
    /// Upper left.
    UpperLeft,
    /// Upper right.
    #[default]
    UpperRight,
    /// Lower left.
    LowerLeft,
    /// Lower right.
    LowerRight,
    /// No legend: another panel of the same figure carries it.
    Hidden,
}

impl Corner {
    /// The corner whose quarter of the data's box (35 % of each axis) holds the fewest
    /// points of `series`: where a legend hides the least.
    pub fn quietest(series: &[Series]) -> Corner {
        let all = || series.iter().flat_map(|s| s.points.iter().copied());
        let finite = |v: f64| v.is_finite();
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for (x, y) in all().filter(|p| finite(p.0) && finite(p.1)) {
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
        }
        let (w, h) = ((x1 - x0).max(1e-300), (y1 - y0).max(1e-300));
        let count = |left: bool, top: bool| {
            all()
                .filter(|&(x, y)| {
                    let fx = (x - x0) / w;
                    let fy = (y - y0) / h;
                    (if left { fx <= 0.35 } else { fx >= 0.65 })
                        && (if top { fy >= 0.65 } else { fy <= 0.35 })
                })
                .count()
        };
        [
            (Corner::UpperRight, count(false, true)),
            (Corner::UpperLeft, count(true, true)),
            (Corner::LowerRight, count(false, false)),
            (Corner::LowerLeft, count(true, false)),
        ]
        .into_iter()
        .min_by_key(|c| c.1)
        .map_or(Corner::UpperRight, |c| c.0)
    }
}

/// A text label placed next to a data point (e.g. the letters of the paper's figures).
#[derive(Debug, Clone, Serialize)]
pub struct Label {
    /// The text.
    pub text: String,
    /// Abscissa of the point.
    pub x: f64,
    /// Ordinate of the point.
    pub y: f64,
}

/// Give a figure's panels one legend where they share one: a panel whose legend
/// entries all appear in an earlier panel's legend shows none ([`Corner::Hidden`]), so
/// the same box is not drawn over the data of every panel.
pub fn share_legends(charts: &mut [Chart]) {
    let mut shown: Vec<String> = Vec::new();
    for chart in charts {
        let names: Vec<&String> = chart
            .series
            .iter()
            .map(|s| &s.name)
            .filter(|n| !n.is_empty())
            .collect();
        if names.iter().all(|n| shown.contains(n)) {
            chart.legend = Corner::Hidden;
        } else {
            shown.extend(names.into_iter().cloned());
        }
    }
}

/// A complete chart.
#[derive(Debug, Clone, Serialize)]
pub struct Chart {
    /// File stem for the outputs (`<name>.csv`, `.png`, `.svg`).
    pub name: String,
    /// Title drawn above the plot.
    pub title: String,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// Data series, drawn in order.
    pub series: Vec<Series>,
    /// Point labels.
    pub labels: Vec<Label>,
    /// Legend position.
    pub legend: Corner,
}

impl Chart {
    /// The chart's data as CSV in long form: one row per point, columns
    /// `series`, x column, y column (numbers as [`super::records::csv_number`]).
    pub fn to_csv(&self) -> Result<Vec<u8>> {
        use super::records::csv_number;
        let mut w = csv::Writer::from_writer(Vec::new());
        let fail = |e: csv::Error| Error::Output {
            path: format!("{}.csv", self.name).into(),
            reason: e.to_string(),
        };
        w.write_record(["series", &self.x.column, &self.y.column])
            .map_err(fail)?;
        for s in &self.series {
            for &(x, y) in &s.points {
                w.write_record([s.name.clone(), csv_number(x), csv_number(y)])
                    .map_err(fail)?;
            }
        }
        w.into_inner().map_err(|e| Error::Output {
            path: format!("{}.csv", self.name).into(),
            reason: e.to_string(),
        })
    }
}
