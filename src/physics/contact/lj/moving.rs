//! Continuation on a mesh that moves with the contact edge.
//!
//! On a fixed mesh the edge of the contact — a tensile annulus ~1/(πμ^{3/2}) wide in x —
//! sweeps across hundreds of fine elements while the curve is traced; the nodal gaps then
//! change abruptly along the curve, predictors fail, and the steps stay tiny. Here the
//! nodes are x = a·ξ on a fixed mesh in ξ, fine around ξ = 1, and a is the contact
//! radius, defined by pinning the gap at ξ = 1 to [`EDGE_GAP`] (or the spec's own
//! `edge_gap`; the results do not depend on it beyond their error). Stretching the mesh
//! multiplies the influence matrix by a (no reassembly), the solution varies smoothly
//! with a, and a changes monotonically along the curve from the first contact to deep
//! contact, so plain natural-parameter continuation in a works.
//!
//! The curve is traced in two legs, each holding one fold. The approach leg freezes the
//! mesh at a = a₀ and follows the central gap h̄(0), which falls monotonically from far
//! out through the jump-in fold A. The contact leg starts in deep contact, where the
//! sample pushes (T̂ < 0), by Newton's method from the JKR solution, and follows a
//! falling through the pull-off and the jump-out fold C. Neither leg needs the unstable
//! branch between the folds, the part hardest to follow (at large μ the central gap
//! levels off there and the continuation has to pin another node); it is traced only
//! for drawing ([`Reach::Whole`]), by both legs going on until they meet where the
//! contact's edge reaches x = a₀, and a failure there only leaves a gap in the curve.

use super::curve::{Curve, CurvePoint, Fold, Hysteresis, crossing, work_between};
use super::solver::{Problem, Solution};
use crate::error::{Error, Result};
use crate::numeric::lagrange;
use crate::physics::contact::hybrid::JumpIn;
use crate::physics::contact::jkr;
use nalgebra::DVector;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// Outer radius of the mesh (in x, at a = a₀): f(h̄) there is ~(2/x²)³ ≈ 1e-10.
pub const OUTER_RADIUS: f64 = 50.0;

/// The softest support spring k̂ whose loop the production trace contains.
pub const SOFTEST_SPRING: f64 = 0.5;

/// The gap h̄ that marks the contact edge by default (inside it h̄ ≈ 1, outside it
/// grows fast).
pub const EDGE_GAP: f64 = 1.2;

/// How the moving mesh is built.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MovingSpec {
    /// Tabor parameter μ.
    pub tabor_mu: f64,
    /// Spacing in ξ at the edge ξ = 1.
    pub fine: f64,
    /// Largest spacing in ξ inside the contact.
    pub inner: f64,
    /// Largest spacing in x, at a = a₀, outside the contact. Up to it the spacing grows
    /// with the distance from the edge alone: the gap outside varies on a length that
    /// grows with that distance, before contact as after.
    pub outer: f64,
    /// Growth ratio of neighbouring elements.
    pub growth: f64,
    /// Contact radius (in x) at which the continuation switches to a; the mesh reaches
    /// x = [`OUTER_RADIUS`] there.
    pub a_start: f64,
    /// The gap pinned at ξ = 1, which defines the contact radius a of the mesh.
    pub edge_gap: f64,
}

impl MovingSpec {
    /// The production mesh for μ, with `per_width` elements across the tensile annulus
    /// at the largest contact radius traced.
    pub fn for_tabor(tabor_mu: f64, per_width: f64) -> Self {
        let width = 1.0 / (std::f64::consts::PI * tabor_mu.powf(1.5));
        let root = tabor_mu.sqrt();
        let a_max = 1.6 * Self::landing_a_hat(tabor_mu) * root;
        Self {
            tabor_mu,
            fine: width / a_max / per_width,
            inner: 0.02,
            outer: 2.0,
            growth: 1.04,
            // The contact first forms at a radius that shrinks as μ grows; the frozen
            // mesh of the central-gap phase would follow its growth up to a₀ node by
            // node (re-pinning, hundreds of tiny steps at μ ≥ 10), so a₀ shrinks too:
            // 0.1√μ up to μ ≈ 3, then ≈ 0.5/μ.
            a_start: 0.1 * root * (5.0 / tabor_mu.powf(1.5)).min(1.0),
            edge_gap: EDGE_GAP,
        }
    }

    /// Contact radius â where the hybrid jump-in lands on the JKR branch (or the
    /// load-control pull-off point's, if larger).
    fn landing_a_hat(tabor_mu: f64) -> f64 {
        JumpIn::Fit
            .alpha_hat_a(tabor_mu)
            .ok()
            .flatten()
            .and_then(jkr::a_hat_from_separation)
            .unwrap_or(jkr::A_HAT_B)
            .max(jkr::pull_off_point().a_hat)
    }

    /// The same mesh with every spacing multiplied by `factor`: the grading too (the
    /// spacing grows as fine + (growth − 1)|ξ − 1|, so growth − 1 scales like a
    /// spacing), which makes the meshes of one family similar and the discretisation
    /// error ∝ spacing².
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            fine: self.fine * factor,
            inner: self.inner * factor,
            outer: self.outer * factor,
            growth: 1.0 + (self.growth - 1.0) * factor,
            ..*self
        }
    }

    /// The ξ nodes, from 0 to ξ_max = [`OUTER_RADIUS`]/a₀, with one at ξ = 1; and the
    /// index of that one.
    pub fn nodes(&self) -> (Vec<f64>, usize) {
        let xi_max = OUTER_RADIUS / self.a_start;
        let spacing = |xi: f64| -> f64 {
            let s = self.fine + (self.growth - 1.0) * (xi - 1.0).abs();
            s.min(if xi < 1.0 {
                self.inner
            } else {
                self.outer / self.a_start
            })
        };
        let mut inner = vec![1.0];
        let mut xi: f64 = 1.0;
        while xi > 0.0 {
            let h = spacing(xi).min(spacing(xi - spacing(xi)));
            xi -= h;
            if xi < 0.5 * h {
                xi = 0.0;
            }
            inner.push(xi);
        }
        inner.reverse();
        let edge = inner.len() - 1;
        let mut nodes = inner;
        let mut xi: f64 = 1.0;
        while xi < xi_max {
            let h = spacing(xi).min(spacing(xi + spacing(xi)));
            xi += h;
            if xi_max - xi < 0.5 * h {
                xi = xi_max;
            }
            nodes.push(xi);
        }
        (nodes, edge)
    }
}

/// How much of the S-curve a solution traces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Reach {
    /// The loop under a rigid support: the approach branch from α̂ = [`RIGID_START`] (or
    /// twice the jump-in separation) through A, and the contact branch from where it
    /// pushes (past every landing) through the pull-off and C. What Ŵ_LJ, the folds and
    /// the pull-off need.
    Rigid,
    /// Also every support spring down to k̂ = [`SOFTEST_SPRING`]: the approach branch
    /// from far enough out for the softest spring's jump-out (the contact branch, traced
    /// from where it pushes, holds every landing). What the tabulated law and the
    /// spring losses use.
    Springs,
    /// The whole S-curve for drawing: [`Reach::Springs`] and the unstable branch between
    /// the folds, which no result uses (it costs up to three times the rest at large μ).
    Whole,
}

impl Reach {
    /// The softest support spring whose loop the trace contains (∞: rigid only).
    pub fn softest_spring(self) -> f64 {
        match self {
            Reach::Rigid => f64::INFINITY,
            Reach::Springs | Reach::Whole => SOFTEST_SPRING,
        }
    }

    /// Whether the trace includes the unstable branch.
    pub fn unstable_branch(self) -> bool {
        self == Reach::Whole
    }
}

/// Where a rigid trace starts on the approach branch (α̂), at least: Fig. 2's range.
pub const RIGID_START: f64 = 4.0;

/// Settings of the continuation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MovingOptions {
    /// Newton tolerance on the gap residual.
    pub tolerance: f64,
    /// Largest chord between successive points in the (α̂, T̂) plane.
    pub max_chord: f64,
    /// Most continuation steps.
    pub max_steps: usize,
    /// How far past the jump-in separation the contact branch is followed (in α̂), so
    /// that a support spring down to k̂ = `softest_spring` still finds its landing (∞:
    /// a rigid support only).
    pub softest_spring: f64,
    /// Whether to trace the unstable branch between the folds too (for drawing: no
    /// result uses it).
    pub unstable_branch: bool,
}

impl MovingOptions {
    /// The default settings, tracing what `reach` asks for.
    pub fn reaching(reach: Reach) -> Self {
        Self {
            softest_spring: reach.softest_spring(),
            unstable_branch: reach.unstable_branch(),
            ..Self::default()
        }
    }

    /// What these settings trace (any trace with the unstable branch counts as
    /// [`Reach::Whole`]).
    pub fn reach(&self) -> Reach {
        match (self.unstable_branch, self.softest_spring.is_finite()) {
            (true, _) => Reach::Whole,
            (false, true) => Reach::Springs,
            (false, false) => Reach::Rigid,
        }
    }
}

impl Default for MovingOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            max_chord: 0.05,
            max_steps: 2000,
            softest_spring: SOFTEST_SPRING,
            unstable_branch: true,
        }
    }
}

/// One continuation phase: the pinned node and the parameter that falls along it.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Frozen mesh (a = a₀), the central gap pinned (or, where it folds, the gap that
    /// changes fastest).
    CentralGap,
    /// The edge gap pinned, the contact radius a the parameter.
    Radius,
}

/// Newton iterations allowed on a continuation step (from a predictor).
const STEP_ITERATIONS: usize = 30;

/// Newton iterations allowed from the JKR guess that starts the contact branch (damped
/// at first; 45–50 from μ = 3 to 50).
const START_ITERATIONS: usize = 150;

/// Where the contact branch starts: the JKR contact radius â with T̂ ≈ −1 (T̂ = 0 at
/// â ≈ 2.42), deeper than any landing of a jump-in, with a rigid support or any spring
/// (those land where the contact branch still pulls, T̂ > 0); deeper ones if the
/// solution there does not yet push.
const CONTACT_START_A_HAT: [f64; 3] = [2.5, 3.0, 3.5];

/// An extremum located on converged solutions: the continuation parameter there, the
/// leg's own parameter there (see [`Leg::along`]), α̂, T̂.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Extremum {
    parameter: f64,
    along: f64,
    alpha_hat: f64,
    t_hat: f64,
}

/// One leg of the trace, in the order it was followed.
#[derive(Debug)]
struct Leg {
    /// The points (arclength not yet set).
    points: Vec<CurvePoint>,
    /// The leg's own parameter at each point, increasing along it: −h̄(0) on the
    /// approach leg, −a on the contact leg.
    along: Vec<f64>,
    /// How many leading points `along` parametrises (on the approach leg, the points
    /// before the continuation first pins another node than the axis, where h̄(0)
    /// folds).
    monotone: usize,
    /// Extrema of α̂ located on converged solutions: minima on the approach leg, maxima
    /// on the contact leg.
    alpha_extrema: Vec<Extremum>,
    /// Maxima of T̂ located on converged solutions (contact leg).
    force_maxima: Vec<Extremum>,
    /// Whether the leg went all the way to its end (the contact at radius a₀); the
    /// unstable branch beyond the fold is only drawn, so a leg may stop short there.
    complete: bool,
}

impl Leg {
    /// Append a point, at continuation parameter `p` of `phase`.
    fn push(&mut self, point: CurvePoint, phase: Phase, p: f64) {
        self.along.push(match phase {
            Phase::CentralGap => -point.central_gap,
            Phase::Radius => -p,
        });
        self.points.push(point);
    }

    /// The leading points `along` parametrises, with their arclength set to it.
    fn in_own_parameter(&self) -> Vec<CurvePoint> {
        let n = self.monotone.min(self.points.len());
        (self.points[..n].iter().zip(&self.along))
            .map(|(p, &along)| CurvePoint { s: along, ..*p })
            .collect()
    }

    /// Whether the sampled α̂ has passed its first extremum (a minimum for `sign` = −1, a
    /// maximum for 1) by at least three points, which the interpolation around the fold
    /// needs.
    fn past_fold(&self, sign: f64) -> bool {
        let p = &self.points;
        (1..p.len().saturating_sub(1))
            .find(|&k| {
                sign * (p[k].alpha_hat - p[k - 1].alpha_hat) > 0.0
                    && sign * (p[k].alpha_hat - p[k + 1].alpha_hat) >= 0.0
            })
            .is_some_and(|k| p.len() - 1 - k >= 3)
    }
}

type Lu = nalgebra::linalg::LU<f64, nalgebra::Dyn, nalgebra::Dyn>;

/// The continuation on one mesh.
struct Tracer<'a> {
    spec: &'a MovingSpec,
    opts: &'a MovingOptions,
    problem: Problem,
    /// Index of the node at ξ = 1.
    edge: usize,
    /// The factorised Jacobian, reused while Newton converges fast.
    lu: Option<Lu>,
    steps: usize,
    iterations: usize,
}

/// Trace the S-curve of `spec`'s μ on the moving mesh (see the module docs) in two legs:
/// the approach branch in the central gap from far out through the jump-in fold A, and
/// the contact branch in the contact radius from deep contact (T̂ < 0, started from the
/// JKR solution) back through the pull-off and the jump-out fold C. Each leg goes on
/// along the unstable branch until the two meet (at contact radius a₀), for plots: that
/// part may stop short without harm, and the curve then has a gap there.
pub fn trace(spec: &MovingSpec, opts: &MovingOptions) -> Result<Curve> {
    let mu = spec.tabor_mu;
    let (xi, edge) = spec.nodes();
    let mut tracer = Tracer {
        spec,
        opts,
        problem: Problem::new(mu, xi),
        edge,
        lu: None,
        steps: 0,
        iterations: 0,
    };
    let approach = tracer.approach()?;
    if !approach.past_fold(-1.0) {
        return Err(Error::NoHysteresis(
            "the force-separation curve has no jump-in fold: approach and retraction \
             follow one curve (the Lennard-Jones loop closes at mu ~ 0.70)"
                .into(),
        ));
    }
    let alpha_hat_a = approach
        .points
        .iter()
        .map(|p| p.alpha_hat)
        .fold(f64::INFINITY, f64::min);
    let contact = tracer.contact(alpha_hat_a)?;
    // Approach, then the contact leg backwards; where both legs reached a₀ they end on
    // the same solution, drawn once.
    let joined = approach.complete && contact.complete;
    let mut points = approach.points.clone();
    points.extend(contact.points.iter().rev().skip(usize::from(joined)));
    let mut s = 0.0;
    for k in 1..points.len() {
        let (p, q) = (points[k - 1], points[k]);
        s += (q.alpha_hat - p.alpha_hat).hypot(q.t_hat - p.t_hat);
        points[k].s = s;
    }
    let hysteresis = Hysteresis::of(&points)?;
    let k_c = points.partition_point(|p| p.s <= hysteresis.fold_c.s);
    // The folds and the pull-off from converged solutions where they were located so
    // (and agree with the traced curve), else interpolated on the curve.
    let exact = |fold: Fold, found: Option<&Extremum>| match found {
        Some(e) if (e.alpha_hat - fold.alpha_hat).abs() < 1e-2 => Fold {
            alpha_hat: e.alpha_hat,
            t_hat: e.t_hat,
            ..fold
        },
        _ => fold,
    };
    let fold_a = exact(hysteresis.fold_a, approach.alpha_extrema.first());
    let exact_c = contact
        .alpha_extrema
        .iter()
        .max_by(|x, y| x.alpha_hat.total_cmp(&y.alpha_hat));
    let fold_c = exact(hysteresis.fold_c, exact_c);
    // Ŵ in the legs' own parameters where both folds were located on converged
    // solutions (and were used), else along the drawn curve.
    let w_hat = match (approach.alpha_extrema.first(), exact_c) {
        (Some(a), Some(c))
            if fold_a.alpha_hat == a.alpha_hat && fold_c.alpha_hat == c.alpha_hat =>
        {
            loop_work(&approach, &contact, a, c)
        }
        _ => None,
    };
    let w_hat = match w_hat {
        Some(w) => w,
        None => Hysteresis::between(&points, fold_a, fold_c)?.w_hat,
    };
    let interpolated = super::curve::pull_off(&points, k_c)
        .map_or(hysteresis.fold_c.t_hat, |t| t.max(hysteresis.fold_c.t_hat));
    // The pull-off lies on the contact branch: at a larger radius than C.
    let exact_pull_off = contact
        .force_maxima
        .iter()
        .filter(|f| exact_c.is_none_or(|c| f.parameter > c.parameter))
        .max_by(|x, y| x.t_hat.total_cmp(&y.t_hat));
    let pull_off_hat = match exact_pull_off {
        Some(f) if (f.t_hat - interpolated).abs() < 1e-2 => f.t_hat,
        _ => interpolated,
    };
    Ok(Curve {
        tabor_mu: mu,
        nodes: tracer.problem.len(),
        points,
        fold_a,
        fold_c,
        pull_off_hat,
        w_hat,
        steps: tracer.steps,
        factorisations: tracer.problem.factorisations(),
        iterations: tracer.iterations,
    })
}

impl Tracer<'_> {
    /// The stretch a of the mesh at continuation parameter `p` of `phase` (frozen at a₀
    /// in the central gap).
    fn mesh_a(&self, phase: Phase, p: f64) -> f64 {
        match phase {
            Phase::CentralGap => self.spec.a_start,
            Phase::Radius => p,
        }
    }

    /// The pinned (node, gap) at continuation parameter `p` of `phase`: node `pin_node`
    /// at gap p in the central gap, the edge at the edge gap in the contact radius.
    fn pin(&self, phase: Phase, p: f64, pin_node: usize) -> (usize, f64) {
        match phase {
            Phase::CentralGap => (pin_node, p),
            Phase::Radius => (self.edge, self.spec.edge_gap),
        }
    }

    /// A point of the curve (arclength unset) from a solution on the mesh stretched by a.
    fn point(&self, sol: &Solution, a: f64) -> CurvePoint {
        CurvePoint {
            s: 0.0,
            alpha_hat: sol.alpha_bar / self.spec.tabor_mu,
            t_hat: self.problem.force_scaled(&sol.gap, a).0,
            central_gap: sol.gap[0],
        }
    }

    /// The approach leg: from far out (far enough that the softest spring's jump-out,
    /// at α̂ + T̂/k̂ of the fold C with T̂ there below ~1.2 times the JKR pull-off 3π/2,
    /// lies on it) in the central gap on the frozen mesh, through the fold A, on until
    /// the contact reaches a₀. Essential: the fold A.
    fn approach(&mut self) -> Result<Leg> {
        let mu = self.spec.tabor_mu;
        let a0 = self.spec.a_start;
        let guess_a = JumpIn::SemiRigid.alpha_hat_a(mu)?.unwrap_or(2.0);
        let alpha_start = (2.0 * guess_a).max(RIGID_START).max(
            jkr::ALPHA_HAT_C + 1.2 * 1.5 * std::f64::consts::PI / self.opts.softest_spring + 1.0,
        );
        // Far out: the rigid gap, relaxed with the central gap pinned.
        let rigid = Solution {
            gap: DVector::from_iterator(
                self.problem.len(),
                self.problem
                    .nodes
                    .iter()
                    .map(|x| alpha_start * mu + 1.0 + 0.5 * (a0 * x).powi(2)),
            ),
            alpha_bar: alpha_start * mu,
        };
        let (first, its) = self.problem.solve_pinned(
            &rigid,
            a0,
            (0, rigid.gap[0]),
            self.opts.tolerance,
            &mut self.lu,
            STEP_ITERATIONS,
        )?;
        self.iterations += its;
        let p = first.gap[0];
        self.follow(Phase::CentralGap, first, p, |leg| leg.past_fold(-1.0))
    }

    /// The contact leg: from deep contact (the solution at a JKR contact radius where it
    /// pushes, T̂ < 0, and α̂ is below the jump-in's landing α̂_A − 0.5), started by
    /// Newton from the JKR gap, in the contact radius a falling, through the pull-off and
    /// the fold C, on until a = a₀. Essential: the fold C.
    fn contact(&mut self, alpha_hat_a: f64) -> Result<Leg> {
        let mu = self.spec.tabor_mu;
        // (A fresh factorisation: the contact leg does not depend on how the approach
        // leg ended.)
        self.lu = None;
        for a_hat in CONTACT_START_A_HAT {
            let (guess, a) = jkr_guess(&self.problem.nodes, a_hat, mu, self.spec.edge_gap);
            let mut lu = None;
            let Ok((start, its)) = self.problem.solve_pinned(
                &guess,
                a,
                (self.edge, self.spec.edge_gap),
                self.opts.tolerance,
                &mut lu,
                START_ITERATIONS,
            ) else {
                continue;
            };
            self.iterations += its;
            let q = self.point(&start, a);
            if q.t_hat < 0.0 && q.alpha_hat < alpha_hat_a - 0.5 {
                return self.follow(Phase::Radius, start, a, |leg| leg.past_fold(1.0));
            }
        }
        Err(Error::Numerical(format!(
            "the Lennard-Jones contact branch could not be started from the JKR solution \
             at mu = {mu}"
        )))
    }

    /// Follow the curve from `start` (parameter `p_start`) in `phase`, the parameter
    /// falling, to the leg's end: in the central gap, until the contact reaches x = a₀
    /// (the leg ends on that solution, edge pinned, a = a₀); in the contact radius, at
    /// a = a₀. A failure before `essential(leg)` holds is an error; after it, the leg
    /// ends there, incomplete.
    fn follow(
        &mut self,
        phase: Phase,
        start: Solution,
        p_start: f64,
        essential: impl Fn(&Leg) -> bool,
    ) -> Result<Leg> {
        let spec = self.spec;
        let (a0, edge, tol) = (spec.a_start, self.edge, self.opts.tolerance);
        let mut leg = Leg {
            points: Vec::new(),
            along: Vec::new(),
            monotone: usize::MAX,
            alpha_extrema: Vec::new(),
            force_maxima: Vec::new(),
            complete: false,
        };
        leg.push(
            self.point(&start, self.mesh_a(phase, p_start)),
            phase,
            p_start,
        );
        // (parameter, solution) of the last few points.
        let mut history: VecDeque<(f64, Solution)> = VecDeque::from(vec![(p_start, start)]);
        // In the central gap the pinned node is the axis, unless its gap folds (stops
        // falling): then the node whose gap changes fastest, in the direction it changes.
        let (mut pin_node, mut direction) = (0usize, -1.0);
        let mut step = match phase {
            Phase::CentralGap => 0.05 * p_start,
            Phase::Radius => 0.01 * p_start,
        };
        let outcome: Result<()> = loop {
            if !self.opts.unstable_branch && essential(&leg) {
                break Err(Error::Numerical("the unstable branch is not traced".into()));
            }
            if self.steps >= self.opts.max_steps {
                break Err(Error::Numerical(format!(
                    "LJ continuation took {} steps without reaching the end of its trace",
                    self.steps
                )));
            }
            let (p_last, last) = history.back().expect("never empty");
            let p_last = *p_last;
            let prev = *leg.points.last().expect("never empty");
            let stalled = |step: f64| {
                (step < 1e-9 * p_last.abs().max(1.0)).then(|| {
                    Error::Numerical(format!(
                        "LJ continuation stalled at alpha_hat = {:.4}, T_hat = {:.4}",
                        prev.alpha_hat, prev.t_hat
                    ))
                })
            };
            let mut p_next = p_last + direction * step;
            let at_end = phase == Phase::Radius && p_next <= a0;
            if at_end {
                p_next = a0;
            }
            let guess = extrapolate(&history, p_next);
            let solved = self.problem.solve_pinned(
                &guess,
                self.mesh_a(phase, p_next),
                self.pin(phase, p_next, pin_node),
                tol,
                &mut self.lu,
                STEP_ITERATIONS,
            );
            let Ok((sol, its)) = solved else {
                self.lu = None;
                step *= 0.5;
                if phase == Phase::CentralGap
                    && history.len() >= 2
                    && step < 1e-6 * p_last.abs().max(1.0)
                {
                    // The pinned gap folds here: pin the one changing fastest instead.
                    let (older, newer) =
                        (&history[history.len() - 2].1, &history[history.len() - 1].1);
                    let change = |j: usize| (newer.gap[j] - older.gap[j]) / newer.gap[j];
                    let fastest = (0..newer.gap.len())
                        .max_by(|&i, &j| change(i).abs().total_cmp(&change(j).abs()))
                        .expect("nodes");
                    if fastest != pin_node {
                        leg.monotone = leg.monotone.min(leg.points.len());
                        pin_node = fastest;
                        direction = change(fastest).signum();
                        step = (newer.gap[fastest] - older.gap[fastest]).abs();
                        for (p, sol) in history.iter_mut() {
                            *p = sol.gap[fastest];
                        }
                        continue;
                    }
                }
                if let Some(e) = stalled(step) {
                    break Err(e);
                }
                continue;
            };
            let q = self.point(&sol, self.mesh_a(phase, p_next));
            let chord = (q.alpha_hat - prev.alpha_hat).hypot(q.t_hat - prev.t_hat);
            let max_chord = chord_cap(self.opts, prev.alpha_hat);
            if chord > max_chord {
                // Too far along the curve for its points to resolve it: shorten in proportion.
                step *= 0.8 * max_chord / chord;
                continue;
            }
            if phase == Phase::CentralGap && sol.gap[edge] <= spec.edge_gap {
                // The contact has reached x = a₀: the solution with the edge pinned
                // there (guessed between the two around that point) ends the leg.
                let before = last.gap[edge];
                let f = (before - spec.edge_gap) / (before - sol.gap[edge]);
                let mut guess = last.clone();
                guess.gap.axpy(f, &(&sol.gap - &last.gap), 1.0);
                guess.alpha_bar += f * (sol.alpha_bar - last.alpha_bar);
                let pinned = (edge, spec.edge_gap);
                match self.problem.solve_pinned(
                    &guess,
                    a0,
                    pinned,
                    tol,
                    &mut self.lu,
                    STEP_ITERATIONS,
                ) {
                    Ok((sol, its)) => {
                        self.iterations += its;
                        self.steps += 1;
                        leg.push(self.point(&sol, a0), phase, a0);
                        break Ok(());
                    }
                    Err(_) => {
                        self.lu = None;
                        step *= 0.5;
                        if let Some(e) = stalled(step) {
                            break Err(e);
                        }
                        continue;
                    }
                }
            }
            self.iterations += its;
            self.steps += 1;
            leg.push(q, phase, p_next);
            history.push_back((p_next, sol));
            if history.len() > 3 {
                history.pop_front();
            }
            if history.len() == 3 {
                self.locate_extrema(phase, pin_node, &history, &mut leg);
            }
            if at_end {
                break Ok(());
            }
            // Step control from the predictor's error (third order for the quadratic
            // extrapolation once three points are known), aiming at PREDICTOR_ERROR…
            let predicted = predictor_error(&guess, &history.back().expect("just pushed").1);
            let factor = if history.len() < 3 {
                1.5
            } else {
                (PREDICTOR_ERROR / predicted.max(1e-12))
                    .cbrt()
                    .clamp(0.5, 2.0)
            };
            // …and at a chord of 0.8 of the largest.
            step *= factor.min(0.8 * max_chord / chord.max(1e-12));
        };
        match outcome {
            Ok(()) => {
                leg.complete = true;
                Ok(leg)
            }
            Err(_) if essential(&leg) => Ok(leg),
            Err(e) => Err(e),
        }
    }

    /// Look for extrema bracketed by the three solutions of `history` (the pinned node
    /// `pin_node` in the central gap) and locate them on converged solutions: the first
    /// minimum of α̂ in the central gap (A), and every maximum of α̂ (C) and of T̂ (the
    /// pull-off) in the contact radius.
    fn locate_extrema(
        &self,
        phase: Phase,
        pin_node: usize,
        history: &VecDeque<(f64, Solution)>,
        leg: &mut Leg,
    ) {
        let mu = self.spec.tabor_mu;
        let mesh_a = |p: f64| self.mesh_a(phase, p);
        let solve = |p: f64, guess: &Solution| -> Result<Solution> {
            let (pin, tol) = (self.pin(phase, p, pin_node), self.opts.tolerance);
            let mut lu = None;
            let (sol, _) =
                self.problem
                    .solve_pinned(guess, mesh_a(p), pin, tol, &mut lu, STEP_ITERATIONS)?;
            Ok(sol)
        };
        let alpha_of = |_: f64, s: &Solution| s.alpha_bar / mu;
        let force_of = |p: f64, s: &Solution| self.problem.force_scaled(&s.gap, mesh_a(p)).0;
        let found = |sign: f64, value: &dyn Fn(f64, &Solution) -> f64| {
            refine_extremum(history, &solve, value, sign).map(|(p, around)| {
                let at_p = |quantity: &dyn Fn(f64, &Solution) -> f64| {
                    let q = [0, 1, 2].map(|i| (around[i].0, quantity(around[i].0, &around[i].1)));
                    lagrange(&q, p)
                };
                Extremum {
                    parameter: p,
                    along: match phase {
                        Phase::CentralGap => -at_p(&|_, s: &Solution| s.gap[0]),
                        Phase::Radius => -p,
                    },
                    alpha_hat: at_p(&alpha_of),
                    t_hat: at_p(&force_of),
                }
            })
        };
        match phase {
            Phase::CentralGap => {
                if leg.alpha_extrema.is_empty() {
                    leg.alpha_extrema.extend(found(-1.0, &alpha_of));
                }
            }
            Phase::Radius => {
                leg.alpha_extrema.extend(found(1.0, &alpha_of));
                leg.force_maxima.extend(found(1.0, &force_of));
            }
        }
    }
}

/// Ŵ = ∫_{α̂_A}^{α̂_C} (T̂_contact − T̂_approach) dα̂ in each leg's own parameter
/// ([`Leg::along`]): ∫ T̂ (dα̂/dp) dp by 4-point Gauss–Legendre on every continuation
/// step, on the cubic through the four solutions around it, from the approach branch's
/// crossing of α̂_C to the fold A and from the contact branch's crossing of α̂_A (the
/// jump-in's landing) to the fold C. The solution varies smoothly in those parameters
/// across the folds, so the steps the predictor sets, not the drawing's chord, decide
/// the accuracy. `None` if a crossing lies outside what the legs parametrise.
fn loop_work(approach: &Leg, contact: &Leg, a: &Extremum, c: &Extremum) -> Option<f64> {
    let (app, con) = (approach.in_own_parameter(), contact.in_own_parameter());
    // The first point past the fold, which must lie inside the parametrised points with
    // two beyond it for the cubic.
    let past = |points: &[CurvePoint], along: f64| {
        let k = points.partition_point(|p| p.s < along);
        (k >= 1 && k + 2 <= points.len()).then_some(k)
    };
    let (k_a, k_c) = (past(&app, a.along)?, past(&con, c.along)?);
    let from_c = crossing(&app, 0, k_a, c.alpha_hat).ok()?;
    let landing = crossing(&con, 0, k_c, a.alpha_hat).ok()?;
    // Along each leg: the approach from α̂_C to A, the contact branch from the landing
    // (α̂_A) to C; the loop runs the contact branch the other way.
    Some(work_between(&app, from_c, a.along) + work_between(&con, landing, c.along))
}

/// The JKR solution at contact radius `a_hat` as a guess on the ξ `nodes`: the gap
/// (eqs. (5) with the Hertz and flat-punch surface displacements, in units of ε and
/// √(Rε)) plus the equilibrium spacing, and the stretch a of the mesh that puts the
/// edge gap at ξ = 1.
fn jkr_guess(nodes: &[f64], a_hat: f64, tabor_mu: f64, edge_gap: f64) -> (Solution, f64) {
    use std::f64::consts::PI;
    let a_jkr = a_hat * tabor_mu.sqrt();
    // The flat punch's lift √(2πaΔγ/E*), in ε.
    let lift = (2.0 * PI * a_jkr * tabor_mu.powf(1.5)).sqrt();
    // Near the edge the gap opens as 1 + (2·lift/π)√(2(x − a)/a).
    let a = a_jkr * (1.0 + 0.5 * (PI * (edge_gap - 1.0) / (2.0 * lift)).powi(2));
    let gap = |x: f64| {
        if x <= a_jkr {
            return 1.0;
        }
        let opening = (a_jkr / x).acos();
        let hertz =
            (a_jkr * (x * x - a_jkr * a_jkr).sqrt() - (2.0 * a_jkr * a_jkr - x * x) * opening) / PI;
        1.0 + hertz + 2.0 * lift / PI * opening
    };
    let guess = Solution {
        gap: DVector::from_iterator(nodes.len(), nodes.iter().map(|xi| gap(a * xi))),
        alpha_bar: tabor_mu * jkr::separation_hat(a_hat),
    };
    (guess, a)
}

/// The largest chord allowed from a point at α̂: `opts.max_chord` where the folds are
/// (α̂ ≤ 3 for every μ), growing in proportion beyond, where the approach branch is a
/// gentle tail T̂ ~ α̂⁻².
fn chord_cap(opts: &MovingOptions, alpha_hat: f64) -> f64 {
    opts.max_chord * (alpha_hat - 2.0).max(1.0)
}

/// The extremum of `value` (a maximum for `sign` = 1, a minimum for −1) over the
/// continuation parameter, if the three solutions of `history` bracket one (the middle
/// one the most extreme), located on converged solutions (`solve` at a parameter from a
/// guess) by successive parabolic interpolation. Returns the parameter there and three
/// converged solutions around it, to interpolate any quantity at it.
///
/// A fold is a smooth extremum of α̂ in the parameter of its phase, so this converges
/// fast, where interpolating the sampled curve is limited by how sharply the curve
/// turns. α̂ is flat at its extremum: points closer than 1e-4 of the first bracket would
/// let the solver's tolerance move the vertex, so the search stops there and the
/// answer comes from a stencil 1 % of the bracket wide around it.
fn refine_extremum(
    history: &VecDeque<(f64, Solution)>,
    solve: &dyn Fn(f64, &Solution) -> Result<Solution>,
    value: &dyn Fn(f64, &Solution) -> f64,
    sign: f64,
) -> Option<(f64, VecDeque<(f64, Solution)>)> {
    // Called after every continuation step: decide on the values before copying any
    // solution.
    let mut order: Vec<(f64, &Solution, f64)> = history
        .iter()
        .map(|(p, s)| (*p, s, sign * value(*p, s)))
        .collect();
    order.sort_by(|x, y| x.0.total_cmp(&y.0));
    let [v0, v1, v2] = [0, 1, 2].map(|i| order[i].2);
    if !(v1 >= v0 && v1 >= v2 && v1 > v0.min(v2)) {
        return None;
    }
    let mut pts: Vec<(f64, Solution, f64)> = order
        .into_iter()
        .map(|(p, s, v)| (p, s.clone(), v))
        .collect();
    let vertex = |pts: &[(f64, Solution, f64)]| {
        let [(p0, v0), (p1, v1), (p2, v2)] = [0, 1, 2].map(|i| (pts[i].0, pts[i].2));
        let (d0, d2) = (p1 - p0, p1 - p2);
        let denominator = d0 * (v1 - v2) - d2 * (v1 - v0);
        let p = p1 - 0.5 * (d0 * d0 * (v1 - v2) - d2 * d2 * (v1 - v0)) / denominator;
        (p.is_finite() && p > p0 && p < p2).then_some(p)
    };
    let closest = 1e-4 * (pts[2].0 - pts[0].0);
    for _ in 0..30 {
        let p = vertex(&pts)?;
        let (p0, p1, p2) = (pts[0].0, pts[1].0, pts[2].0);
        if (p - p1).abs() < closest || p - p0 < closest || p2 - p < closest {
            break;
        }
        let around: VecDeque<(f64, Solution)> =
            pts.iter().map(|(p, s, _)| (*p, s.clone())).collect();
        let sol = solve(p, &extrapolate(&around, p)).ok()?;
        let v = sign * value(p, &sol);
        // Keep three points bracketing the extremum, the most extreme in the middle.
        let new = (p, sol, v);
        let [lo, mid, hi]: [(f64, Solution, f64); 3] = pts.try_into().ok()?;
        pts = match (v >= mid.2, p < p1) {
            (true, true) => vec![lo, new, mid],
            (true, false) => vec![mid, new, hi],
            (false, true) => vec![new, mid, hi],
            (false, false) => vec![lo, mid, new],
        };
    }
    // A last symmetric stencil, wide enough that the solver's tolerance cannot move its
    // vertex, centred where the extremum now lies.
    let centre = vertex(&pts)?;
    let around: VecDeque<(f64, Solution)> = pts.into_iter().map(|(p, s, _)| (p, s)).collect();
    let delta = 100.0 * closest;
    let mut stencil = Vec::with_capacity(3);
    for p in [centre - delta, centre, centre + delta] {
        let sol = solve(p, &extrapolate(&around, p)).ok()?;
        let v = sign * value(p, &sol);
        stencil.push((p, sol, v));
    }
    let p = vertex(&stencil).unwrap_or(centre);
    Some((p, stencil.into_iter().map(|(p, s, _)| (p, s)).collect()))
}

/// Largest relative gap error of the predictor accepted before the step shrinks.
const PREDICTOR_ERROR: f64 = 1e-2;

/// How far the predictor `guess` was from the converged `solution`: largest change of a
/// gap relative to max(1, gap), or of ᾱ.
fn predictor_error(guess: &Solution, solution: &Solution) -> f64 {
    guess
        .gap
        .iter()
        .zip(solution.gap.iter())
        .map(|(g, h)| (g - h).abs() / h.abs().max(1.0))
        .fold((guess.alpha_bar - solution.alpha_bar).abs(), f64::max)
}

/// Lagrange extrapolation of the last solutions to parameter `p`.
fn extrapolate(history: &VecDeque<(f64, Solution)>, p: f64) -> Solution {
    let m = history.len();
    let weight = |i: usize| -> f64 {
        (0..m)
            .filter(|&j| j != i)
            .map(|j| (p - history[j].0) / (history[i].0 - history[j].0))
            .product()
    };
    let mut guess = Solution {
        gap: history[0].1.gap.scale(weight(0)),
        alpha_bar: weight(0) * history[0].1.alpha_bar,
    };
    for (i, (_, sol)) in history.iter().enumerate().skip(1) {
        let w = weight(i);
        guess.gap.axpy(w, &sol.gap, 1.0);
        guess.alpha_bar += w * sol.alpha_bar;
    }
    guess
}
