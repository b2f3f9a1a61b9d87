//! The steady state a drive settles on, its classification and what an instrument
//! reads from it.
//!
//! The steady state is found on the period map P (the state at the same drive phase one
//! period later, [`super::march`]): Newton's method on Pⁿ(z) − z converges
//! quadratically to a period-n orbit ([`super::shooting`]), whose Floquet multipliers say
//! whether it is stable. Motion that settles on no orbit of period ≤ [`MAX_PERIOD`] is
//! `irregular` and averaged over a window that grows until its batch means agree
//! ([`super::window`]).

use super::budget;
use super::march::{Phase, Simulation};
#[doc(hidden)]
pub use super::motion::MIN_CYCLES;
pub use super::motion::{
    Grazing, MARCHING_TOLERANCE, MAX_PERIOD, Motion, SHORT_PERIOD, SteadyOptions, SteadyState,
};
use super::numeric;
use super::recurrence::Recurrence;
use super::surface::Surface;
use super::window::Window;
use crate::error::Result;
use crate::physics::law::ForceLaw;

/// Periods integrated before the first look for orbits of higher period.
const FIRST_STRETCH: usize = 32;
/// Periods the search for an orbit may integrate at most (with shooting).
const SEARCH_PERIODS: usize = 1000;

/// How close, in units of the integrator's relative tolerance, a marched orbit of a
/// relaxing sample is settled (the period map's own jitter is some tenths of it a
/// period).
const MARCHED_FLOOR: f64 = 100.0;

impl<L: ForceLaw> Simulation<'_, L> {
    /// The steady state reached from `phase` (which is left on it): the attractor the
    /// motion settles on, classified as period-n (n ≤ [`MAX_PERIOD`]) or irregular, with
    /// what an instrument reads from it — averages over one pass of a periodic orbit, or
    /// over a window of irregular motion that grows until its batch means agree within
    /// `opts.average_tolerance` (standard errors reported).
    ///
    /// With `opts.shooting` (the default) the period-1 orbit is first looked for by
    /// Newton's method from `phase`; if that fails, or the orbit found is unstable, the
    /// motion is integrated in growing stretches and, after each, orbits of the periods
    /// the last states nearly repeat with are looked for the same way. Without it, the
    /// motion is only integrated, until the state at the drive phase repeats after n
    /// periods closely enough three times running to lie within `opts.tolerance` of the
    /// orbit. Either way at most `opts.max_cycles` periods are integrated; `converged`
    /// says whether the reported averages meet their tolerance.
    /// The search runs on a work budget ([`budget`]): motion too costly to resolve ends
    /// with an error.
    ///
    /// A relaxing sample's surface ([`super::surface`]) has as many variables as its
    /// elements, beyond the period map's derivative: its steady state is only marched
    /// to, judged by the return distances of (x, x') with the surface's own creep
    /// counted in how fast the motion contracts, to within 100 times the
    /// integrator's tolerance (the marched map's own jitter), and its orbit's Floquet
    /// multipliers are not computed (the marching reached it: it attracts).
    pub fn steady_state(&self, phase: &mut Phase, opts: &SteadyOptions) -> Result<SteadyState> {
        let opts = &SteadyOptions {
            shooting: opts.shooting && !self.has_surface(),
            ..*opts
        };
        budget::budgeted(opts.max_steps, || {
            self.steady_state_within_budget(phase, opts)
        })
    }

    fn steady_state_within_budget(
        &self,
        phase: &mut Phase,
        opts: &SteadyOptions,
    ) -> Result<SteadyState> {
        let budget = opts.max_cycles.max(MIN_CYCLES);
        // The search for an orbit gets at most half the budget (seven eighths without
        // shooting); the rest is left for averaging.
        let search_budget = if opts.shooting {
            (budget / 2).min(1 + SEARCH_PERIODS)
        } else {
            budget - budget / 8
        };
        // A first period puts the state on a consistent branch.
        self.rewind(phase);
        self.cycle(phase, &mut numeric::Ignore)?;
        let mut spent = 1;
        // Orbits Newton's method found that the marching has not yet reached.
        let mut pending = Vec::new();
        if opts.shooting {
            let limits = (opts, search_budget);
            if let Some(found) = self.shoot(phase, 1, limits, &mut spent, &mut pending)? {
                return Ok(found);
            }
        }
        // Marched periods serve the averages of irregular motion and the choice of
        // candidate periods, both far coarser than the integrator's tolerance: they are
        // integrated at a tolerance set by the averages' (see [`Simulation::marching`]).
        // Without shooting they must settle the orbit to `opts.tolerance` themselves.
        let marching = if opts.shooting {
            self.marching(opts)
        } else {
            *self
        };
        let mut ring = Recurrence::default();
        ring.push(self.z(phase), phase.branch);
        // The periods marched while searching are the averaging window's first batches,
        // should the motion prove irregular (a transient at their head is cut there).
        let mut window = Window::new(self.memory_periods(), budget - spent);
        let creep = Surface::of(self.law, self.cpl.a1).map(|s| s.creep_hat());
        let mut stretch = FIRST_STRETCH;
        while spent < search_budget {
            for _ in 0..stretch.min(search_budget - spent) {
                let recorded = (&mut ring, &mut window);
                if let Some(found) =
                    self.march_recorded(&marching, phase, recorded, &pending, &mut spent)?
                {
                    return Ok(found);
                }
                if !opts.shooting {
                    // A state contracting onto the orbit by a factor ρ per n periods
                    // is |Δz|·ρ/(1 − ρ) from it; ρ is at most the free oscillator's
                    // e^{−γnT}, so this return distance puts it within `tolerance`.
                    // A relaxing sample's surface may be slower: it creeps back with
                    // its retardation time (in contact its elements relax faster). Its
                    // orbit is only ever marched to, and a marched period jitters by
                    // a fraction of the integrator's tolerance (its steps, adapted to
                    // the surface's kinks, differ from period to period: measured
                    // 3e-10 a period at rtol 1e-9, 2e-9 of wander on a Q = 400
                    // lever), so it is settled to within `MARCHED_FLOOR` rtol.
                    let target = match creep {
                        Some(_) => opts.tolerance.max(MARCHED_FLOOR * self.tol.rtol),
                        None => opts.tolerance,
                    };
                    let within = |n: usize| {
                        let rate = creep.map_or(self.osc.gamma, |c| self.osc.gamma.min(1.0 / c));
                        let rho = (-rate * self.osc.period() * n as f64).exp();
                        target * (1.0 - rho) / rho
                    };
                    if let Some(n) = ring.repeats(within) {
                        let gap = ring.gap(0, n).unwrap_or(0.0);
                        let mut on = phase.clone();
                        // (`None`: the orbit grazes a fold, see `period_map`: march on.)
                        let settled = if creep.is_some() {
                            Some(self.settle_marching(&mut on, n, gap, &mut spent)?)
                        } else {
                            self.settle(&mut on, n, gap, &mut spent)?
                                .map(|(state, _)| state)
                        };
                        if let Some(state) = settled {
                            *phase = on;
                            return Ok(state);
                        }
                    }
                }
            }
            if opts.shooting {
                for n in ring.candidates().into_iter().chain(ring.locked()) {
                    if spent >= search_budget {
                        break;
                    }
                    let limits = (opts, search_budget);
                    if let Some(found) = self.shoot(phase, n, limits, &mut spent, &mut pending)? {
                        return Ok(found);
                    }
                }
            }
            stretch *= 2;
        }
        self.average(phase, opts, (budget, spent), window, ring, pending)
    }

    /// How finely a steady state of `motion` found with `opts` is resolved, in units of
    /// L: for a periodic orbit the larger of its closure tolerance and the integrator's
    /// relative tolerance (Newton aims 100× below the first, and a period integrated at
    /// the second moves a state of size ~1 by about that much); for irregular motion the
    /// tolerance its periods are marched at (`marching`).
    pub fn resolution(&self, opts: &SteadyOptions, motion: &Motion) -> f64 {
        match motion {
            Motion::Periodic { .. } => opts.tolerance.max(self.tol.rtol),
            Motion::Irregular => self.marching(opts).tol.rtol,
        }
    }

    /// Whether `state` (found with `opts`) grazes a switch: a grazing margin below the
    /// larger of `opts.grazing_threshold` and the state's resolution.
    pub fn grazing(&self, opts: &SteadyOptions, state: &SteadyState) -> Grazing {
        let threshold = opts
            .grazing_threshold
            .max(self.resolution(opts, &state.motion));
        let margins = state.window.grazing;
        Grazing {
            any: margins.any / self.cpl.a1 < threshold,
            jump: margins.jump / self.cpl.a1 < threshold,
        }
    }

    /// This simulation with the integrator tolerances loosened to
    /// `opts.marching_fraction` × `opts.average_tolerance` (never tightened): the tolerance
    /// at which periods are marched for averages. A marched trajectory of irregular
    /// motion parts from the exact one whatever the tolerance (that is what irregular
    /// means); what must hold is its statistics, which an integrator error 10⁵ below
    /// the averages' tolerance does not move (tests/steady.rs checks the averages
    /// against exact marching), and its energy balance (< 1e-8 at the defaults).
    pub(super) fn marching(&self, opts: &SteadyOptions) -> Self {
        self.loosened(opts.marching_fraction * opts.average_tolerance)
    }
}
