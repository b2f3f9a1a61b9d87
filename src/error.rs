//! The one error type of the library: every failure is a value with a message
//! a user can act on, never a panic.

use std::path::PathBuf;

/// Errors raised by tapsim. New kinds may be added: match with a wildcard arm.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A parameter is outside its physical domain (NaN, negative, zero, ...).
    #[error("invalid {name} = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name as a user would type it.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// What the value must satisfy.
        reason: &'static str,
    },
    /// A text value (command-line or config) could not be read as a quantity.
    #[error("cannot read {name} from {:?}: {reason}", abbreviate(text, 60))]
    Parse {
        /// Parameter name.
        name: &'static str,
        /// The text given.
        text: String,
        /// Why it was rejected.
        reason: String,
    },
    /// A model was asked for a result outside the range where it applies.
    #[error("{0}")]
    NotApplicable(String),
    /// A value is outside what an AFM can be or what tapsim resolves (a tip radius of
    /// 1 mm, Q = 0.1): refused for the whole run, never turned into a per-cell note as a
    /// law that does not apply at one cell's μ is.
    #[error("{0}")]
    OutOfRange(String),
    /// The Lennard-Jones force–separation curve has no loop at this μ: approach and
    /// retraction follow one curve and nothing is lost (a result, not a failure, for
    /// `tapsim lj`).
    #[error("{0}")]
    NoHysteresis(String),
    /// A numerical procedure failed to converge or bracket its solution.
    #[error("numerical failure: {0}")]
    Numerical(String),
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// Producing an output (plot, CSV, JSON) failed.
    #[error("cannot write {path}: {reason}")]
    Output {
        /// The file concerned.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// The work was asked to stop ([`crate::interrupt`]).
    #[error("interrupted")]
    Interrupted,
    /// Standard output was closed by its reader (`tapsim … | head`): not a failure of
    /// tapsim's; the command ends quietly.
    #[error("standard output was closed")]
    StdoutClosed,
}

/// `text` cut to its first `max` characters (with "…") when longer: long inputs are not
/// echoed whole in messages.
pub(crate) fn abbreviate(text: &str, max: usize) -> std::borrow::Cow<'_, str> {
    match text.char_indices().nth(max) {
        Some((cut, _)) => format!("{}… ({} characters)", &text[..cut], text.chars().count()).into(),
        None => text.into(),
    }
}

/// Result alias used throughout tapsim.
pub type Result<T> = std::result::Result<T, Error>;

/// Check that `value` is finite and strictly positive.
pub fn positive(name: &'static str, value: f64) -> Result<f64> {
    if !value.is_finite() {
        return Err(Error::InvalidParameter {
            name,
            value,
            reason: "must be a finite number",
        });
    }
    if value <= 0.0 {
        return Err(Error::InvalidParameter {
            name,
            value,
            reason: "must be greater than zero",
        });
    }
    Ok(value)
}

/// Check that `value` is a finite number.
pub fn finite(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            name,
            value,
            reason: "must be a finite number",
        })
    }
}
