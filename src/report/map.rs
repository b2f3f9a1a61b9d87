//! The `tapsim map` outputs: heat maps of E_ts, φ and A/A₀ over the (Δγ, E*) grid and
//! the grid as JSON (the CSV is the cells as records). Everything is drawn from the
//! cells as records (JSON objects, fields in order), so a map merged from part files
//! ([`super::part`]) gives the same bytes as one computed whole.

use super::heatmap::{Cell, HeatMap};
use super::records;
use crate::error::Result;
use crate::sweep::MapCell;
use serde_json::{Map, Value};

/// The cells as records.
pub fn cell_records(cells: &[MapCell]) -> Result<Vec<Map<String, Value>>> {
    cells.iter().map(records::object).collect()
}

/// Heat maps of E_ts per cycle, phase and A/A₀ over the grid for `law`. The records come
/// row by row, one row per modulus (as [`map_json`] lays them out); a cell without the
/// value (the law does not apply there) is grey.
pub fn heat_maps(
    law: &str,
    works: &[f64],
    moduli: &[f64],
    cells: &[Map<String, Value>],
) -> Vec<HeatMap> {
    let map = |title: &str, value_label: &str, key: &str| HeatMap {
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
                    .map(|c| match c.get(key).and_then(Value::as_f64) {
                        Some(value) => Cell::Value {
                            value,
                            period_one: c.get("period").and_then(Value::as_u64) == Some(1),
                        },
                        None => Cell::NotApplicable,
                    })
                    .collect()
            })
            .collect(),
    };
    vec![
        map("dissipation per cycle", "E_ts per cycle (eV)", "e_ts_ev"),
        map("phase", "phase lag φ (deg)", "phase_deg"),
        map("amplitude", "A/A₀", "amplitude_ratio"),
    ]
}

/// The grid as one JSON object: the law, both axes, and per observable an array of rows
/// (one per modulus) of values (one per work of adhesion).
pub fn map_json(
    law: &str,
    works: &[f64],
    moduli: &[f64],
    cells: &[Map<String, Value>],
) -> Result<Value> {
    Ok(serde_json::json!({
        "law": law,
        "work_of_adhesion_j_m2": works,
        "modulus_pa": moduli,
        "grid": records::grid_json(cells, works.len())?,
    }))
}
