//! The analysis of a recorded force curve as commercial quantitative-nanomechanics
//! ("QNM") software does it — peak force, adhesion, dissipation, deformation and a DMT
//! modulus fitted to the retract — shared by the force–distance ramp
//! ([`super::force_curve`]) and off-resonance tapping ([`super::peakforce`]), with how
//! their curves are sampled.

use crate::dynamics::observed::Sampling;
use crate::error::{Error, Result};
use serde::Serialize;
use std::f64::consts::PI;

/// One point of a recorded cycle (SI).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ForcePoint {
    /// Time from the start of the cycle (the support at its farthest), s.
    pub t_s: f64,
    /// The support's position: the separation of the undeflected tip, z_c + x_b, m.
    pub piezo_m: f64,
    /// The deflection z, m (toward the sample negative).
    pub deflection_m: f64,
    /// The tip–sample separation α, m (negative: indentation).
    pub separation_m: f64,
    /// The tip–sample force, N (repulsive positive).
    pub force_n: f64,
    /// Whether the support moves toward the sample (the approach half of the cycle).
    pub approach: bool,
    /// Whether the tip is on the law's contact branch.
    pub contact: bool,
}

/// The QNM channels of one cycle, as the instrument computes them from its force curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Channels {
    /// The largest force of the cycle, N.
    pub peak_force_n: f64,
    /// The adhesion: minus the least force on retract, N.
    pub adhesion_n: f64,
    /// The energy dissipated: the area between the approach and retract force–
    /// separation curves, −∮F dα, J.
    pub dissipation_j: f64,
    /// The deformation: from where the approach force last crosses zero before the peak
    /// to the separation at the peak, m.
    pub deformation_m: f64,
    /// The DMT modulus E* fitted to the retract curve between the two force fractions
    /// ([`Analysis`]), Pa; None where fewer than 3 points lie in the window.
    pub dmt_modulus_pa: Option<f64>,
    /// The separation of the fit's zero (where F = −adhesion on the DMT curve), m.
    pub dmt_contact_m: Option<f64>,
    /// Points in the fit's window.
    pub dmt_points: usize,
}

/// How the channels are computed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Analysis {
    /// The DMT fit's window on the retract curve, as fractions of the span from the
    /// adhesion to the peak force (commercial QNM analysis: 30 % and 90 %).
    pub fit_window: (f64, f64),
}

impl Default for Analysis {
    fn default() -> Self {
        Self {
            fit_window: (0.3, 0.9),
        }
    }
}

impl Analysis {
    /// Refuse a window that is not two fractions in order.
    pub fn check(&self) -> Result<()> {
        let (lo, hi) = self.fit_window;
        if !((0.0..1.0).contains(&lo) && lo < hi && hi <= 1.0) {
            return Err(Error::NotApplicable(format!(
                "the DMT fit window {lo}–{hi} must be two fractions 0 ≤ lo < hi ≤ 1 of the \
                 span from the adhesion to the peak force (instruments use 0.3 and 0.9)"
            )));
        }
        Ok(())
    }

    /// The channels of one cycle's force curve `curve` (in time order) for a tip of
    /// radius `radius_m`. The DMT fit: on the retract from the peak to the least force,
    /// F − F_min = (4/3)E*√R (d₀ − d)^{3/2} (Derjaguin, Muller & Toporov 1975), linear in
    /// d once both sides are raised to 2/3, so E* and d₀ come from a straight-line fit.
    pub fn channels(&self, curve: &[ForcePoint], radius_m: f64) -> Channels {
        let peak_at = curve
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.force_n.total_cmp(&b.1.force_n))
            .map_or(0, |(i, _)| i);
        let peak = curve.get(peak_at).map_or(0.0, |p| p.force_n);
        let min_at = (peak_at..curve.len())
            .min_by(|&a, &b| curve[a].force_n.total_cmp(&curve[b].force_n))
            .unwrap_or(peak_at);
        let least = curve.get(min_at).map_or(0.0, |p| p.force_n);
        let dissipation = -curve.windows(2).map(work_on_tip).sum::<f64>();
        // The approach's last crossing of zero force before the peak.
        let zero = (1..=peak_at)
            .rev()
            .find(|&i| curve[i - 1].force_n <= 0.0 && curve[i].force_n > 0.0)
            .map(|i| {
                let (a, b) = (&curve[i - 1], &curve[i]);
                let t = -a.force_n / (b.force_n - a.force_n);
                a.separation_m + t * (b.separation_m - a.separation_m)
            });
        let deformation = zero.map_or(0.0, |z| z - curve[peak_at].separation_m);
        // The DMT fit on the retract between the window's forces.
        let span = peak - least;
        let (lo, hi) = (
            least + self.fit_window.0 * span,
            least + self.fit_window.1 * span,
        );
        let window: Vec<(f64, f64)> = curve[peak_at..=min_at.max(peak_at)]
            .iter()
            .filter(|p| p.force_n >= lo && p.force_n <= hi && p.contact)
            .map(|p| (p.separation_m, (p.force_n - least).powf(2.0 / 3.0)))
            .collect();
        let fit = (window.len() >= 3 && span > 0.0)
            .then(|| line(&window))
            .flatten()
            .filter(|&(slope, _)| slope < 0.0);
        Channels {
            peak_force_n: peak,
            adhesion_n: -least.min(0.0) + 0.0,
            dissipation_j: dissipation,
            deformation_m: deformation,
            dmt_modulus_pa: fit.map(|(slope, _)| 0.75 * (-slope).powf(1.5) / radius_m.sqrt()),
            dmt_contact_m: fit.map(|(slope, intercept)| -intercept / slope),
            dmt_points: window.len(),
        }
    }
}

/// The work the tip–sample force does on the tip between two recorded points,
/// ∫F dα by the trapezoid rule.
pub(crate) fn work_on_tip(pair: &[ForcePoint]) -> f64 {
    0.5 * (pair[0].force_n + pair[1].force_n) * (pair[1].separation_m - pair[0].separation_m)
}

/// The least-squares line y = s·x + c through `points`: (s, c), None if the x coincide.
fn line(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), &(x, y)| (a + x / n, b + y / n));
    let (sxx, sxy) = points.iter().fold((0.0, 0.0), |(a, b), &(x, y)| {
        (a + (x - mx) * (x - mx), b + (x - mx) * (y - my))
    });
    (sxx > 0.0).then(|| {
        let s = sxy / sxx;
        (s, my - s * mx)
    })
}

/// How the force curve is recorded: four points on each integrator step (the steps
/// resolve the contact finely; the area between approach and retract is then within
/// 1e-4 of the exact loss), the closed-form free flight 32 times a period of the lever,
/// and a step's start where the branch switched (the force jumps there at one
/// separation); at most [`MAX_CURVE_SAMPLES`].
pub(crate) const CURVE: Sampling = Sampling {
    points_per_step: 4,
    free_samples: 32.0,
    free_period: 2.0 * PI,
    switch_starts: true,
    max_samples: MAX_CURVE_SAMPLES,
};

/// The most points of a recorded force curve (some 100 bytes each with the curve in
/// SI beside its samples: 100 MB): a slow modulation's cycles of 10⁴ lever periods fit.
pub const MAX_CURVE_SAMPLES: usize = 1_000_000;
