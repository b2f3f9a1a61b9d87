//! Tests of `tapsim::physics::contact::lj::solver` (src/physics/contact/lj/solver.rs).

use nalgebra::DVector;
use tapsim::physics::contact::lj::solver::*;

#[test]
fn a_stretched_mesh_equals_one_assembled_stretched() {
    let xi: Vec<f64> = (0..=60)
        .map(|i| 0.05 * i as f64 + 0.001 * (i * i) as f64)
        .collect();
    let a = 1.7;
    let unit = Problem::new(5.0, xi.clone());
    let stretched = Problem::new(5.0, xi.iter().map(|x| a * x).collect());
    let s = Solution {
        gap: DVector::from_iterator(xi.len(), xi.iter().map(|x| 1.1 + 0.3 * (a * x).powi(2))),
        alpha_bar: 0.4,
    };
    let (r1, r2) = (
        unit.residual_scaled(&s, a),
        stretched.residual_scaled(&s, 1.0),
    );
    // The elastic part of the residual (the rest is identical by construction).
    let mut elastic = r2.clone();
    for (i, x) in stretched.nodes.iter().enumerate() {
        elastic[i] -= s.gap[i] - s.alpha_bar - 1.0 - 0.5 * x * x;
    }
    // Exact in exact arithmetic (G(x, y) dy is homogeneous of degree one); the two
    // assemblies differ by the element quadrature's error only (2.3e-5 here).
    let d = (&r1 - &r2).amax() / elastic.amax();
    assert!(d < 1e-4, "{d:e}");
    let (t1, g1) = unit.force_scaled(&s.gap, a);
    let (t2, g2) = stretched.force_scaled(&s.gap, 1.0);
    // The moments ∫ φ_j x dx are polynomial: exact under stretching.
    assert!((t1 - t2).abs() < 1e-12 * t2.abs(), "{t1} {t2}");
    assert!((&g1 - &g2).amax() < 1e-12 * g2.amax());
}
