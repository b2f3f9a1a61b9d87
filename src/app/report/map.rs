//! The `tapsim map` outputs: heat maps of E_ts, φ and A/A₀ over the (Δγ, E*) grid and
//! the grid as JSON (the CSV is the cells as records). They are drawn from anything
//! that serialises to a cell's record and answers for its values ([`MapRecord`]): the
//! cells as computed, or their records read back from part files ([`super::part`]), so a
//! merged map gives the same bytes as one computed whole.

use super::heatmap::{Cell, HeatMap};
use super::records;
use crate::analysis::sweep::MapCell;
use crate::error::Result;
use crate::physics::params::ELECTRONVOLT_J;
use serde::Serialize;
use serde_json::value::RawValue;

/// What a heat map shows of one cell: E_ts per cycle (eV), the phase (deg), A/A₀, the
/// viscous share of E_ts (eV), the phase's thermal noise (deg; NaN where not asked
/// for), and the thermal average's E_ts (eV), phase (deg) and temperature (K; NaN where
/// there is none),
/// the rest separation (m) where it was solved for (an amplitude setpoint), whether the
/// motion is period-1 and whether it grazes a switch; `None` where the law does not
/// apply.
pub type Plotted = Option<([f64; 8], Option<f64>, bool, bool)>;

/// A cell as its record serialises, and what its heat maps show.
pub trait MapRecord: Serialize {
    /// The cell's plotted values.
    fn plotted(&self) -> Plotted;
}

impl MapRecord for MapCell {
    fn plotted(&self) -> Plotted {
        let o = self.observables.as_ref()?;
        Some((
            [
                o.e_ts_ev,
                o.phase_deg,
                o.amplitude_ratio,
                o.e_ts_viscous_j / ELECTRONVOLT_J,
                self.sigma_phase_deg.unwrap_or(f64::NAN),
                self.thermal_average
                    .map_or(f64::NAN, |a| a.e_ts_j / ELECTRONVOLT_J),
                self.thermal_average.map_or(f64::NAN, |a| a.phase_deg),
                self.thermal_average.map_or(f64::NAN, |a| a.temperature_k),
            ],
            self.separation_m,
            o.period == Some(1),
            o.grazing,
        ))
    }
}

/// The fields of a cell's record that its heat maps show.
#[derive(serde::Deserialize)]
struct PlottedFields {
    e_ts_ev: Option<f64>,
    phase_deg: Option<f64>,
    amplitude_ratio: Option<f64>,
    e_ts_viscous_j: Option<f64>,
    separation_m: Option<f64>,
    period: Option<u64>,
    grazing: Option<bool>,
    sigma_phase_deg: Option<f64>,
    thermal_average: Option<AveragePlotted>,
}

/// The fields of a cell's thermal average that its heat maps show.
#[derive(serde::Deserialize)]
struct AveragePlotted {
    e_ts_j: f64,
    phase_deg: f64,
    temperature_k: f64,
}

impl MapRecord for Box<RawValue> {
    /// Read from the record's text once (the other fields are skipped).
    fn plotted(&self) -> Plotted {
        let f: PlottedFields = serde_json::from_str(self.get()).ok()?;
        Some((
            [
                f.e_ts_ev?,
                f.phase_deg?,
                f.amplitude_ratio?,
                f.e_ts_viscous_j? / ELECTRONVOLT_J,
                f.sigma_phase_deg.unwrap_or(f64::NAN),
                f.thermal_average
                    .as_ref()
                    .map_or(f64::NAN, |a| a.e_ts_j / ELECTRONVOLT_J),
                f.thermal_average.as_ref().map_or(f64::NAN, |a| a.phase_deg),
                f.thermal_average
                    .as_ref()
                    .map_or(f64::NAN, |a| a.temperature_k),
            ],
            f.separation_m,
            f.period == Some(1),
            f.grazing == Some(true),
        ))
    }
}

/// The apparent height of each cell at an amplitude setpoint (m): its rest separation
/// less the reference cell's (the first that holds the setpoint) — the height a
/// topography image shows over a flat sample of the cells' materials. `None` where a
/// cell has no rest separation.
pub fn apparent_heights<T: MapRecord>(cells: &[T]) -> Vec<Option<f64>> {
    let plotted: Vec<Plotted> = cells.iter().map(MapRecord::plotted).collect();
    heights_of(&plotted)
}

/// [`apparent_heights`] from the cells' plotted values.
fn heights_of(plotted: &[Plotted]) -> Vec<Option<f64>> {
    let z: Vec<Option<f64>> = plotted.iter().map(|p| p.and_then(|p| p.1)).collect();
    let reference = z.iter().flatten().next().copied();
    z.iter()
        .map(|z| z.zip(reference).map(|(z, r)| z - r))
        .collect()
}

/// Heat maps of E_ts per cycle, phase and A/A₀ over the grid for `law` (and of E_ts's
/// viscous share, where a sample is viscous); at an amplitude setpoint (`setpoint`, its
/// caption) the apparent height ([`apparent_heights`]) instead of A/A₀, which is the
/// setpoint everywhere. The records come row by row, one row per modulus (as
/// [`map_json`] lays them out); a cell without the value (the law does not apply there,
/// or the branch does not reach the setpoint) is grey.
pub fn heat_maps<T: MapRecord>(
    law: &str,
    setpoint: Option<&str>,
    works: &[f64],
    moduli: &[f64],
    cells: &[T],
) -> Vec<HeatMap> {
    let plotted: Vec<Plotted> = cells.iter().map(MapRecord::plotted).collect();
    let heights = heights_of(&plotted);
    let at = setpoint.map_or(String::new(), |s| format!(" at {s}"));
    let map = |title: &str, value_label: &str, value: &dyn Fn(usize, &[f64; 8]) -> f64| HeatMap {
        title: format!("{law} law{at}: {title}"),
        x_label: "work of adhesion Δγ (J/m²)".into(),
        y_label: "composite modulus E* (GPa)".into(),
        value_label: value_label.into(),
        empty_label: if setpoint.is_some() {
            "law n/a or not reached".into()
        } else {
            "law n/a".into()
        },
        x: works.to_vec(),
        y: moduli.iter().map(|e| e * 1e-9).collect(),
        log_axes: true,
        cells: plotted
            .iter()
            .enumerate()
            .collect::<Vec<_>>()
            .chunks(works.len())
            .map(|row| {
                row.iter()
                    .map(|(k, c)| match c {
                        Some((values, _, period_one, grazing)) => Cell::Value {
                            value: value(*k, values),
                            period_one: *period_one,
                            grazing: *grazing,
                        },
                        None => Cell::NotApplicable,
                    })
                    .collect()
            })
            .collect(),
    };
    let mut maps = vec![
        map("dissipation per cycle", "E_ts per cycle (eV)", &|_, v| v[0]),
        map("phase", "phase lag φ (deg)", &|_, v| v[1]),
    ];
    if setpoint.is_some() {
        maps.push(map(
            "apparent height Δz_c",
            "Δz_c from the first cell (nm)",
            &|k, _| heights[k].map_or(f64::NAN, |h| h * 1e9),
        ));
    } else {
        maps.push(map("amplitude", "A/A₀", &|_, v| v[2]));
    }
    if plotted.iter().flatten().any(|(values, ..)| values[3] > 0.0) {
        maps.push(map(
            "viscous share of the dissipation",
            "E_ts in the viscous sample per cycle (eV)",
            &|_, v| v[3],
        ));
    }
    // The thermal noise, where it was asked for: σ_φ, and the contrast with the first
    // cell that has one over the noise of the two readings.
    if let Some(first) = plotted.iter().flatten().find(|p| p.0[4].is_finite()) {
        let (phase0, sigma0) = (first.0[1], first.0[4]);
        maps.push(map(
            "thermal phase noise σ_φ",
            "σ_φ through the lock-in (deg)",
            &|_, v| v[4],
        ));
        maps.push(map(
            "contrast over noise",
            "|φ − φ₀|/√(σ² + σ₀²), first cell",
            &|_, v| (v[1] - phase0).abs() / v[4].hypot(sigma0),
        ));
    }
    // The thermal averages, where some cells have one: E_ts and φ as an instrument reads
    // them (the average there, the steady state elsewhere).
    if let Some(first) = plotted.iter().flatten().find(|p| p.0[7].is_finite()) {
        let kelvin = first.0[7];
        // The average (index `average`) where there is one, else the steady state's
        // value (index `steady`).
        let read = |v: &[f64; 8], average: usize, steady: usize| {
            if v[average].is_finite() {
                v[average]
            } else {
                v[steady]
            }
        };
        maps.push(map(
            &format!("dissipation as read at {kelvin} K"),
            "E_ts per cycle (eV); thermal average at ○ and •",
            &|_, v| read(v, 5, 0),
        ));
        maps.push(map(
            &format!("phase as read at {kelvin} K"),
            "phase lag φ (deg); thermal average at ○ and •",
            &|_, v| read(v, 6, 1),
        ));
    }
    maps
}

/// The grid as one JSON object: the law, the setpoint (if any), both axes, and per
/// observable an array of rows (one per modulus) of values (one per work of adhesion);
/// at a setpoint also the apparent heights ([`apparent_heights`]).
pub fn map_json<T: MapRecord>(
    law: &str,
    setpoint: Option<&super::part::MapSetpoint>,
    works: &[f64],
    moduli: &[f64],
    cells: &[T],
) -> Result<serde_json::Value> {
    let mut v = serde_json::json!({
        "law": law,
        "work_of_adhesion_j_m2": works,
        "modulus_pa": moduli,
        "grazing_cells": grazing_cells(cells),
        "grid": records::grid_json(cells, works.len())?,
    });
    if let (Some(sp), serde_json::Value::Object(m)) = (setpoint, &mut v) {
        m.insert(
            "setpoint".into(),
            serde_json::to_value(sp).expect("serialises"),
        );
        let heights: Vec<Vec<Option<f64>>> = apparent_heights(cells)
            .chunks(works.len())
            .map(<[Option<f64>]>::to_vec)
            .collect();
        m.insert("apparent_height_m".into(), serde_json::json!(heights));
    }
    Ok(v)
}

/// How many cells' motion grazes a switch.
pub fn grazing_cells<T: MapRecord>(cells: &[T]) -> usize {
    cells
        .iter()
        .filter(|c| c.plotted().is_some_and(|p| p.3))
        .count()
}
