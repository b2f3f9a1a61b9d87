//! What watches the integration: the sample at each end of an accepted step
//! ([`StepEnd`]), the observer told of every step and every closed-form free flight
//! ([`StepObserver`]; trajectory recording, extremes, harmonics, the lock-ins and
//! feedback of the instrument), and the cubic Hermite interpolant on a step that
//! observers read between its ends.

use super::model::{BASE, State};
use crate::physics::law::Branch;
use std::ops::Index;

/// A sample of the trajectory at the end of an accepted step.
#[derive(Debug, Clone, Copy)]
pub struct StepEnd<const N: usize = BASE> {
    /// τ.
    pub tau: f64,
    /// State.
    pub y: State<N>,
    /// Its derivative.
    pub dy: State<N>,
}

/// Per-step observer (trajectory recording and extrema).
pub trait StepObserver {
    /// Called for each accepted step [from, to] of the branch `branch`.
    fn step<const N: usize>(&mut self, from: &StepEnd<N>, to: &StepEnd<N>, branch: Branch);
    /// Called for each closed-form free flight from τ `from` to `to`.
    fn free_flight(&mut self, _flight: &super::free::FreeFlight, _from: f64, _to: f64) {}
}

/// An observer that ignores everything.
pub struct Ignore;

impl StepObserver for Ignore {
    fn step<const N: usize>(&mut self, _: &StepEnd<N>, _: &StepEnd<N>, _: Branch) {}
}

/// An observer lent out: the owner reads it afterwards.
impl<O: StepObserver> StepObserver for &mut O {
    fn step<const N: usize>(&mut self, from: &StepEnd<N>, to: &StepEnd<N>, branch: Branch) {
        (**self).step(from, to, branch);
    }
    fn free_flight(&mut self, flight: &super::free::FreeFlight, from: f64, to: f64) {
        (**self).free_flight(flight, from, to);
    }
}

/// Two observers watching the same integration, each told everything.
impl<A: StepObserver, B: StepObserver> StepObserver for (A, B) {
    fn step<const N: usize>(&mut self, from: &StepEnd<N>, to: &StepEnd<N>, branch: Branch) {
        self.0.step(from, to, branch);
        self.1.step(from, to, branch);
    }
    fn free_flight(&mut self, flight: &super::free::FreeFlight, from: f64, to: f64) {
        self.0.free_flight(flight, from, to);
        self.1.free_flight(flight, from, to);
    }
}

/// Cubic Hermite interpolation of part `i` on the step [a, b] at τ.
#[inline]
pub fn hermite<const N: usize, I: Copy>(a: &StepEnd<N>, b: &StepEnd<N>, i: I, tau: f64) -> f64
where
    State<N>: Index<I, Output = f64>,
{
    let h = b.tau - a.tau;
    let t = (tau - a.tau) / h;
    let (t2, t3) = (t * t, t * t * t);
    (2.0 * t3 - 3.0 * t2 + 1.0) * a.y[i]
        + (t3 - 2.0 * t2 + t) * h * a.dy[i]
        + (-2.0 * t3 + 3.0 * t2) * b.y[i]
        + (t3 - t2) * h * b.dy[i]
}

/// Where in a step (the fraction t in [0, 1]) the cubic Hermite p through the values
/// and scaled slopes (p₀, h·p₀′) and (p₁, h·p₁′) turns: the root of its derivative (a
/// quadratic in t) where the derivative rises (`rising`: a minimum) or falls through zero;
/// ½ where there is none.
#[doc(hidden)]
pub fn hermite_turn_fraction((p0, m0): (f64, f64), (p1, m1): (f64, f64), rising: bool) -> f64 {
    // The cubic is p0 + m0 t + c2 t² + c3 t³; its derivative 3c3 t² + 2c2 t + m0.
    let c3 = 2.0 * p0 + m0 - 2.0 * p1 + m1;
    let c2 = -3.0 * p0 - 2.0 * m0 + 3.0 * p1 - m1;
    let (qa, qb, qc) = (3.0 * c3, 2.0 * c2, m0);
    let t = if qa.abs() <= 1e-14 * (qb.abs() + qc.abs()) {
        -qc / qb
    } else {
        let disc = (qb * qb - 4.0 * qa * qc).max(0.0).sqrt();
        let (r1, r2) = ((-qb - disc) / (2.0 * qa), (-qb + disc) / (2.0 * qa));
        // The root where the derivative rises (falls) through zero.
        if (2.0 * qa * r1 + qb > 0.0) == rising {
            r1
        } else {
            r2
        }
    };
    if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.5
    }
}
