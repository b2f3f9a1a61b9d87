//! Numerical integration of one branch with Dopri5 (`dynamics::dopri5`), stopping at the
//! first branch switch. Dopri5 has no event location, so each accepted step is checked here:
//! the switching function α̂ − level is evaluated on the step's cubic Hermite interpolant
//! (from the states and derivatives at both ends), the crossing is located on it, and
//! the state at the crossing is obtained by integrating again from the start of that
//! step — never by extrapolating dense output.
//!
//! Usually a crossing is not located at all but landed on: when an accepted step ends
//! within reach of the switch, the rest of the way is integrated with Hénon's trick,
//! taking u = √|level − α̂| as the independent variable (dτ/du follows from the velocity)
//! and stopping exactly at u = 0. The contact branches end at folds where T̂ has a
//! square-root singularity in α̂ but is smooth in u, so this last stretch takes two or
//! three smooth steps instead of a cascade of shrinking ones onto the cusp.

use super::budget;
use super::dopri5::{self, Settings, StepError, System};
use super::model::{
    BASE, CARRIED, Coupling, Oscillator, Part, State, V, X, has_tangent, rhs, set_phasor,
    surface_view,
};
#[doc(hidden)]
pub use super::observer::hermite_turn_fraction;
pub use super::observer::{Ignore, StepEnd, StepObserver, hermite};
use super::surface::Surface;
use crate::error::{Error, Result};
use crate::numeric::bracketed_root;
use crate::physics::law::{Branch, ForceLaw};
use std::cell::{Cell, RefCell};

/// Tolerances and step limits of the integrator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Largest step, in τ (keeps short contacts from being stepped over).
    pub h_max: f64,
}

/// Which way the switching function must cross its level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[doc(hidden)]
pub enum Crossing {
    /// α̂ falls to the level (jump-in).
    Down,
    /// α̂ rises to the level (jump-out).
    Up,
}

/// A switching level and the way α̂ must cross it.
pub(crate) type Event = (f64, Crossing);

/// Where a branch ends: α̂ falling to `below`, or rising to `above` (none: it runs on).
/// A branch bounded on both sides (a capillary neck that outlives a hysteretic contact:
/// it breaks above, the tip touches again below) ends at whichever it meets first.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[doc(hidden)]
pub struct Events {
    /// The level α̂ falls to.
    pub below: Option<f64>,
    /// The level α̂ rises to.
    pub above: Option<f64>,
}

impl Events {
    /// Each event, the falling one first.
    fn each(self) -> impl Iterator<Item = Event> {
        self.below
            .map(|level| (level, Crossing::Down))
            .into_iter()
            .chain(self.above.map(|level| (level, Crossing::Up)))
    }
}

/// What a segment learns while the solver owns it.
struct Progress<const N: usize> {
    /// The last accepted step end.
    last: StepEnd<N>,
    /// The step in which the switch happened (its start and end), the located time and
    /// the event.
    hit: Option<(StepEnd<N>, StepEnd<N>, f64, Event)>,
    /// Length of the first accepted step (0 until there is one).
    h: f64,
    /// The step end from which the switch is close enough to land on (Hénon), the
    /// length of the step that ended there, and the event.
    approach: Option<(StepEnd<N>, f64, Event)>,
    /// Why the segment stopped short, if the surface refused a step.
    failed: Option<Error>,
}

struct Segment<'a, L: ForceLaw, O: StepObserver, const N: usize> {
    law: &'a L,
    osc: &'a Oscillator,
    cpl: &'a Coupling,
    branch: Branch,
    /// Where the branch ends (none: run to the end of the span).
    events: Events,
    /// Whether to stop short of the switch to land on it ([`land`]).
    land: bool,
    /// End of the span.
    tau_end: f64,
    /// A relaxing sample's surface, with the step it has open ([`super::surface`]).
    surface: Option<&'a RefCell<Surface>>,
    progress: &'a mut Progress<N>,
    observer: &'a mut O,
}
impl<L: ForceLaw, O: StepObserver, const N: usize> Segment<'_, L, O, N> {
    /// (gap, rate) at τ for deflection `x` and velocity `v` ([`approach_rate`]).
    #[inline]
    fn approach(&self, level: f64, crossing: Crossing, tau: f64, x: f64, v: f64) -> (f64, f64) {
        approach_rate(self.osc, self.cpl, (level, crossing), tau, x, v)
    }

    /// The first time in the step where the gap to the switch closes, from 8 sub-samples
    /// of the Hermite interpolant and a bracketed refinement.
    fn locate(
        &self,
        a: &StepEnd<N>,
        b: &StepEnd<N>,
        level: f64,
        crossing: Crossing,
    ) -> Option<f64> {
        let g = |tau: f64| {
            self.approach(level, crossing, tau, hermite(a, b, X, tau), 0.0)
                .0
        };
        let (g_end, rate_end) = self.approach(level, crossing, b.tau, b.y[X], b.y[V]);
        if g_end > 0.0 {
            // Not crossed at the step's end; it can only have dipped through the level and
            // back if the separation turned around inside the step.
            let (_, rate_start) = self.approach(level, crossing, a.tau, a.y[X], a.y[V]);
            if !(rate_start > 0.0 && rate_end < 0.0) {
                return None;
            }
        }
        if g(a.tau) <= 0.0 {
            return None;
        }
        const SUB: usize = 8;
        let mut t0 = a.tau;
        for k in 1..=SUB {
            let t1 = if k == SUB {
                b.tau
            } else {
                a.tau + (b.tau - a.tau) * k as f64 / SUB as f64
            };
            let g1 = if k == SUB { g_end } else { g(t1) };
            if g1 <= 0.0 {
                return Some(bracketed_root("branch switch", g, t0, t1, 1e-15).unwrap_or(t1));
            }
            t0 = t1;
        }
        None
    }

    /// Whether the switch lies within about one more step of `end` (the step that ended
    /// there was `h` long), the motion heads for it fast enough not to stall on the way
    /// (even decelerating at the present rate it keeps half its speed), and it is reached
    /// well before the span ends.
    fn within_reach(&self, end: &StepEnd<N>, h: f64, level: f64, crossing: Crossing) -> bool {
        let (gap, rate) = self.approach(level, crossing, end.tau, end.y[X], end.y[V]);
        if !(gap > 0.0 && rate > 0.0) {
            return false;
        }
        let time = gap / rate;
        let accel =
            sigma(crossing) * self.cpl.a1 * (end.dy[V] + self.osc.base_acceleration(end.tau));
        time <= 1.5 * h
            && (-accel).max(0.0) * time <= 0.5 * rate
            && end.tau + 2.0 * time < self.tau_end
    }
}

/// +1 when α̂ rises to the level, −1 when it falls to it.
fn sigma(crossing: Crossing) -> f64 {
    match crossing {
        Crossing::Up => 1.0,
        Crossing::Down => -1.0,
    }
}

/// (gap, rate) at τ for deflection `x` and velocity `v`: the distance σ(level − α̂) still
/// to go to the switch (positive on the side the branch lives on) and σ dα̂/dτ, the
/// speed towards it.
fn approach_rate(
    osc: &Oscillator,
    cpl: &Coupling,
    (level, crossing): (f64, Crossing),
    tau: f64,
    x: f64,
    v: f64,
) -> (f64, f64) {
    let (x_b, v_b) = osc.base_at(tau);
    let s = sigma(crossing);
    (s * (level - cpl.alpha_hat(x, x_b)), s * cpl.a1 * (v + v_b))
}

impl<L: ForceLaw, O: StepObserver, const N: usize> System<N> for Segment<'_, L, O, N> {
    const QUADRATURES: std::ops::Range<usize> = CARRIED;
    #[inline]
    fn system(&self, tau: f64, y: &State<N>, dy: &mut State<N>) {
        let surface = self.surface.map(RefCell::borrow);
        rhs(
            self.law,
            self.osc,
            self.cpl,
            self.branch,
            tau,
            y,
            dy,
            surface.as_deref(),
        );
    }

    fn solout(&mut self, tau: f64, y: &State<N>, dy: &State<N>) -> bool {
        let end = StepEnd {
            tau,
            y: *y,
            dy: *dy,
        };
        let start = self.progress.last;
        let first = self
            .events
            .each()
            .filter_map(|event| Some((self.locate(&start, &end, event.0, event.1)?, event)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((t, event)) = first {
            self.progress.hit = Some((start, end, t, event));
            return true;
        }
        self.observer.step(&start, &end, self.branch);
        if let Some(surface) = self.surface {
            if let Err(e) = surface.borrow_mut().close(
                tau,
                surface_view(self.osc, self.cpl, tau, y),
                self.osc.period(),
            ) {
                self.progress.failed = Some(e);
                return true;
            }
        }
        if self.progress.h == 0.0 {
            self.progress.h = end.tau - start.tau;
        }
        self.progress.last = end;
        if self.land {
            let h = end.tau - start.tau;
            let near = self
                .events
                .each()
                .find(|&(level, crossing)| self.within_reach(&end, h, level, crossing));
            if let Some(event) = near {
                self.progress.approach = Some((end, h, event));
                return true;
            }
        }
        false
    }
}

/// The last stretch to a switch in Hénon's variable w = u₀ − u, u = √(σ(level − α̂)),
/// from w = 0 to w = u₀ (the switch). The state keeps its layout with τ in place of x
/// (x follows from u): d/dw = (dτ/dw)·d/dτ, dτ/dw = 2u/(σ dα̂/dτ).
struct Approach<'a, L: ForceLaw, const N: usize> {
    law: &'a L,
    osc: &'a Oscillator,
    cpl: &'a Coupling,
    branch: Branch,
    level: f64,
    sigma: f64,
    u0: f64,
    /// Smallest speed towards the switch accepted (below it the motion may stall).
    min_rate: f64,
    landing: &'a mut Landing<N>,
}

/// The accepted steps of a landing, kept until it is known to have succeeded.
struct Landing<const N: usize> {
    steps: [StepEnd<N>; MAX_LANDING_STEPS],
    len: usize,
    /// Set when the speed towards the switch fell below the accepted minimum, or the
    /// steps did not fit.
    failed: Cell<bool>,
}

/// Steps a landing may take (it normally takes two or three).
const MAX_LANDING_STEPS: usize = 16;

impl<L: ForceLaw, const N: usize> Approach<'_, L, N> {
    /// The τ-form state (x in place of τ) at Hénon variable `w`, and τ.
    #[inline]
    fn tau_form(&self, w: f64, y: &State<N>) -> (f64, State<N>) {
        let u = self.u0 - w;
        let alpha = self.level - self.sigma * u * u;
        let (x_b, _) = self
            .osc
            .base_from(y[X], (y[Part::DriveSin], y[Part::DriveCos]));
        let mut z = *y;
        z[X] = self.cpl.x_at(alpha) - x_b;
        (y[X], z)
    }
}

impl<L: ForceLaw, const N: usize> System<N> for Approach<'_, L, N> {
    const QUADRATURES: std::ops::Range<usize> = CARRIED;
    #[inline]
    fn system(&self, w: f64, y: &State<N>, dy: &mut State<N>) {
        let (tau, z) = self.tau_form(w, y);
        // (Never with a surface: a law with one does not land, see `Span::integrate`.)
        rhs(self.law, self.osc, self.cpl, self.branch, tau, &z, dy, None);
        let (_, v_b) = self
            .osc
            .base_from(tau, (z[Part::DriveSin], z[Part::DriveCos]));
        let mut rate = self.sigma * self.cpl.a1 * (z[V] + v_b);
        if rate.is_nan() || rate < self.min_rate {
            self.landing.failed.set(true);
            rate = self.min_rate;
        }
        let dtau_dw = 2.0 * (self.u0 - w) / rate;
        *dy *= dtau_dw;
        dy[X] = dtau_dw;
    }

    fn solout(&mut self, w: f64, y: &State<N>, _dy: &State<N>) -> bool {
        let (tau, z) = self.tau_form(w, y);
        let mut dz = State::<N>::zeros();
        rhs(
            self.law,
            self.osc,
            self.cpl,
            self.branch,
            tau,
            &z,
            &mut dz,
            None,
        );
        let landing = &mut *self.landing;
        if landing.len == MAX_LANDING_STEPS {
            landing.failed.set(true);
            return true;
        }
        landing.steps[landing.len] = StepEnd { tau, y: z, dy: dz };
        landing.len += 1;
        landing.failed.get()
    }
}

/// Land on the switch (`level`, `crossing`) from `entry` ([`Approach`]) and pass the steps
/// to `observer`. `None` (and nothing observed) if the motion slowed too much on the way
/// (it might not get there) or the switch lies beyond `tau_end`.
#[allow(clippy::too_many_arguments)]
fn land<L: ForceLaw, O: StepObserver, const N: usize>(
    law: &L,
    osc: &Oscillator,
    cpl: &Coupling,
    branch: Branch,
    (level, crossing): (f64, Crossing),
    entry: StepEnd<N>,
    tau_end: f64,
    tol: &Tolerances,
    observer: &mut O,
) -> Result<Option<StepEnd<N>>> {
    let (gap, rate) = approach_rate(
        osc,
        cpl,
        (level, crossing),
        entry.tau,
        entry.y[X],
        entry.y[V],
    );
    let u0 = gap.sqrt();
    let mut y = entry.y;
    y[X] = entry.tau;
    let mut landing = Landing {
        steps: [entry; MAX_LANDING_STEPS],
        len: 0,
        failed: Cell::new(false),
    };
    let system = Approach {
        law,
        osc,
        cpl,
        branch,
        level,
        sigma: sigma(crossing),
        u0,
        min_rate: 0.25 * rate,
        landing: &mut landing,
    };
    let tol = Tolerances { h_max: u0, ..*tol };
    run(system, 0.0, u0, y, u0, &tol, branch)?;
    let steps = &landing.steps[..landing.len];
    match steps.last() {
        Some(last) if !landing.failed.get() && last.tau <= tau_end => {
            let mut from = &entry;
            for step in steps {
                observer.step(from, step, branch);
                from = step;
            }
            Ok(Some(*last))
        }
        _ => Ok(None),
    }
}

/// Where a numerical segment ended.
#[derive(Debug, Clone, Copy)]
#[doc(hidden)]
pub struct SegmentEnd<const N: usize = BASE> {
    /// τ at the end.
    pub tau: f64,
    /// State at the end.
    pub y: State<N>,
    /// The event it ended at, a branch switch (none: it ended at `tau_end`).
    pub switched: Option<Crossing>,
    /// Length of the first accepted step (a good first step for the next segment on
    /// the same branch, which starts in the same state of the motion).
    pub h_first: f64,
    /// The step the controller proposes next, where the segment ended at `tau_end`
    /// (0 otherwise): where an integration going on from there starts.
    pub h_proposed: f64,
}

/// Most steps of one segment with the variational equations. A segment normally takes
/// a hundred or so; where the tip lingers next to a fold of the force law the variational
/// equations grow stiff (the slope there is ∝ 1/√distance) and Dopri5 would crawl. The
/// period map is not smooth there anyway: exceeding this is a numerical failure, which
/// the shooting takes as "no orbit here".
const MAX_TANGENT_STEPS: u32 = 4000;

/// Most steps of any segment (a segment lasts at most a drive period): a period that
/// needs more steps than this is unresolvable in practice (and its run is bounded in
/// time by it).
const MAX_SEGMENT_STEPS: u32 = 1_000_000;

/// Whether [from, to] is too short for Dopri5 to step at this τ (its step-size underflow
/// test is 0.1·h ≤ ε·|τ|); such spans are bridged by the Hermite interpolant instead.
fn too_short(from: f64, to: f64) -> bool {
    to - from <= 100.0 * f64::EPSILON * from.abs().max(1.0)
}

/// The state on the step [a, b] at τ from its cubic Hermite interpolant.
fn interpolate<const N: usize>(a: &StepEnd<N>, b: &StepEnd<N>, tau: f64) -> State<N> {
    let mut y = State::<N>::zeros();
    for i in 0..y.len() {
        y[i] = hermite(a, b, i, tau);
    }
    y
}

#[doc(hidden)]
pub fn run<S: System<N>, const N: usize>(
    mut system: S,
    from: f64,
    to: f64,
    y: State<N>,
    h: f64,
    tol: &Tolerances,
    branch: Branch,
) -> Result<f64> {
    use StepError as E;
    let branch = match branch {
        Branch::Free => "out-of-contact",
        Branch::Contact => "contact",
        Branch::Necked => "capillary-neck",
    };
    let segment_cap = if has_tangent(N) {
        MAX_TANGENT_STEPS
    } else {
        MAX_SEGMENT_STEPS
    };
    let left = budget::left();
    let max_steps = u32::try_from(left).map_or(segment_cap, |l| l.min(segment_cap));
    let limited_by_budget = u64::from(max_steps) == left && max_steps < segment_cap;
    let settings = Settings {
        rtol: tol.rtol,
        atol: tol.atol,
        h_max: tol.h_max,
        h0: h,
        max_steps,
    };
    match dopri5::integrate(&mut system, from, to, y, &settings) {
        Ok(stats) => {
            budget::spend(u64::from(stats.accepted_steps + stats.rejected_steps))?;
            Ok(stats.h_proposed)
        }
        Err(E::MaxNumStepReached { .. }) if limited_by_budget => Err(budget::exhausted()),
        Err(e) => Err({
            if matches!(e, E::MaxNumStepReached { .. }) {
                let _ = budget::spend(u64::from(max_steps));
            }
            Error::Numerical(match e {
                E::StepSizeUnderflow { x } => format!(
                    "the integrator's step fell to round-off on the {branch} branch at \
                     τ = {x:.6e} (ω₀t): the motion there is too abrupt for the tolerances"
                ),
                E::MaxNumStepReached { x, n_step } => format!(
                    "the {branch} branch needed more than {n_step} integration steps in \
                     one drive period at τ = {x:.6e} (ω₀t): the motion is too stiff to \
                     resolve (a cantilever far softer than the contact, or a drive far \
                     below resonance)"
                ),
            })
        }),
    }
}

/// Integrate branch `branch` from (`tau0`, `y0`) to `tau_end`, stopping at the first of
/// its `events` met. `h0` is the first trial step (0 lets the solver choose). A relaxing
/// sample's `surface` is driven along (left with a step open at the end).
#[allow(clippy::too_many_arguments)]
pub(crate) fn integrate<L: ForceLaw, O: StepObserver, const N: usize>(
    law: &L,
    osc: &Oscillator,
    cpl: &Coupling,
    branch: Branch,
    events: Events,
    tau0: f64,
    y0: State<N>,
    tau_end: f64,
    h0: f64,
    tol: &Tolerances,
    surface: Option<&RefCell<Surface>>,
    observer: &mut O,
) -> Result<SegmentEnd<N>> {
    let span = Span {
        law,
        osc,
        cpl,
        branch,
        events,
        tau_end,
        tol,
    };
    span.integrate(tau0, y0, h0, surface, observer)
}

/// What [`integrate`] works on.
#[doc(hidden)]
pub struct Span<'a, L: ForceLaw> {
    pub law: &'a L,
    pub osc: &'a Oscillator,
    pub cpl: &'a Coupling,
    pub branch: Branch,
    pub events: Events,
    pub tau_end: f64,
    pub tol: &'a Tolerances,
}

impl<L: ForceLaw> Span<'_, L> {
    /// Integrate from (`tau0`, `y0`), landing on the switch ([`land`]) once it is within
    /// reach — except with a `surface`, whose steps a landing in another variable would
    /// not drive: its crossing is located.
    fn integrate<O: StepObserver, const N: usize>(
        &self,
        tau0: f64,
        y0: State<N>,
        h0: f64,
        surface: Option<&RefCell<Surface>>,
        observer: &mut O,
    ) -> Result<SegmentEnd<N>> {
        self.integrate_landing(tau0, y0, h0, surface.is_none(), surface, observer)
    }

    /// [`Span::integrate`]; `land_on_switch`: whether to land on the switch.
    pub fn integrate_landing<O: StepObserver, const N: usize>(
        &self,
        tau0: f64,
        y0: State<N>,
        h0: f64,
        land_on_switch: bool,
        surface: Option<&RefCell<Surface>>,
        observer: &mut O,
    ) -> Result<SegmentEnd<N>> {
        let Self {
            law,
            osc,
            cpl,
            branch,
            events,
            tau_end,
            tol,
        } = *self;
        let mut y0 = y0;
        set_phasor(osc, tau0, &mut y0);
        if let Some(surface) = surface {
            surface
                .borrow_mut()
                .open(tau0, surface_view(osc, cpl, tau0, &y0), osc.period())?;
        }
        let mut dy0 = State::<N>::zeros();
        let open = surface.map(RefCell::borrow);
        rhs(law, osc, cpl, branch, tau0, &y0, &mut dy0, open.as_deref());
        drop(open);
        if too_short(tau0, tau_end) {
            // Nothing Dopri5 could step over: advance by one Euler step (error ~ (Δτ)²).
            let y = y0 + dy0 * (tau_end - tau0);
            if let Some(surface) = surface {
                surface.borrow_mut().close(
                    tau_end,
                    surface_view(osc, cpl, tau_end, &y),
                    osc.period(),
                )?;
            }
            return Ok(SegmentEnd {
                tau: tau_end,
                y,
                switched: None,
                h_first: 0.0,
                h_proposed: 0.0,
            });
        }
        let mut progress = Progress {
            last: StepEnd {
                tau: tau0,
                y: y0,
                dy: dy0,
            },
            hit: None,
            h: 0.0,
            approach: None,
            failed: None,
        };
        let segment = Segment {
            law,
            osc,
            cpl,
            branch,
            events,
            land: land_on_switch,
            tau_end,
            surface,
            progress: &mut progress,
            observer: &mut *observer,
        };
        let h_proposed = run(segment, tau0, tau_end, y0, h0, tol, branch)?;
        if let Some(e) = progress.failed {
            return Err(e);
        }
        if let Some((entry, h, event)) = progress.approach {
            let landed = land(law, osc, cpl, branch, event, entry, tau_end, tol, observer)?;
            let end = match landed {
                Some(end) => SegmentEnd {
                    tau: end.tau,
                    y: end.y,
                    switched: Some(event.1),
                    h_first: progress.h,
                    h_proposed: 0.0,
                },
                // Carry on from where the landing started, locating the crossing.
                None => SegmentEnd {
                    h_first: progress.h,
                    ..self.integrate_landing(entry.tau, entry.y, h, false, surface, observer)?
                },
            };
            return Ok(end);
        }
        let Some((start, hit_end, t_hit, event)) = progress.hit else {
            let last = progress.last;
            return Ok(SegmentEnd {
                tau: last.tau,
                y: last.y,
                switched: None,
                h_first: progress.h,
                h_proposed,
            });
        };
        // (The surface is still open at the step's start: the polish drives a copy.)
        let (tau, y, moved) = self.polish(start, hit_end, t_hit, event, surface)?;
        let mut dy = State::<N>::zeros();
        rhs(law, osc, cpl, branch, tau, &y, &mut dy, moved.as_ref());
        // The observer sees the step with the surface open at its start, as every other.
        observer.step(&start, &StepEnd { tau, y, dy }, branch);
        if let (Some(surface), Some(moved)) = (surface, moved) {
            *surface.borrow_mut() = moved;
        }
        Ok(SegmentEnd {
            tau,
            y,
            switched: Some(event.1),
            h_first: progress.h,
            h_proposed: 0.0,
        })
    }

    /// The state at the switch located at `t_hit` inside the step [`start`, `hit_end`]:
    /// the part of the step up to it is integrated again from the step's start, and the
    /// switching time polished by Newton steps on the re-integrated state (the Hermite
    /// interpolant is only fourth-order accurate, and the force may be singular at the
    /// switch, as at the JKR fold C).
    ///
    /// A relaxing sample's `surface` (open at the step's start) is left as it was; the
    /// surface driven to the switch is returned.
    fn polish<const N: usize>(
        &self,
        start: StepEnd<N>,
        hit_end: StepEnd<N>,
        t_hit: f64,
        (level, crossing): Event,
        surface: Option<&RefCell<Surface>>,
    ) -> Result<(f64, State<N>, Option<Surface>)> {
        let mut t = t_hit;
        let mut y = start.y;
        let mut moved = None;
        for attempt in 0..4 {
            let mut refine = Progress {
                last: start,
                hit: None,
                h: 0.0,
                approach: None,
                failed: None,
            };
            let copy = surface.map(|s| RefCell::new(s.borrow().clone()));
            if too_short(start.tau, t) {
                // The switch sits at the very start of the step: interpolate.
                refine.last.y = interpolate(&start, &hit_end, t);
                if let Some(copy) = &copy {
                    let view = surface_view(self.osc, self.cpl, t, &refine.last.y);
                    copy.borrow_mut().close(t, view, self.osc.period())?;
                }
            } else if t > start.tau {
                let mut quiet = Ignore;
                let again = Segment {
                    law: self.law,
                    osc: self.osc,
                    cpl: self.cpl,
                    branch: self.branch,
                    events: Events::default(),
                    land: false,
                    tau_end: t,
                    surface: copy.as_ref(),
                    progress: &mut refine,
                    observer: &mut quiet,
                };
                run(
                    again,
                    start.tau,
                    t,
                    start.y,
                    t - start.tau,
                    self.tol,
                    self.branch,
                )?;
                if let Some(e) = refine.failed {
                    return Err(e);
                }
            }
            y = refine.last.y;
            moved = copy.map(RefCell::into_inner);
            // Still to go, and its rate of decrease.
            let (gap, rate) = approach_rate(self.osc, self.cpl, (level, crossing), t, y[X], y[V]);
            let next = t + gap / rate;
            if attempt == 3
                // 1e-8 in α̂ moves the loop area by ~1e-8 relative (the path itself stays
                // consistent: it switches where it is, a hair from the level).
                || gap.abs() <= 1e-8 * (1.0 + level.abs())
                || !(next > start.tau && next.is_finite())
            {
                break;
            }
            t = next;
        }
        Ok((t, y, moved))
    }
}
