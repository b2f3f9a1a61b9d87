//! **Layer 1 — the paper's physics.** Parameters and units of the contact, the closed
//! forms of contact mechanics (JKR, the semi-rigid jump-in, the hybrid law, the
//! compliant support, the Lennard-Jones solution), the tip–sample force laws the
//! cantilever is integrated against, and the quasi-static cycles and their summaries.
//!
//! May import: the foundation ([`crate::error`], [`crate::numeric`]). Imported by every
//! layer above. A new force law is a file in [`law`] and its line in the law
//! registry, [`law::LAWS`].

pub mod contact;
pub mod law;
pub mod params;
pub mod quasistatic;
pub mod summary;
