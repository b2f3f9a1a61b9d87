//! Tests of `tapsim::app::units` (src/app/units.rs).

use tapsim::app::units::*;

#[test]
fn reads_units_and_prefixes() {
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
    assert!(close(parse("r", "10nm", Dimension::Length).unwrap(), 10e-9));
    assert!(close(parse("r", "1e-8", Dimension::Length).unwrap(), 1e-8));
    assert!(close(
        parse("E", "50 MPa", Dimension::Pressure).unwrap(),
        50e6
    ));
    assert!(close(
        parse("g", "50mJ/m^2", Dimension::SurfaceEnergy).unwrap(),
        0.05
    ));
    assert!(close(
        parse("k", "40N/m", Dimension::Stiffness).unwrap(),
        40.0
    ));
    assert!(close(
        parse("f", "300kHz", Dimension::Frequency).unwrap(),
        3e5
    ));
    assert!(close(
        parse("w", "1.5eV", Dimension::Energy).unwrap(),
        1.5 * tapsim::physics::params::ELECTRONVOLT_J
    ));
    for (text, seconds) in [
        ("1us", 1e-6),
        ("2.5 ns", 2.5e-9),
        ("3ms", 3e-3),
        ("1e-7", 1e-7),
    ] {
        assert!(
            close(parse("t", text, Dimension::Time).unwrap(), seconds),
            "{text}"
        );
    }
    for text in ["50Pa·s", "50 Pa*s", "0.05 kPa s", "50000mPas"] {
        assert!(
            close(parse("eta", text, Dimension::Viscosity).unwrap(), 50.0),
            "{text}"
        );
    }
}

#[test]
fn refuses_garbage() {
    assert!(parse("r", "ten", Dimension::Length).is_err());
    assert!(parse("r", "10 parsecs", Dimension::Length).is_err());
    assert!(parse("r", "NaN", Dimension::Length).is_err());
    assert!(parse("r", "inf", Dimension::Length).is_err());
    assert!(parse("mu", "5 m", Dimension::Dimensionless).is_err());
}
