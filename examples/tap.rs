//! One tapping simulation on the built-in defaults, for every force law.
//!
//! Run with `cargo run --release --example tap`.

use tapsim::dynamics::observables::{Observe, tap};
use tapsim::dynamics::setup::{Numerics, default_setup};
use tapsim::law::LawKind;

fn main() -> tapsim::Result<()> {
    println!(
        "{:>18} {:>8} {:>9} {:>9} {:>10} {:>10} {:>8} {:>7}",
        "law", "A/A0", "phi", "phi_E", "E_ts [eV]", "loop [eV]", "balance", "cycles"
    );
    for law in [
        LawKind::Hybrid,
        LawKind::HybridAttractive,
        LawKind::Jkr,
        LawKind::Dmt,
        LawKind::Hertz,
        LawKind::None,
    ] {
        let setup = tapsim::dynamics::setup::TapSetup {
            law: law.into(),
            ..default_setup()
        };
        let start = std::time::Instant::now();
        let o = tap(&setup, &Numerics::default(), Observe::default())?.observables;
        println!(
            "{:>18} {:>8.5} {:>9.4} {:>9.4} {:>10.4} {:>10.4} {:>8.1e} {:>7} {:?}",
            o.law,
            o.amplitude_ratio,
            o.phase_deg,
            o.phase_from_energy_deg,
            o.e_ts_ev,
            o.loop_area_j / tapsim::params::ELECTRONVOLT_J,
            o.energy_balance_rel,
            o.cycles,
            start.elapsed()
        );
    }
    Ok(())
}
