//! tapsim: tapping-mode AFM with adhesion hysteresis done right.
//!
//! The physics follows Ciavarella, Greenwood & Barber, "Effect of Tabor parameter on
//! hysteresis losses during adhesive contact"; equation numbers in the documentation
//! are that paper's.
//!
//! # The plan of the house
//!
//! The folders are the layers, and data flows one way, up:
//!
//! | layer | folder | what lives there |
//! |---|---|---|
//! | 0 | [`error`], [`numeric`], [`interrupt`] | errors, root finders and quadrature, the stop flag |
//! | 1 | [`physics`] | parameters, contact mechanics, force laws, quasi-static cycles: the paper |
//! | 2 | [`dynamics`] | the cantilever: march, periodic orbits, attractors, modes |
//! | 3 | [`instrument`] | lock-in, feedback, noise, scans, the instrument's modes |
//! | 4 | [`analysis`] | setpoints, sweeps, contrast, identification, reconstruction, fit |
//! | 5 | `app` (feature `app`) | command line, configuration, reports and plots, figures, caches |
//!
//! A module imports only from its own layer or below, and no two modules import each
//! other, directly or round a circle (`tests/architecture.rs` checks both). Layers 0–4
//! are the physics library: no file system, no environment, no terminal; progress and
//! interruption are passed down as values. Without the `app` feature
//! (`--no-default-features`) the crate is that library alone, without the application's
//! dependencies. Where a new piece goes: a force law is a file in [`physics::law`]; an
//! instrument mode a file in [`instrument`]; a way of using the simulations a file in
//! [`analysis`]; a command a file in `app/cli/`.
//!
//! The library's own tests are in the test program, one file for each module they test
//! (`tests/unit/<layer>/`), so that `cargo test` links the library the run built instead
//! of compiling it again with them. What they test beneath the API is public but hidden
//! from these pages (`#[doc(hidden)]`): not an API, and free to change.
//!
//! # Where to start
//!
//! The user guide is the book in `docs/` (by task: how-to guides, explanation,
//! reference, validation); its library page runs these layers from Rust. The entry
//! points, one a layer:
//!
//! - the paper: [`contact::hybrid`], [`contact::jkr`] and [`contact::lj`] (the
//!   quasi-static cycles and their losses), [`law::LawKind`] (the force laws);
//! - the cantilever: [`tap`] on a [`TapSetup`] ([`default_setup`] is the built-in one)
//!   gives the steady state and what a lock-in reads of it ([`TapObservables`]);
//! - the instrument: [`instrument::lockin`], [`instrument::feedback`],
//!   [`instrument::scan`], [`instrument::thermal`], [`instrument::force_curve`];
//! - its uses: [`analysis::setpoint`] (states at a setpoint), [`analysis::contrast`],
//!   [`analysis::fit`].

#![forbid(unsafe_code)]
#![warn(missing_docs)]

// Layer 0: the foundation.
pub mod error;
pub mod interrupt;
pub mod numeric;

// Layers 1–4: the physics library.
pub mod analysis;
pub mod dynamics;
pub mod instrument;
pub mod physics;

// Layer 5: the application on top (feature `app`, on by default).
#[cfg(feature = "app")]
pub mod app;

// The paths of the flat layout before the layers, kept so that code written against
// them builds: deprecated, use the layered paths above.
#[doc(hidden)]
pub use analysis::{bimodal, coexist, contrast, fit, identification, reconstruct, setpoint, sweep};
#[cfg(feature = "app")]
#[doc(hidden)]
pub use app::{cli, config, figures, fnv, lj_cache, report, reproduce, sample, units};
#[doc(hidden)]
pub use physics::{contact, law, params, quasistatic, summary};

pub use dynamics::observables::{Observe, TapObservables, TapRun, tap};
pub use dynamics::setup::{Cantilever, Numerics, TapSetup, default_setup};
pub use error::{Error, Result};
pub use physics::contact::lj::{LjSolution, Reach};
pub use physics::law::{LawKind, LawSpec};
pub use physics::params::Contact;
pub use physics::summary::{HysteresisSummary, LjSummary};

/// The user guide's Rust blocks (docs/src/reference/library.md), compiled and run as
/// doctests so its numbers stay true.
#[cfg(doctest)]
#[doc = include_str!("../docs/src/reference/library.md")]
pub struct GuideDoctests;
