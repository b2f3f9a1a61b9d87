//! The cantilever as the z feedback sees it: marched one drive period (of the first
//! mode) at a time over a material at the rest separation the piezo sets, read by its
//! lock-ins after each period. The loop ([`super::feedback`]) and the scan
//! ([`super::scan`]) run any probe: the point mass under a thermal force ([`OneMode`])
//! or several eigenmodes ([`super::modal::ModalProbe`]).

use super::lockin::LockIn;
use super::repeats::{LoopState, Repeats, STATE_LEN};
use super::thermal::ThermalForce;
use crate::dynamics::march::Phase;
use crate::dynamics::modes::MAX_MODES;
use crate::dynamics::setup::Prepared;
use crate::error::Result;

/// What the lock-ins read after a period: each mode's amplitude over its free amplitude
/// and its phase lag in degrees, the first mode's first (entries past
/// [`Probe::modes`] unused).
pub type Readings = [(f64, f64); MAX_MODES];

/// A cantilever with its lock-ins, as the loop runs it.
pub trait Probe {
    /// The modes read (1: the point mass).
    fn modes(&self) -> usize;
    /// The materials it can be marched over.
    fn materials(&self) -> usize;
    /// The first mode's free amplitude A₀, in m: the unit of the loop's moves.
    fn free_amplitude_m(&self) -> f64;
    /// Drive periods after which the lock-ins' step response is within 1e-4 of 1
    /// (12 + 3n time constants, n the filter order).
    fn settling_periods(&self) -> usize;
    /// March `periods` drive periods of the first mode over material `material` at rest
    /// separation `separation_m`; the lock-ins' readings after the last.
    fn march(&mut self, material: usize, separation_m: f64, periods: usize) -> Result<Readings>;
    /// Its state after the last march, in units of A₀; none (the default) where periods
    /// must all be marched (a random force, drives with no common period). What
    /// [`Repeats`] watches.
    fn loop_state(&self) -> Option<impl Iterator<Item = f64> + '_> {
        None::<std::iter::Empty<f64>>
    }
    /// Drive periods after which its motion can repeat: 1, or the common period of
    /// several modes' drives.
    fn cycle(&self) -> usize {
        1
    }
    /// Show `repeats` the loop's state after a marched period: this probe's
    /// ([`Probe::loop_state`]), then `rest` (the piezo over A₀ and the controller's last
    /// error); whether the loop now repeats itself ([`Repeats::settled`]).
    fn repeats_itself(&self, repeats: &mut Repeats, rest: [f64; 2]) -> bool {
        let state = self.loop_state().map(|parts| {
            let mut state: LoopState = [0.0; STATE_LEN];
            for (o, v) in state.iter_mut().zip(parts.chain(rest)) {
                *o = v;
            }
            state
        });
        repeats.settled(state.as_ref(), self.cycle())
    }
}

/// Drive periods (of period `period_hat`) a lock-in needs to settle
/// ([`Probe::settling_periods`]).
pub fn settling_periods(lockin: &LockIn, period_hat: f64) -> usize {
    ((12.0 + 3.0 * lockin.order() as f64) * lockin.time_constant_hat() / period_hat).ceil() as usize
}

/// The point-mass cantilever (tapsim's one mode) over `materials`, from the state
/// `phase`, read by `lockin`, shaken by `force` ([`ThermalForce::none`] for none).
pub struct OneMode<'a> {
    /// The materials (each its prepared simulation; all share the cantilever).
    pub materials: &'a [Prepared],
    /// Where the oscillator is.
    pub phase: &'a mut Phase,
    /// The lock-in.
    pub lockin: &'a mut LockIn,
    /// The thermal force.
    pub force: &'a mut ThermalForce,
}

impl Probe for OneMode<'_> {
    fn modes(&self) -> usize {
        1
    }

    fn materials(&self) -> usize {
        self.materials.len()
    }

    fn free_amplitude_m(&self) -> f64 {
        self.materials[0].setup.cantilever.free_amplitude_m
    }

    fn settling_periods(&self) -> usize {
        settling_periods(self.lockin, self.materials[0].simulation().osc.period())
    }

    fn march(&mut self, material: usize, separation_m: f64, periods: usize) -> Result<Readings> {
        let sim = self.materials[material].simulation_at(separation_m)?;
        self.force.march(&sim, self.phase, periods, self.lockin)?;
        let mut out = [(0.0, 0.0); MAX_MODES];
        // The deflection is in units of A₀: the amplitude read is A/A₀.
        out[0] = (self.lockin.amplitude(), self.lockin.phase_deg());
        Ok(out)
    }

    fn loop_state(&self) -> Option<impl Iterator<Item = f64> + '_> {
        if self.force.intensity_hat() > 0.0 {
            return None;
        }
        let p = &*self.phase;
        Some([p.x, p.v].into_iter().chain(self.lockin.state()))
    }
}
