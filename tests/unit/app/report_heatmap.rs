//! Tests of `tapsim::app::report::heatmap` (src/app/report/heatmap.rs).

use tapsim::app::report::heatmap::*;

#[test]
fn viridis_runs_from_dark_to_light() {
    assert_eq!(viridis(0.0), VIRIDIS[0]);
    assert_eq!(viridis(1.0), VIRIDIS[8]);
    let lightness = |c: (u8, u8, u8)| 0.3 * c.0 as f64 + 0.59 * c.1 as f64 + 0.11 * c.2 as f64;
    let l: Vec<f64> = (0..=20)
        .map(|i| lightness(viridis(i as f64 / 20.0)))
        .collect();
    assert!(l.windows(2).all(|w| w[1] > w[0]), "{l:?}");
}

#[test]
fn edges_enclose_each_log_spaced_value() {
    // Pixel centres of an image from 0: its first edge is 0 exactly.
    let y: Vec<f64> = (0..48).map(|j| 1000.0 * (j as f64 + 0.5) / 48.0).collect();
    assert_eq!(HeatMap::linear_edges(&y)[0], 0.0);
    let e = HeatMap::edges(&[1.0, 10.0, 100.0]);
    assert_eq!(e.len(), 4);
    let expect = [
        10f64.powf(-0.5),
        10f64.powf(0.5),
        10f64.powf(1.5),
        10f64.powf(2.5),
    ];
    assert!(e.iter().zip(expect).all(|(a, b)| (a - b).abs() < 1e-12 * b));
}
