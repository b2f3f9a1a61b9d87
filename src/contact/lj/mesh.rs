//! Graded radial meshes for the Lennard-Jones problem: fine where the contact edge will
//! travel (the tensile annulus there is ~1/(πμ^{3/2}) wide in x = r/√(Rε)), geometrically
//! coarser elsewhere, reaching far enough that the tractions have died out.

use crate::contact::hybrid::JumpIn;
use crate::contact::jkr;
use crate::numeric::distance_to_interval;
use serde::{Deserialize, Serialize};

/// Outer radius of every mesh: f(h̄) there is ~(2/x²)³ ≈ 1e-10.
pub const OUTER_RADIUS: f64 = 50.0;

/// How a mesh is built.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MeshSpec {
    /// Spacing in the fine band.
    pub fine: f64,
    /// Largest spacing between the axis and the band (the tractions of a nearly rigid
    /// contact vary on a scale of ~0.3 there).
    pub coarse: f64,
    /// Largest spacing out to x = 10 beyond the band (where a distant, nearly rigid tip
    /// still feels the force, h̄₀ ≲ 5).
    pub middle: f64,
    /// The fine band [lo, hi].
    pub band: (f64, f64),
    /// Growth ratio of neighbouring elements outside the band.
    pub growth: f64,
}

impl MeshSpec {
    /// The production mesh for Tabor parameter μ: the fine band covers the contact edge
    /// from the JKR jump-out point C to beyond the landing point of the hybrid jump-in
    /// (x_edge = â√μ), with `per_width` elements across the tensile annulus.
    pub fn for_tabor(tabor_mu: f64, per_width: f64) -> Self {
        let width = 1.0 / (std::f64::consts::PI * tabor_mu.powf(1.5));
        let fine = (width / per_width).min(0.01);
        let root = tabor_mu.sqrt();
        let landing = JumpIn::Fit
            .alpha_hat_a(tabor_mu)
            .ok()
            .flatten()
            .and_then(jkr::a_hat_from_separation)
            .unwrap_or(jkr::A_HAT_B);
        let lo = 0.6 * jkr::A_HAT_C * root;
        let hi = 1.25 * landing.max(jkr::pull_off_point().a_hat) * root;
        Self {
            fine,
            coarse: 0.01,
            middle: 0.08,
            band: (lo, hi),
            growth: 1.04,
        }
    }

    /// The same mesh with every spacing multiplied by `factor` (2 for the coarse mesh of
    /// a Richardson estimate).
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            fine: self.fine * factor,
            coarse: self.coarse * factor,
            middle: self.middle * factor,
            ..*self
        }
    }

    /// The nodes, from 0 to [`OUTER_RADIUS`].
    pub fn nodes(&self) -> Vec<f64> {
        let (lo, hi) = self.band;
        // Spacing wanted at x: fine in the band, growing geometrically away from it,
        // capped at `coarse` towards the axis.
        let spacing = |x: f64| -> f64 {
            let d = distance_to_interval(x, lo, hi);
            // Geometric growth with ratio g per element ≈ spacing grows linearly with
            // distance: s(d) = fine + (g − 1) d.
            let s = self.fine + (self.growth - 1.0) * d;
            if x < lo {
                s.min(self.coarse)
            } else if x < 10.0 {
                s.min(self.middle)
            } else {
                s.min(2.0)
            }
        };
        let mut nodes = vec![0.0];
        let mut x = 0.0;
        while x < OUTER_RADIUS {
            // Take the smaller of the spacings at both ends of the step.
            let mut h = spacing(x);
            h = h.min(spacing(x + h));
            x = (x + h).min(OUTER_RADIUS);
            if OUTER_RADIUS - x < 0.5 * h {
                x = OUTER_RADIUS;
            }
            nodes.push(x);
        }
        nodes
    }
}
