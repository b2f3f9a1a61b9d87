//! Tests of the `dynamics` layer's modules.

mod budget;
mod capture;
mod dopri5;
mod free;
mod free_steps;
mod grazing;
mod harmonics;
mod march;
mod model;
mod modes_set;
mod numeric;
mod setup;
