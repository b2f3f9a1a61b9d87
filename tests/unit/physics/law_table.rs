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

/// The weighted integral ∫ p(x)·2x dx of the interpolant over part of an interval is
/// the integral of what `eval` returns, against Simpson's rule on `eval`.
#[test]
fn weighted_integral_is_the_integral_of_the_interpolant_times_2x() {
    let t = UniformTable::sample(0.5, 3.0, 26, |x| x.sin() + 0.3 * x * x);
    let dx = t.step();
    for (i, frac) in [(0, 1.0), (3, 0.25), (10, 0.7), (24, 1.0), (24, 0.01)] {
        let a = 0.5 + dx * i as f64;
        let b = a + frac * dx;
        // Simpson's rule on 64 panels: exact for the quintic p(x)·2x up to
        // (b − a)⁵/64⁴ times its fourth derivative, far below the tolerance.
        let n = 64;
        let h = (b - a) / n as f64;
        let g = |x: f64| t.eval(x) * 2.0 * x;
        let simpson: f64 = (0..n)
            .map(|k| {
                let x = a + h * k as f64;
                h / 6.0 * (g(x) + 4.0 * g(x + 0.5 * h) + g(x + h))
            })
            .sum();
        let exact = t.weighted_integral(i, frac);
        assert!(
            (exact - simpson).abs() < 1e-13 * (1.0 + simpson.abs()),
            "node {i}, fraction {frac}: {exact} vs {simpson}"
        );
    }
}
