//! Off-resonance tapping scanned over a sample (PeakForce QNM imaging): the support
//! modulated as in [`super::peakforce`], the peak-force feedback moving the z piezo once
//! a cycle, the tip carried along the line over the sample's regions
//! ([`super::scan::Region`]: a material and a surface height each), and per pixel the
//! topography (the piezo position) and the QNM channels of the pixel's last cycle,
//! recorded, as the instrument reads them.
//!
//! Cycles are marched one after another, each at the material and height under the tip
//! at its start (the lever's state carried across, a relaxing sample's surface fresh
//! where the material changes). Once the loop repeats itself over a region — the lever's state
//! at the start of a cycle returning within 1e-9 of the free amplitude, the piezo moving
//! by less than 1e-13 m, for 8 cycles running — the cycles up to the next region are
//! repeats of the last, whose recorded channels every pixel there shows ([`Scanner::exact`]
//! marches every one).

use super::peakforce::{
    Modulation, PeakForceFeedback, SETTLED, check_setpoint, force_points, simulation,
};
use super::qnm::{Analysis, CURVE, Channels};
use super::scan::Region;
use crate::dynamics::budget::budgeted;
use crate::dynamics::march::{Phase, Simulation};
use crate::dynamics::numeric::Ignore;
use crate::dynamics::observed::Recorder;
use crate::dynamics::setup::{Numerics, Prepared};
use crate::error::{Error, Result};
use crate::physics::law::AnyLaw;
use serde::{Deserialize, Serialize};

/// What is recorded over one pixel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct QnmPixel {
    /// The pixel's centre, m.
    pub x_m: f64,
    /// The z piezo position (the support's centre), the mean over the pixel's cycles:
    /// the topography, m.
    pub topography_m: f64,
    /// The peak force of the pixel's last cycle, N.
    pub peak_force_n: f64,
    /// Its error against the setpoint, N (0 where below 1e-9 of it: a loop that holds).
    pub error_n: f64,
    /// The adhesion, N.
    pub adhesion_n: f64,
    /// The dissipation (area between approach and retract), J.
    pub dissipation_j: f64,
    /// The deformation, m.
    pub deformation_m: f64,
    /// The DMT modulus fitted to the retract, Pa (None: no fit).
    pub dmt_modulus_pa: Option<f64>,
}

/// Cycles in a row whose state repeats before the loop is taken to repeat itself.
const QUIET_CYCLES: usize = 8;

/// The most cycles the loop is given to engage.
pub const MAX_ENGAGE_CYCLES: usize = 2000;

/// The peak-force loop marching over a sample's materials.
pub struct Scanner<'a> {
    materials: &'a [Prepared],
    sims: Vec<Simulation<'a, AnyLaw>>,
    analysis: Analysis,
    loop_: PeakForceFeedback,
    /// The lever's state at the start of the next cycle.
    phase: Phase,
    /// The z piezo position, m.
    z_m: f64,
    /// The material and height of the last cycle.
    under: Option<(usize, f64)>,
    /// Cycles in a row that repeated the one before.
    quiet: usize,
    /// The channels of the repeating cycle, once recorded.
    channels: Option<(Channels, f64)>,
    /// Whether to march every cycle.
    exact: bool,
    /// Cycles marched.
    pub marched: usize,
}

impl<'a> Scanner<'a> {
    /// A loop over `materials` (all on one cantilever), with the support modulated by
    /// `modulation`, the channels computed by `analysis`, the feedback `loop_`.
    pub fn new(
        materials: &'a [Prepared],
        modulation: &Modulation,
        analysis: Analysis,
        loop_: PeakForceFeedback,
        numerics: &Numerics,
    ) -> Result<Self> {
        check_setpoint(loop_.setpoint_n)?;
        analysis.check()?;
        if !(loop_.gain > 0.0 && loop_.gain <= 1.0) {
            return Err(Error::InvalidParameter {
                name: "feedback gain",
                value: loop_.gain,
                reason: "must be above 0 and at most 1 (per cycle)",
            });
        }
        let sims = materials
            .iter()
            .map(|p| simulation(p, modulation, 0.0, numerics.min_steps_per_period))
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            materials,
            sims,
            analysis,
            loop_,
            phase: Phase::at_rest(),
            z_m: modulation.amplitude_m + 2e-9,
            under: None,
            quiet: 0,
            channels: None,
            exact: false,
            marched: 0,
        })
    }

    /// March every cycle (no repeats taken).
    pub fn exact(mut self) -> Self {
        self.exact = true;
        self
    }

    /// The z piezo position, m.
    pub fn z_m(&self) -> f64 {
        self.z_m
    }

    /// Engage over `material` at surface height `height_m`: from rest with the
    /// support's lowest point 2 nm above the surface, cycles with the feedback until the
    /// loop repeats itself (at most [`MAX_ENGAGE_CYCLES`]).
    pub fn engage(&mut self, material: usize, height_m: f64, amplitude_m: f64) -> Result<()> {
        self.phase = Phase::at_rest();
        self.z_m = height_m + amplitude_m + 2e-9;
        self.under = None;
        for _ in 0..MAX_ENGAGE_CYCLES {
            self.cycle(material, height_m, false)?;
            if self.quiet >= QUIET_CYCLES {
                return Ok(());
            }
        }
        Err(Error::NotApplicable(format!(
            "the peak-force feedback did not settle in {MAX_ENGAGE_CYCLES} cycles over the \
             first region (gain {}): lower the gain",
            self.loop_.gain
        )))
    }

    /// One modulation cycle over `material` at surface height `height_m` (its channels
    /// recorded if `record`), the feedback moving the piezo at its end; a repeat of the
    /// last where the loop repeats itself over the same region. The channels, if
    /// recorded (or repeated), and the cycle's peak force.
    pub fn cycle(
        &mut self,
        material: usize,
        height_m: f64,
        record: bool,
    ) -> Result<(Option<Channels>, f64)> {
        if self.under != Some((material, height_m)) {
            if self.under.is_some_and(|(m, _)| m != material) {
                self.phase.surface = None;
            }
            self.under = Some((material, height_m));
            self.quiet = 0;
            self.channels = None;
        }
        if !self.exact
            && self.quiet >= QUIET_CYCLES
            && let Some((channels, peak)) = self.channels
        {
            return Ok((Some(channels), peak));
        }
        let p = &self.materials[material];
        let mut sim = self.sims[material];
        let scale = p.setup.contact.separation_scale_m();
        sim.cpl.a0 = (self.z_m - height_m) / scale;
        let cant = &p.setup.cantilever;
        let (k, l) = (cant.stiffness_n_m, cant.free_amplitude_m);
        // Record where asked, and the first repeating cycle (its channels stand for
        // the repeats).
        let record = record || (self.quiet + 1 >= QUIET_CYCLES && self.channels.is_none());
        let before = self.phase.clone();
        sim.rewind(&mut self.phase);
        let (c, channels) = budgeted(p.steady.max_steps, || {
            if record {
                let mut recorder = Recorder::sampling(&p.law, sim.cpl, sim.osc, CURVE);
                let c = sim.cycle(&mut self.phase, &mut recorder)?;
                let curve = force_points(p, &sim, self.z_m - height_m, &recorder.samples);
                Ok((
                    c,
                    Some(self.analysis.channels(&curve, p.setup.contact.radius_m)),
                ))
            } else {
                Ok((sim.cycle(&mut self.phase, &mut Ignore)?, None))
            }
        })?;
        self.marched += 1;
        let peak = c.max_force.max(0.0) * k * l;
        let step = self.loop_.gain * (peak - self.loop_.setpoint_n) / k;
        self.z_m += step;
        let gap = (self.phase.x - before.x)
            .abs()
            .max((self.phase.v - before.v).abs());
        let repeated = gap <= 1e-2 * SETTLED && step.abs() < 1e-13;
        self.quiet = if repeated { self.quiet + 1 } else { 0 };
        if !repeated {
            self.channels = None;
        } else if let Some(ch) = channels {
            self.channels = Some((ch, peak));
        }
        if !(self.z_m - height_m).is_finite() || (self.z_m - height_m).abs() > 10e-6 {
            return Err(Error::NotApplicable(format!(
                "the peak-force feedback moved the support {:.4} nm from the surface without \
                 the peak force reaching the setpoint {:.4} nN: lower the setpoint or raise \
                 the modulation amplitude",
                (self.z_m - height_m) * 1e9,
                self.loop_.setpoint_n * 1e9
            )));
        }
        Ok((channels, peak))
    }

    /// Scan a line of length `length_m` over `regions` in `pixels` pixels of
    /// `cycles_per_pixel` modulation cycles each, from where the loop stands; each
    /// pixel's channels are its last cycle's. `progress` is told each pixel done.
    pub fn line(
        &mut self,
        regions: &[Region],
        (length_m, pixels, cycles_per_pixel): (f64, usize, usize),
        mut progress: impl FnMut(usize),
    ) -> Result<Vec<QnmPixel>> {
        super::scan::check_regions(regions, self.materials.len())?;
        if pixels == 0 || cycles_per_pixel == 0 {
            return Err(Error::NotApplicable(
                "a scan line needs at least one pixel of at least one cycle".into(),
            ));
        }
        let total = pixels * cycles_per_pixel;
        let step = length_m / total as f64;
        let mut under = 0;
        let mut out = Vec::with_capacity(pixels);
        let mut z_sum = 0.0;
        for g in 0..total {
            let x = step * g as f64;
            while under + 1 < regions.len() && x >= regions[under].until_m {
                under += 1;
            }
            let region = regions[under];
            z_sum += self.z_m;
            let last = (g + 1) % cycles_per_pixel == 0;
            let (channels, peak) = self.cycle(region.material, region.height_m, last)?;
            if !last {
                continue;
            }
            let ch = channels.expect("the pixel's last cycle is recorded");
            let error = peak - self.loop_.setpoint_n;
            out.push(QnmPixel {
                x_m: step * cycles_per_pixel as f64 * ((g / cycles_per_pixel) as f64 + 0.5),
                topography_m: z_sum / cycles_per_pixel as f64,
                peak_force_n: peak,
                error_n: if error.abs() < 1e-9 * self.loop_.setpoint_n {
                    0.0
                } else {
                    error
                },
                adhesion_n: ch.adhesion_n,
                dissipation_j: ch.dissipation_j,
                deformation_m: ch.deformation_m,
                dmt_modulus_pa: ch.dmt_modulus_pa,
            });
            z_sum = 0.0;
            progress(out.len());
        }
        Ok(out)
    }
}
