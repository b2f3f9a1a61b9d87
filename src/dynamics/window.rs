//! What an instrument reads from motion that is not periodic: averages over a window
//! of batches that grows until the batch means agree, a transient at its head cut off.

use super::capture::Candidate;
use super::march::{CycleIntegrals, Phase, Simulation};
pub use super::motion::StdErr;
use super::motion::{Motion, SteadyOptions, SteadyState};
use super::numeric;
use super::recurrence::Recurrence;
use crate::error::Result;
use crate::physics::law::ForceLaw;

/// The averaging window of irregular motion: whole batches and the one being filled.
pub(super) struct Window {
    /// Periods per batch.
    batch_len: usize,
    /// Whether batches are as long as the oscillator's memory (else the error estimate
    /// is not trusted: the batch means are correlated).
    long_enough: bool,
    batches: Vec<CycleIntegrals>,
    current: Option<CycleIntegrals>,
    current_len: usize,
}

impl Window {
    /// Batches must outlast the oscillator's `memory` (in periods) to be nearly
    /// independent; where `budget` periods are too few for [`BATCHES`] of those, shorter
    /// batches still give a window and an error estimate, but not a converged one.
    pub(super) fn new(memory: usize, budget: usize) -> Self {
        let batch_len = memory.min(budget / BATCHES).max(1);
        Self {
            batch_len,
            long_enough: batch_len == memory,
            batches: Vec::with_capacity(BATCHES),
            current: None,
            current_len: 0,
        }
    }

    pub(super) fn add(&mut self, c: &CycleIntegrals) {
        self.current = Some(self.current.map_or(*c, |s| s.then(c)));
        self.current_len += 1;
        if self.current_len == self.batch_len {
            self.batches.push(self.current.take().expect("a batch"));
            self.current_len = 0;
        }
    }
}

/// Batches of an irregular window.
const BATCHES: usize = 16;
/// Batches after which a window may be accepted early: when its standard errors are
/// below the tolerance over [`EARLY_MARGIN`]. With 7 degrees of freedom the estimate
/// of a standard error is itself uncertain (below 0.56 of the true value with 5 %
/// probability) and batches one memory long are still slightly correlated (lag-1
/// correlation ≲ 0.3, which hides up to a factor 1.3); the margin covers both.
const MIN_BATCHES: usize = 8;
const EARLY_MARGIN: f64 = 4.0;

impl<L: ForceLaw> Simulation<'_, L> {
    /// The oscillator's memory, the amplitude's relaxation time 2Q (in τ), in periods:
    /// QΩ/π.
    pub(super) fn memory_periods(&self) -> usize {
        (self.osc.omega / (2.0 * std::f64::consts::PI * self.osc.gamma))
            .ceil()
            .clamp(1.0, 1e9) as usize
    }

    /// March one period with `marching` (this simulation at the averages' tolerance),
    /// record it in the recurrence `ring` and the averaging `window`, count it in
    /// `spent`, and return the steady state if the motion has reached one of the orbits
    /// Newton's method found (`pending`).
    pub(super) fn march_recorded(
        &self,
        marching: &Self,
        phase: &mut Phase,
        (ring, window): (&mut Recurrence, &mut Window),
        pending: &[Candidate],
        spent: &mut usize,
    ) -> Result<Option<SteadyState>> {
        self.rewind(phase);
        let c = marching.cycle(phase, &mut numeric::Ignore)?;
        *spent += 1;
        ring.push(self.z(phase), phase.branch);
        window.add(&c);
        Ok(self.reached(phase, pending, *spent))
    }

    /// Average irregular motion, marched at the averages' tolerance ([`Self::marching`]),
    /// over a window of 16 batches (begun during the search for an orbit, `window`)
    /// whose length doubles (by merging pairs and integrating as many again) until the
    /// standard errors of the batch means of A (relative), φ (rad) and E_ts (relative to
    /// E_drive) are below `opts.average_tolerance`, or the budget is spent; from 8
    /// batches on, a window whose errors are below a quarter of it ([`EARLY_MARGIN`])
    /// is accepted. Whenever a window starts with a transient ([`transient_batches`]),
    /// the motion is not yet stationary: orbits are looked for again (with shooting),
    /// and the transient batches are dropped.
    pub(super) fn average(
        &self,
        phase: &mut Phase,
        opts: &SteadyOptions,
        (budget, mut spent): (usize, usize),
        mut window: Window,
        mut ring: Recurrence,
        mut pending: Vec<Candidate>,
    ) -> Result<SteadyState> {
        let marching = self.marching(opts);
        loop {
            let recorded = (&mut ring, &mut window);
            if let Some(found) =
                self.march_recorded(&marching, phase, recorded, &pending, &mut spent)?
            {
                return Ok(found);
            }
            // At the end of each batch: has the motion locked onto a long period?
            if opts.shooting && window.current_len == 0 {
                if let Some(n) = ring.locked() {
                    let limits = (opts, budget);
                    if let Some(found) = self.shoot(phase, n, limits, &mut spent, &mut pending)? {
                        return Ok(found);
                    }
                }
            }
            let count = window.batches.len();
            let full = count >= BATCHES;
            // From MIN_BATCHES batches on, each finished batch is a chance to stop early.
            let early = window.current_len == 0 && count >= MIN_BATCHES;
            let out_of_budget = spent >= budget;
            if full || early || out_of_budget {
                let (averages, std_err) =
                    batch_statistics(&window.batches, window.current.as_ref());
                let relative = |x: f64, of: f64| if of > 0.0 { x / of } else { x };
                let within = |tolerance: f64| {
                    count >= 2
                        && relative(std_err.amplitude, averages.amplitude()) <= tolerance
                        && std_err.phase <= tolerance
                        && relative(std_err.e_ts, averages.e_drive_per_period().abs()) <= tolerance
                };
                let met = if full || out_of_budget {
                    within(opts.average_tolerance)
                } else {
                    within(opts.average_tolerance / EARLY_MARGIN)
                };
                let transient = transient_batches(&window.batches, opts.average_tolerance);
                if out_of_budget || (met && transient == 0) {
                    return Ok(SteadyState {
                        window: averages,
                        cycles: spent,
                        converged: met && window.long_enough && transient == 0,
                        motion: Motion::Irregular,
                        std_err,
                    });
                }
                if !full && transient == 0 {
                    continue;
                }
                if transient > 0 {
                    // Still a transient (a slow passage, e.g. past a fold's ghost): it
                    // may yet settle on an orbit.
                    if opts.shooting {
                        for n in ring.candidates() {
                            let limits = (opts, budget);
                            if let Some(found) =
                                self.shoot(phase, n, limits, &mut spent, &mut pending)?
                            {
                                return Ok(found);
                            }
                        }
                    }
                    window.batches.drain(..transient);
                } else {
                    if window.batches.len() % 2 == 1 {
                        // (More than BATCHES gathered while searching: the oldest goes.)
                        window.batches.remove(0);
                    }
                    window.batches = window.batches.chunks(2).map(|p| p[0].then(&p[1])).collect();
                    window.batch_len *= 2;
                }
            }
        }
    }
}

/// The window (every batch and the unfinished rest) and the standard errors of the
/// means of the whole batches.
fn batch_statistics(
    batches: &[CycleIntegrals],
    rest: Option<&CycleIntegrals>,
) -> (CycleIntegrals, StdErr) {
    let mut window = batches[0];
    for b in &batches[1..] {
        window = window.then(b);
    }
    if let Some(r) = rest {
        window = window.then(r);
    }
    let n = batches.len() as f64;
    let phase = window.phase();
    let std_err_of = |value: &dyn Fn(&CycleIntegrals) -> f64| {
        (crate::numeric::mean_and_variance(batches.iter().map(value)).1 / n).sqrt()
    };
    let std_err = if batches.len() < 2 {
        StdErr {
            amplitude: f64::INFINITY,
            phase: f64::INFINITY,
            e_ts: f64::INFINITY,
        }
    } else {
        StdErr {
            amplitude: std_err_of(&|b| b.amplitude()),
            phase: std_err_of(&|b| crate::numeric::wrap_angle(b.phase() - phase)),
            e_ts: std_err_of(&|b| b.e_ts_per_period()),
        }
    };
    (window, std_err)
}

/// How many leading batches of a window are transient: for A, φ and E_ts per period,
/// the MSER cut ([`crate::numeric::transient_cut`]) that moves the window's mean by
/// more than `tolerance` (A relative, φ in rad, E_ts relative to E_drive, as the
/// standard errors are judged); the largest of the three. A transient that creeps
/// (past a fold's ghost, say) shows up as leading batches far from the rest.
fn transient_batches(batches: &[CycleIntegrals], tolerance: f64) -> usize {
    let n = batches.len();
    if n < 4 {
        return 0;
    }
    let (window, _) = batch_statistics(batches, None);
    let phase = window.phase();
    let cut = |value: &dyn Fn(&CycleIntegrals) -> f64, scale: f64| {
        let ys: Vec<f64> = batches.iter().map(value).collect();
        crate::numeric::transient_cut(&ys, tolerance * scale)
    };
    let relative_to = |x: f64| if x > 0.0 { x } else { 1.0 };
    cut(&|b| b.amplitude(), relative_to(window.amplitude()))
        .max(cut(&|b| crate::numeric::wrap_angle(b.phase() - phase), 1.0))
        .max(cut(
            &|b| b.e_ts_per_period(),
            relative_to(window.e_drive_per_period().abs()),
        ))
}
