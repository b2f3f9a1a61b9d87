//! The marcher: the cantilever integrated in time, one drive period after another, as
//! a chain of segments, one per branch: closed-form free flight where the law is
//! force-free out of contact (and the oscillator is force-driven and underdamped),
//! Dopri5 otherwise; every branch switch is located and the next segment restarts from
//! the located state. The carried integrals give the energies, Fourier projections, mean
//! force and virial of each period; with the variational equations (and a saltation
//! matrix at every switch) a period also gives the exact derivative of the period map.
//!
//! The steady-state solver ([`super::steady`]) and the instrument
//! ([`crate::instrument`]) both march with it: the solver period by period, the
//! instrument watching every step ([`StepObserver`]).

use super::budget;
use super::free::FreeFlight;
use super::grazing::{Margins, SwitchLevels};
use super::model::{
    BASE, Carried, Coupling, Drive, Oscillator, RATE, RATE_TANGENT, SECTION_DIM, State, TANGENT, V,
    X, dissipative_work_index, has_tangent, phi, phi_column, reset_phi, surface_view,
};
use super::numeric::{
    self, Crossing, Events, StepEnd, StepObserver, Tolerances, hermite, hermite_turn_fraction,
};
use super::surface::Surface;
use crate::error::{Error, Result};
use crate::physics::law::{Branch, Exits, ForceLaw};
use nalgebra::{DMatrix, DVector};
use std::cell::RefCell;

/// Where the oscillator is: time, deflection, velocity and the contact branch (and a
/// relaxing sample's surface).
#[derive(Debug, Clone, PartialEq)]
pub struct Phase {
    /// τ.
    pub tau: f64,
    /// Deflection x.
    pub x: f64,
    /// Velocity x'.
    pub v: f64,
    /// Contact branch.
    pub branch: Branch,
    /// First trial step for the next numerical segment on each branch (free, contact,
    /// necked; 0: the solver's choice).
    pub h_next: [f64; Branch::COUNT],
    /// First trial step for a numerical segment that goes on from where the last
    /// [`Simulation::advance`] stopped it (0: none stopped): the integrator's own
    /// proposal, so that cutting a segment into parts costs no smaller steps.
    pub h_carry: f64,
    /// A relaxing sample's surface as the motion left it ([`super::surface`]; none for
    /// every other law, and none yet before the first period: a fresh surface then).
    pub surface: Option<Box<Surface>>,
}

impl Phase {
    /// At rest at τ = 0 out of contact.
    pub fn at_rest() -> Self {
        Self {
            tau: 0.0,
            x: 0.0,
            v: 0.0,
            branch: Branch::Free,
            h_next: [0.0; Branch::COUNT],
            h_carry: 0.0,
            surface: None,
        }
    }

    /// The section state z: (x, x').
    fn section(&self) -> DVector<f64> {
        DVector::from_column_slice(&[self.x, self.v])
    }

    /// This phase moved to the section state `z` ([`Phase::section`]).
    fn with_section(&self, z: &DVector<f64>) -> Self {
        Self {
            x: z[0],
            v: z[1],
            ..self.clone()
        }
    }
}

/// The integrals and extremes of a whole number of drive periods (dimensionless): one
/// period from [`Simulation::cycle`], or the window a steady state is averaged over.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleIntegrals {
    /// Drive periods covered (0 for a part of one: [`Simulation::advance`]).
    pub periods: u32,
    /// Length of the span in τ (`periods` drive periods, or the part of one).
    pub period: f64,
    /// Energy dissipated in the contact, ∮ −f_ts dα: the elastic part summed from the
    /// branch work functions between the located switches (exact for the computed path),
    /// a rate-dependent part from its carried integral.
    pub e_ts: f64,
    /// The part of `e_ts` done against a rate-dependent force (a viscous sample's loss),
    /// from its carried integral; zero for an elastic law.
    pub e_viscous: f64,
    /// The part of `e_ts` a capillary neck lost, from its share of the branch work
    /// functions ([`ForceLaw::capillary_work_hat`]); zero without a neck.
    pub e_capillary: f64,
    /// Energy dissipated by damping.
    pub e_damp: f64,
    /// Energy put in by the drive ([`Oscillator::drive_work`]).
    pub e_drive: f64,
    /// Change of the oscillator's energy ½(x² + x'²) over the span.
    pub delta_mechanical: f64,
    /// ∫ x cos Ωτ dτ.
    pub sc: f64,
    /// ∫ x sin Ωτ dτ.
    pub ss: f64,
    /// ∫ f_ts dτ.
    pub f_int: f64,
    /// ∫ f_ts x dτ.
    pub virial_int: f64,
    /// Time spent on the contact branch.
    pub contact_time: f64,
    /// Smallest separation α̂ met.
    pub min_alpha_hat: f64,
    /// Largest (most repulsive) f_ts met.
    pub max_force: f64,
    /// Smallest (most attractive) f_ts met.
    pub min_force: f64,
    /// The grazing margins ([`super::grazing`]): the smallest distance in α̂ from a
    /// turning point of the separation to a switch level that matters on its branch,
    /// and to one where the force jumps (∞: no turning point near such a level).
    pub grazing: Margins,
    /// Number of jumps into contact.
    pub jumps_in: u32,
    /// Number of jumps out of contact.
    pub jumps_out: u32,
}

impl CycleIntegrals {
    /// Amplitude of the fundamental over the span (units of L): what a lock-in reads.
    pub fn amplitude(&self) -> f64 {
        2.0 / self.period * self.sc.hypot(self.ss)
    }

    /// Phase lag φ of the fundamental over the span, z ≈ A cos(ωt − φ), in radians.
    pub fn phase(&self) -> f64 {
        self.ss.atan2(self.sc)
    }

    /// Energy dissipated in the contact per drive period.
    pub fn e_ts_per_period(&self) -> f64 {
        self.e_ts / f64::from(self.periods)
    }

    /// Energy put in by the drive per drive period.
    pub fn e_drive_per_period(&self) -> f64 {
        self.e_drive / f64::from(self.periods)
    }

    /// The integrals of this span followed by `next` (sums; extremes over both).
    pub fn then(&self, next: &CycleIntegrals) -> CycleIntegrals {
        CycleIntegrals {
            periods: self.periods + next.periods,
            period: self.period + next.period,
            e_ts: self.e_ts + next.e_ts,
            e_viscous: self.e_viscous + next.e_viscous,
            e_capillary: self.e_capillary + next.e_capillary,
            e_damp: self.e_damp + next.e_damp,
            e_drive: self.e_drive + next.e_drive,
            delta_mechanical: self.delta_mechanical + next.delta_mechanical,
            sc: self.sc + next.sc,
            ss: self.ss + next.ss,
            f_int: self.f_int + next.f_int,
            virial_int: self.virial_int + next.virial_int,
            contact_time: self.contact_time + next.contact_time,
            min_alpha_hat: self.min_alpha_hat.min(next.min_alpha_hat),
            max_force: self.max_force.max(next.max_force),
            min_force: self.min_force.min(next.min_force),
            grazing: self.grazing.min(next.grazing),
            jumps_in: self.jumps_in + next.jumps_in,
            jumps_out: self.jumps_out + next.jumps_out,
        }
    }
}

/// Tracks extremes of the separation and force over accepted steps, then passes each
/// step on.
struct Tracker<'a, L: ForceLaw, O: StepObserver> {
    law: &'a L,
    osc: &'a Oscillator,
    cpl: &'a Coupling,
    inner: &'a mut O,
    min_alpha: f64,
    max_f: f64,
    min_f: f64,
    /// The law's switch levels, found at the first turning point (a part of a period
    /// often has none, [`Simulation::advance`]).
    levels: Option<SwitchLevels>,
    /// The grazing margins so far.
    margins: Margins,
    /// A relaxing sample's surface, open at the start of each step shown.
    surface: Option<&'a RefCell<Surface>>,
}

impl<L: ForceLaw, O: StepObserver> Tracker<'_, L, O> {
    /// Take a turning point of the separation at `alpha_hat` on `branch` into the
    /// grazing margin.
    #[inline]
    fn turn(&mut self, branch: Branch, alpha_hat: f64) {
        let law = self.law;
        let levels = self.levels.get_or_insert_with(|| SwitchLevels::of(law));
        self.margins = self.margins.min(levels.margins(branch, alpha_hat));
    }
}

impl<L: ForceLaw, O: StepObserver> StepObserver for Tracker<'_, L, O> {
    fn step<const N: usize>(&mut self, a: &StepEnd<N>, b: &StepEnd<N>, branch: Branch) {
        let alpha = |tau: f64, x: f64| self.cpl.alpha_hat(x, self.osc.base_at(tau).0);
        let mut lowest = alpha(b.tau, b.y[X]);
        // A turning point inside the step: the minimum of the Hermite cubic, where its
        // derivative (a quadratic in the step fraction) vanishes.
        // The force there is an extreme too when the law is monotonic on the branch, as
        // every contact branch is: sampling step ends alone would miss the peak.
        self.max_f = self.max_f.max(b.dy[Carried::Force]);
        self.min_f = self.min_f.min(b.dy[Carried::Force]);
        if a.y[V] > 0.0 && b.y[V] < 0.0 {
            let tau = a.tau + hermite_turn(a, b, false) * (b.tau - a.tau);
            let top = alpha(tau, hermite(a, b, X, tau));
            self.turn(branch, top);
        }
        if a.y[V] < 0.0 && b.y[V] > 0.0 {
            let t = hermite_turn(a, b, true);
            let tau = a.tau + t * (b.tau - a.tau);
            // (The tip is at rest there; the support may not be.)
            let turn =
                self.cpl
                    .contact_state((hermite(a, b, X, tau), 0.0), self.osc.base_at(tau), branch);
            lowest = lowest.min(turn.alpha_hat);
            self.turn(branch, turn.alpha_hat);
            let force_hat = match self.surface {
                Some(s) => {
                    let view = [-turn.alpha_hat, -turn.rate_hat];
                    let pushed = s.borrow().force_at(tau, view);
                    self.law.t_hat(turn.alpha_hat, branch) + self.law.surface_t_hat(&turn, pushed)
                }
                None => self.law.force_hat(&turn),
            };
            let f = -self.cpl.f_scale * force_hat;
            self.max_f = self.max_f.max(f);
            self.min_f = self.min_f.min(f);
        }
        self.min_alpha = self.min_alpha.min(lowest);
        self.inner.step(a, b, branch);
    }

    fn free_flight(&mut self, flight: &FreeFlight, from: f64, to: f64) {
        self.max_f = self.max_f.max(0.0);
        self.min_f = self.min_f.min(0.0);
        self.inner.free_flight(flight, from, to);
    }
}

/// Step fraction in [0, 1] of the turning point of the deflection's Hermite cubic on a
/// step where the velocity changes sign: its minimum (`rising`: from negative to
/// positive) or its maximum.
#[doc(hidden)]
pub fn hermite_turn<const N: usize>(a: &StepEnd<N>, b: &StepEnd<N>, rising: bool) -> f64 {
    let h = b.tau - a.tau;
    hermite_turn_fraction((a.y[X], h * a.y[V]), (b.y[X], h * b.y[V]), rising)
}

/// A law, an oscillator, its coupling to the contact and the integrator settings.
#[derive(Debug)]
pub struct Simulation<'a, L: ForceLaw> {
    /// Tip–sample force law.
    pub law: &'a L,
    /// The oscillator.
    pub osc: Oscillator,
    /// Coupling to the contact.
    pub cpl: Coupling,
    /// Integrator settings.
    pub tol: Tolerances,
}

// By hand: derived, they would ask the law itself to be Copy.
impl<L: ForceLaw> Clone for Simulation<'_, L> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<L: ForceLaw> Copy for Simulation<'_, L> {}

/// The loosest relative tolerance any integration runs at.
pub(crate) const LOOSEST_RTOL: f64 = 1e-5;

impl<L: ForceLaw> Simulation<'_, L> {
    /// Whether the law's sample has a surface the march carries ([`super::surface`]).
    pub fn has_surface(&self) -> bool {
        self.law.has_surface()
    }

    /// Dimension of the section state: x and x'.
    pub fn section_dim(&self) -> usize {
        SECTION_DIM
    }

    /// The section state of `phase`: (x, x'), lengths in units of L.
    pub fn z(&self, phase: &Phase) -> DVector<f64> {
        phase.section()
    }

    /// `phase` moved to the section state `z` ([`Simulation::z`]).
    pub fn at_z(&self, phase: &Phase, z: &DVector<f64>) -> Phase {
        phase.with_section(z)
    }

    /// The branch a state at rest separation α̂ starts on: in contact if the tip is already
    /// below the jump-in separation.
    pub(crate) fn branch_at(&self, tau: f64, x: f64) -> Branch {
        let alpha = self.cpl.alpha_hat(x, self.osc.base_at(tau).0);
        if alpha <= self.law.jump_in_alpha_hat() {
            Branch::Contact
        } else {
            Branch::Free
        }
    }

    /// The force-driven free steady state at τ = 0 (or rest for a base drive).
    pub fn free_steady_start(&self) -> Phase {
        let (x, v) = FreeFlight::steady(&self.osc)
            .map(|(a, b)| (a, b * self.osc.omega))
            .unwrap_or((0.0, 0.0));
        Phase {
            tau: 0.0,
            x,
            v,
            branch: self.branch_at(0.0, x),
            h_next: [0.0; Branch::COUNT],
            h_carry: 0.0,
            surface: None,
        }
    }

    /// Integrate one drive period from `phase`, updating it.
    pub fn cycle<O: StepObserver>(
        &self,
        phase: &mut Phase,
        observer: &mut O,
    ) -> Result<CycleIntegrals> {
        self.span(phase, self.osc.period(), false, observer)
    }

    /// Integrate the part `span` (0 < span ≤ one drive period, in τ) of a drive period
    /// from `phase`, updating it: what a force that changes between parts of a period
    /// needs (the thermal force, [`crate::instrument::thermal`]). The integrals cover
    /// the span (`periods` 0 unless it is a whole period). A numerical segment the
    /// span's end cuts goes on in the next call from the step its integrator proposed
    /// ([`Phase::h_carry`]).
    pub fn advance<O: StepObserver>(
        &self,
        phase: &mut Phase,
        span: f64,
        observer: &mut O,
    ) -> Result<CycleIntegrals> {
        self.span(phase, span.min(self.osc.period()), true, observer)
    }

    /// Integrate `span` from `phase`; `carry`: whether a segment cut at the span's end
    /// leaves its proposed step in [`Phase::h_carry`].
    fn span<O: StepObserver>(
        &self,
        phase: &mut Phase,
        span: f64,
        carry: bool,
        observer: &mut O,
    ) -> Result<CycleIntegrals> {
        Ok(if self.law.is_rate_dependent() {
            self.cycle_in::<RATE, O>(phase, span, carry, observer)?.0
        } else {
            self.cycle_in::<BASE, O>(phase, span, carry, observer)?.0
        })
    }

    /// March `periods` drive periods from `phase` (left at their end, its τ kept within
    /// one period of the drive's origin), every integrator step and free flight shown
    /// to `observer`: the motion in time, as an instrument watching it sees it (a
    /// [`crate::instrument::lockin::LockIn`], say).
    pub fn march<O: StepObserver>(
        &self,
        phase: &mut Phase,
        periods: usize,
        observer: &mut O,
    ) -> Result<()> {
        for _ in 0..periods {
            self.rewind(phase);
            self.cycle(phase, observer)?;
        }
        Ok(())
    }

    /// Integrate one drive period from `phase`, updating it, with the derivative of the
    /// period map, ∂z(τ + T)/∂(z, q)(τ), z the section state ([`Simulation::z`]: x, x'),
    /// q = z_c/L: the variational equations along every segment, the free flight's
    /// transition matrix in closed form, and at every branch switch the saltation
    /// matrix: where the force jumps by Δf_ts as α̂ crosses its level, δx' gains
    /// Δf_ts(δx + δq)/(x' + x_b').
    pub fn cycle_with_derivative(
        &self,
        phase: &mut Phase,
    ) -> Result<(CycleIntegrals, DMatrix<f64>)> {
        self.advance_with_derivative(phase, self.osc.period())
    }

    /// [`Simulation::cycle_with_derivative`] over the part `span` (0 < span ≤ one drive
    /// period) of a period: ∂z(τ + span)/∂(z, q)(τ).
    pub fn advance_with_derivative(
        &self,
        phase: &mut Phase,
        span: f64,
    ) -> Result<(CycleIntegrals, DMatrix<f64>)> {
        let span = span.min(self.osc.period());
        if self.has_surface() {
            return Err(Error::NotApplicable(
                "the period map's derivative is not computed for a relaxing sample: its \
                 surface remembers every tap, as many variables as its elements (its steady \
                 state is found by marching; orbit continuation, shooting and harmonic \
                 balance do not take it)"
                    .into(),
            ));
        }
        let (integrals, derivative) = if self.law.is_rate_dependent() {
            self.cycle_in::<RATE_TANGENT, _>(phase, span, false, &mut numeric::Ignore)
        } else {
            self.cycle_in::<TANGENT, _>(phase, span, false, &mut numeric::Ignore)
        }?;
        Ok((integrals, derivative.expect("a tangent layout carries Φ")))
    }

    /// Move `phase` back by whole drive periods to τ in [0, T): the drive is periodic,
    /// and a τ that grows through a long run costs the integrator its precision (at
    /// τ ≈ 10⁷ Dopri5's steps underflow).
    pub(crate) fn rewind(&self, phase: &mut Phase) {
        let period = self.osc.period();
        if phase.tau >= period {
            phase.tau -= (phase.tau / period).floor() * period;
        }
    }

    /// The branch a state can be on: its own, unless it sits on the wrong side of a
    /// switch (a state carried over from another setpoint or moved by Newton's method:
    /// the tip cannot be out of contact below the jump-in separation, nor in contact
    /// above the jump-out one).
    pub(crate) fn consistent_branch(&self, phase: &Phase) -> Branch {
        let alpha = self.cpl.alpha_hat(phase.x, self.osc.base_at(phase.tau).0);
        match self.law.exits(phase.branch) {
            Exits {
                below: Some((level, next)),
                ..
            } if alpha <= level => next,
            Exits {
                above: Some((level, next)),
                ..
            } if alpha >= level => next,
            _ => phase.branch,
        }
    }

    /// Apply the saltation matrix of a switch `from` → `to` in state `y` at τ.
    fn saltation<const N: usize>(&self, tau: f64, y: &mut State<N>, from: Branch, to: Branch) {
        if !has_tangent(N) {
            return;
        }
        let (x_b, v_b) = self.osc.base_at(tau);
        let at = |branch| self.cpl.contact_state((y[X], y[V]), (x_b, v_b), branch);
        let jump =
            -self.cpl.f_scale * (self.law.force_hat(&at(to)) - self.law.force_hat(&at(from)));
        if jump == 0.0 {
            return;
        }
        let dim = SECTION_DIM;
        let speed = y[V] + v_b;
        let k = jump / speed;
        for col in 0..=dim {
            let at = phi_column(col);
            // δx + δq of this column: how far the switch moves.
            let shift = y[at] + if col == dim { 1.0 } else { 0.0 };
            y[at + 1] += k * shift;
        }
    }

    /// Integrate `span` (at most a drive period) from `phase`; `carry` as in
    /// [`Simulation::span`].
    fn cycle_in<const N: usize, O: StepObserver>(
        &self,
        phase: &mut Phase,
        span: f64,
        carry: bool,
        observer: &mut O,
    ) -> Result<(CycleIntegrals, Option<DMatrix<f64>>)> {
        budget::spend(1)?;
        let period = self.osc.period();
        let tau_end = phase.tau + span;
        phase.branch = self.consistent_branch(phase);
        let mut y = State::<N>::zeros();
        y[X] = phase.x;
        y[V] = phase.v;
        if has_tangent(N) {
            reset_phi(&mut y);
        }
        // A relaxing sample's surface: as the motion left it, or fresh.
        let surface = phase
            .surface
            .take()
            .map(|s| *s)
            .or_else(|| Surface::of(self.law, self.cpl.a1))
            .map(RefCell::new);
        let mechanical = |y: &State<N>| 0.5 * (y[X] * y[X] + y[V] * y[V]);
        let e0 = mechanical(&y);
        let start = (phase.tau, phase.x, phase.v);
        let mut tracker = Tracker {
            law: self.law,
            osc: &self.osc,
            cpl: &self.cpl,
            inner: observer,
            min_alpha: f64::INFINITY,
            max_f: f64::NEG_INFINITY,
            min_f: f64::INFINITY,
            levels: None,
            margins: Margins::NONE,
            surface: surface.as_ref(),
        };
        let (mut contact_time, mut jumps_in, mut jumps_out) = (0.0, 0, 0);
        // E_ts = (RΔγ/(kL))/(L/(με)) ∫ T̂ dα̂ in units of kL².
        let work_scale = self.cpl.f_scale / self.cpl.a1;
        let (mut e_ts, mut e_capillary) = (0.0, 0.0);
        let mut tau = phase.tau;
        // (Closed-form free flight ends only falling to the jump-in, into contact.)
        let (jump_in, closed_form) = match self.law.exits(Branch::Free) {
            Exits {
                below: Some((level, Branch::Contact)),
                above: None,
            } => (level, self.law.free_branch_is_force_free()),
            _ => (f64::NAN, false),
        };
        // Stop when the remaining time is round-off.
        while tau_end - tau > 1e-12 * period {
            let flight = (phase.branch == Branch::Free && closed_form)
                .then(|| FreeFlight::new(&self.osc, tau, y[X], y[V]))
                .flatten();
            if let Some(flight) = flight {
                let level = self.cpl.x_at(jump_in);
                // The separation's motion (under a base drive the support moves too),
                // sampled an eighth of a drive period apart — of the lever's own under
                // a slow base drive, where the drive period is many of its periods.
                let max_dt = match self.osc.drive {
                    Drive::Force { .. } => period / 8.0,
                    Drive::Base { .. } | Drive::Ramp { .. } => {
                        period.min(2.0 * std::f64::consts::PI) / 8.0
                    }
                };
                let fall = flight
                    .separation()
                    .first_fall_to(level, tau, tau_end, max_dt);
                let (hit, min_x) = (fall.hit, fall.min_x);
                let stop = hit.unwrap_or(tau_end);
                for turn in [fall.lowest_turn, fall.highest_turn] {
                    if turn.is_finite() {
                        tracker.turn(Branch::Free, self.cpl.alpha_hat(turn, 0.0));
                    }
                }
                flight.advance(&mut y, tau, stop);
                if let Some(surface) = &surface {
                    let view = surface_view(&self.osc, &self.cpl, stop, &y);
                    surface
                        .borrow_mut()
                        .creep(stop - tau, stop, view, self.osc.period())?;
                }
                tracker.free_flight(&flight, tau, stop);
                tracker.min_alpha = tracker.min_alpha.min(self.cpl.alpha_hat(min_x, 0.0));
                tau = stop;
                if hit.is_some() {
                    self.saltation(tau, &mut y, Branch::Free, Branch::Contact);
                    phase.branch = Branch::Contact;
                    jumps_in += 1;
                }
                continue;
            }
            let exits = self.law.exits(phase.branch);
            let level = |exit: Option<(f64, Branch)>| exit.map(|e| e.0).filter(|l| l.is_finite());
            let events = Events {
                below: level(exits.below),
                above: level(exits.above),
            };
            let alpha_at =
                |tau: f64, y: &State<N>| self.cpl.alpha_hat(y[X], self.osc.base_at(tau).0);
            let alpha_start = alpha_at(tau, &y);
            let work_start = self.law.work_hat(alpha_start, phase.branch);
            let capillary_start = self.law.capillary_work_hat(alpha_start, phase.branch);
            let end = numeric::integrate(
                self.law,
                &self.osc,
                &self.cpl,
                phase.branch,
                events,
                tau,
                y,
                tau_end,
                if phase.h_carry > 0.0 {
                    phase.h_carry
                } else {
                    phase.h_next[phase.branch as usize]
                },
                &self.tol,
                surface.as_ref(),
                &mut tracker,
            )?;
            let alpha_end = alpha_at(end.tau, &end.y);
            e_ts += work_scale * (self.law.work_hat(alpha_end, phase.branch) - work_start);
            e_capillary += work_scale
                * (self.law.capillary_work_hat(alpha_end, phase.branch) - capillary_start);
            if phase.branch == Branch::Contact {
                contact_time += end.tau - tau;
            }
            // The first step of a segment entered afresh is how the next entry starts;
            // one cut at the span's end goes on from its proposed step.
            if end.h_first > 0.0 && phase.h_carry == 0.0 {
                phase.h_next[phase.branch as usize] = end.h_first;
            }
            phase.h_carry = if carry && end.switched.is_none() {
                end.h_proposed
            } else {
                0.0
            };
            tau = end.tau;
            y = end.y;
            if let Some(crossing) = end.switched {
                let exit = match crossing {
                    Crossing::Down => exits.below,
                    Crossing::Up => exits.above,
                };
                let next = exit.expect("a switch happens at an exit").1;
                jumps_in += u32::from(next == Branch::Contact);
                jumps_out += u32::from(phase.branch == Branch::Contact);
                self.saltation(tau, &mut y, phase.branch, next);
                phase.branch = next;
            }
        }
        // A rate-dependent force's work, carried along (zero for every other law).
        let e_viscous = dissipative_work_index(N).map_or(0.0, |i| work_scale * y[i]);
        e_ts += e_viscous;
        phase.tau = tau_end;
        phase.x = y[X];
        phase.v = y[V];
        let integrals = CycleIntegrals {
            periods: u32::from(span == period),
            period: span,
            e_ts,
            e_viscous,
            e_capillary,
            e_damp: y[Carried::Damping],
            e_drive: self.osc.drive_work(
                start,
                (tau, y[X], y[V]),
                (y[Carried::CosProjection], y[Carried::SinProjection]),
                y[Carried::Force],
            ),
            delta_mechanical: mechanical(&y) - e0,
            sc: y[Carried::CosProjection],
            ss: y[Carried::SinProjection],
            f_int: y[Carried::Force],
            virial_int: y[Carried::Virial],
            contact_time,
            min_alpha_hat: tracker.min_alpha,
            max_force: tracker.max_f,
            min_force: tracker.min_f,
            grazing: tracker.margins,
            jumps_in,
            jumps_out,
        };
        phase.surface = surface.map(|s| Box::new(s.into_inner()));
        Ok((integrals, has_tangent(N).then(|| phi(&y))))
    }

    /// This simulation with the integrator's relative tolerance raised to `rtol` (at most
    /// [`LOOSEST_RTOL`]; never lowered), the absolute one in proportion.
    pub(crate) fn loosened(&self, rtol: f64) -> Self {
        let rtol = self.tol.rtol.max(rtol.min(LOOSEST_RTOL));
        Self {
            tol: Tolerances {
                rtol,
                atol: self.tol.atol * rtol / self.tol.rtol,
                ..self.tol
            },
            ..*self
        }
    }
}
