//! From a measured approach curve back to the material: weighted least squares of
//! simulated steady states against amplitude and phase measured over the piezo position
//! (whose zero, the rest separation's offset, is unknown), by Levenberg–Marquardt
//! (the `levenberg-marquardt` crate, a port of MINPACK's lmder; Moré, 1978), the
//! Jacobian by finite differences of converged steady states; then what the data say of
//! each parameter — the Jacobian's singular values and condition number, the
//! parameters' correlations, linearised 68 % and 95 % intervals, and a flag on any
//! parameter the data do not determine (Chandrashekar et al., Soft Matter 18, 8748,
//! 2022, on why the inverse problem of AM-AFM needs one).
//!
//! [`model`] is the forward model (the curve of a parameter set), [`search`] the global
//! stage (a design of starts, each aligned on the data's onset of contact), [`solve`]
//! the fit (local Levenberg–Marquardt runs from the best starts), [`identifiability`]
//! what its Jacobian says, [`diagnose`] whether the fit describes the data, [`select`]
//! which law the data support (AIC, BIC) and [`progress`] what a running fit reports.
//!
//! May import: every library layer below and the rest of [`crate::analysis`]; no I/O
//! (progress is reported to a callback).

pub mod diagnose;
#[doc(hidden)]
pub mod features;
pub mod identifiability;
#[doc(hidden)]
pub mod local;
pub mod model;
pub mod progress;
pub mod search;
pub mod select;
pub mod solve;

pub use diagnose::Diagnosis;
pub use identifiability::{Identifiability, ParameterEstimate};
pub use model::{Curve, Measured, Nuisance, Parameter, SecondMode};
pub use progress::{Progress, Stage};
pub use search::Search;
pub use select::{LawComparison, compare};
pub use solve::{FitOptions, FitReport, Minimum, Profile, fit, profile};
