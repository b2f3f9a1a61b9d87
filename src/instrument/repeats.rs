//! Drive periods not marched because the loop repeats itself (issue 44).
//!
//! Over a stretch of sample that does not change (one material at one height), the
//! whole loop — the oscillator's state at the drive phase, the lock-in's filters, the
//! piezo and the controller — is a map applied once a cycle (a drive period; the
//! common period of several modes' drives, q drive periods), and it settles on a fixed
//! point: from there every cycle repeats the last. [`Repeats`] watches the loop's state
//! after each marched period; once the state moves by a gap d a cycle (against the
//! state a cycle before) that has shrunk geometrically for [`WINDOW`] periods at a rate
//! no slower than ρ (the largest ratio of successive gaps a cycle apart), the state
//! lies within d·ρ/(1 − ρ) of the fixed point, and once that bound is below the
//! tolerance the whole cycles that follow over the same stretch are taken as repeats
//! of the last, not marched. Motion that does not repeat each cycle (a long lock
//! grazing a switch) never shrinks its gap and is always marched; so is a probe under
//! a thermal force or one whose drives have no common period. The exact march is
//! [`Repeats::exact`].

/// The loop state watched: the probe's (deflection, velocity, the lock-in's filter
/// stages and last input) then the piezo and the controller's last
/// error, each in units of A₀ (or of the amplitude ratio).
pub const STATE_LEN: usize = 48;

/// The loop's state after a drive period ([`STATE_LEN`] entries, unused ones zero).
pub type LoopState = [f64; STATE_LEN];

/// Periods over which the gap must shrink before periods are skipped.
pub const WINDOW: usize = 32;

/// The longest cycle watched (in drive periods): a loop that repeats only after more is
/// always marched.
pub const LONGEST_CYCLE: usize = WINDOW / 4;

/// The default bound on the distance from the fixed point at which periods are skipped,
/// in units of A₀: 2e-15 m of piezo on a 20 nm amplitude, 6e-6° of phase — some
/// thousand times below what a skipped period may change of an image (1 pm of
/// topography, 1e-3° of phase, tested against the exact march).
pub const DEFAULT_TOLERANCE: f64 = 1e-7;

/// The slowest contraction trusted: a loop whose gap shrinks by less than this a period
/// is marched on.
const SLOWEST: f64 = 0.9999;

/// Watches the loop's state and says when the periods that follow repeat the last.
#[derive(Debug, Clone, PartialEq)]
pub struct Repeats {
    /// The bound on the distance from the fixed point (none: never skip).
    tolerance: Option<f64>,
    /// The states of the last cycle, oldest first (as many as periods seen, up to the
    /// cycle).
    last: Vec<LoopState>,
    /// The last gaps, newest at `seen % WINDOW`.
    gaps: [f64; WINDOW],
    /// Gaps recorded since the stretch began.
    seen: usize,
    /// For a loop that rings ([`Repeats::within_blocks`]): the block's length, the
    /// largest gap of the block under way and of the two blocks before (the last
    /// first).
    blocks: Option<(usize, f64, [f64; 2])>,
    /// Periods marched.
    pub marched: u64,
    /// Periods taken as repeats.
    pub skipped: u64,
}

impl Repeats {
    /// Every period marched.
    pub fn exact() -> Self {
        Self::skipping(None)
    }

    /// Periods skipped where the state is within `tolerance` (units of A₀) of the
    /// loop's fixed point.
    pub fn within(tolerance: f64) -> Self {
        Self::skipping(Some(tolerance))
    }

    /// Periods skipped where the state is within `tolerance` of the fixed point of a
    /// loop that may ring (approach its fixed point in damped oscillations of up to
    /// `block` periods, as FM's loops do): the gap's largest value over successive
    /// blocks of `block` periods must shrink, by ratios no larger than ρ over the last
    /// three blocks (two ratios: a fast mode that died in the first block does not pass
    /// for the slow one's rate), and the state then lies within M·block·ρ/(1 − ρ) of the
    /// fixed point (M the last block's largest gap). Over
    /// a window shorter than its ringing a gap shrinks near each turn of the oscillation
    /// however far the loop is from its fixed point, which [`Repeats::within`] would take
    /// for convergence.
    pub fn within_blocks(tolerance: f64, block: usize) -> Self {
        Self {
            blocks: Some((block.max(1), 0.0, [0.0; 2])),
            ..Self::skipping(Some(tolerance))
        }
    }

    fn skipping(tolerance: Option<f64>) -> Self {
        Self {
            tolerance,
            last: Vec::new(),
            gaps: [0.0; WINDOW],
            seen: 0,
            blocks: None,
            marched: 0,
            skipped: 0,
        }
    }

    /// Whether periods are ever skipped.
    pub fn is_exact(&self) -> bool {
        self.tolerance.is_none()
    }

    /// A new stretch of sample begins: what was seen says nothing about it.
    pub fn restart(&mut self) {
        self.last.clear();
        self.seen = 0;
        if let Some((_, current, before)) = &mut self.blocks {
            (*current, *before) = (0.0, [0.0; 2]);
        }
    }

    /// Record the state after a marched period of a loop that repeats every `cycle`
    /// periods (`None`: a probe that cannot be skipped); whether the loop now repeats
    /// itself to the tolerance.
    pub fn settled(&mut self, state: Option<&LoopState>, cycle: usize) -> bool {
        self.marched += 1;
        let (Some(tolerance), Some(state)) = (self.tolerance, state) else {
            self.restart();
            return false;
        };
        if cycle > LONGEST_CYCLE {
            return false;
        }
        if self.last.len() < cycle.max(1) {
            self.last.push(*state);
            return false;
        }
        // The state a cycle before, and this one in its place.
        let before = self.last.remove(0);
        self.last.push(*state);
        let gap = state
            .iter()
            .zip(&before)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        self.seen += 1;
        if let Some((block, current, before)) = &mut self.blocks {
            *current = current.max(gap);
            if self.seen % *block != 0 {
                return false;
            }
            let (now, [last, first]) = (*current, *before);
            (*current, *before) = (0.0, [now, last]);
            if now == 0.0 {
                return true;
            }
            if self.seen < 3 * *block {
                return false;
            }
            let rho = (now / last).max(last / first);
            return rho < 1.0 && now * *block as f64 * rho / (1.0 - rho) <= tolerance;
        }
        self.gaps[(self.seen - 1) % WINDOW] = gap;
        if self.seen < WINDOW {
            return false;
        }
        // The slowest contraction over the window (oldest to newest).
        let mut rho: f64 = 0.0;
        for k in cycle..WINDOW {
            let (older, newer) = (
                self.gaps[(self.seen + k - cycle) % WINDOW],
                self.gaps[(self.seen + k) % WINDOW],
            );
            if newer > 0.0 {
                rho = rho.max(newer / older);
            }
        }
        if gap == 0.0 {
            return true;
        }
        rho < SLOWEST && gap * rho / (1.0 - rho) <= tolerance
    }

    /// Count a period taken as a repeat.
    pub fn skip(&mut self) {
        self.skipped += 1;
    }
}
