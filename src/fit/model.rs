//! The forward model of a fit: the parameters it may adjust, the measured curve, and the
//! approach curve a parameter set gives at the measured piezo positions.

use crate::dynamics::setup::{Numerics, TapSetup};
use crate::error::{Error, Result};
use crate::sweep::{Direction, MAX_SWEEP_POINTS, approach_curve};
use serde::Serialize;

/// A parameter a fit may adjust (the others stay as the setup gives them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Parameter {
    /// Composite modulus E*, Pa.
    Modulus,
    /// Work of adhesion Δγ, J/m².
    WorkOfAdhesion,
    /// Range ε of the Lennard-Jones law (the equilibrium gap), m.
    Range,
    /// The offset of the piezo position: z_c = z_piezo + offset, m.
    ZOffset,
}

impl Parameter {
    /// Its key in tables and JSON, unit included.
    pub fn key(self) -> &'static str {
        match self {
            Parameter::Modulus => "modulus_pa",
            Parameter::WorkOfAdhesion => "work_of_adhesion_j_m2",
            Parameter::Range => "range_m",
            Parameter::ZOffset => "z_offset_m",
        }
    }

    /// Whether it is a positive scale, fitted as its logarithm (a relative step means
    /// the same anywhere), or a position, fitted as it is (in nm).
    pub fn is_scale(self) -> bool {
        !matches!(self, Parameter::ZOffset)
    }

    /// Its value in `setup` (the offset is not a setup's: `offset_m`).
    pub fn value(self, setup: &TapSetup, offset_m: f64) -> f64 {
        match self {
            Parameter::Modulus => setup.contact.modulus_pa,
            Parameter::WorkOfAdhesion => setup.contact.work_of_adhesion_j_m2,
            Parameter::Range => setup.contact.range_m,
            Parameter::ZOffset => offset_m,
        }
    }

    /// Set it to `value` in `setup` or `offset_m`.
    pub fn set(self, setup: &mut TapSetup, offset_m: &mut f64, value: f64) {
        match self {
            Parameter::Modulus => setup.contact.modulus_pa = value,
            Parameter::WorkOfAdhesion => setup.contact.work_of_adhesion_j_m2 = value,
            Parameter::Range => setup.contact.range_m = value,
            Parameter::ZOffset => *offset_m = value,
        }
    }
}

/// A measured approach curve — or several, one after another — : piezo positions (any
/// zero; far to near in each) with the amplitude and/or the phase read there, and each
/// channel's standard deviation (the weights of the least squares).
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// Piezo positions, m, decreasing within each approach.
    pub position_m: Vec<f64>,
    /// Where each approach begins (indices into the positions, the first 0): each is
    /// simulated from the free oscillation at its first position, as `approach` starts
    /// — a second approach begun close to the sample reaches the repulsive branch where
    /// one from far stays on the attractive one.
    pub segments: Vec<usize>,
    /// Amplitudes, m.
    pub amplitude_m: Option<Vec<f64>>,
    /// Phases, degrees (90° free at resonance).
    pub phase_deg: Option<Vec<f64>>,
    /// The amplitude's standard deviation, m.
    pub sigma_amplitude_m: f64,
    /// The phase's, degrees.
    pub sigma_phase_deg: f64,
}

impl Measured {
    /// Validate: at least three points, as many values in each channel as positions,
    /// one channel at least, all finite, positions strictly decreasing, standard
    /// deviations positive.
    pub fn validated(self) -> Result<Self> {
        let n = self.position_m.len();
        if !(3..=MAX_SWEEP_POINTS).contains(&n) {
            return Err(Error::OutOfRange(format!(
                "a fit takes 3 to {MAX_SWEEP_POINTS} measured points, not {n}"
            )));
        }
        if self.amplitude_m.is_none() && self.phase_deg.is_none() {
            return Err(Error::NotApplicable(
                "the data hold neither an amplitude nor a phase to fit".into(),
            ));
        }
        for (name, column) in [
            ("position", Some(&self.position_m)),
            ("amplitude", self.amplitude_m.as_ref()),
            ("phase", self.phase_deg.as_ref()),
        ] {
            let Some(column) = column else { continue };
            if column.len() != n {
                return Err(Error::NotApplicable(format!(
                    "{} {name} values for {n} positions",
                    column.len()
                )));
            }
            if let Some((i, v)) = column.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(Error::NotApplicable(format!(
                    "{name} of point {} is {v}: every value must be finite",
                    i + 1
                )));
            }
        }
        if self.segments.first() != Some(&0)
            || self.segments.windows(2).any(|w| w[1] <= w[0])
            || self.segments.last().is_some_and(|&l| l >= n)
        {
            return Err(Error::NotApplicable(format!(
                "the approaches must begin at increasing points from the first, each with a \
                 point of its own: {:?} for {n} points",
                self.segments
            )));
        }
        if let Some(i) = self
            .position_m
            .windows(2)
            .enumerate()
            .position(|(i, w)| w[1] >= w[0] && !self.segments.contains(&(i + 1)))
        {
            return Err(Error::NotApplicable(format!(
                "a fit takes approach curves, positions from far to near: point {} \
                 ({:e} m) does not lie nearer than point {} ({:e} m)",
                i + 2,
                self.position_m[i + 1],
                i + 1,
                self.position_m[i]
            )));
        }
        if self.amplitude_m.is_some() {
            crate::error::positive("amplitude standard deviation", self.sigma_amplitude_m)?;
        }
        if self.phase_deg.is_some() {
            crate::error::positive("phase standard deviation", self.sigma_phase_deg)?;
        }
        Ok(self)
    }

    /// The curves of `setup` at the measured positions shifted by `offset_m`, each
    /// approach from the free oscillation at its first position, joined.
    pub fn simulate(&self, setup: &TapSetup, numerics: &Numerics, offset_m: f64) -> Result<Curve> {
        let n = self.position_m.len();
        let mut joined: Option<Curve> = None;
        for (k, &start) in self.segments.iter().enumerate() {
            let end = self.segments.get(k + 1).copied().unwrap_or(n);
            let c = curve(setup, numerics, &self.position_m[start..end], offset_m)?;
            match joined.as_mut() {
                None => joined = Some(c),
                Some(j) => {
                    j.separation_m.extend(c.separation_m);
                    j.amplitude_m.extend(c.amplitude_m);
                    j.phase_deg.extend(c.phase_deg);
                    j.well_defined.extend(c.well_defined);
                }
            }
        }
        joined.ok_or_else(|| Error::NotApplicable("no approach to simulate".into()))
    }

    /// Residuals per point: one per channel measured.
    pub fn channels(&self) -> usize {
        usize::from(self.amplitude_m.is_some()) + usize::from(self.phase_deg.is_some())
    }

    /// The weighted residuals (model − measured)/σ of `curve`, amplitudes first.
    pub fn residuals(&self, curve: &Curve) -> Vec<f64> {
        let mut r = Vec::with_capacity(self.channels() * self.position_m.len());
        if let Some(a) = &self.amplitude_m {
            r.extend(
                a.iter()
                    .zip(&curve.amplitude_m)
                    .map(|(m, s)| (s - m) / self.sigma_amplitude_m),
            );
        }
        if let Some(p) = &self.phase_deg {
            r.extend(
                p.iter()
                    .zip(&curve.phase_deg)
                    .map(|(m, s)| (s - m) / self.sigma_phase_deg),
            );
        }
        r
    }
}

/// A simulated approach curve at the measured positions.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Curve {
    /// Rest separations z_c = position + offset, m.
    pub separation_m: Vec<f64>,
    /// Amplitudes, m.
    pub amplitude_m: Vec<f64>,
    /// Phases, degrees.
    pub phase_deg: Vec<f64>,
    /// Whether each point is a stable period-1 orbit that does not graze a switch (else
    /// its values are averages over motion that perturbations can change).
    pub well_defined: Vec<bool>,
}

/// The approach curve of `setup` at the piezo positions `position_m` shifted by
/// `offset_m` (each point's steady state started from the last one's, as an approach
/// goes).
pub fn curve(
    setup: &TapSetup,
    numerics: &Numerics,
    position_m: &[f64],
    offset_m: f64,
) -> Result<Curve> {
    let ramp: Vec<(f64, Direction)> = position_m
        .iter()
        .map(|z| (z + offset_m, Direction::Approach))
        .collect();
    let points = approach_curve(setup, numerics, &ramp, |_, _| {})?;
    Ok(Curve {
        separation_m: ramp.iter().map(|r| r.0).collect(),
        amplitude_m: points.iter().map(|p| p.observables.amplitude_m).collect(),
        phase_deg: points.iter().map(|p| p.observables.phase_deg).collect(),
        well_defined: points
            .iter()
            .map(|p| p.observables.regime == "period-1" && !p.observables.grazing)
            .collect(),
    })
}
