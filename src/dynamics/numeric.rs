//! Numerical integration of one branch with ode_solvers' Dopri5, stopping at the first
//! branch switch. Dopri5 has no event location, so each accepted step is checked here:
//! the switching function α̂ − level is evaluated on the step's cubic Hermite interpolant
//! (from the states and derivatives at both ends), the crossing is located on it, and
//! the state at the crossing is obtained by integrating again from the start of that
//! step — never by extrapolating dense output.

use super::model::{Coupling, Oscillator, State, V, X, rhs, set_phasor};
use crate::error::{Error, Result};
use crate::law::{Branch, ForceLaw};
use crate::numeric::bracketed_root;
use ode_solvers::dop_shared::{OutputType, System};
use ode_solvers::dopri5::Dopri5;

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
pub enum Crossing {
    /// α̂ falls to the level (jump-in).
    Down,
    /// α̂ rises to the level (jump-out).
    Up,
}

/// A sample of the trajectory at the end of an accepted step.
#[derive(Debug, Clone, Copy)]
pub struct StepEnd {
    /// τ.
    pub tau: f64,
    /// State.
    pub y: State,
    /// Its derivative.
    pub dy: State,
}

/// Per-step observer (trajectory recording and extrema).
pub trait StepObserver {
    /// Called for each accepted step [from, to] of the branch `branch`.
    fn step(&mut self, from: &StepEnd, to: &StepEnd, branch: Branch);
    /// Called for each closed-form free flight from τ `from` to `to`.
    fn free_flight(&mut self, _flight: &super::free::FreeFlight, _from: f64, _to: f64) {}
}

/// An observer that ignores everything.
pub struct Ignore;

impl StepObserver for Ignore {
    fn step(&mut self, _: &StepEnd, _: &StepEnd, _: Branch) {}
}

/// Cubic Hermite interpolation of component `i` on the step [a, b] at τ.
#[inline]
pub fn hermite(a: &StepEnd, b: &StepEnd, i: usize, tau: f64) -> f64 {
    let h = b.tau - a.tau;
    let t = (tau - a.tau) / h;
    let (t2, t3) = (t * t, t * t * t);
    (2.0 * t3 - 3.0 * t2 + 1.0) * a.y[i]
        + (t3 - 2.0 * t2 + t) * h * a.dy[i]
        + (-2.0 * t3 + 3.0 * t2) * b.y[i]
        + (t3 - t2) * h * b.dy[i]
}

/// What a segment learns while the solver owns it.
struct Progress {
    /// The last accepted step end.
    last: StepEnd,
    /// The step in which the switch happened (its start and end) and the located time.
    hit: Option<(StepEnd, StepEnd, f64)>,
    /// Length of the first accepted step (0 until there is one).
    h: f64,
}

struct Segment<'a, L: ForceLaw, O: StepObserver> {
    law: &'a L,
    osc: &'a Oscillator,
    cpl: &'a Coupling,
    branch: Branch,
    /// Switching level and direction; `None` to run to the end.
    event: Option<(f64, Crossing)>,
    progress: &'a mut Progress,
    observer: &'a mut O,
}
impl<L: ForceLaw, O: StepObserver> Segment<'_, L, O> {
    /// Signed distance to the switch, positive on the side the branch lives on.
    #[inline]
    fn distance(&self, level: f64, crossing: Crossing, tau: f64, x: f64) -> f64 {
        let (x_b, _) = self.osc.base_at(tau);
        let d = self.cpl.alpha_hat(x, x_b) - level;
        match crossing {
            Crossing::Down => d,
            Crossing::Up => -d,
        }
    }

    /// The first time in the step where the distance reaches zero, from 8 sub-samples of
    /// the Hermite interpolant and a bracketed refinement.
    fn locate(&self, a: &StepEnd, b: &StepEnd, level: f64, crossing: Crossing) -> Option<f64> {
        let g = |tau: f64| self.distance(level, crossing, tau, hermite(a, b, X, tau));
        let g_end = self.distance(level, crossing, b.tau, b.y[X]);
        if g_end > 0.0 {
            // Not crossed at the step's end; it can only have dipped through the level and
            // back if the separation turned around inside the step.
            let rate = |e: &StepEnd| {
                let (_, v_b) = self.osc.base_at(e.tau);
                match crossing {
                    Crossing::Down => e.y[V] + v_b,
                    Crossing::Up => -(e.y[V] + v_b),
                }
            };
            if !(rate(a) < 0.0 && rate(b) > 0.0) {
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
}

impl<L: ForceLaw, O: StepObserver> System<f64, State> for Segment<'_, L, O> {
    #[inline]
    fn system(&self, tau: f64, y: &State, dy: &mut State) {
        rhs(self.law, self.osc, self.cpl, self.branch, tau, y, dy);
    }

    fn solout(&mut self, tau: f64, y: &State, dy: &State) -> bool {
        let end = StepEnd {
            tau,
            y: *y,
            dy: *dy,
        };
        let start = self.progress.last;
        if let Some((level, crossing)) = self.event {
            if let Some(t) = self.locate(&start, &end, level, crossing) {
                self.progress.hit = Some((start, end, t));
                return true;
            }
        }
        self.observer.step(&start, &end, self.branch);
        if self.progress.h == 0.0 {
            self.progress.h = end.tau - start.tau;
        }
        self.progress.last = end;
        false
    }
}

/// Where a numerical segment ended.
#[derive(Debug, Clone, Copy)]
pub struct SegmentEnd {
    /// τ at the end.
    pub tau: f64,
    /// State at the end.
    pub y: State,
    /// Whether it ended at a branch switch (else at `tau_end`).
    pub switched: bool,
    /// Length of the first accepted step (a good first step for the next segment on
    /// the same branch, which starts in the same state of the motion).
    pub h_first: f64,
}

fn dopri<S: System<f64, State>>(
    system: S,
    tau0: f64,
    tau1: f64,
    y0: State,
    h0: f64,
    tol: &Tolerances,
) -> Dopri5<f64, State, S> {
    Dopri5::from_param(
        system,
        tau0,
        tau1,
        0.0,
        y0,
        tol.rtol,
        tol.atol,
        0.9,
        0.04,
        0.2,
        10.0,
        tol.h_max,
        h0,
        u32::MAX,
        // No stiffness test: slow base-driven cycles run Dopri5 at its stability limit
        // on purpose (the problem is only mildly stiff there).
        u32::MAX,
        OutputType::Sparse,
    )
}

/// Whether [from, to] is too short for Dopri5 to step at this τ (its step-size underflow
/// test is 0.1·h ≤ ε·|τ|); such spans are bridged by the Hermite interpolant instead.
fn too_short(from: f64, to: f64) -> bool {
    to - from <= 100.0 * f64::EPSILON * from.abs().max(1.0)
}

/// The state on the step [a, b] at τ from its cubic Hermite interpolant.
fn interpolate(a: &StepEnd, b: &StepEnd, tau: f64) -> State {
    let mut y = State::zeros();
    for i in 0..y.len() {
        y[i] = hermite(a, b, i, tau);
    }
    y
}

fn run<S: System<f64, State>>(
    system: S,
    from: f64,
    to: f64,
    y: State,
    h: f64,
    tol: &Tolerances,
    branch: Branch,
) -> Result<()> {
    dopri(system, from, to, y, h, tol)
        .integrate()
        .map(|_| ())
        .map_err(|e| Error::Numerical(format!("Dopri5 on the {branch:?} branch: {e:?}")))
}

/// Integrate branch `branch` from (`tau0`, `y0`) to `tau_end`, stopping at the first
/// crossing of `event` (level, direction) if given. `h0` is the first trial step (0 lets
/// the solver choose).
#[allow(clippy::too_many_arguments)]
pub fn integrate<L: ForceLaw, O: StepObserver>(
    law: &L,
    osc: &Oscillator,
    cpl: &Coupling,
    branch: Branch,
    event: Option<(f64, Crossing)>,
    tau0: f64,
    y0: State,
    tau_end: f64,
    h0: f64,
    tol: &Tolerances,
    observer: &mut O,
) -> Result<SegmentEnd> {
    let mut y0 = y0;
    set_phasor(osc, tau0, &mut y0);
    let mut dy0 = State::zeros();
    rhs(law, osc, cpl, branch, tau0, &y0, &mut dy0);
    if too_short(tau0, tau_end) {
        // Nothing Dopri5 could step over: advance by one Euler step (error ~ (Δτ)²).
        return Ok(SegmentEnd {
            tau: tau_end,
            y: y0 + dy0 * (tau_end - tau0),
            switched: false,
            h_first: 0.0,
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
    };
    let segment = Segment {
        law,
        osc,
        cpl,
        branch,
        event,
        progress: &mut progress,
        observer: &mut *observer,
    };
    run(segment, tau0, tau_end, y0, h0, tol, branch)?;
    let Some((start, hit_end, t_hit)) = progress.hit else {
        let last = progress.last;
        return Ok(SegmentEnd {
            tau: last.tau,
            y: last.y,
            switched: false,
            h_first: progress.h,
        });
    };
    // Integrate the part of the step up to the switch again, from the step's start, and
    // polish the switching time by Newton steps on the re-integrated state (the Hermite
    // interpolant is only fourth-order accurate, and the force may be singular at the
    // switch, as at the JKR fold C).
    let (level, crossing) = event.expect("a hit implies an event");
    let distance = |tau: f64, y: &State| {
        let (x_b, v_b) = osc.base_at(tau);
        let d = cpl.alpha_hat(y[X], x_b) - level;
        let rate = cpl.a1 * (y[V] + v_b);
        match crossing {
            Crossing::Down => (d, rate),
            Crossing::Up => (-d, -rate),
        }
    };
    let mut t = t_hit;
    let mut y = start.y;
    for attempt in 0..4 {
        let mut refine = Progress {
            last: start,
            hit: None,
            h: 0.0,
        };
        if too_short(start.tau, t) {
            // The switch sits at the very start of the step: interpolate.
            refine.last.y = interpolate(&start, &hit_end, t);
        } else if t > start.tau {
            let mut quiet = Ignore;
            let again = Segment {
                law,
                osc,
                cpl,
                branch,
                event: None,
                progress: &mut refine,
                observer: &mut quiet,
            };
            run(again, start.tau, t, start.y, t - start.tau, tol, branch)?;
        }
        y = refine.last.y;
        let (g, rate) = distance(t, &y);
        let next = t - g / rate;
        if attempt == 3
            // 1e-8 in α̂ moves the loop area by ~1e-8 relative (the path itself stays
            // consistent: it switches where it is, a hair from the level).
            || g.abs() <= 1e-8 * (1.0 + level.abs())
            || !(next > start.tau && next.is_finite())
        {
            break;
        }
        t = next;
    }
    let mut dy = State::zeros();
    rhs(law, osc, cpl, branch, t, &y, &mut dy);
    observer.step(&start, &StepEnd { tau: t, y, dy }, branch);
    Ok(SegmentEnd {
        tau: t,
        y,
        switched: true,
        h_first: progress.h,
    })
}
