//! Tests of `tapsim::dynamics::setup` (src/dynamics/setup.rs).

use tapsim::dynamics::setup::*;

#[test]
fn values_in_messages_read_as_a_person_writes_them() {
    assert_eq!(significant(0.0), "0");
    assert_eq!(significant(0.5), "0.5");
    assert_eq!(significant(1e-13), "1e-13");
    assert_eq!(significant(1e7), "1e7");
    assert_eq!(significant(-1.0 / 3e5), "-3.333e-6");
    assert_eq!(with_prefix(2e-8, "m"), "20 nm");
    assert_eq!(with_prefix(-2e-7, "m"), "-200 nm");
    assert_eq!(with_prefix(1e300, "m"), "1e300 m");
    assert_eq!(with_prefix(0.5, ""), "0.5");
}

#[test]
fn an_si_slip_is_refused_with_the_unit_it_probably_meant() {
    let mut setup = default_setup();
    setup.contact.radius_m = 20.0;
    let e = setup.check_plausible().unwrap_err().to_string();
    assert!(
        e.contains("20 m") && e.contains("did you mean 20nm?"),
        "{e}"
    );
    default_setup().check_plausible().unwrap();
}
