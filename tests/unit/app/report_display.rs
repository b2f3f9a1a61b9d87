//! Tests of `tapsim::app::report::display` (src/app/report/display.rs).

use tapsim::app::report::display::*;

#[test]
fn zeros_and_round_off_print_as_zero() {
    assert_eq!(fixed(-0.00004, 4), "0");
    assert_eq!(fixed(0.0, 4), "0");
    assert_eq!(fixed(-0.00051, 4), "-0.0005");
    assert_eq!(fixed(90.000000000001, 4), "90.0000");
    assert_eq!(sci(-3.0459e-34, 4, 1.2566e-16), "0");
    assert_eq!(sci(0.0, 4, 0.0), "0");
    assert_eq!(sci(3.2782e-18, 4, 1.2566e-16), "3.2782e-18");
}
