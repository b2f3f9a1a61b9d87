//! The full Lennard-Jones numerical solution of the adhesive sphere (the paper's §3.1,
//! docs/src/explanation/design.md §1): the ground truth the hybrid theory is judged against.
//!
//! May import: the foundation and the rest of [`crate::physics::contact`].

pub mod curve;
pub mod kernel;
pub mod moving;
pub mod result;
#[doc(hidden)]
pub mod solver;

pub use moving::Reach;
pub(crate) use result::obtain;
pub use result::{Estimate, LjSolution, solve};
