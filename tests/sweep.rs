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
