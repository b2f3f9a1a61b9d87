//! Slow force–distance cycles: the support moves in and out far below resonance, with
//! enough damping that the ringing after each jump dies out, so the cantilever behaves
//! quasi-statically and must lose per cycle the finite-stiffness hysteresis (26).

use super::march::{Phase, Simulation};
use super::model::{Coupling, Drive, Oscillator};
use super::numeric::{Ignore, Tolerances};
use crate::error::{Error, Result, positive};
use crate::physics::contact::hybrid::JumpIn;
use crate::physics::contact::spring;
use crate::physics::law::{AdhesiveLaw, ForceLaw};
use serde::Serialize;

/// Settings of a slow base-driven cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaseDriveOptions {
    /// Drive frequency over resonance (≪ 1).
    pub frequency_ratio: f64,
    /// Quality factor (≈ 1: jumps ring down within a few natural periods).
    pub quality: f64,
    /// Cycles to run before the reported one.
    pub warm_up_cycles: usize,
    /// Relative tolerance of the integrator.
    pub rtol: f64,
}

impl Default for BaseDriveOptions {
    fn default() -> Self {
        Self {
            frequency_ratio: 1e-4,
            quality: 1.0,
            warm_up_cycles: 1,
            rtol: 1e-9,
        }
    }
}

/// Result of a slow base-driven cycle, in the paper's units (Ŵ = W/(μεRΔγ)).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BaseDriveCycle {
    /// Tabor parameter μ.
    pub tabor_mu: f64,
    /// Support stiffness k̂, eq. (22).
    pub k_hat: f64,
    /// Loss per cycle from the dynamics: contact plus damping, Ŵ.
    pub w_hat_dynamic: f64,
    /// Of which dissipated in the contact.
    pub w_hat_contact: f64,
    /// Of which dissipated by damping (ring-down after the jumps, slow motion).
    pub w_hat_damping: f64,
    /// The closed-form finite-stiffness loss, eq. (26).
    pub w_hat_closed_form: f64,
    /// Jumps into contact in the reported cycle.
    pub jumps_in: u32,
}

/// Drive the support of a hybrid contact (jump-in from `jump_in`) of Tabor parameter μ
/// through a spring k̂ slowly in and out, from well outside the jump points down to a
/// compressive force of the order of the pull-off force, and measure the loss per cycle.
pub fn hybrid_cycle(
    tabor_mu: f64,
    k_hat: f64,
    jump_in: JumpIn,
    opts: &BaseDriveOptions,
) -> Result<BaseDriveCycle> {
    positive("k_hat", k_hat)?;
    positive("frequency ratio", opts.frequency_ratio)?;
    positive("quality factor", opts.quality)?;
    let closed = spring::hysteresis(tabor_mu, k_hat, jump_in)?;
    if closed.landing.is_none() {
        return Err(Error::NotApplicable(
            closed
                .no_hysteresis_reason
                .unwrap_or_else(|| "no hysteresis".into()),
        ));
    }
    let law = AdhesiveLaw::hybrid(tabor_mu, jump_in)?;
    // Support travel in α̂_S: from beyond both jump points down to where the spring
    // pushes with about the pull-off force, α̂_S ≈ −3π/(2k̂) − 3.
    let top = law.jump_in_alpha_hat().max(closed.support_alpha_hat_c) + 1.0;
    let bottom = -1.5 * std::f64::consts::PI / k_hat - 3.0;
    let (mid, amplitude) = (0.5 * (top + bottom), 0.5 * (top - bottom));
    // Length unit L = με: x is in α̂ units, forces in k·με, f_scale = RΔγ/(kμε) = 1/k̂.
    let osc = Oscillator {
        gamma: 0.5 / opts.quality,
        omega: opts.frequency_ratio,
        drive: Drive::Base { amplitude },
        bias: 0.0,
    };
    let cpl = Coupling {
        a0: mid,
        a1: 1.0,
        f_scale: 1.0 / k_hat,
    };
    let sim = Simulation {
        law: &law,
        osc,
        cpl,
        tol: Tolerances {
            rtol: opts.rtol,
            atol: opts.rtol * 1e-3,
            h_max: osc.period() / 2000.0,
        },
    };
    let mut phase = Phase::at_rest();
    for _ in 0..opts.warm_up_cycles {
        sim.cycle(&mut phase, &mut Ignore)?;
    }
    let c = sim.cycle(&mut phase, &mut Ignore)?;
    // Energies are in units of k(με)² = μεRΔγ/k̂.
    Ok(BaseDriveCycle {
        tabor_mu,
        k_hat,
        w_hat_dynamic: (c.e_ts + c.e_damp) * k_hat,
        w_hat_contact: c.e_ts * k_hat,
        w_hat_damping: c.e_damp * k_hat,
        w_hat_closed_form: closed.w_hat,
        jumps_in: c.jumps_in,
    })
}
