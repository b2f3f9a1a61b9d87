//! tapsim: tapping-mode AFM with adhesion hysteresis done right.
//!
//! The physics follows Ciavarella, Greenwood & Barber, "Effect of Tabor parameter on
//! hysteresis losses during adhesive contact"; equation numbers in the documentation
//! are that paper's. Data flows one way: [`params`] → [`contact`] (force laws) →
//! [`law`] → [`dynamics`] / [`quasistatic`] → [`instrument`] → [`sweep`] / [`setpoint`] →
//! [`identification`] →
//! [`figures`] → [`report`].

#![forbid(unsafe_code)]
#![warn(missing_docs)]

// The physics library: no file system, no environment, no command line.
pub mod bimodal;
pub mod coexist;
pub mod contact;
pub mod contrast;
pub mod dynamics;
pub mod error;
pub mod fit;
pub mod identification;
pub mod instrument;
pub mod interrupt;
pub mod law;
pub mod numeric;
pub mod params;
pub mod quasistatic;
pub mod reconstruct;
pub mod setpoint;
pub mod summary;
pub mod sweep;

// The application on top (feature `app`, on by default).
#[cfg(feature = "app")]
pub mod cli;
#[cfg(feature = "app")]
pub mod config;
#[cfg(feature = "app")]
pub mod figures;
#[cfg(feature = "app")]
pub mod fnv;
#[cfg(feature = "app")]
pub mod lj_cache;
#[cfg(feature = "app")]
pub mod report;
#[cfg(feature = "app")]
pub mod reproduce;
#[cfg(feature = "app")]
pub mod sample;
#[cfg(feature = "app")]
pub mod units;

pub use contact::lj::{LjSolution, Reach};
pub use dynamics::observables::{Observe, TapObservables, TapRun, tap};
pub use dynamics::setup::{Cantilever, Numerics, TapSetup, default_setup};
pub use error::{Error, Result};
pub use law::{LawKind, LawSpec};
pub use params::Contact;
pub use summary::{HysteresisSummary, LjSummary};

/// The README's Rust blocks, compiled and run as doctests so its numbers stay true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
