//! The quasi-static loading–unloading cycle of the hybrid contact behind a support of
//! finite stiffness (the paper's Fig. 5): the support is moved in from far out, the tip
//! jumps in at A and lands at B, the contact is loaded into compression and unloaded,
//! the tip jumps out at C and lands at D, and the support retracts.

use crate::error::{Error, Result};
use crate::physics::contact::hybrid::JumpIn;
use crate::physics::contact::jkr::{self, ForceBranch, JkrPoint};
use crate::physics::contact::spring::{self, SpringHysteresis};
use serde::Serialize;

/// The part of the cycle a path point belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Segment {
    /// Force-free approach down to A; the jump A → B follows at fixed support position.
    Approach,
    /// Along the contact branch from B into compression.
    Loading,
    /// Back along the contact branch to C; the jump C → D follows at fixed support
    /// position.
    Unloading,
    /// Force-free retraction from D.
    Retract,
}

/// One point of the cycle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PathPoint {
    /// Support separation α̂_S = α̂ + T̂/k̂, eq. (22).
    pub support_alpha_hat: f64,
    /// Tip–sample separation α̂.
    pub alpha_hat: f64,
    /// Force T̂ (tensile positive).
    pub t_hat: f64,
    /// Which part of the cycle.
    pub segment: Segment,
}

/// A sampled quasi-static cycle with the closed-form result it must reproduce.
#[derive(Debug, Clone, Serialize)]
pub struct Cycle {
    /// Closed-form hysteresis of the same system, eq. (26).
    pub hysteresis: SpringHysteresis,
    /// The path, in the order the support traverses it.
    pub points: Vec<PathPoint>,
}

impl Cycle {
    /// Work done by the support over the closed path, ∮ T̂ dα̂_S (trapezoid rule on the
    /// samples; the jumps, at fixed α̂_S, do no work). Converges to eq. (26).
    pub fn enclosed_area(&self) -> f64 {
        let p = &self.points;
        p.iter()
            .zip(p.iter().cycle().skip(1))
            .map(|(a, b)| 0.5 * (a.t_hat + b.t_hat) * (b.support_alpha_hat - a.support_alpha_hat))
            .sum()
    }
}

/// Sample the whole cycle for Tabor parameter μ and support stiffness k̂, with
/// `samples` points on each contact segment (at least 2). The contact is loaded until
/// the compressive force equals the pull-off force 3π/2.
pub fn cycle(tabor_mu: f64, k_hat: f64, jump_in: JumpIn, samples: usize) -> Result<Cycle> {
    let hysteresis = spring::hysteresis(tabor_mu, k_hat, jump_in)?;
    let (Some(alpha_hat_a), Some(b)) = (hysteresis.alpha_hat_a, hysteresis.landing) else {
        return Err(Error::NotApplicable(
            hysteresis
                .no_hysteresis_reason
                .clone()
                .unwrap_or_else(|| "no hysteresis".into()),
        ));
    };
    let samples = samples.max(2);
    let c = hysteresis.jump_out;
    let deepest = jkr::a_hat_from_force(-jkr::PULL_OFF_T_HAT, ForceBranch::LoadStable)
        .ok_or_else(|| Error::Numerical("deepest loading point".into()))?;
    let at = |p: JkrPoint, segment| PathPoint {
        support_alpha_hat: spring::support_separation_hat(&p, k_hat),
        alpha_hat: p.alpha_hat,
        t_hat: p.t_hat,
        segment,
    };
    let free = |alpha_hat: f64, segment| PathPoint {
        support_alpha_hat: alpha_hat,
        alpha_hat,
        t_hat: 0.0,
        segment,
    };
    let start = alpha_hat_a.max(hysteresis.support_alpha_hat_c) + 0.5;
    let sweep = |from: f64, to: f64, segment| {
        (0..samples).map(move |i| {
            let a = from + (to - from) * i as f64 / (samples - 1) as f64;
            at(JkrPoint::at(a), segment)
        })
    };
    let mut points = vec![
        free(start, Segment::Approach),
        free(alpha_hat_a, Segment::Approach),
    ];
    points.extend(sweep(b.a_hat, deepest, Segment::Loading));
    points.extend(sweep(deepest, c.a_hat, Segment::Unloading).skip(1));
    points.push(free(hysteresis.support_alpha_hat_c, Segment::Retract));
    Ok(Cycle { hysteresis, points })
}
