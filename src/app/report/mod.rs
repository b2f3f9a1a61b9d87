//! Everything that leaves tapsim: charts (PNG, SVG), CSV tables, JSON objects and the
//! human-readable summaries. Files are written whole or not at all.
//!
//! May import: the library and the rest of [`crate::app`] but [`crate::app::cli`];
//! computes no physics.

pub mod bifurcation;
pub mod branches;
pub mod chart;
pub mod contrast;
pub mod display;
pub mod fit;
pub mod fit_text;
pub mod gwyddion;
pub mod heatmap;
pub mod hysteresis;
pub mod lj;
pub mod map;
pub mod modes;
pub mod output;
pub mod part;
pub mod plot;
pub mod reconstruct;
pub mod records;
pub mod sweep;
pub mod tap;
