//! Several cantilever eigenmodes sharing one tip–sample force (bimodal AFM: Rodríguez &
//! García, APL 84, 449, 2004; Lozano & García, PRL 100, 076102, 2008): the modes and
//! their defaults ([`set`]), the equations of motion and one period through the law's
//! switches ([`system`]), the periodic orbit ([`orbit`]) and what it reports
//! ([`observables`]), or, for drives with no common period, averages over a window
//! ([`window`]). A value beside the one-mode steady-state solver, not a branch in
//! it: one mode is tapsim's point-mass model, untouched.
//!
//! May import: the foundation, [`crate::physics`] and the rest of [`crate::dynamics`].

pub mod observables;
pub mod orbit;
pub mod set;
pub mod system;
pub mod window;

pub use observables::{
    ModalObservables, ModeObservables, modal_steady, prepare, tap_modes, with_modes,
};
pub use set::{Eigenmode, MAX_MODES, Modal, ModeSet};
pub use window::{WindowedMode, WindowedModes, modal_windowed};
