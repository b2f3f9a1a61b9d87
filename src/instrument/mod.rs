//! **Layer 3 — the instrument around the cantilever**: pieces that read or drive the
//! simulated motion as an AFM's electronics do (lock-in, z feedback, thermal noise,
//! scans, several modes), each a value of its own that watches the integration
//! ([`crate::dynamics::numeric::StepObserver`]) beside the steady-state solver. A new
//! instrument mode is a file here and touches nothing in [`crate::physics`], and in
//! [`crate::dynamics`] at most a new way of moving the lever
//! ([`crate::dynamics::model::Drive`]: the force-curve ramp is one).
//!
//! May import: the foundation, [`crate::physics`], [`crate::dynamics`]. Imported by the
//! analysis and application layers.

pub mod average;
pub mod feedback;
pub mod fm;
pub mod fm_scan;
pub mod force_curve;
pub mod lockin;
pub mod modal;
pub mod noise;
pub mod peakforce;
pub mod peakforce_scan;
pub mod probe;
pub mod qnm;
pub mod repeats;
pub mod sader;
pub mod scan;
pub mod spectrum;
pub mod thermal;

/// The integrator's relative tolerance an instrument marches at unless told otherwise
/// (absolute: 1e-2 of it): the loosest at which the energy balance of the default
/// orbit stays below 1e-6 for the hybrid and the Hertz law (`benches/dynamics.rs`
/// checks it before timing the march), about twice as fast as the steady-state
/// solver's 1e-9.
pub const MARCH_RTOL: f64 = 2e-7;
