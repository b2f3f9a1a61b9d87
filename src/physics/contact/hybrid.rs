//! The paper's "hybrid" theory of the hysteresis loss, eq. (18): Greenwood's
//! semi-rigid jump-in (16)/(17) combined with the JKR contact branch and jump-out (5)–(9).

use super::jkr::{self, JkrPoint};
use super::semi_rigid::{self, EighthPower};
use crate::error::{Result, positive};
use crate::numeric::bracketed_root;
use serde::Serialize;
use std::fmt;

/// How the jump-in separation α̂_A is obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[cfg_attr(feature = "app", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum JumpIn {
    /// The curve fit to the numerical solution, eq. (17) (the paper's choice).
    #[default]
    Fit,
    /// The closed form without the eighth-power term, eq. (16).
    ClosedForm,
    /// The exact turning point of the full semi-rigid separation (14), eq. (15).
    SemiRigid,
}

impl fmt::Display for JumpIn {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            JumpIn::Fit => "fit (17)",
            JumpIn::ClosedForm => "closed form (16)",
            JumpIn::SemiRigid => "semi-rigid turning point (14)-(15)",
        })
    }
}

impl JumpIn {
    /// Jump-in separation α̂_A(μ) by this variant; `Ok(None)` where the variant has
    /// no jump-in instability (semi-rigid (14) at μ ≲ 0.5) or μ lies below the maximum
    /// of the power law (16)/(17), where that law no longer describes a jump-in.
    pub fn alpha_hat_a(self, tabor_mu: f64) -> Result<Option<f64>> {
        positive("Tabor parameter mu", tabor_mu)?;
        let power_law = |coeff: f64, value: f64| {
            // dα̂_A/dμ = 0 at μ = (7/(4·coeff))^{7/3}: below that the law rises with μ.
            let mu_peak = (7.0 / (4.0 * coeff)).powf(7.0 / 3.0);
            (tabor_mu > mu_peak).then_some(value)
        };
        Ok(match self {
            JumpIn::Fit => power_law(semi_rigid::FIT_COEFF, semi_rigid::alpha_hat_a_fit(tabor_mu)),
            JumpIn::ClosedForm => power_law(
                semi_rigid::closed_form_coeff(),
                semi_rigid::alpha_hat_a_closed_form(tabor_mu),
            ),
            JumpIn::SemiRigid => {
                semi_rigid::jump_in_exact(tabor_mu, EighthPower::Keep)?.map(|a| a.alpha_hat)
            }
        })
    }
}

/// Hybrid hysteresis under displacement control (rigid support).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HybridHysteresis {
    /// Tabor parameter μ, eq. (2).
    pub tabor_mu: f64,
    /// Variant used for α̂_A.
    pub jump_in: JumpIn,
    /// Jump-in separation α̂_A; `None` where there is no jump-in instability.
    pub alpha_hat_a: Option<f64>,
    /// Landing point on the JKR contact branch at α̂ = α̂_A (â_A of eq. (18)); `None`
    /// when there is no hysteresis.
    pub landing: Option<JkrPoint>,
    /// Dimensionless loss per cycle Ŵ = Ŵ(â_C) − Ŵ(â_A), eqs. (6), (9), (18); zero when
    /// there is no hysteresis.
    pub w_hat: f64,
    /// Why the model predicts no hysteresis, when it does not.
    pub no_hysteresis_reason: Option<String>,
}

/// Hybrid loss Ŵ(μ): eq. (9) with its lower limit â_B replaced by â_A, the root of
/// α̂_A = √(2πâ_A) − â_A² (18) on the stable contact branch, α̂_A from `jump_in`.
///
/// ```
/// use tapsim::contact::hybrid::{JumpIn, hysteresis};
///
/// // The paper's case μ = 5: 3.206, against JKR's 7.092 (eq. 9).
/// let h = hysteresis(5.0, JumpIn::Fit)?;
/// assert!((h.w_hat - 3.2062).abs() < 1e-4);
/// # Ok::<(), tapsim::Error>(())
/// ```
pub fn hysteresis(tabor_mu: f64, jump_in: JumpIn) -> Result<HybridHysteresis> {
    let alpha_hat_a = jump_in.alpha_hat_a(tabor_mu)?;
    let c = jkr::point_c();
    let landing = alpha_hat_a.and_then(jkr_landing);
    let no_hysteresis_reason = match (alpha_hat_a, landing) {
        (_, Some(_)) => None,
        (None, _) => Some(format!(
            "no jump-in instability at mu = {tabor_mu:.4} with the {jump_in} jump-in: \
             the hybrid theory predicts no hysteresis (it needs mu > {:.3})",
            min_hysteretic_mu(jump_in)?
        )),
        (Some(a), None) => Some(format!(
            "jump-in separation alpha_hat_A = {a:.4} is not below the jump-out separation \
             alpha_hat_C = {:.4} at mu = {tabor_mu:.4}: the hybrid theory predicts no hysteresis \
             (it needs mu > {:.3} with the {jump_in} jump-in)",
            c.alpha_hat,
            min_hysteretic_mu(jump_in)?
        )),
    };
    let w_hat = landing.map_or(0.0, |b| jkr::work_hat(c.a_hat) - jkr::work_hat(b.a_hat));
    Ok(HybridHysteresis {
        tabor_mu,
        jump_in,
        alpha_hat_a,
        landing,
        w_hat,
        no_hysteresis_reason,
    })
}

/// Landing point of a rigid-grip jump-in at α̂_A on the JKR contact branch, eq. (18);
/// `None` unless α̂_A < α̂_C.
fn jkr_landing(alpha_hat_a: f64) -> Option<JkrPoint> {
    (alpha_hat_a < jkr::point_c().alpha_hat)
        .then(|| jkr::a_hat_from_separation(alpha_hat_a))
        .flatten()
        .map(JkrPoint::at)
}

/// Fast path of [`hysteresis`] with the fit (17): Ŵ_hybrid(μ), eqs. (17), (18), (6);
/// 0 where the theory predicts no hysteresis or μ is not a positive number.
#[inline]
pub fn w_hat_fit(tabor_mu: f64) -> f64 {
    let mu_peak = (7.0 / (4.0 * semi_rigid::FIT_COEFF)).powf(7.0 / 3.0);
    if tabor_mu.is_nan() || tabor_mu <= mu_peak {
        return 0.0;
    }
    let alpha_hat_a = semi_rigid::alpha_hat_a_fit(tabor_mu);
    match jkr::a_hat_from_separation(alpha_hat_a) {
        Some(a_hat_a) if alpha_hat_a < jkr::point_c().alpha_hat => {
            jkr::work_hat(jkr::point_c().a_hat) - jkr::work_hat(a_hat_a)
        }
        _ => 0.0,
    }
}

/// The smallest μ at which the hybrid theory with `jump_in` predicts hysteresis, i.e.
/// where α̂_A(μ) = α̂_C (about 1.09 with the fit (17)).
pub fn min_hysteretic_mu(jump_in: JumpIn) -> Result<f64> {
    let alpha_c = jkr::point_c().alpha_hat;
    // Positive above the threshold; no instability counts as below it.
    let excess = |mu: f64| match jump_in.alpha_hat_a(mu) {
        Ok(Some(a)) => alpha_c - a,
        _ => -1.0,
    };
    bracketed_root("hybrid threshold mu", excess, 0.3, 100.0, 1e-12)
}
