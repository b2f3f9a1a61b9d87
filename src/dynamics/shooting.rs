//! Periodic orbits by Newton's method on the period map P (the state at the same drive
//! phase n periods later), with the map's exact derivative from the marcher's
//! variational equations: Pⁿ(z) − z = 0 converges quadratically, and the orbit's Floquet
//! multipliers (the eigenvalues of the monodromy matrix) say whether it is stable.

use super::capture::Candidate;
use super::march::{CycleIntegrals, Phase, Simulation};
use super::model::SECTION_DIM;
use super::model::{chain, phi_start};
pub use super::motion::Multipliers;
use super::motion::{Motion, StdErr, SteadyOptions, SteadyState};
use super::numeric::Ignore;
use crate::error::{Error, Result};
use crate::physics::law::ForceLaw;
use nalgebra::{Complex, DMatrix, DVector};

/// The n-period map evaluated at a state.
pub(crate) struct MapValue {
    /// The state n periods later.
    pub end: Phase,
    /// ∂z(end)/∂(z, q)(start), z the section state.
    pub derivative: DMatrix<f64>,
    /// The integrals over the n periods.
    pub integrals: CycleIntegrals,
    /// |state after k + 1 periods − start|∞ for k < n.
    pub returns: Vec<f64>,
}

impl MapValue {
    /// The derivative in the state alone (the monodromy matrix on an orbit).
    pub fn monodromy(&self) -> DMatrix<f64> {
        let d = self.derivative.nrows();
        self.derivative.columns(0, d).into_owned()
    }
}

/// A periodic orbit found by Newton's method.
struct Orbit {
    /// The state on the orbit at the section.
    phase: Phase,
    /// |Pⁿ(z) − z|∞ there.
    residual: f64,
}

/// Rejected Newton steps in a row after which the search for an orbit gives up.
const MAX_REJECTIONS: usize = 6;
/// Accepted Newton steps that may pass without halving the residual.
const STALL_STEPS: usize = 8;
/// Newton's trial maps are integrated at this fraction of the residual they try to
/// reduce (inexact Newton: the error of the map stays far below what a step must gain).
const NEWTON_TOLERANCE: f64 = 1e-2;

impl<L: ForceLaw> Simulation<'_, L> {
    /// The n-period map from `start` moved to `z`: the state n periods later and the
    /// map's derivative there; `None` if the motion does not return on the branch it
    /// left, or if the variational equations cannot be integrated there (a tip that
    /// stalls at a fold of the force law, where the map is not smooth). Counts the
    /// periods in `spent`.
    pub(crate) fn period_map(
        &self,
        start: &Phase,
        z: &DVector<f64>,
        n: usize,
        spent: &mut usize,
    ) -> Result<Option<MapValue>> {
        let mut p = self.at_z(start, z);
        let branch = self.consistent_branch(&p);
        let mut derivative = phi_start(z.len());
        let mut integrals: Option<CycleIntegrals> = None;
        let mut returns = vec![f64::INFINITY; n];
        for k in 0..n {
            *spent += 1;
            match self.cycle_with_derivative(&mut p) {
                Ok((c, d)) => {
                    derivative = chain(&derivative, &d);
                    integrals = Some(integrals.map_or(c, |s| s.then(&c)));
                    if let Some(r) = returns.get_mut(k) {
                        *r = (self.z(&p) - z).amax();
                    }
                }
                Err(Error::Numerical(_)) => return Ok(None),
                Err(e) => return Err(e),
            }
        }
        let back = p.branch == branch && self.z(&p).iter().all(|c| c.is_finite());
        Ok(back.then(|| MapValue {
            end: p,
            derivative,
            integrals: integrals.expect("n >= 1"),
            returns,
        }))
    }

    /// Newton's method on Pⁿ(z) − z = 0 from `start`, with the exact derivative of the
    /// map. Each step is limited to a trust radius (largest change of x or x', in units
    /// of L) that grows after a step that reduces the residual as the linear model
    /// promises (at least a tenth of the promised reduction) and shrinks fourfold after
    /// one that does not. There is no cap on the number of steps, however many a slowly
    /// contracting (high-Q) orbit needs; it ends when the residual is below `target`,
    /// when a full step no longer reduces a residual already below `floor` (the
    /// integrator's noise), after [`MAX_REJECTIONS`] rejected steps in a row or
    /// [`STALL_STEPS`] accepted ones that do not halve the residual (the map is not
    /// smooth there: a grazing contact), or when `budget` periods are spent.
    fn newton(
        &self,
        start: &Phase,
        n: usize,
        (target, floor): (f64, f64),
        budget: usize,
        spent: &mut usize,
    ) -> Result<Option<Orbit>> {
        let mut z = self.z(start);
        let Some(value) = self.period_map(start, &z, n, spent)? else {
            return Ok(None);
        };
        let mut m = value.monodromy();
        let mut end = value.end;
        let mut r = self.z(&end) - &z;
        let mut norm = r.amax();
        let mut radius: f64 = 0.2;
        let mut rejected = 0;
        // The residual at the last halving and the accepted steps since.
        let (mut checkpoint, mut since) = (norm, 0);
        loop {
            if norm <= target {
                break;
            }
            if *spent + n > budget {
                return Ok(None);
            }
            let Some(inverse) = (&m - DMatrix::identity(z.len(), z.len())).try_inverse() else {
                return Ok(None);
            };
            let step = -(inverse * &r);
            let length = step.amax();
            if !length.is_finite() {
                return Ok(None);
            }
            let scale = (radius / length).min(1.0);
            let trial = &z + step * scale;
            // Inexact Newton: far from the orbit the map need not be exact to the
            // integrator's tolerance, only well below the residual.
            let evaluated = self
                .loosened(NEWTON_TOLERANCE * norm)
                .period_map(start, &trial, n, spent)?
                .map(|value| {
                    let residual = self.z(&value.end) - &trial;
                    (value, residual)
                });
            match evaluated {
                Some((value, residual)) if residual.amax() <= (1.0 - 0.1 * scale) * norm => {
                    z = trial;
                    m = value.monodromy();
                    end = value.end;
                    r = residual;
                    norm = r.amax();
                    radius = radius.max(2.0 * scale * length);
                    rejected = 0;
                    since += 1;
                    if norm <= 0.5 * checkpoint {
                        (checkpoint, since) = (norm, 0);
                    } else if since == STALL_STEPS {
                        return Ok(None);
                    }
                }
                _ if scale == 1.0 && norm <= floor => break,
                _ => {
                    radius = 0.25 * scale * length;
                    rejected += 1;
                    if rejected == MAX_REJECTIONS {
                        return Ok(None);
                    }
                }
            }
        }
        Ok(Some(Orbit {
            phase: self.at_z(&end, &z),
            residual: norm,
        }))
    }

    /// Look for a stable period-n orbit near `phase` by Newton's method, leaving `phase`
    /// as it is: the orbit with its steady state over one pass, a candidate for what the
    /// motion settles on ([`Candidate`]). An orbit that is unstable, or whose least
    /// period is below n, is not one (the motion does not settle on it).
    fn try_period(
        &self,
        phase: &Phase,
        n: usize,
        opts: &SteadyOptions,
        budget: usize,
        spent: &mut usize,
    ) -> Result<Option<Candidate>> {
        let target = (1e-2 * opts.tolerance).max(1e-13);
        let Some(orbit) = self.newton(phase, n, (target, opts.tolerance), budget, spent)? else {
            return Ok(None);
        };
        if *spent + 3 * n > budget {
            return Ok(None);
        }
        let mut on = orbit.phase;
        let Some((state, monodromy)) = self.settle(&mut on, n, orbit.residual, spent)? else {
            return Ok(None);
        };
        if state.motion.stable() != Some(true) {
            return Ok(None);
        }
        let state = SteadyState {
            converged: orbit.residual <= opts.tolerance,
            ..state
        };
        *spent += state.window.periods as usize - 1;
        let grazing = self.grazing(opts, &state).jump;
        Ok(Some(Candidate::new(self, state, on, &monodromy, grazing)?))
    }

    /// Newton's method for a period-n orbit from `phase` ([`Self::try_period`]): if the
    /// orbit found captures `phase` ([`Candidate::captures`]: the marching that led here
    /// has begun converging onto it), `phase` is moved onto it and its steady state
    /// returned; otherwise it joins `pending`, the orbits that later marching may reach.
    pub(super) fn shoot(
        &self,
        phase: &mut Phase,
        n: usize,
        (opts, budget): (&SteadyOptions, usize),
        spent: &mut usize,
        pending: &mut Vec<Candidate>,
    ) -> Result<Option<SteadyState>> {
        let Some(candidate) = self.try_period(phase, n, opts, budget, spent)? else {
            return Ok(None);
        };
        if candidate.captures(self, phase) {
            *phase = candidate.on;
            return Ok(Some(SteadyState {
                cycles: *spent,
                ..candidate.state
            }));
        }
        let known = |c: &Candidate| c.same_orbit(&candidate, 1e3 * opts.tolerance.max(1e-12));
        if !pending.iter().any(known) {
            pending.push(candidate);
        }
        Ok(None)
    }

    /// The steady state of the first of the `pending` orbits whose capture radius the
    /// marched `phase` has entered (`phase` is moved onto it), if any.
    pub(super) fn reached(
        &self,
        phase: &mut Phase,
        pending: &[Candidate],
        spent: usize,
    ) -> Option<SteadyState> {
        let candidate = pending.iter().find(|c| c.captures(self, phase))?;
        *phase = candidate.on.clone();
        Some(SteadyState {
            cycles: spent,
            ..candidate.state
        })
    }

    /// The steady state on the orbit through `phase` that returns after n periods within
    /// `residual`: one pass of it (its least period m, a divisor of n to which the state
    /// returns within 10³ residuals), with its monodromy matrix. `None` if the
    /// variational equations cannot be integrated along it (see `period_map`).
    pub(super) fn settle(
        &self,
        phase: &mut Phase,
        n: usize,
        residual: f64,
        spent: &mut usize,
    ) -> Result<Option<(SteadyState, DMatrix<f64>)>> {
        let start = phase.clone();
        let z = self.z(&start);
        let Some(mut pass) = self.period_map(&start, &z, n, spent)? else {
            return Ok(None);
        };
        let least = (1..=n)
            .find(|&m| n % m == 0 && (m == n || pass.returns[m - 1] <= 1e3 * residual.max(1e-12)))
            .unwrap_or(n);
        if least < n {
            let Some(shorter) = self.period_map(&start, &z, least, spent)? else {
                return Ok(None);
            };
            pass = shorter;
        }
        let monodromy = pass.monodromy();
        *phase = pass.end;
        Ok(Some((
            SteadyState {
                window: pass.integrals,
                cycles: *spent,
                converged: true,
                motion: Motion::Periodic {
                    period: least,
                    multipliers: eigenvalues(&monodromy),
                },
                std_err: StdErr::default(),
            },
            monodromy,
        )))
    }
}

impl<L: ForceLaw> Simulation<'_, L> {
    /// [`Simulation::settle`] for a law with a surface ([`super::surface`]), whose period
    /// map has no derivative here: the n periods marched (the least period found the
    /// same way), no multipliers.
    pub(super) fn settle_marching(
        &self,
        phase: &mut Phase,
        n: usize,
        residual: f64,
        spent: &mut usize,
    ) -> Result<SteadyState> {
        let z = self.z(phase);
        let pass =
            |periods: usize, spent: &mut usize| -> Result<(Phase, CycleIntegrals, Vec<f64>)> {
                let mut p = phase.clone();
                let mut integrals: Option<CycleIntegrals> = None;
                let mut returns = Vec::with_capacity(periods);
                for _ in 0..periods {
                    *spent += 1;
                    self.rewind(&mut p);
                    let c = self.cycle(&mut p, &mut Ignore)?;
                    integrals = Some(integrals.map_or(c, |s| s.then(&c)));
                    returns.push((self.z(&p) - &z).amax());
                }
                Ok((p, integrals.expect("n >= 1"), returns))
            };
        let (mut end, mut integrals, returns) = pass(n, spent)?;
        let least = (1..=n)
            .find(|&m| n % m == 0 && (m == n || returns[m - 1] <= 1e3 * residual.max(1e-12)))
            .unwrap_or(n);
        if least < n {
            (end, integrals, _) = pass(least, spent)?;
        }
        *phase = end;
        Ok(SteadyState {
            window: integrals,
            cycles: *spent,
            converged: true,
            motion: Motion::Periodic {
                period: least,
                multipliers: Multipliers::default(),
            },
            std_err: StdErr::default(),
        })
    }
}

/// Eigenvalues of a monodromy matrix (at most [`SECTION_DIM`] × [`SECTION_DIM`]): in
/// closed form for 2×2, from the real Schur form otherwise.
pub(crate) fn eigenvalues(m: &DMatrix<f64>) -> Multipliers {
    let mut values = [Complex::new(0.0, 0.0); SECTION_DIM];
    let len = m.nrows().min(SECTION_DIM);
    if len == 2 {
        let half_trace = 0.5 * m.trace();
        let disc = Complex::new(half_trace * half_trace - m.determinant(), 0.0).sqrt();
        let h = Complex::new(half_trace, 0.0);
        values[0] = h + disc;
        values[1] = h - disc;
    } else {
        for (v, e) in values.iter_mut().zip(m.complex_eigenvalues().iter()) {
            *v = *e;
        }
    }
    Multipliers { values, len }
}
