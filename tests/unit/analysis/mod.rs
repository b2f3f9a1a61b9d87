//! Tests of the `analysis` layer's modules.

mod fit_local;
mod fit_search;
mod fit_solve;
