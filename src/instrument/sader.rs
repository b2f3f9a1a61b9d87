//! Sader's method: the spring constant of a rectangular cantilever from its plan
//! dimensions and the resonance frequency and quality factor it shows in a fluid
//! (Sader, Chon & Mulvaney, Rev. Sci. Instrum. 70, 3967, 1999), through the fluid's
//! hydrodynamic function (Sader, J. Appl. Phys. 84, 64, 1998).

use crate::error::{Error, Result};
use rustfft::num_complex::Complex;

/// A fluid the cantilever resonates in.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Fluid {
    /// Density ρ_f, kg/m³.
    pub density_kg_m3: f64,
    /// Dynamic viscosity η, Pa·s.
    pub viscosity_pa_s: f64,
}

/// Air at 25 °C and 1 atm.
pub const AIR: Fluid = Fluid {
    density_kg_m3: 1.18,
    viscosity_pa_s: 1.86e-5,
};

/// Water at 25 °C.
pub const WATER: Fluid = Fluid {
    density_kg_m3: 997.0,
    viscosity_pa_s: 8.9e-4,
};

/// The Reynolds numbers over which Sader's correction Ω is fitted to the rectangular
/// beam's hydrodynamic function (to 0.1 %, Sader 1998).
pub const REYNOLDS_RANGE: (f64, f64) = (1e-6, 1e4);

/// The Reynolds number of a beam of width `width_m` oscillating at `omega_rad_s` in
/// `fluid`, Re = ρ_f ω b²/(4η) (Sader 1998, eq. 3).
pub fn reynolds(fluid: Fluid, width_m: f64, omega_rad_s: f64) -> f64 {
    fluid.density_kg_m3 * omega_rad_s * width_m * width_m / (4.0 * fluid.viscosity_pa_s)
}

/// e^z K_ν(z), the modified Bessel function of the second kind scaled, for complex z with
/// Re z > 0 and ν = 0 or 1: the trapezoidal rule on ∫₀^∞ exp(−z(cosh t − 1)) cosh(νt) dt
/// (Abramowitz & Stegun 9.6.24), with a step of 0.1 (the integrand is analytic in the
/// strip |Im t| < π/4 for arg z = −π/4: an error near e^{−2π(π/4)/0.1} ≈ 1e-21 of the
/// value), summed until the integrand is below 1e-20 of the sum.
pub fn bessel_k_scaled(nu: f64, z: Complex<f64>) -> Complex<f64> {
    const STEP: f64 = 0.05;
    let term = |t: f64| (-z * (t.cosh() - 1.0)).exp() * (nu * t).cosh();
    let mut sum = term(0.0) * 0.5;
    let mut t = STEP;
    loop {
        let f = term(t);
        sum += f;
        if f.norm() < 1e-20 * sum.norm() && z.re * (t.cosh() - 1.0) > nu * t + 46.0 {
            break;
        }
        t += STEP;
    }
    sum * STEP
}

/// The hydrodynamic function of a circular cylinder whose diameter is the beam's width,
/// Γ_circ(Re) = 1 + 4i K₁(−i√(iRe)) / (√(iRe) K₀(−i√(iRe))) (Sader 1998, eq. 18).
pub fn hydrodynamic_circular(reynolds: f64) -> Complex<f64> {
    let i = Complex::new(0.0, 1.0);
    let root = (i * reynolds).sqrt();
    let z = -i * root;
    let ratio = bessel_k_scaled(1.0, z) / bessel_k_scaled(0.0, z);
    1.0 + 4.0 * i * ratio / root
}

/// Sader's correction Ω(Re) from the cylinder's hydrodynamic function to the thin
/// rectangular beam's, rational functions of τ = log₁₀ Re (Sader 1998, eq. 21; 0.1 % over
/// [`REYNOLDS_RANGE`]).
pub fn rectangular_correction(reynolds: f64) -> Complex<f64> {
    let tau = reynolds.log10();
    let poly = |c: &[f64]| c.iter().rev().fold(0.0, |acc, a| acc * tau + a);
    let re = poly(&[
        0.91324, -0.48274, 0.46842, -0.12886, 0.044055, -0.0035117, 0.00069085,
    ]) / poly(&[
        1.0, -0.56964, 0.48690, -0.13444, 0.045155, -0.0035862, 0.00069085,
    ]);
    let im = poly(&[
        -0.024134,
        -0.029256,
        0.016294,
        -0.00010961,
        0.000064577,
        -0.000044510,
    ]) / poly(&[
        1.0, -0.59702, 0.55182, -0.18357, 0.079156, -0.014369, 0.0028361,
    ]);
    Complex::new(re, im)
}

/// The hydrodynamic function of a thin rectangular beam, Γ_rect(Re) = Ω(Re)·Γ_circ(Re)
/// (Sader 1998, eq. 20), over [`REYNOLDS_RANGE`].
pub fn hydrodynamic_rectangular(reynolds: f64) -> Result<Complex<f64>> {
    let (lo, hi) = REYNOLDS_RANGE;
    if !(lo..=hi).contains(&reynolds) {
        return Err(Error::OutOfRange(format!(
            "Sader's hydrodynamic function holds for Reynolds numbers from {lo:e} to {hi:e}, \
             not {reynolds:e}"
        )));
    }
    Ok(rectangular_correction(reynolds) * hydrodynamic_circular(reynolds))
}

/// A rectangular cantilever's plan: its length and width.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Plan {
    /// Length L, m.
    pub length_m: f64,
    /// Width b, m.
    pub width_m: f64,
}

/// Sader's spring constant, k = 0.1906 ρ_f b² L Q Γ_i(Re) ω_f² (Sader, Chon & Mulvaney
/// 1999, eq. 3), of a cantilever of plan `plan` resonating at `resonance_hz` with
/// quality `quality` in `fluid`; it holds for Q ≫ 1 and L/b > 3 or so.
pub fn sader_stiffness(plan: Plan, fluid: Fluid, resonance_hz: f64, quality: f64) -> Result<f64> {
    for (what, v) in [
        ("cantilever length", plan.length_m),
        ("cantilever width", plan.width_m),
        ("fluid density", fluid.density_kg_m3),
        ("fluid viscosity", fluid.viscosity_pa_s),
        ("resonance frequency", resonance_hz),
        ("quality factor", quality),
    ] {
        crate::error::positive(what, v)?;
    }
    let omega = 2.0 * std::f64::consts::PI * resonance_hz;
    let gamma = hydrodynamic_rectangular(reynolds(fluid, plan.width_m, omega))?;
    Ok(0.1906
        * fluid.density_kg_m3
        * plan.width_m.powi(2)
        * plan.length_m
        * quality
        * gamma.im
        * omega
        * omega)
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
