//! Tests of `tapsim::physics::contact::lj::kernel` (src/physics/contact/lj/kernel.rs).

use tapsim::physics::contact::lj::kernel::*;

#[test]
fn regular_part_is_the_kernel_plus_the_logarithm() {
    for &(x, y) in &[(1.0, 0.5), (1.0, 0.999), (2.0, 2.1), (0.3, 3.0)] {
        let r = regular(x, y);
        let g = kernel(x, y);
        assert!(
            (r - (g + y / (x + y) * (x - y).abs().ln())).abs() < 1e-12,
            "{x} {y}"
        );
    }
    // Continuous across the diagonal.
    let (a, b) = (regular(1.0, 1.0 - 1e-9), regular(1.0, 1.0 + 1e-9));
    assert!((a - b).abs() < 1e-8);
}

#[test]
fn log_integral_is_exact_for_quadratics() {
    let g = |y: f64| 0.3 + 1.7 * y - 0.4 * y * y;
    let (x, a, b) = (0.37, 0.2, 0.6);
    let exact = {
        // Fine midpoint sum with the singular point excluded analytically enough.
        let n = 2_000_000;
        let h = (b - a) / n as f64;
        (0..n)
            .map(|i| {
                let y = a + h * (i as f64 + 0.5);
                g(y) * (x - y).abs().ln() * h
            })
            .sum::<f64>()
    };
    let got = log_integral(x, a, b, g(a), g(0.5 * (a + b)), g(b));
    assert!((got - exact).abs() < 1e-6, "{got} {exact}");
}
