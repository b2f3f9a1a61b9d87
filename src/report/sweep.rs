//! Reports of sweeps: the approach-curve and phase-contrast charts. (Records go out
//! through [`super::records`].)

use super::chart::{Axis, Chart, Corner, Series, Style};
use crate::sweep::{Direction, SweepPoint};

/// Approach-curve charts: A/A₀, φ, E_ts, virial and peak force against z_c, and the
/// last four against A/A₀; approach and retract as separate series.
pub fn approach_charts(points: &[SweepPoint], title: &str) -> Vec<Chart> {
    type Pick = fn(&SweepPoint) -> f64;
    let nm = |p: &SweepPoint| p.separation_m * 1e9;
    let series = |x: &dyn Fn(&SweepPoint) -> f64, y: Pick| -> Vec<Series> {
        [
            (Direction::Approach, "approach", 1),
            (Direction::Retract, "retract", 2),
        ]
        .into_iter()
        .filter_map(|(dir, name, color)| {
            let pts: Vec<(f64, f64)> = points
                .iter()
                .filter(|p| p.direction == dir)
                .map(|p| (x(p), y(p)))
                .collect();
            (!pts.is_empty()).then(|| {
                let style = if dir == Direction::Approach {
                    Style::Line
                } else {
                    Style::Dashed
                };
                Series::new(name, pts, style, color)
            })
        })
        .collect()
    };
    let chart =
        |name: &str, what: &str, x: Axis, xs: &dyn Fn(&SweepPoint) -> f64, y: Axis, ys: Pick| {
            Chart {
                name: name.into(),
                title: format!("{title}: {what}"),
                x,
                y,
                series: series(xs, ys),
                labels: vec![],
                legend: Corner::LowerRight,
            }
        };
    let zc = || Axis::linear("rest separation z_c (nm)", "separation_nm");
    let ratio = |p: &SweepPoint| p.observables.amplitude_ratio;
    // (file stem, caption, axis label, column, value); the first is A/A₀ itself.
    let quantities: [(&str, &str, &str, &str, Pick); 5] = [
        ("amplitude", "amplitude", "A/A₀", "amplitude_ratio", |p| {
            p.observables.amplitude_ratio
        }),
        ("phase", "phase", "phase lag φ (deg)", "phase_deg", |p| {
            p.observables.phase_deg
        }),
        (
            "e_ts",
            "dissipation",
            "E_ts per cycle (eV)",
            "e_ts_ev",
            |p| p.observables.e_ts_ev,
        ),
        (
            "virial",
            "virial",
            "virial ⟨F_ts z⟩ (eV)",
            "virial_ev",
            |p| p.observables.virial_j / crate::params::ELECTRONVOLT_J,
        ),
        (
            "peak_force",
            "peak force",
            "peak repulsive force (nN)",
            "peak_force_nn",
            |p| p.observables.peak_force_n * 1e9,
        ),
    ];
    let against_separation = quantities.iter().map(|&(name, what, label, column, pick)| {
        chart(name, what, zc(), &nm, Axis::linear(label, column), pick)
    });
    let against_amplitude = quantities
        .iter()
        .skip(1)
        .map(|&(name, what, label, column, pick)| {
            chart(
                &format!("{name}_vs_amplitude"),
                &format!("{what} vs amplitude"),
                Axis::linear("A/A₀", "amplitude_ratio"),
                &ratio,
                Axis::linear(label, column),
                pick,
            )
        });
    against_separation.chain(against_amplitude).collect()
}

/// φ against A/A₀ on the approach branch (free points A/A₀ ≥ 0.999 left out), one series
/// per labelled curve: the phase-contrast view.
pub fn phase_vs_amplitude(name: &str, title: &str, curves: &[(&str, &[SweepPoint])]) -> Chart {
    Chart {
        name: name.into(),
        title: title.into(),
        x: Axis::linear("A/A₀", "amplitude_ratio"),
        y: Axis::linear("phase lag φ (deg)", "phase_deg"),
        series: curves
            .iter()
            .enumerate()
            .map(|(i, (label, points))| {
                let pts = points
                    .iter()
                    .filter(|p| {
                        p.direction == Direction::Approach && p.observables.amplitude_ratio < 0.999
                    })
                    .map(|p| (p.observables.amplitude_ratio, p.observables.phase_deg))
                    .collect();
                Series::new(label, pts, Style::Line, i + 1)
            })
            .collect(),
        labels: vec![],
        legend: Corner::UpperRight,
    }
}
