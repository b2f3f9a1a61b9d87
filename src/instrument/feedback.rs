//! The z feedback of amplitude-modulation AFM: a PI controller that moves the rest
//! separation z_c (the z piezo) to hold the lock-in amplitude at the setpoint, and the
//! loop that runs it on the marched cantilever.
//!
//! Once per drive period the controller reads the lock-in's amplitude ratio A/A₀,
//! forms the error e = A/A₀ − setpoint and moves the sample by
//! Δz_c/A₀ = −(K_p·Δe + K_i·e) (the velocity form of u = K_p·e + K_i·Σe, per period):
//! too large an amplitude brings the sample closer. The piezo position z_c is what the
//! instrument records as topography.

use super::lockin::LockIn;
use super::probe::{OneMode, Probe};
use super::repeats::Repeats;
use super::thermal::ThermalForce;
use crate::dynamics::march::Phase;
use crate::dynamics::setup::Prepared;
use crate::error::{Error, Result};

/// The largest proportional gain K_p (A₀ per unit of A/A₀ error).
pub const MAX_PROPORTIONAL: f64 = 10.0;
/// The largest integral gain K_i (A₀ per unit of A/A₀ error and drive period).
pub const MAX_INTEGRAL: f64 = 1.0;

/// A PI controller on the amplitude error, in units of A₀ and drive periods. Its
/// proportional gain K_p is also the P gain of an instrument panel in SI (metres of z per
/// metre of amplitude error); [`Self::integral_gain_per_s`] gives the I gain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PiController {
    /// The amplitude setpoint A/A₀.
    pub setpoint: f64,
    /// Proportional gain K_p (A₀ of z_c per unit of A/A₀ error).
    pub proportional: f64,
    /// Integral gain K_i (A₀ of z_c per unit of A/A₀ error and drive period).
    pub integral: f64,
    /// The last error (for the velocity form).
    last_error: Option<f64>,
}

impl PiController {
    /// A controller holding `setpoint` (0 < A/A₀ < 1) with gains K_p, K_i ≥ 0 (not both
    /// zero).
    pub fn new(setpoint: f64, proportional: f64, integral: f64) -> Result<Self> {
        if !(setpoint > 0.0 && setpoint < 1.0) {
            return Err(Error::InvalidParameter {
                name: "amplitude setpoint A/A0",
                value: setpoint,
                reason: "the amplitude of a tip that touches lies between 0 and A₀",
            });
        }
        for (name, g, most) in [
            ("proportional gain", proportional, MAX_PROPORTIONAL),
            ("integral gain", integral, MAX_INTEGRAL),
        ] {
            if !(g >= 0.0 && g <= most) {
                return Err(Error::InvalidParameter {
                    name,
                    value: g,
                    reason: "a gain lies from 0 to its most (10 for K_p, 1 for K_i): a \
                             loop that moves the sample by A₀ and more per period on a \
                             small error only throws the tip about",
                });
            }
        }
        if proportional == 0.0 && integral == 0.0 {
            return Err(Error::NotApplicable(
                "a controller with both gains zero does not move the sample".into(),
            ));
        }
        Ok(Self {
            setpoint,
            proportional,
            integral,
            last_error: None,
        })
    }

    /// The integral gain as an instrument panel in SI units shows it, s⁻¹: metres of z
    /// per metre of amplitude error and second (Nanonis' "I gain" on an amplitude
    /// signal). The controller moves z_c by K_i·A₀·e a drive period for an error e in
    /// units of A₀, so the rate per metre of error is K_i·f_drive — a change of units,
    /// not an approximation.
    pub fn integral_gain_per_s(&self, drive_hz: f64) -> f64 {
        self.integral * drive_hz
    }

    /// The integral time T_i = K_p/(K_i·f_drive), s: the "time constant" an instrument
    /// panel shows beside a P gain (u = K_p·(e + ∫e dt/T_i)); `None` where either gain
    /// is zero.
    pub fn integral_time_s(&self, drive_hz: f64) -> Option<f64> {
        (self.proportional > 0.0 && self.integral > 0.0)
            .then(|| self.proportional / self.integral_gain_per_s(drive_hz))
    }

    /// The move of the rest separation (in units of A₀) after a period whose lock-in
    /// amplitude ratio was `amplitude_ratio`, and the error it acted on.
    pub fn update(&mut self, amplitude_ratio: f64) -> (f64, f64) {
        let e = amplitude_ratio - self.setpoint;
        let de = self.last_error.map_or(0.0, |last| e - last);
        self.last_error = Some(e);
        (-(self.proportional * de + self.integral * e), e)
    }
}

/// One drive period of the loop: where the piezo was and what the lock-in read.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct LoopSample {
    /// The rest separation z_c during the period, in m (the topography signal).
    pub separation_m: f64,
    /// The lock-in amplitude at its end, A/A₀.
    pub amplitude_ratio: f64,
    /// The lock-in phase at its end, degrees.
    pub phase_deg: f64,
    /// The amplitude error A/A₀ − setpoint.
    pub error: f64,
}

/// Run the z feedback on `p` for `periods` drive periods from the oscillator state
/// `phase` at rest separation `start_m` (the free oscillation, say), read by `lockin`,
/// under `force` (the thermal force, [`ThermalForce::none`] for none): [`hold_probe`]
/// with the point mass. `phase` is left at the end.
pub fn hold(
    p: &Prepared,
    (start_m, phase): (f64, &mut Phase),
    lockin: &mut LockIn,
    controller: &mut PiController,
    force: &mut ThermalForce,
    periods: usize,
) -> Result<(Vec<LoopSample>, f64)> {
    let mut probe = OneMode {
        materials: std::slice::from_ref(p),
        phase,
        lockin,
        force,
    };
    hold_probe(
        &mut probe,
        0,
        start_m,
        (controller, &mut Repeats::exact()),
        periods,
    )
}

/// Run the z feedback on `probe` over its material `material` for `periods` drive
/// periods from rest separation `start_m`: the lock-ins first settle there with the
/// loop open ([`Probe::settling_periods`]), then each period is marched at the current
/// z_c and `controller` moves z_c on the first mode's amplitude — unless `repeats`
/// finds the loop repeating itself ([`Repeats`]): the whole cycles left are then the
/// last one's repeats ([`Repeats::exact`] marches every period). Returns every
/// closed-loop period's sample and the rest separation the loop has moved to.
pub fn hold_probe<P: Probe>(
    probe: &mut P,
    material: usize,
    start_m: f64,
    (controller, repeats): (&mut PiController, &mut Repeats),
    periods: usize,
) -> Result<(Vec<LoopSample>, f64)> {
    let a0 = probe.free_amplitude_m();
    let cycle = probe.cycle();
    let mut z = start_m;
    let settle = probe.settling_periods();
    probe.march(material, z, settle)?;
    repeats.restart();
    let mut out: Vec<LoopSample> = Vec::with_capacity(periods);
    while out.len() < periods {
        let (amplitude_ratio, phase_deg) = probe.march(material, z, 1)?[0];
        let (dz, error) = controller.update(amplitude_ratio);
        out.push(LoopSample {
            separation_m: z,
            amplitude_ratio,
            phase_deg,
            error,
        });
        z += dz * a0;
        if probe.repeats_itself(repeats, [z / a0, error]) && out.len() >= cycle {
            // The whole cycles left repeat the last.
            let last = out.len() - cycle;
            let left = (periods - out.len()) / cycle * cycle;
            for k in 0..left {
                out.push(out[last + k % cycle]);
                repeats.skip();
            }
        }
    }
    Ok((out, z))
}
