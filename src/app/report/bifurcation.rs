//! The bifurcation diagram: Poincaré samples of the settled motion against the rest
//! separation, coloured by the kind of motion.

use super::chart::{Axis, Chart, Corner, Series, Style};
use crate::analysis::sweep::PoincareSample;

/// Whether a regime ("period-2", …) belongs to a group of the legend.
type Kind = fn(&str) -> bool;

/// Two charts against z_c (nm): the deflection at drive phase 0 and the smallest
/// separation of each sampled period, period-1, period-n and irregular apart.
pub fn bifurcation_charts(samples: &[PoincareSample], title: &str) -> Vec<Chart> {
    type Pick = fn(&PoincareSample) -> f64;
    let quantities: [(&str, &str, &str, &str, Pick); 2] = [
        (
            "bifurcation_deflection",
            "deflection at drive phase 0",
            "deflection z at drive phase 0 (nm)",
            "deflection_nm",
            |s| s.deflection_m * 1e9,
        ),
        (
            "bifurcation_min_separation",
            "closest approach per period",
            "smallest separation per period (nm)",
            "min_separation_nm",
            |s| s.min_separation_m * 1e9,
        ),
    ];
    quantities
        .iter()
        .map(|&(name, what, label, column, pick)| {
            let kinds: [(&str, Kind, usize); 3] = [
                ("period-1", |r| r == "period-1", 2),
                (
                    "period-n (n ≥ 2)",
                    |r| r.starts_with("period-") && r != "period-1",
                    1,
                ),
                ("irregular", |r| r == "irregular", 4),
            ];
            let series: Vec<Series> = kinds
                .iter()
                .filter_map(|&(legend, keep, color)| {
                    let pts: Vec<(f64, f64)> = samples
                        .iter()
                        .filter(|s| keep(&s.regime))
                        .map(|s| (s.separation_m * 1e9, pick(s)))
                        .collect();
                    (!pts.is_empty()).then(|| Series::new(legend, pts, Style::Dots, color))
                })
                .collect();
            Chart {
                name: name.into(),
                title: format!("{title}: {what}"),
                x: super::sweep::separation_axis(),
                y: Axis::linear(label, column),
                legend: Corner::quietest(&series),
                series,
                labels: vec![],
            }
        })
        .collect()
}
