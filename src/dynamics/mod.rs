//! Tapping-mode dynamics: a point-mass cantilever against a hysteretic tip–sample force
//! law, with located branch switches, steady-state detection and the observables of one
//! steady cycle (docs/design.md §2).

pub mod attractors;
pub mod base_drive;
pub mod budget;
mod capture;
pub mod continuation;
mod dopri5;
pub mod free;
pub mod gradient;
pub mod grazing;
pub mod harmonic_balance;
pub mod harmonics;
pub mod march;
pub mod model;
pub mod modes;
pub mod motion;
pub mod numeric;
pub mod observables;
pub mod observed;
mod recurrence;
pub mod setup;
pub mod shooting;
pub mod steady;
pub mod window;
