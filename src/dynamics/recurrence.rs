//! The last states at the drive phase, kept to see after how many periods the motion
//! repeats: the periods worth looking for an orbit of.

use super::model::SECTION_DIM;
use super::motion::{MAX_PERIOD, SHORT_PERIOD};
use crate::physics::law::Branch;
use nalgebra::DVector;

/// How close (units of L) the section state must return after n > [`SHORT_PERIOD`]
/// periods, three periods running, for a period-n orbit to be looked for.
const LOCK_GAP: f64 = 1e-5;

/// The last states at the drive phase, to see after how many periods they repeat.
#[derive(Default)]
pub(super) struct Recurrence {
    /// (section state, branch), newest last; at most 3 + [`MAX_PERIOD`].
    states: std::collections::VecDeque<([f64; SECTION_DIM], Branch)>,
    /// Long periods already looked for, with the return distance then
    /// ([`Recurrence::locked`]).
    tried: Vec<(usize, f64)>,
}

impl Recurrence {
    const KEEP: usize = MAX_PERIOD + 3;

    pub(super) fn push(&mut self, z: DVector<f64>, branch: Branch) {
        if self.states.len() == Self::KEEP {
            self.states.pop_front();
        }
        let mut a = [0.0; SECTION_DIM];
        a[..z.len()].copy_from_slice(z.as_slice());
        self.states.push_back((a, branch));
    }

    /// Distance between the state `back` places from the newest and the one n before it.
    pub(super) fn gap(&self, back: usize, n: usize) -> Option<f64> {
        let len = self.states.len();
        let (a, b) = (
            self.states.get(len.checked_sub(1 + back)?)?,
            self.states.get(len.checked_sub(1 + back + n)?)?,
        );
        (a.1 == b.1).then(|| {
            a.0.iter()
                .zip(&b.0)
                .fold(0.0, |m: f64, (x, y)| m.max((x - y).abs()))
        })
    }

    /// Whether the return distance after n periods has been within `within` for the
    /// last three periods.
    pub(super) fn returns_within(&self, n: usize, within: f64) -> bool {
        (0..3).all(|back| self.gap(back, n).is_some_and(|g| g <= within))
    }

    /// The least n ≤ [`SHORT_PERIOD`] whose return distance has been within `within(n)`
    /// for the last three periods.
    pub(super) fn repeats(&self, within: impl Fn(usize) -> f64) -> Option<usize> {
        (1..=SHORT_PERIOD).find(|&n| self.returns_within(n, within(n)))
    }

    /// Periods worth a Newton search: those up to [`SHORT_PERIOD`] the newest state
    /// nearly returns with (within 0.1 in x and x'), the nearest returns first, at most
    /// three; a multiple of a period already listed is left out (its orbit would be
    /// found as the shorter one).
    pub(super) fn candidates(&self) -> Vec<usize> {
        let mut near: Vec<(f64, usize)> = (1..=SHORT_PERIOD)
            .filter_map(|n| self.gap(0, n).filter(|&g| g <= 0.1).map(|g| (g, n)))
            .collect();
        near.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut out: Vec<usize> = Vec::with_capacity(3);
        for (_, n) in near {
            if out.len() < 3 && !out.iter().any(|&m| n % m == 0) {
                out.push(n);
            }
        }
        out
    }

    /// The least long period n (above [`SHORT_PERIOD`], at most [`MAX_PERIOD`]) the
    /// motion has returned with within [`LOCK_GAP`] three periods running, unless it was
    /// looked for already and the motion has not come 100× closer since (it is marked
    /// with its return distance).
    pub(super) fn locked(&mut self) -> Option<usize> {
        let (n, gap) = (SHORT_PERIOD + 1..=MAX_PERIOD).find_map(|n| {
            let gap = self.gap(0, n)?;
            let fresh = self
                .tried
                .iter()
                .all(|&(m, then)| m != n || gap < 1e-2 * then);
            (fresh && self.returns_within(n, LOCK_GAP)).then_some((n, gap))
        })?;
        self.tried.retain(|&(m, _)| m != n);
        self.tried.push((n, gap));
        Some(n)
    }
}
