//! Tests of `tapsim::instrument::lockin` (src/instrument/lockin.rs).

use tapsim::instrument::lockin::*;

#[test]
fn the_incomplete_gamma_series_matches_the_closed_form() {
    for k in 1..=5 {
        for r in [0.01, 0.3, 1.0, 4.0] {
            let (series, closed) = (incomplete_gamma(k, r), step_response(k, r));
            assert!(
                (series - closed).abs() < 1e-15 + 1e-12 * closed,
                "P({k}, {r}): {series} vs {closed}"
            );
        }
    }
}

#[test]
fn the_clock_follows_tau_moved_back_by_whole_periods() {
    let mut l = LockIn::new(1, 10.0, 1.0).unwrap();
    let period = 2.0 * std::f64::consts::PI;
    let s = SAMPLES_PER_PERIOD as i64;
    assert_eq!(l.samples_in(0.0, 0.5 * period), 0..s / 2 + 1);
    assert_eq!(l.samples_in(0.5 * period, period), s / 2 + 1..s + 1);
    // The marcher moves τ back by a period: the same instant, the sample at τ = T
    // (index S) not taken again as index 0.
    assert_eq!(l.samples_in(0.0, 0.25 * period), 1..s / 4 + 1);
}
