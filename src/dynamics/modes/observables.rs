//! What a several-mode steady state reports: per mode, what a lock-in at the mode's
//! drive frequency reads and where its energy comes from and goes; in sum, the energy
//! the contact takes.

use super::orbit::{ModalOrbit, OrbitOptions, free_section};
use super::set::{Modal, ModeSet};
use super::system::{ModeIntegral, Modes, force_integral, plain_len, tangent_len};
use crate::dynamics::budget;
use crate::dynamics::setup::{Numerics, Prepared, TapSetup};
use crate::error::{Error, Result};
use crate::physics::law::ForceLaw;
use crate::physics::params::ELECTRONVOLT_J;
use serde::Serialize;

/// One mode's share of a steady state. Energies per first-mode drive period, in J.
#[derive(Debug, Clone, Serialize)]
pub struct ModeObservables {
    /// 1, 2, 3.
    pub mode: usize,
    /// Resonance (= drive) frequency as simulated, Hz (a higher mode's moved to the
    /// commensurate ratio).
    pub resonance_hz: f64,
    /// Drive frequency, Hz.
    pub drive_frequency_hz: f64,
    /// Modal stiffness kᵢ, N/m.
    pub stiffness_n_m: f64,
    /// Qᵢ.
    pub quality: f64,
    /// Free amplitude A₀ᵢ, m (0: not driven).
    pub free_amplitude_m: f64,
    /// Aᵢ: the amplitude of qᵢ at Ωᵢ over the common period (a lock-in's), m.
    pub amplitude_m: f64,
    /// Aᵢ/A₀ᵢ (null for a mode that is not driven).
    pub amplitude_ratio: Option<f64>,
    /// φᵢ: the phase lag of qᵢ ≈ Aᵢ cos(Ωᵢτ − φᵢ) behind the mode's drive, degrees
    /// (90° free at resonance).
    pub phase_deg: f64,
    /// The drive's work on the mode, ∮ Fᵢ cos ωᵢt q̇ᵢ dt.
    pub e_drive_j: f64,
    /// What the mode's damping takes, ∮ (mᵢωᵢ/Qᵢ) q̇ᵢ² dt.
    pub e_damp_j: f64,
    /// The work the tip–sample force does on the mode, Eᵢ = ∮ F_ts q̇ᵢ dt: negative
    /// where the mode gives energy to the contact, positive where it takes energy the
    /// contact passes on from another mode.
    pub e_exchange_j: f64,
    /// The mode's virial ⟨F_ts qᵢ⟩ over the common period, J.
    pub virial_j: f64,
    /// |E_drive + Eᵢ − E_damp| over the total drive energy: zero on a periodic orbit.
    pub energy_balance_rel: f64,
}

/// A steady state of several modes.
#[derive(Debug, Clone, Serialize)]
pub struct ModalObservables {
    /// The law.
    pub law: String,
    /// Tabor parameter.
    pub tabor_mu: f64,
    /// Rest separation z_c, m.
    pub separation_m: f64,
    /// The common period in first-mode drive periods.
    pub common_period_periods: u32,
    /// Each mode.
    pub modes: Vec<ModeObservables>,
    /// Energy the contact dissipates per first-mode drive period (from the law's
    /// branch work functions), J.
    pub e_ts_j: f64,
    /// The same in eV.
    pub e_ts_ev: f64,
    /// Its adhesion-hysteresis part, J.
    pub e_ts_adhesion_j: f64,
    /// Its capillary part, J.
    pub e_ts_capillary_j: f64,
    /// |Σ E_drive − Σ E_damp − E_ts| over Σ E_drive (E_ts from the work functions, not
    /// from the Eᵢ).
    pub energy_balance_rel: f64,
    /// ⟨F_ts⟩, N.
    pub mean_force_n: f64,
    /// The fraction of the period in contact.
    pub contact_fraction: f64,
    /// Jumps into contact per first-mode period.
    pub jumps_in: f64,
    /// The smallest separation at a step end or a switch, m (a bound, not located).
    pub min_separation_m: f64,
    /// Floquet multipliers of the orbit over the common period, [re, im].
    pub floquet_multipliers: Vec<[f64; 2]>,
    /// Whether all of them lie inside the unit circle.
    pub stable: bool,
    /// |P(z) − z| at the orbit, each mode's deflection over its free amplitude (its
    /// velocity over that times its frequency).
    pub return_distance_rel: f64,
    /// Common periods integrated to find it.
    pub periods_integrated: usize,
}

/// The modes of `set` on `setup` made ready: the prepared one-mode setup and the modal
/// model. Refuses a rate-dependent law (a viscous or relaxing sample: one mode only).
pub fn prepare(setup: &TapSetup, set: &ModeSet, numerics: &Numerics) -> Result<(Prepared, Modal)> {
    with_modes(Prepared::new(setup, numerics)?, set)
}

/// [`prepare`] from a setup already prepared for one mode.
pub fn with_modes(p: Prepared, set: &ModeSet) -> Result<(Prepared, Modal)> {
    if p.law.is_rate_dependent() {
        return Err(Error::NotApplicable(
            "several modes are simulated with rate-independent laws (hybrid, jkr, lj, dmt, \
             hertz, with or without a capillary neck); a viscous or relaxing sample is \
             simulated with one mode"
                .into(),
        ));
    }
    let modal = Modal::new(&p.setup.cantilever, set)?;
    Ok((p, modal))
}

/// The steady state of the modes at the prepared setup's separation, started from
/// `start` (a section state and its branch) or else from the one-mode steady state with
/// the higher modes' free oscillations on top.
pub fn modal_steady(
    p: &Prepared,
    modal: &Modal,
    numerics: &Numerics,
    start: Option<(&[f64], crate::physics::law::Branch)>,
) -> Result<(ModalObservables, ModalOrbit)> {
    budget::budgeted(numerics.max_steps, || match modal.modes.len() {
        1 => solve::<1, { plain_len(1) }, { tangent_len(1) }>(p, modal, numerics, start),
        2 => solve::<2, { plain_len(2) }, { tangent_len(2) }>(p, modal, numerics, start),
        3 => solve::<3, { plain_len(3) }, { tangent_len(3) }>(p, modal, numerics, start),
        n => Err(Error::OutOfRange(format!(
            "{n} modes: 1 to 3 are simulated"
        ))),
    })
}

fn solve<const M: usize, const P: usize, const T: usize>(
    p: &Prepared,
    modal: &Modal,
    numerics: &Numerics,
    start: Option<(&[f64], crate::physics::law::Branch)>,
) -> Result<(ModalObservables, ModalOrbit)> {
    let (q, period) = modal.common_period()?;
    let modes = Modes::<_, M>::of(p, modal);
    let (z, branch) = match start {
        Some((z, b)) => (z.to_vec(), b),
        None => one_mode_start(p, &modes.modes),
    };
    let opts = OrbitOptions {
        tolerance: numerics.tolerance,
        max_periods: (numerics.max_cycles / q as usize).max(10),
    };
    let orbit = modes.orbit::<P, T>(&z, branch, period, &opts)?;
    Ok((observe::<M>(p, modal, (q, period), &orbit), orbit))
}

/// Where the modes start without a given state: the one-mode steady state (if it has
/// one) with the higher modes' free oscillations on top.
pub(super) fn one_mode_start(
    p: &Prepared,
    modes: &[super::set::ModeModel],
) -> (Vec<f64>, crate::physics::law::Branch) {
    let sim = p.simulation();
    let mut phase = sim.free_steady_start();
    let first = sim
        .steady_state(&mut phase, &p.steady)
        .ok()
        .map(|_| (phase.x, phase.v));
    let branch = if first.is_some() {
        phase.branch
    } else {
        crate::physics::law::Branch::Free
    };
    (free_section(modes, first), branch)
}

fn observe<const M: usize>(
    p: &Prepared,
    modal: &Modal,
    (q, period): (u32, f64),
    orbit: &ModalOrbit,
) -> ModalObservables {
    let cant = &p.setup.cantilever;
    let contact = &p.setup.contact;
    let (k1, a0) = (cant.stiffness_n_m, cant.free_amplitude_m);
    let energy = k1 * a0 * a0;
    let periods = f64::from(q);
    let at = |i: usize, w: ModeIntegral| orbit.integrals[super::system::integral(M, i, w) - 2 * M];
    let drives: Vec<f64> = (0..M)
        .map(|i| modal.modes[i].drive * at(i, ModeIntegral::Drive))
        .collect();
    let damps: Vec<f64> = (0..M)
        .map(|i| modal.modes[i].damping / modal.modes[i].gain * at(i, ModeIntegral::Damping))
        .collect();
    let total_drive: f64 = drives.iter().sum();
    let modes = (0..M)
        .map(|i| {
            let m = &modal.modes[i];
            let (c, s) = (at(i, ModeIntegral::Cos), at(i, ModeIntegral::Sin));
            let amp = 2.0 / period * c.hypot(s);
            let exchange = at(i, ModeIntegral::Exchange);
            let free = m.free_amplitude();
            let (resonance_hz, stiffness, quality) = modal.in_si(cant, i);
            ModeObservables {
                mode: i + 1,
                resonance_hz,
                drive_frequency_hz: cant.resonance_hz * m.omega,
                stiffness_n_m: stiffness,
                quality,
                free_amplitude_m: free * a0,
                amplitude_m: amp * a0,
                amplitude_ratio: (free > 0.0).then(|| amp / free),
                phase_deg: s.atan2(c).to_degrees(),
                e_drive_j: drives[i] / periods * energy,
                e_damp_j: damps[i] / periods * energy,
                e_exchange_j: exchange / periods * energy,
                virial_j: at(i, ModeIntegral::Virial) / period * energy,
                energy_balance_rel: (drives[i] + exchange - damps[i]).abs() / total_drive.abs(),
            }
        })
        .collect();
    // E_ts from the work functions: −∮ f dx = (f_scale/a₁) Σ ΔŴ.
    // The loop closed: the orbit returns to within its tolerance, and the work function
    // between where the pass ended and where it started is that tolerance's, not the
    // contact's.
    let to_energy = p.cpl.f_scale / p.cpl.a1;
    let (first, last) = orbit.tally.alpha_hat_ends;
    let law = &p.law;
    let e_ts = to_energy
        * (orbit.tally.work_hat
            - (law.work_hat(last, orbit.branch) - law.work_hat(first, orbit.branch)));
    let capillary = to_energy
        * (orbit.tally.capillary_work_hat
            - (law.capillary_work_hat(last, orbit.branch)
                - law.capillary_work_hat(first, orbit.branch)));
    let total_damp: f64 = damps.iter().sum();
    // A loop of work-function differences that cancels (a conservative law's) leaves
    // round-off of the values summed, not a dissipation.
    let (adhesion, capillary) = resolved_dissipation(
        e_ts,
        capillary,
        total_drive.abs() + to_energy * orbit.tally.work_scale_hat,
    );
    let e_ts_j = (adhesion + capillary) / periods * energy;
    let scale = contact.separation_scale_m();
    ModalObservables {
        law: p.setup.law.to_string(),
        tabor_mu: contact.tabor_mu(),
        separation_m: p.cpl.a0 * scale,
        common_period_periods: q,
        modes,
        e_ts_j,
        e_ts_ev: e_ts_j / ELECTRONVOLT_J,
        e_ts_adhesion_j: adhesion / periods * energy,
        e_ts_capillary_j: capillary / periods * energy,
        energy_balance_rel: (total_drive - total_damp - e_ts).abs() / total_drive.abs(),
        mean_force_n: orbit.integrals[force_integral(M) - 2 * M] / period * k1 * a0,
        contact_fraction: orbit.tally.contact_time / period,
        jumps_in: f64::from(orbit.tally.jumps_in) / periods,
        min_separation_m: p.cpl.alpha_hat(orbit.tally.min_tip, 0.0) * scale,
        stable: orbit.stable(),
        floquet_multipliers: orbit.multipliers.clone(),
        return_distance_rel: orbit.residual,
        periods_integrated: orbit.periods_integrated,
    }
}

/// The contact's dissipation split into its adhesion-hysteresis and capillary parts
/// (units of k₁A₀₁² or J alike), each 0 where it is within 1e-12 of `scale` (the sums it
/// came from: a conservative law's work functions cancel to their round-off, not to a
/// dissipation).
pub(super) fn resolved_dissipation(total: f64, capillary: f64, scale: f64) -> (f64, f64) {
    let floor = 1e-12 * scale;
    let resolved = |e: f64| if e.abs() <= floor { 0.0 } else { e };
    (resolved(total - capillary), resolved(capillary))
}

/// The steady state of `set`'s modes on `setup` (Rodríguez & García's bimodal
/// tapping, APL 84, 449, 2004, with tapsim's force laws).
pub fn tap_modes(setup: &TapSetup, set: &ModeSet, numerics: &Numerics) -> Result<ModalObservables> {
    let (p, modal) = prepare(setup, set, numerics)?;
    Ok(modal_steady(&p, &modal, numerics, None)?.0)
}
