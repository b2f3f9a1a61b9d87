//! The period-1 orbit family followed through the rest separation by pseudo-arclength
//! continuation of the shooting equations.
//!
//! Unknowns u = (z, q): the section state at the drive phase (x and x',
//! [`Simulation::z`]) and the rest separation q = z_c/L. The equations
//! P(z; q) − z = 0 have the Jacobian [M − I | ∂P/∂q],
//! exact from the variational equations ([`Simulation::cycle_with_derivative`]); its null
//! vector is the branch's tangent, so the family is followed through its folds, stable
//! and unstable parts alike. Each new point is predicted along the tangent and corrected
//! by Newton's method on the equations plus the arclength condition. The test functions
//! det(M − I) (a Floquet multiplier through +1: a fold) and det(M + I) (through −1: a
//! period doubling) are watched between points, and where one changes sign its zero is
//! located by the secant method along the step.
//!
//! The period map is smooth wherever the contact switches are crossed transversally. Where
//! an orbit grazes a switch (it just starts to touch, or a hysteretic law's tip stalls at
//! a fold) it is not, and the continuation may stop there; [`Stop`] says why.

use super::march::{CycleIntegrals, Phase, Simulation};
use super::shooting::{Multipliers, eigenvalues};
use crate::error::{Error, Result};
use crate::physics::law::ForceLaw;
use nalgebra::{Complex, DMatrix, DVector, Vector3};

/// Settings of a continuation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContinuationOptions {
    /// Where to stop: the branch is followed while q stays between the start and this.
    pub q_end: f64,
    /// Largest step along the branch (in units of L; the arclength mixes x, x' and q).
    pub max_step: f64,
    /// Smallest step tried before giving up.
    pub min_step: f64,
    /// Most points on the branch.
    pub max_points: usize,
    /// Largest |P(z) − z| accepted at a point (units of L).
    pub tolerance: f64,
}

impl Default for ContinuationOptions {
    fn default() -> Self {
        Self {
            q_end: 0.0,
            max_step: 0.01,
            min_step: 1e-7,
            max_points: 5000,
            tolerance: 1e-10,
        }
    }
}

/// What a point of the branch is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointKind {
    /// A point of the branch.
    Regular,
    /// A fold: a Floquet multiplier at +1; the branch turns back in q there.
    Fold,
    /// A period doubling: a Floquet multiplier at −1; a period-2 family branches off.
    PeriodDoubling,
}

/// A point of the period-1 orbit family.
#[derive(Debug, Clone)]
pub struct BranchPoint {
    /// q = z_c/L.
    pub q: f64,
    /// The state on the orbit at the drive phase.
    pub phase: Phase,
    /// The integrals over the orbit's period.
    pub integrals: CycleIntegrals,
    /// Floquet multipliers.
    pub multipliers: Multipliers,
    /// What the point is.
    pub kind: PointKind,
}

impl BranchPoint {
    /// Whether the orbit is stable (every multiplier inside the unit circle).
    pub fn stable(&self) -> bool {
        self.multipliers.iter().all(|m| m.norm() < 1.0)
    }
}

/// Why a continuation ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stop {
    /// It reached `q_end`.
    Reached,
    /// It came back past its start.
    TurnedBack,
    /// The step fell below `min_step` at this q: the map is not smooth there.
    NotSmooth(f64),
    /// It made `max_points` points.
    PointCap,
}

/// A followed branch: its points in order along the branch (folds and period doublings
/// inserted where they lie) and why it ended.
#[derive(Debug, Clone)]
pub struct Branch {
    /// The points.
    pub points: Vec<BranchPoint>,
    /// Why it ended.
    pub stop: Stop,
}

/// A point of the unknowns with its evaluation.
#[derive(Clone)]
struct Solved {
    /// (z, q).
    u: DVector<f64>,
    phase: Phase,
    integrals: CycleIntegrals,
    /// [M − I | ∂P/∂q] at u.
    jacobian: DMatrix<f64>,
}

impl Solved {
    /// Dimension of the section state.
    fn dim(&self) -> usize {
        self.jacobian.nrows()
    }

    /// q.
    fn q(&self) -> f64 {
        self.u[self.dim()]
    }

    fn monodromy(&self) -> DMatrix<f64> {
        let d = self.dim();
        self.jacobian.columns(0, d) + DMatrix::identity(d, d)
    }

    /// The unit null vector of the Jacobian, pointing the way of `along`: for a section
    /// of (x, x') the cross product of its two rows, otherwise the solution of the
    /// Jacobian bordered by `along`.
    fn tangent(&self, along: &DVector<f64>) -> Option<DVector<f64>> {
        let t = if self.dim() == 2 {
            let row = |i: usize| {
                Vector3::new(
                    self.jacobian[(i, 0)],
                    self.jacobian[(i, 1)],
                    self.jacobian[(i, 2)],
                )
            };
            let t = row(0).cross(&row(1));
            DVector::from_column_slice((t / t.norm()).as_slice())
        } else {
            let d = self.dim();
            let mut bordered = self.jacobian.clone().insert_row(d, 0.0);
            bordered.row_mut(d).copy_from(&along.transpose());
            let mut e = DVector::zeros(d + 1);
            e[d] = 1.0;
            let t = bordered.lu().solve(&e)?;
            &t / t.norm()
        };
        if !t.iter().all(|c| c.is_finite()) {
            return None;
        }
        Some(if t.dot(along) < 0.0 { -t } else { t })
    }

    /// det(M − I) and det(M + I).
    fn tests(&self) -> [f64; 2] {
        let m = self.monodromy();
        let one = DMatrix::identity(self.dim(), self.dim());
        [(&m - &one).determinant(), (&m + &one).determinant()]
    }

    fn point(&self, kind: PointKind) -> BranchPoint {
        BranchPoint {
            q: self.q(),
            phase: self.phase.clone(),
            integrals: self.integrals,
            multipliers: eigenvalues(&self.monodromy()),
            kind,
        }
    }
}

/// Follows the period-1 family of one simulation (its rest separation is replaced by q).
struct Follower<'a, 'b, L: ForceLaw> {
    sim: &'b Simulation<'a, L>,
    tolerance: f64,
}

impl<L: ForceLaw> Follower<'_, '_, L> {
    /// The period map at u from the section `at` (its drive phase and branch): its
    /// residual P − z and Jacobian. `None` where it cannot be evaluated (the orbit comes
    /// back on another branch, or stalls at a fold).
    fn evaluate(&self, at: &Phase, u: &DVector<f64>) -> Result<Option<(DVector<f64>, Solved)>> {
        let d = u.len() - 1;
        let mut sim = *self.sim;
        sim.cpl.a0 = u[d] * sim.cpl.a1;
        let z = u.rows(0, d).into_owned();
        let mut spent = 0;
        let Some(value) = sim.period_map(at, &z, 1, &mut spent)? else {
            return Ok(None);
        };
        let mut jacobian = value.derivative;
        for i in 0..d {
            jacobian[(i, i)] -= 1.0;
        }
        let residual = sim.z(&value.end) - &z;
        let phase = Phase {
            tau: at.tau,
            ..sim.at_z(&value.end, &z)
        };
        let solved = Solved {
            u: u.clone(),
            phase,
            integrals: value.integrals,
            jacobian,
        };
        Ok(Some((residual, solved)))
    }

    /// Newton's method on P(u) − z = 0 and t·(u − anchor) = 0 from `anchor`, the section
    /// as at `from`.
    fn correct(
        &self,
        from: &Phase,
        anchor: DVector<f64>,
        t: &DVector<f64>,
    ) -> Result<Option<Solved>> {
        super::budget::budgeted(super::budget::STEPS, || {
            self.correct_within_budget(from, anchor, t)
        })
    }

    fn correct_within_budget(
        &self,
        from: &Phase,
        anchor: DVector<f64>,
        t: &DVector<f64>,
    ) -> Result<Option<Solved>> {
        let mut u = anchor.clone();
        for _ in 0..8 {
            let Some((r, solved)) = self.evaluate(from, &u)? else {
                return Ok(None);
            };
            if r.amax() <= self.tolerance {
                return Ok(Some(solved));
            }
            let d = r.len();
            let mut system = solved.jacobian.insert_row(d, 0.0);
            system.row_mut(d).copy_from(&t.transpose());
            let rhs = DVector::from_fn(d + 1, |i, _| {
                if i < d {
                    -r[i]
                } else {
                    -t.dot(&(&u - &anchor))
                }
            });
            let Some(du) = system.lu().solve(&rhs) else {
                return Ok(None);
            };
            if !du.iter().all(|d| d.is_finite()) || du.amax() > 0.5 {
                return Ok(None);
            }
            u += du;
        }
        Ok(None)
    }

    /// The point where test function `which` vanishes between `from` (tangent `t`) and
    /// the point a step `h` along it, by the secant method on the step length.
    fn locate(&self, from: &Solved, t: &DVector<f64>, h: f64, which: usize) -> Result<Solved> {
        let at =
            |s: f64| -> Result<Option<Solved>> { self.correct(&from.phase, &from.u + t * s, t) };
        let (mut a, mut fa) = (0.0, from.tests()[which]);
        let Some(end) = at(h)? else {
            return Err(Error::Numerical(
                "the step to a bifurcation could not be repeated".into(),
            ));
        };
        let (mut b, mut fb) = (h, end.tests()[which]);
        let mut best = if fa.abs() < fb.abs() {
            from.clone()
        } else {
            end
        };
        // Illinois-modified regula falsi: bracketing, superlinear.
        let mut side = 0;
        for _ in 0..60 {
            let s = (a * fb - b * fa) / (fb - fa);
            let Some(p) = at(s)? else {
                break;
            };
            let fs = p.tests()[which];
            best = p;
            if fs == 0.0 || (b - a).abs() < 1e-14 * (1.0 + h) {
                break;
            }
            if fs.signum() == fb.signum() {
                (b, fb) = (s, fs);
                if side == 1 {
                    fa *= 0.5;
                }
                side = 1;
            } else {
                (a, fa) = (s, fs);
                if side == -1 {
                    fb *= 0.5;
                }
                side = -1;
            }
            // The multiplier it tracks is within 1e-10 of ±1.
            let m = best.monodromy();
            let target = if which == 0 { 1.0 } else { -1.0 };
            if eigenvalues(&m)
                .iter()
                .any(|l| (l - Complex::new(target, 0.0)).norm() < 1e-10)
            {
                break;
            }
        }
        Ok(best)
    }
}

/// Follow the period-1 orbit family of `sim` from the orbit through `start` (a state on
/// it at the drive phase, at the simulation's own rest separation) towards
/// `opts.q_end`, with folds and period doublings located on the way.
pub fn follow_period_one<L: ForceLaw>(
    sim: &Simulation<'_, L>,
    start: &Phase,
    opts: &ContinuationOptions,
) -> Result<Branch> {
    let follower = Follower {
        sim,
        tolerance: opts.tolerance,
    };
    let q0 = sim.cpl.a0 / sim.cpl.a1;
    let toward = (opts.q_end - q0).signum();
    let z0 = sim.z(start);
    let d = z0.len();
    let u0 = z0.insert_row(d, q0);
    // The first point: corrected at fixed q (the tangent condition along q).
    let mut along_q = DVector::zeros(d + 1);
    along_q[d] = toward;
    let no_tangent = || Error::Numerical("the branch has no tangent at its first point".into());
    let Some(mut here) = follower.correct(start, u0, &along_q)? else {
        return Err(Error::Numerical(
            "no period-1 orbit through the starting state to continue".into(),
        ));
    };
    let mut t = here.tangent(&along_q).ok_or_else(no_tangent)?;
    let mut points = vec![here.point(PointKind::Regular)];
    let mut h = opts
        .max_step
        .min(0.1 * (opts.q_end - q0).abs())
        .max(opts.min_step);
    let stop = loop {
        if points.len() >= opts.max_points {
            break Stop::PointCap;
        }
        let Some(next) = follower.correct(&here.phase, &here.u + &t * h, &t)? else {
            h *= 0.5;
            if h < opts.min_step {
                break Stop::NotSmooth(here.q());
            }
            continue;
        };
        // A tangent that reverses more than a right angle: the step jumped branches.
        let t_next = next.tangent(&t).filter(|t_next| t_next.dot(&t) >= 0.5);
        let Some(t_next) = t_next else {
            h *= 0.5;
            if h < opts.min_step {
                break Stop::NotSmooth(here.q());
            }
            continue;
        };
        let (before, after) = (here.tests(), next.tests());
        for (which, kind) in [(0, PointKind::Fold), (1, PointKind::PeriodDoubling)] {
            if before[which] != 0.0 && before[which].signum() != after[which].signum() {
                let found = follower.locate(&here, &t, h, which)?;
                points.push(found.point(kind));
            }
        }
        points.push(next.point(PointKind::Regular));
        let q = next.q();
        here = next;
        t = t_next;
        if (q - opts.q_end) * toward >= 0.0 {
            break Stop::Reached;
        }
        if (q - q0) * toward < 0.0 {
            break Stop::TurnedBack;
        }
        h = (1.5 * h).min(opts.max_step);
    };
    Ok(Branch { points, stop })
}
