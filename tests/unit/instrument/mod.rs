//! Tests of the `instrument` layer's modules.

mod average;
mod lockin;
mod repeats;
mod sader;
mod scan;
mod spectrum;
mod thermal;
