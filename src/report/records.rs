//! Records out as CSV (one row each, the fields as columns) or as one JSON object of
//! equal-length arrays, from anything that serialises to a JSON object.

use crate::error::{Error, Result};
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
