//! Continuation on a mesh that moves with the contact edge.
//!
//! On a fixed mesh the edge of the contact — a tensile annulus ~1/(πμ^{3/2}) wide in x —
//! sweeps across hundreds of fine elements while the curve is traced; the nodal gaps then
//! change abruptly along the curve, predictors fail, and the steps stay tiny. Here the
//! nodes are x = a·ξ on a fixed mesh in ξ, fine around ξ = 1, and a is the contact
//! radius, defined by pinning the gap at ξ = 1 to [`EDGE_GAP`] (or the spec's own
//! `edge_gap`; the results do not depend on it beyond their error). Stretching the mesh
//! multiplies the influence matrix by a (no reassembly), the solution varies smoothly
//! with a, and a grows monotonically from the first contact to deep contact, so plain
//! natural-parameter continuation in a works.
//!
//! Before there is a contact the same mesh is frozen at a = a₀ and the curve is followed
//! in the central gap h̄(0), which falls monotonically from far out through the jump-in
//! fold A to the forming contact; once the gap at x = a₀ falls to the edge gap the
//! continuation switches to a.

use super::curve::{Curve, CurvePoint, Fold, Hysteresis};
use super::solver::{Problem, Solution};
use crate::contact::hybrid::JumpIn;
use crate::contact::jkr;
use crate::error::{Error, Result};
use crate::numeric::lagrange;
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
    /// twice the jump-in separation) through A, C and the pull-off, down the contact
    /// branch past the jump-in's landing. What Ŵ_LJ, the folds and the pull-off need.
    Rigid,
    /// Also every support spring down to k̂ = [`SOFTEST_SPRING`]: the approach branch
    /// from far enough out for the softest spring's jump-out, the contact branch deep
    /// enough for its landing. What the tabulated law and the spring losses use.
    Springs,
}

impl Reach {
    /// The softest support spring whose loop the trace contains (∞: rigid only).
    pub fn softest_spring(self) -> f64 {
        match self {
            Reach::Rigid => f64::INFINITY,
            Reach::Springs => SOFTEST_SPRING,
        }
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
}

impl MovingOptions {
    /// The default settings, tracing what `reach` asks for.
    pub fn reaching(reach: Reach) -> Self {
        Self {
            softest_spring: reach.softest_spring(),
            ..Self::default()
        }
    }

    /// What these settings trace.
    pub fn reach(&self) -> Reach {
        if self.softest_spring.is_finite() {
            Reach::Springs
        } else {
            Reach::Rigid
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
        }
    }
}

/// One continuation phase: the pinned node and how its parameter moves.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Frozen mesh (a = a₀), central gap pinned and decreasing.
    CentralGap,
    /// Edge gap pinned, a increasing.
    Radius,
}

/// Trace the S-curve of `spec`'s μ on the moving mesh (see the module docs): approach
/// branch, fold A, unstable branch, fold C, contact branch past the landing point of
/// the jump-in (and of a support spring as soft as `opts.softest_spring`).
pub fn trace(spec: &MovingSpec, opts: &MovingOptions) -> Result<Curve> {
    let mu = spec.tabor_mu;
    let (xi, edge) = spec.nodes();
    let problem = Problem::new(mu, xi);
    let a0 = spec.a_start;
    let guess_a = JumpIn::SemiRigid.alpha_hat_a(mu)?.unwrap_or(2.0);
    // Far enough out that the softest spring's jump-out (at α̂ + T̂/k̂ of the fold C,
    // T̂ there below ~1.2 times the JKR pull-off 3π/2) lies on the traced approach.
    let alpha_start = (2.0 * guess_a)
        .max(RIGID_START)
        .max(jkr::ALPHA_HAT_C + 1.2 * 1.5 * std::f64::consts::PI / opts.softest_spring + 1.0);
    let tol = opts.tolerance;
    let point = |sol: &Solution, a: f64, s: f64| CurvePoint {
        s,
        alpha_hat: sol.alpha_bar / mu,
        t_hat: problem.force_scaled(&sol.gap, a).0,
        central_gap: sol.gap[0],
    };
    // Far out: the rigid gap, relaxed with the central gap pinned.
    let rigid = Solution {
        gap: DVector::from_iterator(
            problem.len(),
            problem
                .nodes
                .iter()
                .map(|x| alpha_start * mu + 1.0 + 0.5 * (a0 * x).powi(2)),
        ),
        alpha_bar: alpha_start * mu,
    };
    let mut lu = None;
    let (first, mut iterations) =
        problem.solve_pinned(&rigid, a0, (0, rigid.gap[0]), tol, &mut lu)?;
    let mut points = vec![point(&first, a0, 0.0)];
    // (parameter, solution) of the last few points of the current phase.
    let mut history: VecDeque<(f64, Solution)> = VecDeque::from(vec![(first.gap[0], first)]);
    let mut phase = Phase::CentralGap;
    // Before contact the gap pinned is the central one, unless that one folds (stops
    // falling): then the node whose gap changes fastest, in the direction it changes.
    let (mut pin_node, mut direction) = (0usize, -1.0);
    let mut step = 0.05 * history[0].0;
    let mut seen_c = false;
    let mut steps = 0;
    let landing_alpha = guess_a - 0.5;
    // Extremes located on converged solutions: (parameter, α̂, T̂) of the fold A (the
    // first minimum of α̂ in the central gap), the fold C (the largest maximum of α̂ in
    // the contact radius) and the pull-off (the largest maximum of T̂ after C).
    let mut exact_a: Option<(f64, f64, f64)> = None;
    let mut exact_c: Option<(f64, f64, f64)> = None;
    let mut exact_pull_off: Option<(f64, f64, f64)> = None;
    loop {
        if steps >= opts.max_steps {
            return Err(Error::Numerical(format!(
                "LJ continuation took {steps} steps without passing the landing point"
            )));
        }
        let (p_last, last) = history.back().expect("never empty");
        let p_next = match phase {
            Phase::CentralGap => p_last + direction * step,
            Phase::Radius => p_last + step,
        };
        let guess = extrapolate(&history, p_next);
        let (pin, a_next) = match phase {
            Phase::CentralGap => ((pin_node, p_next), a0),
            Phase::Radius => ((edge, spec.edge_gap), p_next),
        };
        let prev = *points.last().expect("never empty");
        let (sol, its) = match problem.solve_pinned(&guess, a_next, pin, tol, &mut lu) {
            Ok(v) => v,
            Err(_) => {
                lu = None;
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
                        pin_node = fastest;
                        direction = change(fastest).signum();
                        step = (newer.gap[fastest] - older.gap[fastest]).abs();
                        for (p, sol) in history.iter_mut() {
                            *p = sol.gap[fastest];
                        }
                        continue;
                    }
                }
                if step < 1e-9 * p_last.abs().max(1.0) {
                    return Err(Error::Numerical(format!(
                        "LJ continuation stalled at alpha_hat = {:.4}, T_hat = {:.4}",
                        prev.alpha_hat, prev.t_hat
                    )));
                }
                continue;
            }
        };
        let q = point(&sol, a_next, 0.0);
        let chord = (q.alpha_hat - prev.alpha_hat).hypot(q.t_hat - prev.t_hat);
        let max_chord = chord_cap(opts, prev.alpha_hat);
        if chord > max_chord {
            // Too far along the curve for its points to resolve it: shorten in proportion.
            step *= 0.8 * max_chord / chord;
            continue;
        }
        if phase == Phase::CentralGap && sol.gap[edge] <= spec.edge_gap {
            // The contact has reached x = a₀: pin the edge there (from the two solutions
            // around that point) and follow a from now on.
            let before = &last.gap[edge];
            let f = (before - spec.edge_gap) / (before - sol.gap[edge]);
            let mut guess = last.clone();
            guess.gap.axpy(f, &(&sol.gap - &last.gap), 1.0);
            guess.alpha_bar += f * (sol.alpha_bar - last.alpha_bar);
            match problem.solve_pinned(&guess, a0, (edge, spec.edge_gap), tol, &mut lu) {
                Ok((sol, its)) => {
                    iterations += its;
                    steps += 1;
                    let q = point(&sol, a0, 0.0);
                    let chord = (q.alpha_hat - prev.alpha_hat).hypot(q.t_hat - prev.t_hat);
                    points.push(CurvePoint {
                        s: prev.s + chord,
                        ..q
                    });
                    history.clear();
                    history.push_back((a0, sol));
                    phase = Phase::Radius;
                    step = 0.02 * a0;
                }
                Err(_) => {
                    lu = None;
                    step *= 0.5;
                }
            }
            continue;
        }
        iterations += its;
        steps += 1;
        points.push(CurvePoint {
            s: prev.s + chord,
            ..q
        });
        history.push_back((p_next, sol));
        if history.len() > 3 {
            history.pop_front();
        }
        if history.len() == 3 {
            let alpha_of = |_: f64, s: &Solution| s.alpha_bar / mu;
            let problem = &problem;
            let at = |phase: Phase| {
                move |p: f64, guess: &Solution| -> Result<Solution> {
                    let (pin, a) = match phase {
                        Phase::CentralGap => ((pin_node, p), a0),
                        Phase::Radius => ((edge, spec.edge_gap), p),
                    };
                    let mut lu = None;
                    Ok(problem.solve_pinned(guess, a, pin, tol, &mut lu)?.0)
                }
            };
            let found = |sign: f64, value: &dyn Fn(f64, &Solution) -> f64| {
                refine_extremum(&history, &at(phase), value, sign).map(|(p, around)| {
                    let at_p = |quantity: &dyn Fn(f64, &Solution) -> f64| {
                        let q =
                            [0, 1, 2].map(|i| (around[i].0, quantity(around[i].0, &around[i].1)));
                        lagrange(&q, p)
                    };
                    let force = |q: f64, s: &Solution| {
                        let a = if phase == Phase::Radius { q } else { a0 };
                        problem.force_scaled(&s.gap, a).0
                    };
                    (p, at_p(&alpha_of), at_p(&force))
                })
            };
            match phase {
                Phase::CentralGap if exact_a.is_none() => exact_a = found(-1.0, &alpha_of),
                Phase::CentralGap => {}
                Phase::Radius => {
                    if let Some(c) = found(1.0, &alpha_of) {
                        if exact_c.is_none_or(|old| c.1 > old.1) {
                            exact_c = Some(c);
                            exact_pull_off = None;
                        }
                    }
                    let force_of = |p: f64, s: &Solution| problem.force_scaled(&s.gap, p).0;
                    if let Some(c) = exact_c {
                        if let Some(f) = found(1.0, &force_of).filter(|f| f.0 > c.0) {
                            if exact_pull_off.is_none_or(|old| f.2 > old.2) {
                                exact_pull_off = Some(f);
                            }
                        }
                    }
                }
            }
        }
        // Step control from the predictor's error (third order for the quadratic
        // extrapolation once three points are known), aiming at PREDICTOR_ERROR.
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
        if q.alpha_hat > guess_a + 0.3 {
            seen_c = true;
        }
        if seen_c
            && phase == Phase::Radius
            && past_landing(&points, landing_alpha, opts)
            && past_pull_off(&points)
        {
            break;
        }
    }
    let hysteresis = Hysteresis::of(&points)?;
    let k_c = points.partition_point(|p| p.s <= hysteresis.fold_c.s);
    // The folds and the pull-off from converged solutions where they were located so
    // (and agree with the traced curve), else interpolated on the curve.
    let exact = |fold: Fold, found: Option<(f64, f64, f64)>| match found {
        Some((_, alpha_hat, t_hat)) if (alpha_hat - fold.alpha_hat).abs() < 1e-2 => Fold {
            alpha_hat,
            t_hat,
            ..fold
        },
        _ => fold,
    };
    let fold_a = exact(hysteresis.fold_a, exact_a);
    let fold_c = exact(hysteresis.fold_c, exact_c);
    let w_hat = Hysteresis::between(&points, fold_a, fold_c)?.w_hat;
    let interpolated = super::curve::pull_off(&points, k_c)
        .map_or(hysteresis.fold_c.t_hat, |t| t.max(hysteresis.fold_c.t_hat));
    let pull_off_hat = match exact_pull_off {
        Some((_, _, t_hat)) if (t_hat - interpolated).abs() < 1e-2 => t_hat,
        _ => interpolated,
    };
    Ok(Curve {
        tabor_mu: mu,
        nodes: problem.len(),
        points,
        fold_a,
        fold_c,
        pull_off_hat,
        w_hat,
        steps,
        factorisations: problem.factorisations(),
        iterations,
    })
}

/// The largest chord allowed from a point at α̂: `opts.max_chord` where the folds are
/// (α̂ ≤ 3 for every μ), growing in proportion beyond, where the approach branch is a
/// gentle tail T̂ ~ α̂⁻².
fn chord_cap(opts: &MovingOptions, alpha_hat: f64) -> f64 {
    opts.max_chord * (alpha_hat - 2.0).max(1.0)
}

/// Whether the contact branch has gone below `landing_alpha` and, seen through the
/// softest support spring, below the spring's own jump-in landing too (and, for springs,
/// to where T̂ < 0, below the landing of any softer spring).
fn past_landing(points: &[CurvePoint], landing_alpha: f64, opts: &MovingOptions) -> bool {
    let q = points.last().expect("never empty");
    if q.alpha_hat >= landing_alpha {
        return false;
    }
    let k = opts.softest_spring;
    // The spring's jump-in: the first minimum of α̂ + T̂/k̂ (on the approach branch).
    let support = |p: &CurvePoint| p.alpha_hat + p.t_hat / k;
    let first_min = points
        .windows(2)
        .find(|w| support(&w[1]) > support(&w[0]))
        .map(|w| support(&w[0]));
    // (A softer spring lands where the contact branch still pulls, T̂ > 0: a trace for
    // springs goes on until it pushes.)
    // (No minimum at all: no fold, no loop; the trace need only pass `landing_alpha`.)
    first_min.is_none_or(|m| support(q) < m - 0.5) && (k.is_infinite() || q.t_hat < 0.0)
}

/// Whether the contact branch has passed its largest T̂ (the load-control pull-off):
/// the last point lies 1e-3 below the largest T̂ traced.
fn past_pull_off(points: &[CurvePoint]) -> bool {
    let peak = points
        .iter()
        .map(|p| p.t_hat)
        .fold(f64::NEG_INFINITY, f64::max);
    points.last().is_some_and(|q| q.t_hat < peak - 1e-3)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mesh_has_its_edge_node_at_one_and_reaches_the_outer_radius() {
        for mu in [1.0, 5.0, 10.0] {
            let spec = MovingSpec::for_tabor(mu, 7.0);
            let (xi, edge) = spec.nodes();
            assert_eq!(xi[0], 0.0);
            assert_eq!(xi[edge], 1.0);
            assert!(xi.windows(2).all(|w| w[1] > w[0]));
            let last = *xi.last().unwrap();
            assert!((last * spec.a_start - OUTER_RADIUS).abs() < 1e-9 * OUTER_RADIUS);
            // Finest at the edge; inside the contact no coarser than `inner`.
            let h = |i: usize| xi[i + 1] - xi[i];
            assert!((h(edge) - spec.fine).abs() < 1e-12);
            assert!((h(edge - 1) - spec.fine).abs() < 1e-12);
            assert!((1..edge).all(|i| h(i) <= spec.inner + 1e-12));
            assert!((0..xi.len() - 1).all(|i| h(i) >= spec.fine - 1e-12));
        }
    }
}
