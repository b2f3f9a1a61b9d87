//! The `tapsim lj` report: the Lennard-Jones numerical solution for one μ beside the
//! paper's closed forms.

use crate::contact::hybrid::{self, JumpIn};
use crate::contact::jkr;
use crate::contact::lj::LjSolution;
use crate::contact::semi_rigid;
use crate::error::Result;
use serde::Serialize;
use std::fmt::Write as _;

/// The `tapsim lj` report where the curve has no loop: nothing is lost.
#[derive(Debug, Clone, Serialize)]
pub struct NoLoopReport {
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

impl NoLoopReport {
    /// The report for μ = `tabor_mu`, with the solver's reason.
    pub fn new(tabor_mu: f64, note: String) -> Self {
        Self {
            tabor_mu,
            hysteresis: false,
            w_hat: 0.0,
            w_hat_error: 0.0,
            note,
        }
    }

    /// A table for people.
    pub fn to_text(&self) -> String {
        format!(
            "Lennard-Jones numerical solution, Tabor parameter μ = {}\n  no hysteresis, \
             Ŵ_LJ = 0: {}\n",
            self.tabor_mu, self.note
        )
    }
}

/// Flat JSON view of an [`LjSolution`] with comparisons.
#[derive(Debug, Clone, Serialize)]
pub struct LjReport {
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

impl LjReport {
    /// The report of `s`.
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
        crate::params::k_hat(k_hat)?;
        let loop_ = s.spring_loop(k_hat)?;
        self.k_hat = Some(k_hat);
        self.w_hat_spring = Some(loop_.w_hat);
        self.w_hat_spring_hybrid =
            crate::contact::spring::hysteresis(s.tabor_mu, k_hat, JumpIn::Fit)
                .ok()
                .map(|h| h.w_hat);
        Ok(self)
    }

    /// A table for people.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "Lennard-Jones numerical solution, Tabor parameter μ = {}",
            self.tabor_mu
        );
        let _ = writeln!(
            s,
            "  mesh: {} nodes, extrapolated with {} nodes (and fewer for the error \
             estimate), {} continuation steps",
            self.nodes, self.nodes_coarse, self.steps
        );
        let row = |s: &mut String, name: &str, v: f64, e: f64| {
            let _ = writeln!(s, "  {name:<28} {v:>10.5} ± {e:.1e}");
        };
        row(
            &mut s,
            "jump-in α̂_A",
            self.alpha_hat_a,
            self.alpha_hat_a_error,
        );
        row(&mut s, "force at A, T̂_A", self.t_hat_a, self.t_hat_a_error);
        row(
            &mut s,
            "jump-out α̂_C",
            self.alpha_hat_c,
            self.alpha_hat_c_error,
        );
        row(&mut s, "force at C, T̂_C", self.t_hat_c, self.t_hat_c_error);
        row(
            &mut s,
            "pull-off (load control)",
            self.pull_off_hat,
            self.pull_off_hat_error,
        );
        row(&mut s, "hysteresis Ŵ_LJ", self.w_hat, self.w_hat_error);
        let _ = writeln!(s, "Against the paper's closed forms");
        let _ = writeln!(
            s,
            "  α̂_A fit (17)                {:>10.5}  ({:+.2} %)",
            self.alpha_hat_a_fit,
            100.0 * self.fit_rel_error
        );
        let _ = writeln!(
            s,
            "  α̂_A closed form (16)         {:>10.5}",
            self.alpha_hat_a_closed_form
        );
        let _ = writeln!(
            s,
            "  Ŵ hybrid (18)                {:>10.5}  ({:+.2} %)",
            self.w_hat_hybrid,
            100.0 * self.hybrid_rel_error
        );
        let _ = writeln!(s, "  Ŵ JKR (9)                    {:>10.5}", self.w_hat_jkr);
        let _ = writeln!(
            s,
            "  pull-off / (3π/2)            {:>10.5}",
            self.pull_off_over_jkr
        );
        if let (Some(k), Some(w)) = (self.k_hat, self.w_hat_spring) {
            let _ = writeln!(s, "With a support of stiffness k̂ = {k} in series, eq. (22)");
            let _ = writeln!(s, "  Ŵ_LJ with the spring         {w:>10.5}");
            if let Some(h) = self.w_hat_spring_hybrid {
                let _ = writeln!(
                    s,
                    "  Ŵ hybrid (26)                {h:>10.5}  ({:+.2} %)",
                    100.0 * (h - w) / w
                );
            }
        }
        s
    }
}

/// The traced curve as CSV: s, alpha_hat, t_hat, central_gap.
pub fn curve_csv(s: &LjSolution) -> Result<Vec<u8>> {
    super::records::records_csv(&s.curve)
}
