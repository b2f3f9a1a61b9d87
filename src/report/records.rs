//! Records out as CSV (one row each, the fields as columns) or as one JSON object of
//! equal-length arrays, from anything that serialises to a JSON object.

use crate::error::{Error, Result};
use serde::Serialize;
use serde_json::{Map, Value};

/// A record as a JSON object (its fields in order).
pub fn object<T: Serialize>(record: &T) -> Result<Map<String, Value>> {
    let fail = |reason: String| Error::Output {
        path: "records".into(),
        reason,
    };
    match serde_json::to_value(record) {
        Ok(Value::Object(m)) => Ok(m),
        Ok(_) => Err(fail("a record is not an object".into())),
        Err(e) => Err(fail(e.to_string())),
    }
}

/// A record's fields with every nested object's fields brought up beside them, named
/// `outer_inner` (a sweep point's `thermal_average` becomes `thermal_average_e_ts_j`,
/// …): one CSV column each.
fn flat(record: Map<String, Value>) -> Map<String, Value> {
    let mut out = Map::new();
    for (key, value) in record {
        match value {
            Value::Object(inner) => {
                for (k, v) in flat(inner) {
                    out.insert(format!("{key}_{k}"), v);
                }
            }
            v => {
                out.insert(key, v);
            }
        }
    }
    out
}

/// One JSON object whose fields are arrays (one entry per record, null where a record
/// lacks the field), in record-field order. Records are converted one at a time.
pub fn columns_json<T: Serialize>(records: &[T]) -> Result<Value> {
    let mut columns: Vec<(String, Vec<Value>)> = Vec::new();
    for (i, r) in records.iter().enumerate() {
        for (key, value) in object(r)? {
            match columns.iter_mut().find(|(name, _)| *name == key) {
                Some((_, column)) => {
                    column.resize(i, Value::Null);
                    column.push(value);
                }
                None => {
                    let mut column = vec![Value::Null; i];
                    column.push(value);
                    columns.push((key, column));
                }
            }
        }
    }
    Ok(Value::Object(
        columns
            .into_iter()
            .map(|(key, mut column)| {
                column.resize(records.len(), Value::Null);
                (key, Value::Array(column))
            })
            .collect(),
    ))
}

/// The records as CSV, one row each, the fields as columns. Records are turned into
/// JSON objects one at a time (twice: once for the columns, once for the row), so memory
/// holds the CSV text and one record, not every record as an object.
pub fn records_csv<T: Serialize>(records: &[T]) -> Result<Vec<u8>> {
    let fail = |e: csv::Error| Error::Output {
        path: "records.csv".into(),
        reason: e.to_string(),
    };
    let mut keys: Vec<String> = Vec::new();
    for r in records {
        for k in flat(object(r)?).keys() {
            if !keys.contains(k) {
                keys.push(k.clone());
            }
        }
    }
    let mut w = csv::Writer::from_writer(Vec::new());
    if !keys.is_empty() {
        w.write_record(&keys).map_err(fail)?;
        for r in records {
            let row = flat(object(r)?);
            w.write_record(keys.iter().map(|k| match row.get(k) {
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

/// `records` laid out row by row on a grid `columns` wide (row-major, as a map's cells
/// are: one row per value of the slow axis): one object with, per key, an array of rows.
pub fn grid_json<T: Serialize>(records: &[T], columns: usize) -> Result<Value> {
    let Value::Object(flat) = columns_json(records)? else {
        unreachable!("columns_json returns an object")
    };
    let width = columns.max(1);
    Ok(Value::Object(
        flat.into_iter()
            .map(|(key, column)| {
                let Value::Array(values) = column else {
                    unreachable!("columns are arrays")
                };
                // Moved, not copied, into the rows (a 200 × 200 map's columns are large).
                let rows_count = values.len().div_ceil(width);
                let mut values = values.into_iter();
                let rows = (0..rows_count)
                    .map(|_| Value::Array(values.by_ref().take(width).collect()))
                    .collect();
                (key, Value::Array(rows))
            })
            .collect(),
    ))
}
