//! Charts of the period-1 orbit family: A/A₀, φ and E_ts against the rest separation,
//! stable orbits solid, unstable dashed, folds and period doublings marked, an approach
//! ramp optionally drawn over them.

use super::chart::{Axis, Chart, Corner, Series, Style};
use crate::analysis::sweep::{BranchPointKind, BranchRecord, SweepPoint};
use crate::physics::params::ELECTRONVOLT_J;

type Pick = fn(&crate::dynamics::observables::TapObservables) -> f64;

/// The quantities charted: (file stem, caption, axis label, column, value).
const QUANTITIES: [(&str, &str, &str, &str, Pick); 3] = [
    ("amplitude", "amplitude", "A/A₀", "amplitude_ratio", |o| {
        o.amplitude_ratio
    }),
    ("phase", "phase", "phase lag φ (deg)", "phase_deg", |o| {
        o.phase_deg
    }),
    (
        "e_ts",
        "dissipation",
        "E_ts per cycle (eV)",
        "e_ts_ev",
        |o| o.e_ts_j / ELECTRONVOLT_J,
    ),
];

/// Runs of consecutive points of one stability and one piece of the branch, each with
/// the neighbouring point of the run before where only the stability changes, so the
/// lines join there and break between pieces. An orbit whose stability rests on a
/// grazing contact (`stable` null) is drawn with the stable ones and marked as grazing.
fn runs(points: &[BranchRecord]) -> Vec<(bool, Vec<&BranchRecord>)> {
    let stable = |p: &BranchRecord| p.observables.stable != Some(false);
    let mut out: Vec<(bool, Vec<&BranchRecord>)> = Vec::new();
    for p in points {
        match out.last_mut() {
            Some((s, run)) if run[0].segment != p.segment || *s != stable(p) => {
                let last = *run.last().expect("runs are not empty");
                // Join a change of stability, not a gap between pieces.
                let start = if last.segment == p.segment {
                    vec![last, p]
                } else {
                    vec![p]
                };
                out.push((stable(p), start));
            }
            Some((_, run)) => run.push(p),
            None => out.push((stable(p), vec![p])),
        }
    }
    out
}

/// One chart per quantity against z_c (nm), E_ts only for a law with a loop (a
/// conservative law's is round-off); orbits that graze a switch marked by squares;
/// `ramp`, if given, is drawn as markers (approach and retract).
pub fn branch_charts(points: &[BranchRecord], ramp: &[SweepPoint], title: &str) -> Vec<Chart> {
    let nm = |m: f64| m * 1e9;
    let lossless = points.iter().all(|p| p.observables.loop_area_j == 0.0);
    QUANTITIES
        .iter()
        .filter(|q| !(lossless && q.0 == "e_ts"))
        .map(|&(name, what, label, column, pick)| {
            let mut series = Vec::new();
            let (mut named_stable, mut named_unstable) = (false, false);
            for (stable, run) in runs(points) {
                let named = if stable {
                    &mut named_stable
                } else {
                    &mut named_unstable
                };
                let legend = if *named {
                    ""
                } else if stable {
                    "stable orbits"
                } else {
                    "unstable orbits"
                };
                *named = true;
                series.push(Series::new(
                    legend,
                    run.iter()
                        .map(|p| (nm(p.separation_m), pick(&p.observables)))
                        .collect(),
                    if stable { Style::Line } else { Style::Dashed },
                    if stable { 1 } else { 2 },
                ));
            }
            for (kind, legend, color) in [
                (BranchPointKind::Fold, "fold (multiplier +1)", 3),
                (BranchPointKind::PeriodDoubling, "period doubling (−1)", 4),
            ] {
                let marks: Vec<(f64, f64)> = points
                    .iter()
                    .filter(|p| p.point == kind)
                    .map(|p| (nm(p.separation_m), pick(&p.observables)))
                    .collect();
                if !marks.is_empty() {
                    series.push(Series::new(legend, marks, Style::Markers, color));
                }
            }
            let grazing: Vec<(f64, f64)> = points
                .iter()
                .filter(|p| p.observables.grazing)
                .map(|p| (nm(p.separation_m), pick(&p.observables)))
                .collect();
            if !grazing.is_empty() {
                series.push(Series::new("grazes a switch", grazing, Style::Squares, 6));
            }
            series.extend(super::sweep::ramp_markers(ramp, &|p: &SweepPoint| {
                (nm(p.separation_m), pick(&p.observables))
            }));
            Chart {
                name: format!("branch_{name}"),
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
