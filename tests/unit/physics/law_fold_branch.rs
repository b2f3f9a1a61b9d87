//! Tests of `tapsim::physics::law::fold_branch` (src/physics/law/fold_branch.rs).

use tapsim::physics::contact::jkr;
use tapsim::physics::law::fold_branch::*;

/// A made-up approach branch with a square-root fold at (1, 2).
fn made_up_approach() -> FoldBranch {
    FoldBranch::new(
        (1.0, 2.0),
        Side::Above,
        3.0,
        2001,
        FarField::Decay { kappa: 0.2 },
        |u| 2.0 - u + 0.1 * u * u,
    )
}

#[test]
fn work_is_the_antiderivative_everywhere() {
    let b = made_up_approach();
    for &alpha in &[0.2, 0.9, 1.0, 1.3, 5.0, 9.9, 10.5, 40.0] {
        let h = 1e-5;
        let dw = (b.work_hat(alpha + h) - b.work_hat(alpha - h)) / (2.0 * h);
        assert!(
            (dw - b.t_hat(alpha)).abs() < 1e-6,
            "{alpha}: {dw} vs {}",
            b.t_hat(alpha)
        );
    }
    assert_eq!(b.work_hat(1.0), 0.0);
}

#[test]
fn slope_is_the_derivative_of_the_force_everywhere() {
    let approach = made_up_approach();
    let contact = FoldBranch::new(
        (jkr::ALPHA_HAT_C, jkr::T_HAT_C),
        Side::Below,
        2.0,
        2001,
        FarField::JkrShift { shift: 0.0 },
        |u| jkr_force(jkr::ALPHA_HAT_C - u * u),
    );
    let check = |b: &FoldBranch, alpha: f64| {
        let h = 1e-6;
        let fd = (b.t_hat(alpha + h) - b.t_hat(alpha - h)) / (2.0 * h);
        let s = b.slope_hat(alpha);
        assert!(
            (s - fd).abs() < 1e-5 * (1.0 + fd.abs()),
            "{alpha}: {s} vs {fd}"
        );
    };
    for &alpha in &[0.2, 0.9, 1.3, 5.0, 9.9, 10.5, 40.0] {
        check(&approach, alpha);
    }
    for &alpha in &[-20.0, -3.9, -2.0, 0.0, 1.0, 1.5, 1.7, 3.0] {
        check(&contact, alpha);
        // The pair from one look-up is the two evaluations, to the bit.
        let both = contact.t_and_slope_hat(alpha);
        assert_eq!(both, (contact.t_hat(alpha), contact.slope_hat(alpha)));
    }
    for &alpha in &[0.2, 0.9, 1.0, 1.3, 5.0, 10.5, 40.0] {
        let both = approach.t_and_slope_hat(alpha);
        assert_eq!(both, (approach.t_hat(alpha), approach.slope_hat(alpha)));
    }
}
