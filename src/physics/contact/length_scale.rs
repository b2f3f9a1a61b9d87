//! The adhesive length scale s₀, equations (19)–(21).

use std::f64::consts::PI;

/// B = 16/(9√3) ≈ 1.0264 in the peak Lennard-Jones traction σ₀ = BΔγ/ε, eq. (19).
pub fn lj_peak_traction_coeff() -> f64 {
    16.0 / (9.0 * 3f64.sqrt())
}

/// s₀ = E*ε²/(πΔγ) in metres, eq. (20) (with B ≈ 1, as the paper takes it).
pub fn s0_m(modulus_pa: f64, range_m: f64, work_of_adhesion_j_m2: f64) -> f64 {
    modulus_pa * range_m * range_m / (PI * work_of_adhesion_j_m2)
}

/// Ratio a/s₀ of a contact radius to the adhesive length scale, from its dimensionless
/// contact radius: a/s₀ = π â μ², eqs. (2)–(4), (20).
#[inline]
pub fn contact_radius_over_s0(a_hat: f64, tabor_mu: f64) -> f64 {
    PI * a_hat * tabor_mu * tabor_mu
}

/// The JKR pull-off criterion a_C/s₀ ≫ 1 rewritten as μ² ≫ 2/π^{4/3} ≈ 0.44, eq. (21).
pub fn pull_off_criterion_mu_squared() -> f64 {
    2.0 / PI.powf(4.0 / 3.0)
}
