//! Tests of `tapsim::instrument::sader` (src/instrument/sader.rs).

use rustfft::num_complex::Complex;
use tapsim::instrument::sader::*;

/// K_ν by its power series (A&S 9.6.13 and 9.6.11), for small |z|.
fn series(nu: u32, z: Complex<f64>) -> Complex<f64> {
    const EULER: f64 = 0.577_215_664_901_532_9;
    let q = z * z / 4.0;
    let log = (z / 2.0).ln();
    let (mut sum, mut term) = (Complex::new(0.0, 0.0), Complex::new(1.0, 0.0));
    let mut harmonic = 0.0;
    if nu == 0 {
        // K₀ = −(ln(z/2) + γ) I₀ + Σ_{k≥1} H_k (z²/4)^k/(k!)².
        let mut i0 = Complex::new(1.0, 0.0);
        for k in 1..80 {
            term *= q / (k * k) as f64;
            harmonic += 1.0 / k as f64;
            i0 += term;
            sum += term * harmonic;
        }
        -(log + EULER) * i0 + sum
    } else {
        // K₁ = 1/z + ln(z/2) I₁ − (z/4) Σ_{k≥0} (ψ(k+1) + ψ(k+2)) (z²/4)^k/(k!(k+1)!).
        let mut i1 = z / 2.0;
        let psi = |n: f64| -EULER + n;
        let mut h_next = 1.0;
        sum += term * (psi(0.0) + psi(h_next));
        for k in 1..80 {
            term *= q / (k * (k + 1)) as f64;
            harmonic += 1.0 / k as f64;
            h_next += 1.0 / (k + 1) as f64;
            i1 += z / 2.0 * term;
            sum += term * (psi(harmonic) + psi(h_next));
        }
        1.0 / z + log * i1 - z / 4.0 * sum
    }
}

/// e^z K_ν by its asymptotic expansion (A&S 9.7.2), for large |z|, to its smallest
/// term.
fn asymptotic(nu: u32, z: Complex<f64>) -> Complex<f64> {
    let mu = 4.0 * (nu * nu) as f64;
    let (mut sum, mut term) = (Complex::new(1.0, 0.0), Complex::new(1.0, 0.0));
    // Summed to its smallest term (near k = 2|z|).
    for k in 1..200 {
        let odd = (2 * k - 1) as f64;
        let next = term * (mu - odd * odd) / (k as f64 * 8.0) / z;
        if next.norm() > term.norm() {
            break;
        }
        term = next;
        sum += term;
    }
    (std::f64::consts::PI / (2.0 * z)).sqrt() * sum
}

/// The trapezoidal integral meets the power series at small |z| and the asymptotic
/// expansion at large, on the ray arg z = −π/4 that Sader's function takes, within
/// 1e-12.
#[test]
fn bessel_k_meets_its_series_and_its_asymptotic_expansion() {
    let ray = Complex::from_polar(1.0, -std::f64::consts::FRAC_PI_4);
    for r in [1e-3, 0.1, 1.0, 2.0] {
        let z = ray * r;
        for nu in [0, 1] {
            let got = bessel_k_scaled(nu as f64, z) * (-z).exp();
            let want = series(nu, z);
            assert!(
                (got / want - 1.0).norm() < 1e-12,
                "K{nu}({z}): {got} vs {want}"
            );
        }
    }
    for r in [40.0, 100.0] {
        let z = ray * r;
        for nu in [0, 1] {
            let got = bessel_k_scaled(nu as f64, z);
            let want = asymptotic(nu, z);
            assert!(
                (got / want - 1.0).norm() < 1e-12,
                "K{nu}({z}): {got} vs {want}"
            );
        }
    }
}

/// At large Reynolds numbers the cylinder's Γ tends to 1 + 4e^{iπ/4}/√Re (the
/// boundary layer's limit, K₁/K₀ → 1), and the correction Ω to 1 (the thin beam and
/// the cylinder alike in inviscid flow: Γ_r → 1).
#[test]
fn the_hydrodynamic_function_reaches_its_inviscid_limit() {
    let re: f64 = 1e8;
    let g = hydrodynamic_circular(re);
    let limit = 1.0 + 4.0 * Complex::from_polar(1.0, std::f64::consts::FRAC_PI_4) / re.sqrt();
    assert!(
        (g - limit).norm() < 1e-3 * (limit - 1.0).norm(),
        "{g} vs {limit}"
    );
    let omega = rectangular_correction(1e4);
    assert!(
        (omega.re - 1.0).abs() < 0.05 && omega.im.abs() < 0.01,
        "{omega}"
    );
}

/// Beam theory closes the loop (Euler–Bernoulli, independent of Sader's formula): a
/// silicon lever 125 × 30 × 4 µm in air has k = Ebh³/(4L³); its vacuum resonance
/// (1.8751²/L²)√(EI/μ), lowered in air by the fluid's added mass
/// (ω_f = ω_vac/√(1 + πρb²Γ_r/(4μ))) and damped to Q = (4μ/(πρb²) + Γ_r)/Γ_i (Sader
/// 1998, eqs. 14 and 15), give Sader's k back within 0.1 % (the 0.1906 = 0.2427π/4
/// of the formula against beam theory's 1.8751⁴/12·0.2427 = 1.0003).
#[test]
fn sader_returns_the_beam_theory_stiffness() {
    let (e, rho_c, l, b, h): (f64, f64, f64, f64, f64) = (169e9, 2330.0, 125e-6, 30e-6, 4e-6);
    let k_beam = e * b * h.powi(3) / (4.0 * l.powi(3));
    let mu = rho_c * b * h;
    let inertia = b * h.powi(3) / 12.0;
    let omega_vac = 1.875_104_f64.powi(2) / (l * l) * (e * inertia / mu).sqrt();
    let added = |omega: f64| {
        let g = hydrodynamic_rectangular(reynolds(AIR, b, omega)).unwrap();
        (
            g,
            std::f64::consts::PI * AIR.density_kg_m3 * b * b / (4.0 * mu),
        )
    };
    let mut omega = omega_vac;
    for _ in 0..50 {
        let (g, m) = added(omega);
        omega = omega_vac / (1.0 + m * g.re).sqrt();
    }
    let (g, m) = added(omega);
    let quality = (1.0 / m + g.re) / g.im;
    let f = omega / (2.0 * std::f64::consts::PI);
    let k = sader_stiffness(
        Plan {
            length_m: l,
            width_m: b,
        },
        AIR,
        f,
        quality,
    )
    .unwrap();
    eprintln!("f {f} Hz, Q {quality}, k {k} vs {k_beam}");
    assert!((k / k_beam - 1.0).abs() < 1e-3, "{k} vs {k_beam}");
}
