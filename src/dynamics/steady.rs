//! Cycle-by-cycle integration to the steady state, its classification and what an
//! instrument reads from it.
//!
//! Each drive period is integrated as a chain of segments, one per branch: closed-form
//! free flight where the law is force-free out of contact (and the oscillator is
//! force-driven and underdamped), Dopri5 otherwise; every branch switch is located and the
//! next segment restarts from the located state. The carried integrals give the energies,
//! Fourier projections, mean force and virial of each cycle.
//!
//! The steady state is found on the period map P (the state at the same drive phase one
//! period later). Its exact derivative comes from the variational equations integrated
//! with the motion and a saltation matrix at every branch switch, so Newton's method on
//! Pⁿ(z) − z converges quadratically to a period-n orbit, and the orbit's Floquet
//! multipliers (the eigenvalues of the monodromy matrix) say whether it is stable. Motion
//! that settles on no orbit of period ≤ [`MAX_PERIOD`] is `irregular` and averaged over a
//! window that grows until its batch means agree.

use super::budget;
use super::capture::Candidate;
use super::free::FreeFlight;
use super::grazing::{Margins, SwitchLevels};
use super::model::{
    BASE, Carried, Coupling, MEMORY, MEMORY_TANGENT, MODES, Oscillator, RATE, RATE_TANGENT, State,
    TANGENT, V, X, chain, dissipative_work_index, has_tangent, internal, internal_count, phi,
    phi_column, phi_start, relax_internal, reset_phi, section_dim, set_internal,
};
use super::numeric::{
    self, Crossing, Events, StepEnd, StepObserver, Tolerances, hermite, internal_at,
};
use crate::error::{Error, Result};
use crate::law::{Branch, Exits, ForceLaw, Internal, MAX_INTERNAL};
use nalgebra::{Complex, DMatrix, DVector};

/// Where the oscillator is: time, deflection, velocity, the law's internal state and
/// the contact branch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Phase {
    /// τ.
    pub tau: f64,
    /// Deflection x.
    pub x: f64,
    /// Velocity x'.
    pub v: f64,
    /// The law's internal state ([`ForceLaw::internal_states`]; zeros for a law without).
    pub internal: Internal,
    /// Contact branch.
    pub branch: Branch,
    /// First trial step for the next numerical segment on each branch (free, contact,
    /// necked; 0: the solver's choice).
    pub h_next: [f64; Branch::COUNT],
}

impl Phase {
    /// At rest at τ = 0 out of contact.
    pub fn at_rest() -> Self {
        Self {
            tau: 0.0,
            x: 0.0,
            v: 0.0,
            internal: Internal::default(),
            branch: Branch::Free,
            h_next: [0.0; Branch::COUNT],
        }
    }

    /// The section state z of dimension `d`: (x, x'), then the first d − 2 internal
    /// variables times `scale`.
    fn section(&self, d: usize, scale: f64) -> DVector<f64> {
        DVector::from_fn(d, |i, _| match i {
            0 => self.x,
            1 => self.v,
            k => scale * self.internal[k - 2 * MODES],
        })
    }

    /// This phase moved to the section state `z` ([`Phase::section`]).
    fn with_section(&self, z: &DVector<f64>, scale: f64) -> Self {
        let mut internal = self.internal;
        for (k, s) in internal.iter_mut().enumerate().take(z.len() - 2 * MODES) {
            *s = z[2 * MODES + k] / scale;
        }
        Self {
            x: z[0],
            v: z[1],
            internal,
            ..*self
        }
    }
}

/// The integrals and extremes of a whole number of drive periods (dimensionless): one
/// period from [`Simulation::cycle`], or the window a steady state is averaged over.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleIntegrals {
    /// Drive periods covered.
    pub periods: u32,
    /// Length of the span in τ (`periods` drive periods).
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
    levels: SwitchLevels,
    /// The grazing margins so far.
    margins: Margins,
}

impl<L: ForceLaw, O: StepObserver> Tracker<'_, L, O> {
    /// Take a turning point of the separation at `alpha_hat` on `branch` into the
    /// grazing margin.
    #[inline]
    fn turn(&mut self, branch: Branch, alpha_hat: f64) {
        self.margins = self.margins.min(self.levels.margins(branch, alpha_hat));
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
            let turn = self.cpl.contact_state(
                (hermite(a, b, X, tau), 0.0),
                self.osc.base_at(tau),
                branch,
                internal_at(a, b, tau),
            );
            lowest = lowest.min(turn.alpha_hat);
            self.turn(branch, turn.alpha_hat);
            let f = -self.cpl.f_scale * self.law.force_hat(&turn);
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
fn hermite_turn<const N: usize>(a: &StepEnd<N>, b: &StepEnd<N>, rising: bool) -> f64 {
    let h = b.tau - a.tau;
    let (p0, p1, m0, m1) = (a.y[X], b.y[X], h * a.y[V], h * b.y[V]);
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

/// The longest period looked for; motion that repeats after no n ≤ this is `irregular`.
/// Periods up to [`SHORT_PERIOD`] are looked for wherever the motion nearly repeats;
/// longer ones (mode locks near grazing, such as 13 touches in 27 periods) where the
/// section state has returned within `LOCK_GAP` (1e-5) three periods running.
pub const MAX_PERIOD: usize = 1000;

/// The longest period looked for from loose near-returns, and by time-marching alone
/// (without shooting).
pub const SHORT_PERIOD: usize = 8;

/// How close (units of L) the section state must return after n > [`SHORT_PERIOD`]
/// periods, three periods running, for a period-n orbit to be looked for.
const LOCK_GAP: f64 = 1e-5;

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

/// The most dimensions a section state has: each mode's x and x', and the law's
/// internal state.
pub const MAX_SECTION: usize = 2 * MODES + MAX_INTERNAL;

/// Floquet multipliers of a periodic orbit: the eigenvalues of its monodromy matrix, one
/// per dimension of the section state (two for a law without internal state).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Multipliers {
    values: [Complex<f64>; MAX_SECTION],
    len: usize,
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

/// The n-period map evaluated at a state.
pub(crate) struct MapValue {
    /// The state n periods later.
    pub end: Phase,
    /// ∂z(end)/∂(z, q)(start), z the section state.
    pub derivative: DMatrix<f64>,
    /// The integrals over the n periods.
    pub integrals: CycleIntegrals,
    /// |state after k + 1 periods − start|∞ for k < n.
    pub returns: Vec<f64>,
}

impl MapValue {
    /// The derivative in the state alone (the monodromy matrix on an orbit).
    pub fn monodromy(&self) -> DMatrix<f64> {
        let d = self.derivative.nrows();
        self.derivative.columns(0, d).into_owned()
    }
}

/// A periodic orbit found by Newton's method.
struct Orbit {
    /// The state on the orbit at the section.
    phase: Phase,
    /// |Pⁿ(z) − z|∞ there.
    residual: f64,
}

impl<L: ForceLaw> Simulation<'_, L> {
    /// Dimension of the section state: x, x' and the law's internal state.
    pub fn section_dim(&self) -> usize {
        2 * MODES + self.law.internal_states().min(MAX_INTERNAL)
    }

    /// The section state of `phase`: (x, x') and the law's internal variables (forces
    /// in the contact's units, [`ForceLaw::internal_states`]) as forces in units of kL,
    /// so that every component is a length in units of L and one norm and tolerance
    /// serve them all.
    pub fn z(&self, phase: &Phase) -> DVector<f64> {
        phase.section(self.section_dim(), self.cpl.f_scale)
    }

    /// `phase` moved to the section state `z` ([`Simulation::z`]).
    pub fn at_z(&self, phase: &Phase, z: &DVector<f64>) -> Phase {
        phase.with_section(z, self.cpl.f_scale)
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
            internal: Internal::default(),
            branch: self.branch_at(0.0, x),
            h_next: [0.0; Branch::COUNT],
        }
    }

    /// Integrate one drive period from `phase`, updating it.
    pub fn cycle<O: StepObserver>(
        &self,
        phase: &mut Phase,
        observer: &mut O,
    ) -> Result<CycleIntegrals> {
        Ok(if self.law.internal_states() > 0 {
            self.cycle_in::<MEMORY, O>(phase, observer)?.0
        } else if self.law.is_rate_dependent() {
            self.cycle_in::<RATE, O>(phase, observer)?.0
        } else {
            self.cycle_in::<BASE, O>(phase, observer)?.0
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
    /// period map, ∂z(τ + T)/∂(z, q)(τ), z the section state ([`Simulation::z`]: x, x'
    /// and the law's internal state, in its units), q = z_c/L: the variational equations along every segment, the
    /// free flight's transition matrix in closed form, and at every branch switch the
    /// saltation matrix: where the force jumps by Δf_ts as α̂ crosses its level, δx'
    /// gains Δf_ts(δx + δq)/(x' + x_b') (and an internal variable whose rate jumps, its
    /// jump times the same).
    pub fn cycle_with_derivative(
        &self,
        phase: &mut Phase,
    ) -> Result<(CycleIntegrals, DMatrix<f64>)> {
        let (integrals, derivative) = if self.law.internal_states() > 0 {
            self.cycle_in::<MEMORY_TANGENT, _>(phase, &mut numeric::Ignore)
        } else if self.law.is_rate_dependent() {
            self.cycle_in::<RATE_TANGENT, _>(phase, &mut numeric::Ignore)
        } else {
            self.cycle_in::<TANGENT, _>(phase, &mut numeric::Ignore)
        }?;
        let mut derivative = derivative.expect("a tangent layout carries Φ");
        // In the section's units (`Simulation::z`): internal rows times f_scale, internal
        // columns divided by it.
        let d = derivative.nrows();
        for row in 2 * MODES..d {
            for col in 0..=d {
                derivative[(row, col)] *= self.cpl.f_scale;
                if col < d {
                    derivative[(col, row)] /= self.cpl.f_scale;
                }
            }
        }
        Ok((integrals, derivative))
    }

    /// Move `phase` back by whole drive periods to τ in [0, T): the drive is periodic,
    /// and a τ that grows through a long run costs the integrator its precision (at
    /// τ ≈ 10⁷ Dopri5's steps underflow).
    fn rewind(&self, phase: &mut Phase) {
        let period = self.osc.period();
        if phase.tau >= period {
            phase.tau -= (phase.tau / period).floor() * period;
        }
    }

    /// The branch a state can be on: its own, unless it sits on the wrong side of a
    /// switch (a state carried over from another setpoint or moved by Newton's method:
    /// the tip cannot be out of contact below the jump-in separation, nor in contact
    /// above the jump-out one).
    fn consistent_branch(&self, phase: &Phase) -> Branch {
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
        let at = |branch| {
            self.cpl
                .contact_state((y[X], y[V]), (x_b, v_b), branch, internal(y))
        };
        let jump =
            -self.cpl.f_scale * (self.law.force_hat(&at(to)) - self.law.force_hat(&at(from)));
        let kinds = internal_count(N);
        let (rates_to, rates_from) = if kinds > 0 {
            (
                self.law.internal_rates_hat(&at(to)),
                self.law.internal_rates_hat(&at(from)),
            )
        } else {
            ([0.0; MAX_INTERNAL], [0.0; MAX_INTERNAL])
        };
        let rate_jumps = (0..kinds).any(|k| rates_to[k] != rates_from[k]);
        if jump == 0.0 && !rate_jumps {
            return;
        }
        let dim = section_dim(N);
        let speed = y[V] + v_b;
        let k = jump / speed;
        for col in 0..=dim {
            let at = phi_column(N, col);
            // δx + δq of this column: how far the switch moves.
            let shift = y[at] + if col == dim { 1.0 } else { 0.0 };
            y[at + 1] += k * shift;
            for i in 0..kinds {
                y[at + 2 * MODES + i] += (rates_to[i] - rates_from[i]) / speed * shift;
            }
        }
    }

    fn cycle_in<const N: usize, O: StepObserver>(
        &self,
        phase: &mut Phase,
        observer: &mut O,
    ) -> Result<(CycleIntegrals, Option<DMatrix<f64>>)> {
        budget::spend(1)?;
        let period = self.osc.period();
        let tau_end = phase.tau + period;
        phase.branch = self.consistent_branch(phase);
        let mut y = State::<N>::zeros();
        y[X] = phase.x;
        y[V] = phase.v;
        set_internal(&mut y, &phase.internal);
        if has_tangent(N) {
            reset_phi(&mut y);
        }
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
            levels: SwitchLevels::of(self.law),
            margins: Margins::NONE,
        };
        let (mut contact_time, mut jumps_in, mut jumps_out) = (0.0, 0, 0);
        // E_ts = (RΔγ/(kL))/(L/(με)) ∫ T̂ dα̂ in units of kL².
        let work_scale = self.cpl.f_scale / self.cpl.a1;
        let (mut e_ts, mut e_capillary) = (0.0, 0.0);
        let mut tau = phase.tau;
        // An internal state evolves in free flight too: in closed form if the law says
        // how it relaxes there, else integrated with the motion.
        let relaxation = self.law.free_relaxation_rates();
        // (Closed-form free flight ends only falling to the jump-in, into contact.)
        let (jump_in, closed_form) = match self.law.exits(Branch::Free) {
            Exits {
                below: Some((level, Branch::Contact)),
                above: None,
            } => (
                level,
                self.law.free_branch_is_force_free()
                    && (internal_count(N) == 0 || relaxation.is_some()),
            ),
            _ => (f64::NAN, false),
        };
        // Stop when the remaining time is round-off.
        while tau_end - tau > 1e-12 * period {
            let flight = (phase.branch == Branch::Free && closed_form)
                .then(|| FreeFlight::new(&self.osc, tau, y[X], y[V]))
                .flatten();
            if let Some(flight) = flight {
                let level = self.cpl.x_at(jump_in);
                let fall = flight.first_fall_to(level, tau, tau_end, period / 8.0);
                let (hit, min_x) = (fall.hit, fall.min_x);
                let stop = hit.unwrap_or(tau_end);
                for turn in [fall.lowest_turn, fall.highest_turn] {
                    if turn.is_finite() {
                        tracker.turn(Branch::Free, self.cpl.alpha_hat(turn, 0.0));
                    }
                }
                flight.advance(&mut y, tau, stop);
                if let Some(rates) = &relaxation {
                    relax_internal(&mut y, rates, stop - tau);
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
                phase.h_next[phase.branch as usize],
                &self.tol,
                &mut tracker,
            )?;
            let alpha_end = alpha_at(end.tau, &end.y);
            e_ts += work_scale * (self.law.work_hat(alpha_end, phase.branch) - work_start);
            e_capillary += work_scale
                * (self.law.capillary_work_hat(alpha_end, phase.branch) - capillary_start);
            if phase.branch == Branch::Contact {
                contact_time += end.tau - tau;
            }
            if end.h_first > 0.0 {
                phase.h_next[phase.branch as usize] = end.h_first;
            }
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
        phase.internal = internal(&y);
        let integrals = CycleIntegrals {
            periods: 1,
            period,
            e_ts,
            e_viscous,
            e_capillary,
            e_damp: y[Carried::Damping],
            e_drive: self.osc.drive_work(
                start,
                (tau, y[X], y[V]),
                y[Carried::CosProjection],
                y[Carried::SinProjection],
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
        Ok((integrals, has_tangent(N).then(|| phi(&y))))
    }

    /// The n-period map from `start` moved to `z`: the state n periods later and the
    /// map's derivative there; `None` if the motion does not return on the branch it
    /// left, or if the variational equations cannot be integrated there (a tip that
    /// stalls at a fold of the force law, where the map is not smooth). Counts the
    /// periods in `spent`.
    pub(crate) fn period_map(
        &self,
        start: &Phase,
        z: &DVector<f64>,
        n: usize,
        spent: &mut usize,
    ) -> Result<Option<MapValue>> {
        let mut p = self.at_z(start, z);
        let branch = self.consistent_branch(&p);
        let mut derivative = phi_start(z.len());
        let mut integrals: Option<CycleIntegrals> = None;
        let mut returns = vec![f64::INFINITY; n];
        for k in 0..n {
            *spent += 1;
            match self.cycle_with_derivative(&mut p) {
                Ok((c, d)) => {
                    derivative = chain(&derivative, &d);
                    integrals = Some(integrals.map_or(c, |s| s.then(&c)));
                    if let Some(r) = returns.get_mut(k) {
                        *r = (self.z(&p) - z).amax();
                    }
                }
                Err(Error::Numerical(_)) => return Ok(None),
                Err(e) => return Err(e),
            }
        }
        let back = p.branch == branch && self.z(&p).iter().all(|c| c.is_finite());
        Ok(back.then(|| MapValue {
            end: p,
            derivative,
            integrals: integrals.expect("n >= 1"),
            returns,
        }))
    }

    /// Newton's method on Pⁿ(z) − z = 0 from `start`, with the exact derivative of the
    /// map. Each step is limited to a trust radius (largest change of x or x', in units
    /// of L) that grows after a step that reduces the residual as the linear model
    /// promises (at least a tenth of the promised reduction) and shrinks fourfold after
    /// one that does not. There is no cap on the number of steps, however many a slowly
    /// contracting (high-Q) orbit needs; it ends when the residual is below `target`,
    /// when a full step no longer reduces a residual already below `floor` (the
    /// integrator's noise), after [`MAX_REJECTIONS`] rejected steps in a row or
    /// [`STALL_STEPS`] accepted ones that do not halve the residual (the map is not
    /// smooth there: a grazing contact), or when `budget` periods are spent.
    fn newton(
        &self,
        start: &Phase,
        n: usize,
        (target, floor): (f64, f64),
        budget: usize,
        spent: &mut usize,
    ) -> Result<Option<Orbit>> {
        let mut z = self.z(start);
        let Some(value) = self.period_map(start, &z, n, spent)? else {
            return Ok(None);
        };
        let (mut end, mut m) = (value.end, value.monodromy());
        let mut r = self.z(&end) - &z;
        let mut norm = r.amax();
        let mut radius: f64 = 0.2;
        let mut rejected = 0;
        // The residual at the last halving and the accepted steps since.
        let (mut checkpoint, mut since) = (norm, 0);
        loop {
            if norm <= target {
                break;
            }
            if *spent + n > budget {
                return Ok(None);
            }
            let Some(inverse) = (&m - DMatrix::identity(z.len(), z.len())).try_inverse() else {
                return Ok(None);
            };
            let step = -(inverse * &r);
            let length = step.amax();
            if !length.is_finite() {
                return Ok(None);
            }
            let scale = (radius / length).min(1.0);
            let trial = &z + step * scale;
            // Inexact Newton: far from the orbit the map need not be exact to the
            // integrator's tolerance, only well below the residual.
            let evaluated = self
                .loosened(NEWTON_TOLERANCE * norm)
                .period_map(start, &trial, n, spent)?
                .map(|value| {
                    let residual = self.z(&value.end) - &trial;
                    (value, residual)
                });
            match evaluated {
                Some((value, residual)) if residual.amax() <= (1.0 - 0.1 * scale) * norm => {
                    z = trial;
                    m = value.monodromy();
                    end = value.end;
                    r = residual;
                    norm = r.amax();
                    radius = radius.max(2.0 * scale * length);
                    rejected = 0;
                    since += 1;
                    if norm <= 0.5 * checkpoint {
                        (checkpoint, since) = (norm, 0);
                    } else if since == STALL_STEPS {
                        return Ok(None);
                    }
                }
                _ if scale == 1.0 && norm <= floor => break,
                _ => {
                    radius = 0.25 * scale * length;
                    rejected += 1;
                    if rejected == MAX_REJECTIONS {
                        return Ok(None);
                    }
                }
            }
        }
        Ok(Some(Orbit {
            phase: self.at_z(&end, &z),
            residual: norm,
        }))
    }

    /// Look for a stable period-n orbit near `phase` by Newton's method, leaving `phase`
    /// as it is: the orbit with its steady state over one pass, a candidate for what the
    /// motion settles on ([`Candidate`]). An orbit that is unstable, or whose least
    /// period is below n, is not one (the motion does not settle on it).
    fn try_period(
        &self,
        phase: &Phase,
        n: usize,
        opts: &SteadyOptions,
        budget: usize,
        spent: &mut usize,
    ) -> Result<Option<Candidate>> {
        let target = (1e-2 * opts.tolerance).max(1e-13);
        let Some(orbit) = self.newton(phase, n, (target, opts.tolerance), budget, spent)? else {
            return Ok(None);
        };
        if *spent + 3 * n > budget {
            return Ok(None);
        }
        let mut on = orbit.phase;
        let Some((state, monodromy)) = self.settle(&mut on, n, orbit.residual, spent)? else {
            return Ok(None);
        };
        if state.motion.stable() != Some(true) {
            return Ok(None);
        }
        let state = SteadyState {
            converged: orbit.residual <= opts.tolerance,
            ..state
        };
        *spent += state.window.periods as usize - 1;
        let grazing = self.grazing(opts, &state).jump;
        Ok(Some(Candidate::new(self, state, on, &monodromy, grazing)?))
    }

    /// Newton's method for a period-n orbit from `phase` ([`Self::try_period`]): if the
    /// orbit found captures `phase` ([`Candidate::captures`]: the marching that led here
    /// has begun converging onto it), `phase` is moved onto it and its steady state
    /// returned; otherwise it joins `pending`, the orbits that later marching may reach.
    fn shoot(
        &self,
        phase: &mut Phase,
        n: usize,
        (opts, budget): (&SteadyOptions, usize),
        spent: &mut usize,
        pending: &mut Vec<Candidate>,
    ) -> Result<Option<SteadyState>> {
        let Some(candidate) = self.try_period(phase, n, opts, budget, spent)? else {
            return Ok(None);
        };
        if candidate.captures(self, phase) {
            *phase = candidate.on;
            return Ok(Some(SteadyState {
                cycles: *spent,
                ..candidate.state
            }));
        }
        let known = |c: &Candidate| c.same_orbit(&candidate, 1e3 * opts.tolerance.max(1e-12));
        if !pending.iter().any(known) {
            pending.push(candidate);
        }
        Ok(None)
    }

    /// The steady state of the first of the `pending` orbits whose capture radius the
    /// marched `phase` has entered (`phase` is moved onto it), if any.
    fn reached(
        &self,
        phase: &mut Phase,
        pending: &[Candidate],
        spent: usize,
    ) -> Option<SteadyState> {
        let candidate = pending.iter().find(|c| c.captures(self, phase))?;
        *phase = candidate.on;
        Some(SteadyState {
            cycles: spent,
            ..candidate.state
        })
    }

    /// The steady state on the orbit through `phase` that returns after n periods within
    /// `residual`: one pass of it (its least period m, a divisor of n to which the state
    /// returns within 10³ residuals), with its monodromy matrix. `None` if the
    /// variational equations cannot be integrated along it (see `period_map`).
    fn settle(
        &self,
        phase: &mut Phase,
        n: usize,
        residual: f64,
        spent: &mut usize,
    ) -> Result<Option<(SteadyState, DMatrix<f64>)>> {
        let start = *phase;
        let z = self.z(&start);
        let Some(mut pass) = self.period_map(&start, &z, n, spent)? else {
            return Ok(None);
        };
        let least = (1..=n)
            .find(|&m| n % m == 0 && (m == n || pass.returns[m - 1] <= 1e3 * residual.max(1e-12)))
            .unwrap_or(n);
        if least < n {
            let Some(shorter) = self.period_map(&start, &z, least, spent)? else {
                return Ok(None);
            };
            pass = shorter;
        }
        *phase = pass.end;
        let monodromy = pass.monodromy();
        Ok(Some((
            SteadyState {
                window: pass.integrals,
                cycles: *spent,
                converged: true,
                motion: Motion::Periodic {
                    period: least,
                    multipliers: eigenvalues(&monodromy),
                },
                std_err: StdErr::default(),
            },
            monodromy,
        )))
    }

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
    pub fn steady_state(&self, phase: &mut Phase, opts: &SteadyOptions) -> Result<SteadyState> {
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
        let mut stretch = FIRST_STRETCH;
        while spent < search_budget {
            for _ in 0..stretch.min(search_budget - spent) {
                self.rewind(phase);
                let c = marching.cycle(phase, &mut numeric::Ignore)?;
                spent += 1;
                ring.push(self.z(phase), phase.branch);
                window.add(&c);
                if let Some(found) = self.reached(phase, &pending, spent) {
                    return Ok(found);
                }
                if !opts.shooting {
                    // A state contracting onto the orbit by a factor ρ per n periods
                    // is |Δz|·ρ/(1 − ρ) from it; ρ is at most the free oscillator's
                    // e^{−γnT}, so this return distance puts it within `tolerance`.
                    let within = |n: usize| {
                        let rho = (-self.osc.gamma * self.osc.period() * n as f64).exp();
                        opts.tolerance * (1.0 - rho) / rho
                    };
                    if let Some(n) = ring.repeats(within) {
                        let gap = ring.gap(0, n).unwrap_or(0.0);
                        let mut on = *phase;
                        // (`None`: the orbit grazes a fold, see `period_map`: march on.)
                        if let Some((state, _)) = self.settle(&mut on, n, gap, &mut spent)? {
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
    fn marching(&self, opts: &SteadyOptions) -> Self {
        self.loosened(opts.marching_fraction * opts.average_tolerance)
    }

    /// This simulation with the integrator's relative tolerance raised to `rtol` (at most
    /// [`LOOSEST_RTOL`]; never lowered), the absolute one in proportion.
    fn loosened(&self, rtol: f64) -> Self {
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

    /// The oscillator's memory, the amplitude's relaxation time 2Q (in τ), in periods:
    /// QΩ/π.
    fn memory_periods(&self) -> usize {
        (self.osc.omega / (2.0 * std::f64::consts::PI * self.osc.gamma))
            .ceil()
            .clamp(1.0, 1e9) as usize
    }

    /// Average irregular motion, marched at the averages' tolerance ([`Self::marching`]),
    /// over a window of 16 batches (begun during the search for an orbit, `window`)
    /// whose length doubles (by merging pairs and integrating as many again) until the
    /// standard errors of the batch means of A (relative), φ (rad) and E_ts (relative to
    /// E_drive) are below `opts.average_tolerance`, or the budget is spent; from 8
    /// batches on, a window whose errors are below a quarter of it ([`EARLY_MARGIN`])
    /// is accepted. Whenever a window starts with a transient ([`transient_batches`]),
    /// the motion is not yet stationary: orbits are looked for again (with shooting),
    /// and the transient batches are dropped.
    fn average(
        &self,
        phase: &mut Phase,
        opts: &SteadyOptions,
        (budget, mut spent): (usize, usize),
        mut window: Window,
        mut ring: Recurrence,
        mut pending: Vec<Candidate>,
    ) -> Result<SteadyState> {
        let marching = self.marching(opts);
        loop {
            self.rewind(phase);
            let c = marching.cycle(phase, &mut numeric::Ignore)?;
            spent += 1;
            ring.push(self.z(phase), phase.branch);
            window.add(&c);
            if let Some(found) = self.reached(phase, &pending, spent) {
                return Ok(found);
            }
            // At the end of each batch: has the motion locked onto a long period?
            if opts.shooting && window.current_len == 0 {
                if let Some(n) = ring.locked() {
                    let limits = (opts, budget);
                    if let Some(found) = self.shoot(phase, n, limits, &mut spent, &mut pending)? {
                        return Ok(found);
                    }
                }
            }
            let count = window.batches.len();
            let full = count >= BATCHES;
            // From MIN_BATCHES batches on, each finished batch is a chance to stop early.
            let early = window.current_len == 0 && count >= MIN_BATCHES;
            let out_of_budget = spent >= budget;
            if full || early || out_of_budget {
                let (averages, std_err) =
                    batch_statistics(&window.batches, window.current.as_ref());
                let relative = |x: f64, of: f64| if of > 0.0 { x / of } else { x };
                let within = |tolerance: f64| {
                    count >= 2
                        && relative(std_err.amplitude, averages.amplitude()) <= tolerance
                        && std_err.phase <= tolerance
                        && relative(std_err.e_ts, averages.e_drive_per_period().abs()) <= tolerance
                };
                let met = if full || out_of_budget {
                    within(opts.average_tolerance)
                } else {
                    within(opts.average_tolerance / EARLY_MARGIN)
                };
                let transient = transient_batches(&window.batches, opts.average_tolerance);
                if out_of_budget || (met && transient == 0) {
                    return Ok(SteadyState {
                        window: averages,
                        cycles: spent,
                        converged: met && window.long_enough && transient == 0,
                        motion: Motion::Irregular,
                        std_err,
                    });
                }
                if !full && transient == 0 {
                    continue;
                }
                if transient > 0 {
                    // Still a transient (a slow passage, e.g. past a fold's ghost): it
                    // may yet settle on an orbit.
                    if opts.shooting {
                        for n in ring.candidates() {
                            let limits = (opts, budget);
                            if let Some(found) =
                                self.shoot(phase, n, limits, &mut spent, &mut pending)?
                            {
                                return Ok(found);
                            }
                        }
                    }
                    window.batches.drain(..transient);
                } else {
                    if window.batches.len() % 2 == 1 {
                        // (More than BATCHES gathered while searching: the oldest goes.)
                        window.batches.remove(0);
                    }
                    window.batches = window.batches.chunks(2).map(|p| p[0].then(&p[1])).collect();
                    window.batch_len *= 2;
                }
            }
        }
    }
}

/// Rejected Newton steps in a row after which the search for an orbit gives up.
const MAX_REJECTIONS: usize = 6;
/// Accepted Newton steps that may pass without halving the residual.
const STALL_STEPS: usize = 8;
/// The fewest periods a steady-state search may be given: enough to classify the motion
/// and average irregular motion over a window of its own.
pub(crate) const MIN_CYCLES: usize = 32;
/// The averaging window of irregular motion: whole batches and the one being filled.
struct Window {
    /// Periods per batch.
    batch_len: usize,
    /// Whether batches are as long as the oscillator's memory (else the error estimate
    /// is not trusted: the batch means are correlated).
    long_enough: bool,
    batches: Vec<CycleIntegrals>,
    current: Option<CycleIntegrals>,
    current_len: usize,
}

impl Window {
    /// Batches must outlast the oscillator's `memory` (in periods) to be nearly
    /// independent; where `budget` periods are too few for [`BATCHES`] of those, shorter
    /// batches still give a window and an error estimate, but not a converged one.
    fn new(memory: usize, budget: usize) -> Self {
        let batch_len = memory.min(budget / BATCHES).max(1);
        Self {
            batch_len,
            long_enough: batch_len == memory,
            batches: Vec::with_capacity(BATCHES),
            current: None,
            current_len: 0,
        }
    }

    fn add(&mut self, c: &CycleIntegrals) {
        self.current = Some(self.current.map_or(*c, |s| s.then(c)));
        self.current_len += 1;
        if self.current_len == self.batch_len {
            self.batches.push(self.current.take().expect("a batch"));
            self.current_len = 0;
        }
    }
}

/// Batches of an irregular window.
const BATCHES: usize = 16;
/// Batches after which a window may be accepted early: when its standard errors are
/// below the tolerance over [`EARLY_MARGIN`]. With 7 degrees of freedom the estimate
/// of a standard error is itself uncertain (below 0.56 of the true value with 5 %
/// probability) and batches one memory long are still slightly correlated (lag-1
/// correlation ≲ 0.3, which hides up to a factor 1.3); the margin covers both.
const MIN_BATCHES: usize = 8;
const EARLY_MARGIN: f64 = 4.0;
/// Periods integrated before the first look for orbits of higher period.
const FIRST_STRETCH: usize = 32;
/// Periods the search for an orbit may integrate at most (with shooting).
const SEARCH_PERIODS: usize = 1000;
/// Marched periods are integrated at this fraction of the averages' tolerance (the
/// default of [`SteadyOptions::marching_fraction`]).
pub const MARCHING_TOLERANCE: f64 = 1e-5;
/// Newton's trial maps are integrated at this fraction of the residual they try to
/// reduce (inexact Newton: the error of the map stays far below what a step must gain).
const NEWTON_TOLERANCE: f64 = 1e-2;
/// The loosest relative tolerance any integration runs at.
const LOOSEST_RTOL: f64 = 1e-5;

/// The window (every batch and the unfinished rest) and the standard errors of the
/// means of the whole batches.
fn batch_statistics(
    batches: &[CycleIntegrals],
    rest: Option<&CycleIntegrals>,
) -> (CycleIntegrals, StdErr) {
    let mut window = batches[0];
    for b in &batches[1..] {
        window = window.then(b);
    }
    if let Some(r) = rest {
        window = window.then(r);
    }
    let n = batches.len() as f64;
    let phase = window.phase();
    let std_err_of = |value: &dyn Fn(&CycleIntegrals) -> f64| {
        let mean = batches.iter().map(value).sum::<f64>() / n;
        let var = batches
            .iter()
            .map(|b| (value(b) - mean).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        (var / n).sqrt()
    };
    let std_err = if batches.len() < 2 {
        StdErr {
            amplitude: f64::INFINITY,
            phase: f64::INFINITY,
            e_ts: f64::INFINITY,
        }
    } else {
        StdErr {
            amplitude: std_err_of(&|b| b.amplitude()),
            phase: std_err_of(&|b| wrap_angle(b.phase() - phase)),
            e_ts: std_err_of(&|b| b.e_ts_per_period()),
        }
    };
    (window, std_err)
}

/// How many leading batches of a window are transient, by the marginal standard error
/// rule (MSER; White, Simulation 69, 323, 1997): for A, φ and E_ts per period, the cut d
/// ≤ n/2 that minimises the variance of the remaining batch values over (n − d)², taken
/// only where it at least halves that of the whole window (a stationary window's
/// minimum is at d = 0 but for chance) and where dropping the d batches moves the
/// window's mean by more than `tolerance` (A relative, φ in rad, E_ts relative to
/// E_drive, as the standard errors are judged): a cut that changes nothing reported is
/// chance, or a transient too small to matter. The largest such cut of the three. A
/// transient that creeps (past a fold's ghost, say) shows up as leading batches far
/// from the rest.
fn transient_batches(batches: &[CycleIntegrals], tolerance: f64) -> usize {
    let n = batches.len();
    if n < 4 {
        return 0;
    }
    let (window, _) = batch_statistics(batches, None);
    let phase = window.phase();
    let cut = |value: &dyn Fn(&CycleIntegrals) -> f64, scale: f64| {
        let ys: Vec<f64> = batches.iter().map(value).collect();
        let mean = |d: usize| ys[d..].iter().sum::<f64>() / (n - d) as f64;
        let mser = |d: usize| {
            let (rest, m) = (&ys[d..], mean(d));
            rest.iter().map(|y| (y - m).powi(2)).sum::<f64>() / ((n - d) as f64).powi(3)
        };
        let whole = mser(0);
        let (best, at) = (1..=n / 2)
            .map(|d| (d, mser(d)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("n >= 4");
        let moves = (mean(best) - mean(0)).abs() > tolerance * scale;
        if at < 0.5 * whole && moves { best } else { 0 }
    };
    let relative_to = |x: f64| if x > 0.0 { x } else { 1.0 };
    cut(&|b| b.amplitude(), relative_to(window.amplitude()))
        .max(cut(&|b| wrap_angle(b.phase() - phase), 1.0))
        .max(cut(
            &|b| b.e_ts_per_period(),
            relative_to(window.e_drive_per_period().abs()),
        ))
}

/// An angle difference brought into (−π, π].
fn wrap_angle(d: f64) -> f64 {
    use std::f64::consts::PI;
    PI - (PI - d).rem_euclid(2.0 * PI)
}

/// Eigenvalues of a monodromy matrix (at most [`MAX_SECTION`] × [`MAX_SECTION`]): in
/// closed form for 2×2, from the real Schur form otherwise.
pub(crate) fn eigenvalues(m: &DMatrix<f64>) -> Multipliers {
    let mut values = [Complex::new(0.0, 0.0); MAX_SECTION];
    let len = m.nrows().min(MAX_SECTION);
    if len == 2 {
        let half_trace = 0.5 * m.trace();
        let disc = Complex::new(half_trace * half_trace - m.determinant(), 0.0).sqrt();
        let h = Complex::new(half_trace, 0.0);
        values[0] = h + disc;
        values[1] = h - disc;
    } else {
        for (v, e) in values.iter_mut().zip(m.complex_eigenvalues().iter()) {
            *v = *e;
        }
    }
    Multipliers { values, len }
}

/// The last states at the drive phase, to see after how many periods they repeat.
#[derive(Default)]
struct Recurrence {
    /// (section state, branch), newest last; at most 3 + [`MAX_PERIOD`].
    states: std::collections::VecDeque<([f64; MAX_SECTION], Branch)>,
    /// Long periods already looked for, with the return distance then
    /// ([`Recurrence::locked`]).
    tried: Vec<(usize, f64)>,
}

impl Recurrence {
    const KEEP: usize = MAX_PERIOD + 3;

    fn push(&mut self, z: DVector<f64>, branch: Branch) {
        if self.states.len() == Self::KEEP {
            self.states.pop_front();
        }
        let mut a = [0.0; MAX_SECTION];
        a[..z.len()].copy_from_slice(z.as_slice());
        self.states.push_back((a, branch));
    }

    /// Distance between the state `back` places from the newest and the one n before it.
    fn gap(&self, back: usize, n: usize) -> Option<f64> {
        let len = self.states.len();
        let (a, b) = (
            self.states.get(len.checked_sub(1 + back)?)?,
            self.states.get(len.checked_sub(1 + back + n)?)?,
        );
        (a.1 == b.1).then(|| {
            a.0.iter()
                .zip(&b.0)
                .fold(0.0, |m: f64, (x, y)| m.max((x - y).abs()))
        })
    }

    /// Whether the return distance after n periods has been within `within` for the
    /// last three periods.
    fn returns_within(&self, n: usize, within: f64) -> bool {
        (0..3).all(|back| self.gap(back, n).is_some_and(|g| g <= within))
    }

    /// The least n ≤ [`SHORT_PERIOD`] whose return distance has been within `within(n)`
    /// for the last three periods.
    fn repeats(&self, within: impl Fn(usize) -> f64) -> Option<usize> {
        (1..=SHORT_PERIOD).find(|&n| self.returns_within(n, within(n)))
    }

    /// Periods worth a Newton search: those up to [`SHORT_PERIOD`] the newest state
    /// nearly returns with (within 0.1 in x and x'), the nearest returns first, at most
    /// three; a multiple of a period already listed is left out (its orbit would be
    /// found as the shorter one).
    fn candidates(&self) -> Vec<usize> {
        let mut near: Vec<(f64, usize)> = (1..=SHORT_PERIOD)
            .filter_map(|n| self.gap(0, n).filter(|&g| g <= 0.1).map(|g| (g, n)))
            .collect();
        near.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut out: Vec<usize> = Vec::with_capacity(3);
        for (_, n) in near {
            if out.len() < 3 && !out.iter().any(|&m| n % m == 0) {
                out.push(n);
            }
        }
        out
    }

    /// The least long period n (above [`SHORT_PERIOD`], at most [`MAX_PERIOD`]) the
    /// motion has returned with within [`LOCK_GAP`] three periods running, unless it was
    /// looked for already and the motion has not come 100× closer since (it is marked
    /// with its return distance).
    fn locked(&mut self) -> Option<usize> {
        let (n, gap) = (SHORT_PERIOD + 1..=MAX_PERIOD).find_map(|n| {
            let gap = self.gap(0, n)?;
            let fresh = self
                .tried
                .iter()
                .all(|&(m, then)| m != n || gap < 1e-2 * then);
            (fresh && self.returns_within(n, LOCK_GAP)).then_some((n, gap))
        })?;
        self.tried.retain(|&(m, _)| m != n);
        self.tried.push((n, gap));
        Some(n)
    }
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
    /// At most this many integrator steps ([`budget`]).
    pub max_steps: u64,
    /// Periods marched for averages and for the choice of candidate periods are
    /// integrated at this fraction of `average_tolerance` ([`MARCHING_TOLERANCE`]
    /// unless tightened to re-decide a grazing state).
    pub marching_fraction: f64,
    /// A grazing margin below this (units of L) counts as grazing ([`super::grazing`]),
    /// as does one below the state's resolution ([`Simulation::resolution`]): the
    /// thermal rms deflection at 300 K over A₀ for a prepared experiment.
    pub grazing_threshold: f64,
}

/// Whether a steady state grazes a switch ([`Simulation::grazing`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Grazing {
    /// A turning point lies within the threshold of some switch level.
    pub any: bool,
    /// … of a level where the force jumps: the period map is discontinuous within that
    /// distance, and an orbit's stability rests on the grazing contact.
    pub jump: bool,
}

/// The outcome of [`Simulation::steady_state`].
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hermite_turn_finds_the_turning_points_of_parabolas() {
        // x = (τ − 0.3)², sampled at τ = 0 and 1 with exact slopes: the cubic is exact.
        let end = |tau: f64| {
            let mut y = State::<BASE>::zeros();
            y[X] = (tau - 0.3) * (tau - 0.3);
            y[V] = 2.0 * (tau - 0.3);
            StepEnd {
                tau,
                y,
                dy: State::<BASE>::zeros(),
            }
        };
        let t = hermite_turn(&end(0.0), &end(1.0), true);
        assert!((t - 0.3).abs() < 1e-12, "{t}");
        // And the top of x = −(τ − 0.6)².
        let top = |tau: f64| {
            let mut e = end(tau + 0.3 - 0.6);
            e.tau = tau;
            e.y[X] = -e.y[X];
            e.y[V] = -e.y[V];
            e
        };
        let t = hermite_turn(&top(0.0), &top(1.0), false);
        assert!((t - 0.6).abs() < 1e-12, "{t}");
    }
}
