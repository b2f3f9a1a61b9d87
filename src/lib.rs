//! tapsim: tapping-mode AFM with adhesion hysteresis done right.
//!
//! The physics follows Ciavarella, Greenwood & Barber, "Effect of Tabor parameter on
//! hysteresis losses during adhesive contact"; equation numbers in the documentation
//! are that paper's. Data flows one way: [`params`] → [`contact`] (force laws) →
//! [`law`] → [`dynamics`] / [`quasistatic`] → [`sweep`] → [`figures`] → [`report`].

#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod cli;
pub mod config;
pub mod contact;
pub mod contrast;
pub mod dynamics;
pub mod error;
pub mod figures;
pub mod law;
pub mod lj_cache;
pub mod numeric;
pub mod params;
pub mod quasistatic;
pub mod report;
pub mod reproduce;
pub mod sweep;
pub mod units;

pub use error::{Error, Result};

/// The README's Rust blocks, compiled and run as doctests so its numbers stay true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
