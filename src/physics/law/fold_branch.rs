//! A force branch T̂(α̂) that ends at a fold (α̂₀, T̂₀), where T̂ has a square-root
//! singularity in α̂. Tabulated against u = √(σ(α̂ − α̂₀)) — smooth through the fold — on
//! a uniform grid (O(1) look-up), with its work function (antiderivative) the exact
//! integral of the interpolant (cumulative over whole intervals, in closed form within
//! the last: [`UniformTable::weighted_integral`]), continued past the fold by point
//! reflection (so overshooting trial stages see a continuous force) and beyond the
//! table by an analytic far field.

use super::table::UniformTable;
use crate::physics::contact::jkr;

/// Which side of the fold the branch lives on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// α̂ ≥ α̂₀ (an approach branch ending at the jump-in fold).
    Above,
    /// α̂ ≤ α̂₀ (a contact branch ending at the jump-out fold).
    Below,
}

/// How the branch continues beyond its table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FarField {
    /// T̂ ∝ 1/(α̂ + κ)² (a distant attraction).
    Decay {
        /// κ (1/μ for the Lennard-Jones and semi-rigid attractions).
        kappa: f64,
    },
    /// The JKR curve (5) plus a constant (deep contact tends to JKR, then Hertz).
    JkrShift {
        /// Added to the JKR force.
        shift: f64,
    },
}

/// A tabulated fold branch.
#[derive(Debug, Clone)]
pub struct FoldBranch {
    table: UniformTable,
    /// +1 above the fold, −1 below.
    sign: f64,
    /// Last abscissa of the table.
    u_max: f64,
    /// ∫ T̂ dα̂ from the fold to each node.
    cumulative: Vec<f64>,
    fold_alpha_hat: f64,
    fold_t_hat: f64,
    far: FarField,
}

impl FoldBranch {
    /// Tabulate `t_of_u` (T̂ as a function of u = √|α̂ − α̂₀|) on `nodes` points up to
    /// u = `u_max`.
    pub fn new(
        fold: (f64, f64),
        side: Side,
        u_max: f64,
        nodes: usize,
        far: FarField,
        t_of_u: impl Fn(f64) -> f64,
    ) -> Self {
        let table = UniformTable::sample(0.0, u_max, nodes, t_of_u);
        let mut branch = Self {
            cumulative: Vec::with_capacity(table.len()),
            sign: match side {
                Side::Above => 1.0,
                Side::Below => -1.0,
            },
            u_max: table.end(),
            table,
            fold_alpha_hat: fold.0,
            fold_t_hat: fold.1,
            far,
        };
        let mut sum = 0.0;
        for i in 0..branch.table.len() {
            if i > 0 {
                sum += branch.work_in_table(i - 1, 1.0);
            }
            branch.cumulative.push(sum);
        }
        branch
    }

    /// The fold (α̂₀, T̂₀).
    pub fn fold(&self) -> (f64, f64) {
        (self.fold_alpha_hat, self.fold_t_hat)
    }

    fn sign(&self) -> f64 {
        self.sign
    }

    fn alpha_at(&self, u: f64) -> f64 {
        self.fold_alpha_hat + self.sign() * u * u
    }

    /// ∫ T̂ dα̂ from node `i` to the fraction `t` of its interval: dα̂ = σ 2u du.
    fn work_in_table(&self, i: usize, t: f64) -> f64 {
        self.sign() * self.table.weighted_integral(i, t)
    }

    /// T̂ at α̂.
    #[inline]
    pub fn t_hat(&self, alpha_hat: f64) -> f64 {
        let d = self.sign * (alpha_hat - self.fold_alpha_hat);
        if d >= 0.0 {
            let u = d.sqrt();
            if u <= self.u_max {
                return self.table.eval(u);
            }
        }
        self.t_hat_outside(alpha_hat, d)
    }

    /// T̂ past the fold (point reflection through it) or beyond the table (far field).
    #[cold]
    fn t_hat_outside(&self, alpha_hat: f64, d: f64) -> f64 {
        if d < 0.0 {
            return 2.0 * self.fold_t_hat - self.t_hat(2.0 * self.fold_alpha_hat - alpha_hat);
        }
        let end = self.u_max;
        let (alpha_end, t_end) = (self.alpha_at(end), self.table.eval(end));
        match self.far {
            FarField::Decay { kappa } => {
                let k = (alpha_end + kappa) / (alpha_hat + kappa);
                t_end * k * k
            }
            FarField::JkrShift { shift } => jkr_force(alpha_hat) + shift,
        }
    }

    /// Slope dT̂/dα̂ at α̂: (dT̂/du)·σ/(2u). It grows as 1/√(distance) towards the fold,
    /// where it is capped at the value a distance `FOLD_SLOPE_FLOOR_U`² away (an
    /// integrable singularity: the cap changes ∫ (dT̂/dα̂) dτ by O(that distance)).
    #[inline]
    pub fn slope_hat(&self, alpha_hat: f64) -> f64 {
        let d = self.sign * (alpha_hat - self.fold_alpha_hat);
        if d >= 0.0 {
            let u = d.sqrt();
            if u <= self.u_max {
                return self.table.slope(u) * self.sign / (2.0 * u.max(FOLD_SLOPE_FLOOR_U));
            }
        }
        self.slope_outside(alpha_hat, d)
    }

    /// [`FoldBranch::t_hat`] and [`FoldBranch::slope_hat`] at once: one square root and
    /// one look-up.
    #[inline]
    pub fn t_and_slope_hat(&self, alpha_hat: f64) -> (f64, f64) {
        let d = self.sign * (alpha_hat - self.fold_alpha_hat);
        if d >= 0.0 {
            let u = d.sqrt();
            if u <= self.u_max {
                let (t, slope_u) = self.table.eval_and_slope(u);
                return (t, slope_u * self.sign / (2.0 * u.max(FOLD_SLOPE_FLOOR_U)));
            }
        }
        (
            self.t_hat_outside(alpha_hat, d),
            self.slope_outside(alpha_hat, d),
        )
    }

    /// The slope past the fold (the reflected force has the mirrored slope) or beyond
    /// the table (the far field's derivative).
    #[cold]
    fn slope_outside(&self, alpha_hat: f64, d: f64) -> f64 {
        if d < 0.0 {
            return self.slope_hat(2.0 * self.fold_alpha_hat - alpha_hat);
        }
        match self.far {
            FarField::Decay { kappa } => {
                let end = self.u_max;
                let (alpha_end, t_end) = (self.alpha_at(end), self.table.eval(end));
                let k = (alpha_end + kappa) / (alpha_hat + kappa);
                -2.0 * t_end * k * k / (alpha_hat + kappa)
            }
            FarField::JkrShift { .. } => jkr_slope(alpha_hat),
        }
    }

    /// Work function Φ with dΦ/dα̂ = T̂, zero at the fold.
    pub fn work_hat(&self, alpha_hat: f64) -> f64 {
        let d = self.sign() * (alpha_hat - self.fold_alpha_hat);
        if d < 0.0 {
            // Φ(α) = 2T₀(α − α₀) + Φ(2α₀ − α) for the reflected force.
            return 2.0 * self.fold_t_hat * (alpha_hat - self.fold_alpha_hat)
                + self.work_hat(2.0 * self.fold_alpha_hat - alpha_hat);
        }
        let u = d.sqrt();
        let h = self.table.step();
        let end = self.table.end();
        if u <= end {
            let i = ((u / h) as usize).min(self.table.len() - 2);
            return self.cumulative[i] + self.work_in_table(i, u / h - i as f64);
        }
        let last = self.cumulative[self.table.len() - 1];
        let (alpha_end, t_end) = (self.alpha_at(end), self.table.eval(end));
        match self.far {
            FarField::Decay { kappa } => {
                let a = alpha_end + kappa;
                last + t_end * a * a * (1.0 / a - 1.0 / (alpha_hat + kappa))
            }
            FarField::JkrShift { shift } => {
                last + jkr_work(alpha_hat) - jkr_work(alpha_end) + shift * (alpha_hat - alpha_end)
            }
        }
    }
}

/// JKR force (5) on the stable contact branch at α̂ (≤ α̂_C).
#[doc(hidden)]
pub fn jkr_force(alpha_hat: f64) -> f64 {
    jkr::force_hat(jkr::a_hat_from_separation(alpha_hat).unwrap_or(jkr::A_HAT_C))
}

/// dT̂/dα̂ of the JKR curve (5) on its stable contact branch at α̂: (dT̂/dâ)/(dα̂/dâ).
fn jkr_slope(alpha_hat: f64) -> f64 {
    let a = jkr::a_hat_from_separation(alpha_hat).unwrap_or(jkr::A_HAT_C);
    jkr::d_force_d_a(a) / jkr::d_separation_d_a(a)
}

/// Distance in u = √|α̂ − α̂₀| from the fold below which [`FoldBranch::slope_hat`] is
/// held at its value there.
pub(crate) const FOLD_SLOPE_FLOOR_U: f64 = 1e-8;

/// JKR work function (6) along the stable contact branch at α̂.
fn jkr_work(alpha_hat: f64) -> f64 {
    jkr::work_hat(jkr::a_hat_from_separation(alpha_hat).unwrap_or(jkr::A_HAT_C))
}
