//! Greenwood's semi-rigid theory of the jump into contact, equations (11)–(17).
//!
//! Tractions are those of the Lennard-Jones law (10) between a *rigid* sphere and a
//! rigid plane at central gap h̄₀ = h₀/ε; their elastic displacement u(0) is then added
//! to the separation. The jump-in point A is where dα/dh̄₀ = 0 (15).

use crate::error::{Error, Result, positive};
use crate::numeric::bracketed_root;
use serde::Serialize;
use std::f64::consts::PI;

/// Coefficient 2145/4096 of the eighth-power term in eqs. (13), (14).
pub const EIGHTH_POWER_COEFF: f64 = 2145.0 / 4096.0;

/// Coefficient 0.95 · 7/5^{5/7} (π²/2)^{1/7} of the curve fit, eq. (17), as printed.
pub const FIT_COEFF: f64 = 2.6460;

/// Whether the eighth-power (repulsive) term of eqs. (13), (14) is kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EighthPower {
    /// Full expressions (13), (14).
    Keep,
    /// Drop the h̄₀⁻⁸ term, as the paper does to reach (16).
    Drop,
}

/// Rigid-body force T̂(h̄₀) = (8π/3)(1/h̄₀² − 1/(4h̄₀⁸)) (tensile positive), eq. (12).
#[inline]
pub fn force_hat(h0_bar: f64) -> f64 {
    let h2 = h0_bar * h0_bar;
    let h8 = h2 * h2 * h2 * h2;
    8.0 * PI / 3.0 * (1.0 / h2 - 0.25 / h8)
}

/// Central elastic displacement u(0)/ε = π√(2μ³/h̄₀)(1/h̄₀² − 2145/(4096h̄₀⁸)), eq. (13).
#[inline]
pub fn central_displacement_over_range(h0_bar: f64, tabor_mu: f64, eighth: EighthPower) -> f64 {
    let h2 = h0_bar * h0_bar;
    let repulsive = match eighth {
        EighthPower::Keep => EIGHTH_POWER_COEFF / (h2 * h2 * h2 * h2),
        EighthPower::Drop => 0.0,
    };
    PI * (2.0 * tabor_mu.powi(3) / h0_bar).sqrt() * (1.0 / h2 - repulsive)
}

/// Separation α/ε = h̄₀ − 1 + u(0)/ε, eq. (14).
#[inline]
#[doc(hidden)]
pub fn separation_over_range(h0_bar: f64, tabor_mu: f64, eighth: EighthPower) -> f64 {
    h0_bar - 1.0 + central_displacement_over_range(h0_bar, tabor_mu, eighth)
}

/// dα/dh̄₀ of eq. (14) divided by ε: the quantity set to zero in eq. (15).
#[inline]
pub fn d_separation_d_h0(h0_bar: f64, tabor_mu: f64, eighth: EighthPower) -> f64 {
    let scale = PI * (2.0 * tabor_mu.powi(3)).sqrt();
    let attract = -2.5 * h0_bar.powf(-3.5);
    let repulse = match eighth {
        EighthPower::Keep => 8.5 * EIGHTH_POWER_COEFF * h0_bar.powf(-9.5),
        EighthPower::Drop => 0.0,
    };
    1.0 + scale * (attract + repulse)
}

/// Jump-in state at the turning point A of the semi-rigid curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SemiRigidJumpIn {
    /// Central gap h̄₀ = h₀/ε at A.
    pub h0_bar: f64,
    /// Separation α̂_A = α_A/(με).
    pub alpha_hat: f64,
    /// Rigid-body attraction T̂ at A, eq. (12).
    pub t_hat: f64,
}

/// Exact turning point A of eq. (14): the largest root of dα/dh̄₀ = 0 (15), found
/// numerically. `Ok(None)` when there is no turning point (small μ: no jump-in
/// instability in the semi-rigid theory).
///
/// With the eighth-power term dα/dh̄₀ has a single minimum, at h̄₀⁶ = 323·(2145/4096)/35
/// independent of μ; A is the root above it. Without it, dα/dh̄₀ is increasing and
/// has exactly one root.
pub fn jump_in_exact(tabor_mu: f64, eighth: EighthPower) -> Result<Option<SemiRigidJumpIn>> {
    positive("Tabor parameter mu", tabor_mu)?;
    let g = |h: f64| d_separation_d_h0(h, tabor_mu, eighth);
    // Upper bracket: the closed-form root of the eighth-power-free condition, where the
    // full dα/dh̄₀ is positive; pushed up until positive in any case.
    let mut hi = (5.0 * PI / 2f64.sqrt() * tabor_mu.powf(1.5)).powf(2.0 / 7.0);
    while g(hi) <= 0.0 {
        hi *= 2.0;
    }
    let lo = match eighth {
        EighthPower::Keep => {
            let h_min = (323.0 * EIGHTH_POWER_COEFF / 35.0).powf(1.0 / 6.0);
            if g(h_min) >= 0.0 {
                return Ok(None);
            }
            h_min
        }
        EighthPower::Drop => {
            let mut lo = hi;
            while g(lo) >= 0.0 {
                lo *= 0.5;
                if lo < 1e-300 {
                    return Err(Error::Numerical(
                        "semi-rigid turning point not bracketed".into(),
                    ));
                }
            }
            lo
        }
    };
    let h0_bar = bracketed_root("semi-rigid jump-in (15)", g, lo, hi, 1e-15)?;
    Ok(Some(SemiRigidJumpIn {
        h0_bar,
        alpha_hat: separation_over_range(h0_bar, tabor_mu, eighth) / tabor_mu,
        t_hat: force_hat(h0_bar),
    }))
}

/// Closed-form jump-in separation without the eighth-power term,
/// α̂_A = 7/5^{5/7} (π²/2)^{1/7} μ^{-4/7} − 1/μ, eq. (16).
#[inline]
pub fn alpha_hat_a_closed_form(tabor_mu: f64) -> f64 {
    closed_form_coeff() * tabor_mu.powf(-4.0 / 7.0) - 1.0 / tabor_mu
}

/// The coefficient 7/5^{5/7} (π²/2)^{1/7} ≈ 2.7855 of eq. (16).
pub fn closed_form_coeff() -> f64 {
    7.0 / 5f64.powf(5.0 / 7.0) * (PI * PI / 2.0).powf(1.0 / 7.0)
}

/// Curve fit to the numerical jump-in separation, α̂_A = 2.6460 μ^{-4/7} − 1/μ, eq. (17)
/// (the paper: better than 0.4 % for μ > 2).
#[inline]
pub fn alpha_hat_a_fit(tabor_mu: f64) -> f64 {
    FIT_COEFF * tabor_mu.powf(-4.0 / 7.0) - 1.0 / tabor_mu
}
