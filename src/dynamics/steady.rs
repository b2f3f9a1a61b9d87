//! Cycle-by-cycle integration to the steady state.
//!
//! Each drive period is integrated as a chain of segments, one per branch: closed-form
//! free flight where the law is force-free out of contact (and the oscillator is
//! force-driven and underdamped), Dopri5 otherwise; every branch switch is located and the
//! next segment restarts from the located state. The carried integrals give the energies,
//! Fourier projections, mean force and virial of each cycle.

use super::free::FreeFlight;
use super::model::{Coupling, E_DAMP, F_INT, Oscillator, SC, SS, State, V, VIRIAL, X};
use super::numeric::{self, Crossing, StepEnd, StepObserver, Tolerances, hermite};
use crate::error::Result;
use crate::law::{Branch, ForceLaw};

/// Where the oscillator is: time, deflection, velocity and contact branch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Phase {
    /// τ.
    pub tau: f64,
    /// Deflection x.
    pub x: f64,
    /// Velocity x'.
    pub v: f64,
    /// Contact branch.
    pub branch: Branch,
    /// First trial step for the next numerical segment on each branch (free, contact;
    /// 0: the solver's choice).
    pub h_next: [f64; 2],
}

impl Phase {
    /// At rest at τ = 0 out of contact.
    pub fn at_rest() -> Self {
        Self {
            tau: 0.0,
            x: 0.0,
            v: 0.0,
            branch: Branch::Free,
            h_next: [0.0; 2],
        }
    }
}

/// The integrals and extremes of one drive period (dimensionless).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleIntegrals {
    /// Drive period in τ.
    pub period: f64,
    /// Energy dissipated in the contact, ∮ −f_ts dα, summed from the branch work functions
    /// between the located switches (exact for the computed path).
    pub e_ts: f64,
    /// Energy dissipated by damping.
    pub e_damp: f64,
    /// Energy put in by the drive ([`Oscillator::drive_work`]).
    pub e_drive: f64,
    /// Change of the oscillator's energy ½(x² + x'²) over the period.
    pub delta_mechanical: f64,
    /// ∮ x cos Ωτ dτ.
    pub sc: f64,
    /// ∮ x sin Ωτ dτ.
    pub ss: f64,
    /// ∮ f_ts dτ.
    pub f_int: f64,
    /// ∮ f_ts x dτ.
    pub virial_int: f64,
    /// Time spent on the contact branch.
    pub contact_time: f64,
    /// Smallest separation α̂ met.
    pub min_alpha_hat: f64,
    /// Largest (most repulsive) f_ts met.
    pub max_force: f64,
    /// Smallest (most attractive) f_ts met.
    pub min_force: f64,
    /// Number of jumps into contact.
    pub jumps_in: u32,
    /// Number of jumps out of contact.
    pub jumps_out: u32,
}

impl CycleIntegrals {
    /// Amplitude of the fundamental (units of L).
    pub fn amplitude(&self) -> f64 {
        2.0 / self.period * self.sc.hypot(self.ss)
    }

    /// Phase lag φ of the fundamental, z ≈ A cos(ωt − φ), in radians.
    pub fn phase(&self) -> f64 {
        self.ss.atan2(self.sc)
    }
}

/// Tracks extremes of the separation and force over accepted steps, then passes each
/// step on.
struct Tracker<'a, O: StepObserver> {
    osc: &'a Oscillator,
    cpl: &'a Coupling,
    inner: &'a mut O,
    min_alpha: f64,
    max_f: f64,
    min_f: f64,
}

impl<O: StepObserver> StepObserver for Tracker<'_, O> {
    fn step(&mut self, a: &StepEnd, b: &StepEnd, branch: Branch) {
        let alpha = |tau: f64, x: f64| self.cpl.alpha_hat(x, self.osc.base_at(tau).0);
        let mut lowest = alpha(b.tau, b.y[X]);
        // A turning point inside the step: the minimum of the Hermite cubic, where its
        // derivative (a quadratic in the step fraction) vanishes.
        if a.y[V] < 0.0 && b.y[V] > 0.0 {
            let t = hermite_minimum(a, b);
            let tau = a.tau + t * (b.tau - a.tau);
            lowest = lowest.min(alpha(tau, hermite(a, b, X, tau)));
        }
        self.min_alpha = self.min_alpha.min(lowest);
        self.max_f = self.max_f.max(b.dy[F_INT]);
        self.min_f = self.min_f.min(b.dy[F_INT]);
        self.inner.step(a, b, branch);
    }

    fn free_flight(&mut self, flight: &FreeFlight, from: f64, to: f64) {
        self.max_f = self.max_f.max(0.0);
        self.min_f = self.min_f.min(0.0);
        self.inner.free_flight(flight, from, to);
    }
}

/// Step fraction in [0, 1] of the minimum of the deflection's Hermite cubic on a step
/// where the velocity goes from negative to positive.
fn hermite_minimum(a: &StepEnd, b: &StepEnd) -> f64 {
    let h = b.tau - a.tau;
    let (p0, p1, m0, m1) = (a.y[X], b.y[X], h * a.y[V], h * b.y[V]);
    // The cubic is p0 + m0 t + c2 t² + c3 t³; its derivative 3c3 t² + 2c2 t + m0.
    let c3 = 2.0 * p0 + m0 - 2.0 * p1 + m1;
    let c2 = -3.0 * p0 - 2.0 * m0 + 3.0 * p1 - m1;
    let (qa, qb, qc) = (3.0 * c3, 2.0 * c2, m0);
    let t = if qa.abs() <= 1e-14 * (qb.abs() + qc.abs()) {
        -qc / qb
    } else {
        let disc = (qb * qb - 4.0 * qa * qc).max(0.0).sqrt();
        let (r1, r2) = ((-qb - disc) / (2.0 * qa), (-qb + disc) / (2.0 * qa));
        // The root where the derivative rises through zero.
        if 2.0 * qa * r1 + qb > 0.0 { r1 } else { r2 }
    };
    if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.5
    }
}

/// A law, an oscillator, its coupling to the contact and the integrator settings.
#[derive(Debug, Clone, Copy)]
pub struct Simulation<'a, L: ForceLaw> {
    /// Tip–sample force law.
    pub law: &'a L,
    /// The oscillator.
    pub osc: Oscillator,
    /// Coupling to the contact.
    pub cpl: Coupling,
    /// Integrator settings.
    pub tol: Tolerances,
}

impl<L: ForceLaw> Simulation<'_, L> {
    /// The branch a state at rest separation α̂ starts on: in contact if the tip is already
    /// below the jump-in separation.
    pub fn branch_at(&self, tau: f64, x: f64) -> Branch {
        let alpha = self.cpl.alpha_hat(x, self.osc.base_at(tau).0);
        if alpha <= self.law.jump_in_alpha_hat() {
            Branch::Contact
        } else {
            Branch::Free
        }
    }

    /// The force-driven free steady state at τ = 0 (or rest for a base drive).
    pub fn free_steady_start(&self) -> Phase {
        let (x, v) = FreeFlight::steady(&self.osc)
            .map(|(a, b)| (a, b * self.osc.omega))
            .unwrap_or((0.0, 0.0));
        Phase {
            tau: 0.0,
            x,
            v,
            branch: self.branch_at(0.0, x),
            h_next: [0.0; 2],
        }
    }

    /// Integrate one drive period from `phase`, updating it.
    pub fn cycle<O: StepObserver>(
        &self,
        phase: &mut Phase,
        observer: &mut O,
    ) -> Result<CycleIntegrals> {
        let period = self.osc.period();
        let tau_end = phase.tau + period;
        // A state carried over from another setpoint may sit on the wrong side of a
        // switch (the tip cannot be out of contact below the jump-in separation).
        let alpha = self.cpl.alpha_hat(phase.x, self.osc.base_at(phase.tau).0);
        phase.branch = match phase.branch {
            Branch::Free if alpha <= self.law.jump_in_alpha_hat() => Branch::Contact,
            Branch::Contact if alpha >= self.law.jump_out_alpha_hat() => Branch::Free,
            b => b,
        };
        let mut y = State::zeros();
        y[X] = phase.x;
        y[V] = phase.v;
        let mechanical = |y: &State| 0.5 * (y[X] * y[X] + y[V] * y[V]);
        let e0 = mechanical(&y);
        let start = (phase.tau, phase.x, phase.v);
        let mut tracker = Tracker {
            osc: &self.osc,
            cpl: &self.cpl,
            inner: observer,
            min_alpha: f64::INFINITY,
            max_f: f64::NEG_INFINITY,
            min_f: f64::INFINITY,
        };
        let (mut contact_time, mut jumps_in, mut jumps_out) = (0.0, 0, 0);
        // E_ts = (RΔγ/(kL))/(L/(με)) ∫ T̂ dα̂ in units of kL².
        let work_scale = self.cpl.f_scale / self.cpl.a1;
        let mut e_ts = 0.0;
        let mut tau = phase.tau;
        let closed_form = self.law.free_branch_is_force_free();
        // Stop when the remaining time is round-off.
        while tau_end - tau > 1e-12 * period {
            let flight = (phase.branch == Branch::Free && closed_form)
                .then(|| FreeFlight::new(&self.osc, tau, y[X], y[V]))
                .flatten();
            if let Some(flight) = flight {
                let level = self.cpl.x_at(self.law.jump_in_alpha_hat());
                let (hit, min_x) = flight.first_fall_to(level, tau, tau_end, period / 8.0);
                let stop = hit.unwrap_or(tau_end);
                flight.advance(&mut y, tau, stop);
                tracker.free_flight(&flight, tau, stop);
                tracker.min_alpha = tracker.min_alpha.min(self.cpl.alpha_hat(min_x, 0.0));
                tau = stop;
                if hit.is_some() {
                    phase.branch = Branch::Contact;
                    jumps_in += 1;
                }
                continue;
            }
            let (level, crossing) = match phase.branch {
                Branch::Free => (self.law.jump_in_alpha_hat(), Crossing::Down),
                Branch::Contact => (self.law.jump_out_alpha_hat(), Crossing::Up),
            };
            let event = level.is_finite().then_some((level, crossing));
            let alpha_at = |tau: f64, y: &State| self.cpl.alpha_hat(y[X], self.osc.base_at(tau).0);
            let work_start = self.law.work_hat(alpha_at(tau, &y), phase.branch);
            let end = numeric::integrate(
                self.law,
                &self.osc,
                &self.cpl,
                phase.branch,
                event,
                tau,
                y,
                tau_end,
                phase.h_next[phase.branch as usize],
                &self.tol,
                &mut tracker,
            )?;
            e_ts += work_scale
                * (self.law.work_hat(alpha_at(end.tau, &end.y), phase.branch) - work_start);
            if phase.branch == Branch::Contact {
                contact_time += end.tau - tau;
            }
            if end.h_first > 0.0 {
                phase.h_next[phase.branch as usize] = end.h_first;
            }
            tau = end.tau;
            y = end.y;
            if end.switched {
                phase.branch = match phase.branch {
                    Branch::Free => {
                        jumps_in += 1;
                        Branch::Contact
                    }
                    Branch::Contact => {
                        jumps_out += 1;
                        Branch::Free
                    }
                };
            }
        }
        phase.tau = tau_end;
        phase.x = y[X];
        phase.v = y[V];
        Ok(CycleIntegrals {
            period,
            e_ts,
            e_damp: y[E_DAMP],
            e_drive: self.osc.drive_work(start, (tau, y[X], y[V]), y[SC], y[SS]),
            delta_mechanical: mechanical(&y) - e0,
            sc: y[SC],
            ss: y[SS],
            f_int: y[F_INT],
            virial_int: y[VIRIAL],
            contact_time,
            min_alpha_hat: tracker.min_alpha,
            max_force: tracker.max_f,
            min_force: tracker.min_f,
            jumps_in,
            jumps_out,
        })
    }

    /// Look for the period-one orbit by shooting: Newton's method on the one-period map
    /// P(x, x') − (x, x') = 0, its Jacobian by finite differences (two more periods per
    /// iteration). On success `phase` is moved onto the orbit; the periods spent are
    /// returned either way (0 work is wasted beyond them: a failure leaves `phase` as it
    /// was). Fails — and the caller integrates the transient — where the map changes its
    /// switching pattern under the perturbation, or the orbit is not period-one.
    fn shoot(&self, phase: &mut Phase) -> Result<(bool, usize)> {
        let start = *phase;
        let mut periods = 0;
        let mut z = (phase.x, phase.v);
        let map = |z: (f64, f64), periods: &mut usize| -> Result<Option<(f64, f64)>> {
            let mut p = Phase {
                x: z.0,
                v: z.1,
                ..start
            };
            self.cycle(&mut p, &mut numeric::Ignore)?;
            *periods += 1;
            // The orbit must return on the branch it left.
            Ok((p.branch == start.branch).then_some((p.x - z.0, p.v - z.1)))
        };
        for _ in 0..12 {
            let Some(f) = map(z, &mut periods)? else {
                return Ok((false, periods));
            };
            let size = f.0.abs().max(f.1.abs());
            if size < 1e-11 {
                *phase = Phase {
                    x: z.0,
                    v: z.1,
                    ..start
                };
                return Ok((true, periods));
            }
            let h = 1e-7;
            let (Some(fx), Some(fv)) = (
                map((z.0 + h, z.1), &mut periods)?,
                map((z.0, z.1 + h), &mut periods)?,
            ) else {
                return Ok((false, periods));
            };
            // J = [[∂f0/∂x, ∂f0/∂v], [∂f1/∂x, ∂f1/∂v]].
            let (a, b, c, d) = (
                (fx.0 - f.0) / h,
                (fv.0 - f.0) / h,
                (fx.1 - f.1) / h,
                (fv.1 - f.1) / h,
            );
            let det = a * d - b * c;
            if !det.is_finite() || det.abs() < 1e-300 {
                return Ok((false, periods));
            }
            let step = ((d * f.0 - b * f.1) / det, (a * f.1 - c * f.0) / det);
            // Far from the orbit full Newton steps overshoot (the map is only weakly
            // contracting): limit them; the caller integrates closer if this fails.
            let scale = (0.2 / step.0.abs().max(step.1.abs())).min(1.0);
            z = (z.0 - scale * step.0, z.1 - scale * step.1);
        }
        Ok((false, periods))
    }

    /// Integrate cycles until the amplitude, phase and contact dissipation change by less
    /// than `opts.tolerance` (relative; the energy relative to the drive input) over
    /// `opts.streak` consecutive cycles, or until `opts.max_cycles`. Reports the last cycle.
    /// When `opts.shooting` is set, the periodic orbit is first looked for by shooting
    /// (a few dozen periods instead of ~Q ln(1/tolerance)/π); the cycles integrated
    /// afterwards still have to pass the convergence test.
    pub fn steady_state(&self, phase: &mut Phase, opts: &SteadyOptions) -> Result<SteadyState> {
        let mut last: Option<CycleIntegrals> = None;
        let mut streak = 0;
        let mut cycles = 0;
        if opts.shooting {
            // A first period puts the state on a consistent branch; where shooting fails,
            // a stretch of transient brings the state closer before the next attempt.
            self.cycle(phase, &mut numeric::Ignore)?;
            cycles += 1;
            for _ in 0..4 {
                let (found, spent) = self.shoot(phase)?;
                cycles += spent;
                if found || cycles >= opts.max_cycles {
                    break;
                }
                for _ in 0..SHOOTING_RETRY_PERIODS {
                    self.cycle(phase, &mut numeric::Ignore)?;
                }
                cycles += SHOOTING_RETRY_PERIODS;
            }
        }
        while cycles < opts.max_cycles.max(1) {
            let c = self.cycle(phase, &mut numeric::Ignore)?;
            cycles += 1;
            if let Some(p) = last {
                let da = (c.amplitude() - p.amplitude()).abs() / c.amplitude().max(1e-300);
                let dphi = (c.phase() - p.phase()).abs();
                let de = (c.e_ts - p.e_ts).abs() / c.e_drive.abs().max(1e-300);
                if da < opts.tolerance && dphi < opts.tolerance && de < opts.tolerance {
                    streak += 1;
                } else {
                    streak = 0;
                }
            }
            last = Some(c);
            if streak >= opts.streak && cycles >= opts.min_cycles {
                break;
            }
        }
        Ok(SteadyState {
            cycle: last.expect("at least one cycle"),
            cycles,
            converged: streak >= opts.streak,
        })
    }
}

/// Transient periods integrated between shooting attempts.
const SHOOTING_RETRY_PERIODS: usize = 100;

/// Settings of the steady-state search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteadyOptions {
    /// Convergence tolerance per cycle.
    pub tolerance: f64,
    /// Consecutive converged cycles required.
    pub streak: usize,
    /// At least this many cycles.
    pub min_cycles: usize,
    /// At most this many cycles.
    pub max_cycles: usize,
    /// Look for the periodic orbit by shooting first.
    pub shooting: bool,
}

/// The outcome of [`Simulation::steady_state`].
#[derive(Debug, Clone, Copy)]
pub struct SteadyState {
    /// The reported (last) cycle.
    pub cycle: CycleIntegrals,
    /// Cycles integrated in all.
    pub cycles: usize,
    /// Whether the convergence criterion was met.
    pub converged: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hermite_minimum_finds_the_turning_point_of_a_parabola() {
        // x = (τ − 0.3)², sampled at τ = 0 and 1 with exact slopes: the cubic is exact.
        let end = |tau: f64| {
            let mut y = State::zeros();
            y[X] = (tau - 0.3) * (tau - 0.3);
            y[V] = 2.0 * (tau - 0.3);
            StepEnd {
                tau,
                y,
                dy: State::zeros(),
            }
        };
        let t = hermite_minimum(&end(0.0), &end(1.0));
        assert!((t - 0.3).abs() < 1e-12, "{t}");
    }
}
