//! Reports of sweeps: records as CSV, as one JSON object of equal-length arrays, and
//! the approach-curve charts.

use super::chart::{Axis, Chart, Corner, Series, Style};
use crate::error::{Error, Result};
use crate::sweep::{Direction, SweepPoint};
use serde::Serialize;
use serde_json::{Map, Value};

/// Serialise records to JSON objects (one per record).
fn objects<T: Serialize>(records: &[T]) -> Result<Vec<Map<String, Value>>> {
    records
        .iter()
        .map(|r| match serde_json::to_value(r) {
            Ok(Value::Object(m)) => Ok(m),
            Ok(_) => Err(Error::Output {
                path: "records".into(),
                reason: "a record is not an object".into(),
            }),
            Err(e) => Err(Error::Output {
                path: "records".into(),
                reason: e.to_string(),
            }),
        })
        .collect()
}

/// Every field name of the records, in first-seen order (records may lack some).
fn field_names(rows: &[Map<String, Value>]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for r in rows {
        for k in r.keys() {
            if !names.contains(k) {
                names.push(k.clone());
            }
        }
    }
    names
}

/// One JSON object whose fields are arrays (one entry per record, null where a record
/// lacks the field), in record-field order.
pub fn columns_json<T: Serialize>(records: &[T]) -> Result<Value> {
    let rows = objects(records)?;
    let mut out = Map::new();
    for key in field_names(&rows) {
        let column = rows
            .iter()
            .map(|r| r.get(&key).cloned().unwrap_or(Value::Null))
            .collect();
        out.insert(key, Value::Array(column));
    }
    Ok(Value::Object(out))
}

/// The records as CSV, one row each, the fields as columns.
pub fn records_csv<T: Serialize>(records: &[T]) -> Result<Vec<u8>> {
    let rows = objects(records)?;
    let fail = |e: csv::Error| Error::Output {
        path: "records.csv".into(),
        reason: e.to_string(),
    };
    let mut w = csv::Writer::from_writer(Vec::new());
    let keys = field_names(&rows);
    if !keys.is_empty() {
        w.write_record(&keys).map_err(fail)?;
        for r in &rows {
            w.write_record(keys.iter().map(|k| match r.get(k) {
                Some(Value::String(s)) => s.clone(),
                Some(Value::Null) | None => String::new(),
                Some(v) => v.to_string(),
            }))
            .map_err(fail)?;
        }
    }
    w.into_inner().map_err(|e| Error::Output {
        path: "records.csv".into(),
        reason: e.to_string(),
    })
}

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
