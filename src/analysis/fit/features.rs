//! Where a measured approach shows its features — the branch jump (the steepest fall
//! of the phase, or jump of the amplitude) and the onset of the interaction — which the
//! global stage aligns its starts on ([`super::search`]), the model follows
//! ([`Measured::split_at_branch_jump`]) and the verdict compares ([`super::diagnose`]).

use super::model::Measured;

/// The phase must fall by this much between two points to be the branch jump, degrees.
const JUMP_DEG: f64 = 10.0;
/// The amplitude must move by this fraction between two points to be a jump.
const JUMP_AMPLITUDE: f64 = 0.02;
/// Where an approach's first segment shows its features, in the data's positions.
#[derive(Debug, Clone, Copy, PartialEq)]
#[doc(hidden)]
pub struct Features {
    /// The branch jump: between points i and i + 1 (the steepest fall of the phase, or
    /// jump of the amplitude, beyond its threshold).
    pub jump: Option<usize>,
    /// Where the channel first leaves its first point's value by the threshold
    /// (interpolated), m.
    pub onset_m: Option<f64>,
}

impl Features {
    /// The features of the first approach of `curve` (values at `data`'s positions):
    /// the phase's where the data hold one, else the amplitude's.
    pub fn of(data: &Measured, phase: Option<&[f64]>, amplitude: Option<&[f64]>) -> Self {
        let end = first_end(data);
        let z = &data.position_m[..end];
        if let Some(p) = phase {
            let threshold = (10.0 * data.sigma_phase_deg).max(1.0);
            let jump = steepest(&p[..end], |a, b| a - b).filter(|&(_, d)| d > JUMP_DEG);
            return Self {
                jump: jump.map(|j| j.0),
                onset_m: onset(z, &p[..end], threshold),
            };
        }
        let Some(a) = amplitude else {
            return Self {
                jump: None,
                onset_m: None,
            };
        };
        let scale = a[0].abs().max(f64::MIN_POSITIVE);
        let threshold = (10.0 * data.sigma_amplitude_m).max(5e-3 * scale);
        let jump =
            steepest(&a[..end], |x, y| (y - x).abs()).filter(|&(_, d)| d > JUMP_AMPLITUDE * scale);
        Self {
            jump: jump.map(|j| j.0),
            onset_m: onset(z, &a[..end], threshold),
        }
    }
}

/// Where the first approach of `data` ends.
#[doc(hidden)]
pub fn first_end(data: &Measured) -> usize {
    data.segments
        .get(1)
        .copied()
        .unwrap_or(data.position_m.len())
}

/// The index i and size of the largest `step(v[i], v[i+1])`.
fn steepest(v: &[f64], step: impl Fn(f64, f64) -> f64) -> Option<(usize, f64)> {
    v.windows(2)
        .enumerate()
        .map(|(i, w)| (i, step(w[0], w[1])))
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// Where `v` first differs from `v[0]` by more than `threshold`, interpolated between
/// the positions `z`.
#[doc(hidden)]
pub fn onset(z: &[f64], v: &[f64], threshold: f64) -> Option<f64> {
    let i = v.iter().position(|x| (x - v[0]).abs() > threshold)?;
    let (d0, d1) = ((v[i - 1] - v[0]).abs(), (v[i] - v[0]).abs());
    let t = ((threshold - d0) / (d1 - d0)).clamp(0.0, 1.0);
    Some(z[i - 1] + (z[i] - z[i - 1]) * t)
}

impl Measured {
    /// These data with their approach from far split where its phase jumps from above
    /// its first (free) value to below it — from the attractive to the repulsive branch
    /// — the points after the jump simulated as an approach begun there from the free
    /// oscillation (which reaches the repulsive branch): each point is then simulated on
    /// the branch the data show, and the residuals are smooth in the parameters however
    /// far the model's own jump lies from the data's. None where there is no such jump
    /// (or the data are already split into approaches, or are setpoint data).
    pub fn split_at_branch_jump(&self) -> Option<Measured> {
        if self.setpoint_ratio.is_some() || self.segments.len() != 1 {
            return None;
        }
        let phase = self.phase_deg.as_deref()?;
        let j = Features::of(self, Some(phase), None).jump?;
        (phase[j] > phase[0] && phase[j + 1] < phase[0]).then(|| Measured {
            segments: vec![0, j + 1],
            ..self.clone()
        })
    }
}
