//! A rigid sphere on a standard-linear-solid half-space, unloading included: the
//! receding contact of Ting (J. Appl. Mech. 33, 845, 1966), computed by the method of
//! dimensionality reduction (Popov & Heß, *Method of Dimensionality Reduction in Contact
//! Mechanics and Friction*, Springer 2015; for viscoelastic media Popov, Willert & Heß,
//! Facta Universitatis Mech. Eng. 16, 99, 2018; Ting's rebound reproduced: Argatov &
//! Popov, ZAMM 96, 956, 2016). Ting's case, a touch of a relaxed surface, is checked
//! here against his formulas; a touch of a surface that has not recovered from the last
//! one rests on the reduction's claim for arbitrary histories, not checked here.
//!
//! Lee & Radok's hereditary Hertz integral (what [`crate::physics::law::StandardLinearSolid`]
//! runs) holds while the contact grows. Once it shrinks, the force depends on the
//! history only up to the instant t₁ when the contact last had today's radius, and t₁
//! is where ∫_{t₁}^{t} E(t − s) dδ(s) = 0 (Ting). A non-adhesive contact then never
//! pulls, and it ends before the indentation returns to zero: the surface, slower than
//! the tip, has not come back yet.
//!
//! The reduction maps the half-space onto a row of independent elements at ξ ≥ 0,
//! pressed by the profile ξ² (the sphere's x²/(2R) transformed). In the contact's units
//! (indentation δ̂ = −α̂, the [`crate::physics::law`] scales; ξ̂ in √(length unit · R))
//! each element is a standard linear solid: a spring E_∞ in parallel with a Maxwell arm
//! (spring r·E_∞, r = (E₀ − E_∞)/E_∞, relaxation time τ̂_r) whose extension is v̂. Its
//! surface moves with the tip where the tip is below its free position, and freely
//! otherwise:
//!
//!   û = max(δ̂ − ξ̂², κ v̂),  κ = r/(1 + r),   dv̂/dτ = (û − v̂)/τ̂_r,
//!   q̂ = (1 + r)û − r v̂ ≥ 0,   F̂ = 2∫₀^∞ q̂ dξ̂
//!
//! (F̂ compressive positive, the Hertz force (4/3)δ̂^{3/2} for an elastic E_∞). An
//! element touches exactly where its force would be positive, (1 + r)(δ̂ − ξ̂²) − r v̂ > 0,
//! and there its two equations of motion agree, so v̂ is smooth across a touch. A free
//! element creeps back with the retardation time (1 + r)τ̂_r: the surface remembers the
//! last contact until it has.
//!
//! Limits: τ̂_r → 0 the Hertz contact on E_∞, τ̂_r → ∞ on E₀ = (1 + r)E_∞.
//!
//! Discretisation: nodes ξ̂_j = j·h carry v̂_j = c_j − p_j ξ̂_j², split so that both
//! elastic limits are exact between nodes (p = c = 0 as τ̂_r → ∞; p = 1, c = δ̂ in
//! contact as τ̂_r → 0). Inside the contact p and c are interpolated linearly in each
//! cell, where q̂ is then a cubic, integrated exactly; in the cell the contact's edge
//! crosses they are extrapolated from the touching side and the edge is located by
//! Newton. In time each element is advanced exactly for an indentation linear over a
//! step, its touches located. Checked (tests below) against Ting's formulas evaluated
//! on their own for a loading–unloading history: second order in h, 1.3e-6 of the peak
//! force at 400 cells; the elastic limits within 1e-7 at 50.

use crate::error::{Error, Result, positive};
use crate::numeric::{bracketed_root, newton_bracketed};

/// The most nodes whose state within a step is found once per force on the stack.
const STACK_NODES: usize = 256;

/// Two-point Gauss–Legendre abscissae on [0, 1] (exact for cubics).
const GAUSS_2: [f64; 2] = [0.211_324_865_405_187_1, 0.788_675_134_594_812_9];

/// A sphere on a standard-linear-solid half-space, with the surface's memory.
#[derive(Debug, Clone, PartialEq)]
pub struct RelaxingHalfSpace {
    /// r = (E₀ − E_∞)/E_∞.
    modulus_ratio: f64,
    /// τ̂_r.
    relaxation_hat: f64,
    /// Node spacing h in ξ̂.
    spacing: f64,
    /// p_j (the Maxwell extension v̂_j = c_j − p_j ξ̂_j²).
    p: Vec<f64>,
    /// c_j.
    c: Vec<f64>,
    /// The integrator step's start ([`RelaxingHalfSpace::begin_step`]): δ̂_n and dδ̂/dτ
    /// there.
    step_start: (f64, f64),
    /// Whether each element touched at the step's start …
    touching: Vec<bool>,
    /// … and whether any did.
    any_touching: bool,
}

/// The state of one element: its Maxwell extension split as v̂ = c − pξ̂².
#[derive(Debug, Clone, Copy)]
struct Element {
    p: f64,
    c: f64,
}

impl Element {
    /// The element after creeping free (dv̂/dτ = −v̂/((1 + r)τ̂_r)), `decay` the factor
    /// e^{−s/((1 + r)τ̂_r)} of the time s.
    fn creep(self, decay: f64) -> Self {
        Self {
            p: self.p * decay,
            c: self.c * decay,
        }
    }
}

/// The cubic Hermite interpolant on [0, 1] with values y₀, y₁ and slopes r₀, r₁ (per
/// unit of s) at its ends, and its derivative, at s.
fn hermite(s: f64, (y0, r0): (f64, f64), (y1, r1): (f64, f64)) -> (f64, f64) {
    let (s2, s3) = (s * s, s * s * s);
    (
        (2.0 * s3 - 3.0 * s2 + 1.0) * y0
            + (s3 - 2.0 * s2 + s) * r0
            + (3.0 * s2 - 2.0 * s3) * y1
            + (s3 - s2) * r1,
        (6.0 * s2 - 6.0 * s) * y0
            + (3.0 * s2 - 4.0 * s + 1.0) * r0
            + (6.0 * s - 6.0 * s2) * y1
            + (3.0 * s2 - 2.0 * s) * r1,
    )
}

impl RelaxingHalfSpace {
    /// A relaxed, flat surface: modulus ratio r = (E₀ − E_∞)/E_∞ (> 0), relaxation time
    /// τ̂_r (> 0), for indentations up to `max_indentation_hat` (the nodes reach
    /// ξ̂ = √δ̂_max), with `cells` cells across that reach.
    pub fn new(
        modulus_ratio: f64,
        relaxation_hat: f64,
        max_indentation_hat: f64,
        cells: usize,
    ) -> Result<Self> {
        positive("modulus ratio", modulus_ratio)?;
        positive("relaxation time", relaxation_hat)?;
        positive("largest indentation", max_indentation_hat)?;
        if !(2..=1_000_000).contains(&cells) {
            return Err(Error::InvalidParameter {
                name: "cells",
                value: cells as f64,
                reason: "between 2 and 10⁶",
            });
        }
        // One cell of margin: an edge in the last cell still has a node past it.
        let spacing = max_indentation_hat.sqrt() / cells as f64;
        Ok(Self {
            modulus_ratio,
            relaxation_hat,
            spacing,
            p: vec![0.0; cells + 2],
            c: vec![0.0; cells + 2],
            step_start: (0.0, 0.0),
            touching: vec![false; cells + 2],
            any_touching: false,
        })
    }

    /// Cells across the nodes' reach.
    pub fn cells(&self) -> usize {
        self.p.len() - 2
    }

    /// Let every element creep free for `duration_hat` (dv̂/dτ = −v̂/((1 + r)τ̂_r)): the
    /// surface while the tip is away from it (the caller knows no element touches).
    pub fn creep(&mut self, duration_hat: f64) {
        let decay = (-duration_hat.max(0.0) / self.creep_hat()).exp();
        for j in 0..self.p.len() {
            let e = self.stored(j).creep(decay);
            self.p[j] = e.p;
            self.c[j] = e.c;
        }
    }

    /// The same surface on nodes that reach `reach_hat`, as many cells across: p and c
    /// interpolated linearly from today's nodes, zero past them (no element there has
    /// been touched; moving to a shorter reach drops what the elements past it hold,
    /// [`RelaxingHalfSpace::extension_beyond`]). Second order in the old spacing, once.
    pub fn regrid(&mut self, reach_hat: f64) {
        let old = (self.spacing, self.p.clone(), self.c.clone());
        let last = old.1.len() - 1;
        self.spacing = reach_hat.sqrt() / self.cells() as f64;
        for j in 0..self.p.len() {
            let at = self.xi(j) / old.0;
            let k = at.floor() as usize;
            let (p, c) = if k >= last {
                (0.0, 0.0)
            } else {
                let w = at - k as f64;
                (
                    old.1[k] + w * (old.1[k + 1] - old.1[k]),
                    old.2[k] + w * (old.2[k + 1] - old.2[k]),
                )
            };
            self.p[j] = p;
            self.c[j] = c;
        }
    }

    /// The largest Maxwell extension |v̂| of the nodes past the indentation `reach_hat`
    /// (ξ̂² > reach): what moving to that reach would drop.
    pub fn extension_beyond(&self, reach_hat: f64) -> f64 {
        (0..self.p.len())
            .filter(|&j| self.xi(j).powi(2) > reach_hat)
            .map(|j| {
                let e = self.stored(j);
                (e.c - e.p * self.xi(j).powi(2)).abs()
            })
            .fold(0.0, f64::max)
    }

    /// The largest indentation the nodes reach.
    pub fn reach_hat(&self) -> f64 {
        let x = self.spacing * (self.p.len() - 2) as f64;
        x * x
    }

    fn xi(&self, j: usize) -> f64 {
        self.spacing * j as f64
    }

    /// κ = r/(1 + r): the free surface sits at κv̂.
    fn kappa(&self) -> f64 {
        self.modulus_ratio / (1.0 + self.modulus_ratio)
    }

    /// The retardation time (1 + r)τ̂_r a free element creeps back with.
    pub fn creep_hat(&self) -> f64 {
        (1.0 + self.modulus_ratio) * self.relaxation_hat
    }

    /// Refuse an indentation beyond [`RelaxingHalfSpace::reach_hat`].
    fn within_reach(&self, indentation_hat: f64) -> Result<()> {
        if indentation_hat > self.reach_hat() {
            return Err(Error::NotApplicable(format!(
                "relaxing half-space: indentation {indentation_hat:.6} beyond the nodes' reach {:.6}",
                self.reach_hat()
            )));
        }
        Ok(())
    }

    /// Advance the surface by `duration_hat` while the indentation goes linearly from
    /// `from_hat` to `to_hat` (each element exactly; where it touches or lets go within
    /// the step, the instant is located). Refused past [`RelaxingHalfSpace::reach_hat`].
    pub fn advance(&mut self, from_hat: f64, to_hat: f64, duration_hat: f64) -> Result<()> {
        if !(from_hat.is_finite() && to_hat.is_finite() && duration_hat.is_finite())
            || duration_hat < 0.0
        {
            return Err(Error::Numerical(format!(
                "relaxing half-space: a step from δ̂ = {from_hat} to {to_hat} over {duration_hat}"
            )));
        }
        self.within_reach(from_hat.max(to_hat))?;
        if duration_hat == 0.0 {
            return Ok(());
        }
        let step = Step {
            d0: from_hat,
            slope: (to_hat - from_hat) / duration_hat,
            tau: self.relaxation_hat,
            kappa: self.kappa(),
            creep: self.creep_hat(),
        };
        let (decay, creep_decay) = (
            (-duration_hat / step.tau).exp(),
            (-duration_hat / step.creep).exp(),
        );
        for j in 0..self.p.len() {
            let xi2 = self.xi(j).powi(2);
            let next = step.advance(self.stored(j), xi2, duration_hat, (decay, creep_decay))?;
            self.p[j] = next.p;
            self.c[j] = next.c;
        }
        Ok(())
    }

    /// Open an integrator's step at indentation δ̂_n, rising at `rate_hat`: the
    /// elements as they are now are the step's start. At a point of the step the
    /// indentation is taken as the cubic in time with δ̂ and its rate at both ends
    /// (fourth order, as the step's own points are), and an element that touches
    /// throughout has the Maxwell extension v̂ = c − pξ̂²,
    ///
    ///   c = c_n e^{−Δ/τ̂_r} + ∫₀^Δ e^{−(Δ−s)/τ̂_r} δ̂(s) ds/τ̂_r,  p = 1 − (1 − p_n)e^{−Δ/τ̂_r},
    ///
    /// the integral in closed form (four exponential moments): exact for that cubic however
    /// fast the relaxation, so no stiff equation is left to the integrator. One that
    /// stays free creeps in closed form; one that touches or lets go within the step is
    /// switched where its gap vanishes (cubic in time over the step, from its values
    /// and rates at both ends).
    ///
    /// Refused at an indentation beyond [`RelaxingHalfSpace::reach_hat`] (a step's
    /// points must stay within it too: the elements past it are not there).
    pub fn begin_step(&mut self, indentation_hat: f64, rate_hat: f64) -> Result<()> {
        if !(indentation_hat.is_finite() && rate_hat.is_finite()) {
            return Err(Error::Numerical(format!(
                "relaxing half-space: a step from δ̂ = {indentation_hat}, rate {rate_hat}"
            )));
        }
        self.within_reach(indentation_hat)?;
        self.step_start = (indentation_hat, rate_hat);
        for j in 0..self.p.len() {
            self.touching[j] = self.gap(j, self.stored(j), indentation_hat) > 0.0;
        }
        self.any_touching = self.touching.contains(&true);
        Ok(())
    }

    /// The force F̂ at `elapsed_hat` into the step opened by
    /// [`RelaxingHalfSpace::begin_step`], where the indentation is `indentation_hat`
    /// (rising at `rate_hat`); the surface is not changed.
    pub fn force_in_step_hat(&self, indentation_hat: f64, rate_hat: f64, elapsed_hat: f64) -> f64 {
        // A tip above the undeformed level touches no element that did not touch at the
        // step's start (each element's free surface sits at ξ̂² + κv̂ ≥ 0).
        if indentation_hat <= 0.0 && !self.any_touching {
            return 0.0;
        }
        let now = self.point(indentation_hat, rate_hat, elapsed_hat);
        let node = |j| self.in_step(j, &now);
        // Each node is read by the cells on both sides and by the lines through it:
        // found once, on the stack, where the nodes fit there.
        if self.p.len() <= STACK_NODES {
            let mut nodes = [Element { p: 0.0, c: 0.0 }; STACK_NODES];
            for (j, e) in nodes.iter_mut().enumerate().take(self.p.len()) {
                *e = node(j);
            }
            self.force_of(indentation_hat, &|j| nodes[j])
        } else {
            self.force_of(indentation_hat, &node)
        }
    }

    /// Close the step opened by [`RelaxingHalfSpace::begin_step`] at `elapsed_hat`,
    /// indentation `indentation_hat` (rising at `rate_hat`): the elements become what
    /// [`RelaxingHalfSpace::force_in_step_hat`] saw there.
    pub fn end_step(&mut self, indentation_hat: f64, rate_hat: f64, elapsed_hat: f64) {
        let now = self.point(indentation_hat, rate_hat, elapsed_hat);
        for j in 0..self.p.len() {
            let e = self.in_step(j, &now);
            self.p[j] = e.p;
            self.c[j] = e.c;
        }
    }

    /// The point `elapsed` into the open step where the indentation is `indentation`,
    /// rising at `rate`: what every element's state there shares.
    fn point(&self, indentation: f64, rate: f64, elapsed: f64) -> StepPoint {
        let (d_n, rate_n) = self.step_start;
        // The indentation over the step, a cubic in the fraction of it.
        let path = [
            d_n,
            rate_n * elapsed,
            3.0 * (indentation - d_n) - (2.0 * rate_n + rate) * elapsed,
            2.0 * (d_n - indentation) + (rate_n + rate) * elapsed,
        ];
        StepPoint {
            indentation,
            rate,
            elapsed,
            decay: (-elapsed / self.relaxation_hat).exp(),
            creep_decay: (-elapsed / self.creep_hat()).exp(),
            path,
            memory: relaxing_memory(path, elapsed / self.relaxation_hat),
        }
    }

    /// Element j's gap δ̂ − ξ̂² − κv̂ (positive where it touches).
    fn gap(&self, j: usize, e: Element, indentation_hat: f64) -> f64 {
        let xi2 = self.xi(j).powi(2);
        indentation_hat - xi2 - self.kappa() * (e.c - e.p * xi2)
    }

    /// Element j at `elapsed` into the step (see [`RelaxingHalfSpace::begin_step`]).
    fn in_step(&self, j: usize, now: &StepPoint) -> Element {
        let (d_n, rate_n) = self.step_start;
        let (indentation, rate, elapsed) = (now.indentation, now.rate, now.elapsed);
        let start = self.stored(j);
        let (tau, creep_time) = (self.relaxation_hat, self.creep_hat());
        // Touching from `e` for a time whose relaxation is `decay`, gaining `memory`.
        let touching = |e: Element, decay: f64, memory: f64| Element {
            p: 1.0 - (1.0 - e.p) * decay,
            c: e.c * decay + memory,
        };
        let (e, touched) = if self.touching[j] {
            (touching(start, now.decay, now.memory), true)
        } else {
            (start.creep(now.creep_decay), false)
        };
        let g = self.gap(j, e, indentation);
        if g == 0.0 || (g > 0.0) == touched {
            return e;
        }
        // Switched within the step, where the gap vanished: cubic in time from its
        // values and rates at both ends (the instant fourth order, and the state more:
        // the two motions' rates are equal at a switch).
        let xi2 = self.xi(j).powi(2);
        let v_rate = |e: Element, d: f64| {
            let v = e.c - e.p * xi2;
            if touched {
                (d - xi2 - v) / tau
            } else {
                -v / creep_time
            }
        };
        let gap_rate =
            |e: Element, d: f64, rate: f64| (rate - self.kappa() * v_rate(e, d)) * elapsed;
        let frac = newton_bracketed(
            |s| {
                hermite(
                    s,
                    (self.gap(j, start, d_n), gap_rate(start, d_n, rate_n)),
                    (g, gap_rate(e, indentation, rate)),
                )
            },
            0.0,
            1.0,
            1e-14,
        );
        // The memory up to the switch: the same cubic over the first `frac` of the step.
        let mut first = now.path;
        for (k, a) in first.iter_mut().enumerate() {
            *a *= frac.powi(k as i32);
        }
        let (at, rest) = (frac * elapsed, (1.0 - frac) * elapsed);
        let memory_there = relaxing_memory(first, at / tau);
        if touched {
            touching(start, (-at / tau).exp(), memory_there).creep((-rest / creep_time).exp())
        } else {
            let at_switch = start.creep((-at / creep_time).exp());
            let rest_decay = (-rest / tau).exp();
            let memory = now.memory - rest_decay * memory_there;
            touching(at_switch, rest_decay, memory)
        }
    }

    /// The force F̂ (compressive positive; (4/3)δ̂^{3/2} for the relaxed elastic
    /// contact) at indentation `indentation_hat`, on the surface as it is now.
    pub fn force_hat(&self, indentation_hat: f64) -> f64 {
        self.force_of(indentation_hat, &|j| self.stored(j))
    }

    /// The contact radius ξ̂ (= a/√(R·length unit)): the outermost point where the
    /// elements' force is positive at `indentation_hat`, 0 out of contact.
    pub fn contact_radius_hat(&self, indentation_hat: f64) -> f64 {
        let node = |j| self.stored(j);
        (0..self.p.len() - 1)
            .rev()
            .find_map(|j| self.touching_part(j, indentation_hat, &node))
            .map_or(0.0, |(_, b, _)| b)
    }

    fn stored(&self, j: usize) -> Element {
        Element {
            p: self.p[j],
            c: self.c[j],
        }
    }

    /// F̂ = 2∫q̂ dξ̂ with the elements `node(j)`.
    fn force_of(&self, indentation_hat: f64, node: &impl Fn(usize) -> Element) -> f64 {
        let total: f64 = (0..self.p.len() - 1)
            .filter_map(|j| {
                let (a, b, line) = self.touching_part(j, indentation_hat, node)?;
                let q = self.line_force(line, indentation_hat, node);
                let len = b - a;
                Some(
                    0.5 * len
                        * GAUSS_2
                            .iter()
                            .map(|g| q(a + g * len).0.max(0.0))
                            .sum::<f64>(),
                )
            })
            .sum();
        2.0 * total
    }

    /// The element force density q̂(ξ̂) = (1 + r)(δ̂ − ξ̂²) − r(c − pξ̂²) with p and c on
    /// the line through nodes k and k + 1 (a cubic in ξ̂), and its derivative.
    fn line_force<N: Fn(usize) -> Element>(
        &self,
        k: usize,
        indentation_hat: f64,
        node: &N,
    ) -> impl Fn(f64) -> (f64, f64) + use<N> {
        let (r, h, xk) = (self.modulus_ratio, self.spacing, self.xi(k));
        let (e0, e1) = (node(k), node(k + 1));
        let (dp, dc) = ((e1.p - e0.p) / h, (e1.c - e0.c) / h);
        move |x: f64| {
            let p = e0.p + (x - xk) * dp;
            let c = e0.c + (x - xk) * dc;
            (
                (1.0 + r) * (indentation_hat - x * x) - r * (c - p * x * x),
                -2.0 * (1.0 + r) * x - r * (dc - dp * x * x - 2.0 * p * x),
            )
        }
    }

    /// The part of cell j where q̂ > 0, and the node whose line gives q̂ there. Within
    /// the contact p and c are interpolated between the cell's nodes; in a cell the
    /// contact's edge crosses they are extrapolated from the touching side (the
    /// elements in contact vary smoothly up to the edge; across it they do not), and
    /// the edge is located by Newton. `None` where no element of the cell touches.
    fn touching_part(
        &self,
        j: usize,
        indentation_hat: f64,
        node: &impl Fn(usize) -> Element,
    ) -> Option<(f64, f64, usize)> {
        let (x0, x1) = (self.xi(j), self.xi(j + 1));
        let last = self.p.len() - 2;
        let r = self.modulus_ratio;
        let at_node = |k: usize| {
            let (e, x) = (node(k), self.xi(k));
            (1.0 + r) * (indentation_hat - x * x) - r * (e.c - e.p * x * x)
        };
        let (in0, in1) = (at_node(j) > 0.0, at_node(j + 1) > 0.0);
        let (line, a, b) = match (in0, in1) {
            (true, true) => (j, x0, x1),
            (false, false) => return None,
            (true, false) => {
                let line = j.saturating_sub(1);
                let q = self.line_force(line, indentation_hat, node);
                (line, x0, newton_bracketed(&q, x0, x1, 1e-15 * self.spacing))
            }
            (false, true) => {
                let line = (j + 1).min(last);
                let q = self.line_force(line, indentation_hat, node);
                (line, newton_bracketed(&q, x0, x1, 1e-15 * self.spacing), x1)
            }
        };
        Some((a, b, line))
    }

    /// The free surface's depth under the axis, κv̂(0) (positive below the undeformed
    /// level): where the tip next touches.
    pub fn surface_depth_hat(&self) -> f64 {
        self.kappa() * self.c[0]
    }
}

/// The memory an element in contact gains over a time Δ while the indentation is the
/// cubic δ̂(sΔ) = Σ a_k s^k (s in [0, 1]): ∫₀^Δ e^{−(Δ−t)/τ̂_r} δ̂(t) dt/τ̂_r =
/// Σ a_k M_k(λ), λ = Δ/τ̂_r, with the exponential moments M_k = λ∫₀¹ s^k e^{−λ(1−s)} ds
/// (M₀ = 1 − e^{−λ}, M_k = 1 − (k/λ)M_{k−1} by parts, stable for λ ≥ 1; below, their
/// series Σ_m (−1)^m λ^{m+1} k!/(k + m + 1)!). Exact for any λ ≥ 0: δ̂(Δ) as λ → ∞.
#[doc(hidden)]
pub fn relaxing_memory(a: [f64; 4], lambda: f64) -> f64 {
    let mut moments = [0.0; 4];
    if lambda < 1.0 {
        for (k, m) in moments.iter_mut().enumerate() {
            let mut term = lambda / (k + 1) as f64;
            *m = term;
            for n in 1..20 {
                term *= -lambda / (k + n + 1) as f64;
                *m += term;
            }
        }
    } else {
        moments[0] = -(-lambda).exp_m1();
        for k in 1..4 {
            moments[k] = 1.0 - k as f64 / lambda * moments[k - 1];
        }
    }
    a.iter().zip(moments).map(|(a, m)| a * m).sum()
}

/// A point inside an integrator's step ([`RelaxingHalfSpace::begin_step`]).
struct StepPoint {
    /// δ̂ there …
    indentation: f64,
    /// … its rate …
    rate: f64,
    /// … and the time Δ since the step's start.
    elapsed: f64,
    /// e^{−Δ/τ̂_r}.
    decay: f64,
    /// e^{−Δ/((1 + r)τ̂_r)}.
    creep_decay: f64,
    /// The indentation's cubic over the step, Σ a_k s^k in the fraction s of Δ.
    path: [f64; 4],
    /// What an element touching throughout gains: [`relaxing_memory`] of the path.
    memory: f64,
}

/// One step of an indentation linear in time, δ̂(s) = d0 + slope·s.
struct Step {
    d0: f64,
    slope: f64,
    tau: f64,
    kappa: f64,
    creep: f64,
}

impl Step {
    /// The element's gap at time s: δ̂(s) − ξ̂² − κv̂, positive where it touches (its
    /// force (1 + r)(δ̂ − ξ̂²) − r v̂ is then positive).
    fn gap(&self, e: Element, xi2: f64, s: f64) -> f64 {
        self.d0 + self.slope * s - xi2 - self.kappa * (e.c - e.p * xi2)
    }

    /// The element at time `from + s` of one that is `e` at time `from`: touching
    /// throughout (dv̂/dτ = (δ̂ − ξ̂² − v̂)/τ̂_r, split as dp/dτ = (1 − p)/τ̂_r and
    /// dc/dτ = (δ̂ − c)/τ̂_r, `decay` = e^{−s/τ̂_r}) or free throughout
    /// (dv̂/dτ = −v̂/((1 + r)τ̂_r), `decay` = e^{−s/((1 + r)τ̂_r)}).
    fn evolve(&self, e: Element, from: f64, s: f64, touching: bool, decay: f64) -> Element {
        if touching {
            // c(s) = c₀e^{−x} + δ̂(from)(1 − e^{−x}) + slope·s·φ(x), x = s/τ̂_r,
            // φ(x) = 1 − (1 − e^{−x})/x: no cancellation at large τ̂_r.
            let x = s / self.tau;
            let m = 1.0 - decay;
            let phi = if x < 1e-2 {
                x * (0.5 - x * (1.0 / 6.0 - x * (1.0 / 24.0 - x / 120.0)))
            } else {
                1.0 - m / x
            };
            Element {
                p: e.p * decay + m,
                c: e.c * decay + (self.d0 + self.slope * from) * m + self.slope * s * phi,
            }
        } else {
            e.creep(decay)
        }
    }

    fn evolve_for(&self, e: Element, from: f64, s: f64, touching: bool) -> Element {
        let time = if touching { self.tau } else { self.creep };
        self.evolve(e, from, s, touching, (-s / time).exp())
    }

    /// The element after `duration`, in the mode it starts in, switched where its gap
    /// changes sign (at most a few times a step). `decays` are the whole step's.
    fn advance(
        &self,
        mut e: Element,
        xi2: f64,
        duration: f64,
        decays: (f64, f64),
    ) -> Result<Element> {
        // At a touch the two modes' rates agree; which one follows is the sign of the
        // gap's rate there (the tip's against the free surface's creep).
        let rising = |e: Element| self.slope + self.kappa * (e.c - e.p * xi2) / self.creep > 0.0;
        let g0 = self.gap(e, xi2, 0.0);
        let mut touching = g0 > 0.0 || (g0 == 0.0 && rising(e));
        let mut start = 0.0;
        for switches in 0..8 {
            let end = if start == 0.0 {
                let decay = if touching { decays.0 } else { decays.1 };
                self.evolve(e, 0.0, duration, touching, decay)
            } else {
                self.evolve_for(e, start, duration - start, touching)
            };
            let g1 = self.gap(end, xi2, duration);
            if g1 == 0.0 || (g1 > 0.0) == touching || switches == 7 {
                return Ok(end);
            }
            // The switch: where the gap along this mode's solution changes sign (at the
            // start it has this mode's sign, whatever round-off says after a switch).
            let sign = if touching { 1.0 } else { -1.0 };
            let at = bracketed_root(
                "relaxing half-space: an element's touch",
                |s| {
                    if s <= start {
                        sign * f64::MIN_POSITIVE
                    } else {
                        self.gap(self.evolve_for(e, start, s - start, touching), xi2, s)
                    }
                },
                start,
                duration,
                1e-14,
            )?;
            e = self.evolve_for(e, start, at - start, touching);
            start = at;
            touching = rising(e);
        }
        unreachable!("the loop returns on its last pass")
    }
}
