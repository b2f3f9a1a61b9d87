//! The `tapsim map` outputs: heat maps of E_ts, φ and A/A₀ over the (Δγ, E*) grid and
//! the grid as JSON (the CSV is the cells as records). They are drawn from anything
//! that serialises to a cell's record and answers for its values ([`MapRecord`]): the
//! cells as computed, or their records read back from part files ([`super::part`]), so a
//! merged map gives the same bytes as one computed whole.

use super::heatmap::{Cell, HeatMap};
use super::records;
use crate::error::Result;
use crate::params::ELECTRONVOLT_J;
use crate::sweep::MapCell;
use serde::Serialize;
use serde_json::value::RawValue;

/// What a heat map shows of one cell: E_ts per cycle (eV), the phase (deg), A/A₀ and the
/// viscous share of E_ts (eV), whether the motion is period-1 and whether it grazes a
/// switch; `None` where the law does not apply.
pub type Plotted = Option<([f64; 4], bool, bool)>;

/// A map cell as its record serialises, and what its heat maps show.
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
            ],
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
    period: Option<u64>,
    grazing: Option<bool>,
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
            ],
            f.period == Some(1),
            f.grazing == Some(true),
        ))
    }
}

/// Heat maps of E_ts per cycle, phase and A/A₀ over the grid for `law` (and of E_ts's
/// viscous share, where a sample is viscous). The records come
/// row by row, one row per modulus (as [`map_json`] lays them out); a cell without the
/// value (the law does not apply there) is grey.
pub fn heat_maps<T: MapRecord>(
    law: &str,
    works: &[f64],
    moduli: &[f64],
    cells: &[T],
) -> Vec<HeatMap> {
    let plotted: Vec<Plotted> = cells.iter().map(MapRecord::plotted).collect();
    let map = |title: &str, value_label: &str, which: usize| HeatMap {
        title: format!("{law} law: {title}"),
        x_label: "work of adhesion Δγ (J/m²)".into(),
        y_label: "composite modulus E* (GPa)".into(),
        value_label: value_label.into(),
        x: works.to_vec(),
        y: moduli.iter().map(|e| e * 1e-9).collect(),
        cells: plotted
            .chunks(works.len())
            .map(|row| {
                row.iter()
                    .map(|c| match c {
                        Some((values, period_one, grazing)) => Cell::Value {
                            value: values[which],
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
        map("dissipation per cycle", "E_ts per cycle (eV)", 0),
        map("phase", "phase lag φ (deg)", 1),
        map("amplitude", "A/A₀", 2),
    ];
    if plotted.iter().flatten().any(|(values, ..)| values[3] > 0.0) {
        maps.push(map(
            "viscous share of the dissipation",
            "E_ts in the viscous sample per cycle (eV)",
            3,
        ));
    }
    maps
}

/// The grid as one JSON object: the law, both axes, and per observable an array of rows
/// (one per modulus) of values (one per work of adhesion).
pub fn map_json<T: MapRecord>(
    law: &str,
    works: &[f64],
    moduli: &[f64],
    cells: &[T],
) -> Result<serde_json::Value> {
    Ok(serde_json::json!({
        "law": law,
        "work_of_adhesion_j_m2": works,
        "modulus_pa": moduli,
        "grazing_cells": grazing_cells(cells),
        "grid": records::grid_json(cells, works.len())?,
    }))
}

/// How many cells' motion grazes a switch.
pub fn grazing_cells<T: MapRecord>(cells: &[T]) -> usize {
    cells
        .iter()
        .filter(|c| c.plotted().is_some_and(|p| p.2))
        .count()
}
