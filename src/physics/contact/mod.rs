//! Tip–sample contact mechanics of a sphere on a flat: the paper's closed forms.
//!
//! - [`jkr`]: the JKR curve and its jump points, eqs. (3)–(9);
//! - [`semi_rigid`]: Greenwood's semi-rigid jump-in, eqs. (11)–(17);
//! - [`hybrid`]: the hybrid hysteresis loss, eq. (18);
//! - [`spring`]: a support of finite stiffness, eqs. (22)–(27);
//! - [`length_scale`]: the adhesive length scale, eqs. (19)–(21);
//! - [`lj`]: the full Lennard-Jones numerical solution (§3.1);
//! - [`viscoelastic`]: a sphere on a relaxing (standard-linear-solid) half-space,
//!   unloading included (Ting 1966; not in the paper).
//!
//! May import: the foundation and [`crate::physics::params`]. Pure: the Lennard-Jones
//! cache on disk is the application's, handed in as a source.

pub mod hybrid;
pub mod jkr;
pub mod length_scale;
pub mod lj;
pub mod semi_rigid;
pub mod spring;
pub mod viscoelastic;
