//! Grazing: how close the motion comes to switching branch where it does not, or to not
//! switching where it does.
//!
//! A hysteretic law switches branch where the separation α̂ crosses a level (the jump-in
//! α̂_A, the jump-out α̂_C, a neck's rupture gap). Where a turning point of α̂ lies close to
//! such a level, a perturbation of that size changes which branches a period visits: the
//! period map is not smooth there, and where the force jumps at the level the basins of
//! the attractors nearby can be finer than any perturbation an instrument or an
//! integrator makes (grazing; di Bernardo et al., *Piecewise-smooth Dynamical Systems*,
//! Springer 2008, ch. 4; van de Water & Molenaar, Nanotechnology 11, 192, 2000). The
//! *grazing margin* of a stretch of motion is the smallest distance, over its turning
//! points, from the turning point to a level that matters on the branch it lies on: the
//! branch's own exits (the turning point misses them by that much) and the levels at
//! which the other branches enter it (the turning point has cleared them by that much).

use crate::physics::law::{Branch, ForceLaw};

/// Every branch, in the order of its index.
const BRANCHES: [Branch; Branch::COUNT] = [Branch::Free, Branch::Contact, Branch::Necked];

/// The most levels that matter on one branch: its two exits and two entries from each
/// other branch.
const MAX_LEVELS: usize = 2 * Branch::COUNT;

/// The switch levels (α̂) that matter to a turning point on each branch, each marked by
/// whether the force jumps there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SwitchLevels {
    levels: [[(f64, bool); MAX_LEVELS]; Branch::COUNT],
    counts: [usize; Branch::COUNT],
}

/// Grazing margins in α̂: over every switch level, and over those where the force jumps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Margins {
    /// To the nearest level (∞: none).
    pub any: f64,
    /// To the nearest level where the force jumps (∞: none).
    pub jump: f64,
}

impl Margins {
    /// No turning point yet.
    pub const NONE: Self = Self {
        any: f64::INFINITY,
        jump: f64::INFINITY,
    };

    /// The smaller of each.
    #[inline]
    pub fn min(self, other: Self) -> Self {
        Self {
            any: self.any.min(other.any),
            jump: self.jump.min(other.jump),
        }
    }
}

impl SwitchLevels {
    /// The levels of `law`, from its branches' exits ([`ForceLaw::exits`]); a law that
    /// never switches has none. The force jumps at a level where T̂ on the two branches
    /// differs there by more than 10⁻⁹ of its size (Hertz's and DMT's contact onset, and
    /// a capillary neck's rupture, are continuous; a hysteretic law's jump-in and
    /// jump-out are not). Where it is continuous a grazing turning point leaves the
    /// period map continuous, and does not cut its basins up.
    pub fn of<L: ForceLaw>(law: &L) -> Self {
        let mut out = Self {
            levels: [[(f64::NAN, false); MAX_LEVELS]; Branch::COUNT],
            counts: [0; Branch::COUNT],
        };
        for from in BRANCHES {
            let exits = law.exits(from);
            for (level, to) in [exits.below, exits.above].into_iter().flatten() {
                if !level.is_finite() {
                    continue;
                }
                let (a, b) = (law.t_hat(level, from), law.t_hat(level, to));
                let jumps = (a - b).abs() > 1e-9 * a.abs().max(b.abs()).max(1e-300);
                out.add(from, level, jumps);
                out.add(to, level, jumps);
            }
        }
        out
    }

    fn add(&mut self, branch: Branch, level: f64, jumps: bool) {
        let (b, n) = (branch as usize, self.counts[branch as usize]);
        if n == MAX_LEVELS {
            return;
        }
        match self.levels[b][..n].iter_mut().find(|l| l.0 == level) {
            Some(known) => known.1 |= jumps,
            None => {
                self.levels[b][n] = (level, jumps);
                self.counts[b] += 1;
            }
        }
    }

    /// The distances from a turning point at `alpha_hat` on `branch` to the nearest
    /// level that matters there.
    #[inline]
    pub fn margins(&self, branch: Branch, alpha_hat: f64) -> Margins {
        let b = branch as usize;
        self.levels[b][..self.counts[b]]
            .iter()
            .fold(Margins::NONE, |m, &(level, jumps)| {
                let d = (alpha_hat - level).abs();
                Margins {
                    any: m.any.min(d),
                    jump: if jumps { m.jump.min(d) } else { m.jump },
                }
            })
    }
}

/// Boltzmann's constant in J/K (exact, SI 2019).
pub const BOLTZMANN_J_K: f64 = 1.380_649e-23;

/// The temperature at which a margin is compared with thermal motion, in K.
pub const ROOM_TEMPERATURE_K: f64 = 300.0;

/// The rms thermal deflection of a cantilever of stiffness `stiffness_n_m` at
/// `temperature_k`, √(k_B T/k) in m (equipartition, ½k⟨z²⟩ = ½k_B T; Hutter &
/// Bechhoefer, RSI 64, 1868, 1993).
pub fn thermal_rms_m(stiffness_n_m: f64, temperature_k: f64) -> f64 {
    (BOLTZMANN_J_K * temperature_k / stiffness_n_m).sqrt()
}
