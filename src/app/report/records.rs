//! Records out as CSV (one row each, the fields as columns) or as one JSON object of
//! equal-length arrays, from anything that serialises to a JSON object; and the one
//! document every `--json` prints.
//!
//! The JSON conventions (docs/src/reference/output.md): every document is one object whose first key
//! is `format_version` ([`FORMAT_VERSION`]); a single result's fields are its keys; many
//! results are columns (one array per field, one entry per result); a map is its axes
//! plus a `grid` of rows. A numerical error estimate is a sibling key `<name>_error`, a
//! statistical standard error `<name>_std_err…`, both in the value's unit. JSON keeps
//! every digit; CSV rounds each value to [`CSV_DIGITS`] significant digits, so a 90 that
//! round-off made 89.99999999999999 reads as 90.

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

/// The version of the JSON conventions every `--json` document follows (its first key).
/// 2: every document is an object with this key; contrast's rows became columns;
/// `reproduce` gained `lj_mu5`.
pub const FORMAT_VERSION: u32 = 2;

/// The significant digits of a CSV value: more than any result here is converged to,
/// fewer than the 17 that show binary round-off.
pub const CSV_DIGITS: usize = 10;

/// `value` as one JSON document: an object with `format_version` first, then the value's
/// own keys, pretty-printed (serialised in place: a 200 × 200 map is not copied). An
/// error if `value` is not an object.
pub fn document<T: Serialize>(value: &T) -> Result<String> {
    #[derive(Serialize)]
    struct Document<'a, T> {
        format_version: u32,
        #[serde(flatten)]
        body: &'a T,
    }
    serde_json::to_string_pretty(&Document {
        format_version: FORMAT_VERSION,
        body: value,
    })
    .map_err(|e| Error::Output {
        path: "JSON document".into(),
        reason: e.to_string(),
    })
}

/// A number as a CSV cell: [`CSV_DIGITS`] significant digits in the shortest form that
/// reads back as the rounded value (`90`, `2.358974359e-8`), zero (negative zero too) as
/// `0`, integers whole. Not finite (never a result) as `NaN`/`inf` for the reader to
/// refuse.
pub fn csv_number(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    if !x.is_finite() {
        return x.to_string();
    }
    let rounded: f64 = format!("{x:.*e}", CSV_DIGITS - 1)
        .parse()
        .expect("a formatted float parses");
    let text = Value::from(rounded).to_string();
    match text.strip_suffix(".0") {
        Some(whole) => whole.to_string(),
        None => text,
    }
}

/// A JSON value as a CSV cell: a string as it is, null as empty, a float by
/// [`csv_number`].
fn cell(value: &Value) -> String {
    match value {
        Value::String(s) => s.clone(),
        Value::Null => String::new(),
        Value::Number(n) if n.is_f64() => csv_number(n.as_f64().expect("an f64")),
        v => v.to_string(),
    }
}

/// Keys whose values are complex numbers as `[re, im]` pairs (a CSV column each part).
const COMPLEX_ARRAYS: [&str; 1] = ["floquet_multipliers"];

/// A record's fields with every nested object's fields brought up beside them, named
/// `outer_inner` (a sweep point's `thermal_average` becomes `thermal_average_e_ts_j`,
/// …), and every array's entries too, numbered from 1 (`materials_1`; the complex
/// `floquet_multipliers` as `floquet_multipliers_1_re`, `…_1_im`): one CSV column each,
/// no JSON inside a cell.
fn flat(record: Map<String, Value>) -> Map<String, Value> {
    fn put(out: &mut Map<String, Value>, key: String, value: Value) {
        match value {
            Value::Object(inner) => {
                for (k, v) in inner {
                    put(out, format!("{key}_{k}"), v);
                }
            }
            Value::Array(items) => {
                let complex = COMPLEX_ARRAYS.iter().any(|c| key.ends_with(c));
                for (i, v) in items.into_iter().enumerate() {
                    match (complex, v) {
                        (true, Value::Array(parts)) if parts.len() == 2 => {
                            let [re, im] = <[Value; 2]>::try_from(parts).expect("two parts");
                            out.insert(format!("{key}_{}_re", i + 1), re);
                            out.insert(format!("{key}_{}_im", i + 1), im);
                        }
                        (_, v) => put(out, format!("{key}_{}", i + 1), v),
                    }
                }
            }
            v => {
                out.insert(key, v);
            }
        }
    }
    let mut out = Map::new();
    for (key, value) in record {
        put(&mut out, key, value);
    }
    out
}

/// Records (computed, or read back from part files) as the values they hold; `what`
/// names their kind where one is not.
pub fn typed<T: Serialize, U: serde::de::DeserializeOwned>(
    records: &[T],
    what: &str,
) -> Result<Vec<U>> {
    records
        .iter()
        .map(|r| {
            serde_json::to_value(r)
                .and_then(serde_json::from_value)
                .map_err(|e| {
                    Error::NotApplicable(format!("a record that is not a {what} one: {e}"))
                })
        })
        .collect()
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
            w.write_record(keys.iter().map(|k| row.get(k).map_or(String::new(), cell)))
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
