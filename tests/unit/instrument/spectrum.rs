//! Tests of `tapsim::instrument::spectrum` (src/instrument/spectrum.rs).

use tapsim::dynamics::grazing::BOLTZMANN_J_K;
use tapsim::instrument::spectrum::*;

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
