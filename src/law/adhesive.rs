//! Adhesive laws with a JKR contact branch: the paper's hybrid law (jump-in at α̂_A of
//! (17)), the hybrid law with Greenwood's semi-rigid attraction on approach, and classic
//! JKR (jump-in at α̂ = 0). All jump out at the rigid-grip point C of eq. (8).

use super::table::UniformTable;
use super::{Branch, ForceLaw};
use crate::contact::hybrid::JumpIn;
use crate::contact::jkr;
use crate::contact::semi_rigid::{self, EighthPower};
use crate::error::{Error, Result, positive};
use crate::numeric::{GAUSS_LEGENDRE_4, bracketed_root};

/// Nodes of the semi-rigid approach table (uniform in √(α̂ − α̂_A)).
const APPROACH_NODES: usize = 4097;
/// The approach table reaches α̂_A + this; beyond, T̂ falls as 1/(α̂ + 1/μ)².
const APPROACH_SPAN: f64 = 60.0;

/// The approach (out-of-contact) branch of an adhesive law.
#[derive(Debug, Clone)]
pub enum Approach {
    /// No force before the jump-in.
    ForceFree,
    /// Greenwood's semi-rigid attraction (12) at the separation (14), tabulated against
    /// s = √(α̂ − α̂_A), which is smooth through the fold A.
    SemiRigid {
        /// T̂(s).
        table: UniformTable,
        /// ∫ T̂ dα̂ from A to each node.
        cumulative: Vec<f64>,
        /// Tabor parameter μ (for the far tail).
        tabor_mu: f64,
    },
}

/// Nodes of the contact-branch table (uniform in √(α̂_C − α̂)).
const CONTACT_NODES: usize = 8193;
/// The contact table reaches down to α̂_C − this; deeper, eq. (5) is inverted in closed form.
const CONTACT_SPAN: f64 = 60.0;

/// The JKR contact branch T̂(α̂) of eq. (5) on its displacement-stable side, tabulated
/// against s = √(α̂_C − α̂), in which it is smooth through the fold C (the closed-form
/// inverse costs a cube root and several square roots per call; the table one).
fn contact_table() -> UniformTable {
    UniformTable::sample(0.0, CONTACT_SPAN.sqrt(), CONTACT_NODES, |s| {
        if s == 0.0 {
            // At the fold itself the inverse is ill-conditioned (â has an infinite slope):
            // take the exact point C of eq. (8).
            return jkr::T_HAT_C;
        }
        let alpha = jkr::ALPHA_HAT_C - s * s;
        jkr::force_hat(jkr::a_hat_from_separation(alpha).unwrap_or(jkr::A_HAT_C))
    })
}

/// ∫ T̂ dα̂ = ∫ T̂(s) 2s ds over [s_a, s_b] inside one table interval, exact for the
/// cubic interpolant (4-point Gauss–Legendre).
fn work_along(table: &UniformTable, s_a: f64, s_b: f64) -> f64 {
    let (mid, half) = (0.5 * (s_a + s_b), 0.5 * (s_b - s_a));
    GAUSS_LEGENDRE_4
        .iter()
        .map(|&(x, w)| {
            let s = mid + half * x;
            w * half * table.eval(s) * 2.0 * s
        })
        .sum()
}

/// An adhesive law: approach branch, jump-in at `jump_in`, JKR contact branch, jump-out
/// at α̂_C.
#[derive(Debug, Clone)]
pub struct AdhesiveLaw {
    contact: UniformTable,
    approach: Approach,
    jump_in: f64,
    jump_in_t_hat: f64,
    c_alpha_hat: f64,
    c_t_hat: f64,
    loop_area: f64,
}

impl AdhesiveLaw {
    fn with_approach(approach: Approach, jump_in: f64, jump_in_t_hat: f64) -> Result<Self> {
        let c = jkr::point_c();
        if jump_in >= c.alpha_hat {
            return Err(Error::NotApplicable(format!(
                "its jump-in separation {jump_in:.4} is not below the jump-out separation \
                 alpha_hat_C = {:.4}, so there is no contact branch to land on",
                c.alpha_hat
            )));
        }
        let mut law = Self {
            contact: contact_table(),
            approach,
            jump_in,
            jump_in_t_hat,
            c_alpha_hat: c.alpha_hat,
            c_t_hat: c.t_hat,
            loop_area: 0.0,
        };
        let landing = jkr::a_hat_from_separation(jump_in)
            .ok_or_else(|| Error::Numerical("landing point of the jump-in".into()))?;
        let contact_work = jkr::work_hat(c.a_hat) - jkr::work_hat(landing);
        law.loop_area = contact_work - law.approach_work(c.alpha_hat);
        Ok(law)
    }

    /// The paper's hybrid law: force-free approach, jump-in at α̂_A from `jump_in`
    /// ((17) by default), JKR contact branch (5), jump-out at α̂_C (8); loop area Ŵ (18).
    pub fn hybrid(tabor_mu: f64, jump_in: JumpIn) -> Result<Self> {
        let alpha_a = jump_in.alpha_hat_a(tabor_mu)?.ok_or_else(|| {
            Error::NotApplicable("there is no jump-in instability at this mu".into())
        })?;
        Self::with_approach(Approach::ForceFree, alpha_a, 0.0)
    }

    /// Classic JKR: no force before contact, jump-in at α̂ = 0 (B), jump-out at C; loop
    /// area Ŵ_JKR (9).
    pub fn jkr() -> Self {
        Self::with_approach(Approach::ForceFree, 0.0, 0.0).expect("0 < alpha_hat_C")
    }

    /// The hybrid law with the semi-rigid attraction (12), (14) on the approach branch and
    /// the jump-in at its fold (15).
    pub fn hybrid_attractive(tabor_mu: f64) -> Result<Self> {
        positive("Tabor parameter mu", tabor_mu)?;
        let fold = semi_rigid::jump_in_exact(tabor_mu, EighthPower::Keep)?.ok_or_else(|| {
            Error::NotApplicable("the semi-rigid curve (14) has no fold at this mu".into())
        })?;
        let alpha =
            |h: f64| semi_rigid::separation_over_range(h, tabor_mu, EighthPower::Keep) / tabor_mu;
        let s_max = APPROACH_SPAN.sqrt();
        // Central gap h̄₀(s) on the stable side of the fold: α̂(h̄₀) = α̂_A + s².
        let gap_at = |s: f64| -> f64 {
            if s <= 0.0 {
                return fold.h0_bar;
            }
            let target = fold.alpha_hat + s * s;
            let mut hi = fold.h0_bar + 1.0;
            while alpha(hi) < target {
                hi = fold.h0_bar + 2.0 * (hi - fold.h0_bar);
            }
            bracketed_root(
                "semi-rigid approach table",
                |h| alpha(h) - target,
                fold.h0_bar,
                hi,
                1e-15,
            )
            .unwrap_or(fold.h0_bar)
        };
        let table = UniformTable::sample(0.0, s_max, APPROACH_NODES, |s| {
            semi_rigid::force_hat(gap_at(s))
        });
        let mut cumulative = Vec::with_capacity(table.len());
        let mut sum = 0.0;
        for i in 0..table.len() {
            if i > 0 {
                let h = table.step();
                sum += work_along(&table, h * (i - 1) as f64, h * i as f64);
            }
            cumulative.push(sum);
        }
        Self::with_approach(
            Approach::SemiRigid {
                table,
                cumulative,
                tabor_mu,
            },
            fold.alpha_hat,
            fold.t_hat,
        )
    }

    /// Work function of the approach branch, zero at the jump-in point; past the jump-in
    /// (α̂ < α̂_A) that of the point reflection through A.
    fn approach_work(&self, alpha_hat: f64) -> f64 {
        let Approach::SemiRigid {
            table,
            cumulative,
            tabor_mu,
        } = &self.approach
        else {
            return 0.0;
        };
        let d = alpha_hat - self.jump_in;
        if d < 0.0 {
            // Φ(α) = 2T_A(α − α_A) + Φ(2α_A − α) for the reflected force.
            return 2.0 * self.jump_in_t_hat * d + self.approach_work(self.jump_in - d);
        }
        let s = d.sqrt();
        let h = table.step();
        if s <= table.end() {
            let i = ((s / h) as usize).min(table.len() - 2);
            return cumulative[i] + work_along(table, h * i as f64, s);
        }
        // Tail T̂ = T̂_end ((α̂_end + 1/μ)/(α̂ + 1/μ))².
        let kappa = 1.0 / tabor_mu;
        let far = self.jump_in + table.end() * table.end() + kappa;
        let t_end = table.eval(table.end());
        cumulative[table.len() - 1] + t_end * far * far * (1.0 / far - 1.0 / (alpha_hat + kappa))
    }

    /// The approach branch above the jump-in (and its point reflection through A below).
    #[inline]
    fn approach_t_hat(&self, alpha_hat: f64) -> f64 {
        match &self.approach {
            Approach::ForceFree => 0.0,
            Approach::SemiRigid {
                table, tabor_mu, ..
            } => {
                let d = alpha_hat - self.jump_in;
                if d < 0.0 {
                    return 2.0 * self.jump_in_t_hat - table.eval((-d).sqrt());
                }
                let s = d.sqrt();
                if s <= table.end() {
                    table.eval(s)
                } else {
                    let far = self.jump_in + table.end() * table.end();
                    let k = (far + 1.0 / tabor_mu) / (alpha_hat + 1.0 / tabor_mu);
                    table.eval(table.end()) * k * k
                }
            }
        }
    }

    /// The JKR contact branch (5) on the displacement-stable side (â ≥ â_C), continued past
    /// C by point reflection through C so that overshooting trial stages see a continuous
    /// force.
    #[inline]
    fn contact_t_hat(&self, alpha_hat: f64) -> f64 {
        let d = self.c_alpha_hat - alpha_hat;
        if d < 0.0 {
            return 2.0 * self.c_t_hat - self.contact.eval((-d).sqrt());
        }
        let s = d.sqrt();
        if s <= self.contact.end() {
            self.contact.eval(s)
        } else {
            jkr::force_hat(jkr::a_hat_from_separation(alpha_hat).unwrap_or(jkr::A_HAT_C))
        }
    }
}

impl AdhesiveLaw {
    /// Work function of the contact branch: Ŵ(â(α̂)) of eq. (6); past C that of the point
    /// reflection through C.
    fn contact_work(&self, alpha_hat: f64) -> f64 {
        let d = alpha_hat - self.c_alpha_hat;
        if d > 0.0 {
            return 2.0 * self.c_t_hat * d + self.contact_work(self.c_alpha_hat - d);
        }
        jkr::work_hat(jkr::a_hat_from_separation(alpha_hat).unwrap_or(jkr::A_HAT_C))
    }
}

impl ForceLaw for AdhesiveLaw {
    #[inline]
    fn t_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        match branch {
            Branch::Free => self.approach_t_hat(alpha_hat),
            Branch::Contact => self.contact_t_hat(alpha_hat),
        }
    }
    fn work_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        match branch {
            Branch::Free => self.approach_work(alpha_hat),
            Branch::Contact => self.contact_work(alpha_hat),
        }
    }
    fn jump_in_alpha_hat(&self) -> f64 {
        self.jump_in
    }
    fn jump_out_alpha_hat(&self) -> f64 {
        self.c_alpha_hat
    }
    fn free_branch_is_force_free(&self) -> bool {
        matches!(self.approach, Approach::ForceFree)
    }
    fn loop_area_hat(&self) -> f64 {
        self.loop_area
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::hybrid;

    #[test]
    fn loop_areas_match_the_closed_forms() {
        let h = AdhesiveLaw::hybrid(5.0, JumpIn::Fit).unwrap();
        assert!((h.loop_area_hat() - hybrid::w_hat_fit(5.0)).abs() < 1e-12);
        assert!((AdhesiveLaw::jkr().loop_area_hat() - jkr::w_hat_jkr()).abs() < 1e-12);
    }

    #[test]
    fn contact_table_matches_the_closed_form() {
        let l = AdhesiveLaw::jkr();
        let mut worst: f64 = 0.0;
        // From 1e-6 below C (nearer, the closed form itself is ill-conditioned).
        for i in 0..20_000 {
            let alpha = jkr::ALPHA_HAT_C - 1e-6 - 70.0 * (i as f64 / 20_000.0).powi(2);
            let exact = jkr::force_hat(jkr::a_hat_from_separation(alpha).unwrap());
            worst =
                worst.max((l.t_hat(alpha, Branch::Contact) - exact).abs() / (1.0 + exact.abs()));
        }
        assert!(worst < 1e-12, "{worst:e}");
    }

    #[test]
    fn work_functions_are_antiderivatives_of_the_force() {
        let laws = [
            AdhesiveLaw::jkr(),
            AdhesiveLaw::hybrid_attractive(5.0).unwrap(),
        ];
        for l in &laws {
            for branch in [Branch::Free, Branch::Contact] {
                for &alpha in &[-3.0, -0.5, 0.3, 0.9, 1.2, 1.6, 1.7, 2.5, 40.0, 80.0] {
                    let h = 1e-5;
                    let dw =
                        (l.work_hat(alpha + h, branch) - l.work_hat(alpha - h, branch)) / (2.0 * h);
                    let t = l.t_hat(alpha, branch);
                    assert!(
                        (dw - t).abs() < 1e-6 * (1.0 + t.abs()),
                        "{branch:?} {alpha}: {dw} vs {t}"
                    );
                }
            }
        }
    }

    #[test]
    fn contact_branch_is_continuous_through_c() {
        let l = AdhesiveLaw::jkr();
        let c = jkr::point_c();
        for eps in [1e-3, 1e-6, 1e-9] {
            let below = l.t_hat(c.alpha_hat - eps, Branch::Contact);
            let above = l.t_hat(c.alpha_hat + eps, Branch::Contact);
            assert!((below - c.t_hat).abs() < 10.0 * eps.sqrt());
            assert!((above - c.t_hat).abs() < 10.0 * eps.sqrt());
        }
        assert!(l.t_hat(100.0, Branch::Contact).is_finite());
    }

    #[test]
    fn attractive_approach_follows_the_semi_rigid_curve() {
        let mu = 5.0;
        let l = AdhesiveLaw::hybrid_attractive(mu).unwrap();
        let fold = semi_rigid::jump_in_exact(mu, EighthPower::Keep)
            .unwrap()
            .unwrap();
        for &dh in &[1e-3, 0.1, 0.5, 2.0, 8.0, 50.0] {
            let h = fold.h0_bar + dh;
            let alpha = semi_rigid::separation_over_range(h, mu, EighthPower::Keep) / mu;
            let t = l.t_hat(alpha, Branch::Free);
            let expect = semi_rigid::force_hat(h);
            assert!((t - expect).abs() < 1e-6 * expect, "h {h}: {t} vs {expect}");
        }
        // Less loss than the force-free hybrid with the same jump-in would give.
        assert!(l.loop_area_hat() > 0.0);
    }
}
