//! **Layer 5 — the application** (feature `app`, on by default): the command line,
//! configuration files and units, sample files, reports (text, CSV, JSON) and plots
//! (PNG, SVG), the paper's figures and `reproduce`, the on-disk Lennard-Jones cache,
//! sharded runs and their merge. Everything that touches files, the terminal or the
//! environment lives here.
//!
//! May import: every layer below. Imported by nothing in the library (the binary
//! `tapsim` calls [`cli::main`]).

pub mod cli;
pub mod config;
pub mod figures;
pub mod fnv;
pub mod lj_cache;
pub mod report;
pub mod reproduce;
pub mod sample;
pub mod units;
