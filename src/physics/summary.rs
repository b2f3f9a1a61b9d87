//! Summaries of a contact's adhesion hysteresis for people and programs: the paper's
//! closed forms for one contact ([`HysteresisSummary`]) and the Lennard-Jones numerical
//! solution beside them ([`LjSummary`]). Pure data gathered from the contact modules;
//! the application renders them as tables and JSON.

use crate::error::Result;
use crate::physics::contact::hybrid::{self, JumpIn};
use crate::physics::contact::jkr;
use crate::physics::contact::length_scale::contact_radius_over_s0;
use crate::physics::contact::lj::LjSolution;
use crate::physics::contact::semi_rigid;
use crate::physics::contact::spring;
use crate::physics::params::{Contact, ELECTRONVOLT_J};
use serde::Serialize;

/// Dimensionless stiffness of the support, given directly or from SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Support {
    /// Rigid grips (displacement control).
    Rigid,
    /// Dimensionless stiffness k̂, eq. (22).
    KHat(f64),
    /// Stiffness k in N/m (needs an SI contact).
    NewtonsPerMetre(f64),
}

/// What the summary is computed from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Input {
    /// A Tabor parameter given directly.
    TaborMu(f64),
    /// A contact given in SI units.
    Si(Contact),
}

/// SI quantities (only when the input was SI).
#[derive(Debug, Clone, Serialize)]
pub struct SiSection {
    /// The contact.
    #[serde(flatten)]
    pub contact: Contact,
    /// β, eq. (4).
    pub beta: f64,
    /// Force scale RΔγ in N.
    pub force_scale_n: f64,
    /// Separation scale με in m.
    pub separation_scale_m: f64,
    /// Energy scale μεRΔγ in J.
    pub energy_scale_j: f64,
    /// Energy scale μεRΔγ in eV.
    pub energy_scale_ev: f64,
    /// Adhesive length scale s₀ in m, eq. (20).
    pub s0_m: f64,
    /// Support stiffness in N/m, if given.
    pub stiffness_n_m: Option<f64>,
    /// The headline loss per cycle in J: with the spring if a stiffness was given,
    /// else the rigid hybrid value.
    pub w_j: f64,
    /// `w_j` in eV.
    pub w_ev: f64,
    /// JKR loss (9) in J.
    pub w_jkr_j: f64,
    /// Rigid-support hybrid loss (18) in J.
    pub w_hybrid_j: f64,
    /// The keys these had until 0.1 (`w_joule`, `w_jkr_joule`, `w_hybrid_joule`: the
    /// same values), kept for one release.
    #[serde(flatten)]
    pub deprecated: DeprecatedLossKeys,
}

/// The loss keys of `hysteresis --json` before every energy key ended in `_j`: the same
/// values as `w_j`, `w_jkr_j`, `w_hybrid_j`, kept for one release.
#[derive(Debug, Clone, Serialize)]
pub struct DeprecatedLossKeys {
    /// = `w_j`.
    pub w_joule: f64,
    /// = `w_jkr_j`.
    pub w_jkr_joule: f64,
    /// = `w_hybrid_j`.
    pub w_hybrid_joule: f64,
}

/// Finite-stiffness results, eqs. (22)–(27).
#[derive(Debug, Clone, Serialize)]
pub struct SpringSection {
    /// k̂, eq. (22).
    pub k_hat: f64,
    /// Landing point B with the spring (Fig. 5).
    pub a_hat_b_spring: Option<f64>,
    /// T̂ at B.
    pub t_hat_b_spring: Option<f64>,
    /// Tip separation α̂ at B.
    pub alpha_hat_b_spring: Option<f64>,
    /// Jump-out point C with the spring, eq. (24).
    pub a_hat_c_spring: f64,
    /// T̂ at C.
    pub t_hat_c_spring: f64,
    /// Tip separation α̂ at C.
    pub alpha_hat_c_spring: f64,
    /// Support separation α̂_S at C, eq. (22).
    pub support_alpha_hat_c_spring: f64,
    /// Loss per cycle with the spring, eq. (26).
    pub w_hat_spring: f64,
    /// Soft-support asymptote (3π/2)²/(2k̂), eq. (27).
    pub w_hat_soft_limit: f64,
    /// Why there is no hysteresis, when there is none.
    pub spring_note: Option<String>,
}

/// The closed-form hysteresis of one contact, eqs. (8), (9), (17), (18), (20)–(27).
#[derive(Debug, Clone, Serialize)]
pub struct HysteresisSummary {
    /// Tabor parameter μ, eq. (2).
    pub tabor_mu: f64,
    /// Whether μ was the built-in default.
    pub tabor_mu_is_default: bool,
    /// Jump-in variant.
    pub jump_in: JumpIn,
    /// Whether the hybrid theory predicts hysteresis (rigid support).
    pub hysteresis: bool,
    /// Jump-in separation α̂_A.
    pub alpha_hat_a: Option<f64>,
    /// Contact radius â_A at the rigid-grip landing point, eq. (18).
    pub a_hat_a: Option<f64>,
    /// T̂ at the rigid-grip landing point.
    pub t_hat_a_landing: Option<f64>,
    /// JKR jump-in point B, eq. (8).
    pub a_hat_b: f64,
    /// T̂_B = 4π/3, eq. (8).
    pub t_hat_b: f64,
    /// Jump-out separation α̂_C = 3π^{2/3}/4, eq. (8).
    pub alpha_hat_c: f64,
    /// â_C = π^{1/3}/2, eq. (8).
    pub a_hat_c: f64,
    /// T̂_C = 5π/6, eq. (8).
    pub t_hat_c: f64,
    /// Load-control pull-off force 3π/2.
    pub pull_off_hat: f64,
    /// Hybrid loss, eq. (18) (0 without hysteresis).
    pub w_hat_hybrid: f64,
    /// JKR loss, eq. (9).
    pub w_hat_jkr: f64,
    /// Ratio Ŵ_hybrid / Ŵ_JKR.
    pub hybrid_over_jkr: f64,
    /// a_C/s₀ = π â_C μ², eqs. (20), (21).
    pub a_c_over_s0: f64,
    /// a_A/s₀ at the landing point.
    pub a_a_over_s0: Option<f64>,
    /// Why there is no hysteresis, when there is none.
    pub note: Option<String>,
    /// Finite-stiffness results.
    #[serde(flatten)]
    pub spring: Option<SpringSection>,
    /// SI results.
    #[serde(flatten)]
    pub si: Option<SiSection>,
}

impl HysteresisSummary {
    /// Gather the closed forms for `input` on `support`. `mu_is_default` only marks the
    /// output.
    pub fn compute(
        input: Input,
        support: Support,
        jump_in: JumpIn,
        mu_is_default: bool,
    ) -> Result<Self> {
        let tabor_mu = match input {
            Input::TaborMu(mu) => crate::physics::params::tabor_mu(mu)?,
            Input::Si(c) => c.tabor_mu(),
        };
        let k_hat = match (support, input) {
            (Support::Rigid, _) => None,
            (Support::KHat(k), _) => Some(crate::physics::params::k_hat(k)?),
            (Support::NewtonsPerMetre(k), Input::Si(c)) => Some(c.k_hat(k)?),
            (Support::NewtonsPerMetre(_), Input::TaborMu(_)) => {
                return Err(crate::Error::NotApplicable(
                    "a support stiffness in N/m needs the contact in SI units (radius, \
                     modulus, work of adhesion, range); with a Tabor parameter give the \
                     dimensionless stiffness k_hat instead"
                        .into(),
                ));
            }
        };
        let rigid = hybrid::hysteresis(tabor_mu, jump_in)?;
        let b = jkr::point_b();
        let c = jkr::point_c();
        let w_hat_jkr = jkr::w_hat_jkr();
        let spring = k_hat
            .map(|k| spring::hysteresis(tabor_mu, k, jump_in))
            .transpose()?
            .map(|s| SpringSection {
                k_hat: s.k_hat,
                a_hat_b_spring: s.landing.map(|p| p.a_hat),
                t_hat_b_spring: s.landing.map(|p| p.t_hat),
                alpha_hat_b_spring: s.landing.map(|p| p.alpha_hat),
                a_hat_c_spring: s.jump_out.a_hat,
                t_hat_c_spring: s.jump_out.t_hat,
                alpha_hat_c_spring: s.jump_out.alpha_hat,
                support_alpha_hat_c_spring: s.support_alpha_hat_c,
                w_hat_spring: s.w_hat,
                w_hat_soft_limit: spring::w_hat_soft_limit(s.k_hat),
                spring_note: s.no_hysteresis_reason,
            });
        let si = match (input, support) {
            (Input::Si(contact), support) => {
                let scale = contact.energy_scale_j();
                let headline = spring.as_ref().map_or(rigid.w_hat, |s| s.w_hat_spring) * scale;
                Some(SiSection {
                    contact,
                    beta: contact.beta(),
                    force_scale_n: contact.force_scale_n(),
                    separation_scale_m: contact.separation_scale_m(),
                    energy_scale_j: scale,
                    energy_scale_ev: scale / ELECTRONVOLT_J,
                    s0_m: contact.s0_m(),
                    stiffness_n_m: match support {
                        Support::NewtonsPerMetre(k) => Some(k),
                        _ => None,
                    },
                    w_j: headline,
                    w_ev: headline / ELECTRONVOLT_J,
                    w_jkr_j: w_hat_jkr * scale,
                    w_hybrid_j: rigid.w_hat * scale,
                    deprecated: DeprecatedLossKeys {
                        w_joule: headline,
                        w_jkr_joule: w_hat_jkr * scale,
                        w_hybrid_joule: rigid.w_hat * scale,
                    },
                })
            }
            (Input::TaborMu(_), _) => None,
        };
        Ok(Self {
            tabor_mu,
            tabor_mu_is_default: mu_is_default,
            jump_in,
            hysteresis: rigid.landing.is_some(),
            alpha_hat_a: rigid.alpha_hat_a,
            a_hat_a: rigid.landing.map(|p| p.a_hat),
            t_hat_a_landing: rigid.landing.map(|p| p.t_hat),
            a_hat_b: b.a_hat,
            t_hat_b: b.t_hat,
            alpha_hat_c: c.alpha_hat,
            a_hat_c: c.a_hat,
            t_hat_c: c.t_hat,
            pull_off_hat: jkr::PULL_OFF_T_HAT,
            w_hat_hybrid: rigid.w_hat,
            w_hat_jkr,
            hybrid_over_jkr: rigid.w_hat / w_hat_jkr,
            a_c_over_s0: contact_radius_over_s0(c.a_hat, tabor_mu),
            a_a_over_s0: rigid
                .landing
                .map(|p| contact_radius_over_s0(p.a_hat, tabor_mu)),
            note: rigid.no_hysteresis_reason,
            spring,
            si,
        })
    }
}

/// The Lennard-Jones solution where the curve has no loop: nothing is lost.
#[derive(Debug, Clone, Serialize)]
pub struct NoLoopSummary {
    /// Tabor parameter μ.
    pub tabor_mu: f64,
    /// Always false.
    pub hysteresis: bool,
    /// Ŵ_LJ = 0.
    pub w_hat: f64,
    /// 0.
    pub w_hat_error: f64,
    /// Why.
    pub note: String,
}

impl NoLoopSummary {
    /// The summary for μ = `tabor_mu`, with the solver's reason.
    pub fn new(tabor_mu: f64, note: String) -> Self {
        Self {
            tabor_mu,
            hysteresis: false,
            w_hat: 0.0,
            w_hat_error: 0.0,
            note,
        }
    }
}

/// An [`LjSolution`] flat, beside the closed forms: the hybrid loss (18) with the fit
/// (17), the closed form (16), JKR (9).
#[derive(Debug, Clone, Serialize)]
pub struct LjSummary {
    /// Tabor parameter μ.
    pub tabor_mu: f64,
    /// Whether the curve has a loop (always, for a solution with folds).
    pub hysteresis: bool,
    /// Jump-in separation α̂_A (fold A).
    pub alpha_hat_a: f64,
    /// Its estimated discretisation error.
    pub alpha_hat_a_error: f64,
    /// Force at A.
    pub t_hat_a: f64,
    /// Its error.
    pub t_hat_a_error: f64,
    /// Jump-out separation α̂_C (fold C).
    pub alpha_hat_c: f64,
    /// Its error.
    pub alpha_hat_c_error: f64,
    /// Force at C.
    pub t_hat_c: f64,
    /// Its error.
    pub t_hat_c_error: f64,
    /// Load-control pull-off force.
    pub pull_off_hat: f64,
    /// Its error.
    pub pull_off_hat_error: f64,
    /// Pull-off relative to the JKR value 3π/2.
    pub pull_off_over_jkr: f64,
    /// Hysteresis loss Ŵ_LJ.
    pub w_hat: f64,
    /// Its estimated discretisation error.
    pub w_hat_error: f64,
    /// The hybrid theory's Ŵ (18) with the fit (17).
    pub w_hat_hybrid: f64,
    /// (Ŵ_hybrid − Ŵ_LJ)/Ŵ_LJ.
    pub hybrid_rel_error: f64,
    /// α̂_A from the fit (17).
    pub alpha_hat_a_fit: f64,
    /// (fit − numerical)/numerical.
    pub fit_rel_error: f64,
    /// α̂_A from the closed form (16).
    pub alpha_hat_a_closed_form: f64,
    /// JKR loss (9).
    pub w_hat_jkr: f64,
    /// Mesh nodes (production).
    pub nodes: usize,
    /// Mesh nodes (coarse, for the error estimate).
    pub nodes_coarse: usize,
    /// Continuation steps.
    pub steps: usize,
    /// Support stiffness k̂ (22), when given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub k_hat: Option<f64>,
    /// Ŵ_LJ with the support in series, when k̂ is given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub w_hat_spring: Option<f64>,
    /// The hybrid theory's (26) at the same k̂.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub w_hat_spring_hybrid: Option<f64>,
}

impl LjSummary {
    /// The summary of `s`.
    pub fn new(s: &LjSolution) -> Self {
        let mu = s.tabor_mu;
        let hybrid = hybrid::hysteresis(mu, JumpIn::Fit)
            .map(|h| h.w_hat)
            .unwrap_or(0.0);
        let fit = semi_rigid::alpha_hat_a_fit(mu);
        Self {
            tabor_mu: mu,
            hysteresis: true,
            alpha_hat_a: s.alpha_hat_a.value,
            alpha_hat_a_error: s.alpha_hat_a.error,
            t_hat_a: s.t_hat_a.value,
            t_hat_a_error: s.t_hat_a.error,
            alpha_hat_c: s.alpha_hat_c.value,
            alpha_hat_c_error: s.alpha_hat_c.error,
            t_hat_c: s.t_hat_c.value,
            t_hat_c_error: s.t_hat_c.error,
            pull_off_hat: s.pull_off_hat.value,
            pull_off_hat_error: s.pull_off_hat.error,
            pull_off_over_jkr: s.pull_off_hat.value / jkr::PULL_OFF_T_HAT,
            w_hat: s.w_hat.value,
            w_hat_error: s.w_hat.error,
            w_hat_hybrid: hybrid,
            hybrid_rel_error: (hybrid - s.w_hat.value) / s.w_hat.value,
            alpha_hat_a_fit: fit,
            fit_rel_error: (fit - s.alpha_hat_a.value) / s.alpha_hat_a.value,
            alpha_hat_a_closed_form: semi_rigid::alpha_hat_a_closed_form(mu),
            w_hat_jkr: jkr::w_hat_jkr(),
            nodes: s.nodes,
            nodes_coarse: s.nodes_coarse,
            steps: s.steps,
            k_hat: None,
            w_hat_spring: None,
            w_hat_spring_hybrid: None,
        }
    }

    /// Add the loss with a support of stiffness k̂ in series.
    pub fn with_spring(mut self, s: &LjSolution, k_hat: f64) -> Result<Self> {
        crate::physics::params::k_hat(k_hat)?;
        let loop_ = s.spring_loop(k_hat)?;
        self.k_hat = Some(k_hat);
        self.w_hat_spring = Some(loop_.w_hat);
        self.w_hat_spring_hybrid =
            crate::physics::contact::spring::hysteresis(s.tabor_mu, k_hat, JumpIn::Fit)
                .ok()
                .map(|h| h.w_hat);
        Ok(self)
    }
}
