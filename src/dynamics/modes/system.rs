//! The equations of motion of several eigenmodes sharing one tip–sample force, their
//! variational equations, and one common period integrated through the law's switches.
//!
//! Mode i (units of the first mode: τ = ω₁t, lengths A₀₁, forces k₁A₀₁):
//!
//!   qᵢ″ + (rᵢ/Qᵢ)qᵢ′ + rᵢ²qᵢ = cᵢ(f_ts(α̂) + fᵢ cos Ωᵢτ),  α̂ = a₀ + a₁Σⱼqⱼ,
//!
//! (Rodríguez & García, APL 84, 449, 2004, their Eq. 1 made dimensionless). The state
//! holds each mode's (qᵢ, qᵢ′), six integrals per mode over the period (∫qᵢ′², the
//! drive's ∫cos Ωᵢτ qᵢ′, the tip force's ∫f qᵢ′ and ∫f qᵢ, the lock-in's ∫qᵢ cos Ωᵢτ and
//! ∫qᵢ sin Ωᵢτ), ∫f, and with a tangent the 2M × 2M matrix Φ = ∂z/∂z₀ of the section
//! state z = (q₁, q₁′, …) — a layout of [`plain_len`] or [`tangent_len`] components.

use super::set::{Modal, ModeModel};
use crate::dynamics::budget;
use crate::dynamics::dopri5::{self, Settings, StepError, System};
use crate::dynamics::model::{Coupling, State};
use crate::dynamics::numeric::{Ignore, StepEnd, StepObserver, Tolerances, hermite_turn_fraction};
use crate::dynamics::setup::Prepared;
use crate::error::{Error, Result};
use crate::numeric::bracketed_root;
use crate::physics::law::AnyLaw;
use crate::physics::law::{Branch, ForceLaw};

/// Components without the tangent for `m` modes.
pub const fn plain_len(m: usize) -> usize {
    8 * m + 1
}

/// Components with the tangent for `m` modes.
pub const fn tangent_len(m: usize) -> usize {
    plain_len(m) + 4 * m * m
}

/// An integral carried for each mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModeIntegral {
    /// ∫ qᵢ′² dτ (times rᵢ/(Qᵢcᵢ): the energy damping takes).
    Damping = 0,
    /// ∫ cos Ωᵢτ qᵢ′ dτ (times fᵢ: the drive's work).
    Drive = 1,
    /// ∫ f_ts qᵢ′ dτ: the work the tip force does on the mode.
    Exchange = 2,
    /// ∫ f_ts qᵢ dτ: the mode's virial.
    Virial = 3,
    /// ∫ x cos Ωᵢτ dτ, x = Σⱼqⱼ the deflection: what a lock-in at mode i's drive
    /// frequency reads (not qᵢ alone: the tip force puts every mode's motion at the
    /// others' frequencies too).
    Cos = 4,
    /// ∫ x sin Ωᵢτ dτ.
    Sin = 5,
}

/// Index of mode i's deflection.
#[inline]
pub const fn q(i: usize) -> usize {
    2 * i
}

/// Index of mode i's velocity.
#[inline]
pub const fn v(i: usize) -> usize {
    2 * i + 1
}

/// Index of an integral of mode i in a layout of `m` modes.
#[inline]
pub const fn integral(m: usize, i: usize, which: ModeIntegral) -> usize {
    2 * m + 6 * i + which as usize
}

/// Index of ∫ f_ts dτ.
#[inline]
pub const fn force_integral(m: usize) -> usize {
    8 * m
}

/// Index of Φ's entry (row, col), column by column.
#[inline]
pub const fn phi(m: usize, row: usize, col: usize) -> usize {
    plain_len(m) + 2 * m * col + row
}

/// The modes, the law and the coupling: what the right-hand side needs.
pub struct Modes<'a, L, const M: usize> {
    /// The modes.
    pub modes: [ModeModel; M],
    /// The law.
    pub law: &'a L,
    /// α̂ = a₀ + a₁ Σqᵢ, f = −f_scale·T̂.
    pub cpl: Coupling,
    /// Integrator tolerances.
    pub tol: Tolerances,
    /// The support moving as x_b = p + uτ ((p, u); (0, 0) for a still support): a leg of
    /// a force–distance ramp ([`crate::instrument::force_curve`]); α̂ = a₀ + a₁(Σqᵢ + x_b).
    pub support: (f64, f64),
}

impl<'a, const M: usize> Modes<'a, AnyLaw, M> {
    /// The first `M` modes of `modal` on the prepared setup `p` (its law, coupling and
    /// tolerances). A mode of quality Q turns an integration error into an amplitude
    /// error Q times larger: the tolerances are tightened by the first mode's Q over the
    /// highest (one mode keeps tapsim's), and the longest step shortened for the
    /// fastest mode.
    pub fn of(p: &'a Prepared, modal: &Modal) -> Self {
        let models: [ModeModel; M] = std::array::from_fn(|i| modal.modes[i]);
        let fastest = models
            .iter()
            .map(|m| m.omega.max(m.r))
            .fold(1.0f64, f64::max);
        let q_max = models.iter().map(ModeModel::quality).fold(0.0f64, f64::max);
        let tighter = (models[0].quality() / q_max).min(1.0);
        let mut tol = p.tol;
        tol.h_max = p.tol.h_max * p.osc.omega / fastest;
        tol.rtol *= tighter;
        tol.atol *= tighter;
        Self {
            modes: models,
            law: &p.law,
            cpl: p.cpl,
            tol,
            support: (0.0, 0.0),
        }
    }
}

impl<L: ForceLaw, const M: usize> Modes<'_, L, M> {
    /// The tip's deflection Σqᵢ.
    #[inline]
    pub fn tip<const S: usize>(y: &State<S>) -> f64 {
        (0..M).map(|i| y[q(i)]).sum()
    }

    /// The tip's velocity Σqᵢ′.
    #[inline]
    pub fn tip_velocity<const S: usize>(y: &State<S>) -> f64 {
        (0..M).map(|i| y[v(i)]).sum()
    }

    /// The support's position x_b at τ (units of A₀₁).
    #[inline]
    pub fn x_b(&self, tau: f64) -> f64 {
        self.support.0 + self.support.1 * tau
    }

    /// The separation coordinate Σqᵢ + x_b of state `y` at τ (what the law's levels are
    /// set in, in units of A₀₁).
    #[inline]
    pub fn reach<const S: usize>(&self, tau: f64, y: &State<S>) -> f64 {
        Self::tip(y) + self.x_b(tau)
    }

    /// f_ts at tip deflection `x` at τ on `branch`.
    #[inline]
    pub fn force(&self, x: f64, tau: f64, branch: Branch) -> f64 {
        -self.cpl.f_scale * self.law.t_hat(self.cpl.alpha_hat(x, self.x_b(tau)), branch)
    }

    /// The right-hand side (and the variational equations δqᵢ″ = −(rᵢ/Qᵢ)δqᵢ′ − rᵢ²δqᵢ +
    /// cᵢ(∂f/∂x)Σⱼδqⱼ, ∂f/∂x = −f_scale·a₁·dT̂/dα̂, where the layout has a tangent).
    #[inline]
    pub fn rhs<const S: usize>(&self, branch: Branch, tau: f64, y: &State<S>, dy: &mut State<S>) {
        let x = Self::tip(y);
        let alpha = self.cpl.alpha_hat(x, self.x_b(tau));
        let f = -self.cpl.f_scale * self.law.t_hat(alpha, branch);
        for (i, m) in self.modes.iter().enumerate() {
            let (s, c) = (m.omega * tau).sin_cos();
            let (qi, vi) = (y[q(i)], y[v(i)]);
            dy[q(i)] = vi;
            dy[v(i)] = -m.damping * vi - m.r * m.r * qi + m.gain * (f + m.drive * c);
            dy[integral(M, i, ModeIntegral::Damping)] = vi * vi;
            dy[integral(M, i, ModeIntegral::Drive)] = c * vi;
            dy[integral(M, i, ModeIntegral::Exchange)] = f * vi;
            dy[integral(M, i, ModeIntegral::Virial)] = f * qi;
            dy[integral(M, i, ModeIntegral::Cos)] = x * c;
            dy[integral(M, i, ModeIntegral::Sin)] = x * s;
        }
        dy[force_integral(M)] = f;
        if S == tangent_len(M) {
            let slope = -self.cpl.f_scale * self.cpl.a1 * self.law.slope_hat(alpha, branch);
            for col in 0..2 * M {
                let dx: f64 = (0..M).map(|j| y[phi(M, q(j), col)]).sum();
                for (i, m) in self.modes.iter().enumerate() {
                    let (dq, dv) = (y[phi(M, q(i), col)], y[phi(M, v(i), col)]);
                    dy[phi(M, q(i), col)] = dv;
                    dy[phi(M, v(i), col)] = -m.damping * dv - m.r * m.r * dq + m.gain * slope * dx;
                }
            }
        }
    }

    /// The saltation of Φ at a switch from `from` to `to` at state `y` (Aizerman &
    /// Gantmacher's jump matrix, S = I + (g⁺ − g⁻)∇hᵀ/(∇h·g⁻) with h = α̂ − level): the
    /// force steps by Δf, each velocity's rate by cᵢΔf, and a perturbation δx of the tip
    /// moves the switch by −δx/x′, so δqᵢ′ gains cᵢΔf·δx/x′.
    pub fn saltation<const S: usize>(&self, tau: f64, y: &mut State<S>, from: Branch, to: Branch) {
        if S != tangent_len(M) {
            return;
        }
        let x = Self::tip(y);
        let velocity = Self::tip_velocity(y) + self.support.1;
        let step = self.force(x, tau, to) - self.force(x, tau, from);
        if velocity == 0.0 || step == 0.0 {
            return;
        }
        for col in 0..2 * M {
            let dx: f64 = (0..M).map(|j| y[phi(M, q(j), col)]).sum();
            for (i, m) in self.modes.iter().enumerate() {
                y[phi(M, v(i), col)] += m.gain * step * dx / velocity;
            }
        }
    }
}

/// Cubic Hermite interpolation of the tip deflection on the step [a, b] at τ.
fn tip_at<const M: usize, const S: usize>(a: &StepEnd<S>, b: &StepEnd<S>, tau: f64) -> f64 {
    let h = b.tau - a.tau;
    let t = (tau - a.tau) / h;
    let (t2, t3) = (t * t, t * t * t);
    (0..M)
        .map(|i| {
            let k = q(i);
            (2.0 * t3 - 3.0 * t2 + 1.0) * a.y[k]
                + (t3 - 2.0 * t2 + t) * h * a.dy[k]
                + (-2.0 * t3 + 3.0 * t2) * b.y[k]
                + (t3 - t2) * h * b.dy[k]
        })
        .sum()
}

/// How near a level (units of A₀₁) an accepted step may end and be taken to have
/// reached it.
const SNAP: f64 = 1e-10;

/// The shortest span integrated again to a crossing (shorter ones end at the step end
/// or start).
const SHORTEST: f64 = 1e-9;

/// Sub-intervals of an accepted step searched for a crossing (a contact shorter than a
/// step is not stepped over).
const PROBES: usize = 8;

/// One branch integrated until its first switch (or the end), each accepted step short
/// of the switch shown to the observer (if any).
struct Segment<'m, 'a, 'o, L, const M: usize, const S: usize, O> {
    modes: &'m Modes<'a, L, M>,
    observer: Option<&'o mut O>,
    branch: Branch,
    /// Tip deflections at which the branch ends: falling to `below`, rising to `above`.
    below: Option<f64>,
    above: Option<f64>,
    last: Option<StepEnd<S>>,
    /// The step the crossing is in, where, and whether it is the level below.
    hit: Option<(StepEnd<S>, f64, bool)>,
    end: Option<State<S>>,
    /// The lowest tip deflection over the steps taken whole (a turning point inside a
    /// step from the Hermite cubic of Σqᵢ).
    min_tip: f64,
}

impl<L: ForceLaw, const M: usize, const S: usize, O: StepObserver> System<S>
    for Segment<'_, '_, '_, L, M, S, O>
{
    // The integrals and ∫f, which the right-hand side never reads.
    const QUADRATURES: std::ops::Range<usize> = integral(M, 0, ModeIntegral::Damping)..plain_len(M);
    #[inline]
    fn system(&self, tau: f64, y: &State<S>, dy: &mut State<S>) {
        self.modes.rhs(self.branch, tau, y, dy);
    }

    fn solout(&mut self, tau: f64, y: &State<S>, dy: &State<S>) -> bool {
        let end = StepEnd {
            tau,
            y: *y,
            dy: *dy,
        };
        self.end = Some(*y);
        let Some(start) = self.last.replace(end) else {
            return false;
        };
        // The first probe past which the tip is beyond a level, and the crossing in it.
        // (By more than SNAP: a segment that starts on its own level after a switch of
        // a law whose branches meet there, DMT's, does not switch straight back.)
        let beyond = |x: f64| {
            self.below.is_some_and(|l| x < l - SNAP) || self.above.is_some_and(|l| x > l + SNAP)
        };
        let h = end.tau - start.tau;
        let mut lo = start.tau;
        let shift = |t: f64| self.modes.x_b(t);
        for k in 1..=PROBES {
            let t = start.tau + h * k as f64 / PROBES as f64;
            let x = if k == PROBES {
                self.modes.reach(tau, y)
            } else {
                tip_at::<M, S>(&start, &end, t) + shift(t)
            };
            if beyond(x) {
                let falling = self.below.is_some_and(|l| x < l - SNAP);
                let level =
                    if falling { self.below } else { self.above }.expect("a level was passed");
                let at = bracketed_root(
                    "a switch of the force law",
                    |t| tip_at::<M, S>(&start, &end, t) + shift(t) - level,
                    lo,
                    t,
                    // (The tolerance is relative to 1 + |τ|: 1e-14 of the step, but
                    // not below a few units of τ's round-off, which a bracket cannot
                    // shrink under — it then ended unconverged at the probe.)
                    (1e-14 * h / (1.0 + t.abs())).max(4.0 * f64::EPSILON),
                );
                let at = at.unwrap_or(t);
                self.hit = Some((start, at, falling));
                return true;
            }
            lo = t;
        }
        // Within reach of a level it is heading for: there (a fold's square-root
        // singularity would otherwise shrink the steps towards it without end).
        let x = self.modes.reach(tau, y);
        let heading = Modes::<L, M>::tip_velocity(y) + self.modes.support.1;
        let near = |l: Option<f64>, sign: f64| {
            l.is_some_and(|l| (x - l).abs() <= SNAP && sign * heading > 0.0)
        };
        if near(self.below, -1.0) || near(self.above, 1.0) {
            self.hit = Some((start, tau, near(self.below, -1.0)));
            return true;
        }
        self.min_tip = self
            .min_tip
            .min(lowest_tip::<M, S>(&start, &end, self.modes.support));
        if let Some(o) = self.observer.as_deref_mut() {
            o.step(&start, &end, self.branch);
        }
        false
    }
}

/// The lowest separation coordinate Σqᵢ + x_b over a step (the support at (p, u)): its
/// ends, or the turning point inside it where the Hermite cubic has its minimum.
fn lowest_tip<const M: usize, const S: usize>(
    a: &StepEnd<S>,
    b: &StepEnd<S>,
    (p, u): (f64, f64),
) -> f64 {
    let h = b.tau - a.tau;
    let sum = |e: &StepEnd<S>, part: fn(usize) -> usize| (0..M).map(|i| e.y[part(i)]).sum::<f64>();
    let (x0, x1) = (sum(a, q) + p + u * a.tau, sum(b, q) + p + u * b.tau);
    let (d0, d1) = (h * (sum(a, v) + u), h * (sum(b, v) + u));
    let ends = x0.min(x1);
    if d0 < 0.0 && d1 > 0.0 {
        let t = hermite_turn_fraction((x0, d0), (x1, d1), true);
        let at = a.tau + t * h;
        ends.min(tip_at::<M, S>(a, b, at) + p + u * at)
    } else {
        ends
    }
}

/// Steps of one segment at most (a stalled integration ends with an error).
const MAX_SEGMENT_STEPS: u32 = 1_000_000;

fn run<S2: System<S>, const S: usize>(
    system: &mut S2,
    from: f64,
    to: f64,
    y: State<S>,
    tol: &Tolerances,
    h0: f64,
) -> Result<f64> {
    let left = budget::left();
    let max_steps = u32::try_from(left).map_or(MAX_SEGMENT_STEPS, |l| l.min(MAX_SEGMENT_STEPS));
    let settings = Settings {
        rtol: tol.rtol,
        atol: tol.atol,
        h_max: tol.h_max,
        h0,
        max_steps,
    };
    match dopri5::integrate(system, from, to, y, &settings) {
        Ok(stats) => {
            budget::spend(u64::from(stats.accepted_steps + stats.rejected_steps))?;
            Ok(stats.h_proposed)
        }
        Err(StepError::MaxNumStepReached { .. }) if u64::from(max_steps) == left => {
            Err(budget::exhausted())
        }
        Err(StepError::StepSizeUnderflow { x }) => Err(Error::Numerical(format!(
            "the integrator's step fell to round-off at τ = {x:.6e} (ω₁t): the modes' \
             motion there is too abrupt for the tolerances"
        ))),
        Err(StepError::MaxNumStepReached { x, n_step }) => Err(Error::Numerical(format!(
            "one segment of the modes' motion needed more than {n_step} integration steps \
             at τ = {x:.6e} (ω₁t): too stiff to resolve (a mode far faster than the \
             first?)"
        ))),
    }
}

/// What one pass over [τ₀, τ₁] saw besides the state: the contact's work functions
/// summed over its segments, time in contact and the jumps into it.
#[derive(Debug, Clone, Copy, Default)]
pub struct PassTally {
    /// Σ over segments of ΔŴ_branch (the contact's units).
    pub work_hat: f64,
    /// Its capillary part.
    pub capillary_work_hat: f64,
    /// Σ |Ŵ| at the segments' ends: the scale of the round-off of `work_hat`.
    pub work_scale_hat: f64,
    /// α̂ at the start and at the end of the pass.
    pub alpha_hat_ends: (f64, f64),
    /// τ spent on the contact branch.
    pub contact_time: f64,
    /// Jumps into contact.
    pub jumps_in: u32,
    /// The smallest separation coordinate Σqᵢ + x_b (the tip deflection, the support
    /// still): at a step end or a switch, or at a turning point inside a step.
    pub min_tip: f64,
}

impl<L: ForceLaw, const M: usize> Modes<'_, L, M> {
    /// Integrate from (τ₀, y, branch) to τ₁ through every switch of the law; returns the
    /// state, the branch at τ₁ and the tally. The carried integrals and Φ go on from
    /// what `y` holds.
    pub fn pass<const S: usize>(
        &self,
        tau0: f64,
        y: State<S>,
        branch: Branch,
        tau1: f64,
    ) -> Result<(State<S>, Branch, PassTally)> {
        self.pass_observed(tau0, y, branch, tau1, &mut Ignore)
    }

    /// [`Self::pass`], each accepted step (cut at the switches) shown to `observer`: a
    /// lock-in watching the motion ([`crate::instrument::modal`]).
    pub fn pass_observed<const S: usize, O: StepObserver>(
        &self,
        tau0: f64,
        y: State<S>,
        branch: Branch,
        tau1: f64,
        observer: &mut O,
    ) -> Result<(State<S>, Branch, PassTally)> {
        self.pass_stepped(tau0, y, branch, tau1, observer, &mut 0.0)
    }

    /// [`Self::pass_observed`] starting with the step `h` (0: the integrator's own
    /// guess), left at the step proposed at the end: passes that follow one another
    /// (to each mode's period ends, [`super::window`]) go on with the step they had.
    pub fn pass_stepped<const S: usize, O: StepObserver>(
        &self,
        tau0: f64,
        mut y: State<S>,
        mut branch: Branch,
        tau1: f64,
        observer: &mut O,
        h: &mut f64,
    ) -> Result<(State<S>, Branch, PassTally)> {
        let mut tally = PassTally {
            min_tip: self.reach(tau0, &y),
            alpha_hat_ends: (self.cpl.alpha_hat(self.reach(tau0, &y), 0.0), f64::NAN),
            ..PassTally::default()
        };
        let mut tau = tau0;
        let alpha = |tau: f64, y: &State<S>| self.cpl.alpha_hat(self.reach(tau, y), 0.0);
        let mut switches = 0u32;
        while tau1 - tau > 1e-13 * tau1.abs().max(1.0) {
            let exits = self.law.exits(branch);
            let mut seg = Segment {
                modes: self,
                observer: Some(&mut *observer),
                branch,
                below: exits.below.map(|(l, _)| self.cpl.x_at(l)),
                above: exits.above.map(|(l, _)| self.cpl.x_at(l)),
                last: None,
                hit: None,
                end: None,
                min_tip: f64::INFINITY,
            };
            seg.last = Some(StepEnd {
                tau,
                y,
                dy: {
                    let mut dy = State::<S>::zeros();
                    self.rhs(branch, tau, &y, &mut dy);
                    dy
                },
            });
            let alpha_start = alpha(tau, &y);
            *h = run(&mut seg, tau, tau1, y, &self.tol, *h).map_err(|e| match e {
                Error::Numerical(why) => Error::Numerical(format!(
                    "{why} (on the {} branch from τ = {tau:.6}, α̂ = {alpha_start:.6})",
                    match branch {
                        Branch::Free => "out-of-contact",
                        Branch::Contact => "contact",
                        Branch::Necked => "capillary-neck",
                    }
                )),
                e => e,
            })?;
            let seg_min = seg.min_tip;
            let (next_tau, next_y, next_branch) = match seg.hit {
                Some((start, at, falling)) => {
                    // Integrate again from the step's start to the crossing.
                    let mut to = Segment::<L, M, S, O> {
                        modes: self,
                        observer: None,
                        branch,
                        below: None,
                        above: None,
                        last: None,
                        hit: None,
                        end: None,
                        min_tip: f64::INFINITY,
                    };
                    let level =
                        if falling { seg.below } else { seg.above }.expect("a hit crosses a level");
                    // Integrate again from the step's start to the crossing, and correct
                    // the time by Newton's method until the tip is at the level: where
                    // the force steps, an error in the time is one in the velocity.
                    let mut at = at;
                    let mut y_at = match seg.last.filter(|e| e.tau == at) {
                        Some(end) => end.y,
                        None => start.y,
                    };
                    for _ in 0..8 {
                        if at >= start.tau + SHORTEST && seg.last.is_none_or(|e| e.tau != at) {
                            to.end = None;
                            run(&mut to, start.tau, at, start.y, &self.tol, at - start.tau)?;
                            y_at = to.end.unwrap_or(start.y);
                        }
                        let miss = self.reach(at, &y_at) - level;
                        let speed = Self::tip_velocity(&y_at) + self.support.1;
                        if miss.abs() <= SNAP || speed == 0.0 {
                            break;
                        }
                        let next = at - miss / speed;
                        if next < start.tau + SHORTEST {
                            break;
                        }
                        at = next;
                    }
                    let next = if falling { exits.below } else { exits.above }
                        .expect("a hit crosses a level")
                        .1;
                    // The step cut at the switch, as the observer sees it.
                    let mut dy = State::<S>::zeros();
                    self.rhs(branch, at, &y_at, &mut dy);
                    observer.step(
                        &start,
                        &StepEnd {
                            tau: at,
                            y: y_at,
                            dy,
                        },
                        branch,
                    );
                    (at, y_at, next)
                }
                None => (tau1, seg.end.unwrap_or(y), branch),
            };
            let alpha_end = alpha(next_tau, &next_y);
            let (w_end, w_start) = (
                self.law.work_hat(alpha_end, branch),
                self.law.work_hat(alpha_start, branch),
            );
            tally.work_hat += w_end - w_start;
            tally.work_scale_hat += w_end.abs() + w_start.abs();
            tally.capillary_work_hat += self.law.capillary_work_hat(alpha_end, branch)
                - self.law.capillary_work_hat(alpha_start, branch);
            if branch == Branch::Contact {
                tally.contact_time += next_tau - tau;
            }
            tally.min_tip = tally
                .min_tip
                .min(self.reach(next_tau, &next_y))
                .min(seg_min);
            y = next_y;
            tau = next_tau;
            if next_branch != branch {
                self.saltation(tau, &mut y, branch, next_branch);
                if next_branch == Branch::Contact {
                    tally.jumps_in += 1;
                }
                branch = next_branch;
                switches += 1;
                if switches > 10_000 {
                    return Err(Error::Numerical(
                        "more than 10000 switches of the force law in one common period: \
                         the tip chatters on a switch"
                            .into(),
                    ));
                }
            }
        }
        tally.alpha_hat_ends.1 = alpha(tau, &y);
        Ok((y, branch, tally))
    }
}
