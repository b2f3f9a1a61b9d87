//! The instrument around the cantilever: pieces that read or drive the simulated motion
//! as an AFM's electronics do, each a value of its own that watches the integration
//! ([`crate::dynamics::numeric::StepObserver`]) beside the steady-state solver.

pub mod feedback;
pub mod lockin;
pub mod scan;
