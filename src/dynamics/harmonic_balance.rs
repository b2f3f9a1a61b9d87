//! The first-harmonic balance of the force-driven cantilever: where the steady states
//! at a rest separation lie, estimated in microseconds, as seeds for the exact search.
//!
//! If the tip moved as a pure cosine x = m + Â cos ψ (ψ = Ωτ − θ, θ the phase lag), the
//! tip force along it would have a mean f̄ and a first harmonic f_c cos ψ + f_s sin ψ
//! (f_s > 0 where the loop loses energy: E_ts = π Â f_s). Balancing that harmonic in
//! x'' + 2γx' + x = f_ts + f₀ cos Ωτ, with L(Ω) = 1 − Ω² + 2iγΩ, gives the describing-
//! function equations of García & San Paulo (Phys. Rev. B 60, 4961, 1999; in their
//! energy and virial form, San Paulo & García, Phys. Rev. B 66, 041406, 2002):
//!
//!   |Â·L(Ω) − f_c + i f_s| = f₀,   Â e^{−iθ} = f₀ Â / (Â·L(Ω) − f_c + i f_s),   m = f̄.
//!
//! Their roots in Â are the orbits the averaged motion has at this separation: one far
//! from the sample, and, where the attractive and the repulsive regimes coexist, three
//! (two stable, the middle one a saddle). The walk along the cosine follows the law's
//! branches (jump-in and jump-out where they fall), so the hysteresis enters f_s. A root
//! is only an estimate (the tip's motion has harmonics, a relaxing sample's surface is
//! not in it): each is a start for the exact steady-state search, which decides.

use super::march::{Phase, Simulation};
use super::model::Drive;
use crate::numeric::{GAUSS_LEGENDRE_8, bracketed_root};
use crate::physics::law::{Branch, ContactState, ForceLaw};
use std::f64::consts::PI;

/// Gauss–Legendre panels along a stretch of the cosine on one branch.
const PANELS: usize = 8;
/// Amplitudes tried, evenly spaced up to [`REACH`] times the free amplitude.
const GRID: usize = 96;
/// How far above the free amplitude roots are looked for.
const REACH: f64 = 1.25;
/// Golden-section steps into a dip of the residual between grid points.
const GOLDEN_STEPS: usize = 40;
/// A bracket whose residual stays above this fraction of f₀ holds a jump of the
/// residual (the tip starting or stopping to touch), not a root.
const ROOT_RESIDUAL: f64 = 1e-3;

/// A stable root of the first-harmonic balance.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// Amplitude Â (units of L).
    pub amplitude: f64,
    /// Phase lag θ behind the drive, degrees.
    pub phase_deg: f64,
    /// The state at τ = 0 on the cosine, on the branch the walk along it is on there: a
    /// start for [`Simulation::steady_state`].
    pub start: Phase,
}

/// The tip force along one cosine: its mean and its first harmonic.
#[derive(Debug, Clone, Copy)]
struct Harmonic {
    mean: f64,
    cos: f64,
    sin: f64,
}

impl<L: ForceLaw> Simulation<'_, L> {
    /// The stable roots of the first-harmonic balance at this rest separation
    /// (García & San Paulo, Phys. Rev. B 60, 4961, 1999; see the module), smallest
    /// amplitude first: where the residual rises through zero as Â grows (a root where it
    /// falls is the saddle between two of them), continuous there (a jump of the residual
    /// where the tip starts to touch is a grazing orbit, not a root). None for a base drive.
    pub fn harmonic_balance(&self) -> Vec<Estimate> {
        let Drive::Force { amplitude: f0 } = self.osc.drive else {
            return Vec::new();
        };
        let (w, g) = (self.osc.omega, self.osc.gamma);
        let (lr, li) = (1.0 - w * w, 2.0 * g * w);
        let free = f0 / lr.hypot(li);
        let residual = |a: f64| -> (f64, f64, Harmonic) {
            // The mean deflection from the mean force, once corrected.
            let first = self.along(a, 0.0);
            let m = first.mean;
            let h = if (self.cpl.a1 * m).abs() > 1e-2 {
                self.along(a, m)
            } else {
                first
            };
            let (re, im) = (a * lr - h.cos, a * li + h.sin);
            (re.hypot(im) - f0, m, h)
        };
        let step = REACH * free / GRID as f64;
        let at = |j: usize| step * (j + 1) as f64;
        let r: [f64; GRID] = std::array::from_fn(|j| residual(at(j)).0);
        // Brackets of a rise through zero: between neighbours, or, inside a dip of the
        // residual narrower than the grid (a stiff contact), between its minimum and the
        // right neighbour (the minimum's left side then holds the saddle).
        let mut brackets = Vec::new();
        for j in 1..GRID {
            if r[j - 1] < 0.0 && r[j] >= 0.0 {
                brackets.push((at(j - 1), at(j)));
            }
            if j + 1 < GRID && r[j] > 0.0 && r[j] <= r[j - 1] && r[j] <= r[j + 1] {
                let (bottom, depth) = golden_minimum(|a| residual(a).0, (at(j - 1), at(j + 1)));
                if depth < 0.0 {
                    brackets.push((bottom, at(j + 1)));
                }
            }
        }
        brackets.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut out = Vec::new();
        for (lo, hi) in brackets {
            // (A bracket that does not converge holds no root worth starting from.)
            let Ok(a) = bracketed_root("a harmonic-balance root", |a| residual(a).0, lo, hi, 1e-12)
            else {
                continue;
            };
            let (res, m, h) = residual(a);
            if res.abs() <= ROOT_RESIDUAL * f0 {
                out.push(self.estimate(a, m, h, f0, (lr, li)));
            }
        }
        out
    }

    /// The root's orbit: amplitude, phase and its state at τ = 0.
    fn estimate(&self, a: f64, m: f64, h: Harmonic, f0: f64, (lr, li): (f64, f64)) -> Estimate {
        // Y = f₀ Â / (Â L − f_c + i f_s); x(τ) = m + Re(Y e^{iΩτ}).
        let (dr, di) = (a * lr - h.cos, a * li + h.sin);
        let d2 = dr * dr + di * di;
        let (yr, yi) = (f0 * a * dr / d2, -f0 * a * di / d2);
        let theta = (-yi).atan2(yr);
        let (x, v) = (m + yr, -self.osc.omega * yi);
        // ψ = −θ at τ = 0: the branch the cosine is on there, walked from its top.
        let branch = self.branch_along(a, m, (-theta).rem_euclid(2.0 * PI));
        Estimate {
            amplitude: a,
            phase_deg: theta.to_degrees(),
            start: Phase {
                x,
                v,
                branch,
                ..Phase::at_rest()
            },
        }
    }

    /// The force along x = m + Â cos ψ over its second turn (the first settles the
    /// branch): each stretch on one branch, between switches placed in closed form (α̂ =
    /// c + r cos ψ), integrated by Gauss–Legendre on panels that halve toward the
    /// bottom of the cosine, where the force is.
    fn along(&self, a: f64, m: f64) -> Harmonic {
        let mut sum = Harmonic {
            mean: 0.0,
            cos: 0.0,
            sin: 0.0,
        };
        let mut branch = self.branch_at(0.0, m + a);
        for turn in 0..2 {
            self.walk(a, m, &mut branch, &mut |branch, from, to| {
                if turn == 1 {
                    self.integrate(a, m, branch, (from, to), &mut sum);
                }
            });
        }
        Harmonic {
            mean: sum.mean / (2.0 * PI),
            cos: sum.cos / PI,
            sin: sum.sin / PI,
        }
    }

    /// The branch at ψ on the second turn of the cosine.
    fn branch_along(&self, a: f64, m: f64, psi: f64) -> Branch {
        let mut branch = self.branch_at(0.0, m + a);
        self.walk(a, m, &mut branch, &mut |_, _, _| {});
        let mut at = branch;
        self.walk(a, m, &mut branch, &mut |on, from, to| {
            if (from..to).contains(&psi) {
                at = on;
            }
        });
        at
    }

    /// One turn of the cosine from its top, `branch` carried through: `stretch(branch,
    /// ψ₁, ψ₂)` for each stretch on one branch, in order.
    fn walk(
        &self,
        a: f64,
        m: f64,
        branch: &mut Branch,
        stretch: &mut impl FnMut(Branch, f64, f64),
    ) {
        let (c, r) = (self.cpl.alpha_hat(m, 0.0), self.cpl.a1 * a);
        // Where α̂ = level on the way down (ψ in [0, π]).
        let down = |level: f64| ((level - c) / r).clamp(-1.0, 1.0).acos();
        for half in 0..2 {
            let mut psi = PI * half as f64;
            let end = psi + PI;
            for _ in 0..=2 * Branch::COUNT {
                let exits = self.law.exits(*branch);
                let exit = if half == 0 {
                    exits.below.map(|(level, next)| (down(level), next))
                } else {
                    exits
                        .above
                        .map(|(level, next)| (2.0 * PI - down(level), next))
                };
                match exit {
                    Some((at, next)) if at < end => {
                        let at = at.max(psi);
                        if at > psi {
                            stretch(*branch, psi, at);
                        }
                        psi = at;
                        *branch = next;
                    }
                    _ => break,
                }
            }
            if psi < end {
                stretch(*branch, psi, end);
            }
        }
    }

    /// Add ∫ f dψ, ∫ f cos ψ dψ and ∫ f sin ψ dψ over [ψ₁, ψ₂] on `branch` to `sum`.
    fn integrate(
        &self,
        a: f64,
        m: f64,
        branch: Branch,
        (from, to): (f64, f64),
        sum: &mut Harmonic,
    ) {
        if branch == Branch::Free && self.law.free_branch_is_force_free() {
            return;
        }
        // Panels halving toward the bottom (ψ = π), which ends the first half of the turn
        // and starts the second.
        let toward_end = to <= PI;
        let edge = |k: usize| {
            let u = if k >= PANELS {
                1.0
            } else {
                1.0 - 0.5f64.powi(k as i32)
            };
            if toward_end {
                from + (to - from) * u
            } else {
                to - (to - from) * u
            }
        };
        for k in 0..PANELS {
            let (p0, p1) = (edge(k).min(edge(k + 1)), edge(k).max(edge(k + 1)));
            let (mid, half) = (0.5 * (p0 + p1), 0.5 * (p1 - p0));
            for &(node, weight) in &GAUSS_LEGENDRE_8 {
                let psi = mid + half * node;
                let (s, c) = psi.sin_cos();
                let state = ContactState {
                    alpha_hat: self.cpl.alpha_hat(m + a * c, 0.0),
                    rate_hat: -self.cpl.a1 * a * self.osc.omega * s,
                    branch,
                };
                let f = -self.cpl.f_scale * self.law.force_hat(&state) * weight * half;
                sum.mean += f;
                sum.cos += f * c;
                sum.sin += f * s;
            }
        }
    }
}

/// The smallest value of `f` on [lo, hi] and where it is, by golden-section search (f
/// unimodal there).
fn golden_minimum(f: impl Fn(f64) -> f64, (mut lo, mut hi): (f64, f64)) -> (f64, f64) {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..GOLDEN_STEPS {
        if f1 <= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
        if f1.min(f2) < 0.0 {
            break;
        }
    }
    if f1 <= f2 { (x1, f1) } else { (x2, f2) }
}
