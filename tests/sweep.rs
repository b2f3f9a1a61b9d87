//! Approach–retract curves.

use tapsim::dynamics::setup::{Numerics, default_setup};
use tapsim::sweep::{self, Direction};

#[test]
fn hybrid_dissipates_its_loop_exactly_where_the_tip_reaches_the_jump_in() {
    let setup = default_setup();
    let ramp = sweep::ramp(24e-9, 10e-9, 15, true).unwrap();
    let points = sweep::approach_curve(&setup, &Numerics::default(), &ramp, |_, _| {}).unwrap();
    assert_eq!(points.len(), 30);
    let (mut touching, mut free) = (0, 0);
    for p in &points {
        let o = &p.observables;
        if o.jumps_in > 0.0 {
            touching += 1;
            // Every touch traverses the whole loop: E_ts per period is the loop area times
            // the touches per period (1 on a period-1 orbit, fewer if some periods miss).
            let expected = o.jumps_in * o.loop_area_j;
            let rel = (o.e_ts_j - expected).abs() / expected;
            assert!(
                rel < 1e-5,
                "z_c {:e} ({}): E_ts {} vs {} loops {}",
                p.separation_m,
                o.regime,
                o.e_ts_j,
                o.jumps_in,
                o.loop_area_j
            );
        } else {
            free += 1;
            assert_eq!(o.e_ts_j, 0.0, "z_c {:e}", p.separation_m);
            assert!(o.min_separation_m > 0.0);
        }
    }
    assert!(touching > 5 && free > 2, "{touching} {free}");
    // The ramp goes down then up, and the oscillator is carried along.
    assert_eq!(points[0].direction, Direction::Approach);
    assert_eq!(points[29].direction, Direction::Retract);
    assert!(points[14].observables.amplitude_ratio < points[0].observables.amplitude_ratio);
}

#[test]
fn bad_ramps_are_refused() {
    assert!(sweep::ramp(10e-9, 20e-9, 10, true).is_err());
    assert!(sweep::ramp(20e-9, 10e-9, 1, true).is_err());
    assert!(sweep::ramp(f64::NAN, 10e-9, 10, true).is_err());
}

#[test]
fn dmt_approach_jumps_from_the_attractive_to_the_repulsive_regime() {
    // Weak attraction on a stiffer sample: the phase falls through 90° on approach.
    let mut setup = default_setup();
    setup.law = tapsim::law::LawKind::Dmt.into();
    setup.law.hamaker_j = Some(5e-20);
    setup.contact.modulus_pa = tapsim::params::composite_modulus(169e9, 0.28, 2e9, 0.4).unwrap();
    let ramp = sweep::ramp(24e-9, 8e-9, 16, true).unwrap();
    // This ramp once ended in a Dopri5 step-size underflow (a switch located at the very
    // start of a step, late in the run): it must complete.
    let points = sweep::approach_curve(&setup, &Numerics::default(), &ramp, |_, _| {}).unwrap();
    let approach: Vec<f64> = points
        .iter()
        .filter(|p| p.direction == Direction::Approach)
        .map(|p| p.observables.phase_deg)
        .collect();
    assert!(approach.iter().any(|&p| p > 90.5), "{approach:?}");
    assert!(approach.last().copied().unwrap() < 40.0, "{approach:?}");
    // The largest drop between neighbouring setpoints crosses 90°.
    let (i, _) = approach
        .windows(2)
        .enumerate()
        .map(|(i, w)| (i, w[0] - w[1]))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    assert!(approach[i] > 90.0 && approach[i + 1] < 90.0, "{approach:?}");
    assert!(points.iter().all(|p| p.observables.converged));
}

#[test]
fn dmt_bistability_has_a_hysteresis_window_on_retract() {
    let mut setup = default_setup();
    setup.law = tapsim::law::LawKind::Dmt.into();
    setup.law.hamaker_j = Some(1.5e-19);
    setup.contact.modulus_pa = tapsim::params::composite_modulus(169e9, 0.28, 2e9, 0.4).unwrap();
    let ramp = sweep::ramp(22e-9, 14e-9, 17, true).unwrap();
    let numerics = sweep::sweep_numerics(Numerics::default(), (false, false));
    let points = sweep::approach_curve(&setup, &numerics, &ramp, |_, _| {}).unwrap();
    let phase = |dir: Direction| -> Vec<(f64, f64)> {
        let mut v: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.direction == dir)
            .map(|p| (p.separation_m, p.observables.phase_deg))
            .collect();
        v.sort_by(|a, b| b.0.total_cmp(&a.0)); // far to near
        v
    };
    let (approach, retract) = (phase(Direction::Approach), phase(Direction::Retract));
    // Approach: attractive (> 90°) far out, a single jump to repulsive (< 90°).
    let jump_in = approach
        .windows(2)
        .position(|w| w[0].1 > 90.0 && w[1].1 < 90.0)
        .expect("a jump on approach");
    assert!(approach[..=jump_in].iter().skip(3).all(|p| p.1 > 90.0));
    assert!(approach[jump_in + 1..].iter().all(|p| p.1 < 90.0));
    // Retract: still repulsive at the last attractive setpoint of the approach — the
    // hysteresis window — and back to attractive further out.
    let window = approach[jump_in].0;
    let back = retract.iter().find(|p| p.0 == window).unwrap();
    assert!(
        back.1 < 90.0,
        "no window: retract at {window:e} m has {} deg",
        back.1
    );
    let jump_out = retract
        .windows(2)
        .position(|w| w[0].1 > 90.0 && w[1].1 < 90.0)
        .expect("a jump on retract");
    assert!(
        retract[jump_out].0 > window,
        "the retract jump lies farther out than the approach jump"
    );
    println!(
        "approach jumps between {:.1} and {:.1} nm; retract stays repulsive at {:.1} nm (φ {:.1}° vs {:.1}°)",
        approach[jump_in].0 * 1e9,
        approach[jump_in + 1].0 * 1e9,
        window * 1e9,
        back.1,
        approach[jump_in].1
    );
}
