//! A requested stop ([`tapsim::interrupt`]) ends sweeps and maps early. In a file of its
//! own: the request is for the whole process, and would stop other tests' sweeps.

use tapsim::dynamics::setup::{Numerics, default_setup};
use tapsim::error::Error;

/// A requested stop ends a map before its first cell and an approach curve before its
/// first point; cleared, they run.
#[test]
fn a_requested_stop_ends_sweeps_until_cleared() {
    let setup = default_setup();
    let numerics = Numerics::default();
    let ramp = tapsim::sweep::ramp(22e-9, 20e-9, 2, false).unwrap();
    tapsim::interrupt::request();
    let stopped = tapsim::sweep::approach_curve(&setup, &numerics, &ramp, |_, _| {});
    let map = tapsim::sweep::map_cells(&setup, &numerics, (&[0.1], &[1e9]), &[0], 1, || {}, None);
    tapsim::interrupt::clear();
    assert!(matches!(stopped, Err(Error::Interrupted)), "{stopped:?}");
    assert!(matches!(map, Err(Error::Interrupted)));
    let points = tapsim::sweep::approach_curve(&setup, &numerics, &ramp, |_, _| {}).unwrap();
    assert_eq!(points.len(), 2);
}
