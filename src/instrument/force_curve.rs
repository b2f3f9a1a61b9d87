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
use crate::dynamics::model::Drive;
use crate::dynamics::numeric::Ignore;
use crate::dynamics::observed::{Recorder, Sampling};
use crate::dynamics::setup::{Cantilever, Numerics, Prepared, TapSetup};
use crate::error::{Error, Result};
use crate::physics::law::{AnyLaw, Branch, ForceLaw, Internal};
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
        match self.turn_m {
            Some(turn) => self.start_m - turn,
            None => MAX_TRAVEL_M.min(MAX_LEG_PERIODS * self.velocity_m_s / cantilever.resonance_hz),
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
        let periods = travel / self.velocity_m_s * f0;
        if periods > MAX_LEG_PERIODS || self.dwell_s * f0 > MAX_LEG_PERIODS {
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

/// The recorded legs: samples, each leg's (first sample, time offset τ₀, approach).
struct Record {
    samples: Vec<(f64, f64, f64, f64, f64, Branch)>,
    legs: Vec<(usize, f64, Leg)>,
    integrals: Option<CycleIntegrals>,
    /// Whether a leg needed more points than a record holds.
    overflowed: bool,
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
    let cant = &p.setup.cantilever;
    let (k, l) = (cant.stiffness_n_m, cant.free_amplitude_m);
    let w0 = 2.0 * PI * cant.resonance_hz;
    let scale = p.setup.contact.separation_scale_m();
    let mut sim = p.simulation();
    sim.cpl.a0 = 0.0;
    sim.tol.h_max = 2.0 * PI / numerics.min_steps_per_period;
    let start = ramp.start_m / l;
    if sim.cpl.alpha_hat(0.0, start) <= p.law.jump_in_alpha_hat() {
        return Err(Error::NotApplicable(format!(
            "the ramp starts at {:.4} nm, inside the law's reach for contact (it jumps in \
             at {:.4} nm): start farther out",
            ramp.start_m * 1e9,
            p.law.jump_in_alpha_hat() * scale * 1e9
        )));
    }
    let speed = ramp.velocity_m_s / (l * w0);
    let travel = ramp.travel_m(cant) / l;
    let trigger = ramp.trigger_n.map(|f| f / (k * l));
    let record = budgeted(p.steady.max_steps, || {
        let mut phase = at_rest(&sim, start);
        let mut record = Record {
            samples: Vec::new(),
            legs: Vec::new(),
            integrals: None,
            overflowed: false,
        };
        let mut t0 = 0.0;
        let approach = Leg {
            from: start,
            speed: -speed,
            span: travel / speed,
            approach: true,
        };
        let (turn, triggered) = leg(&mut sim, &mut phase, approach, trigger, &mut record, t0)?;
        if let (Some(f), None, false) = (ramp.trigger_n, ramp.turn_m, triggered) {
            return Err(Error::NotApplicable(format!(
                "the force did not reach the trigger of {:.4} nN with the support {:.4} nm past \
                 its start ({:.4} nN at most): lower the trigger or give a turn position",
                f * 1e9,
                travel * l * 1e9,
                record.samples.iter().map(|s| s.4).fold(0.0, f64::max) * k * l * 1e9
            )));
        }
        t0 += phase.tau;
        if ramp.dwell_s > 0.0 {
            let dwell = Leg {
                from: turn,
                speed: 0.0,
                span: ramp.dwell_s * w0,
                approach: false,
            };
            leg(&mut sim, &mut phase, dwell, None, &mut record, t0)?;
            t0 += phase.tau;
        }
        let retract = Leg {
            from: turn,
            speed,
            span: (start - turn) / speed,
            approach: false,
        };
        leg(&mut sim, &mut phase, retract, None, &mut record, t0)?;
        if record.overflowed {
            return Err(Error::NotApplicable(
                "the force curve needs more than 10⁶ recorded points: raise the velocity or \
                 shorten the ramp"
                    .into(),
            ));
        }
        Ok((record, turn, triggered, phase))
    });
    let (record, turn, triggered, phase) = record?;
    let integrals = record.integrals.expect("a ramp has legs");
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
    let final_energy = 0.5 * (phase.x * phase.x + phase.v * phase.v) * energy;
    let (drive, contact, damping) = (
        integrals.e_drive * energy,
        integrals.e_ts * energy,
        integrals.e_damp * energy,
    );
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
        final_energy_j: final_energy,
        energy_balance_rel: ((drive - contact - damping - integrals.delta_mechanical * energy)
            / books)
            .abs(),
        curve,
    })
}

/// The lever at rest with the support at `start` (units of L): its deflection where
/// the spring holds the law's force out of contact (a few fixed-point steps; the force
/// there is far weaker than the lever).
fn at_rest(sim: &Simulation<'_, AnyLaw>, start: f64) -> Phase {
    let mut phase = Phase::at_rest();
    for _ in 0..8 {
        let state = sim.cpl.contact_state(
            (phase.x, 0.0),
            (start, 0.0),
            Branch::Free,
            Internal::default(),
        );
        phase.x = -sim.cpl.f_scale * sim.law.force_hat(&state);
    }
    phase
}

/// March one leg, recording it; with a `trigger` (units of kL) stop where the force
/// first reaches it. The support's position where the leg ended (units of L) and
/// whether the trigger ended it.
fn leg(
    sim: &mut Simulation<'_, AnyLaw>,
    phase: &mut Phase,
    leg: Leg,
    trigger: Option<f64>,
    record: &mut Record,
    t0: f64,
) -> Result<(f64, bool)> {
    phase.tau = 0.0;
    sim.osc.drive = Drive::Ramp {
        position: leg.from,
        speed: leg.speed,
    };
    // The span one call may cover: the whole leg.
    sim.osc.omega = 2.0 * PI / leg.span;
    let first = record.samples.len();
    let mut recorder = Recorder::sampling(sim.law, sim.cpl, sim.osc, RAMP_CURVE);
    if let Some(last) = record.samples.last() {
        // Go on from the last leg's end, which is this leg's start.
        recorder
            .samples
            .push((0.0, last.1, last.2, last.3, last.4, last.5));
    }
    let mut triggered = false;
    match trigger {
        None => {
            let c = sim.advance(phase, leg.span, &mut recorder)?;
            add(c, record);
        }
        Some(level) => {
            // A lever period at a time; the period that reaches the trigger is marched
            // again to the first time it does (bisection on the span).
            let chunk = 2.0 * PI;
            while phase.tau < leg.span - 1e-12 * leg.span {
                let span = chunk.min(leg.span - phase.tau);
                let (before, kept) = (*phase, recorder.samples.len());
                let c = sim.advance(phase, span, &mut recorder)?;
                if c.max_force < level {
                    add(c, record);
                    continue;
                }
                recorder.samples.truncate(kept);
                let (mut lo, mut hi) = (0.0, span);
                while hi - lo > 1e-9 * chunk {
                    let mid = 0.5 * (lo + hi);
                    let mut trial = before;
                    let c = sim.advance(&mut trial, mid, &mut Ignore)?;
                    if c.max_force >= level {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                *phase = before;
                let c = sim.advance(phase, hi, &mut recorder)?;
                add(c, record);
                triggered = true;
                break;
            }
        }
    }
    record.overflowed |= recorder.overflowed;
    let skip = usize::from(first > 0);
    record.samples.extend(recorder.samples.drain(skip..));
    record.legs.push((first, t0, leg));
    Ok((leg.from + leg.speed * phase.tau, triggered))
}

/// Add a span's integrals to the record's.
fn add(integrals: CycleIntegrals, record: &mut Record) {
    record.integrals = Some(match record.integrals {
        Some(before) => before.then(&integrals),
        None => integrals,
    });
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
