//! The Python extension `tapsim._tapsim`: tapsim's commands run in this process, on the
//! command line's own parsing, defaults, checks and code paths
//! ([`tapsim::app::cli::run_captured`]), with the GIL released; each command's `--json`
//! document handed to Python as dicts, with numpy arrays for its columns and grids.
//! The package `tapsim` (python/tapsim/__init__.py) builds the arguments from keyword
//! arguments and wraps the dicts in result objects.

use numpy::{IntoPyArray, PyArray2};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;
use serde_json::Value;

/// A refused command as the Python exception it raises: `ValueError` with the command
/// line's message.
fn refusal(r: tapsim::app::cli::Refused) -> PyErr {
    PyValueError::new_err(r.message)
}

/// A command's `--json` document, parsed.
fn document(text: &str) -> PyResult<Value> {
    serde_json::from_str(text)
        .map_err(|e| PyRuntimeError::new_err(format!("tapsim printed no JSON document: {e}")))
}

/// Whether every entry is a number (a column to become a numpy array).
fn all_numbers(items: &[Value]) -> bool {
    !items.is_empty() && items.iter().all(Value::is_number)
}

/// A JSON value as Python: objects as dicts, a list of numbers as a 1-D numpy array
/// (int64 where every entry is an integer, else float64: the same bits as the JSON's
/// numbers), a list of equal-length lists of numbers as a 2-D float64 array, anything
/// else (strings, nulls, mixed) as it is.
fn to_python<'py>(py: Python<'py>, value: Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match value {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
        Value::Number(n) => match n.as_i64() {
            Some(i) => i.into_pyobject(py)?.into_any(),
            None => n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any(),
        },
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Array(items) => {
            if all_numbers(&items) {
                if items.iter().all(Value::is_i64) {
                    let v: Vec<i64> = items.iter().filter_map(Value::as_i64).collect();
                    v.into_pyarray(py).into_any()
                } else {
                    let v: Vec<f64> = items.iter().filter_map(Value::as_f64).collect();
                    v.into_pyarray(py).into_any()
                }
            } else if let Some(rows) = matrix(&items) {
                PyArray2::from_vec2(py, &rows)
                    .map_err(|e| PyRuntimeError::new_err(e.to_string()))?
                    .into_any()
            } else if items.iter().all(Value::is_array) {
                // Rows with gaps (a map's grey cells): plain lists, which the package
                // makes one masked 2-D array.
                let list = PyList::empty(py);
                for item in items {
                    let row = PyList::empty(py);
                    if let Value::Array(values) = item {
                        for x in values {
                            row.append(to_python(py, x)?)?;
                        }
                    }
                    list.append(row)?;
                }
                list.into_any()
            } else {
                let list = PyList::empty(py);
                for item in items {
                    list.append(to_python(py, item)?)?;
                }
                list.into_any()
            }
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (key, item) in map {
                dict.set_item(key, to_python(py, item)?)?;
            }
            dict.into_any()
        }
    })
}

/// Rows of numbers, all of one length (a grid), as floats.
fn matrix(items: &[Value]) -> Option<Vec<Vec<f64>>> {
    let rows: Vec<&Vec<Value>> = items.iter().map(Value::as_array).collect::<Option<_>>()?;
    let width = rows.first()?.len();
    rows.iter()
        .map(|r| {
            (r.len() == width && all_numbers(r))
                .then(|| r.iter().filter_map(Value::as_f64).collect())
        })
        .collect()
}

/// `work` on a thread of its own while this one, the GIL released, waits for it and
/// looks for signals every 50 ms: Ctrl-C asks the work to stop
/// ([`tapsim::interrupt`]: a sweep or map ends at its next point or cell), waits for it
/// to end, and raises KeyboardInterrupt; nothing runs on behind the user's back.
fn interruptible<T: Send + 'static>(
    py: Python<'_>,
    work: impl FnOnce() -> T + Send + 'static,
) -> PyResult<T> {
    use std::sync::mpsc::RecvTimeoutError;
    tapsim::interrupt::clear();
    let (tx, rx) = std::sync::mpsc::channel();
    // (Behind a mutex: the GIL-free closures that wait on it must be Sync.)
    let rx = std::sync::Mutex::new(rx);
    let worker = std::thread::Builder::new()
        .name("tapsim".into())
        .stack_size(8 << 20)
        .spawn(move || {
            let _ = tx.send(work());
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start a thread: {e}")))?;
    let ended = || {
        PyRuntimeError::new_err("tapsim's worker ended without a result (a bug: please report it)")
    };
    loop {
        let wait = |rx: &std::sync::Mutex<std::sync::mpsc::Receiver<T>>| {
            rx.lock()
                .map_err(|_| RecvTimeoutError::Disconnected)?
                .recv_timeout(std::time::Duration::from_millis(50))
        };
        match py.detach(|| wait(&rx)) {
            Ok(value) => {
                let _ = worker.join();
                return Ok(value);
            }
            Err(RecvTimeoutError::Timeout) => {
                if let Err(signal) = py.check_signals() {
                    tapsim::interrupt::request();
                    py.detach(|| {
                        if let Ok(rx) = rx.lock() {
                            let _ = rx.recv();
                        }
                    });
                    let _ = worker.join();
                    tapsim::interrupt::clear();
                    return Err(signal);
                }
            }
            Err(RecvTimeoutError::Disconnected) => return Err(ended()),
        }
    }
}

/// Run `tapsim ARGS` (the words after `tapsim`, `--json` among them) and return its
/// document. The GIL is released while it runs; Ctrl-C stops it (KeyboardInterrupt).
/// Raises ValueError with the command line's message where the command line refuses.
#[pyfunction]
fn run<'py>(py: Python<'py>, args: Vec<String>) -> PyResult<Bound<'py, PyAny>> {
    let text =
        interruptible(py, move || tapsim::app::cli::run_captured(&args))?.map_err(refusal)?;
    to_python(py, document(&text)?)
}

/// Run several commands in parallel (one rayon task each, the GIL released) and return
/// their documents in order; Ctrl-C stops them. Raises ValueError for the first refused
/// one, naming it.
#[pyfunction]
fn run_many<'py>(py: Python<'py>, batch: Vec<Vec<String>>) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let outcomes: Vec<Result<String, tapsim::app::cli::Refused>> = interruptible(py, move || {
        batch
            .par_iter()
            .map(|args| tapsim::app::cli::run_captured(args))
            .collect()
    })?;
    outcomes
        .into_iter()
        .enumerate()
        .map(|(i, outcome)| match outcome {
            Ok(text) => to_python(py, document(&text)?),
            Err(r) => Err(PyValueError::new_err(format!("setup {i}: {}", r.message))),
        })
        .collect()
}

/// The extension module.
#[pymodule]
fn _tapsim(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(run_many, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
