//! The steady state of several eigenmodes: a periodic orbit over the common period,
//! found by Newton's method on the period map with the exact variational equations
//! (the saltation at every switch included), marching where Newton does not converge,
//! and classified by its Floquet multipliers.

use super::system::{Modes, PassTally, phi, plain_len, q, tangent_len, v};
use crate::dynamics::model::State;
use crate::dynamics::numeric::Tolerances;
use crate::error::{Error, Result};
use crate::physics::law::{Branch, ForceLaw};
use nalgebra::{DMatrix, DVector};

/// A periodic orbit of the modes over one common period.
#[derive(Debug, Clone)]
pub struct ModalOrbit {
    /// The section state at τ = 0: (q₁, q₁′, q₂, q₂′, …).
    pub section: Vec<f64>,
    /// The law's branch at τ = 0.
    pub branch: Branch,
    /// The carried integrals over the period (the plain layout's components after the
    /// section state).
    pub integrals: Vec<f64>,
    /// What the pass saw of the contact.
    pub tally: PassTally,
    /// Floquet multipliers (re, im).
    pub multipliers: Vec<[f64; 2]>,
    /// |P(z) − z| as [`OrbitOptions::tolerance`] measures it.
    pub residual: f64,
    /// Common periods integrated in all.
    pub periods_integrated: usize,
}

impl ModalOrbit {
    /// Whether every multiplier lies inside the unit circle.
    pub fn stable(&self) -> bool {
        self.multipliers.iter().all(|m| m[0].hypot(m[1]) < 1.0)
    }
}

/// How hard to look.
#[derive(Debug, Clone, Copy)]
pub struct OrbitOptions {
    /// The largest |P(z) − z| accepted, each mode's deflection in units of its free
    /// amplitude and its velocity in units of that times its frequency (the first
    /// mode's: units of A₀₁, as one mode's orbits; a mode that is not driven in A₀₁).
    pub tolerance: f64,
    /// Common periods integrated at most.
    pub max_periods: usize,
}

/// Common periods marched at most where Newton's method fails.
const MARCH_PERIODS: usize = 50;

/// How much looser the tolerances of the period map are far from the orbit.
const COARSE: f64 = 100.0;

/// The return distance (units of A₀₁) below which the period map is taken at the
/// tolerances.
const FINE_WITHIN: f64 = 1e-5;

/// Newton iterations at most before marching takes over.
const NEWTON_ITERATIONS: usize = 25;

/// Halvings of a Newton step that returned farther than its start.
const BACKTRACKS: usize = 4;

impl<L: ForceLaw, const M: usize> Modes<'_, L, M> {
    /// The size of a difference `r` of section states, each mode's parts over the scale
    /// of its free motion ([`OrbitOptions::tolerance`]): a small second mode's phase is
    /// converged as well as the first's.
    fn distance(&self, r: &[f64]) -> f64 {
        self.modes
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let free = m.free_amplitude();
                let a = if free > 0.0 { free } else { 1.0 };
                (r[q(i)].abs() / a).max(r[v(i)].abs() / (a * m.omega.max(m.r)))
            })
            .fold(0.0, f64::max)
    }

    /// How far the pass ending at `y` returned from its start `z` ([`Self::distance`]).
    fn returned<const S: usize>(&self, y: &State<S>, z: &[f64]) -> f64 {
        let r: Vec<f64> = z.iter().enumerate().map(|(k, z)| y[k] - z).collect();
        self.distance(&r)
    }

    /// The state of layout `S` with section `z`, zero integrals and Φ = I (if carried).
    fn start<const S: usize>(z: &[f64]) -> State<S> {
        let mut y = State::<S>::zeros();
        y.as_mut_slice()[..2 * M].copy_from_slice(z);
        if S == tangent_len(M) {
            for k in 0..2 * M {
                y[phi(M, k, k)] = 1.0;
            }
        }
        y
    }

    /// The periodic orbit near `z0` (on `branch0` at τ = 0) over the common period
    /// `period`; `P` and `T` are the plain and the tangent layouts' lengths.
    pub fn orbit<const P: usize, const T: usize>(
        &self,
        z0: &[f64],
        branch0: Branch,
        period: f64,
        opts: &OrbitOptions,
    ) -> Result<ModalOrbit> {
        const { assert!(P == plain_len(M) && T == tangent_len(M)) };
        let d = 2 * M;
        let mut z = z0.to_vec();
        let mut branch = branch0;
        let mut periods = 0usize;
        let mut best = f64::INFINITY;
        // Newton on P(z) − z, each step checked against the residual it leads to.
        // Far from the orbit the period map is taken at COARSE times the tolerances (an
        // inexact Newton step is as good there); near it, and for what is reported, at
        // the tolerances.
        let coarse = Modes {
            tol: Tolerances {
                rtol: self.tol.rtol * COARSE,
                atol: self.tol.atol * COARSE,
                ..self.tol
            },
            ..*self
        };
        let mut last_step: Option<(Vec<f64>, Vec<f64>)> = None;
        let mut from_branch = branch;
        let mut backtracks = 0;
        for _ in 0..NEWTON_ITERATIONS {
            let fine = best <= FINE_WITHIN;
            let map = if fine { self } else { &coarse };
            let (y, end_branch, tally) =
                map.pass::<T>(0.0, Self::start::<T>(&z), branch, period)?;
            periods += 1;
            let r: Vec<f64> = (0..d).map(|k| y[k] - z[k]).collect();
            let residual = self.distance(&r);
            if end_branch != branch {
                // Not closed on this branch: go on from where the period ended.
                z = y.as_slice()[..d].to_vec();
                branch = end_branch;
                continue;
            }
            if fine && residual <= opts.tolerance {
                return Ok(self.finished(&z, branch, &y, tally, residual, periods));
            }
            // A step that returned farther than the best point is halved from there (up
            // to BACKTRACKS times): near an orbit that grazes a switch the period map
            // jumps, and a whole step lands on another pattern of contacts.
            if residual > best && backtracks < BACKTRACKS {
                if let Some((from, step)) = &mut last_step {
                    backtracks += 1;
                    step.iter_mut().for_each(|s| *s *= 0.5);
                    z = from.iter().zip(step.iter()).map(|(a, s)| a - s).collect();
                    branch = from_branch;
                    continue;
                }
            }
            backtracks = 0;
            let jacobian =
                DMatrix::from_fn(d, d, |row, col| y[phi(M, row, col)] - f64::from(row == col));
            let step = jacobian.lu().solve(&DVector::from_vec(r));
            match step {
                Some(step)
                    if residual < 1e3 * best.min(1.0) && step.iter().all(|s| s.is_finite()) =>
                {
                    // Newton step, limited to a tenth of the free amplitude per mode.
                    let scale = step.amax().max(0.1) / 0.1;
                    let applied: Vec<f64> = step.iter().map(|s| s / scale).collect();
                    from_branch = branch;
                    last_step = Some((z.clone(), applied.clone()));
                    for k in 0..d {
                        z[k] -= applied[k];
                    }
                }
                _ => {
                    last_step = None;
                    z = y.as_slice()[..d].to_vec();
                }
            }
            best = best.min(residual);
        }
        // Marching: the period map applied until it returns within the tolerance, in
        // windows of MARCH_PERIODS. A window that contracts the return distance (an orbit
        // Newton's method missed, whose high-Q modes settle slowly)
        // earns the next while the rate it contracts at reaches the tolerance within
        // `max_periods`; one that does not ends the search.
        let mut last = f64::INFINITY;
        let newton_periods = periods;
        let budget = periods + opts.max_periods;
        let mut limit = periods + opts.max_periods.min(MARCH_PERIODS);
        let mut window_start = f64::INFINITY;
        while periods < limit {
            let (y, end_branch, _) = self.pass::<P>(0.0, Self::start::<P>(&z), branch, period)?;
            periods += 1;
            let residual = self.returned(&y, &z);
            z = y.as_slice()[..d].to_vec();
            let closed = end_branch == branch;
            branch = end_branch;
            if closed && residual <= opts.tolerance {
                let (y, end, tally) = self.pass::<T>(0.0, Self::start::<T>(&z), branch, period)?;
                let residual = self.returned(&y, &z);
                if end == branch && residual <= 10.0 * opts.tolerance {
                    return Ok(self.finished(&z, branch, &y, tally, residual, periods + 1));
                }
            }
            last = residual;
            if window_start.is_infinite() {
                window_start = residual;
            }
            if periods == limit && closed {
                let rate = (residual / window_start).powf(1.0 / MARCH_PERIODS as f64);
                let needed = (opts.tolerance / residual).ln() / rate.ln();
                if rate < 0.999 && periods as f64 + needed <= budget as f64 {
                    limit = (periods + MARCH_PERIODS).min(budget);
                }
                window_start = residual;
            }
        }
        Err(Error::NotApplicable(format!(
            "the modes settle on no orbit of the common period: Newton's method did not \
             converge and {} periods of marching do not return (last return distance \
             {last:.1e} of the free motion). The motion is of a longer period or irregular \
             (where the first mode alone is, `tapsim tap` names it), which several modes are \
             not reported for",
            periods - newton_periods
        )))
    }

    /// The orbit through `z` on `branch`, from the tangent pass `y` over its period:
    /// the monodromy matrix is that pass's Φ.
    fn finished<const T: usize>(
        &self,
        z: &[f64],
        branch: Branch,
        y: &State<T>,
        tally: PassTally,
        residual: f64,
        periods: usize,
    ) -> ModalOrbit {
        let d = 2 * M;
        let multipliers = DMatrix::from_fn(d, d, |row, col| y[phi(M, row, col)])
            .complex_eigenvalues()
            .iter()
            .map(|c| [c.re, c.im])
            .collect();
        ModalOrbit {
            section: z.to_vec(),
            branch,
            integrals: y.as_slice()[2 * M..plain_len(M)].to_vec(),
            tally,
            multipliers,
            residual,
            periods_integrated: periods,
        }
    }
}

/// The section state of the free steady oscillation of every mode at τ = 0 (each mode's
/// linear response to its own drive), the first mode's replaced by `first` if given.
pub fn free_section(modes: &[super::set::ModeModel], first: Option<(f64, f64)>) -> Vec<f64> {
    let mut z = vec![0.0; 2 * modes.len()];
    for (i, m) in modes.iter().enumerate() {
        // q = Re[G f e^{iΩτ}], G = c/(r² − Ω² + i rΩ/Q).
        let (re, im) = (m.r * m.r - m.omega * m.omega, m.damping * m.omega);
        let den = re * re + im * im;
        let (g_re, g_im) = (m.gain * m.drive * re / den, -m.gain * m.drive * im / den);
        z[q(i)] = g_re;
        z[v(i)] = -m.omega * g_im;
    }
    if let Some((x, v1)) = first {
        z[0] = x;
        z[1] = v1;
    }
    z
}
