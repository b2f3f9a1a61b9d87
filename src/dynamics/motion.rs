//! What the steady-state search reports and is told: how the motion repeats (its
//! period and Floquet multipliers), the window averages' standard errors, the search's
//! settings and its outcome. The solvers ([`super::steady`], [`super::shooting`],
//! [`super::window`], the recurrence and capture tests) all speak these types and import
//! them from here, so that none needs another's module for a type.

use super::march::CycleIntegrals;
use super::model::SECTION_DIM;
use nalgebra::Complex;

/// The longest period looked for; motion that repeats after no n ≤ this is `irregular`.
/// Periods up to [`SHORT_PERIOD`] are looked for wherever the motion nearly repeats;
/// longer ones (mode locks near grazing, such as 13 touches in 27 periods) where the
/// section state has returned within `LOCK_GAP` (1e-5) three periods running.
pub const MAX_PERIOD: usize = 1000;

/// The longest period looked for from loose near-returns, and by time-marching alone
/// (without shooting).
pub const SHORT_PERIOD: usize = 8;

/// How the steady motion repeats.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// The state at the drive phase returns after `period` drive periods (and after no
    /// fewer).
    Periodic {
        /// n.
        period: usize,
        /// Eigenvalues of the orbit's monodromy matrix (the derivative of the n-period
        /// map).
        multipliers: Multipliers,
    },
    /// Quasi-periodic, chaotic or intermittent motion, or a period above [`MAX_PERIOD`].
    Irregular,
}

impl Motion {
    /// "period-n" or "irregular".
    pub fn regime(&self) -> String {
        match self {
            Motion::Periodic { period, .. } => format!("period-{period}"),
            Motion::Irregular => "irregular".into(),
        }
    }

    /// n for a periodic orbit.
    pub fn period(&self) -> Option<usize> {
        match self {
            Motion::Periodic { period, .. } => Some(*period),
            Motion::Irregular => None,
        }
    }

    /// Whether a periodic orbit is stable (every multiplier inside the unit circle).
    pub fn stable(&self) -> Option<bool> {
        match self {
            Motion::Periodic { multipliers, .. } => {
                Some(multipliers.iter().all(|m| m.norm() < 1.0))
            }
            Motion::Irregular => None,
        }
    }
}

/// The fewest periods a steady-state search may be given: enough to classify the motion
/// and average irregular motion over a window of its own.
#[doc(hidden)]
pub const MIN_CYCLES: usize = 32;
/// Marched periods are integrated at this fraction of the averages' tolerance (the
/// default of [`SteadyOptions::marching_fraction`]).
pub const MARCHING_TOLERANCE: f64 = 1e-5;

/// Floquet multipliers of a periodic orbit: the eigenvalues of its monodromy matrix, one
/// per dimension of the section state (two; none for an orbit only marched to, on a
/// relaxing sample's surface).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Multipliers {
    pub(super) values: [Complex<f64>; SECTION_DIM],
    pub(super) len: usize,
}

impl Multipliers {
    /// The multipliers.
    pub fn as_slice(&self) -> &[Complex<f64>] {
        &self.values[..self.len]
    }

    /// Iterate over them.
    pub fn iter(&self) -> std::slice::Iter<'_, Complex<f64>> {
        self.as_slice().iter()
    }
}

/// Standard errors of window averages (batch means); zero for a periodic orbit.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StdErr {
    /// Of the amplitude (units of L).
    pub amplitude: f64,
    /// Of the phase (rad).
    pub phase: f64,
    /// Of E_ts per drive period (units of kL²).
    pub e_ts: f64,
}

/// Settings of the steady-state search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteadyOptions {
    /// Periodic orbits: the largest |Pⁿ(z) − z| accepted (units of L); Newton aims 100×
    /// lower. Time-marching: how close to the orbit the state must be (judged from its
    /// return distances).
    pub tolerance: f64,
    /// Irregular motion: the standard error of the averages (A relative, φ in rad, E_ts
    /// relative to E_drive) to reach.
    pub average_tolerance: f64,
    /// At most this many periods.
    pub max_cycles: usize,
    /// Look for periodic orbits by Newton's method on the period map.
    pub shooting: bool,
    /// At most this many integrator steps ([`super::budget`]).
    pub max_steps: u64,
    /// Periods marched for averages and for the choice of candidate periods are
    /// integrated at this fraction of `average_tolerance` ([`MARCHING_TOLERANCE`]
    /// unless tightened to re-decide a grazing state).
    pub marching_fraction: f64,
    /// A grazing margin below this (units of L) counts as grazing ([`super::grazing`]),
    /// as does one below the state's resolution ([`super::march::Simulation::resolution`]): the
    /// thermal rms deflection at 300 K over A₀ for a prepared experiment.
    pub grazing_threshold: f64,
}

/// Whether a steady state grazes a switch ([`super::march::Simulation::grazing`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Grazing {
    /// A turning point lies within the threshold of some switch level.
    pub any: bool,
    /// … of a level where the force jumps: the period map is discontinuous within that
    /// distance, and an orbit's stability rests on the grazing contact.
    pub jump: bool,
}

/// The outcome of [`super::march::Simulation::steady_state`].
#[derive(Debug, Clone, Copy)]
pub struct SteadyState {
    /// The integrals over what is reported: one pass of the periodic orbit (n periods),
    /// or the averaging window of irregular motion.
    pub window: CycleIntegrals,
    /// Periods integrated in all.
    pub cycles: usize,
    /// Whether the reported values meet their tolerance.
    pub converged: bool,
    /// How the motion repeats.
    pub motion: Motion,
    /// Standard errors of the window averages.
    pub std_err: StdErr,
}
