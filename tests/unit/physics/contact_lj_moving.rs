//! Tests of `tapsim::physics::contact::lj::moving` (src/physics/contact/lj/moving.rs).

use tapsim::physics::contact::lj::moving::*;

#[test]
fn the_mesh_has_its_edge_node_at_one_and_reaches_the_outer_radius() {
    for mu in [1.0, 5.0, 10.0] {
        let spec = MovingSpec::for_tabor(mu, 7.0);
        let (xi, edge) = spec.nodes();
        assert_eq!(xi[0], 0.0);
        assert_eq!(xi[edge], 1.0);
        assert!(xi.windows(2).all(|w| w[1] > w[0]));
        let last = *xi.last().unwrap();
        assert!((last * spec.a_start - OUTER_RADIUS).abs() < 1e-9 * OUTER_RADIUS);
        // Finest at the edge; inside the contact no coarser than `inner`.
        let h = |i: usize| xi[i + 1] - xi[i];
        assert!((h(edge) - spec.fine).abs() < 1e-12);
        assert!((h(edge - 1) - spec.fine).abs() < 1e-12);
        assert!((1..edge).all(|i| h(i) <= spec.inner + 1e-12));
        assert!((0..xi.len() - 1).all(|i| h(i) >= spec.fine - 1e-12));
    }
}
