//! The instrument around the cantilever: pieces that read or drive the simulated motion
//! as an AFM's electronics do, each a value of its own that watches the integration
//! ([`crate::dynamics::numeric::StepObserver`]) beside the steady-state solver.

pub mod average;
pub mod feedback;
pub mod lockin;
pub mod modal;
pub mod noise;
pub mod probe;
pub mod repeats;
pub mod scan;
pub mod spectrum;
pub mod thermal;

/// The integrator's relative tolerance an instrument marches at unless told otherwise
/// (absolute: 1e-2 of it): the loosest at which the energy balance of the default
/// orbit stays below 1e-6 for the hybrid and the Hertz law (`benches/dynamics.rs`
/// checks it before timing the march), about twice as fast as the steady-state
/// solver's 1e-9.
pub const MARCH_RTOL: f64 = 2e-7;
