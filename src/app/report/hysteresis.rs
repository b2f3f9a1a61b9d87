//! The `tapsim hysteresis` report: the closed-form summary of one contact as a table for
//! people (its JSON is the summary itself).

use crate::physics::summary::HysteresisSummary;
use std::fmt::Write as _;

impl HysteresisSummary {
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
                si.w_j, si.w_ev
            );
            let _ = writeln!(s, "  W_JKR                        {:.4e} J", si.w_jkr_j);
        }
        s
    }
}
