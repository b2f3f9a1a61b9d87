//! The `tapsim hysteresis` report: the paper's closed-form results for one contact,
//! as a JSON object and as a table for people.

use crate::contact::hybrid::{self, JumpIn};
use crate::contact::jkr;
use crate::contact::length_scale::contact_radius_over_s0;
use crate::contact::spring;
use crate::error::Result;
use crate::params::{Contact, ELECTRONVOLT_J};
use serde::Serialize;
use std::fmt::Write as _;

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

/// What the report is computed from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Input {
    /// A Tabor parameter given directly.
    TaborMu(f64),
    /// A contact given in SI units.
    Si(Contact),
}

/// SI quantities of the report (only when the input was SI).
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
    pub w_joule: f64,
    /// `w_joule` in eV.
    pub w_ev: f64,
    /// JKR loss (9) in J.
    pub w_jkr_joule: f64,
    /// Rigid-support hybrid loss (18) in J.
    pub w_hybrid_joule: f64,
}

/// Finite-stiffness section of the report, eqs. (22)–(27).
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

/// The full report.
#[derive(Debug, Clone, Serialize)]
pub struct HysteresisReport {
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

impl HysteresisReport {
    /// Compute the report. `mu_is_default` only marks the output.
    pub fn compute(
        input: Input,
        support: Support,
        jump_in: JumpIn,
        mu_is_default: bool,
    ) -> Result<Self> {
        let tabor_mu = match input {
            Input::TaborMu(mu) => crate::params::tabor_mu(mu)?,
            Input::Si(c) => c.tabor_mu(),
        };
        let k_hat = match (support, input) {
            (Support::Rigid, _) => None,
            (Support::KHat(k), _) => Some(crate::params::k_hat(k)?),
            (Support::NewtonsPerMetre(k), Input::Si(c)) => Some(c.k_hat(k)?),
            (Support::NewtonsPerMetre(_), Input::TaborMu(_)) => {
                return Err(crate::Error::NotApplicable(
                    "a stiffness in N/m needs the contact in SI units (--radius, --modulus, \
                     --work-of-adhesion, --range); with --mu give --k-hat instead"
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
                    w_joule: headline,
                    w_ev: headline / ELECTRONVOLT_J,
                    w_jkr_joule: w_hat_jkr * scale,
                    w_hybrid_joule: rigid.w_hat * scale,
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

    /// A table for people.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        let opt = |v: Option<f64>| v.map_or_else(|| "—".to_string(), |v| format!("{v:.6}"));
        let default = if self.tabor_mu_is_default {
            "  (default; set --mu or SI inputs)"
        } else {
            ""
        };
        let _ = writeln!(
            s,
            "Hysteresis loss per approach–separation cycle (Ciavarella, Greenwood & Barber)"
        );
        if let Some(si) = &self.si {
            let c = &si.contact;
            let _ = writeln!(s, "  tip radius R                 {:.4e} m", c.radius_m);
            let _ = writeln!(s, "  composite modulus E*         {:.4e} Pa", c.modulus_pa);
            let _ = writeln!(
                s,
                "  work of adhesion Δγ          {:.4e} J/m²",
                c.work_of_adhesion_j_m2
            );
            let _ = writeln!(s, "  LJ range ε                   {:.4e} m", c.range_m);
            let _ = writeln!(s, "  β (4)                        {:.6}", si.beta);
            let _ = writeln!(
                s,
                "  scales: force RΔγ {:.4e} N, separation με {:.4e} m, energy μεRΔγ {:.4e} J",
                si.force_scale_n, si.separation_scale_m, si.energy_scale_j
            );
            let _ = writeln!(s, "  adhesive length s₀ (20)      {:.4e} m", si.s0_m);
        }
        let _ = writeln!(
            s,
            "  Tabor parameter μ (2)        {:.6}{default}",
            self.tabor_mu
        );
        let _ = writeln!(s, "  jump-in                      {}", self.jump_in);
        let _ = writeln!(s, "JKR (rigid grips), eqs. (8), (9)");
        let _ = writeln!(
            s,
            "  B: â_B = {:.6}  T̂_B = {:.6}  (α̂_B = 0)",
            self.a_hat_b, self.t_hat_b
        );
        let _ = writeln!(
            s,
            "  C: â_C = {:.6}  T̂_C = {:.6}  α̂_C = {:.6}",
            self.a_hat_c, self.t_hat_c, self.alpha_hat_c
        );
        let _ = writeln!(
            s,
            "  load-control pull-off T̂ = 3π/2 = {:.6}",
            self.pull_off_hat
        );
        let _ = writeln!(s, "  Ŵ_JKR (9)                    {:.6}", self.w_hat_jkr);
        let _ = writeln!(s, "Hybrid (rigid grips), eq. (18)");
        let _ = writeln!(
            s,
            "  α̂_A                          {}",
            opt(self.alpha_hat_a)
        );
        let _ = writeln!(s, "  â_A (landing)                {}", opt(self.a_hat_a));
        let _ = writeln!(
            s,
            "  Ŵ_hybrid                     {:.6}  ({:.1} % of JKR)",
            self.w_hat_hybrid,
            100.0 * self.hybrid_over_jkr
        );
        let _ = writeln!(s, "  a_C/s₀ (20)-(21)             {:.4}", self.a_c_over_s0);
        if let Some(note) = &self.note {
            let _ = writeln!(s, "  note: {note}");
        }
        if let Some(sp) = &self.spring {
            let _ = writeln!(s, "Finite support stiffness, eqs. (22)-(27)");
            let _ = writeln!(s, "  k̂ (22)                       {:.6}", sp.k_hat);
            let _ = writeln!(
                s,
                "  B: â = {}  T̂ = {}",
                opt(sp.a_hat_b_spring),
                opt(sp.t_hat_b_spring)
            );
            let _ = writeln!(
                s,
                "  C: â = {:.6}  T̂ = {:.6}  α̂_S = {:.6}",
                sp.a_hat_c_spring, sp.t_hat_c_spring, sp.support_alpha_hat_c_spring
            );
            let _ = writeln!(s, "  Ŵ (26)                       {:.6}", sp.w_hat_spring);
            let _ = writeln!(
                s,
                "  soft limit (27)              {:.6}",
                sp.w_hat_soft_limit
            );
            if let Some(note) = &sp.spring_note {
                let _ = writeln!(s, "  note: {note}");
            }
        }
        if let Some(si) = &self.si {
            let _ = writeln!(s, "Energy lost per cycle");
            let _ = writeln!(
                s,
                "  W                            {:.4e} J = {:.4} eV",
                si.w_joule, si.w_ev
            );
            let _ = writeln!(s, "  W_JKR                        {:.4e} J", si.w_jkr_joule);
        }
        s
    }
}
