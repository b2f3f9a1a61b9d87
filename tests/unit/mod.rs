//! The library's own tests, one file for each module they test, in the layers'
//! folders; they reach the internals through the library's public paths.

mod analysis;
mod app;
mod dynamics;
mod instrument;
mod numeric;
mod physics;
