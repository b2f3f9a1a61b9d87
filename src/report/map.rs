//! The `tapsim map` outputs: heat maps of E_ts, φ and A/A₀ over the (Δγ, E*) grid and
//! the grid as JSON (the CSV is the cells as records).

use super::heatmap::{Cell, HeatMap};
use super::records;
use crate::dynamics::observables::TapObservables;
use crate::error::Result;
use crate::sweep::MapCell;

/// Heat maps of E_ts per cycle, phase and A/A₀ over the grid for `law`. The cells come
/// row by row, one row per modulus (as [`map_json`] lays them out).
pub fn heat_maps(law: &str, works: &[f64], moduli: &[f64], cells: &[MapCell]) -> Vec<HeatMap> {
    let map = |title: &str, value_label: &str, value: fn(&TapObservables) -> f64| HeatMap {
        title: format!("{law} law: {title}"),
        x_label: "work of adhesion Δγ (J/m²)".into(),
        y_label: "composite modulus E* (GPa)".into(),
        value_label: value_label.into(),
        x: works.to_vec(),
        y: moduli.iter().map(|e| e * 1e-9).collect(),
        cells: cells
            .chunks(works.len())
            .map(|row| {
                row.iter()
                    .map(|c| {
                        c.observables
                            .as_ref()
                            .map_or(Cell::NotApplicable, |o| Cell::Value {
                                value: value(o),
                                period_one: o.period == Some(1),
                            })
                    })
                    .collect()
            })
            .collect(),
    };
    vec![
        map("dissipation per cycle", "E_ts per cycle (eV)", |o| {
            o.e_ts_ev
        }),
        map("phase", "phase lag φ (deg)", |o| o.phase_deg),
        map("amplitude", "A/A₀", |o| o.amplitude_ratio),
    ]
}

/// The grid as one JSON object: the law, both axes, and per observable an array of rows
/// (one per modulus) of values (one per work of adhesion).
pub fn map_json(
    law: &str,
    works: &[f64],
    moduli: &[f64],
    cells: &[MapCell],
) -> Result<serde_json::Value> {
    Ok(serde_json::json!({
        "law": law,
        "work_of_adhesion_j_m2": works,
        "modulus_pa": moduli,
        "grid": records::grid_json(cells, works.len())?,
    }))
}
