//! FM-AFM imaging: the phase-locked loop and the amplitude controller of
//! [`super::fm`] running every drive period, and a z feedback that moves the piezo to
//! hold the frequency shift Δf at a setpoint, while the tip is carried along the line
//! over the sample's regions ([`super::scan::Region`]: a material and a surface height
//! each). Per pixel the topography (the piezo position), the frequency shift and its
//! error, the excitation and the energy per cycle the dissipation channel reads from it,
//! (πkA²/Q)(F/F₀ − Ω) (Anczykowski et al., Appl. Surf. Sci. 140, 376, 1999), each the
//! mean over the pixel's drive periods.
//!
//! Each period is marched at the material and height under the tip at its start, at
//! the loops' frequency and excitation, the lever's state carried across boundaries.
//! Every period advances the tip by the same step (the line's length over its periods
//! at f₀; the drive's own period differs from 1/f₀ by Δf/f₀, below 1 % here). Once the
//! whole loop — the lever's state, Ω, F/F₀ and the piezo — repeats itself over a region
//! ([`Repeats`]: within 1e-7 A of its fixed point, the frequency shift within 0.1 µHz),
//! the periods up to the next region are the last one's repeats ([`FmScanner::exact`]
//! marches every one).

use super::fm::{AmplitudeController, Engagement, FmDrive, Loops, PhaseLockedLoop, period};
use super::repeats::{DEFAULT_TOLERANCE, LoopState, Repeats, STATE_LEN};
use super::scan::{Region, check_regions, stretch_end};
use super::thermal::ThermalForce;
use crate::dynamics::march::Phase;
use crate::dynamics::setup::Prepared;
use crate::error::{Error, Result};
use crate::physics::law::ForceLaw;
use serde::{Deserialize, Serialize};

/// The unit in which [`Repeats`] sees the frequency shift: its tolerance (1e-7 of a
/// unit) is then 0.1 µHz, far below a frequency shift any PLL resolves.
const SHIFT_UNIT_HZ: f64 = 3.0;

/// What is recorded over one pixel: means over its drive periods.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FmPixel {
    /// The pixel's centre, m.
    pub x_m: f64,
    /// The z piezo position (topography), m.
    pub topography_m: f64,
    /// The frequency shift Δf = f − f₀, Hz.
    pub frequency_shift_hz: f64,
    /// Its error against the setpoint, Hz (0 where below 1e-9 of the setpoint: a loop
    /// that holds).
    pub error_hz: f64,
    /// The excitation over its free value, F/F₀.
    pub excitation_ratio: f64,
    /// The energy per cycle the dissipation channel reads, (πkA²/Q)(F/F₀ − Ω), J.
    pub dissipation_j: f64,
    /// The amplitude over its setpoint (1 where the amplitude controller holds).
    pub amplitude_ratio: f64,
}

/// The z feedback of FM-AFM: an integral controller on the frequency shift, moving the
/// piezo by −g·(Δf − Δf_set) each drive period.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ShiftFeedback {
    /// The frequency-shift setpoint Δf_set, Hz.
    pub setpoint_hz: f64,
    /// The gain g, m of piezo per Hz of error and drive period: positive where Δf rises
    /// with z at the setpoint (the attractive side of the Δf(z) curve), negative where
    /// it falls (the repulsive side).
    pub gain_m_per_hz: f64,
    /// The time constant it was set for, in drive periods.
    pub time_constant_periods: f64,
}

impl ShiftFeedback {
    /// The feedback whose error decays by e each `periods` drive periods on a Δf(z) of
    /// slope `slope_hz_per_m` at the setpoint: g = 1/(periods · slope) (a first-order
    /// loop: each period removes 1/periods of the error).
    pub fn with_time_constant(setpoint_hz: f64, slope_hz_per_m: f64, periods: f64) -> Result<Self> {
        if !(setpoint_hz.is_finite() && setpoint_hz != 0.0) {
            return Err(Error::NotApplicable(format!(
                "a frequency-shift setpoint is a finite shift, not {setpoint_hz} Hz (zero is \
                 the free cantilever, met anywhere far from the sample)"
            )));
        }
        if !(periods.is_finite() && periods >= 1.0) {
            return Err(Error::InvalidParameter {
                name: "z feedback time constant",
                value: periods,
                reason: "at least one drive period: the loop moves the piezo once a period",
            });
        }
        if !(slope_hz_per_m.is_finite() && slope_hz_per_m != 0.0) {
            return Err(Error::NotApplicable(format!(
                "the frequency shift does not change with z at the setpoint {setpoint_hz} Hz \
                 (slope {slope_hz_per_m:e} Hz/m): no feedback can hold it"
            )));
        }
        Ok(Self {
            setpoint_hz,
            gain_m_per_hz: 1.0 / (periods * slope_hz_per_m),
            time_constant_periods: periods,
        })
    }

    /// The integral gain as an instrument panel shows it, m/(Hz·s): g times the drive
    /// frequency (a change of units).
    pub fn integral_gain_m_per_hz_s(&self, drive_hz: f64) -> f64 {
        self.gain_m_per_hz * drive_hz
    }
}

/// The FM loops and the z feedback marching over a sample's materials.
pub struct FmScanner<'a> {
    materials: &'a [Prepared],
    pll: PhaseLockedLoop,
    agc: AmplitudeController,
    feedback: ShiftFeedback,
    drive: FmDrive,
    phase: Phase,
    /// The z piezo position, m.
    z_m: f64,
    repeats: Repeats,
    /// Periods marched so far (all lines), for messages.
    count: usize,
}

impl<'a> FmScanner<'a> {
    /// The loops over `materials` (all on one cantilever, none with a relaxing sample),
    /// the PLL and amplitude controller tuned to its quality factor
    /// ([`PhaseLockedLoop::for_quality`], [`AmplitudeController::for_quality`]), the z
    /// feedback `feedback`. Not yet engaged. Periods are taken as repeats once the
    /// loops' ringing (damped oscillations of some Q periods: [`Repeats::within_blocks`]
    /// over blocks of twice the longer of Q and the z feedback's time constant) has died
    /// down to the tolerance.
    pub fn new(materials: &'a [Prepared], feedback: ShiftFeedback) -> Result<Self> {
        let Some(first) = materials.first() else {
            return Err(Error::NotApplicable(
                "an FM scan needs at least one material".into(),
            ));
        };
        if materials.iter().any(|p| p.law.has_surface()) {
            return Err(Error::OutOfRange(
                "FM with a relaxing sample (whose surface remembers the last tap) is not supported yet"
                    .into(),
            ));
        }
        let quality = first.setup.cantilever.quality;
        Ok(Self {
            materials,
            pll: PhaseLockedLoop::for_quality(quality)?,
            agc: AmplitudeController::for_quality(quality)?,
            feedback,
            drive: FmDrive {
                omega: 1.0,
                excitation: 1.0,
            },
            phase: Phase::at_rest(),
            z_m: f64::NAN,
            repeats: Repeats::within_blocks(
                DEFAULT_TOLERANCE,
                (2.0 * quality.max(feedback.time_constant_periods)).ceil() as usize,
            ),
            count: 0,
        })
    }

    /// March every period (no repeats taken).
    pub fn exact(mut self) -> Self {
        self.repeats = Repeats::exact();
        self
    }

    /// The z piezo position, m.
    pub fn z_m(&self) -> f64 {
        self.z_m
    }

    /// Periods marched and taken as repeats so far.
    pub fn periods(&self) -> (u64, u64) {
        (self.repeats.marched, self.repeats.skipped)
    }

    /// Engage the loops on the settled state `at` over a region of surface height
    /// `height_m`: the lever there, the PLL and the amplitude controller preloaded to
    /// hold its drive (a bumpless start).
    pub fn engage(&mut self, at: &Engagement, height_m: f64) {
        self.phase = at.phase.clone();
        self.drive = at.drive;
        self.pll.hold(at.drive.omega);
        self.agc.hold(at.drive.excitation);
        self.z_m = height_m + at.separation_m;
    }

    /// Scan a line of length `length_m` over `regions` in `pixels` pixels of
    /// `periods_per_pixel` drive periods each, from where the loops stand. `progress` is
    /// told each pixel done. Refuses where the loops lose the cantilever or the z
    /// feedback drives the rest position below the surface (the tip crashed: the loop
    /// passed the Δf(z) curve's turning point, where its sign turns).
    pub fn line(
        &mut self,
        regions: &[Region],
        (length_m, pixels, periods_per_pixel): (f64, usize, usize),
        mut progress: impl FnMut(usize),
    ) -> Result<Vec<FmPixel>> {
        check_regions(regions, self.materials.len())?;
        if pixels == 0 || periods_per_pixel == 0 {
            return Err(Error::NotApplicable(
                "a scan line needs at least one pixel of at least one drive period".into(),
            ));
        }
        if !self.z_m.is_finite() {
            return Err(Error::NotApplicable(
                "the FM loops scan only once engaged".into(),
            ));
        }
        let cant = self.materials[0].setup.cantilever;
        let (f0, a0) = (cant.resonance_hz, cant.free_amplitude_m);
        let loss_unit_j = std::f64::consts::PI * cant.stiffness_n_m * a0 * a0 / cant.quality;
        let total = pixels * periods_per_pixel;
        let step = length_m / total as f64;
        let set = self.feedback.setpoint_hz;
        let mut under = 0;
        let mut out = Vec::with_capacity(pixels);
        let mut sum = [0.0; 6];
        let mut last = [0.0; 6];
        let mut repeat_until = 0;
        let mut none = ThermalForce::none();
        self.repeats.restart();
        for g in 0..total {
            let x = step * g as f64;
            while under + 1 < regions.len() && x >= regions[under].until_m {
                under += 1;
                self.repeats.restart();
                repeat_until = 0;
            }
            let region = regions[under];
            if g < repeat_until {
                self.repeats.skip();
            } else {
                let p = &self.materials[region.material];
                let during = self.z_m;
                self.count += 1;
                let mut loops: Loops = (&mut self.pll, &mut self.agc, &mut none);
                let s = period(
                    p,
                    &mut self.phase,
                    &mut loops,
                    &mut self.drive,
                    (during - region.height_m, self.count),
                )
                .map_err(|e| match e {
                    Error::NotApplicable(why) => Error::NotApplicable(format!(
                        "the FM loops lost the cantilever at x = {:.2} nm (rest separation \
                         {:.4} nm): {why}. The surface changed faster than the loops \
                         follow: a step up that carries the tip past the turning point of \
                         Δf(z), which no z feedback meets in time (the loop's sign is wrong \
                         beyond it and runs the tip in), or a loop too slow for the scan; \
                         hold a setpoint nearer 0 Hz, a faster z loop (a shorter time constant) or \
                         scan slower",
                        x * 1e9,
                        (during - region.height_m) * 1e9,
                    )),
                    other => other,
                })?;
                let shift_hz = (s.frequency_ratio - 1.0) * f0;
                let error = shift_hz - set;
                self.z_m -= self.feedback.gain_m_per_hz * error;
                let rest = self.z_m - region.height_m;
                if !(rest >= 0.0 && rest.is_finite()) {
                    return Err(Error::NotApplicable(format!(
                        "the z feedback drove the tip into the sample at x = {:.2} nm (rest \
                         separation {:.4} nm): past the turning point of Δf(z) the loop's \
                         sign is wrong and it crashes; use a setpoint nearer 0 Hz, a slower \
                         loop (a longer time constant) or a slower scan",
                        x * 1e9,
                        rest * 1e9
                    )));
                }
                last = [
                    during,
                    shift_hz,
                    error,
                    s.excitation_ratio,
                    s.dissipation_read() * loss_unit_j,
                    s.amplitude,
                ];
                let state = self.loop_state(rest / a0);
                if self.repeats.settled(Some(&state), 1) {
                    repeat_until = stretch_end(regions, under, (step, total));
                }
            }
            for (s, v) in sum.iter_mut().zip(last) {
                *s += v;
            }
            if (g + 1) % periods_per_pixel != 0 {
                continue;
            }
            let n = periods_per_pixel as f64;
            let mean = sum.map(|s| s / n);
            out.push(FmPixel {
                x_m: step * n * ((g / periods_per_pixel) as f64 + 0.5),
                topography_m: mean[0],
                frequency_shift_hz: mean[1],
                error_hz: if mean[2].abs() < 1e-9 * set.abs() {
                    0.0
                } else {
                    mean[2]
                },
                excitation_ratio: mean[3],
                dissipation_j: mean[4],
                amplitude_ratio: mean[5],
            });
            sum = [0.0; 6];
            progress(out.len());
        }
        Ok(out)
    }

    /// What [`Repeats`] watches: the lever's state (units of A), the frequency shift
    /// in units of [`SHIFT_UNIT_HZ`], F/F₀ and the rest separation `rest` in units of A.
    fn loop_state(&self, rest: f64) -> LoopState {
        let f0 = self.materials[0].setup.cantilever.resonance_hz;
        let p = &self.phase;
        let parts = [
            p.x,
            p.v,
            (self.drive.omega - 1.0) * f0 / SHIFT_UNIT_HZ,
            self.drive.excitation,
            rest,
        ];
        let mut state = [0.0; STATE_LEN];
        state[..parts.len()].copy_from_slice(&parts);
        state
    }
}
