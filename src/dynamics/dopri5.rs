//! The Dormand–Prince 5(4) pair (Dormand & Prince, J. Comput. Appl. Math. 6, 19, 1980)
//! with the step-size control of Hairer's DOPRI5 (Hairer, Nørsett & Wanner, Solving
//! Ordinary Differential Equations I, §II.4 and II.5: a PI controller on the embedded
//! error estimate, β = 0.04, and Hairer's initial step), on a fixed-size state and with no
//! allocation: the segment integrator of [`super::numeric`] calls it for every branch of
//! every drive period, millions of times in a march.
//!
//! It follows ode_solvers' `Dopri5` (which the tests keep as an independent integrator)
//! operation for operation, so a trajectory is the same to the last bit; what it leaves
//! out is the per-call allocation of the stages and the per-step record of every state,
//! and the stiffness test (never run here).

use super::model::State;

/// A right-hand side and an observer of accepted steps.
#[doc(hidden)]
pub trait System<const N: usize> {
    /// The components that are quadratures: integrals the right-hand side never reads
    /// (their derivative depends on the other components alone). Only a step's solution
    /// needs them, not its intermediate stages, which skip them (the same numbers, less
    /// arithmetic).
    const QUADRATURES: std::ops::Range<usize> = 0..0;
    /// dy/dt at (t, y).
    fn system(&self, t: f64, y: &State<N>, dy: &mut State<N>);
    /// Told each accepted step's end (t, y, dy/dt there); true stops the integration.
    fn solout(&mut self, _t: f64, _y: &State<N>, _dy: &State<N>) -> bool {
        false
    }
}

/// Why an integration stopped short.
#[derive(Debug, Clone, Copy, PartialEq)]
#[doc(hidden)]
pub enum StepError {
    /// The step fell to round-off of t.
    StepSizeUnderflow {
        /// Where.
        x: f64,
    },
    /// More than the allowed number of steps.
    MaxNumStepReached {
        /// Where.
        x: f64,
        /// The limit.
        n_step: u32,
    },
}

/// Steps taken.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[doc(hidden)]
pub struct Stats {
    /// Accepted steps.
    pub accepted_steps: u32,
    /// Rejected steps (after the first accepted one).
    pub rejected_steps: u32,
    /// The step the controller proposes after the last accepted one (at least the step
    /// it had proposed before that one was cut short to end at `x_end`): where an
    /// integration that goes on from `x_end` should start.
    pub h_proposed: f64,
}

/// The settings of one integration.
#[derive(Debug, Clone, Copy, PartialEq)]
#[doc(hidden)]
pub struct Settings {
    /// Relative and absolute tolerance.
    pub rtol: f64,
    pub atol: f64,
    /// Largest step.
    pub h_max: f64,
    /// First trial step (0: Hairer's estimate).
    pub h0: f64,
    /// Most steps.
    pub max_steps: u32,
}

/// Runge–Kutta matrix (rows 2–7), nodes and error weights (b − b̂) of the pair.
const A: [[f64; 6]; 6] = [
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Controller constants: safety factor, β, the bounds of the step ratio.
#[doc(hidden)]
pub const SAFETY: f64 = 0.9;
#[doc(hidden)]
pub const BETA: f64 = 0.04;
#[doc(hidden)]
pub const FAC_MIN: f64 = 0.2;
#[doc(hidden)]
pub const FAC_MAX: f64 = 10.0;

/// Integrate from (`x`, `y`) to `x_end` (> x), each accepted step shown to `f.solout`.
#[doc(hidden)]
pub fn integrate<S: System<N>, const N: usize>(
    f: &mut S,
    mut x: f64,
    x_end: f64,
    mut y: State<N>,
    s: &Settings,
) -> Result<Stats, StepError> {
    let alpha = 0.2 - BETA * 0.75;
    let (facc1, facc2) = (1.0 / FAC_MIN, 1.0 / FAC_MAX);
    let mut fac_old: f64 = 1.0e-4;
    let mut reject = false;
    let mut stats = Stats::default();
    let mut h = if s.h0 == 0.0 {
        initial_step(f, x, x_end, &y, s)
    } else {
        s.h0
    };
    let mut k = [State::<N>::zeros(); 7];
    f.system(x, &y, &mut k[0]);
    let (mut n_step, mut last) = (0u32, false);
    // The step proposed before the last one was cut to end at x_end.
    let mut h_uncut = 0.0;
    while !last {
        if n_step > s.max_steps {
            return Err(StepError::MaxNumStepReached { x, n_step });
        }
        if 0.1 * h.abs() <= f64::EPSILON * x.abs() {
            return Err(StepError::StepSizeUnderflow { x });
        }
        if x + 1.01 * h - x_end > 0.0 {
            h_uncut = h;
            h = x_end - x;
            last = true;
        }
        n_step += 1;
        let mut y_next = y;
        // The stages the right-hand side reads skip the quadratures; the last, the
        // step's solution, has them all.
        let skip = S::QUADRATURES;
        let (read_to, read_from) = (skip.start.min(N), skip.end.clamp(skip.start.min(N), N));
        for stage in 1..7 {
            y_next = y;
            let ranges = if stage < 6 {
                [0..read_to, read_from..N]
            } else {
                [0..N, N..N]
            };
            for (j, kj) in k.iter().enumerate().take(stage) {
                let a = A[stage - 1][j];
                for range in ranges.clone() {
                    for i in range {
                        y_next[i] += kj[i] * h * a;
                    }
                }
            }
            f.system(x + h * C[stage], &y_next, &mut k[stage]);
        }
        k[1] = k[6];
        let mut err = 0.0;
        for i in 0..N {
            let e = (k[0][i] * E[0]
                + k[2][i] * E[2]
                + k[3][i] * E[3]
                + k[4][i] * E[4]
                + k[5][i] * E[5]
                + k[1][i] * E[6])
                * h;
            let sc = s.atol + y[i].abs().max(y_next[i].abs()) * s.rtol;
            err += (e / sc) * (e / sc);
        }
        let err = (err / N as f64).sqrt();
        // Hairer's PI step-size controller.
        let fac11 = err.powf(alpha);
        let fac = facc2.max(facc1.min(fac11 * fac_old.powf(-BETA) / SAFETY));
        let mut h_new = h / fac;
        if err <= 1.0 {
            stats.accepted_steps += 1;
            fac_old = err.max(1.0e-4);
            if h_new.abs() > s.h_max {
                h_new = s.h_max;
            }
            if reject {
                h_new = h_new.abs().min(h.abs());
            }
            reject = false;
            k[0] = k[1];
            y = y_next;
            x += h;
            if f.solout(x, &y, &k[0]) {
                last = true;
            }
            if last {
                stats.h_proposed = h_new.abs().max(h_uncut.abs()).min(s.h_max);
                return Ok(stats);
            }
        } else {
            h_new = h / facc1.min(fac11 / SAFETY);
            reject = true;
            last = false;
            if stats.accepted_steps >= 1 {
                stats.rejected_steps += 1;
            }
        }
        h = h_new;
    }
    Ok(stats)
}

/// Hairer's initial step: an explicit Euler step's error estimate set to 0.01 of the
/// tolerance, capped by 100 times the first guess and by `h_max`.
fn initial_step<S: System<N>, const N: usize>(
    f: &S,
    x: f64,
    _x_end: f64,
    y: &State<N>,
    s: &Settings,
) -> f64 {
    let mut f0 = State::<N>::zeros();
    f.system(x, y, &mut f0);
    let (mut d0, mut d1) = (0.0, 0.0);
    for i in 0..N {
        let sc = s.atol + y[i].abs() * s.rtol;
        d0 += (y[i] / sc) * (y[i] / sc);
        d1 += (f0[i] / sc) * (f0[i] / sc);
    }
    let mut h0 = if d0 < 1.0e-10 || d1 < 1.0e-10 {
        1.0e-6
    } else {
        0.01 * (d0 / d1).sqrt()
    };
    h0 = h0.min(s.h_max);
    let y1 = y + f0 * h0;
    let mut f1 = State::<N>::zeros();
    f.system(x + h0, &y1, &mut f1);
    let mut d2: f64 = 0.0;
    for i in 0..N {
        let sc = s.atol + y[i].abs() * s.rtol;
        d2 += ((f1[i] - f0[i]) / sc) * ((f1[i] - f0[i]) / sc);
    }
    d2 = d2.sqrt() / h0;
    let h1 = if d1.sqrt().max(d2.abs()) <= 1.0e-15 {
        1.0e-6_f64.max(h0.abs() * 1.0e-3)
    } else {
        (0.01 / d1.sqrt().max(d2)).powf(1.0 / 5.0)
    };
    (100.0 * h0.abs()).min(h1.min(s.h_max))
}
