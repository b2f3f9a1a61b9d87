//! A request to stop long work early: the Python package sets it when Ctrl-C arrives
//! during a call (the command line is stopped by the signal itself). Sweeps, maps and
//! approach curves look at it before each point or cell and end with
//! [`Error::Interrupted`]; whatever was computed is dropped. The request is for the
//! whole process (every run in it stops) until [`clear`].

use crate::error::{Error, Result};
use std::sync::atomic::{AtomicBool, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// Ask every running sweep to stop at its next point.
pub fn request() {
    REQUESTED.store(true, Ordering::SeqCst);
}

/// Withdraw the request (before new work starts).
pub fn clear() {
    REQUESTED.store(false, Ordering::SeqCst);
}

/// [`Error::Interrupted`] where a stop was requested.
pub fn check() -> Result<()> {
    if REQUESTED.load(Ordering::Relaxed) {
        Err(Error::Interrupted)
    } else {
        Ok(())
    }
}
