//! Adhesive laws with a contact branch ending at a jump-out fold: the paper's hybrid law
//! (jump-in at α̂_A of (17)), the hybrid law with Greenwood's semi-rigid attraction on
//! approach, classic JKR (jump-in at α̂ = 0), and the tabulated Lennard-Jones law from the
//! numerical solution. The JKR-based laws jump out at the rigid-grip point C of eq. (8).

use super::fold_branch::{FarField, FoldBranch, Side};
use super::registry::not_applicable;
use super::{AnyLaw, Branch, ForceLaw, LawInfo, LawSpec};
use crate::error::{Error, Result, positive};
use crate::numeric::{bracketed_root, lagrange};
use crate::physics::contact::hybrid::JumpIn;
use crate::physics::contact::jkr;
use crate::physics::contact::lj::LjSolution;
use crate::physics::contact::lj::Reach;
use crate::physics::contact::lj::curve::CurvePoint;
use crate::physics::contact::semi_rigid::{self, EighthPower};
use crate::physics::params::Contact;
use std::sync::OnceLock;

/// The registry's entry for the paper's hybrid law.
pub(super) const HYBRID: LawInfo = LawInfo {
    name: "hybrid",
    help: "the paper's hybrid law: force-free approach, jump-in at α̂_A of eq. (17), \
           JKR contact branch (5), jump-out at α̂_C (8); loop area Ŵ_hybrid (18)",
    build: |_, contact| {
        let mu = contact.tabor_mu();
        AdhesiveLaw::hybrid(mu, JumpIn::Fit)
            .map(AnyLaw::Adhesive)
            .map_err(|e| not_applicable("hybrid", mu, e))
    },
    hertzian: false,
    touches_at_range: false,
};

/// The registry's entry for the hybrid law with a semi-rigid attraction on approach.
pub(super) const HYBRID_ATTRACTIVE: LawInfo = LawInfo {
    name: "hybrid-attractive",
    help: "the hybrid law with Greenwood's semi-rigid attraction (12), (14) on the \
           approach branch, jumping in at that curve's own fold (15)",
    build: |_, contact| {
        let mu = contact.tabor_mu();
        AdhesiveLaw::hybrid_attractive(mu)
            .map(AnyLaw::Adhesive)
            .map_err(|e| not_applicable("hybrid-attractive", mu, e))
    },
    hertzian: false,
    touches_at_range: false,
};

/// The registry's entry for classic JKR.
pub(super) const JKR: LawInfo = LawInfo {
    name: "jkr",
    help: "classic JKR: no force before contact, jump-in at α = 0, jump-out at α̂_C (8)",
    build: |_, _| Ok(AnyLaw::Adhesive(AdhesiveLaw::jkr())),
    hertzian: false,
    touches_at_range: false,
};

/// The registry's entry for the tabulated Lennard-Jones law.
pub(super) const LJ: LawInfo = LawInfo {
    name: "lj",
    help: "the Lennard-Jones law (10) tabulated from the full numerical solution: both \
           branches, jumps at its folds A and C (first use per μ solves it)",
    build: |_: &LawSpec, contact: &Contact| {
        let mu = contact.tabor_mu();
        let solution = crate::physics::contact::lj::obtain(mu, Reach::Springs).map_err(|e| {
            match e {
                // No loop: no hysteretic law to tabulate (a cell a map skips).
                Error::NoHysteresis(why) => Error::NotApplicable(why),
                other => other,
            }
        })?;
        AdhesiveLaw::lennard_jones(&solution)
            .map(AnyLaw::Adhesive)
            .map_err(|e| not_applicable("lj", mu, e))
    },
    hertzian: false,
    touches_at_range: false,
};

/// Nodes of the contact-branch tables (uniform in √(α̂_C − α̂)).
const CONTACT_NODES: usize = 8193;
/// The JKR contact table reaches down to α̂_C − this; deeper, eq. (5) in closed form.
const CONTACT_SPAN: f64 = 60.0;
/// Nodes of the approach tables (uniform in √(α̂ − α̂_A)).
const APPROACH_NODES: usize = 4097;
/// The semi-rigid approach table reaches α̂_A + this; beyond, T̂ falls as 1/(α̂ + 1/μ)².
const APPROACH_SPAN: f64 = 60.0;

/// The JKR contact branch T̂(α̂) of eq. (5) on its displacement-stable side, tabulated
/// against √(α̂_C − α̂) (the closed-form inverse costs a cube root and several square
/// roots per call; the table one). It depends on nothing (the hats absorb every
/// parameter), so it is built once per process and copied: a map builds a law per cell.
fn jkr_contact() -> FoldBranch {
    static TABLE: OnceLock<FoldBranch> = OnceLock::new();
    TABLE
        .get_or_init(|| {
            FoldBranch::new(
                (jkr::ALPHA_HAT_C, jkr::T_HAT_C),
                Side::Below,
                CONTACT_SPAN.sqrt(),
                CONTACT_NODES,
                FarField::JkrShift { shift: 0.0 },
                |u| {
                    if u == 0.0 {
                        // At the fold the inverse is ill-conditioned: take C of eq. (8).
                        return jkr::T_HAT_C;
                    }
                    let alpha = jkr::ALPHA_HAT_C - u * u;
                    jkr::force_hat(jkr::a_hat_from_separation(alpha).unwrap_or(jkr::A_HAT_C))
                },
            )
        })
        .clone()
}

/// An adhesive law: approach branch (force-free or tabulated), jump-in at its fold or
/// at a given separation, contact branch, jump-out at the contact branch's fold.
#[derive(Debug, Clone)]
pub struct AdhesiveLaw {
    /// `None`: no force before the jump-in.
    approach: Option<FoldBranch>,
    jump_in: f64,
    contact: FoldBranch,
    loop_area: f64,
}

impl AdhesiveLaw {
    fn new(approach: Option<FoldBranch>, jump_in: f64, contact: FoldBranch) -> Result<Self> {
        let (c_alpha, _) = contact.fold();
        if jump_in >= c_alpha {
            return Err(Error::NotApplicable(format!(
                "its jump-in separation {jump_in:.4} is not below the jump-out separation \
                 {c_alpha:.4}, so there is no contact branch to land on"
            )));
        }
        let mut law = Self {
            approach,
            jump_in,
            contact,
            loop_area: 0.0,
        };
        // ∮ T̂ dα̂ = ∫_{α̂_A}^{α̂_C} (T̂_contact − T̂_approach) dα̂.
        law.loop_area = law.work_hat(c_alpha, Branch::Contact)
            - law.work_hat(jump_in, Branch::Contact)
            - (law.work_hat(c_alpha, Branch::Free) - law.work_hat(jump_in, Branch::Free));
        Ok(law)
    }

    /// The paper's hybrid law: force-free approach, jump-in at α̂_A from `jump_in`
    /// ((17) by default), JKR contact branch (5), jump-out at α̂_C (8); loop area Ŵ (18).
    pub fn hybrid(tabor_mu: f64, jump_in: JumpIn) -> Result<Self> {
        let alpha_a = jump_in.alpha_hat_a(tabor_mu)?.ok_or_else(|| {
            Error::NotApplicable("there is no jump-in instability at this mu".into())
        })?;
        Self::new(None, alpha_a, jkr_contact())
    }

    /// Classic JKR: no force before contact, jump-in at α̂ = 0 (B), jump-out at C; loop
    /// area Ŵ_JKR (9).
    pub fn jkr() -> Self {
        Self::new(None, 0.0, jkr_contact()).expect("0 < alpha_hat_C")
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
        // Central gap h̄₀(u) on the stable side of the fold: α̂(h̄₀) = α̂_A + u².
        let gap_at = |u: f64| -> f64 {
            if u <= 0.0 {
                return fold.h0_bar;
            }
            let target = fold.alpha_hat + u * u;
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
        let approach = FoldBranch::new(
            (fold.alpha_hat, fold.t_hat),
            Side::Above,
            APPROACH_SPAN.sqrt(),
            APPROACH_NODES,
            FarField::Decay {
                kappa: 1.0 / tabor_mu,
            },
            |u| semi_rigid::force_hat(gap_at(u)),
        );
        Self::new(Some(approach), fold.alpha_hat, jkr_contact())
    }

    /// The tabulated Lennard-Jones law of a numerical solution: its approach branch up to
    /// the fold A, its contact branch from the fold C into contact; beyond the traced range
    /// the approach decays as 1/(α̂ + 1/μ)² and the contact branch follows JKR (5) shifted
    /// to join it.
    pub fn lennard_jones(solution: &LjSolution) -> Result<Self> {
        let a = (solution.alpha_hat_a.value, solution.t_hat_a.value);
        let c = (solution.alpha_hat_c.value, solution.t_hat_c.value);
        let resample = |points: &[CurvePoint],
                        fold: (f64, f64),
                        side: Side|
         -> Result<(Vec<(f64, f64)>, f64)> {
            // (u, T̂) of the traced points, u = √|α̂ − α̂₀| increasing away from the fold.
            let mut pts: Vec<(f64, f64)> = points
                .iter()
                .map(|p| {
                    (
                        (match side {
                            Side::Above => p.alpha_hat - fold.0,
                            Side::Below => fold.0 - p.alpha_hat,
                        })
                        .max(0.0)
                        .sqrt(),
                        p.t_hat,
                    )
                })
                .collect();
            pts.push((0.0, fold.1));
            pts.sort_by(|x, y| x.0.total_cmp(&y.0));
            pts.dedup_by(|x, y| (x.0 - y.0).abs() < 1e-12);
            let u_max = pts.last().map_or(0.0, |p| p.0);
            if pts.len() < 8 || u_max <= 0.0 {
                return Err(Error::Numerical(
                    "too few traced points for the LJ law".into(),
                ));
            }
            Ok((pts, u_max))
        };
        let (app, u_app) = resample(solution.approach_branch(), a, Side::Above)?;
        let (con, u_con) = resample(solution.contact_branch(), c, Side::Below)?;
        let approach = FoldBranch::new(
            a,
            Side::Above,
            u_app,
            APPROACH_NODES,
            FarField::Decay {
                kappa: 1.0 / solution.tabor_mu,
            },
            |u| local_cubic(&app, u),
        );
        let deepest = c.0 - u_con * u_con;
        let shift = local_cubic(&con, u_con)
            - jkr::force_hat(jkr::a_hat_from_separation(deepest).unwrap_or(jkr::A_HAT_C));
        let contact = FoldBranch::new(
            c,
            Side::Below,
            u_con,
            CONTACT_NODES,
            FarField::JkrShift { shift },
            |u| local_cubic(&con, u),
        );
        Self::new(Some(approach), a.0, contact)
    }
}

/// Cubic through the four sample points nearest to `u` (sorted by u).
fn local_cubic(points: &[(f64, f64)], u: f64) -> f64 {
    let k = points.partition_point(|p| p.0 < u);
    let start = k.saturating_sub(2).min(points.len() - 4);
    lagrange(&points[start..start + 4], u)
}

impl ForceLaw for AdhesiveLaw {
    #[inline]
    fn t_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        match (branch, &self.approach) {
            (Branch::Contact, _) => self.contact.t_hat(alpha_hat),
            // (Out of contact, with or without a neck: the approach branch.)
            (_, None) => 0.0,
            (_, Some(a)) => a.t_hat(alpha_hat),
        }
    }
    #[inline]
    fn slope_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        match (branch, &self.approach) {
            (Branch::Contact, _) => self.contact.slope_hat(alpha_hat),
            // (Out of contact, with or without a neck: the approach branch.)
            (_, None) => 0.0,
            (_, Some(a)) => a.slope_hat(alpha_hat),
        }
    }
    #[inline]
    fn t_and_slope_hat(&self, alpha_hat: f64, branch: Branch) -> (f64, f64) {
        match (branch, &self.approach) {
            (Branch::Contact, _) => self.contact.t_and_slope_hat(alpha_hat),
            (_, None) => (0.0, 0.0),
            (_, Some(a)) => a.t_and_slope_hat(alpha_hat),
        }
    }
    fn work_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        match (branch, &self.approach) {
            (Branch::Contact, _) => self.contact.work_hat(alpha_hat),
            // (Out of contact, with or without a neck: the approach branch.)
            (_, None) => 0.0,
            (_, Some(a)) => a.work_hat(alpha_hat),
        }
    }
    fn jump_in_alpha_hat(&self) -> f64 {
        self.jump_in
    }
    fn jump_out_alpha_hat(&self) -> f64 {
        self.contact.fold().0
    }
    fn free_branch_is_force_free(&self) -> bool {
        self.approach.is_none()
    }
    fn loop_area_hat(&self) -> f64 {
        self.loop_area
    }
}
