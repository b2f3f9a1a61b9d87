//! Identification curves (García et al., PRL 97, 016103 (2006); Gómez & García,
//! Ultramicroscopy 110, 626 (2010)): the shape of E/E_max against A/A₀ tells the
//! dissipation mechanisms apart.

use tapsim::dynamics::setup::{Numerics, TapSetup, default_setup};
use tapsim::identification::{self, Mechanism, Normalized};
use tapsim::law::{LawKind, LawSpec};
use tapsim::sweep::{self, Direction, SweepPoint};

/// The approach from 1.2 A₀ to `to` A₀ in `points` setpoints, with each point's
/// identification values.
fn approach(setup: &TapSetup, to: f64, points: usize) -> Vec<(SweepPoint, Normalized)> {
    let a0 = setup.cantilever.free_amplitude_m;
    let ramp = sweep::ramp(1.2 * a0, to * a0, points, false).unwrap();
    let numerics = sweep::sweep_numerics(Numerics::default(), (false, false));
    let curve = sweep::approach_curve(setup, &numerics, &ramp, |_, _| {}).unwrap();
    let normalized = identification::normalize(&curve);
    curve.into_iter().zip(normalized).collect()
}

/// Adhesion hysteresis (the hybrid law) is a loop traversed whole on every touch, so
/// its curve is a step: 0 while the tip does not reach the jump-in, then a plateau at 1
/// on every period-1 setpoint (on the others, the touches per period) — and that shape
/// does not change with A₀, k or Q (only where the step stands, next to A/A₀ = 1, and
/// where the motion is not period-1).
#[test]
fn adhesion_hysteresis_steps_to_a_plateau_that_a0_k_and_q_do_not_move() {
    let base = default_setup();
    let c = base.cantilever;
    let variants = [
        ("defaults", c),
        ("A0 x 1.5", {
            let mut c = c;
            c.free_amplitude_m *= 1.5;
            c
        }),
        ("k x 2", {
            let mut c = c;
            c.stiffness_n_m *= 2.0;
            c
        }),
        ("Q x 2", {
            let mut c = c;
            c.quality *= 2.0;
            c
        }),
    ];
    for (name, cantilever) in variants {
        let setup = TapSetup {
            cantilever,
            ..base.clone()
        };
        let curve = approach(&setup, 0.4, 24);
        // The most touches per period on the curve (1 where some setpoint touches every
        // period; below where grazing locks skip touches everywhere, as at Q x 2).
        let most = curve
            .iter()
            .map(|(p, _)| p.observables.jumps_in)
            .fold(0.0, f64::max);
        let (mut plateau, mut step) = (Vec::new(), None);
        for (p, n) in &curve {
            let o = &p.observables;
            let e = n.of(Mechanism::Adhesion).expect("the hybrid dissipates");
            assert_eq!(n.of(Mechanism::Viscous), None, "{name}: an elastic sample");
            assert_eq!(n.of(Mechanism::All), Some(e), "{name}: one mechanism");
            if o.jumps_in == 0.0 {
                assert_eq!(e, 0.0, "{name}: no touch, no loss");
                step.get_or_insert(o.amplitude_ratio);
                continue;
            }
            // Each touch loses the whole loop: E/E_max is the touches per period over
            // the most on the curve (below 1 where the motion skips touches).
            assert!(
                (e - o.jumps_in / most).abs() < 1e-5,
                "{name}: A/A0 {} ({}): {e} vs {} touches",
                o.amplitude_ratio,
                o.regime,
                o.jumps_in
            );
            if o.period == Some(1) {
                assert!(
                    (e - 1.0).abs() < 1e-6,
                    "{name}: A/A0 {}: {e}",
                    o.amplitude_ratio
                );
                plateau.push(o.amplitude_ratio);
            }
        }
        let (low, high) = (
            plateau.iter().copied().fold(f64::INFINITY, f64::min),
            plateau.iter().copied().fold(0.0, f64::max),
        );
        println!(
            "{name}: plateau over A/A0 {low:.3}..{high:.3} ({} setpoints)",
            plateau.len()
        );
        if most < 1.0 {
            // No setpoint touches every period: the loop's loss per touch exceeds what
            // the drive supplies, the turning point stays pinned at the jump-in, and
            // every touching state grazes it (mode locks that skip touches).
            assert!(
                curve
                    .iter()
                    .all(|(p, _)| p.observables.jumps_in == 0.0 || p.observables.grazing),
                "{name}: a touching setpoint that does not graze"
            );
            continue;
        }
        assert!(
            plateau.len() >= 5 && low < 0.6,
            "{name}: plateau {low}..{high}"
        );
        assert!(step.is_some_and(|s| s > 0.95), "{name}: step at {step:?}");
    }
}

/// A Kelvin–Voigt sample dissipates most at an intermediate amplitude: at first touch
/// the tip barely indents, at small amplitudes it moves slowly; the maximum lies inside,
/// and the curve falls on both sides of it.
#[test]
fn a_viscous_sample_dissipates_most_at_an_intermediate_amplitude() {
    let setup = TapSetup {
        law: LawSpec {
            viscosity_pa_s: Some(10.0),
            ..LawKind::Hertz.into()
        },
        ..default_setup()
    };
    let curve = approach(&setup, 0.3, 36);
    let touching: Vec<(f64, f64)> = curve
        .iter()
        .filter(|(p, _)| p.direction == Direction::Approach && p.observables.min_separation_m < 0.0)
        .map(|(p, n)| {
            assert_eq!(p.observables.period, Some(1), "{:?}", p.observables.regime);
            assert_eq!(n.of(Mechanism::Adhesion), None, "Hertz has no hysteresis");
            let e = n.of(Mechanism::Viscous).expect("the sample dissipates");
            assert_eq!(n.of(Mechanism::All), Some(e));
            (p.observables.amplitude_ratio, e)
        })
        .collect();
    let (at, _) = touching
        .iter()
        .copied()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    let (first, last) = (touching[0], touching[touching.len() - 1]);
    println!(
        "maximum at A/A0 {at:.3}; {:.3} at first touch (A/A0 {:.3}), {:.3} at A/A0 {:.3}",
        first.1, first.0, last.1, last.0
    );
    assert!(at > 0.5 && at < 0.9, "maximum at A/A0 {at}");
    assert!(first.1 < 0.5 && last.1 < 0.95, "{first:?} {last:?}");
}

/// A capillary neck, like adhesion hysteresis, loses a fixed loop per touch: its curve
/// is the touches per period — a step to a plateau at 1 on every period-1 setpoint.
#[test]
fn a_capillary_neck_steps_to_a_plateau_too() {
    let setup = TapSetup {
        law: LawSpec {
            rupture_distance_m: Some(1e-9),
            contact_angle_deg: Some(60.0),
            ..LawKind::Hertz.into()
        },
        ..default_setup()
    };
    let curve = approach(&setup, 0.4, 24);
    let mut plateau = 0;
    for (p, n) in &curve {
        let o = &p.observables;
        let e = n.of(Mechanism::Capillary).expect("the neck dissipates");
        assert_eq!(n.of(Mechanism::All), Some(e), "one mechanism");
        assert!(
            (e - o.jumps_in).abs() < 1e-6,
            "A/A0 {}: {e} vs {}",
            o.amplitude_ratio,
            o.jumps_in
        );
        if o.period == Some(1) && o.jumps_in > 0.0 {
            plateau += 1;
        }
    }
    assert!(plateau >= 10, "{plateau} period-1 touching setpoints");
}
