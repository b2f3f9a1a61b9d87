//! The work budget of one steady state: however hostile the parameters (a cantilever
//! a million times softer than the contact, a drive far below resonance, a tolerance at
//! round-off), a computation ends within seconds, with an error that says why, instead
//! of integrating for hours.
//!
//! Work is counted in integrator steps (and one per drive period, so that closed-form
//! free flights count too) on the thread doing it. `budgeted` gives a computation its
//! budget ([`STEPS`] unless a caller asks for more); computations nested inside it share
//! that budget.

use crate::error::{Error, Result};
use std::cell::Cell;

/// The default number of integrator steps one steady state (one setpoint of a sweep)
/// may take: one to three seconds of work. A well-posed tapping problem takes 10³–10⁶.
pub const STEPS: u64 = 5_000_000;

thread_local! {
    static LEFT: Cell<Option<u64>> = const { Cell::new(None) };
    static TOTAL: Cell<u64> = const { Cell::new(0) };
}

/// Ends the budget when the computation that set it ends, however it ends.
struct Reset;

impl Drop for Reset {
    fn drop(&mut self) {
        LEFT.set(None);
    }
}

/// Run `f` with a budget of `steps`, unless it runs inside a budgeted computation
/// already (then it spends from that one).
#[doc(hidden)]
pub fn budgeted<T>(steps: u64, f: impl FnOnce() -> Result<T>) -> Result<T> {
    if LEFT.get().is_some() {
        return f();
    }
    LEFT.set(Some(steps));
    TOTAL.set(steps);
    let _reset = Reset;
    f()
}

/// Steps left (unlimited outside a budgeted computation).
#[doc(hidden)]
pub fn left() -> u64 {
    LEFT.get().unwrap_or(u64::MAX)
}

/// Spend `steps`; an error once the budget is exhausted.
#[doc(hidden)]
pub fn spend(steps: u64) -> Result<()> {
    if let Some(left) = LEFT.get() {
        if steps > left {
            LEFT.set(Some(0));
            return Err(exhausted());
        }
        LEFT.set(Some(left - steps));
    }
    Ok(())
}

/// The error of an exhausted budget (which it leaves spent: [`left`] is 0 after it).
pub(crate) fn exhausted() -> Error {
    if LEFT.get().is_some() {
        LEFT.set(Some(0));
    }
    Error::Numerical(format!(
        "gave up after {} integration steps (the work budget of one steady state): \
         the motion is too costly to resolve with these parameters. Usual causes: a \
         cantilever far softer than the contact (raise its stiffness), a drive far from \
         resonance, a Q far outside 1 to 10⁶, or a relative tolerance (rtol) near round-off",
        TOTAL.get()
    ))
}
