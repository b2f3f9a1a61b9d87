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
        if o.jumps_in >= 1 {
            touching += 1;
            let rel = (o.e_ts_j - o.loop_area_j).abs() / o.loop_area_j;
            assert!(
                rel < 1e-5,
                "z_c {:e}: E_ts {} vs loop {}",
                p.separation_m,
                o.e_ts_j,
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
    setup.law = tapsim::law::LawKind::Dmt;
    setup.hamaker_j = Some(5e-20);
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
