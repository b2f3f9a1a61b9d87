//! `tapsim hysteresis`: the paper's closed-form results for one contact.

use crate::app::config::{ContactInputs, number, stiffness};
use crate::error::Result;
use crate::physics::contact::hybrid::JumpIn;
use crate::physics::summary::{HysteresisSummary, Input, Support};
use clap::Args;

/// Tabor parameter used when neither --mu nor an SI contact is given.
pub const DEFAULT_MU: f64 = 5.0;

/// Hysteresis loss per approach–separation cycle: JKR (9), hybrid (18), and with a
/// support of finite stiffness (26).
///
/// Give the Tabor parameter μ (2) directly with --mu, or the contact in SI units
/// (--radius, --modulus, --work-of-adhesion, --range), from which μ is derived.
/// Without either, μ = 5 (the paper's reference case). Add --k-hat (or --stiffness in
/// N/m with SI inputs) for a compliant support, eqs. (22)-(27).
///
/// JSON keys (--json): tabor_mu, alpha_hat_a, a_hat_a, alpha_hat_c, a_hat_c, t_hat_c,
/// w_hat_hybrid, w_hat_jkr, ...; with a stiffness also k_hat, a_hat_b_spring,
/// a_hat_c_spring, w_hat_spring; with SI inputs also w_j, w_ev (w_joule, w_jkr_joule, w_hybrid_joule: the
/// old names of w_j, w_jkr_j, w_hybrid_j, kept for one release).
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct HysteresisArgs {
    /// Tabor parameter μ, eq. (2) [dimensionless, > 0]. Default 5 without SI inputs.
    #[arg(long, allow_hyphen_values = true, value_parser = number, conflicts_with_all =
          ["radius", "modulus", "tip_modulus", "sample_modulus", "work_of_adhesion", "range"])]
    mu: Option<f64>,
    #[command(flatten)]
    contact: ContactInputs,
    /// Dimensionless support stiffness k̂ = μεk/(RΔγ), eq. (22) [> 0].
    #[arg(long, allow_hyphen_values = true, value_parser = number, conflicts_with = "stiffness")]
    k_hat: Option<f64>,
    /// Support (cantilever) stiffness k [N/m]; needs the SI contact inputs.
    #[arg(long, allow_hyphen_values = true, value_parser = stiffness)]
    stiffness: Option<f64>,
    /// Jump-in separation α̂_A: the fit (17), the closed form (16), or the exact
    /// turning point of the semi-rigid separation (14)-(15).
    #[arg(long, value_enum, ignore_case = true, default_value_t = JumpIn::Fit)]
    jump_in: JumpIn,
    /// Print one JSON object on stdout instead of the table.
    #[arg(long)]
    json: bool,
    /// No notes of files written on stderr.
    #[arg(long, short = 'q')]
    pub(super) quiet: bool,
}

/// Run the subcommand.
pub fn run(args: HysteresisArgs) -> Result<()> {
    let (input, mu_is_default) = if args.contact.any() {
        (Input::Si(args.contact.contact()?), false)
    } else {
        (
            Input::TaborMu(args.mu.unwrap_or(DEFAULT_MU)),
            args.mu.is_none(),
        )
    };
    let support = match (args.k_hat, args.stiffness) {
        (Some(k), _) => Support::KHat(k),
        (None, Some(k)) => Support::NewtonsPerMetre(k),
        (None, None) => Support::Rigid,
    };
    let report = HysteresisSummary::compute(input, support, args.jump_in, mu_is_default)?;
    if args.json {
        outln!("{}", crate::app::report::records::document(&report)?);
    } else {
        out!("{}", report.to_text());
    }
    Ok(())
}
