//! The Lennard-Jones kernel against closed forms: the semi-rigid (12)–(14) for rigid gaps,
//! and the Hertz pressure, whose displacement is known exactly.

use std::f64::consts::PI;
use tapsim::contact::lj::kernel::{influence_matrix, influence_row, moment_weights};
use tapsim::contact::lj::moving::MovingSpec;
use tapsim::contact::lj::result::ELEMENTS_PER_ANNULUS;
use tapsim::contact::semi_rigid::{self, EighthPower};

fn lj(h: f64) -> f64 {
    h.powi(-3) - h.powi(-9)
}

/// u(0) (13) and T̂ (12) for the rigid gap h̄₀ + x²/2 on `nodes`, with the closed forms.
fn rigid_gap(nodes: &[f64], h0: f64) -> ((f64, f64), (f64, f64)) {
    let mu: f64 = 1.0;
    let m = influence_matrix(nodes);
    let f: Vec<f64> = nodes.iter().map(|&x| lj(h0 + 0.5 * x * x)).collect();
    let c = 32.0 / (3.0 * PI) * mu.powf(1.5);
    let u0: f64 = c * (0..nodes.len()).map(|j| m[(0, j)] * f[j]).sum::<f64>();
    let u0_exact = semi_rigid::central_displacement_over_range(h0, mu, EighthPower::Keep);
    let w = moment_weights(nodes);
    let h_end = h0 + 0.5 * nodes.last().unwrap().powi(2);
    let tail = 0.5 * h_end.powi(-2) - 0.125 * h_end.powi(-8);
    let t = 16.0 * PI / 3.0 * (w.iter().zip(&f).map(|(w, f)| w * f).sum::<f64>() + tail);
    ((u0, u0_exact), (t, semi_rigid::force_hat(h0)))
}

/// On the production mesh as it stands on the approach branch (a = a₀) and on the one
/// 1.5 times coarser — the pair every reported value is extrapolated from — u(0) and T̂
/// of rigid gaps converge at second order, and their Richardson extrapolation matches
/// the closed forms to 1e-4 (the single production mesh to 1e-3: its spacing grows
/// with the distance from the contact edge, and a gap h̄₀ = 1 pulls hardest near x ≈ 1).
#[test]
fn rigid_gaps_reproduce_the_semi_rigid_closed_forms_on_the_production_mesh() {
    use tapsim::contact::lj::result::MESH_RATIO;
    for mu in [2.0, 5.0, 10.0] {
        let spec = MovingSpec::for_tabor(mu, ELEMENTS_PER_ANNULUS);
        let on = |spec: &MovingSpec| -> Vec<f64> {
            spec.nodes().0.iter().map(|xi| spec.a_start * xi).collect()
        };
        let (fine, coarse) = (on(&spec), on(&spec.scaled(MESH_RATIO)));
        for h0 in [1.0, 2.0, 5.0] {
            let (f, c) = (rigid_gap(&fine, h0), rigid_gap(&coarse, h0));
            for (what, (value, exact), (coarse_value, _)) in [("u(0)", f.0, c.0), ("T", f.1, c.1)] {
                let richardson = value + (value - coarse_value) / (MESH_RATIO.powi(2) - 1.0);
                let (single, extrapolated) = (
                    (value - exact).abs() / exact.abs(),
                    (richardson - exact).abs() / exact.abs(),
                );
                println!(
                    "mu {mu}, h0 {h0}: {what} error {single:.2e} on the production mesh \
                     ({} nodes), {extrapolated:.2e} extrapolated",
                    fine.len()
                );
                assert!(single < 1e-3, "mu {mu}, h0 {h0}, {what}: {single:e}");
                assert!(
                    extrapolated < 1e-4,
                    "mu {mu}, h0 {h0}, {what}: {extrapolated:e}"
                );
            }
        }
    }
}

/// Displacement at x = 1 for the rigid gap 1 + y²/2 on a uniform mesh of spacing h.
fn u_at_1(h: f64) -> f64 {
    let n = (50.0 / h).round() as usize;
    let nodes: Vec<f64> = (0..=n).map(|i| 50.0 * i as f64 / n as f64).collect();
    let row = influence_row(1.0, &nodes);
    row.iter()
        .zip(&nodes)
        .map(|(m, y)| m * lj(1.0 + 0.5 * y * y))
        .sum()
}

#[test]
fn off_axis_displacement_converges_at_second_order() {
    // Piecewise-linear tractions: the error should fall 4x per halving of the spacing.
    let reference = u_at_1(0.003125);
    let errors: Vec<f64> = [0.05, 0.025, 0.0125]
        .iter()
        .map(|&h| (u_at_1(h) - reference).abs())
        .collect();
    let ratios = [errors[0] / errors[1], errors[1] / errors[2]];
    println!("u(1) errors {errors:?}, ratios {ratios:?}");
    for r in ratios {
        assert!(r > 3.0 && r < 5.5, "{ratios:?}");
    }
}

#[test]
fn hertz_pressure_gives_the_hertz_displacement() {
    // ∫₀¹ √(1 − s²) G(r, s) ds = (π²/16)(2 − r²) for r ≤ 1.
    let n = 4000;
    let nodes: Vec<f64> = (0..=n).map(|i| i as f64 / n as f64).collect();
    let m = influence_matrix(&nodes);
    let p: Vec<f64> = nodes
        .iter()
        .map(|&s| (1.0 - s * s).max(0.0).sqrt())
        .collect();
    for (i, &r) in nodes.iter().enumerate().step_by(400) {
        let u: f64 = (0..nodes.len()).map(|j| m[(i, j)] * p[j]).sum();
        let exact = PI * PI / 16.0 * (2.0 - r * r);
        assert!((u - exact).abs() < 1e-4 * exact, "r {r}: {u} vs {exact}");
    }
}
