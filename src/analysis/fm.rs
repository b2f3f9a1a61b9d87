//! Frequency-modulation AFM with settled loops: the state in which a phase-locked loop
//! holds the drive 90° ahead of the motion and an amplitude controller holds the
//! amplitude at its setpoint A, at a rest separation z_c. Two channels are read: the
//! frequency shift Δf = f − f₀ and the excitation, whose rise above its free value is
//! the energy the sample takes per cycle.
//!
//! The cantilever of the setup is driven by a force F cos(ωt + 90°) relative to its
//! motion's first harmonic; the loops settle where the orbit's amplitude is A (the
//! setup's free amplitude A₀: in FM the amplitude is held at its free value) and its
//! phase lag behind the drive is 90°. Those two conditions fix the two unknowns, the
//! drive frequency Ω = ω/ω₀ and the excitation F, which are found with the orbit itself
//! by Newton's method over one drive period ([`settle`]). The excitation is reported as
//! the ratio to its free value at the same
//! amplitude, F/F₀ with F₀ = kA/Q. Two closed forms follow from the first harmonic of
//! the equation of motion, and the tests check the orbit against both: with the drive
//! in quadrature, k(1 − Ω²)A²/2 = ⟨F_ts·q₁⟩ (q₁ the motion's first harmonic; to first
//! order Δf/f₀ = −⟨F_ts q⟩/(kA²), Giessibl, Phys. Rev. B 56, 16010, 1997), and the
//! energy balance, E_ts = (πkA²/Q)(F/F₀ − Ω) (Anczykowski, Gotsmann, Fuchs, Cleveland
//! & Elings, Appl. Surf. Sci. 140, 376, 1999), exact up to the damping of the higher
//! harmonics.
//!
//! The loops as they run in time, with their gains, are [`crate::instrument::fm`]; they
//! lock onto the state found here.

use crate::analysis::reconstruct::Inversion;
use crate::dynamics::march::{CycleIntegrals, Phase, Simulation};
use crate::dynamics::motion::{Motion, StdErr, SteadyState};
use crate::dynamics::numeric::Ignore;
use crate::dynamics::observables::TapObservables;
use crate::dynamics::observed::{Recorder, TrajectorySample};
use crate::dynamics::setup::{Numerics, Prepared, TapSetup};
use crate::dynamics::shooting::eigenvalues;
use crate::error::{Error, Result};
use crate::instrument::fm::{Engagement, FmDrive};
use crate::physics::law::{AnyLaw, ForceLaw};
use nalgebra::{DMatrix, DVector};
use serde::Serialize;
use std::f64::consts::PI;

/// The phase lag of the motion behind the drive the phase-locked loop holds, in degrees:
/// the free cantilever's at resonance.
pub const LOCKED_PHASE_DEG: f64 = 90.0;

/// The tolerance of the residuals: the orbit's return over one period (units of A), the
/// amplitude's relative error and the phase's error in radians.
const TOLERANCE: f64 = 1e-12;

/// Newton iterations before a point is given up.
const MAX_ITERATIONS: usize = 40;

/// The settled FM state at one rest separation.
#[derive(Debug, Clone, Serialize)]
pub struct FmState {
    /// Rest separation z_c in m.
    pub separation_m: f64,
    /// Frequency shift Δf = f − f₀ in Hz.
    pub frequency_shift_hz: f64,
    /// The drive frequency over the free resonance, Ω = f/f₀.
    pub frequency_ratio: f64,
    /// The excitation over its free value at the same amplitude, F/F₀ (1 far from the
    /// sample).
    pub excitation_ratio: f64,
    /// The energy the sample takes per cycle read from the excitation,
    /// (πkA²/Q)(F/F₀ − Ω), in J: what the dissipation channel reports.
    pub e_ts_from_excitation_j: f64,
    /// Newton iterations taken.
    pub iterations: usize,
    /// The orbit's observables (amplitude, phase, E_ts from the law, forces, …). Its
    /// Floquet multipliers are those of the orbit under a fixed drive (the loops'
    /// own dynamics are not in them).
    pub observables: TapObservables,
    /// Where the next point of an approach starts.
    #[serde(skip)]
    pub next: FmGuess,
}

impl FmState {
    /// The state as the instrument's loops take it up.
    pub fn engagement(&self) -> Engagement {
        Engagement {
            phase: self.next.phase.clone(),
            drive: FmDrive {
                omega: self.frequency_ratio,
                excitation: self.excitation_ratio,
            },
            separation_m: self.separation_m,
        }
    }
}

/// `p`'s experiment driven at Ω with the excitation ratio `excitation` (F/F₀, the
/// drive in units of kA being F/F₀/Q) rather than its own drive.
fn driven(p: &Prepared, omega: f64, excitation: f64) -> Simulation<'_, AnyLaw> {
    p.simulation_driven(omega, excitation / p.setup.cantilever.quality)
}

/// The whole of `p` so driven (its setup's drive frequency too), for what reads the
/// setup: the observables, a recorded trajectory.
fn driven_prepared(p: &Prepared, omega: f64, excitation: f64) -> Prepared {
    let sim = driven(p, omega, excitation);
    let (osc, tol) = (sim.osc, sim.tol);
    let mut at = p.clone();
    at.osc = osc;
    at.tol = tol;
    at.setup.cantilever.drive_frequency_hz = omega * at.setup.cantilever.resonance_hz;
    at
}

/// One drive period from the state (x, x') at drive phase 0 (the rest of the state,
/// the branch, from `start`), at the unknowns `u` = (x, x', Ω, ln F/F₀): the residuals of
/// the FM orbit (the return (Δx, Δx'), the amplitude's relative error, the phase's error
/// in radians), the period's integrals and the state at its end.
fn residuals(
    p: &Prepared,
    u: [f64; 4],
    start: &Phase,
) -> Result<([f64; 4], CycleIntegrals, Phase)> {
    let sim = driven(p, u[2], u[3].exp());
    let mut phase = Phase {
        tau: 0.0,
        x: u[0],
        v: u[1],
        ..start.clone()
    };
    let c = sim.cycle(&mut phase, &mut Ignore)?;
    phase.tau = 0.0;
    Ok((
        [
            phase.x - u[0],
            phase.v - u[1],
            c.amplitude() - 1.0,
            c.phase() - LOCKED_PHASE_DEG.to_radians(),
        ],
        c,
        phase,
    ))
}

/// Where the loops settle at `setup`'s rest separation, holding the amplitude at the
/// setup's free amplitude A₀ and the drive 90° ahead, from the guess `guess` (the last
/// point's on an approach, [`FmGuess::free`] far from the sample).
///
/// The FM orbit is found directly, as a periodic orbit of the drive period with the two
/// loop conditions, by Newton's method on (x, x', Ω, ln F/F₀) at drive phase 0 (the
/// Jacobian by differences, four periods an iteration): under a fixed drive the same
/// orbit may be unstable (where the attraction bends the resonance), which the loops
/// stabilise; a search through the fixed-drive steady state would fall off it. Refuses
/// a point where Newton's method does not meet the tolerance (an orbit that grazes a
/// switch, or none near the guess).
pub fn settle(setup: &TapSetup, numerics: &Numerics, guess: &FmGuess) -> Result<FmState> {
    let amplitude_m = setup.cantilever.free_amplitude_m;
    let mut u = [
        guess.phase.x,
        guess.phase.v,
        guess.omega,
        guess.excitation.ln(),
    ];
    let mut start = guess.phase.clone();
    let p = Prepared::new(setup, numerics)?;
    let (mut r, mut c, mut end) = residuals(&p, u, &start)?;
    for iteration in 0..MAX_ITERATIONS {
        if r.iter().all(|e| e.abs() < TOLERANCE) {
            let (omega, excitation) = (u[2], u[3].exp());
            let settled = driven_prepared(&p, omega, excitation);
            let mut at = Phase {
                tau: 0.0,
                x: u[0],
                v: u[1],
                ..start
            };
            // ∂z(T)/∂(z, q): the monodromy is its square part.
            let (_, derivative) = settled.simulation().cycle_with_derivative(&mut at)?;
            let monodromy = derivative.columns(0, derivative.nrows()).into_owned();
            let state = SteadyState {
                window: c,
                cycles: iteration + 1,
                converged: true,
                motion: Motion::Periodic {
                    period: 1,
                    multipliers: eigenvalues(&monodromy),
                },
                std_err: StdErr::default(),
            };
            let observables = TapObservables::new(&settled, &state)?;
            let cant = &setup.cantilever;
            return Ok(FmState {
                separation_m: setup.separation_m,
                frequency_shift_hz: (omega - 1.0) * cant.resonance_hz,
                frequency_ratio: omega,
                excitation_ratio: excitation,
                e_ts_from_excitation_j: PI * cant.stiffness_n_m * amplitude_m * amplitude_m
                    / cant.quality
                    * (excitation - omega),
                iterations: iteration,
                observables,
                next: FmGuess {
                    phase: end,
                    omega,
                    excitation,
                },
            });
        }
        // The Jacobian by forward differences.
        let steps = [1e-7, 1e-7, 1e-8, 1e-7];
        let mut jacobian = DMatrix::<f64>::zeros(4, 4);
        for (k, h) in steps.into_iter().enumerate() {
            let mut uk = u;
            uk[k] += h;
            let (rk, _, _) = residuals(&p, uk, &start)?;
            for i in 0..4 {
                jacobian[(i, k)] = (rk[i] - r[i]) / h;
            }
        }
        let Some(du) = jacobian.lu().solve(&DVector::from_row_slice(&r)) else {
            break;
        };
        // Steps no larger than the resonance's width in Ω, a factor 2 in the excitation
        // and a fifth of the amplitude in the state.
        let width = 1.0 / setup.cantilever.quality;
        let scale = (du[2].abs() / width)
            .max(du[3].abs() / 2f64.ln())
            .max(du[0].hypot(du[1]) / 0.2)
            .max(1.0);
        for k in 0..4 {
            u[k] -= du[k] / scale;
        }
        start = end;
        (r, c, end) = residuals(&p, u, &start)?;
    }
    Err(Error::NotApplicable(format!(
        "at z_c = {:.4} nm the loops did not settle in {MAX_ITERATIONS} iterations (return \
         {:.2e}, amplitude error {:.2e}, phase error {:.2e} rad): the orbit there may graze a \
         switch",
        setup.separation_m * 1e9,
        r[0].hypot(r[1]),
        r[2],
        r[3]
    )))
}

/// Where a search for the settled FM state starts: an orbit's state at drive phase 0
/// and the loops' (Ω, F/F₀).
#[derive(Debug, Clone)]
pub struct FmGuess {
    /// The state (x, x' in units of A, the branch).
    pub phase: Phase,
    /// Ω.
    pub omega: f64,
    /// F/F₀.
    pub excitation: f64,
}

impl FmGuess {
    /// The free cantilever's orbit at resonance (far from the sample). Refuses a relaxing
    /// sample, whose surface's memory the search does not carry.
    pub fn free(setup: &TapSetup, numerics: &Numerics) -> Result<Self> {
        let p = Prepared::new(setup, numerics)?;
        if p.law.has_surface() {
            return Err(Error::OutOfRange(
                "FM with a relaxing sample (whose surface remembers the last tap) is not supported yet"
                    .into(),
            ));
        }
        Ok(Self {
            phase: driven(&p, 1.0, 1.0).free_steady_start(),
            omega: 1.0,
            excitation: 1.0,
        })
    }
}

/// One drive period of the settled FM orbit `state` of `setup`, recorded (SI; time from
/// the period's start at drive phase 0).
pub fn trajectory(
    setup: &TapSetup,
    numerics: &Numerics,
    state: &FmState,
) -> Result<Vec<TrajectorySample>> {
    let p = driven_prepared(
        &Prepared::new(setup, numerics)?,
        state.frequency_ratio,
        state.excitation_ratio,
    );
    let mut recorder = Recorder::new(&p.law, p.cpl, p.osc);
    let mut phase = state.next.phase.clone();
    p.simulation().cycle(&mut phase, &mut recorder)?;
    Ok(recorder.to_si(&p))
}

/// One point of an FM approach: the settled state, or why there is none.
#[derive(Debug, Clone, Serialize)]
pub struct FmPoint {
    /// Rest separation z_c in m.
    pub separation_m: f64,
    /// The settled state (none where the loops find no stable period-1 orbit or do not
    /// settle).
    pub state: Option<FmState>,
    /// Why there is no state.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// An FM approach: the settled state at each rest separation of `separations_m` in
/// turn, each from the last settled one's (Ω, F/F₀), the first from the free
/// cantilever's. A point where the loops do not settle is reported as such and the next
/// starts from the last that did. `progress` is called after each point.
pub fn approach(
    setup: &TapSetup,
    numerics: &Numerics,
    separations_m: &[f64],
    mut progress: impl FnMut(),
) -> Result<Vec<FmPoint>> {
    let mut guess = FmGuess::free(setup, numerics)?;
    let mut out = Vec::with_capacity(separations_m.len());
    for &z in separations_m {
        crate::interrupt::check()?;
        let at = TapSetup {
            separation_m: z,
            ..setup.clone()
        };
        let point = match settle(&at, numerics, &guess) {
            Ok(s) => {
                guess = s.next.clone();
                FmPoint {
                    separation_m: z,
                    state: Some(s),
                    note: None,
                }
            }
            Err(Error::NotApplicable(why)) => FmPoint {
                separation_m: z,
                state: None,
                note: Some(why),
            },
            Err(other) => return Err(other),
        };
        out.push(point);
        progress();
    }
    Ok(out)
}

/// The force at each closest distance D an FM approach's orbits reach, from their
/// frequency shifts: `inversion` (the Sader–Jarvis formula, Sader & Jarvis, APL 84,
/// 1801, 2004, or the first-order relation inverted exactly, Giessibl, APL 78, 123,
/// 2001; [`Inversion`]) of the shift the first harmonic's balance gives,
/// Ω_eff = (Ω² − 1)/2 = −⟨F_ts q₁⟩/(kA²) (to first order Δf/f₀), at the constant
/// amplitude A; D is each orbit's least separation. `states` in any order of z_c, each
/// a distinct D; returns (D in m, F in N, repulsive positive) by increasing D, the
/// force beyond the farthest point taken as zero.
pub fn force_from_shift(
    setup: &TapSetup,
    states: &[FmState],
    inversion: Inversion,
) -> Result<Vec<(f64, f64)>> {
    let mut points: Vec<(f64, f64)> = states
        .iter()
        .map(|s| {
            let w = s.frequency_ratio;
            (s.observables.min_separation_m, 0.5 * (w * w - 1.0))
        })
        .collect();
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    if points.len() < 3 || points.windows(2).any(|p| p[0].0 >= p[1].0) {
        return Err(Error::NotApplicable(
            "the inversion needs at least 3 orbits, each reaching a distance of its own".into(),
        ));
    }
    let closest: Vec<f64> = points.iter().map(|p| p.0).collect();
    let shift: Vec<f64> = points.iter().map(|p| p.1).collect();
    let amplitude = vec![setup.cantilever.free_amplitude_m; points.len()];
    let force = inversion.force(setup.cantilever.stiffness_n_m, &closest, &amplitude, &shift);
    Ok(closest.into_iter().zip(force).collect())
}

/// The settled state at which the frequency shift is `shift_hz`, as an FM instrument's z
/// feedback holds it: an approach from `from_m` toward `to_m` in `steps` steps (each
/// point from the last) until Δf first crosses the setpoint, then the secant method on
/// z_c between the two points that bracket it (each trial settled from the nearer one),
/// to 1e-9 of the setpoint's size in Hz. A setpoint the approach never reaches, or an
/// approach that loses the orbit before it, is refused with what was reached.
pub fn at_shift(
    setup: &TapSetup,
    numerics: &Numerics,
    shift_hz: f64,
    (from_m, to_m): (f64, f64),
    steps: usize,
) -> Result<FmState> {
    if !(shift_hz.is_finite() && shift_hz != 0.0) {
        return Err(Error::NotApplicable(format!(
            "a frequency-shift setpoint is a finite shift, not {shift_hz} Hz (zero is the \
             free cantilever, met anywhere far from the sample)"
        )));
    }
    let at = |z: f64| TapSetup {
        separation_m: z,
        ..setup.clone()
    };
    let mut last = settle(&at(from_m), numerics, &FmGuess::free(setup, numerics)?)?;
    let steps = steps.max(2);
    let mut reached = last.frequency_shift_hz;
    for i in 1..=steps {
        crate::interrupt::check()?;
        let z = from_m + (to_m - from_m) * i as f64 / steps as f64;
        let next = settle(&at(z), numerics, &last.next).map_err(|e| {
            Error::NotApplicable(format!(
                "the approach toward the setpoint {shift_hz} Hz lost the orbit at z_c = {:.4} \
                 nm, having reached {reached:.4} Hz: {e}",
                z * 1e9
            ))
        })?;
        reached = next.frequency_shift_hz;
        let (a, b) = (
            last.frequency_shift_hz - shift_hz,
            next.frequency_shift_hz - shift_hz,
        );
        if a * b <= 0.0 {
            // The secant method inside the bracket [last, next].
            let (mut lo, mut hi) = (last, next);
            for _ in 0..60 {
                let (flo, fhi) = (
                    lo.frequency_shift_hz - shift_hz,
                    hi.frequency_shift_hz - shift_hz,
                );
                if fhi.abs() <= 1e-9 * shift_hz.abs() {
                    return Ok(hi);
                }
                if flo.abs() <= 1e-9 * shift_hz.abs() {
                    return Ok(lo);
                }
                let t = (flo / (flo - fhi)).clamp(0.05, 0.95);
                let z = lo.separation_m + t * (hi.separation_m - lo.separation_m);
                let guess = if t < 0.5 { &lo.next } else { &hi.next };
                let trial = settle(&at(z), numerics, guess).map_err(|e| {
                    Error::NotApplicable(format!(
                        "the frequency shift jumps across the setpoint {shift_hz} Hz between \
                         z_c = {:.4} nm ({:.4} Hz) and {:.4} nm ({:.4} Hz), and no settled \
                         orbit holds it in between ({e}): the loops cannot hold this setpoint",
                        lo.separation_m * 1e9,
                        lo.frequency_shift_hz,
                        hi.separation_m * 1e9,
                        hi.frequency_shift_hz
                    ))
                })?;
                if (trial.frequency_shift_hz - shift_hz) * flo <= 0.0 {
                    hi = trial;
                } else {
                    lo = trial;
                }
            }
            return Err(Error::NotApplicable(format!(
                "the frequency shift did not settle on the setpoint {shift_hz} Hz between \
                 z_c = {:.4} and {:.4} nm: it may jump there (a switch grazed)",
                lo.separation_m * 1e9,
                hi.separation_m * 1e9
            )));
        }
        last = next;
    }
    Err(Error::NotApplicable(format!(
        "the setpoint {shift_hz} Hz is not reached between z_c = {:.4} and {:.4} nm (the \
         shift there: {reached:.4} Hz)",
        from_m * 1e9,
        to_m * 1e9
    )))
}

/// Where an FM image engages over `setup`'s material: the settled state at the
/// frequency shift `shift_hz` ([`at_shift`] from `range` in `steps` steps), as the
/// instrument's loops take it up ([`Engagement`]), and the slope ∂Δf/∂z_c there in
/// Hz/m, by the difference to a state settled 1e-3 A nearer the sample (on the way the
/// approach came: the side of the curve the feedback holds).
pub fn engagement(
    setup: &TapSetup,
    numerics: &Numerics,
    shift_hz: f64,
    range: (f64, f64),
    steps: usize,
) -> Result<(Engagement, f64)> {
    let state = at_shift(setup, numerics, shift_hz, range, steps)?;
    let dz = 1e-3 * setup.cantilever.free_amplitude_m * (range.0 - range.1).signum();
    let nearer = TapSetup {
        separation_m: state.separation_m - dz,
        ..setup.clone()
    };
    let next = settle(&nearer, numerics, &state.next)?;
    let slope = (state.frequency_shift_hz - next.frequency_shift_hz) / dz;
    Ok((state.engagement(), slope))
}
