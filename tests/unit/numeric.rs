//! Tests of `tapsim::numeric` (src/numeric.rs).

use tapsim::numeric::*;

#[test]
fn finds_cube_root_of_two() {
    let r = bracketed_root("t", |x| x * x * x - 2.0, 0.0, 2.0, 1e-15).unwrap();
    assert!((r - 2f64.cbrt()).abs() < 1e-14);
}

#[test]
fn gauss_legendre_rules_integrate_polynomials_exactly() {
    let int = |rule: &[(f64, f64)], p: i32| rule.iter().map(|(x, w)| w * x.powi(p)).sum::<f64>();
    for p in 0..16 {
        let exact = if p % 2 == 1 {
            0.0
        } else {
            2.0 / (p as f64 + 1.0)
        };
        assert!(
            (int(&GAUSS_LEGENDRE_8, p) - exact).abs() < 1e-14,
            "GL8 x^{p}"
        );
        if p < 8 {
            assert!(
                (int(&GAUSS_LEGENDRE_4, p) - exact).abs() < 1e-14,
                "GL4 x^{p}"
            );
        }
    }
}

#[test]
fn newton_bracketed_stops_at_the_ulp_level_far_from_zero() {
    // At x ≈ 11 the spacing of doubles (1.8e-15) exceeds the requested tolerance; a
    // converged Newton step that lands on the bracket's end must stop, not bisect.
    let root = 10.982_493_883_375_94;
    let calls = std::cell::Cell::new(0);
    let r = newton_bracketed(
        |x| {
            calls.set(calls.get() + 1);
            // The exact root lies between two doubles: no double makes f vanish.
            (x - root + 4.7e-16, 1.0)
        },
        10.2,
        11.0,
        1e-15,
    );
    assert!((r - root).abs() < 4e-15, "{r}");
    assert!(calls.get() <= 8, "{} evaluations", calls.get());
}

#[test]
fn newton_bracketed_finds_roots_fast_and_safely() {
    let r = newton_bracketed(|x| (x * x * x - 2.0, 3.0 * x * x), 0.0, 2.0, 1e-15);
    assert!((r - 2f64.cbrt()).abs() < 1e-14);
    // A derivative that would throw Newton out of the bracket.
    let r = newton_bracketed(|x| (x.atan(), 1.0 / (1.0 + x * x)), -10.0, 3.0, 1e-15);
    assert!(r.abs() < 1e-14);
}

#[test]
fn rejects_bracket_without_sign_change() {
    assert!(bracketed_root("t", |x| x * x + 1.0, -1.0, 1.0, 1e-12).is_err());
}
