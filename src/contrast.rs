//! Phase contrast between materials: the same cantilever and amplitude setpoints on two
//! or more samples, for several force laws side by side — how much contrast the classic
//! JKR law overstates against the hybrid and the exact Lennard-Jones law.

use crate::config::TapInputs;
use crate::dynamics::setup::{Numerics, TapSetup};
use crate::error::{Error, Result};
use crate::law::LawKind;
use crate::sweep::{self, Direction, SweepPoint};
use serde::Serialize;

/// A named material: the contact inputs that differ from the base setup.
#[derive(Debug, Clone)]
pub struct Material {
    /// Name used in tables and legends.
    pub name: String,
    /// Inputs overriding the base setup (contact keys).
    pub inputs: TapInputs,
}

impl Material {
    /// Parse `name:key=value,key=value` (keys: the flags' names, values with units),
    /// e.g. `b:sample-modulus=1GPa,work-of-adhesion=0.08`.
    pub fn parse(text: &str) -> Result<Self> {
        let bad = |reason: &str| Error::Parse {
            name: "material",
            text: text.to_string(),
            reason: reason.into(),
        };
        let (name, rest) = text
            .split_once(':')
            .ok_or_else(|| bad("expected name:key=value,key=value"))?;
        if name.trim().is_empty() {
            return Err(bad("the material needs a name before ':'"));
        }
        let mut inputs = TapInputs::default();
        for pair in rest.split(',').filter(|p| !p.trim().is_empty()) {
            let (key, value) = pair
                .split_once('=')
                .ok_or_else(|| bad("each property is key=value"))?;
            inputs.set(key.trim(), value.trim())?;
        }
        Ok(Self {
            name: name.trim().to_string(),
            inputs,
        })
    }
}

/// φ at one amplitude setpoint for every material, and the contrast.
#[derive(Debug, Clone, Serialize)]
pub struct ContrastRow {
    /// Force law.
    pub law: String,
    /// Amplitude setpoint A/A₀.
    pub amplitude_ratio: f64,
    /// φ of each material (degrees), in the order given; NaN where the approach curve does
    /// not reach this setpoint.
    pub phase_deg: Vec<f64>,
    /// φ(last material) − φ(first material), degrees.
    pub delta_phase_deg: f64,
}

/// The approach curve of one material under one law.
#[derive(Debug, Clone)]
pub struct LawCurve {
    /// Material name.
    pub material: String,
    /// Force law.
    pub law: LawKind,
    /// The approach points.
    pub points: Vec<SweepPoint>,
}

/// φ at amplitude ratio `r` on the approach branch of `curve`, by linear interpolation
/// between the first pair of setpoints that brackets it.
fn phase_at(curve: &[SweepPoint], r: f64) -> f64 {
    let approach: Vec<&SweepPoint> = curve
        .iter()
        .filter(|p| p.direction == Direction::Approach)
        .collect();
    approach
        .windows(2)
        .find(|w| {
            let (a, b) = (
                w[0].observables.amplitude_ratio,
                w[1].observables.amplitude_ratio,
            );
            (a - r) * (b - r) <= 0.0 && a != b
        })
        .map(|w| {
            let (a, b) = (
                w[0].observables.amplitude_ratio,
                w[1].observables.amplitude_ratio,
            );
            let f = (a - r) / (a - b);
            w[0].observables.phase_deg
                + f * (w[1].observables.phase_deg - w[0].observables.phase_deg)
        })
        .unwrap_or(f64::NAN)
}

/// Approach curves of every material under every law, and the contrast table at the
/// amplitude setpoints `ratios`. `progress` is told what is being computed.
pub fn contrast(
    base: &TapInputs,
    materials: &[Material],
    laws: &[LawKind],
    ratios: &[f64],
    points: usize,
    mut progress: impl FnMut(&str),
) -> Result<(Vec<ContrastRow>, Vec<LawCurve>)> {
    if materials.len() < 2 {
        return Err(Error::NotApplicable(
            "phase contrast needs at least two materials".into(),
        ));
    }
    let mut curves = Vec::new();
    for m in materials {
        let inputs = m.inputs.clone().or(base.clone());
        let (setup, numerics): (TapSetup, Numerics) = inputs.resolve()?;
        let numerics = sweep::sweep_numerics(&inputs, numerics);
        let a0 = setup.cantilever.free_amplitude_m;
        let ramp = sweep::ramp(1.2 * a0, 0.3 * a0, points, false)?;
        for &law in laws {
            progress(&format!("{}, {law}", m.name));
            let s = TapSetup {
                law,
                ..setup.clone()
            };
            curves.push(LawCurve {
                material: m.name.clone(),
                law,
                points: sweep::approach_curve(&s, &numerics, &ramp, |_, _| {})?,
            });
        }
    }
    let mut rows = Vec::new();
    for &law in laws {
        for &r in ratios {
            let phase_deg: Vec<f64> = materials
                .iter()
                .map(|m| {
                    curves
                        .iter()
                        .find(|c| c.material == m.name && c.law == law)
                        .map_or(f64::NAN, |c| phase_at(&c.points, r))
                })
                .collect();
            rows.push(ContrastRow {
                law: law.to_string(),
                amplitude_ratio: r,
                delta_phase_deg: phase_deg[phase_deg.len() - 1] - phase_deg[0],
                phase_deg,
            });
        }
    }
    Ok((rows, curves))
}
