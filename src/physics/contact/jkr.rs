//! The JKR solution for a sphere on a flat in the paper's dimensionless variables,
//! equations (3)–(9).
//!
//! T̂ = T/(RΔγ) (tensile positive), α̂ = β²α/R = α/(με) (separation),
//! â = βa/R (contact radius), Ŵ = W/(μεRΔγ) (work).

use serde::Serialize;
use std::f64::consts::PI;

const SQRT_2PI: f64 = 2.506_628_274_631_000_7;

/// A point of the JKR curve: contact radius â, separation α̂, force T̂.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct JkrPoint {
    /// Contact radius â.
    pub a_hat: f64,
    /// Separation α̂.
    pub alpha_hat: f64,
    /// Force T̂ (tensile positive).
    pub t_hat: f64,
}

impl JkrPoint {
    /// The point of the JKR curve at contact radius `a_hat`, eq. (5).
    pub fn at(a_hat: f64) -> Self {
        Self {
            a_hat,
            alpha_hat: separation_hat(a_hat),
            t_hat: force_hat(a_hat),
        }
    }
}

/// Separation α̂(â) = √(2πâ) − â², eq. (5).
#[inline]
pub fn separation_hat(a_hat: f64) -> f64 {
    SQRT_2PI * a_hat.sqrt() - a_hat * a_hat
}

/// Force T̂(â) = √(8πâ³) − 4â³/3 (tensile positive), eq. (5).
#[inline]
pub fn force_hat(a_hat: f64) -> f64 {
    let a3 = a_hat * a_hat * a_hat;
    2.0 * SQRT_2PI * a3.sqrt() - 4.0 * a3 / 3.0
}

/// dα̂/dâ = √(2π)/(2√â) − 2â, the derivative of eq. (5).
#[inline]
pub fn d_separation_d_a(a_hat: f64) -> f64 {
    SQRT_2PI / (2.0 * a_hat.sqrt()) - 2.0 * a_hat
}

/// dT̂/dâ = 3√(2π)√â − 4â², the derivative of eq. (5).
#[inline]
pub fn d_force_d_a(a_hat: f64) -> f64 {
    3.0 * SQRT_2PI * a_hat.sqrt() - 4.0 * a_hat * a_hat
}

/// Indefinite work integral Ŵ(â) = 8â⁵/15 + πâ² − 4√(2πâ⁷)/3, eq. (6).
/// The work done along the curve from â₁ to â₂ is Ŵ(â₂) − Ŵ(â₁).
#[inline]
pub fn work_hat(a_hat: f64) -> f64 {
    let a2 = a_hat * a_hat;
    let a5 = a2 * a2 * a_hat;
    8.0 * a5 / 15.0 + PI * a2 - 4.0 * SQRT_2PI * (a5 * a2).sqrt() / 3.0
}

/// â_B = ∛(2π), eq. (8) (as a literal so hot paths need no cube root; a test checks it).
pub const A_HAT_B: f64 = 1.845_270_148_644_028_4;
/// â_C = π^{1/3}/2, eq. (8).
pub const A_HAT_C: f64 = 0.732_295_943_780_761_6;
/// α̂_C = 3π^{2/3}/4, eq. (8).
pub const ALPHA_HAT_C: f64 = 1.608_772_047_833_269_2;
/// T̂_C = 5π/6, eq. (8).
pub const T_HAT_C: f64 = 5.0 * PI / 6.0;

/// Jump-in point B under displacement control (α̂_B = 0): â_B = ∛(2π), T̂_B = 4π/3, eq. (8).
pub fn point_b() -> JkrPoint {
    JkrPoint::at(A_HAT_B)
}

/// Jump-out point C under displacement control (dα̂/dT̂ = 0): â_C = π^{1/3}/2,
/// α̂_C = 3π^{2/3}/4, T̂_C = 5π/6, eq. (8).
pub fn point_c() -> JkrPoint {
    JkrPoint {
        a_hat: A_HAT_C,
        alpha_hat: ALPHA_HAT_C,
        t_hat: T_HAT_C,
    }
}

/// Load-control pull-off point (dT̂/dâ = 0): â = (9π/8)^{1/3}, T̂ = 3π/2, the maximum
/// tensile force of eq. (5) (quoted after eq. (10) and in eq. (27)).
pub fn pull_off_point() -> JkrPoint {
    JkrPoint::at((9.0 * PI / 8.0).cbrt())
}

/// Load-control pull-off force T̂₀ = 3π/2 (eq. (27)).
pub const PULL_OFF_T_HAT: f64 = 1.5 * PI;

/// Hysteresis loss of one rigid-grip cycle, Ŵ_JKR = Ŵ(â_C) − Ŵ(â_B) = 7.092, eq. (9).
pub fn w_hat_jkr() -> f64 {
    work_hat(point_c().a_hat) - work_hat(point_b().a_hat)
}

/// Contact radius â on the stable (displacement-control) contact branch â ≥ â_C for a
/// given separation α̂ ≤ α̂_C: the larger positive root of the quartic
/// s⁴ − √(2π)s + α̂ = 0 in s = √â (eq. (5), as used in eq. (18)).
///
/// Closed form (Ferrari): the resolvent cubic y³ − α̂y − π/4 = 0 has one positive root,
/// written without cancellation, and s = (r + √(2√(2π)/r − 2y))/2 with r = √(2y).
/// Returns `None` for α̂ > α̂_C (no contact branch there) or a non-finite input.
#[inline]
pub fn a_hat_from_separation(alpha_hat: f64) -> Option<f64> {
    let q = alpha_hat;
    // Quartic s⁴ − p s + q with p = √(2π); resolvent y³ − q y − p²/8 = 0, p²/8 = π/4.
    let half_minus_q0 = PI / 8.0; // −Q/2 with Q = −p²/8
    let disc = half_minus_q0 * half_minus_q0 - q * q * q / 27.0;
    if !q.is_finite() || disc < -1e-13 {
        return None;
    }
    let c1 = (half_minus_q0 + disc.max(0.0).sqrt()).cbrt();
    let c2 = q / (3.0 * c1);
    // y = c1 + c2 = (c1³ + c2³)/(c1² − c1c2 + c2²), and c1³ + c2³ = p²/8.
    let y = (PI / 4.0) / (c1 * c1 - c1 * c2 + c2 * c2);
    let r = (2.0 * y).sqrt();
    let s = 0.5 * (r + (2.0 * SQRT_2PI / r - 2.0 * y).max(0.0).sqrt());
    Some(s * s)
}

/// Which root of T̂(â) = T̂ (eq. (5)) to return from [`a_hat_from_force`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ForceBranch {
    /// â ≥ â_pull-off: stable under load control (dT̂/dâ < 0).
    LoadStable,
    /// â ≤ â_pull-off: the small-contact side, which contains the displacement-control
    /// jump-out point C.
    SmallContact,
}

/// Contact radius â for a force T̂ ≤ 3π/2 on the chosen branch of eq. (5).
/// With u = â^{3/2}, eq. (5) is the quadratic T̂ = √(8π)u − 4u²/3.
/// Returns `None` for T̂ above the pull-off force or a non-finite input; on the
/// small-contact branch also for T̂ < 0 (it only reaches down to T̂ = 0 at â = 0).
#[inline]
pub fn a_hat_from_force(t_hat: f64, branch: ForceBranch) -> Option<f64> {
    let b = 2.0 * SQRT_2PI; // √(8π)
    let disc = b * b - 16.0 * t_hat / 3.0;
    if !t_hat.is_finite() || disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    let u = match branch {
        ForceBranch::LoadStable => 3.0 * (b + root) / 8.0,
        ForceBranch::SmallContact => {
            if t_hat < 0.0 {
                return None;
            }
            // (b − root) without cancellation: (b² − root²)/(b + root).
            3.0 * (16.0 * t_hat / 3.0) / (8.0 * (b + root))
        }
    };
    Some(u.powf(2.0 / 3.0))
}
