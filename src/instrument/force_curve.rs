//! Force–distance curves: the support of the cantilever ramped toward the sample at a
//! constant speed, held for a dwell, and withdrawn at the same speed to where it began
//! (a triangular ramp), the point-mass cantilever integrated against the law all the
//! way, every jump into and out of contact located. This is the paper's cycle with a
//! compliant support (§4, eqs. (22)–(27)): the spring is the lever, and as the ramp
//! slows the support's work per cycle tends to Ŵ(μ, k̂)·μεRΔγ of eq. (26), the snap-in to
//! the support separation α̂_A of eq. (17) and the pull-off to the support separation at
//! C, eq. (24).
//!
//! Each leg of the ramp is a [`Drive::Ramp`] (the support at a constant speed, its
//! acceleration zero) marched by the same marcher as tapping, so free flight between
//! the jumps is in closed form and the energies are the march's exact integrals. The
//! approach turns back at a piezo position or, as an instrument's trigger does, where
//! the force first reaches a threshold (located to 1e-9 of a lever period).

use super::peakforce::check_setpoint;
use super::qnm::{Analysis, Channels, ForcePoint};
use crate::dynamics::budget::budgeted;
use crate::dynamics::march::{CycleIntegrals, Phase, Simulation};
use crate::dynamics::model::{Drive, State};
use crate::dynamics::modes::system::{ModeIntegral, Modes, force_integral, integral};
use crate::dynamics::modes::{Modal, ModeSet};
use crate::dynamics::numeric::{Ignore, StepEnd, StepObserver};
use crate::dynamics::observed::{Recorder, Sample, Sampling};
use crate::dynamics::setup::{Cantilever, Numerics, Prepared, TapSetup};
use crate::error::{Error, Result};
use crate::physics::law::{AnyLaw, Branch, ForceLaw};
use serde::Serialize;
use std::f64::consts::PI;

/// The ramp of the support.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Ramp {
    /// Where the ramp starts and ends: the separation of the undeflected tip from the
    /// sample, m (default 20 nm; out of contact).
    pub start_m: f64,
    /// The nearest the support comes, as the undeflected tip's separation, m (negative:
    /// pressed in); None: as far as the trigger needs, at most [`MAX_TRAVEL_M`].
    pub turn_m: Option<f64>,
    /// Turn back where the force first reaches this, N (an instrument's trigger;
    /// default 5 nN); None: at `turn_m`.
    pub trigger_n: Option<f64>,
    /// The support's speed on both legs, m/s (default 1 µm/s).
    pub velocity_m_s: f64,
    /// How long the support rests at the turn, s (default 0).
    pub dwell_s: f64,
}

impl Default for Ramp {
    fn default() -> Self {
        Self {
            start_m: 20e-9,
            turn_m: None,
            trigger_n: Some(5e-9),
            velocity_m_s: 1e-6,
            dwell_s: 0.0,
        }
    }
}

/// How many times a steady state's work budget a force curve with higher modes may take
/// (some 20 s of work on three modes).
pub const MODES_BUDGET: u64 = 100;

/// The farthest an approach goes past its start looking for the trigger, m.
pub const MAX_TRAVEL_M: f64 = 1e-6;

/// The most periods of the lever a leg of the ramp (or the dwell) may last: the motion
/// is integrated through every one of them.
pub const MAX_LEG_PERIODS: f64 = 2e5;

/// The fewest periods of the lever a leg must last: a faster ramp is no force curve
/// (the lever cannot follow the support).
pub const MIN_LEG_PERIODS: f64 = 20.0;

impl Ramp {
    /// How far the approach goes at most, m: to the turn position, or without one as
    /// far as the trigger may need — [`MAX_TRAVEL_M`], or what the lever's
    /// [`MAX_LEG_PERIODS`] allow at this velocity if less.
    pub fn travel_m(&self, cantilever: &Cantilever) -> f64 {
        self.travel_with(cantilever.resonance_hz)
    }

    /// [`Ramp::travel_m`] where the fastest motion integrated has frequency `fastest_hz`.
    fn travel_with(&self, fastest_hz: f64) -> f64 {
        match self.turn_m {
            Some(turn) => self.start_m - turn,
            None => MAX_TRAVEL_M.min(MAX_LEG_PERIODS * self.velocity_m_s / fastest_hz),
        }
    }

    /// Refuse a ramp no instrument runs or the lever cannot follow.
    pub fn check(&self, cantilever: &Cantilever) -> Result<()> {
        if !(self.start_m > 0.0 && self.start_m <= 10e-6) {
            return Err(Error::InvalidParameter {
                name: "ramp start",
                value: self.start_m,
                reason: "must be above the sample (positive) and at most 10 µm from it",
            });
        }
        if self.turn_m.is_none() && self.trigger_n.is_none() {
            return Err(Error::NotApplicable(
                "a force curve needs a turn: a piezo position to ramp to, a trigger force, \
                 or both (whichever comes first)"
                    .into(),
            ));
        }
        if let Some(turn) = self.turn_m
            && !(turn < self.start_m && turn >= self.start_m - 10e-6)
        {
            return Err(Error::NotApplicable(format!(
                "the ramp must turn nearer the sample than it starts, and at most 10 µm on: \
                 it starts at {:.4} nm and would turn at {:.4} nm",
                self.start_m * 1e9,
                turn * 1e9
            )));
        }
        if let Some(trigger) = self.trigger_n {
            check_setpoint(trigger).map_err(|_| Error::InvalidParameter {
                name: "trigger force",
                value: trigger,
                reason: "must be 1 pN to 10 µN (instruments trigger at 0.1–100 nN)",
            })?;
        }
        if !(self.velocity_m_s > 0.0 && self.velocity_m_s.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "ramp velocity",
                value: self.velocity_m_s,
                reason: "must be positive (instruments ramp at 0.01–100 µm/s)",
            });
        }
        if !(self.dwell_s >= 0.0 && self.dwell_s.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "dwell",
                value: self.dwell_s,
                reason: "must be zero or positive",
            });
        }
        let f0 = cantilever.resonance_hz;
        let travel = self.travel_m(cantilever);
        // (Without a turn the travel is cut to what may be integrated; the sample must
        // be within it.)
        let to_sample = self.start_m / self.velocity_m_s * f0;
        if self.turn_m.is_none() && to_sample > MAX_LEG_PERIODS {
            return Err(Error::NotApplicable(format!(
                "at {} µm/s the support takes {to_sample:.0} periods of the {:.4} kHz \
                 cantilever to reach the sample from {:.4} nm; at most {MAX_LEG_PERIODS} are \
                 integrated a leg: raise the velocity or start nearer",
                self.velocity_m_s * 1e6,
                f0 * 1e-3,
                self.start_m * 1e9
            )));
        }
        let periods = travel / self.velocity_m_s * f0;
        if periods > MAX_LEG_PERIODS * (1.0 + 1e-12) || self.dwell_s * f0 > MAX_LEG_PERIODS {
            return Err(Error::NotApplicable(format!(
                "a ramp of {:.4} nm at {} µm/s (dwell {} s) lasts {:.0} periods of the \
                 {:.4} kHz cantilever a leg; at most {MAX_LEG_PERIODS} are integrated: raise \
                 the velocity, shorten the ramp or the dwell",
                travel * 1e9,
                self.velocity_m_s * 1e6,
                self.dwell_s,
                periods.max(self.dwell_s * f0),
                f0 * 1e-3
            )));
        }
        let least = self.start_m.min(travel) / self.velocity_m_s * f0;
        if least < MIN_LEG_PERIODS {
            return Err(Error::NotApplicable(format!(
                "at {} µm/s the support crosses {:.4} nm in {:.1} periods of the {:.4} kHz \
                 cantilever, too fast for a force curve (at least {MIN_LEG_PERIODS}): lower \
                 the velocity",
                self.velocity_m_s * 1e6,
                self.start_m.min(travel) * 1e9,
                least,
                f0 * 1e-3
            )));
        }
        Ok(())
    }
}

/// A jump into or out of contact, located.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Jump {
    /// Time from the start of the ramp, s.
    pub t_s: f64,
    /// The support's position (the undeflected tip's separation), m.
    pub piezo_m: f64,
    /// The tip–sample separation at the switch, m.
    pub separation_m: f64,
    /// The force on the contact branch at the switch (just after a snap-in, just before
    /// a pull-off), N.
    pub force_n: f64,
}

/// A recorded force–distance curve and what an instrument's analysis reads from it.
#[derive(Debug, Clone, Serialize)]
pub struct ForceCurve {
    /// The ramp that was run.
    pub ramp: Ramp,
    /// Where the support turned (the undeflected tip's separation), m.
    pub turn_m: f64,
    /// Whether the trigger turned the ramp (else the turn position did).
    pub triggered: bool,
    /// The first jump into contact on the approach (for a law without a jump, Hertz or
    /// DMT, where contact begins); None if the tip never touched.
    pub snap_in: Option<Jump>,
    /// The last jump out of contact on the retract (for a law without a jump, where
    /// contact ends); None if the tip left no contact on the way back.
    pub pull_off: Option<Jump>,
    /// The QNM channels of the whole curve ([`Analysis::channels`]).
    pub channels: Channels,
    /// The deepest indentation, −min α (0 if the tip never went below α = 0), m.
    pub max_indentation_m: f64,
    /// The energy the contact took, −∮F dα over the exact path (switches located), J.
    pub contact_loss_j: f64,
    /// The energy damping took (the ringing after the jumps among it), J.
    pub damping_loss_j: f64,
    /// The support's work on the lever, −∮F dz_piezo: the area of the force–piezo loop,
    /// the paper's loss with a compliant support (eq. (26) in the slow limit), J.
    pub drive_work_j: f64,
    /// The lever's energy left at the end (its ringing), J.
    pub final_energy_j: f64,
    /// |drive work − contact loss − damping loss − energy left| over the drive work or,
    /// where more, half the work the contact exchanges with the tip.
    pub energy_balance_rel: f64,
    /// The curve: approach, dwell and retract in time order, both sides of every switch.
    pub curve: Vec<ForcePoint>,
}

/// How the curve is recorded: each integrator step's end (the steps resolve the
/// contact at least 40 times a lever period), the closed-form free flight 8 times a
/// lever period, both sides of every switch; at most 10⁶ points.
const RAMP_CURVE: Sampling = Sampling {
    points_per_step: 1,
    free_samples: 8.0,
    free_period: 2.0 * PI,
    switch_starts: true,
    max_samples: 1_000_000,
};

/// One leg of the ramp: the support from `from` (units of L) at `speed` (L per 1/ω₀)
/// for at most `span` (1/ω₀).
#[derive(Debug, Clone, Copy)]
struct Leg {
    from: f64,
    speed: f64,
    span: f64,
    approach: bool,
}

/// The energies of the legs so far (units of kL²): what the contact and damping took,
/// the support's work, and the change of the lever's energy.
#[derive(Debug, Clone, Copy, Default)]
struct Energies {
    contact: f64,
    damping: f64,
    drive: f64,
    mechanical: f64,
}

/// The recorded legs: samples, each leg's (first sample, time offset τ₀, approach).
struct Record {
    samples: Vec<Sample>,
    legs: Vec<(usize, f64, Leg)>,
    energies: Energies,
    /// Whether a leg needed more points than a record holds.
    overflowed: bool,
}

impl Record {
    /// A new leg's recording starts from the last leg's end, which is its start (at the
    /// leg's τ = 0): that sample, if there is one.
    fn leg_start(&self) -> Option<Sample> {
        self.samples
            .last()
            .map(|last| (0.0, last.1, last.2, last.3, last.4, last.5))
    }

    /// Append a leg's recorded `samples` (their first, the last leg's end, dropped where
    /// a leg came before) and whether they `overflowed`.
    fn append(&mut self, samples: &mut Vec<Sample>, overflowed: bool) {
        let skip = usize::from(!self.samples.is_empty());
        self.overflowed |= overflowed;
        self.samples.extend(samples.drain(skip..));
    }
}

/// A cantilever the ramp moves: one leg at a time.
trait Lever {
    /// March `leg` (τ from 0), recording it into `record` (its samples' τ from the leg's
    /// start; the energies added); with a `trigger` (units of kL) stop where the force
    /// first reaches it. How long the leg lasted (τ) and whether the trigger ended it.
    fn leg(&mut self, leg: Leg, trigger: Option<f64>, record: &mut Record) -> Result<(f64, bool)>;
    /// The lever's energy now, units of kL².
    fn energy(&self) -> f64;
}

/// The point-mass lever.
struct OneMode<'a> {
    sim: Simulation<'a, AnyLaw>,
    phase: Phase,
}

/// Run a force–distance curve on `setup` (its cantilever, contact and law; the tapping
/// drive unused), analysed by `analysis`.
pub fn force_curve(
    setup: &TapSetup,
    numerics: &Numerics,
    ramp: &Ramp,
    analysis: &Analysis,
) -> Result<ForceCurve> {
    analysis.check()?;
    ramp.check(&setup.cantilever)?;
    let p = Prepared::new(setup, numerics)?;
    let mut sim = p.simulation();
    sim.cpl.a0 = 0.0;
    sim.tol.h_max = 2.0 * PI / numerics.min_steps_per_period;
    let start = ramp.start_m / p.setup.cantilever.free_amplitude_m;
    let lever = OneMode {
        phase: at_rest(&sim, start),
        sim,
    };
    run(
        &p,
        lever,
        ramp,
        analysis,
        (p.steady.max_steps, ramp.travel_m(&p.setup.cantilever)),
    )
}

/// [`force_curve`] with the cantilever's higher eigenmodes of `set` marched with the
/// first (bimodal AFM's model, [`crate::dynamics::modes`]; their drives off): the tip is
/// the sum of the modes, and the ringing after each jump shows every mode's.
pub fn force_curve_modes(
    setup: &TapSetup,
    numerics: &Numerics,
    set: &ModeSet,
    ramp: &Ramp,
    analysis: &Analysis,
) -> Result<ForceCurve> {
    use crate::dynamics::modes::system::plain_len;
    analysis.check()?;
    ramp.check(&setup.cantilever)?;
    let (p, modal) = crate::dynamics::modes::prepare(setup, set, numerics)?;
    // Every mode's period is stepped through (no closed-form free flight): the highest
    // mode sets the work, some 40 steps a period of it, at the least.
    let fastest = modal.modes.iter().map(|m| m.r).fold(1.0f64, f64::max);
    let cant = &p.setup.cantilever;
    let travel_m = ramp.travel_with(cant.resonance_hz * fastest);
    // (Without a turn the support must reach the sample within what may be integrated.)
    let reach_m = if ramp.turn_m.is_some() {
        travel_m
    } else {
        ramp.start_m.max(travel_m)
    };
    let leg_periods = (reach_m / ramp.velocity_m_s).max(ramp.dwell_s) * cant.resonance_hz * fastest;
    if leg_periods > MAX_LEG_PERIODS * (1.0 + 1e-12) {
        return Err(Error::NotApplicable(format!(
            "a leg of this ramp lasts {leg_periods:.0} periods of the highest of {} modes \
             ({:.4} kHz); at most {MAX_LEG_PERIODS} are integrated: raise the velocity, \
             shorten the ramp or the dwell, or take fewer modes",
            modal.modes.len(),
            cant.resonance_hz * fastest * 1e-3
        )));
    }
    let budget = p.steady.max_steps.saturating_mul(MODES_BUDGET);
    match modal.modes.len() {
        1 => run(
            &p,
            SeveralModes::<1, { plain_len(1) }>::new(&p, &modal, numerics, ramp),
            ramp,
            analysis,
            (budget, travel_m),
        ),
        2 => run(
            &p,
            SeveralModes::<2, { plain_len(2) }>::new(&p, &modal, numerics, ramp),
            ramp,
            analysis,
            (budget, travel_m),
        ),
        _ => run(
            &p,
            SeveralModes::<3, { plain_len(3) }>::new(&p, &modal, numerics, ramp),
            ramp,
            analysis,
            (budget, travel_m),
        ),
    }
}

/// The ramp's legs with `lever`, and what the curve shows.
fn run<Lv: Lever>(
    p: &Prepared,
    mut lever: Lv,
    ramp: &Ramp,
    analysis: &Analysis,
    (budget, travel_m): (u64, f64),
) -> Result<ForceCurve> {
    let cant = &p.setup.cantilever;
    let (k, l) = (cant.stiffness_n_m, cant.free_amplitude_m);
    let w0 = 2.0 * PI * cant.resonance_hz;
    let scale = p.setup.contact.separation_scale_m();
    let start = ramp.start_m / l;
    if p.cpl.a1 * start <= p.law.jump_in_alpha_hat() {
        return Err(Error::NotApplicable(format!(
            "the ramp starts at {:.4} nm, inside the law's reach for contact (it jumps in \
             at {:.4} nm): start farther out",
            ramp.start_m * 1e9,
            p.law.jump_in_alpha_hat() * scale * 1e9
        )));
    }
    let speed = ramp.velocity_m_s / (l * w0);
    let travel = travel_m / l;
    let trigger = ramp.trigger_n.map(|f| f / (k * l));
    let record = budgeted(budget, || {
        let mut record = Record {
            samples: Vec::new(),
            legs: Vec::new(),
            energies: Energies::default(),
            overflowed: false,
        };
        let mut t0 = 0.0;
        let mut march =
            |leg: Leg, trigger, record: &mut Record, t0: &mut f64| -> Result<(f64, bool)> {
                let first = record.samples.len();
                let (span, triggered) = lever.leg(leg, trigger, record)?;
                record.legs.push((first, *t0, leg));
                *t0 += span;
                Ok((leg.from + leg.speed * span, triggered))
            };
        let approach = Leg {
            from: start,
            speed: -speed,
            span: travel / speed,
            approach: true,
        };
        let (turn, triggered) = march(approach, trigger, &mut record, &mut t0)?;
        if let (Some(f), None, false) = (ramp.trigger_n, ramp.turn_m, triggered) {
            return Err(Error::NotApplicable(format!(
                "the force did not reach the trigger of {:.4} nN with the support {:.4} nm past \
                 its start ({:.4} nN at most): lower the trigger or give a turn position",
                f * 1e9,
                travel * l * 1e9,
                record.samples.iter().map(|s| s.4).fold(0.0, f64::max) * k * l * 1e9
            )));
        }
        if ramp.dwell_s > 0.0 {
            let dwell = Leg {
                from: turn,
                speed: 0.0,
                span: ramp.dwell_s * w0,
                approach: false,
            };
            march(dwell, None, &mut record, &mut t0)?;
        }
        let retract = Leg {
            from: turn,
            speed,
            span: (start - turn) / speed,
            approach: false,
        };
        march(retract, None, &mut record, &mut t0)?;
        if record.overflowed {
            return Err(Error::NotApplicable(
                "the force curve needs more than 10⁶ recorded points: raise the velocity or \
                 shorten the ramp"
                    .into(),
            ));
        }
        Ok((record, turn, triggered))
    });
    let (record, turn, triggered) = record?;
    let e = record.energies;
    let curve = to_si(&record, (k, l, w0, scale));
    // A switch at α = 0 (Hertz, DMT, JKR) is located to round-off of the ramp's lengths
    // and the force there to round-off of the peak: those are zeros.
    let peak = curve.iter().map(|p| p.force_n.abs()).fold(0.0, f64::max);
    let zero_below = |v: f64, scale: f64| if v.abs() < 1e-12 * scale { 0.0 } else { v };
    let jumps = |approach: bool| {
        let mut found = curve
            .windows(2)
            .filter(|w| w[0].approach == approach && w[1].approach == approach)
            .filter(|w| w[0].contact != w[1].contact && w[1].contact == approach)
            .map(|w| {
                let on = if approach { w[1] } else { w[0] };
                Jump {
                    t_s: on.t_s,
                    piezo_m: zero_below(on.piezo_m, ramp.start_m),
                    separation_m: zero_below(on.separation_m, ramp.start_m),
                    force_n: zero_below(on.force_n, peak),
                }
            });
        if approach {
            found.next()
        } else {
            found.next_back()
        }
    };
    let energy = k * l * l;
    let (drive, contact, damping) = (e.drive * energy, e.contact * energy, e.damping * energy);
    let exchanged = 0.5
        * curve
            .windows(2)
            .map(|w| super::qnm::work_on_tip(w).abs())
            .sum::<f64>();
    let books = drive.abs().max(exchanged).max(f64::MIN_POSITIVE);
    Ok(ForceCurve {
        ramp: *ramp,
        turn_m: turn * l,
        triggered,
        snap_in: jumps(true),
        pull_off: jumps(false),
        channels: analysis.channels(&curve, p.setup.contact.radius_m),
        max_indentation_m: curve.iter().map(|c| -c.separation_m).fold(0.0, f64::max),
        contact_loss_j: if contact.abs() < 1e-12 * books {
            0.0
        } else {
            contact
        },
        damping_loss_j: damping,
        drive_work_j: drive,
        final_energy_j: lever.energy() * energy,
        energy_balance_rel: ((drive - contact - damping - e.mechanical * energy) / books).abs(),
        curve,
    })
}

/// The lever at rest with the support at `start` (units of L): its deflection where
/// the spring holds the law's force out of contact (a few fixed-point steps; the force
/// there is far weaker than the lever).
fn at_rest(sim: &Simulation<'_, AnyLaw>, start: f64) -> Phase {
    let mut phase = Phase::at_rest();
    for _ in 0..8 {
        let state = sim
            .cpl
            .contact_state((phase.x, 0.0), (start, 0.0), Branch::Free);
        phase.x = -sim.cpl.f_scale * sim.law.force_hat(&state);
    }
    phase
}

impl Lever for OneMode<'_> {
    fn energy(&self) -> f64 {
        0.5 * (self.phase.x * self.phase.x + self.phase.v * self.phase.v)
    }

    fn leg(&mut self, leg: Leg, trigger: Option<f64>, record: &mut Record) -> Result<(f64, bool)> {
        let (sim, phase) = (&mut self.sim, &mut self.phase);
        phase.tau = 0.0;
        sim.osc.drive = Drive::Ramp {
            position: leg.from,
            speed: leg.speed,
        };
        // The span one call may cover: the whole leg.
        sim.osc.omega = 2.0 * PI / leg.span;
        let mut recorder = Recorder::sampling(sim.law, sim.cpl, sim.osc, RAMP_CURVE);
        recorder.samples.extend(record.leg_start());
        let add = |c: CycleIntegrals, record: &mut Record| {
            let e = &mut record.energies;
            e.contact += c.e_ts;
            e.damping += c.e_damp;
            e.drive += c.e_drive;
            e.mechanical += c.delta_mechanical;
        };
        let mut triggered = false;
        match trigger {
            None => {
                let c = sim.advance(phase, leg.span, &mut recorder)?;
                add(c, record);
            }
            Some(level) => {
                // A lever period at a time; the period that reaches the trigger is
                // marched again to the first time it does (bisection on the span).
                let chunk = 2.0 * PI;
                while phase.tau < leg.span - 1e-12 * leg.span {
                    let span = chunk.min(leg.span - phase.tau);
                    let (before, kept) = (phase.clone(), recorder.samples.len());
                    let c = sim.advance(phase, span, &mut recorder)?;
                    if c.max_force < level {
                        add(c, record);
                        continue;
                    }
                    recorder.samples.truncate(kept);
                    let hi = first_reach(span, |s| {
                        let mut trial = before.clone();
                        Ok(sim.advance(&mut trial, s, &mut Ignore)?.max_force >= level)
                    })?;
                    *phase = before;
                    let c = sim.advance(phase, hi, &mut recorder)?;
                    add(c, record);
                    triggered = true;
                    break;
                }
            }
        }
        record.append(&mut recorder.samples, recorder.overflowed);
        Ok((phase.tau, triggered))
    }
}

/// The first span s in (0, `span`] at which `reached(s)` (monotone: false, then true)
/// holds, to 1e-9 of a lever period (bisection).
fn first_reach(span: f64, mut reached: impl FnMut(f64) -> Result<bool>) -> Result<f64> {
    let (mut lo, mut hi) = (0.0, span);
    while hi - lo > 1e-9 * 2.0 * PI {
        let mid = 0.5 * (lo + hi);
        if reached(mid)? {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(hi)
}

/// The cantilever's first `M` eigenmodes (`P` = their state's length).
struct SeveralModes<'a, const M: usize, const P: usize> {
    modes: Modes<'a, AnyLaw, M>,
    y: State<P>,
    branch: Branch,
}

impl<'a, const M: usize, const P: usize> SeveralModes<'a, M, P> {
    fn new(p: &'a Prepared, modal: &Modal, numerics: &Numerics, ramp: &Ramp) -> Self {
        let mut modes = Modes::<_, M>::of(p, modal);
        for m in &mut modes.modes {
            m.drive = 0.0;
        }
        modes.cpl.a0 = 0.0;
        // Every mode's period resolved (the longest step set for the fastest mode).
        let fastest = modes.modes.iter().map(|m| m.r).fold(1.0f64, f64::max);
        modes.tol.h_max = 2.0 * PI / numerics.min_steps_per_period / fastest;
        let start = ramp.start_m / p.setup.cantilever.free_amplitude_m;
        modes.support = (start, 0.0);
        // At rest: each mode holds its share cᵢ/rᵢ² of the static force.
        let mut y = State::<P>::zeros();
        let mut x = 0.0;
        for _ in 0..8 {
            let f = modes.force(x, 0.0, Branch::Free);
            for (i, m) in modes.modes.iter().enumerate() {
                y[2 * i] = m.gain * f / (m.r * m.r);
            }
            x = Modes::<AnyLaw, M>::tip(&y);
        }
        Self {
            modes,
            y,
            branch: Branch::Free,
        }
    }

    /// Integrals of the state (from what `y` carries): Σ damping, ∫f.
    fn carried(&self, y: &State<P>) -> (f64, f64) {
        let damping = (0..M)
            .map(|i| {
                let m = &self.modes.modes[i];
                m.damping / m.gain * y[integral(M, i, ModeIntegral::Damping)]
            })
            .sum();
        (damping, y[force_integral(M)])
    }

    fn energy_of(&self, y: &State<P>) -> f64 {
        (0..M)
            .map(|i| {
                let m = &self.modes.modes[i];
                (y[2 * i + 1].powi(2) + (m.r * y[2 * i]).powi(2)) / (2.0 * m.gain)
            })
            .sum()
    }
}

/// Records the modes' tip at every step's end in contact and [`MODES_SAMPLES`] a lever
/// period out of it (both sides of every switch), and the largest force at every
/// step's end.
struct TipRecorder<'r, 'a, const M: usize> {
    modes: &'r Modes<'a, AnyLaw, M>,
    samples: Vec<Sample>,
    overflowed: bool,
    max_force: f64,
}

/// Samples a lever period a force curve with higher modes records out of contact (their
/// steps are many times shorter than the lever's period).
const MODES_SAMPLES: f64 = 32.0;

impl<'r, 'a, const M: usize> TipRecorder<'r, 'a, M> {
    fn new(modes: &'r Modes<'a, AnyLaw, M>) -> Self {
        Self {
            modes,
            samples: Vec::new(),
            overflowed: false,
            max_force: f64::NEG_INFINITY,
        }
    }

    fn push<const N: usize>(&mut self, tau: f64, y: &State<N>, branch: Branch) {
        if self.samples.len() >= RAMP_CURVE.max_samples {
            self.overflowed = true;
            return;
        }
        let x: f64 = (0..M).map(|i| y[2 * i]).sum();
        let v: f64 = (0..M).map(|i| y[2 * i + 1]).sum();
        let alpha = self.modes.cpl.alpha_hat(x, self.modes.x_b(tau));
        let f = self.modes.force(x, tau, branch) + 0.0;
        self.samples.push((tau, x, v, alpha, f, branch));
    }
}

impl<const M: usize> StepObserver for TipRecorder<'_, '_, M> {
    fn step<const N: usize>(&mut self, from: &StepEnd<N>, to: &StepEnd<N>, branch: Branch) {
        let x: f64 = (0..M).map(|i| to.y[2 * i]).sum();
        self.max_force = self.max_force.max(self.modes.force(x, to.tau, branch));
        match self.samples.last() {
            Some(last) if last.5 == branch => {
                // Every step in contact (the force curve's area is taken over them);
                // out of it, where the force is weak or none, a few a lever period.
                if branch != Branch::Free || to.tau - last.0 >= 2.0 * PI / MODES_SAMPLES {
                    self.push(to.tau, &to.y, branch);
                }
            }
            _ => {
                self.push(from.tau, &from.y, branch);
                self.push(to.tau, &to.y, branch);
            }
        }
    }
}

impl<const M: usize, const P: usize> Lever for SeveralModes<'_, M, P> {
    fn energy(&self) -> f64 {
        self.energy_of(&self.y)
    }

    fn leg(&mut self, leg: Leg, trigger: Option<f64>, record: &mut Record) -> Result<(f64, bool)> {
        self.modes.support = (leg.from, leg.speed);
        let mut rec = TipRecorder::new(&self.modes);
        rec.samples.extend(record.leg_start());
        let (y0, e0) = (self.y, self.energy_of(&self.y));
        let (mut y, mut branch, mut tau, mut work_hat) = (self.y, self.branch, 0.0, 0.0);
        let mut triggered = false;
        // A lever period at a time while a trigger is looked for; else 256 (one pass
        // integrates a branch in one segment, whose steps are bounded).
        let chunk = 2.0 * PI * if trigger.is_some() { 1.0 } else { 256.0 };
        while tau < leg.span - 1e-12 * leg.span {
            let end = (tau + chunk).min(leg.span);
            let kept = rec.samples.len();
            let (y1, b1, tally) = self.modes.pass_observed(tau, y, branch, end, &mut rec)?;
            let reached =
                trigger.is_some_and(|level| rec.samples[kept..].iter().any(|s| s.4 >= level));
            if !reached {
                (y, branch, tau) = (y1, b1, end);
                work_hat += tally.work_hat;
                continue;
            }
            let level = trigger.expect("reached a trigger");
            rec.samples.truncate(kept);
            let modes = &self.modes;
            let at = first_reach(end - tau, |s| {
                let mut probe = TipRecorder::new(modes);
                modes.pass_observed(tau, y, branch, tau + s, &mut probe)?;
                Ok(probe.max_force >= level)
            })?;
            let (y1, b1, tally) = self
                .modes
                .pass_observed(tau, y, branch, tau + at, &mut rec)?;
            (y, branch, tau) = (y1, b1, tau + at);
            work_hat += tally.work_hat;
            triggered = true;
            break;
        }
        // The leg's last state, whatever the spacing.
        if rec.samples.last().is_none_or(|s| s.0 < tau) {
            rec.push(tau, &y, branch);
        }
        let ((d0, f0), (d1, f1)) = (self.carried(&y0), self.carried(&y));
        let e = &mut record.energies;
        e.contact += self.modes.cpl.f_scale / self.modes.cpl.a1 * work_hat;
        e.damping += d1 - d0;
        e.drive -= leg.speed * (f1 - f0);
        e.mechanical += self.energy_of(&y) - e0;
        record.append(&mut rec.samples, rec.overflowed);
        self.y = y;
        self.branch = branch;
        Ok((tau, triggered))
    }
}

/// The record in SI: time from the ramp's start, the support, deflection, separation
/// and force.
fn to_si(record: &Record, (k, l, w0, scale): (f64, f64, f64, f64)) -> Vec<ForcePoint> {
    let mut out = Vec::with_capacity(record.samples.len());
    for (i, &(first, t0, leg)) in record.legs.iter().enumerate() {
        let end = record
            .legs
            .get(i + 1)
            .map_or(record.samples.len(), |next| next.0);
        for &(tau, x, _, alpha, f, branch) in &record.samples[first..end] {
            let x_b = leg.from + leg.speed * tau;
            out.push(ForcePoint {
                t_s: (t0 + tau) / w0,
                piezo_m: x_b * l,
                deflection_m: x * l,
                separation_m: alpha * scale,
                force_n: f * k * l,
                approach: leg.approach,
                contact: branch != Branch::Free,
            });
        }
    }
    out
}

impl ForceCurve {
    /// At most `n` points of the curve, evenly spread in time, with both sides of every
    /// switch and the points of least and greatest force kept: what an instrument
    /// stores (512–4096 points a curve) and a plot or a file needs.
    pub fn thinned(&self, n: usize) -> Vec<ForcePoint> {
        let c = &self.curve;
        if c.len() <= n.max(2) {
            return c.clone();
        }
        let duration = c.last().map_or(0.0, |p| p.t_s).max(f64::MIN_POSITIVE);
        let extreme = |better: fn(f64, f64) -> bool| {
            (0..c.len())
                .reduce(|a, b| {
                    if better(c[b].force_n, c[a].force_n) {
                        b
                    } else {
                        a
                    }
                })
                .unwrap_or(0)
        };
        let (lo, hi) = (extreme(|a, b| a < b), extreme(|a, b| a > b));
        let mut out = Vec::with_capacity(n + 8);
        let mut slot = -1i64;
        for (i, p) in c.iter().enumerate() {
            let s = (p.t_s / duration * n as f64) as i64;
            let switch = (i > 0 && c[i - 1].contact != p.contact)
                || (i + 1 < c.len() && c[i + 1].contact != p.contact);
            if s != slot || switch || i == lo || i == hi || i + 1 == c.len() {
                out.push(*p);
                slot = s;
            }
        }
        out
    }
}
