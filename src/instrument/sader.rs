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
