//! Off-resonance tapping (Bruker's PeakForce Tapping, Asylum's Fast Force Mapping, JPK's
//! QI): the support of the cantilever is moved sinusoidally far below resonance, so
//! that every modulation cycle is a fast force–distance curve — the paper's cycle with
//! the cantilever as its compliant support (§4, eqs. (22)–(27)) — and the instrument
//! reads per cycle the peak force, the adhesion, the energy dissipated, the deformation
//! and a DMT modulus fitted to the retract curve (the "QNM" channels).
//!
//! The support moves as x_b = A_m cos 2πf_m t (at its farthest from the sample at t = 0;
//! the first half of a cycle approaches, the second retracts), the tip–sample
//! separation is z_c + x_b + z (z the deflection, measured from the support), and the
//! point-mass cantilever obeys the tapping model's equation of motion with the drive
//! force replaced by the support's motion. The support's acceleration does not enter
//! (the deflection it adds, (f_m/f₀)²·A_m — 7 pm at 2 kHz, 300 kHz, 150 nm — is the
//! baseline instruments subtract). A value beside the tapping solver, not a branch
//! in it: the same marcher, the same located switches, the same steady-state search on
//! the period map of the modulation.

use crate::dynamics::budget::budgeted;
use crate::dynamics::march::{Phase, Simulation};
use crate::dynamics::model::Drive;
use crate::dynamics::numeric::Ignore;
use crate::dynamics::observed::{Recorder, Sample};
use crate::dynamics::setup::{Cantilever, Numerics, Prepared, TapSetup};
use crate::error::{Error, Result};
use crate::physics::law::{AnyLaw, Branch};
use serde::Serialize;
use std::f64::consts::PI;

pub use super::qnm::{Analysis, Channels, ForcePoint, MAX_CURVE_SAMPLES};
use super::qnm::{CURVE, work_on_tip};

/// The support's modulation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Modulation {
    /// f_m, Hz (PeakForce Tapping: 0.1–8 kHz; default 2 kHz).
    pub frequency_hz: f64,
    /// A_m, m (default 150 nm).
    pub amplitude_m: f64,
}

impl Default for Modulation {
    fn default() -> Self {
        Self {
            frequency_hz: 2e3,
            amplitude_m: 150e-9,
        }
    }
}

/// The highest modulation frequency, as a fraction of the cantilever's resonance: above
/// it a cycle is no longer a force curve (the lever cannot follow the support).
pub const MAX_FREQUENCY_RATIO: f64 = 0.2;

impl Modulation {
    /// Refuse a modulation that is not off-resonance tapping on `cantilever`.
    pub fn check(&self, cantilever: &Cantilever) -> Result<()> {
        let f0 = cantilever.resonance_hz;
        if !(self.frequency_hz > 0.0 && self.frequency_hz.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "modulation frequency",
                value: self.frequency_hz,
                reason: "must be positive (PeakForce Tapping runs at 0.1–8 kHz)",
            });
        }
        if self.frequency_hz > MAX_FREQUENCY_RATIO * f0 {
            return Err(Error::NotApplicable(format!(
                "a modulation at {:.4} kHz is not off-resonance on a cantilever resonating \
                 at {:.4} kHz: off-resonance tapping needs f_m well below f₀ (at most \
                 {MAX_FREQUENCY_RATIO}·f₀ = {:.4} kHz; instruments use 0.1–8 kHz on levers of \
                 50–500 kHz)",
                self.frequency_hz * 1e-3,
                f0 * 1e-3,
                MAX_FREQUENCY_RATIO * f0 * 1e-3
            )));
        }
        if !(self.amplitude_m > 0.0 && self.amplitude_m <= 10e-6) {
            return Err(Error::InvalidParameter {
                name: "modulation amplitude",
                value: self.amplitude_m,
                reason: "must be above 0 and at most 10 µm (instruments use 10–300 nm)",
            });
        }
        // Resolve the lever's own motion: the cycle is at most 10⁵ of its periods.
        if f0 / self.frequency_hz > 1e5 {
            return Err(Error::NotApplicable(format!(
                "a modulation at {} Hz lasts {:.0} periods of the {:.4} kHz cantilever; at \
                 most 100000 are integrated per cycle: raise the modulation frequency",
                self.frequency_hz,
                f0 / self.frequency_hz,
                f0 * 1e-3
            )));
        }
        Ok(())
    }
}

/// A cycle of off-resonance tapping at a rest separation, once the motion has settled.
#[derive(Debug, Clone, Serialize)]
pub struct PeakForceCycle {
    /// z_c: the separation of the undeflected tip with the support at the modulation's
    /// centre, m.
    pub separation_m: f64,
    /// How the settled motion repeats ("period-1": every cycle alike; "period-n": n
    /// cycles before it repeats, each listed; "irregular").
    pub regime: String,
    /// Modulation cycles marched before the motion repeated itself (to [`SETTLED`] of the
    /// free amplitude), or before giving up on it.
    pub settled_after: usize,
    /// The channels of each cycle of the settled motion (one for period-1, n for
    /// period-n, the last 8 for irregular motion).
    pub cycles: Vec<Channels>,
    /// The energy the tip–sample force took from the cantilever per cycle, −∮F dα over
    /// the exact path (switches located), J; the channels' dissipation is the same
    /// integral over the recorded curve.
    pub contact_loss_j: f64,
    /// The energy damping took per cycle (the ringing after pull-off among it), J.
    pub damping_loss_j: f64,
    /// The work the moving support did on the cantilever per cycle, J.
    pub drive_work_j: f64,
    /// |drive work − contact loss − damping loss − change of the lever's energy| per
    /// cycle, over the drive work or, where more, the work the contact stores and gives
    /// back in a cycle (half of ∮|F dα|).
    pub energy_balance_rel: f64,
    /// The recorded force curve of the settled motion (its cycles in turn).
    pub curve: Vec<ForcePoint>,
}

/// The most cycles of irregular motion whose channels are listed.
const IRREGULAR_CYCLES: usize = 8;

/// The motion has settled once the state at the start of a cycle is within this of its
/// repeating motion (units of the free amplitude; 2 fm on the built-in lever).
pub const SETTLED: f64 = 1e-7;

/// Modulation cycles marched at most before the motion is called irregular.
pub const MAX_SETTLE_CYCLES: usize = 400;

/// Cycles in a row whose return gap must be below [`SETTLED`]/100.
const QUIET_CYCLES: usize = 8;

/// The longest repeat looked for, in modulation cycles.
pub const LONGEST_REPEAT: usize = 8;

/// March `sim` from rest until its state at the start of a cycle (deflection and
/// velocity) repeats itself after n ≤ [`LONGEST_REPEAT`] cycles: the
/// state there, n (None: irregular after [`MAX_SETTLE_CYCLES`]) and the cycles
/// marched. Repeating means a return gap |s_k − s_{k−n}| below [`SETTLED`]/100 for
/// [`QUIET_CYCLES`] cycles running: for motion contracting onto its cycle by any factor
/// up to 0.99 a cycle the state is then within [`SETTLED`] of it (gap·ρ/(1 − ρ)). The
/// integrator's own noise is some 1e-13 of the free amplitude. Newton's method on the
/// period map is not used: after each pull-off the lever rings and meets the next
/// jump-in with what is left, and turning points of the separation near the jump-in
/// level shrink the region where its answer may be trusted to nothing.
fn settle(sim: &Simulation<'_, AnyLaw>) -> Result<(Phase, Option<usize>, usize)> {
    let mut phase = Phase::at_rest();
    let mut history: Vec<[f64; 2]> = Vec::with_capacity(MAX_SETTLE_CYCLES);
    // Per repeat n: cycles running with the gap quiet, and with it no longer shrinking.
    let mut quiet = [0usize; LONGEST_REPEAT];
    let mut stalled = [0usize; LONGEST_REPEAT];
    let mut last_gap = [f64::INFINITY; LONGEST_REPEAT];
    for marched in 1..=MAX_SETTLE_CYCLES {
        sim.rewind(&mut phase);
        sim.cycle(&mut phase, &mut Ignore)?;
        let state = [phase.x, phase.v];
        history.push(state);
        for n in 1..=LONGEST_REPEAT {
            let Some(before) = history.len().checked_sub(n + 1).map(|k| history[k]) else {
                continue;
            };
            let gap = state
                .iter()
                .zip(&before)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            quiet[n - 1] = if gap <= 1e-2 * SETTLED {
                quiet[n - 1] + 1
            } else {
                0
            };
            stalled[n - 1] = if gap >= 0.99 * last_gap[n - 1] {
                stalled[n - 1] + 1
            } else {
                0
            };
            last_gap[n - 1] = gap;
        }
        // The least quiet repeat, once every shorter one that divides it has stopped
        // shrinking (an orbit approached with a negative multiplier returns closer after
        // two cycles than after one while it converges).
        if let Some(n) = (1..=LONGEST_REPEAT).find(|&n| quiet[n - 1] >= QUIET_CYCLES)
            && (1..n)
                .filter(|d| n % d == 0)
                .all(|d| stalled[d - 1] >= QUIET_CYCLES)
        {
            return Ok((phase, Some(n), marched));
        }
    }
    Ok((phase, None, MAX_SETTLE_CYCLES))
}

/// A recorder's samples of `sim` (at rest separation `separation_m`) in SI.
pub(crate) fn force_points(
    p: &Prepared,
    sim: &Simulation<'_, AnyLaw>,
    separation_m: f64,
    samples: &[Sample],
) -> Vec<ForcePoint> {
    let cant = &p.setup.cantilever;
    let (k, l) = (cant.stiffness_n_m, cant.free_amplitude_m);
    let w0 = 2.0 * PI * cant.resonance_hz;
    let scale = p.setup.contact.separation_scale_m();
    samples
        .iter()
        .map(|&(tau, x, _, alpha, f, branch)| {
            let (x_b, v_b) = sim.osc.base_at(tau);
            ForcePoint {
                t_s: (tau % sim.osc.period()) / w0,
                piezo_m: separation_m + x_b * l,
                deflection_m: x * l,
                separation_m: alpha * scale,
                force_n: f * k * l,
                approach: v_b < 0.0,
                contact: branch != Branch::Free,
            }
        })
        .collect()
}

/// The simulation of `setup`'s cantilever and law driven through its support by
/// `modulation`, at rest separation `separation_m`: the length unit L is the free
/// amplitude as in tapping, the time unit 1/ω₀, and every step resolves the lever's own
/// period (at least the numerics' steps per period of it).
pub(crate) fn simulation<'a>(
    p: &'a Prepared,
    modulation: &Modulation,
    separation_m: f64,
    steps_per_period: f64,
) -> Result<Simulation<'a, AnyLaw>> {
    let cant = &p.setup.cantilever;
    modulation.check(cant)?;
    let scale_m = cant.free_amplitude_m;
    if !(separation_m.is_finite() && separation_m.abs() <= 10.0 * modulation.amplitude_m + 1e-6) {
        return Err(Error::InvalidParameter {
            name: "rest separation",
            value: separation_m,
            reason: "must lie within ten modulation amplitudes of the sample",
        });
    }
    let mut sim = p.simulation();
    sim.osc.drive = Drive::Base {
        amplitude: modulation.amplitude_m / scale_m,
    };
    sim.osc.omega = modulation.frequency_hz / cant.resonance_hz;
    sim.cpl.a0 = separation_m / p.setup.contact.separation_scale_m();
    sim.tol.h_max = 2.0 * PI / steps_per_period;
    Ok(sim)
}

/// A settled cycle of off-resonance tapping on `setup` (its cantilever, contact and
/// law; the tapping drive unused) at rest separation `separation_m`, channels computed
/// by `analysis`.
pub fn cycle(
    setup: &TapSetup,
    numerics: &Numerics,
    modulation: &Modulation,
    analysis: &Analysis,
    separation_m: f64,
) -> Result<PeakForceCycle> {
    analysis.check()?;
    let p = Prepared::new(setup, numerics)?;
    let sim = simulation(&p, modulation, separation_m, numerics.min_steps_per_period)?;
    // One work budget for settling and recording alike.
    let (period, marched, samples, starts, sums) = budgeted(p.steady.max_steps, || {
        let (mut phase, period, marched) = settle(&sim)?;
        let cycles = period.unwrap_or(IRREGULAR_CYCLES);
        let mut recorder = Recorder::sampling(&p.law, sim.cpl, sim.osc, CURVE);
        let mut sums = (0.0, 0.0, 0.0, 0.0);
        let mut starts = Vec::with_capacity(cycles + 1);
        for _ in 0..cycles {
            sim.rewind(&mut phase);
            starts.push(recorder.samples.len());
            let c = sim.cycle(&mut phase, &mut recorder)?;
            if recorder.overflowed {
                return Err(Error::NotApplicable(format!(
                    "the settled motion's force curve needs more than {MAX_CURVE_SAMPLES} \
                     samples, the most tapsim records: raise the modulation frequency"
                )));
            }
            sums = (
                sums.0 + c.e_ts,
                sums.1 + c.e_damp,
                sums.2 + c.e_drive,
                sums.3 + c.delta_mechanical,
            );
        }
        starts.push(recorder.samples.len());
        Ok((period, marched, recorder.samples, starts, sums))
    })?;
    let cycles = period.unwrap_or(IRREGULAR_CYCLES);
    let cant = &p.setup.cantilever;
    let (k, l) = (cant.stiffness_n_m, cant.free_amplitude_m);
    let energy = k * l * l;
    let n = cycles as f64;
    let curve = force_points(&p, &sim, separation_m, &samples);
    let channels = starts
        .windows(2)
        .map(|w| analysis.channels(&curve[w[0]..w[1]], p.setup.contact.radius_m))
        .collect();
    let drive = sums.2;
    // The energy the books are kept on: the drive's work, or the work the contact
    // stores and gives back each cycle where that is more (a conservative contact,
    // whose drive work is the slow motion's damping alone).
    let exchanged = 0.5 * curve.windows(2).map(|w| work_on_tip(w).abs()).sum::<f64>() / n;
    let books = (drive / n * energy)
        .abs()
        .max(exchanged)
        .max(f64::MIN_POSITIVE);
    Ok(PeakForceCycle {
        separation_m,
        regime: period.map_or("irregular".into(), |n| format!("period-{n}")),
        settled_after: marched,
        cycles: channels,
        // (An elastic law's loss is the branch work functions' round-off: none.)
        contact_loss_j: if (sums.0 / n * energy).abs() < 1e-12 * books {
            0.0
        } else {
            sums.0 / n * energy
        },
        damping_loss_j: sums.1 / n * energy,
        drive_work_j: drive / n * energy,
        energy_balance_rel: ((drive - sums.0 - sums.1 - sums.3) * energy / books).abs(),
        curve,
    })
}

/// The least peak-force setpoint, N: below it the peak is lost in the free ringing.
pub const MIN_SETPOINT_N: f64 = 1e-12;

/// Refuse a peak-force setpoint no instrument holds (N).
pub fn check_setpoint(setpoint_n: f64) -> Result<()> {
    if (MIN_SETPOINT_N..=1e-5).contains(&setpoint_n) {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name: "peak-force setpoint",
            value: setpoint_n,
            reason: "must be 1 pN to 10 µN (instruments use 0.1–100 nN)",
        })
    }
}

/// The settled cycle whose peak force is `setpoint_n` (N): the rest separation solved
/// for directly (the peak force falls as the support is withdrawn; bracketed from where
/// the support's lowest point just reaches the sample, then regula falsi to 1e-4 nm),
/// what a peak-force feedback settles on.
pub fn at_setpoint(
    setup: &TapSetup,
    numerics: &Numerics,
    modulation: &Modulation,
    analysis: &Analysis,
    setpoint_n: f64,
) -> Result<PeakForceCycle> {
    check_setpoint(setpoint_n)?;
    modulation.check(&setup.cantilever)?;
    let peak = |z: f64| -> Result<f64> {
        let c = cycle(setup, numerics, modulation, analysis, z)?;
        Ok(c.cycles
            .iter()
            .map(|ch| ch.peak_force_n)
            .fold(f64::NEG_INFINITY, f64::max))
    };
    // Withdrawn until the peak is below the setpoint, pushed in until it is above.
    let top = modulation.amplitude_m + 2.0 * setup.contact.range_m;
    let mut hi = top;
    let mut f_hi = peak(hi)?;
    let mut depth = 1e-9;
    while f_hi >= setpoint_n {
        hi += depth;
        depth *= 2.0;
        if depth > modulation.amplitude_m {
            return Err(Error::NotApplicable(
                "the peak force stays above the setpoint however far the support is withdrawn"
                    .into(),
            ));
        }
        f_hi = peak(hi)?;
    }
    let mut lo = top - 1e-9;
    let mut depth = 1e-9;
    let mut f_lo = peak(lo)?;
    while f_lo < setpoint_n {
        depth *= 2.0;
        if depth > modulation.amplitude_m {
            return Err(Error::NotApplicable(format!(
                "a peak force of {:.4} nN is not reached with the support pushed {:.4} nm \
                 into the sample (the most this modulation allows; peak {:.4} nN there): \
                 lower the setpoint or raise the modulation amplitude",
                setpoint_n * 1e9,
                depth * 0.5e9,
                f_lo * 1e9
            )));
        }
        lo = top - depth;
        f_lo = peak(lo)?;
    }
    let mut failure = None;
    let z = crate::numeric::bracketed_root(
        "peak force at the setpoint",
        |z| match peak(z) {
            Ok(f) => f - setpoint_n,
            Err(e) => {
                failure.get_or_insert(e);
                f64::NAN
            }
        },
        lo,
        hi,
        1e-13,
    )?;
    if let Some(e) = failure {
        return Err(e);
    }
    let found = cycle(setup, numerics, modulation, analysis, z)?;
    // Where the motion changes across the bracket (a period doubling, say) the peak
    // force may jump over the setpoint: then no separation holds it.
    let held = found
        .cycles
        .iter()
        .map(|ch| ch.peak_force_n)
        .fold(f64::NEG_INFINITY, f64::max);
    if (held / setpoint_n - 1.0).abs() > 1e-3 {
        return Err(Error::NotApplicable(format!(
            "the peak force jumps across the setpoint {:.4} nN at z_c = {:.4} nm (to {:.4} nN \
             in {} motion): no rest separation holds it; try another setpoint",
            setpoint_n * 1e9,
            z * 1e9,
            held * 1e9,
            found.regime
        )));
    }
    Ok(found)
}

/// The peak-force feedback of an instrument: after each modulation cycle the rest
/// separation moves by `gain`·(F_peak − F_set)/k (k the lever's stiffness: the change of
/// deflection that would make up the error on a stiff sample), an integral controller
/// acting once a cycle as the instrument's does.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PeakForceFeedback {
    /// F_set, N.
    pub setpoint_n: f64,
    /// The controller's gain per cycle (0 < g ≤ 1; default 0.5).
    pub gain: f64,
}

/// One cycle of a feedback run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FeedbackCycle {
    /// The rest separation during the cycle, m.
    pub separation_m: f64,
    /// The cycle's peak force, N.
    pub peak_force_n: f64,
}

/// A feedback run: every cycle, and whether the loop settled.
#[derive(Debug, Clone, Serialize)]
pub struct FeedbackRun {
    /// Each modulation cycle in turn.
    pub cycles: Vec<FeedbackCycle>,
    /// Whether the peak force held the setpoint within 1e-3 and the separation moved by
    /// less than 1e-4 nm a cycle for the last 8 cycles.
    pub settled: bool,
}

/// The most cycles a feedback run marches.
pub const MAX_FEEDBACK_CYCLES: usize = 2000;

/// Run the peak-force feedback on `setup` from rest at `start_m` (the support's lowest
/// point just above the sample, say) until it settles or [`MAX_FEEDBACK_CYCLES`] pass.
pub fn feedback(
    setup: &TapSetup,
    numerics: &Numerics,
    modulation: &Modulation,
    loop_: &PeakForceFeedback,
    start_m: f64,
) -> Result<FeedbackRun> {
    check_setpoint(loop_.setpoint_n)?;
    if !(loop_.gain > 0.0 && loop_.gain <= 1.0) {
        return Err(Error::InvalidParameter {
            name: "feedback gain",
            value: loop_.gain,
            reason: "must be above 0 and at most 1 (per cycle)",
        });
    }
    let p = Prepared::new(setup, numerics)?;
    let mut sim = simulation(&p, modulation, start_m, numerics.min_steps_per_period)?;
    let cant = &p.setup.cantilever;
    let (k, l) = (cant.stiffness_n_m, cant.free_amplitude_m);
    let scale = p.setup.contact.separation_scale_m();
    let mut z = start_m;
    let mut phase = Phase::at_rest();
    let mut cycles = Vec::new();
    let mut quiet = 0;
    let limit = 10.0 * modulation.amplitude_m + 1e-6;
    budgeted(p.steady.max_steps.saturating_mul(4), || {
        for _ in 0..MAX_FEEDBACK_CYCLES {
            sim.cpl.a0 = z / scale;
            sim.rewind(&mut phase);
            let c = sim.cycle(&mut phase, &mut Ignore)?;
            let peak = c.max_force * k * l;
            cycles.push(FeedbackCycle {
                separation_m: z,
                peak_force_n: peak,
            });
            let step = loop_.gain * (peak - loop_.setpoint_n) / k;
            let held = (peak / loop_.setpoint_n - 1.0).abs() < 1e-3 && step.abs() < 1e-13;
            quiet = if held { quiet + 1 } else { 0 };
            if quiet >= QUIET_CYCLES {
                return Ok(true);
            }
            z += step;
            if z.abs() > limit {
                return Err(Error::NotApplicable(format!(
                    "the feedback withdrew the support beyond {:.4} nm without the peak \
                     force reaching the setpoint {:.4} nN: lower the setpoint or raise the \
                     modulation amplitude",
                    limit * 1e9,
                    loop_.setpoint_n * 1e9
                )));
            }
        }
        Ok(false)
    })
    .map(|settled| FeedbackRun { cycles, settled })
}
