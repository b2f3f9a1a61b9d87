//! An approach–retract curve with the hybrid law on the built-in defaults, printed as a
//! table. Run with `cargo run --release --example approach`.

use tapsim::dynamics::setup::{Numerics, default_setup};
use tapsim::sweep;

fn main() -> tapsim::Result<()> {
    let setup = default_setup();
    let a0 = setup.cantilever.free_amplitude_m;
    let ramp = sweep::ramp(1.2 * a0, 0.4 * a0, 20, true)?;
    let numerics = sweep::sweep_numerics(Numerics::default(), (false, false));
    let points = sweep::approach_curve(&setup, &numerics, &ramp, |_, _| {})?;
    println!(
        "{:>9} {:>9} {:>8} {:>9} {:>9}",
        "z_c (nm)", "dir", "A/A0", "phi", "E_ts eV"
    );
    for p in &points {
        let o = &p.observables;
        println!(
            "{:>9.2} {:>9?} {:>8.4} {:>9.3} {:>9.3}",
            p.separation_m * 1e9,
            p.direction,
            o.amplitude_ratio,
            o.phase_deg,
            o.e_ts_ev
        );
    }
    Ok(())
}
