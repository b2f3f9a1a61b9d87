//! The thermal spectrum of a cantilever and its calibration: Welch's estimate of a
//! record's power spectral density, the simple harmonic oscillator's thermal spectrum,
//! and the fit of one to the other from which Hutter & Bechhoefer (RSI 64, 1868, 1993)
//! calibrate the spring constant, k = k_BT/⟨z²⟩, ⟨z²⟩ the area under the fitted
//! resonance.

use crate::dynamics::grazing::BOLTZMANN_J_K;
use crate::error::{Error, Result};
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DVector, Dyn, OMatrix, Owned, U4, Vector4};
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
    /// The window each segment was multiplied by.
    pub window: SpectralWindow,
}

/// The window of a spectral estimate's segments, which sets how its neighbouring bins
/// correlate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[cfg_attr(feature = "app", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum SpectralWindow {
    /// Hann's (tapsim's, and most instruments'): the Fourier coefficients of
    /// neighbouring bins correlate by −2/3 (next-but-one 1/6), their powers by 4/9 and
    /// 1/36.
    #[default]
    Hann,
    /// None (a rectangular window): bins independent.
    Rectangular,
}

impl SpectralWindow {
    /// The factor by which a fit's errors exceed those of independent bins,
    /// √(1 + 2Σρ_j²) over the bins' power correlations ρ_j² (the variance of a smooth
    /// model fitted to a sum of correlated bins): √(35/18) = 1.394 for Hann's window.
    pub fn error_factor(self) -> f64 {
        match self {
            SpectralWindow::Hann => (1.0 + 2.0 * (4.0 / 9.0 + 1.0 / 36.0f64)).sqrt(),
            SpectralWindow::Rectangular => 1.0,
        }
    }
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
            window: SpectralWindow::Hann,
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

/// A thermal calibration: the fitted resonance, the spring constant it implies, and
/// their standard errors.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Calibration {
    /// Fitted resonance frequency, Hz.
    pub resonance_hz: f64,
    /// Its standard error, Hz.
    pub resonance_sd_hz: f64,
    /// Fitted quality factor.
    pub quality: f64,
    /// Its standard error.
    pub quality_sd: f64,
    /// The spring constant k_BT/⟨z²⟩, ⟨z²⟩ the fitted resonance's area, N/m.
    pub stiffness_n_m: f64,
    /// Its standard error, N/m.
    pub stiffness_sd_n_m: f64,
    /// The fitted resonance's white level S_z(0), m²/Hz.
    pub low_frequency_m2_hz: f64,
    /// The fitted white background beneath the resonance (detector noise), m²/Hz.
    pub background_m2_hz: f64,
    /// Its standard error, m²/Hz.
    pub background_sd_m2_hz: f64,
    /// The scatter of the bins about the fit, the rms of P/S − 1 (1/√M for a Welch
    /// estimate of M independent segments).
    pub scatter: f64,
    /// Bins fitted.
    pub bins: usize,
}

/// Fit the SHO thermal spectrum over a white background, S(f) = S₀/((1 − f²/f₀²)² +
/// f²/(f₀²Q²)) + B, to `psd` (of a deflection in m) at temperature `temperature_k`, and
/// calibrate k = 2k_BT/(πf₀QS₀) = k_BT/⟨z²⟩ (Hutter & Bechhoefer, RSI 64, 1868, 1993).
///
/// Each bin of a Welch estimate scatters by the same fraction about its mean (a χ²
/// variate of 2M degrees of freedom over M segments), so the fit weighs the residuals
/// P_k − S(f_k) by 1/S(f_k): Levenberg–Marquardt with the weights held, repeated with
/// the weights of the last fit until it stands still, solves the maximum-likelihood
/// equations Σ (P_k − S_k)/S_k² ∂S_k = 0 — unbiased, where least squares on P_k/S_k − 1
/// would raise S by the fraction 1/M. Over the bins within 20 linewidths of the
/// resonance (at most half its frequency away), started from the highest bin, the
/// half-maximum width around it and the median level nearby. The standard errors are
/// the fit's covariance, s²(JᵀJ)⁻¹ with s² the relative residuals' mean square,
/// widened by the correlation of neighbouring bins that the spectrum's window makes
/// ([`SpectralWindow::error_factor`]).
pub fn calibrate(psd: &Psd, temperature_k: f64) -> Result<Calibration> {
    if psd.freq_hz.len() != psd.density.len() || psd.freq_hz.len() < 8 {
        return Err(fail("fewer than 8 bins"));
    }
    let (peak, &top) = psd
        .density
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .ok_or_else(|| fail("no bins"))?;
    if !(top > 0.0 && top.is_finite()) {
        return Err(fail("no power in the spectrum"));
    }
    let f0 = psd.freq_hz[peak];
    // The level away from the resonance: the median over 0.5–1.5 f₀ (the background
    // plus a few times S₀ of the resonance's tails).
    let mut around: Vec<f64> = psd
        .freq_hz
        .iter()
        .zip(&psd.density)
        .filter(|(f, _)| (**f / f0 - 1.0).abs() <= 0.5)
        .map(|(_, p)| *p)
        .collect();
    around.sort_by(f64::total_cmp);
    let level = around[around.len() / 2];
    // The half-maximum width, over a running mean of 5 bins.
    let smooth = |i: usize| {
        let lo = i.saturating_sub(2);
        let hi = (i + 3).min(psd.density.len());
        psd.density[lo..hi].iter().sum::<f64>() / (hi - lo) as f64
    };
    // The highest bin of a noisy estimate stands above the resonance: the smoothed
    // peak sets the half maximum.
    let (peak, crest) = (0..psd.density.len())
        .map(|i| (i, smooth(i)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((peak, top));
    let f0 = psd.freq_hz[peak];
    let half = level + 0.5 * (crest - level);
    let mut lo = peak;
    while lo > 0 && smooth(lo) > half {
        lo -= 1;
    }
    let mut hi = peak;
    while hi + 1 < psd.density.len() && smooth(hi) > half {
        hi += 1;
    }
    let width = (psd.freq_hz[hi] - psd.freq_hz[lo]).max(psd.freq_hz[1] - psd.freq_hz[0]);
    let q0 = (f0 / width).max(1.0);
    let white0 = (crest - level).max(0.0) / (q0 * q0);
    if white0 <= 0.0 {
        return Err(fail("no resonance stands above the background"));
    }
    // A first fit over the window the guess sets, a second over the one the first sets.
    let first = fit_window(psd, (f0, q0, white0), (level / white0 - 4.0).max(0.0))?;
    let (f1, q1, s1, b1) = first.physical();
    let fitted = fit_window(psd, (f1, q1.abs(), s1), b1 / s1)?;
    let (resonance_hz, quality, white, background) = fitted.physical();
    let quality = quality.abs();
    let (f0, q0, white0) = fitted.guess;
    let residuals = fitted.residuals().ok_or_else(|| fail("no residuals"))?;
    let jacobian = fitted.jacobian().ok_or_else(|| fail("no Jacobian"))?;
    let dof = fitted.bins.len() - 4;
    let s2 = residuals.norm_squared() / dof as f64;
    let covariance = (jacobian.transpose() * &jacobian)
        .try_inverse()
        .ok_or_else(|| fail("the fit's parameters are not determined"))?
        * (s2 * psd.window.error_factor().powi(2));
    let p = fitted.p;
    // ln k = const − ln f₀ − ln Q − ln S₀.
    let dlnk = Vector4::new(-1.0 / p[0], -1.0 / p[1].abs(), -1.0, 0.0);
    let var_lnk = (dlnk.transpose() * covariance * dlnk)[0];
    let stiffness_n_m = 2.0 * BOLTZMANN_J_K * temperature_k
        / (std::f64::consts::PI * resonance_hz * quality * white);
    let sd = |i: usize, scale: f64| scale * covariance[(i, i)].max(0.0).sqrt();
    let out = Calibration {
        resonance_hz,
        resonance_sd_hz: sd(0, f0),
        quality,
        quality_sd: sd(1, q0),
        stiffness_n_m,
        stiffness_sd_n_m: stiffness_n_m * var_lnk.max(0.0).sqrt(),
        low_frequency_m2_hz: white,
        background_m2_hz: background,
        background_sd_m2_hz: sd(3, white0),
        scatter: s2.sqrt(),
        bins: fitted.bins.len(),
    };
    let finite = [
        out.resonance_sd_hz,
        out.quality_sd,
        out.stiffness_n_m,
        out.stiffness_sd_n_m,
        out.background_m2_hz,
    ]
    .iter()
    .all(|v| v.is_finite());
    if !(resonance_hz > 0.0 && quality > 0.0 && white > 0.0 && finite) {
        return Err(fail("the fit left the physical range"));
    }
    Ok(out)
}

/// The weighted fit ([`calibrate`]) over the bins within 20 linewidths of the guess's
/// resonance (at most half its frequency away), from the guess (f₀', Q', S₀') and the
/// background `background` S₀'.
fn fit_window(psd: &Psd, guess: (f64, f64, f64), background: f64) -> Result<ShoFit> {
    let (f0, q0, _) = guess;
    let reach = (20.0 * f0 / q0).min(0.5 * f0);
    let bins: Vec<(f64, f64)> = psd
        .freq_hz
        .iter()
        .zip(&psd.density)
        .filter(|(f, _)| (**f - f0).abs() <= reach)
        .map(|(f, p)| (*f, *p))
        .collect();
    if bins.len() < 16 {
        return Err(fail(&format!(
            "only {} bins lie within the resonance (a finer frequency resolution resolves \
             it)",
            bins.len()
        )));
    }
    let mut fitted = ShoFit {
        bins,
        guess,
        p: Vector4::new(1.0, 1.0, 0.0, background),
        weights: Vec::new(),
    };
    for _ in 0..MAX_REWEIGHTINGS {
        let before = fitted.p;
        fitted.weights = fitted.model();
        if fitted.weights.iter().any(|w| !(*w > 0.0 && w.is_finite())) {
            return Err(fail("the fit left the physical range"));
        }
        let (after, report) = LevenbergMarquardt::new().minimize(fitted);
        if !report.termination.was_successful() {
            return Err(fail(&format!("{:?}", report.termination)));
        }
        fitted = after;
        if (fitted.p - before).amax() < 1e-10 {
            return Ok(fitted);
        }
    }
    Err(fail("the weighted fit does not settle"))
}

/// Why the thermal spectrum cannot be fitted.
fn fail(why: &str) -> Error {
    Error::Numerical(format!("the thermal spectrum cannot be fitted: {why}"))
}

/// The most passes of the weighted fit.
const MAX_REWEIGHTINGS: usize = 30;

/// The fit's problem: p = (f₀/f₀', Q/Q', ln(S₀/S₀'), B/S₀') around the guess
/// (f₀', Q', S₀'), the residuals (P_k − S_k)/w_k.
struct ShoFit {
    bins: Vec<(f64, f64)>,
    guess: (f64, f64, f64),
    p: Vector4<f64>,
    weights: Vec<f64>,
}

impl ShoFit {
    /// S(f_k) at each bin.
    fn model(&self) -> Vec<f64> {
        let (f0, q, white, background) = self.physical();
        self.bins
            .iter()
            .map(|&(f, _)| white / sho_denominator(f / f0, q) + background)
            .collect()
    }

    fn physical(&self) -> (f64, f64, f64, f64) {
        (
            self.guess.0 * self.p[0],
            self.guess.1 * self.p[1],
            self.guess.2 * self.p[2].exp(),
            self.guess.2 * self.p[3],
        )
    }
}

impl LeastSquaresProblem<f64, Dyn, U4> for ShoFit {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, U4>;
    type ParameterStorage = Owned<f64, U4>;

    fn set_params(&mut self, p: &Vector4<f64>) {
        self.p = *p;
    }

    fn params(&self) -> Vector4<f64> {
        self.p
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let (f0, q, white, background) = self.physical();
        Some(DVector::from_iterator(
            self.bins.len(),
            self.bins
                .iter()
                .zip(&self.weights)
                .map(|(&(f, p), w)| (p - white / sho_denominator(f / f0, q) - background) / w),
        ))
    }

    fn jacobian(&self) -> Option<OMatrix<f64, Dyn, U4>> {
        let (f0, q, white, _) = self.physical();
        let mut j = OMatrix::<f64, Dyn, U4>::zeros(self.bins.len());
        for (row, (&(f, _), w)) in self.bins.iter().zip(&self.weights).enumerate() {
            let u = f / f0;
            let d = sho_denominator(u, q);
            // r = (P − S)/w: ∂r/∂θ = −∂S/∂θ / w, ∂S/∂θ = −(S₀/D²)·∂D/∂θ for f₀ and Q.
            let dd_du = -4.0 * u * (1.0 - u * u) + 2.0 * u / (q * q);
            let dd_df0 = dd_du * (-u / f0);
            let dd_dq = -2.0 * u * u / (q * q * q);
            let g = white / (d * d) / w;
            j[(row, 0)] = g * dd_df0 * self.guess.0;
            j[(row, 1)] = g * dd_dq * self.guess.1;
            j[(row, 2)] = -white / d / w;
            j[(row, 3)] = -self.guess.2 / w;
        }
        Some(j)
    }
}
