//! The instrument on several eigenmodes (bimodal AFM as Rodríguez & García run it,
//! APL 84, 449, 2004): each mode driven at its own frequency and read by its own
//! lock-in there (the same filter for all), the z feedback holding the first mode's
//! amplitude at the setpoint, and a line scanned as with one mode ([`super::scan`]).
//!
//! The modes are marched with the steady-state solver's equations and switch handling
//! ([`crate::dynamics::modes::system`]), one first-mode drive period at a time, τ taken
//! back by the common period each time one ends (every drive's phase is the same
//! there); drives with no common period are marched as they are, τ never taken back. Each lock-in reads its own mode's deflection qᵢ — what `tap --modes` reports
//! as Aᵢ, φᵢ; a photodiode's lock-in reads the tip's Σqⱼ, which also holds the other
//! modes' motion at Ωᵢ. No thermal force: the thermal instrument is the point mass's.

use super::lockin::{LockIn, LockIns};
use super::probe::{Probe, Readings, settling_periods};
use crate::dynamics::model::State;
use crate::dynamics::modes::MAX_MODES;
use crate::dynamics::modes::orbit::free_section;
use crate::dynamics::modes::set::Modal;
use crate::dynamics::modes::system::{Modes, plain_len};
use crate::dynamics::setup::Prepared;
use crate::error::{Error, Result};
use crate::physics::law::Branch;

/// Several eigenmodes over `materials` (each prepared with its modal model; all share
/// the cantilever and its modes), each read by its lock-in.
pub struct ModalProbe<'a> {
    materials: &'a [(Prepared, Modal)],
    lockins: Vec<LockIn>,
    /// Each mode's (qᵢ, qᵢ′).
    section: [f64; 2 * MAX_MODES],
    branch: Branch,
    /// The first-mode drive period the next march starts with, within the common period
    /// (counted on where the drives have none: τ is then not taken back).
    period_index: u32,
}

impl<'a> ModalProbe<'a> {
    /// The modes of `materials` (at least one) oscillating freely, read by lock-ins of
    /// filter order `order` and time constant `time_constant_hat` (τ = ω₁t) each at its
    /// mode's drive frequency. Refuses a higher mode that is not driven (its lock-in has
    /// no reference) and materials whose modes differ.
    pub fn new(
        materials: &'a [(Prepared, Modal)],
        order: usize,
        time_constant_hat: f64,
    ) -> Result<Self> {
        let Some((_, modal)) = materials.first() else {
            return Err(Error::NotApplicable("a probe needs a material".into()));
        };
        if materials.iter().any(|(_, m)| m != modal) {
            return Err(Error::NotApplicable(
                "the materials of a scan share one cantilever and its modes".into(),
            ));
        }
        if let Some(k) = modal.modes.iter().position(|m| m.drive == 0.0) {
            return Err(Error::NotApplicable(format!(
                "mode {} is not driven: a scan reads every mode with a lock-in at its drive \
                 frequency (give it a free amplitude)",
                k + 1
            )));
        }
        // Each lock-in reads the deflection, the sum of the modes, at its mode's drive.
        let count = modal.modes.len();
        let lockins = modal
            .modes
            .iter()
            .map(|m| Ok(LockIn::new(order, time_constant_hat, m.omega)?.summing(count)))
            .collect::<Result<Vec<_>>>()?;
        let mut section = [0.0; 2 * MAX_MODES];
        let free = free_section(&modal.modes, None);
        section[..free.len()].copy_from_slice(&free);
        Ok(Self {
            materials,
            lockins,
            section,
            branch: Branch::Free,
            period_index: 0,
        })
    }

    /// March `periods` first-mode drive periods of `M` modes (`P` = [`plain_len`]`(M)`).
    fn march_modes<const M: usize, const P: usize>(
        &mut self,
        material: usize,
        separation_m: f64,
        periods: usize,
    ) -> Result<()> {
        let (p, modal) = &self.materials[material];
        let mut modes = Modes::<_, M>::of(p, modal);
        modes.cpl = p.simulation_at(separation_m)?.cpl;
        let period = modal.march_period();
        for _ in 0..periods {
            let k = self.period_index;
            let mut y = State::<P>::zeros();
            y.as_mut_slice()[..2 * M].copy_from_slice(&self.section[..2 * M]);
            let (y, branch, _) = modes.pass_observed(
                f64::from(k) * period,
                y,
                self.branch,
                f64::from(k + 1) * period,
                &mut LockIns(&mut self.lockins),
            )?;
            self.section[..2 * M].copy_from_slice(&y.as_slice()[..2 * M]);
            self.branch = branch;
            self.period_index = modal.periods.map_or(k + 1, |q| (k + 1) % q);
        }
        Ok(())
    }
}

impl Probe for ModalProbe<'_> {
    fn modes(&self) -> usize {
        self.lockins.len()
    }

    fn materials(&self) -> usize {
        self.materials.len()
    }

    fn free_amplitude_m(&self) -> f64 {
        self.materials[0].0.setup.cantilever.free_amplitude_m
    }

    fn settling_periods(&self) -> usize {
        let modal = &self.materials[0].1;
        settling_periods(&self.lockins[0], modal.march_period())
    }

    fn march(&mut self, material: usize, separation_m: f64, periods: usize) -> Result<Readings> {
        match self.lockins.len() {
            1 => self.march_modes::<1, { plain_len(1) }>(material, separation_m, periods)?,
            2 => self.march_modes::<2, { plain_len(2) }>(material, separation_m, periods)?,
            _ => self.march_modes::<3, { plain_len(3) }>(material, separation_m, periods)?,
        }
        let mut out = [(0.0, 0.0); MAX_MODES];
        let modal = &self.materials[0].1;
        for ((o, l), m) in out.iter_mut().zip(&self.lockins).zip(&modal.modes) {
            *o = (l.amplitude() / m.free_amplitude(), l.phase_deg());
        }
        Ok(out)
    }

    fn loop_state(&self) -> Option<impl Iterator<Item = f64> + '_> {
        // Without a common period the motion never repeats.
        self.materials[0].1.periods?;
        let modes = self.lockins.len();
        Some(
            self.section[..2 * modes]
                .iter()
                .copied()
                .chain(self.lockins.iter().flat_map(LockIn::state)),
        )
    }

    fn cycle(&self) -> usize {
        self.materials[0].1.periods.map_or(1, |q| q as usize)
    }
}
