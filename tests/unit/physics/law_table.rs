//! Tests of `tapsim::physics::law::table` (src/physics/law/table.rs).

use tapsim::physics::law::table::*;

#[test]
fn interpolates_smooth_functions_to_fourth_order() {
    let err = |n: usize| {
        let t = UniformTable::sample(0.0, 3.0, n, f64::sin);
        (0..1000)
            .map(|i| {
                let x = 3.0 * i as f64 / 999.0;
                (t.eval(x) - x.sin()).abs()
            })
            .fold(0.0, f64::max)
    };
    let (e1, e2) = (err(50), err(100));
    assert!(e1 < 1e-5 && e2 < e1 / 12.0, "{e1} {e2}");
}

#[test]
fn slope_is_the_derivative_of_the_interpolant() {
    let t = UniformTable::sample(0.0, 3.0, 60, f64::sin);
    for i in 0..300 {
        let x = 0.001 + 2.99 * i as f64 / 299.0;
        let h = 1e-6;
        let fd = (t.eval(x + h) - t.eval(x - h)) / (2.0 * h);
        assert!((t.slope(x) - fd).abs() < 1e-8, "{x}");
        assert!((t.slope(x) - x.cos()).abs() < 1e-4, "{x}");
    }
}
