//! Tests of `tapsim::instrument::repeats` (src/instrument/repeats.rs).

use tapsim::instrument::repeats::*;

fn state(x: f64) -> LoopState {
    let mut s = [0.0; STATE_LEN];
    s[0] = x;
    s[5] = -0.5 * x;
    s
}

#[test]
fn a_geometric_approach_settles_once_its_bound_is_below_the_tolerance() {
    // x_j = 0.9^j: gap 0.1·0.9^(j−1), bound gap·9 = 0.9^j, the true distance.
    let mut r = Repeats::within(1e-6);
    let mut settled_at = None;
    for j in 0..400 {
        if r.settled(Some(&state(0.9f64.powi(j))), 1) {
            settled_at = Some(j);
            break;
        }
    }
    // 0.9^j ≤ 1e-6 from j = 132 on.
    assert_eq!(settled_at, Some(132));
}

#[test]
fn motion_that_does_not_shrink_its_gap_is_never_skipped() {
    // A period-2 alternation of 1e-12: tiny, but not contracting.
    let mut r = Repeats::within(1e-6);
    for j in 0..1000 {
        assert!(!r.settled(Some(&state(1e-12 * (j % 2) as f64)), 1));
    }
    // A probe that cannot say its state, and the exact march, never settle.
    assert!(!(0..100).any(|_| r.settled(None, 1)));
    let mut exact = Repeats::exact();
    assert!(!(0..100).any(|_| exact.settled(Some(&state(0.0)), 1)));
}

#[test]
fn a_restart_forgets_the_stretch_before() {
    let mut r = Repeats::within(1e-3);
    for j in 0..200 {
        r.settled(Some(&state(0.5f64.powi(j))), 1);
    }
    assert!(r.settled(Some(&state(0.5f64.powi(200))), 1));
    r.restart();
    assert!(!r.settled(Some(&state(0.5f64.powi(201))), 1));
}

#[test]
fn a_ringing_loop_settles_only_once_its_oscillation_has_died_down() {
    // x_j = r^j cos(2πj/400), r = 0.995: the distance from the fixed point 0 is at
    // most r^j. Near each turn of the oscillation the gap shrinks over 32 periods
    // however far out the loop is; the window's bound is fooled there, the blocks'
    // is not.
    let x = |j: i32| 0.995f64.powi(j) * (2.0 * std::f64::consts::PI * j as f64 / 400.0).cos();
    let tolerance = 1e-6;
    let first = |mut r: Repeats| (0..20_000).find(|&j| r.settled(Some(&state(x(j))), 1));
    let window = first(Repeats::within(tolerance)).expect("settles");
    assert!(0.995f64.powi(window) > 10.0 * tolerance, "{window}");
    let blocks = first(Repeats::within_blocks(tolerance, 800)).expect("settles");
    assert!(0.995f64.powi(blocks) <= tolerance, "{blocks}");
    // And not much later than it must: within two blocks of r^j = 1e-6.
    assert!(blocks < 2757 + 1600, "{blocks}");
}

#[test]
fn a_loop_that_repeats_every_second_period_settles_watched_over_two() {
    // ±1 alternating, plus a decaying 0.8^j: over one period it never repeats; over
    // two the gap is 0.36·0.8^(j−2), shrinking by ρ = 0.64 a cycle, and the bound
    // gap·ρ/(1 − ρ) = 0.8^j is the true distance from the cycle.
    let x = |j: i32| if j % 2 == 0 { 1.0 } else { -1.0 } + 0.8f64.powi(j);
    let mut one = Repeats::within(1e-6);
    assert!(!(0..400).any(|j| one.settled(Some(&state(x(j))), 1)));
    let mut two = Repeats::within(1e-6);
    let at = (0..400).find(|&j| two.settled(Some(&state(x(j))), 2));
    // 0.8^j ≤ 1e-6 from j = 62 on.
    assert_eq!(at, Some(62));
    // A cycle longer than watched is never skipped.
    let mut long = Repeats::within(1.0);
    assert!(!(0..400).any(|_| long.settled(Some(&state(0.0)), LONGEST_CYCLE + 1)));
}
