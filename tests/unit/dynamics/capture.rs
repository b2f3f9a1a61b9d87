//! Tests of `tapsim::dynamics::capture` (src/dynamics/capture.rs).

use nalgebra::DMatrix;
use tapsim::dynamics::capture::*;

#[test]
fn transient_growth_of_a_rotation_that_decays() {
    // A rotation by 90° scaled by 0.9: ‖Mᵏ‖∞ = 0.9ᵏ, so the growth is 1 (k = 0).
    let m = DMatrix::from_row_slice(2, 2, &[0.0, -0.9, 0.9, 0.0]);
    assert_eq!(transient_growth(&m), 1.0);
    // A shear: Mᵏ = [[0.9ᵏ, k·0.9ᵏ⁻¹·s], [0, 0.9ᵏ]] grows before it decays; its
    // largest ∞-norm over k, found by brute force.
    let s = 2.0;
    let m = DMatrix::from_row_slice(2, 2, &[0.9, s, 0.0, 0.9]);
    let brute = (0..200)
        .map(|k| {
            let k = k as f64;
            0.9f64.powf(k) + k * 0.9f64.powf(k - 1.0) * s
        })
        .fold(1.0, f64::max);
    assert!((transient_growth(&m) - brute).abs() < 1e-12 * brute);
}
