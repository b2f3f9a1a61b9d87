//! The loops of FM-AFM as they run in time: a phase-locked loop that sets the drive
//! frequency so that the motion lags the drive by a set phase (90°: the cantilever
//! self-excited at its own, shifted resonance), and an amplitude controller that sets
//! the excitation so that the amplitude holds its setpoint. Both are values of their
//! own, updated once a drive period from that period's demodulated deflection (the
//! first harmonic over the period, the boxcar detector of a digital PLL clocked by its
//! own oscillator), and the cantilever is marched between updates by the existing
//! marcher with the loops' frequency and excitation. Each period starts at the drive's
//! phase 0, so a new frequency leaves the drive continuous.
//!
//! Units: frequencies as Ω = f/f₀, the amplitude in units of its setpoint A (the length
//! unit of the setup, its free amplitude), the excitation as F/F₀ with F₀ = kA/Q (the
//! free cantilever's at resonance). The settled state is
//! [`crate::analysis::fm::settle`]'s, which finds it directly.

use crate::dynamics::march::Phase;
use crate::dynamics::numeric::Ignore;
use crate::dynamics::setup::Prepared;
use crate::error::{Error, Result};
use crate::instrument::average::{AVERAGE_RECORDS, AverageRequest, settling_periods};
use crate::instrument::thermal::{STEPS_PER_PERIOD, ThermalForce, intensity_hat};
use serde::Serialize;

/// A PI loop: output = centre + K_p·e + K_i·Σe, e the error each period.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Pi {
    proportional: f64,
    integral: f64,
    sum: f64,
}

impl Pi {
    fn new(name: &'static str, proportional: f64, integral: f64) -> Result<Self> {
        for (what, g) in [("proportional", proportional), ("integral", integral)] {
            if !(g.is_finite() && g >= 0.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value: g,
                    reason: if what == "proportional" {
                        "its proportional gain must be finite and not negative"
                    } else {
                        "its integral gain must be finite and not negative"
                    },
                });
            }
        }
        if integral == 0.0 {
            return Err(Error::NotApplicable(format!(
                "the {name} needs an integral gain: without it the loop settles off its \
                 setpoint"
            )));
        }
        Ok(Self {
            proportional,
            integral,
            sum: 0.0,
        })
    }

    /// Preload the integral so that a zero error gives the correction `output`
    /// (bumpless engagement on a settled state).
    fn hold(&mut self, output: f64) {
        self.sum = output / self.integral;
    }

    /// The correction after a period with error `e`.
    fn update(&mut self, e: f64) -> f64 {
        self.sum += e;
        self.proportional * e + self.integral * self.sum
    }
}

/// The phase-locked loop: its PI filter turns the phase error (the motion's lag behind
/// the drive minus the set lag, in radians) into the drive frequency Ω.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseLockedLoop {
    /// The lag it holds, in radians (π/2).
    pub locked_lag_rad: f64,
    /// The centre frequency Ω_c, from which the filter's output moves it.
    pub centre: f64,
    filter: Pi,
}

impl PhaseLockedLoop {
    /// A PLL holding a lag of 90° about the free resonance, with gains K_p (Ω per
    /// radian of error) and K_i (Ω per radian and period).
    pub fn new(proportional: f64, integral: f64) -> Result<Self> {
        Ok(Self {
            locked_lag_rad: std::f64::consts::FRAC_PI_2,
            centre: 1.0,
            filter: Pi::new("phase-locked loop", proportional, integral)?,
        })
    }

    /// Gains that lock on a cantilever of quality factor Q: the free lever's phase
    /// turns by 2Q radians per unit of Ω (near resonance) and follows a change in
    /// Q/π periods, so K_p = 1/Q (a loop gain of 2) and K_i = 8/Q² (an integral time of
    /// Q/8 periods). Tried on the defaults (Q = 400) with the amplitude controller's
    /// [`AmplitudeController::for_quality`]: from the free oscillation onto the hybrid
    /// contact at 19 nm the loops settle to 1e-9 within 2 000 periods; a quarter of
    /// these gains takes 5 000.
    pub fn for_quality(quality: f64) -> Result<Self> {
        Self::new(1.0 / quality, 8.0 / (quality * quality))
    }

    /// Hold the drive frequency Ω while the lag is the set one: the loop engaged on a
    /// state already settled there.
    pub fn hold(&mut self, omega: f64) {
        self.filter.hold(self.centre - omega);
    }

    /// The drive frequency Ω after a period in which the motion lagged the drive by
    /// `lag_rad`: a lag beyond the set one means the drive is above the resonance.
    pub fn update(&mut self, lag_rad: f64) -> f64 {
        self.centre - self.filter.update(lag_rad - self.locked_lag_rad)
    }
}

/// The amplitude controller: its PI filter turns the amplitude error (A/A_set − 1) into
/// the excitation F/F₀.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AmplitudeController {
    filter: Pi,
}

impl AmplitudeController {
    /// A controller with gains K_p (F/F₀ per unit of relative amplitude error) and K_i
    /// (the same per period), starting from the free excitation F/F₀ = 1.
    pub fn new(proportional: f64, integral: f64) -> Result<Self> {
        Ok(Self {
            filter: Pi::new("amplitude controller", proportional, integral)?,
        })
    }

    /// Gains that hold the amplitude on a cantilever of quality factor Q: the amplitude
    /// follows the excitation with unit gain and a time constant of Q/π periods, so
    /// K_p = 2 and K_i = 16/Q (an integral time of Q/8 periods; tried as the PLL's
    /// [`PhaseLockedLoop::for_quality`] says).
    pub fn for_quality(quality: f64) -> Result<Self> {
        Self::new(2.0, 16.0 / quality)
    }

    /// Hold the excitation F/F₀ while the amplitude is at its setpoint: the loop
    /// engaged on a state already settled there.
    pub fn hold(&mut self, excitation: f64) {
        self.filter.hold(1.0 - excitation);
    }

    /// The excitation F/F₀ after a period whose amplitude was `amplitude` (units of
    /// the setpoint).
    pub fn update(&mut self, amplitude: f64) -> f64 {
        1.0 - self.filter.update(amplitude - 1.0)
    }
}

/// One drive period of the loops.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FmSample {
    /// The rest separation z_c over the period, in m.
    pub separation_m: f64,
    /// The drive frequency over the period, Ω.
    pub frequency_ratio: f64,
    /// The excitation over the period, F/F₀.
    pub excitation_ratio: f64,
    /// The amplitude demodulated over the period, in units of the setpoint.
    pub amplitude: f64,
    /// The motion's lag behind the drive over the period, in degrees.
    pub phase_deg: f64,
}

impl FmSample {
    /// The energy the dissipation channel reads per cycle in units of the free
    /// cantilever's loss πkA²/Q: F/F₀ − Ω (Anczykowski et al. 1999), from the
    /// excitation and frequency of this period, as an instrument reads it whether or not
    /// its loops have settled.
    pub fn dissipation_read(&self) -> f64 {
        self.excitation_ratio - self.frequency_ratio
    }
}

/// Where the loops are engaged: a settled FM state (the one
/// [`crate::analysis::fm::settle`] finds), taken up without a bump.
#[derive(Debug, Clone)]
pub struct Engagement {
    /// The lever's state at a drive period's start.
    pub phase: Phase,
    /// The drive frequency Ω and excitation F/F₀ the loops hold there.
    pub drive: FmDrive,
    /// The rest separation z_c there, m (a scan's piezo sits at z_c plus the surface
    /// height).
    pub separation_m: f64,
}

/// What the FM channels read under the thermal force, averaged: means over
/// [`AVERAGE_RECORDS`] independent records and their standard errors from the records'
/// spread.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FmAverage {
    /// Temperature, K.
    pub temperature_k: f64,
    /// Drive periods averaged (after settling), over all records.
    pub periods: usize,
    /// Independent records (each its own settling and stream).
    pub records: usize,
    /// The mean frequency shift, Hz.
    pub frequency_shift_hz: f64,
    /// Its standard error, Hz.
    pub frequency_shift_std_err_hz: f64,
    /// The mean excitation over its free value, F/F₀.
    pub excitation_ratio: f64,
    /// Its standard error.
    pub excitation_ratio_std_err: f64,
    /// The mean energy per cycle the dissipation channel reads, (πkA²/Q)(F/F₀ − Ω), J.
    pub e_ts_from_excitation_j: f64,
    /// Its standard error, J.
    pub e_ts_std_err_j: f64,
    /// The seed whose streams the records drew.
    pub seed: u64,
}

/// The FM channels of `p`'s cantilever under the thermal force at the request's
/// temperature, the loops (tuned to its Q: [`PhaseLockedLoop::for_quality`],
/// [`AmplitudeController::for_quality`]) engaged on the settled state `at` at `p`'s
/// rest separation: [`AVERAGE_RECORDS`] records (streams 0, 1, … of the seed, marched in
/// parallel: the same result on any thread count), each ten decay times (10 Q/π
/// periods) of settling under the force and then its share of the periods; each record's
/// mean Δf, F/F₀ and dissipation read; their means and standard errors. At 0 K every
/// record holds the settled state.
pub fn thermal_average(
    p: &Prepared,
    at: &Engagement,
    request: &AverageRequest,
) -> Result<FmAverage> {
    use rayon::prelude::*;
    let c = p.setup.cantilever;
    request.check(c.quality)?;
    let per_record = request.periods / AVERAGE_RECORDS;
    let intensity = intensity_hat(
        request.temperature_k,
        c.stiffness_n_m,
        c.quality,
        c.free_amplitude_m,
    );
    let settle = settling_periods(c.quality);
    let loss_unit_j =
        std::f64::consts::PI * c.stiffness_n_m * c.free_amplitude_m.powi(2) / c.quality;
    let records: Vec<[f64; 3]> = (0..AVERAGE_RECORDS)
        .into_par_iter()
        .map(|stream| -> Result<[f64; 3]> {
            let mut force =
                ThermalForce::new(intensity, STEPS_PER_PERIOD, request.seed, stream as u64)?;
            let (mut pll, mut agc) = (
                PhaseLockedLoop::for_quality(c.quality)?,
                AmplitudeController::for_quality(c.quality)?,
            );
            pll.hold(at.drive.omega);
            agc.hold(at.drive.excitation);
            let (mut phase, mut drive) = (at.phase.clone(), at.drive);
            let mut loops: Loops = (&mut pll, &mut agc, &mut force);
            let mut sum = [0.0; 3];
            for i in 0..settle + per_record {
                let s = period(
                    p,
                    &mut phase,
                    &mut loops,
                    &mut drive,
                    (p.setup.separation_m, i + 1),
                )?;
                if i >= settle {
                    sum[0] += (s.frequency_ratio - 1.0) * c.resonance_hz;
                    sum[1] += s.excitation_ratio;
                    sum[2] += s.dissipation_read() * loss_unit_j;
                }
            }
            Ok(sum.map(|v| v / per_record as f64))
        })
        .collect::<Result<_>>()?;
    let n = records.len() as f64;
    let stat = |i: usize| {
        let (m, var) = crate::numeric::mean_and_variance(records.iter().map(|b| b[i]));
        (m, (var / n).sqrt())
    };
    let ((df, df_se), (x, x_se), (e, e_se)) = (stat(0), stat(1), stat(2));
    Ok(FmAverage {
        temperature_k: request.temperature_k,
        periods: per_record * AVERAGE_RECORDS,
        records: AVERAGE_RECORDS,
        frequency_shift_hz: df,
        frequency_shift_std_err_hz: df_se,
        excitation_ratio: x,
        excitation_ratio_std_err: x_se,
        e_ts_from_excitation_j: e,
        e_ts_std_err_j: e_se,
        seed: request.seed,
    })
}

/// The loops and the thermal force they run under ([`ThermalForce::none`] for none).
pub type Loops<'a> = (
    &'a mut PhaseLockedLoop,
    &'a mut AmplitudeController,
    &'a mut ThermalForce,
);

/// March `p`'s cantilever (its length unit the amplitude setpoint) for `periods` drive
/// periods at its rest separation under the two loops and the thermal force, from the
/// state `phase` at a drive period's start, driven at first at the PLL's centre with
/// the free excitation. Every period's sample; `phase` is left at the end.
pub fn run(p: &Prepared, phase: &mut Phase, loops: Loops, periods: usize) -> Result<Vec<FmSample>> {
    let z = vec![p.setup.separation_m; periods];
    run_along(p, phase, loops, &z)
}

/// [`run`] with the rest separation moved to `separations_m[i]` (m) for period i: an
/// approach or a scan under the loops, one period per entry.
pub fn run_along(
    p: &Prepared,
    phase: &mut Phase,
    mut loops: Loops,
    separations_m: &[f64],
) -> Result<Vec<FmSample>> {
    let mut drive = FmDrive {
        omega: loops.0.centre,
        excitation: 1.0,
    };
    let mut out = Vec::with_capacity(separations_m.len());
    for (i, &z) in separations_m.iter().enumerate() {
        let sample = period(p, phase, &mut loops, &mut drive, (z, i + 1)).map_err(|e| match e {
            Error::NotApplicable(why) if why.contains("lost lock") => Error::NotApplicable(format!(
                "{why}: its centre frequency is too far from the cantilever's resonance for its \
                 gains to capture (or its gains are unstable on this cantilever): set the \
                 centre to the free resonance"
            )),
            other => other,
        })?;
        out.push(sample);
    }
    Ok(out)
}

/// What the loops drive the cantilever with over a period: the frequency Ω and the
/// excitation F/F₀.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FmDrive {
    /// Ω = f/f₀.
    pub omega: f64,
    /// F/F₀.
    pub excitation: f64,
}

/// One drive period of `p`'s cantilever at rest separation `separation_m` (m) under
/// `drive`, from the state `phase` at the period's start (left at its end), then the
/// loops' update of `drive` for the next; `number` counts the periods for messages.
/// The period's sample. Refuses where the loops lose the cantilever: no amplitude left,
/// a lag outside (0°, 180°) (the lock lost), or a drive run away.
pub fn period(
    p: &Prepared,
    phase: &mut Phase,
    (pll, amplitude, force): &mut Loops,
    drive: &mut FmDrive,
    (separation_m, number): (f64, usize),
) -> Result<FmSample> {
    crate::interrupt::check()?;
    let FmDrive { omega, excitation } = *drive;
    let quality = p.setup.cantilever.quality;
    let mut sim = p.simulation_driven(omega, excitation / quality);
    sim.cpl.a0 = separation_m / p.setup.contact.separation_scale_m();
    phase.tau = 0.0;
    let (c, _) = force.march(&sim, phase, 1, &mut Ignore)?;
    let c = c.expect("one period marched");
    phase.tau = 0.0;
    let (a, lag) = (c.amplitude(), c.phase());
    if !(a.is_finite() && lag.is_finite() && a > 0.0) {
        return Err(Error::NotApplicable(
            "the loops lost the cantilever (no amplitude left to lock on): their gains are \
             too high for it"
                .into(),
        ));
    }
    // The lock detector: a lag outside (0°, 180°) is a drive on the wrong side of the
    // resonance by more than the phase detector can tell, and what the loop then reads
    // is no frequency of the cantilever's.
    if !(lag > 0.0 && lag < std::f64::consts::PI) {
        return Err(Error::NotApplicable(format!(
            "the PLL lost lock in period {number} (the motion lagged the drive by {:.1}° at \
             Ω = {omega:.5}, centre {:.5})",
            lag.to_degrees(),
            pll.centre
        )));
    }
    let sample = FmSample {
        separation_m,
        frequency_ratio: omega,
        excitation_ratio: excitation,
        amplitude: a,
        phase_deg: lag.to_degrees(),
    };
    *drive = FmDrive {
        omega: pll.update(lag),
        excitation: amplitude.update(a),
    };
    if !(drive.omega > 0.5 && drive.omega < 2.0 && drive.excitation > 0.0 && drive.excitation < 1e3)
    {
        return Err(Error::NotApplicable(format!(
            "the loops ran away (Ω = {:.4}, F/F₀ = {:.4}): their gains make them unstable on \
             this cantilever",
            drive.omega, drive.excitation
        )));
    }
    Ok(sample)
}
