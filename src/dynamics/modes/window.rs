//! Modes whose drives have no common period (no pᵢ/q with q ≤ 32 within the
//! tolerance, or a tolerance of 0 and ratios that are not exactly rational): the motion
//! is not periodic — quasi-periodic on a torus, or irregular — and what a lock-in reads
//! is a time average. The modes are marched with the steady-state solver's equations and
//! switch handling ([`super::system`]) from the one-mode steady state with the higher
//! modes' free motion on top, for twenty memories (the slowest mode's amplitude
//! relaxation time 2Qᵢ/ωᵢ) to settle; then each mode's integrals are taken over whole
//! numbers of its **own** drive periods (so its projection on its drive holds no leak of
//! its own line) and averaged over eight consecutive windows, each period weighted
//! by a smooth bump across its window (a weighted Birkhoff average: on a quasi-periodic
//! orbit it converges faster than any power of the window's length, where a plain mean's
//! error falls only as 1/length — slow beats of the drives, such as 15f₂ − 94f₁ ≈
//! 0.003f₁ on a beam, make that error large). The standard errors are the windows'
//! scatter over √8; the windows double in length until every driven mode's Aᵢ
//! (relative) and φᵢ (rad) and E_ts (relative to the drives' work) are within the
//! average tolerance, or the cycle budget is spent (then not converged, and said).

use super::observables::{one_mode_start, resolved_dissipation};
use super::set::Modal;
use super::system::{ModeIntegral, Modes, force_integral, integral, plain_len};
use crate::dynamics::budget;
use crate::dynamics::model::State;
use crate::dynamics::numeric::Ignore;
use crate::dynamics::setup::{Numerics, Prepared};
use crate::error::{Error, Result};
use crate::numeric::{mean_and_variance, wrap_angle};
use crate::physics::law::ForceLaw;
use crate::physics::params::ELECTRONVOLT_J;
use serde::Serialize;

/// Windows of a round.
const WINDOWS: usize = 8;

/// Memories (the slowest mode's amplitude relaxation time) marched before the first
/// round: a start's transient decays to e⁻²⁰ ≈ 2e-9 of itself (a higher mode starts
/// at its free phase, 90°, some 60° from where the contact takes it; a transient that
/// decays slower than the modes' own damping shows up as a drift and lengthens the
/// windows).
const SETTLE_MEMORIES: f64 = 20.0;

/// One mode's time averages, each with the standard error of its batch means. Energies
/// per first-mode drive period, in J.
#[derive(Debug, Clone, Serialize)]
pub struct WindowedMode {
    /// 1, 2, 3.
    pub mode: usize,
    /// Resonance (= drive) frequency, Hz (as given: no common period to move it to).
    pub resonance_hz: f64,
    /// Drive frequency, Hz.
    pub drive_frequency_hz: f64,
    /// Modal stiffness kᵢ, N/m.
    pub stiffness_n_m: f64,
    /// Qᵢ.
    pub quality: f64,
    /// Free amplitude A₀ᵢ, m (0: not driven).
    pub free_amplitude_m: f64,
    /// Aᵢ: the amplitude of qᵢ at Ωᵢ over the window (a lock-in's), m.
    pub amplitude_m: f64,
    /// Its standard error (of the batch means; 0 where they agree to within 1e-9 of
    /// the value: round-off), m. So are the other standard errors.
    pub amplitude_std_err_m: f64,
    /// Aᵢ/A₀ᵢ (null for a mode that is not driven).
    pub amplitude_ratio: Option<f64>,
    /// Its standard error.
    pub amplitude_ratio_std_err: Option<f64>,
    /// φᵢ, the lag of qᵢ behind the mode's drive, degrees.
    pub phase_deg: f64,
    /// Its standard error, degrees.
    pub phase_std_err_deg: f64,
    /// The drive's work on the mode.
    pub e_drive_j: f64,
    /// What the mode's damping takes.
    pub e_damp_j: f64,
    /// The work the tip–sample force does on the mode, Eᵢ = ∫F_ts q̇ᵢ dt.
    pub e_exchange_j: f64,
    /// Its standard error.
    pub e_exchange_std_err_j: f64,
    /// The mode's virial ⟨F_ts qᵢ⟩, J.
    pub virial_j: f64,
    /// First-mode drive periods its windows span (whole periods of its own).
    pub periods_averaged: f64,
}

/// Several modes without a common period: averages over a window.
#[derive(Debug, Clone, Serialize)]
pub struct WindowedModes {
    /// The law.
    pub law: String,
    /// Tabor parameter.
    pub tabor_mu: f64,
    /// Rest separation z_c, m.
    pub separation_m: f64,
    /// What the numbers are.
    pub motion: &'static str,
    /// Each mode.
    pub modes: Vec<WindowedMode>,
    /// Energy the contact dissipates per first-mode drive period (the law's work
    /// functions over the window, the contact's stored energy at its ends taken off), J.
    pub e_ts_j: f64,
    /// Its standard error, J.
    pub e_ts_std_err_j: f64,
    /// E_ts in eV.
    pub e_ts_ev: f64,
    /// Its adhesion-hysteresis part, J.
    pub e_ts_adhesion_j: f64,
    /// Its capillary part, J.
    pub e_ts_capillary_j: f64,
    /// |Σ E_drive − Σ E_damp − E_ts| over Σ E_drive: what the modes' stored energy
    /// changed by over the windows (their ends are not the same state), not zero.
    pub energy_balance_rel: f64,
    /// ⟨F_ts⟩, N.
    pub mean_force_n: f64,
    /// The fraction of the time in contact.
    pub contact_fraction: f64,
    /// Jumps into contact per first-mode period.
    pub jumps_in: f64,
    /// The smallest separation at a step end or a switch, m (a bound, not located).
    pub min_separation_m: f64,
    /// Windows averaged (each a weighted average; their scatter gives the errors).
    pub windows: usize,
    /// First-mode periods a window spans.
    pub window_periods: u64,
    /// First-mode periods averaged over (all windows).
    pub periods_averaged: f64,
    /// First-mode periods integrated in all (the settling and shorter windows before
    /// included).
    pub periods_integrated: f64,
    /// Whether every standard error is below the average tolerance (else the budget
    /// ran out first).
    pub converged: bool,
}

/// The weight of a weighted Birkhoff average at t ∈ (0, 1): the bump exp(−1/(t(1 − t)))
/// (Das, Sander, Saiki & Yorke, Nonlinearity 30, 4111, 2017: with it a time average over
/// a quasi-periodic orbit converges faster than any power of the window's length, where
/// the plain average's error falls as 1/length).
fn bump(t: f64) -> f64 {
    if t <= 0.0 || t >= 1.0 {
        0.0
    } else {
        (-1.0 / (t * (1.0 - t))).exp()
    }
}

/// A mode's integrals (the [`ModeIntegral`]s) over its own periods, each period's
/// weighted by the window's bump; `weight` is the sum of the weights.
#[derive(Debug, Clone, Copy, Default)]
struct ModeSums {
    weight: f64,
    values: [f64; 6],
}

impl ModeSums {
    fn add(&mut self, w: f64, period: &[f64; 6]) {
        self.weight += w;
        for (v, p) in self.values.iter_mut().zip(period) {
            *v += w * p;
        }
    }

    fn then(&self, next: &Self) -> Self {
        Self {
            weight: self.weight + next.weight,
            values: std::array::from_fn(|k| self.values[k] + next.values[k]),
        }
    }

    /// The weighted mean of integral `which` per τ (the mode's own period `period`).
    fn rate(&self, which: ModeIntegral, period: f64) -> f64 {
        self.values[which as usize] / (self.weight * period)
    }

    /// Aᵢ (units of A₀₁).
    fn amplitude(&self, period: f64) -> f64 {
        2.0 * self
            .rate(ModeIntegral::Cos, period)
            .hypot(self.rate(ModeIntegral::Sin, period))
    }

    /// φᵢ (rad).
    fn phase(&self) -> f64 {
        self.values[ModeIntegral::Sin as usize].atan2(self.values[ModeIntegral::Cos as usize])
    }
}

/// The contact over first-mode periods, each weighted as [`ModeSums`].
#[derive(Debug, Clone, Copy)]
struct ContactSums {
    weight: f64,
    /// ∫ f dτ.
    force: f64,
    /// Dissipation, the law's units (Σ ΔŴ less the stored Ŵ's change over the period).
    dissipated_hat: f64,
    /// Its capillary part.
    capillary_hat: f64,
    /// Σ |Ŵ| at the segments' ends.
    work_scale_hat: f64,
    contact_time: f64,
    jumps_in: f64,
    /// Drive work less damping, all modes (units of k₁A₀₁²).
    drive_less_damp: f64,
    /// Unweighted: the smallest tip deflection.
    min_tip: f64,
}

impl ContactSums {
    fn empty() -> Self {
        Self {
            weight: 0.0,
            force: 0.0,
            dissipated_hat: 0.0,
            capillary_hat: 0.0,
            work_scale_hat: 0.0,
            contact_time: 0.0,
            jumps_in: 0.0,
            drive_less_damp: 0.0,
            min_tip: f64::INFINITY,
        }
    }

    fn add(&mut self, w: f64, p: &Self) {
        self.weight += w;
        self.force += w * p.force;
        self.dissipated_hat += w * p.dissipated_hat;
        self.capillary_hat += w * p.capillary_hat;
        self.work_scale_hat += w * p.work_scale_hat;
        self.contact_time += w * p.contact_time;
        self.jumps_in += w * p.jumps_in;
        self.drive_less_damp += w * p.drive_less_damp;
        self.min_tip = self.min_tip.min(p.min_tip);
    }

    fn then(&self, next: &Self) -> Self {
        let mut s = *self;
        s.add(1.0, next);
        s.weight = self.weight + next.weight;
        s
    }
}

/// Averages of the modes of `modal` on the prepared setup over windows (the module's
/// method), whether or not their drives have a common period.
pub fn modal_windowed(p: &Prepared, modal: &Modal, numerics: &Numerics) -> Result<WindowedModes> {
    // Averages integrate thousands of periods where a steady state's search integrates
    // hundreds: four work budgets.
    budget::budgeted(numerics.max_steps.saturating_mul(4), || {
        match modal.modes.len() {
            1 => average::<1, { plain_len(1) }>(p, modal, numerics),
            2 => average::<2, { plain_len(2) }>(p, modal, numerics),
            3 => average::<3, { plain_len(3) }>(p, modal, numerics),
            n => Err(Error::OutOfRange(format!(
                "{n} modes: 1 to 3 are simulated"
            ))),
        }
    })
}

/// The windows of a round being gathered: each mode's own periods (the first mode's
/// also for the contact), `per_window[i]` of them a window, [`WINDOWS`] windows.
struct Round<const M: usize> {
    per_window: [u64; M],
    /// Own periods of the round so far, each mode (beyond WINDOWS windows: ignored
    /// until the others have theirs).
    done: [u64; M],
    current: [ModeSums; M],
    windows: [Vec<ModeSums>; M],
    contact: ContactSums,
    contacts: Vec<ContactSums>,
}

impl<const M: usize> Round<M> {
    fn new(length: f64, own: &[f64; M]) -> Self {
        Self {
            per_window: std::array::from_fn(|i| ((length / own[i]).round() as u64).max(1)),
            done: [0; M],
            current: [ModeSums::default(); M],
            windows: std::array::from_fn(|_| Vec::with_capacity(WINDOWS)),
            contact: ContactSums::empty(),
            contacts: Vec::with_capacity(WINDOWS),
        }
    }

    fn complete(&self) -> bool {
        self.windows.iter().all(|w| w.len() == WINDOWS) && self.contacts.len() == WINDOWS
    }

    /// Mode i's own period ended with its integrals `period` (and, for the first
    /// mode, the contact's `contact`).
    fn period_ended(&mut self, i: usize, period: &[f64; 6], contact: Option<&ContactSums>) {
        if self.windows[i].len() == WINDOWS {
            return;
        }
        let n = self.per_window[i];
        let k = self.done[i] % n;
        let w = bump((k as f64 + 0.5) / n as f64);
        self.current[i].add(w, period);
        if let Some(c) = contact {
            self.contact.add(w, c);
        }
        self.done[i] += 1;
        if k + 1 == n {
            self.windows[i].push(std::mem::take(&mut self.current[i]));
            if contact.is_some() {
                self.contacts
                    .push(std::mem::replace(&mut self.contact, ContactSums::empty()));
            }
        }
    }
}

fn average<const M: usize, const P: usize>(
    p: &Prepared,
    modal: &Modal,
    numerics: &Numerics,
) -> Result<WindowedModes> {
    let modes = Modes::<_, M>::of(p, modal);
    let (z, mut branch) = one_mode_start(p, &modes.modes);
    let mut y = State::<P>::zeros();
    y.as_mut_slice()[..2 * M].copy_from_slice(&z);
    let own: [f64; M] = std::array::from_fn(|i| modal.own_period(i));
    // The slowest mode's memory, 2Qᵢ/rᵢ in τ.
    let memory = modes
        .modes
        .iter()
        .map(|m| 2.0 / m.damping)
        .fold(own[0], f64::max);
    let budget_tau = numerics.max_cycles as f64 * own[0];
    let settle = SETTLE_MEMORIES * memory;
    if settle + WINDOWS as f64 * memory > budget_tau {
        return Err(Error::NotApplicable(format!(
            "the modes remember their start for {:.0} first-mode periods (2Q/ω of the \
             slowest): settling and averaging over them needs more than the budget of {} \
             periods",
            memory / own[0],
            numerics.max_cycles
        )));
    }
    let law = &p.law;
    let alpha = |x: f64| p.cpl.alpha_hat(x, 0.0);
    let to_energy = p.cpl.f_scale / p.cpl.a1;
    let tolerance = numerics.average_tolerance;
    // Each mode's integrals over its own period so far, and the first mode's contact.
    let mut period = [[0.0; 6]; M];
    let mut contact = ContactSums::empty();
    let mut contact_start = (
        alpha(Modes::<crate::physics::law::AnyLaw, M>::tip(&y)),
        branch,
    );
    let mut ended = [0u64; M];
    let (mut tau, mut h) = (0.0, 0.0);
    let mut length = memory;
    let mut round: Option<Round<M>> = None;
    let mut fallback = None;
    loop {
        // To the next end of some mode's own period.
        let next = (0..M)
            .map(|i| (ended[i] + 1) as f64 * own[i])
            .fold(f64::INFINITY, f64::min);
        y.as_mut_slice()[2 * M..].iter_mut().for_each(|c| *c = 0.0);
        let (end, end_branch, tally) =
            match modes.pass_stepped(tau, y, branch, next, &mut Ignore, &mut h) {
                Ok(pass) => pass,
                // The work budget spent after a round that did not meet the tolerance:
                // that round, not converged.
                Err(_) if budget::left() == 0 && fallback.is_some() => {
                    return Ok(fallback.expect("a round"));
                }
                Err(e) => return Err(e),
            };
        let integrals = &end.as_slice()[2 * M..];
        for (i, acc) in period.iter_mut().enumerate() {
            let m = &modes.modes[i];
            let base = integral(M, i, ModeIntegral::Damping) - 2 * M;
            for (k, a) in acc.iter_mut().enumerate() {
                *a += integrals[base + k];
            }
            contact.drive_less_damp += m.drive * integrals[base + ModeIntegral::Drive as usize]
                - m.damping / m.gain * integrals[base + ModeIntegral::Damping as usize];
        }
        contact.force += integrals[force_integral(M) - 2 * M];
        contact.dissipated_hat += tally.work_hat;
        contact.capillary_hat += tally.capillary_work_hat;
        contact.work_scale_hat += tally.work_scale_hat;
        contact.contact_time += tally.contact_time;
        contact.jumps_in += f64::from(tally.jumps_in);
        contact.min_tip = contact.min_tip.min(tally.min_tip);
        (tau, y, branch) = (next, end, end_branch);
        if round.is_none() && tau >= settle {
            round = Some(Round::new(length, &own));
        }
        for i in 0..M {
            if (ended[i] + 1) as f64 * own[i] != next {
                continue;
            }
            ended[i] += 1;
            let done = std::mem::take(&mut period[i]);
            let mut closed = None;
            if i == 0 {
                // The contact's period: its work functions less what it stores at the
                // ends (each on its own branch).
                let (a0, b0) = contact_start;
                let a1 = tally.alpha_hat_ends.1;
                let mut c = std::mem::replace(&mut contact, ContactSums::empty());
                c.dissipated_hat -= law.work_hat(a1, branch) - law.work_hat(a0, b0);
                c.capillary_hat -=
                    law.capillary_work_hat(a1, branch) - law.capillary_work_hat(a0, b0);
                contact_start = (a1, branch);
                closed = Some(c);
            }
            if let Some(r) = round.as_mut() {
                r.period_ended(i, &done, closed.as_ref());
            }
        }
        let Some(r) = round.as_ref() else { continue };
        let out_of_budget = tau >= budget_tau;
        if !r.complete() && !out_of_budget {
            continue;
        }
        if r.contacts.len() < 2 || r.windows.iter().any(|w| w.len() < 2) {
            return Err(Error::Numerical(format!(
                "the budget of {} first-mode periods ran out before two windows of \
                 {:.0} periods each were averaged",
                numerics.max_cycles,
                length / own[0]
            )));
        }
        let stats = Statistics::of(r, &own, to_energy);
        let met = stats.within(&modes.modes, &own, tolerance);
        if met || out_of_budget {
            return Ok(report::<M>(p, modal, r, &stats, tau, met));
        }
        // What is reported if the work budget runs out before the next round ends.
        fallback = Some(report::<M>(p, modal, r, &stats, tau, false));
        length *= 2.0;
        round = Some(Round::new(length, &own));
    }
}

/// What the windows' values of one quantity say of their mean's error.
#[derive(Debug, Clone, Copy)]
struct Spread {
    /// The standard error of the mean, or half the drift if that is larger.
    error: f64,
    /// Whether the first half of the windows and the second differ by more than twice
    /// their difference's standard error (and by more than 1e-9 of the scale, round-off):
    /// a transient not yet gone.
    drifts: bool,
}

impl Spread {
    fn of(values: &[f64], scale: f64) -> Self {
        let n = values.len();
        let std_err = (mean_and_variance(values.iter().copied()).1 / n as f64).sqrt();
        let half = n / 2;
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let drift = (mean(&values[..half]) - mean(&values[n - half..])).abs();
        // The halves' means differ with a standard error of twice the mean's.
        Self {
            error: std_err.max(0.5 * drift),
            drifts: drift > 4.0 * std_err && drift > 1e-9 * scale.abs(),
        }
    }
}

/// A round's means (over all its windows) and their errors (from the windows' values).
struct Statistics<const M: usize> {
    modes: [ModeSums; M],
    contact: ContactSums,
    /// Of Aᵢ (units of A₀₁), φᵢ (rad), Eᵢ per τ.
    amplitude: [Spread; M],
    phase: [Spread; M],
    exchange: [Spread; M],
    /// Of the dissipation per τ (k₁A₀₁² units).
    e_ts: Spread,
    /// The drives' work per τ (k₁A₀₁² units).
    drive_rate: f64,
}

impl<const M: usize> Statistics<M> {
    fn of(r: &Round<M>, own: &[f64; M], to_energy: f64) -> Self {
        let modes: [ModeSums; M] = std::array::from_fn(|i| {
            r.windows[i]
                .iter()
                .fold(ModeSums::default(), |acc, x| acc.then(x))
        });
        let contact = r
            .contacts
            .iter()
            .fold(ContactSums::empty(), |acc, c| acc.then(c));
        let drive_rate = (0..M)
            .map(|i| modes[i].rate(ModeIntegral::Drive, own[i]))
            .sum::<f64>();
        let values = |i: usize, f: &dyn Fn(&ModeSums) -> f64| -> Vec<f64> {
            r.windows[i].iter().map(f).collect()
        };
        Self {
            amplitude: std::array::from_fn(|i| {
                let a = values(i, &|w| w.amplitude(own[i]));
                Spread::of(&a, modes[i].amplitude(own[i]))
            }),
            phase: std::array::from_fn(|i| {
                let mean = modes[i].phase();
                Spread::of(&values(i, &|w| wrap_angle(w.phase() - mean)), 1.0)
            }),
            exchange: std::array::from_fn(|i| {
                let e = values(i, &|w| w.rate(ModeIntegral::Exchange, own[i]));
                Spread::of(&e, drive_rate)
            }),
            e_ts: Spread::of(
                &r.contacts
                    .iter()
                    .map(|c| to_energy * c.dissipated_hat / (c.weight * own[0]))
                    .collect::<Vec<_>>(),
                drive_rate,
            ),
            drive_rate,
            modes,
            contact,
        }
    }

    /// Whether the errors are below `tolerance` — each driven mode's A (relative) and φ
    /// (rad), E_ts relative to the drives' work — and none of them drifts.
    fn within(&self, modes: &[super::set::ModeModel], own: &[f64; M], tolerance: f64) -> bool {
        (0..M).filter(|&i| modes[i].drive != 0.0).all(|i| {
            let (a, phi) = (self.amplitude[i], self.phase[i]);
            a.error <= tolerance * self.modes[i].amplitude(own[i])
                && phi.error <= tolerance
                && !a.drifts
                && !phi.drifts
        }) && self.e_ts.error <= tolerance * self.drive_rate.abs()
            && !self.e_ts.drifts
    }
}

fn report<const M: usize>(
    p: &Prepared,
    modal: &Modal,
    r: &Round<M>,
    s: &Statistics<M>,
    tau: f64,
    converged: bool,
) -> WindowedModes {
    let cant = &p.setup.cantilever;
    let contact = &p.setup.contact;
    let (k1, a0) = (cant.stiffness_n_m, cant.free_amplitude_m);
    let first_period = modal.drive_period();
    let own: [f64; M] = std::array::from_fn(|i| modal.own_period(i));
    // Per τ → per first-mode drive period, in J.
    let per_period = first_period * k1 * a0 * a0;
    // Scatter within 1e-9 of a value's scale is the round-off of the sums.
    let scatter = |e: f64, scale: f64| if e <= 1e-9 * scale.abs() { 0.0 } else { e };
    let modes = (0..M)
        .map(|i| {
            let m = &modal.modes[i];
            let w = &s.modes[i];
            let free = m.free_amplitude();
            let amp = w.amplitude(own[i]);
            let amp_err = scatter(s.amplitude[i].error, amp);
            let (resonance_hz, stiffness, quality) = modal.in_si(cant, i);
            WindowedMode {
                mode: i + 1,
                resonance_hz,
                drive_frequency_hz: cant.resonance_hz * m.omega,
                stiffness_n_m: stiffness,
                quality,
                free_amplitude_m: free * a0,
                amplitude_m: amp * a0,
                amplitude_std_err_m: amp_err * a0,
                amplitude_ratio: (free > 0.0).then(|| amp / free),
                amplitude_ratio_std_err: (free > 0.0).then(|| amp_err / free),
                phase_deg: w.phase().to_degrees(),
                phase_std_err_deg: scatter(s.phase[i].error, 1.0).to_degrees(),
                e_drive_j: m.drive * w.rate(ModeIntegral::Drive, own[i]) * per_period,
                e_damp_j: m.damping / m.gain * w.rate(ModeIntegral::Damping, own[i]) * per_period,
                e_exchange_j: w.rate(ModeIntegral::Exchange, own[i]) * per_period,
                e_exchange_std_err_j: scatter(s.exchange[i].error, s.drive_rate) * per_period,
                virial_j: w.rate(ModeIntegral::Virial, own[i]) * k1 * a0 * a0,
                periods_averaged: (r.done[i] as f64 * own[i] / first_period).round(),
            }
        })
        .collect();
    let c = &s.contact;
    let span = c.weight * first_period;
    let to_energy = p.cpl.f_scale / p.cpl.a1;
    let (adhesion, capillary) = resolved_dissipation(
        to_energy * c.dissipated_hat,
        to_energy * c.capillary_hat,
        c.drive_less_damp.abs() + to_energy * c.work_scale_hat,
    );
    let e_ts_j = (adhesion + capillary) / span * per_period;
    let scale = contact.separation_scale_m();
    WindowedModes {
        law: p.setup.law.to_string(),
        tabor_mu: contact.tabor_mu(),
        separation_m: p.cpl.a0 * scale,
        motion: "no common period: weighted averages over windows of whole periods of \
                 each mode",
        modes,
        e_ts_j,
        e_ts_std_err_j: if e_ts_j == 0.0 {
            0.0
        } else {
            scatter(s.e_ts.error, s.drive_rate) * per_period
        },
        e_ts_ev: e_ts_j / ELECTRONVOLT_J,
        e_ts_adhesion_j: adhesion / span * per_period,
        e_ts_capillary_j: capillary / span * per_period,
        energy_balance_rel: (c.drive_less_damp - (adhesion + capillary)).abs()
            / c.drive_less_damp.abs().max((s.drive_rate * span).abs()),
        mean_force_n: c.force / span * k1 * a0,
        contact_fraction: c.contact_time / span,
        jumps_in: c.jumps_in / c.weight,
        min_separation_m: p.cpl.alpha_hat(c.min_tip, 0.0) * scale,
        windows: r.contacts.len(),
        window_periods: r.per_window[0],
        periods_averaged: r.done[0] as f64,
        periods_integrated: tau / first_period,
        converged,
    }
}
