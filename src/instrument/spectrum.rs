//! The thermal spectrum of a cantilever and its calibration: Welch's estimate of a
//! record's power spectral density, the simple harmonic oscillator's thermal spectrum,
//! and the fit of one to the other from which Hutter & Bechhoefer (RSI 64, 1868, 1993)
//! calibrate the spring constant, k = k_BT/⟨z²⟩, ⟨z²⟩ the area under the fitted
//! resonance.

use crate::dynamics::grazing::BOLTZMANN_J_K;
use crate::error::{Error, Result};
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DVector, Dyn, OMatrix, Owned, U3, Vector3};
use rustfft::num_complex::Complex;

/// A one-sided power spectral density.
#[derive(Debug, Clone, PartialEq)]
pub struct Psd {
    /// Frequencies, Hz (from the first bin above 0 to below the Nyquist frequency).
    pub freq_hz: Vec<f64>,
    /// Density at each, in the record's unit squared per Hz.
    pub density: Vec<f64>,
    /// Segments averaged.
    pub segments: usize,
}

/// Welch's estimate of the one-sided PSD of `record` sampled at `rate_hz`
/// ([`Welch`]).
pub fn welch(record: &[f64], rate_hz: f64, segment: usize) -> Result<Psd> {
    let mut w = Welch::new(rate_hz, segment)?;
    w.push(record);
    w.psd()
}

/// Welch's estimate of a one-sided PSD, fed a record piece by piece (its memory is two
/// segments, whatever the record's length): segments of `segment` samples (a power of
/// two) overlapping by half, each with its mean removed and a periodic Hann window,
/// the squared magnitudes of their Fourier transforms averaged and normalised so that
/// the density integrates to the variance (P_k = 2|X_k|²/(f_s Σw²)).
pub struct Welch {
    rate_hz: f64,
    segment: usize,
    window: Vec<f64>,
    fft: std::sync::Arc<dyn rustfft::Fft<f64>>,
    buffer: Vec<Complex<f64>>,
    /// Samples not yet in a whole segment (the second half of the last one first).
    pending: Vec<f64>,
    sum: Vec<f64>,
    segments: usize,
}

impl std::fmt::Debug for Welch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Welch")
            .field("rate_hz", &self.rate_hz)
            .field("segment", &self.segment)
            .field("segments", &self.segments)
            .finish()
    }
}

impl Welch {
    /// An estimate of segments of `segment` samples at `rate_hz`.
    pub fn new(rate_hz: f64, segment: usize) -> Result<Self> {
        if !segment.is_power_of_two() || !(16..=MAX_SEGMENT).contains(&segment) {
            return Err(Error::NotApplicable(format!(
                "a Welch segment is a power of two from 16 to {MAX_SEGMENT} samples, not \
                 {segment}"
            )));
        }
        crate::error::positive("sampling rate", rate_hz)?;
        Ok(Self {
            rate_hz,
            segment,
            window: (0..segment)
                .map(|n| {
                    let s = (std::f64::consts::PI * n as f64 / segment as f64).sin();
                    s * s
                })
                .collect(),
            fft: rustfft::FftPlanner::new().plan_fft_forward(segment),
            buffer: vec![Complex::new(0.0, 0.0); segment],
            pending: Vec::with_capacity(2 * segment),
            sum: vec![0.0; segment / 2],
            segments: 0,
        })
    }

    /// Take the next samples of the record.
    pub fn push(&mut self, samples: &[f64]) {
        for chunk in samples.chunks(self.segment) {
            self.pending.extend_from_slice(chunk);
            while self.pending.len() >= self.segment {
                self.transform();
                self.pending.drain(..self.segment / 2);
            }
        }
    }

    /// Add the segment at the head of `pending`.
    fn transform(&mut self) {
        let part = &self.pending[..self.segment];
        let mean = part.iter().sum::<f64>() / self.segment as f64;
        for ((b, x), w) in self.buffer.iter_mut().zip(part).zip(&self.window) {
            *b = Complex::new((x - mean) * w, 0.0);
        }
        self.fft.process(&mut self.buffer);
        for (s, b) in self.sum.iter_mut().zip(&self.buffer) {
            *s += b.norm_sqr();
        }
        self.segments += 1;
    }

    /// The estimate from the segments so far.
    pub fn psd(&self) -> Result<Psd> {
        if self.segments == 0 {
            return Err(Error::NotApplicable(format!(
                "the record is shorter than one Welch segment ({} samples)",
                self.segment
            )));
        }
        let power: f64 = self.window.iter().map(|w| w * w).sum();
        let scale = 2.0 / (self.rate_hz * power * self.segments as f64);
        Ok(Psd {
            freq_hz: (1..self.segment / 2)
                .map(|k| k as f64 * self.rate_hz / self.segment as f64)
                .collect(),
            density: self.sum[1..].iter().map(|s| s * scale).collect(),
            segments: self.segments,
        })
    }
}

/// The longest Welch segment.
pub const MAX_SEGMENT: usize = 1 << 24;

/// The thermal deflection PSD of a simple harmonic oscillator (one-sided, m²/Hz),
/// S_z(f) = (2k_BT/(πk f₀ Q)) / ((1 − f²/f₀²)² + f²/(f₀²Q²)) (Hutter & Bechhoefer
/// 1993); it integrates to k_BT/k.
pub fn sho_psd(
    freq_hz: f64,
    resonance_hz: f64,
    quality: f64,
    stiffness_n_m: f64,
    temperature_k: f64,
) -> f64 {
    let white = 2.0 * BOLTZMANN_J_K * temperature_k
        / (std::f64::consts::PI * stiffness_n_m * resonance_hz * quality);
    white / sho_denominator(freq_hz / resonance_hz, quality)
}

/// (1 − u²)² + u²/Q².
fn sho_denominator(u: f64, quality: f64) -> f64 {
    (1.0 - u * u).powi(2) + (u / quality).powi(2)
}

/// A thermal calibration: the fitted resonance and the spring constant it implies.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Calibration {
    /// Fitted resonance frequency, Hz.
    pub resonance_hz: f64,
    /// Fitted quality factor.
    pub quality: f64,
    /// The spring constant k_BT/⟨z²⟩, ⟨z²⟩ the fitted resonance's area, N/m.
    pub stiffness_n_m: f64,
    /// The fitted white level S_z(0), m²/Hz.
    pub low_frequency_m2_hz: f64,
    /// Bins fitted.
    pub bins: usize,
}

/// Fit the SHO thermal spectrum to `psd` (of a deflection in m) at temperature
/// `temperature_k` (Levenberg–Marquardt on the relative residuals P_k/S(f_k) − 1, unbiased
/// at the truth for a Welch estimate, over the bins within 20 linewidths of the
/// resonance, at most half its frequency away), starting from the highest bin and the
/// area under the estimate.
pub fn calibrate(psd: &Psd, temperature_k: f64) -> Result<Calibration> {
    let fail =
        |why: &str| Error::Numerical(format!("the thermal spectrum cannot be fitted: {why}"));
    let (peak, &top) = psd
        .density
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .ok_or_else(|| fail("no bins"))?;
    if !(top > 0.0 && top.is_finite()) {
        return Err(fail("no power in the record"));
    }
    let f0 = psd.freq_hz[peak];
    let df = psd.freq_hz[0];
    let area: f64 = psd.density.iter().sum::<f64>() * df;
    // S(f₀) = S(0)·Q², area = S(0)·πf₀Q/2.
    let q0 = (std::f64::consts::PI * f0 * top / (2.0 * area)).max(1.0);
    let white0 = top / (q0 * q0);
    let half = (20.0 * f0 / q0).min(0.5 * f0);
    let bins: Vec<(f64, f64)> = psd
        .freq_hz
        .iter()
        .zip(&psd.density)
        .filter(|(f, _)| (**f - f0).abs() <= half)
        .map(|(f, p)| (*f, *p))
        .collect();
    if bins.len() < 8 {
        return Err(fail(&format!(
            "only {} bins lie within the resonance (a longer segment resolves it)",
            bins.len()
        )));
    }
    let problem = ShoFit {
        bins: &bins,
        guess: (f0, q0, white0),
        p: Vector3::new(1.0, 1.0, 0.0),
    };
    let (fitted, report) = LevenbergMarquardt::new().minimize(problem);
    if !report.termination.was_successful() {
        return Err(fail(&format!("{:?}", report.termination)));
    }
    let (resonance_hz, quality, white) = fitted.physical();
    if !(resonance_hz > 0.0 && quality > 0.0 && white > 0.0) {
        return Err(fail("the fit left the physical range"));
    }
    Ok(Calibration {
        resonance_hz,
        quality,
        stiffness_n_m: 2.0 * BOLTZMANN_J_K * temperature_k
            / (std::f64::consts::PI * resonance_hz * quality * white),
        low_frequency_m2_hz: white,
        bins: bins.len(),
    })
}

/// The fit's problem: p = (f₀/f₀', Q/Q', ln(S₀/S₀')) around the guess (f₀', Q', S₀').
struct ShoFit<'a> {
    bins: &'a [(f64, f64)],
    guess: (f64, f64, f64),
    p: Vector3<f64>,
}

impl ShoFit<'_> {
    fn physical(&self) -> (f64, f64, f64) {
        (
            self.guess.0 * self.p[0],
            self.guess.1 * self.p[1],
            self.guess.2 * self.p[2].exp(),
        )
    }
}

impl LeastSquaresProblem<f64, Dyn, U3> for ShoFit<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, U3>;
    type ParameterStorage = Owned<f64, U3>;

    fn set_params(&mut self, p: &Vector3<f64>) {
        self.p = *p;
    }

    fn params(&self) -> Vector3<f64> {
        self.p
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let (f0, q, white) = self.physical();
        Some(DVector::from_iterator(
            self.bins.len(),
            self.bins
                .iter()
                .map(|&(f, p)| p * sho_denominator(f / f0, q) / white - 1.0),
        ))
    }

    fn jacobian(&self) -> Option<OMatrix<f64, Dyn, U3>> {
        let (f0, q, white) = self.physical();
        let mut j = OMatrix::<f64, Dyn, U3>::zeros(self.bins.len());
        for (row, &(f, p)) in self.bins.iter().enumerate() {
            let u = f / f0;
            let d = sho_denominator(u, q);
            // r = p·D/S₀ − 1: ∂r/∂θ = (p/S₀)·∂D/∂θ (S₀: −p·D/S₀ per unit of ln S₀).
            let dd_du = -4.0 * u * (1.0 - u * u) + 2.0 * u / (q * q);
            let dd_df0 = dd_du * (-u / f0);
            let dd_dq = -2.0 * u * u / (q * q * q);
            j[(row, 0)] = p / white * dd_df0 * self.guess.0;
            j[(row, 1)] = p / white * dd_dq * self.guess.1;
            j[(row, 2)] = -p * d / white;
        }
        Some(j)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welch_recovers_a_sine_and_white_noise_power() {
        // A sine of amplitude a has variance a²/2: the density's integral.
        let (rate, n) = (1024.0, 1 << 14);
        let a = 0.7;
        let x: Vec<f64> = (0..n)
            .map(|i| a * (2.0 * std::f64::consts::PI * 100.0 * i as f64 / rate).sin())
            .collect();
        let psd = welch(&x, rate, 1024).unwrap();
        let df = psd.freq_hz[0];
        let total: f64 = psd.density.iter().sum::<f64>() * df;
        assert!((total / (a * a / 2.0) - 1.0).abs() < 1e-3, "{total}");
        assert_eq!(psd.segments, 31);
    }

    #[test]
    fn the_sho_spectrum_integrates_to_equipartition() {
        let (f0, q, k, t) = (3e5, 50.0, 2.0, 300.0);
        // Trapezoids to 40 f₀ on a grid fine across the resonance, and the tail
        // ∫ S ≈ S(0)·f₀⁴/(3f³) beyond.
        let n = 4_000_000;
        let top = 40.0 * f0;
        let h = top / n as f64;
        let mut sum = 0.0;
        for i in 0..n {
            let (a, b) = (i as f64 * h, (i + 1) as f64 * h);
            sum += 0.5 * h * (sho_psd(a, f0, q, k, t) + sho_psd(b, f0, q, k, t));
        }
        let white = sho_psd(0.0, f0, q, k, t);
        sum += white * f0.powi(4) / (3.0 * top.powi(3));
        let kt_k = BOLTZMANN_J_K * t / k;
        assert!((sum / kt_k - 1.0).abs() < 1e-5, "{}", sum / kt_k);
    }
}
