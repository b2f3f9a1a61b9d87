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
use crate::instrument::thermal::ThermalForce;
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
