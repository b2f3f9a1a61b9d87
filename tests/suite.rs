//! The integration tests, built as one binary: one link of the library instead of one
//! per file, and the two test threads kept busy across files. Each file is a module
//! (`cargo test --release lj::` runs tests/lj.rs); the slow checks are `#[ignore]`d
//! (`cargo test --release -- --ignored`).

mod common;

mod architecture;
mod bimodal;
mod cli;
mod coexist;
mod continuation;
mod docs;
mod dynamics;
mod files;
mod fit;
mod fit_cli;
mod fit_global;
mod fm;
mod fm_scan;
mod force_curve;
mod grazing;
mod gwyddion;
mod hostile;
mod hybrid;
mod identification;
mod instrument;
mod interrupt;
mod jkr;
mod lj;
mod lj_kernel;
mod modes;
mod modes_cli;
mod noise;
mod peakforce;
mod readback;
mod reconstruct;
mod reconstruct_cli;
mod relaxing;
mod repeats;
mod semi_rigid;
mod setpoint;
mod slurm;
mod spring;
mod steady;
mod sweep;
mod thermal;
mod tour;
mod unit;
