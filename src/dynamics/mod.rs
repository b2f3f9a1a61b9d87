//! **Layer 2 — the cantilever.** Tapping-mode dynamics: a point-mass cantilever (and
//! its higher modes, [`modes`]) against a hysteretic tip–sample force law, marched with
//! every branch switch located ([`march`]); periodic orbits by shooting, irregular
//! motion by windows, the attractors at a separation, continuation of orbit families,
//! and the observables of one steady cycle (docs/src/explanation/design.md §2).
//!
//! May import: the foundation and [`crate::physics`]. Imported by the instrument,
//! analysis and application layers.

pub mod attractors;
pub mod base_drive;
pub mod budget;
#[doc(hidden)]
pub mod capture;
pub mod continuation;
#[doc(hidden)]
pub mod dopri5;
pub mod free;
pub mod free_steps;
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
pub mod observer;
mod recurrence;
pub mod setup;
pub mod shooting;
pub mod steady;
pub mod surface;
pub mod window;
