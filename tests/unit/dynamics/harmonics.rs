//! Tests of `tapsim::dynamics::harmonics` (src/dynamics/harmonics.rs).

use tapsim::dynamics::harmonics::*;

#[test]
fn the_quintic_hermite_interpolant_reproduces_quintics() {
    let p =
        |t: f64| 0.3 - 1.2 * t + 0.7 * t * t + 2.0 * t.powi(3) - 1.1 * t.powi(4) + 0.4 * t.powi(5);
    let dp = |t: f64| -1.2 + 1.4 * t + 6.0 * t * t - 4.4 * t.powi(3) + 2.0 * t.powi(4);
    let ddp = |t: f64| 1.4 + 12.0 * t - 13.2 * t * t + 8.0 * t.powi(3);
    for t in [0.0, 0.13, 0.5, 0.77, 1.0] {
        let (q, dq) = quintic_hermite(t, (p(0.0), dp(0.0), ddp(0.0)), (p(1.0), dp(1.0), ddp(1.0)));
        assert!((q - p(t)).abs() < 1e-14, "{t}: {q} vs {}", p(t));
        assert!((dq - dp(t)).abs() < 1e-13, "{t}: {dq} vs {}", dp(t));
    }
}
