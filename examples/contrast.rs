//! Phase contrast between a soft and a stiffer polymer under the classic JKR law and the
//! paper's hybrid law. Run with `cargo run --release --example contrast`.

use tapsim::config::{MaterialSpec, TapInputs};
use tapsim::contrast::contrast;
use tapsim::law::LawKind;

fn main() -> tapsim::Result<()> {
    let materials = [
        MaterialSpec::parse("soft:sample-modulus=0.5GPa,work-of-adhesion=0.1")?,
        MaterialSpec::parse("stiff:sample-modulus=1GPa,work-of-adhesion=0.08")?,
    ]
    .iter()
    .map(|m| m.resolve(&TapInputs::default()))
    .collect::<tapsim::Result<Vec<_>>>()?;
    let (rows, _) = contrast(
        &materials,
        &[LawKind::Jkr, LawKind::Hybrid],
        (&[0.9, 0.8, 0.7], 30),
        None,
        |what| eprintln!("approach curve: {what}"),
    )?;
    // Materials are compared only on the same branch (attractive or repulsive).
    for r in rows {
        let delta = r.delta_phase_deg.map_or(
            "none: the materials sit on different branches".into(),
            |d| format!("{d:+.2} deg"),
        );
        println!(
            "{:>7} A/A0 = {:.1}, {:?} branch: delta phi = {delta}",
            r.law, r.amplitude_ratio, r.branch
        );
    }
    Ok(())
}
