//! Finite support stiffness, equations (22)–(27): the support (e.g. a cantilever of
//! stiffness k̂ = μεk/(RΔγ)) is in series with the contact, so the support separation
//! is α̂_S = α̂ + T̂/k̂ (22) and both jumps happen where dα̂_S/dT̂ = 0 (23).

use super::hybrid::JumpIn;
use super::jkr::{self, JkrPoint};
use crate::error::{Result, positive};
use crate::numeric::bracketed_root;
use serde::Serialize;

const SQRT_2PI: f64 = 2.506_628_274_631_000_7;

/// Support separation α̂_S = α̂ + T̂/k̂ of a point of the contact curve, eq. (22).
#[inline]
pub fn support_separation_hat(point: &JkrPoint, k_hat: f64) -> f64 {
    point.alpha_hat + point.t_hat / k_hat
}

/// Jump-out point C with a support of stiffness k̂: the root of
/// (dα̂/dâ)/(dT̂/dâ) = −1/k̂ on the JKR curve, eq. (24). It lies between the rigid-grip
/// point â_C of (8) (k̂ → ∞) and the load-control pull-off point (k̂ → 0).
pub fn jump_out(k_hat: f64) -> Result<JkrPoint> {
    positive("k_hat", k_hat)?;
    // k̂·2s·dα̂/dâ + 2s·dT̂/dâ in s = √â: no division by small k̂.
    let f = |s: f64| {
        let s2 = s * s;
        k_hat * (SQRT_2PI - 4.0 * s2 * s) + 6.0 * SQRT_2PI * s2 - 8.0 * s2 * s2 * s
    };
    let lo = jkr::point_c().a_hat.sqrt();
    let hi = jkr::pull_off_point().a_hat.sqrt();
    let s = bracketed_root("spring jump-out (24)", f, lo, hi, 1e-15)?;
    Ok(JkrPoint::at(s * s))
}

/// Landing point B of a jump-in from (α̂_A, T̂ = 0): the point of the stable contact
/// branch (beyond the spring jump-out point `c`) with α̂ + T̂/k̂ = α̂_A, eqs. (22), (25).
/// `None` when α̂_A is not below the support separation at `c` (no hysteresis).
pub fn landing(alpha_hat_a: f64, k_hat: f64, c: &JkrPoint) -> Result<Option<JkrPoint>> {
    positive("k_hat", k_hat)?;
    if alpha_hat_a.is_nan() || alpha_hat_a >= support_separation_hat(c, k_hat) {
        return Ok(None);
    }
    // k̂(α̂_S − α̂_A): positive at C, decreasing to −∞ along the branch.
    let f = |a: f64| k_hat * (jkr::separation_hat(a) - alpha_hat_a) + jkr::force_hat(a);
    let mut hi = 2.0 * c.a_hat;
    while f(hi) > 0.0 {
        hi *= 2.0;
    }
    let a = bracketed_root("spring landing (22)", f, c.a_hat, hi, 1e-15)?;
    Ok(Some(JkrPoint::at(a)))
}

/// Hybrid hysteresis with a support of finite stiffness.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpringHysteresis {
    /// Tabor parameter μ, eq. (2).
    pub tabor_mu: f64,
    /// Dimensionless support stiffness k̂, eq. (22).
    pub k_hat: f64,
    /// Variant used for α̂_A.
    pub jump_in: JumpIn,
    /// Jump-in separation α̂_A (also the support separation at A and B).
    pub alpha_hat_a: Option<f64>,
    /// Landing point B on the contact branch (Fig. 5); `None` without hysteresis.
    pub landing: Option<JkrPoint>,
    /// Jump-out point C (24).
    pub jump_out: JkrPoint,
    /// Support separation α̂_S at C (and D), eq. (22).
    pub support_alpha_hat_c: f64,
    /// Loss per cycle, eq. (26); zero without hysteresis.
    pub w_hat: f64,
    /// Why the model predicts no hysteresis, when it does not.
    pub no_hysteresis_reason: Option<String>,
}

/// Hybrid loss with a finite support stiffness,
/// Ŵ = (Ŵ(â_C) − Ŵ(â_B)) + (T̂_C² − T̂_B²)/(2k̂), eq. (26), with B from (22) and C from (24).
pub fn hysteresis(tabor_mu: f64, k_hat: f64, jump_in: JumpIn) -> Result<SpringHysteresis> {
    positive("k_hat", k_hat)?;
    let alpha_hat_a = jump_in.alpha_hat_a(tabor_mu)?;
    let c = jump_out(k_hat)?;
    let support_alpha_hat_c = support_separation_hat(&c, k_hat);
    let landing = match alpha_hat_a {
        Some(a) => landing(a, k_hat, &c)?,
        None => None,
    };
    let w_hat = landing.map_or(0.0, |b| {
        jkr::work_hat(c.a_hat) - jkr::work_hat(b.a_hat)
            + (c.t_hat * c.t_hat - b.t_hat * b.t_hat) / (2.0 * k_hat)
    });
    let no_hysteresis_reason = match (alpha_hat_a, landing) {
        (_, Some(_)) => None,
        (None, _) => Some(format!(
            "no jump-in instability at mu = {tabor_mu:.4} with the {jump_in} jump-in: \
             no hysteresis"
        )),
        (Some(a), None) => Some(format!(
            "jump-in separation alpha_hat_A = {a:.4} is not below the support separation \
             at jump-out, {support_alpha_hat_c:.4}, at k_hat = {k_hat:.4}: no hysteresis"
        )),
    };
    Ok(SpringHysteresis {
        tabor_mu,
        k_hat,
        jump_in,
        alpha_hat_a,
        landing,
        jump_out: c,
        support_alpha_hat_c,
        w_hat,
        no_hysteresis_reason,
    })
}

/// Soft-support asymptote Ŵ → T̂₀²/(2k̂) with T̂₀ = 3π/2, eq. (27).
#[inline]
pub fn w_hat_soft_limit(k_hat: f64) -> f64 {
    jkr::PULL_OFF_T_HAT * jkr::PULL_OFF_T_HAT / (2.0 * k_hat)
}
