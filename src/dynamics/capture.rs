//! When Newton's method may finish what marching has begun.
//!
//! Newton's method on the period map converges to an orbit from anywhere in its own
//! basin of convergence, which is not the orbit's basin of attraction: from a state the
//! motion would carry elsewhere it can land on another attractor. The steady state the
//! motion *settles on* is taken from Newton only once the marched motion has come within
//! the orbit's *capture radius*: a neighbourhood in which no period's switching pattern
//! can change, so that the period map is smooth there and contracts onto the orbit.
//!
//! A state δz (∞-norm, units of L) from the orbit moves a turning point of the
//! separation by at most about its amplitude change, √2·|δz|, amplified at most by the
//! transient growth G = max_k ‖Mᵏ‖∞ of the linearised map M (the monodromy matrix) —
//! so while √2·G·|δz| stays below the orbit's grazing margin ([`super::grazing`]) no
//! turning point crosses a switch level. The capture radius is that margin over √2·G.
//! Far from any switch (a large margin) it is wide and Newton's answer is taken at once;
//! for an orbit that grazes a switch it shrinks to nothing, and the answer is what
//! marching reaches.

use super::march::{Phase, Simulation};
use super::motion::SteadyState;
use crate::physics::law::{Branch, ForceLaw};
use nalgebra::{DMatrix, DVector};

/// Powers of the monodromy matrix looked at for transient growth, at most.
const GROWTH_POWERS: usize = 4096;

/// The transient growth max_k ‖Mᵏ‖∞ (k ≥ 0) of a stable monodromy matrix: powers are
/// taken until their norm has fallen below ½ (after which the growth can only repeat
/// smaller), or [`GROWTH_POWERS`] of them.
#[doc(hidden)]
pub fn transient_growth(m: &DMatrix<f64>) -> f64 {
    let norm = |a: &DMatrix<f64>| {
        a.row_iter()
            .map(|r| r.iter().map(|x| x.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    };
    let mut power = m.clone();
    let mut growth: f64 = 1.0;
    for _ in 0..GROWTH_POWERS {
        let n = norm(&power);
        if !n.is_finite() {
            return f64::INFINITY;
        }
        growth = growth.max(n);
        if n < 0.5 {
            break;
        }
        power = &power * m;
    }
    growth
}

/// A stable orbit Newton's method found, waiting for the marched motion to reach it.
pub(crate) struct Candidate {
    /// The steady state over one pass of it.
    pub state: SteadyState,
    /// Its state at the section, where the reported pass starts.
    pub on: Phase,
    /// Its section states, one per drive period of the pass, with their branches.
    points: Vec<(DVector<f64>, Branch)>,
    /// Its capture radius (units of L).
    radius: f64,
}

impl Candidate {
    /// The orbit through `on` (whose steady state is `state`, its monodromy matrix
    /// `monodromy`), with its section states and capture radius: unbounded unless it
    /// grazes a level where the force jumps (`grazing`, [`Simulation::grazing`]), for only
    /// there can a perturbation below the thermal motion change where the motion goes.
    pub(crate) fn new<L: ForceLaw>(
        sim: &Simulation<'_, L>,
        state: SteadyState,
        on: Phase,
        monodromy: &DMatrix<f64>,
        grazing: bool,
    ) -> crate::error::Result<Self> {
        let n = state.window.periods as usize;
        let mut points = Vec::with_capacity(n);
        let mut p = on.clone();
        points.push((sim.z(&p), p.branch));
        for _ in 1..n {
            sim.cycle(&mut p, &mut super::numeric::Ignore)?;
            points.push((sim.z(&p), p.branch));
        }
        let radius = if grazing {
            let margin = state.window.grazing.jump / sim.cpl.a1;
            margin / (std::f64::consts::SQRT_2 * transient_growth(monodromy))
        } else {
            f64::INFINITY
        };
        Ok(Self {
            state,
            on,
            points,
            radius,
        })
    }

    /// Whether `phase` lies within the capture radius of the orbit.
    pub(crate) fn captures<L: ForceLaw>(&self, sim: &Simulation<'_, L>, phase: &Phase) -> bool {
        let z = sim.z(phase);
        self.points
            .iter()
            .any(|(p, branch)| *branch == phase.branch && (&z - p).amax() <= self.radius)
    }

    /// Whether this is the orbit of `other` (a section state of one within `tolerance`
    /// of one of the other's).
    pub(crate) fn same_orbit(&self, other: &Candidate, tolerance: f64) -> bool {
        self.points.len() == other.points.len()
            && self
                .points
                .iter()
                .any(|(p, _)| (p - &other.points[0].0).amax() <= tolerance)
    }
}
