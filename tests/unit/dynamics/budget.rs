//! Tests of `tapsim::dynamics::budget` (src/dynamics/budget.rs).

use tapsim::dynamics::budget::*;

#[test]
fn a_budget_is_spent_shared_when_nested_and_ended() {
    assert_eq!(left(), u64::MAX);
    let e = budgeted(STEPS, || {
        spend(STEPS - 10)?;
        budgeted(STEPS, || spend(5))?;
        assert_eq!(left(), 5);
        spend(6)
    })
    .unwrap_err();
    assert!(e.to_string().contains("work budget"), "{e}");
    assert_eq!(left(), u64::MAX);
    budgeted(7, || spend(7)).unwrap();
}
