//! **Layer 4 — what the simulations are run for.** Amplitude setpoints and the states at
//! them, sweeps (approach curves, maps, ramps), phase contrast between materials, the
//! coexisting states at a separation, bimodal contrast, identification of the
//! material, force reconstruction and fitting measured curves.
//!
//! May import: the foundation, [`crate::physics`], [`crate::dynamics`],
//! [`crate::instrument`]. Imported by the application ([`crate::app`]) and the Python
//! binding. No I/O: progress and interruption come in as values.

pub mod bimodal;
pub mod coexist;
pub mod contrast;
pub mod fit;
pub mod fm;
pub mod identification;
pub mod qnm_map;
pub mod reconstruct;
pub mod setpoint;
pub mod sweep;
