//! The `tapsim map` outputs: heat maps of E_ts, φ and A/A₀ over the (Δγ, E*) grid and
//! the grid as JSON (the CSV is the cells as records). They are drawn from anything
//! that serialises to a cell's record and answers for its values ([`MapRecord`]): the
//! cells as computed, or their records read back from part files ([`super::part`]), so a
//! merged map gives the same bytes as one computed whole.

use super::heatmap::{Cell, HeatMap};
use super::records;
use crate::error::Result;
use crate::sweep::MapCell;
use serde::Serialize;
use serde_json::value::RawValue;

/// A map cell's values by their record's key.
pub trait MapRecord: Serialize {
    /// The number under `key` (`None` where the law does not apply).
    fn number(&self, key: &str) -> Option<f64>;
}

impl MapRecord for MapCell {
    fn number(&self, key: &str) -> Option<f64> {
        let o = self.observables.as_ref()?;
        match key {
            "e_ts_ev" => Some(o.e_ts_ev),
            "phase_deg" => Some(o.phase_deg),
            "amplitude_ratio" => Some(o.amplitude_ratio),
            "period" => o.period.map(|p| p as f64),
            _ => None,
        }
    }
}

impl MapRecord for Box<RawValue> {
    fn number(&self, key: &str) -> Option<f64> {
        let record: serde_json::Map<String, serde_json::Value> =
            serde_json::from_str(self.get()).ok()?;
        record.get(key)?.as_f64()
    }
}

/// Heat maps of E_ts per cycle, phase and A/A₀ over the grid for `law`. The records come
/// row by row, one row per modulus (as [`map_json`] lays them out); a cell without the
/// value (the law does not apply there) is grey.
pub fn heat_maps<T: MapRecord>(
    law: &str,
    works: &[f64],
    moduli: &[f64],
    cells: &[T],
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
                    .map(|c| match c.number(key) {
                        Some(value) => Cell::Value {
                            value,
                            period_one: c.number("period") == Some(1.0),
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
pub fn map_json<T: Serialize>(
    law: &str,
    works: &[f64],
    moduli: &[f64],
    cells: &[T],
) -> Result<serde_json::Value> {
    Ok(serde_json::json!({
        "law": law,
        "work_of_adhesion_j_m2": works,
        "modulus_pa": moduli,
        "grid": records::grid_json(cells, works.len())?,
    }))
}
