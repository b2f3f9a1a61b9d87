//! The `tapsim lj` report: the Lennard-Jones summary as a table for people (its JSON is
//! the summary itself), and the traced curve as CSV.

use crate::error::Result;
use crate::physics::contact::lj::LjSolution;
use crate::physics::summary::{LjSummary, NoLoopSummary};
use std::fmt::Write as _;

impl NoLoopSummary {
    /// A table for people.
    pub fn to_text(&self) -> String {
        format!(
            "Lennard-Jones numerical solution, Tabor parameter μ = {}\n  no hysteresis, \
             Ŵ_LJ = 0: {}\n",
            self.tabor_mu, self.note
        )
    }
}

impl LjSummary {
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
