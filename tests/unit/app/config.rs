//! Tests of `tapsim::app::config` (src/app/config.rs).

use clap::Args;
use tapsim::app::config::*;
use tapsim::app::units::Dimension;
use tapsim::physics::law::{LAW_PARAMS, LawKind, LawSpec};
use tapsim::physics::params::{self};

#[test]
fn every_numeric_flag_is_a_key_and_every_key_a_flag() {
    use clap::{Args, Command};
    let command = TapInputs::augment_args(Command::new("tap"));
    let mut flags: Vec<String> = command
        .get_arguments()
        .filter_map(|a| a.get_long().map(str::to_string))
        .filter(|long| !["config", "law"].contains(&long.as_str()))
        .collect();
    // The setpoint keys are flags of `tap` and `map` alone (the other commands
    // refuse them).
    let mut keys: Vec<String> = FIELDS
        .iter()
        .map(|f| f.0.to_string())
        .filter(|k| !["setpoint", "amplitude-setpoint"].contains(&k.as_str()))
        .chain(LAW_PARAMS.iter().map(|p| p.key.to_string()))
        .collect();
    flags.sort();
    keys.sort();
    assert_eq!(flags, keys);
    // And each key reaches its own field.
    for (key, _, slot) in FIELDS {
        let mut inputs = TapInputs::default();
        *slot(&mut inputs) = Some(1.0);
        let set: Vec<&str> = FIELDS
            .iter()
            .filter(|(_, _, other)| other(&mut inputs).is_some())
            .map(|f| f.0)
            .collect();
        assert_eq!(set, [*key]);
    }
}

#[test]
fn every_law_parameter_of_the_registry_reaches_the_law_spec() {
    for (i, param) in LAW_PARAMS.iter().enumerate() {
        // Read in its own unit, through a key as through its flag.
        assert!(
            param.unit == "deg" || dimension(param) != Dimension::Dimensionless,
            "{}: unit {} has no dimension",
            param.key,
            param.unit
        );
        let mut by_key = TapInputs::default();
        by_key.set(param.key, "7").unwrap();
        let flag = format!("--{}", param.key);
        let by_flag = <TapInputs as clap::FromArgMatches>::from_arg_matches(
            &TapInputs::augment_args(clap::Command::new("tap"))
                .try_get_matches_from(["tap", flag.as_str(), "7"])
                .unwrap(),
        )
        .unwrap();
        for inputs in [by_key, by_flag] {
            let spec = LawSpec::from_values(LawKind::Hertz, inputs.law_params.0);
            let set: Vec<_> = spec.params().iter().map(|(_, v)| v.is_some()).collect();
            assert_eq!(set.iter().filter(|s| **s).count(), 1, "{}", param.key);
            assert_eq!(spec.params()[i].1, Some(7.0), "{}", param.key);
        }
    }
}

#[test]
fn toml_with_units_and_flags_over_it() {
    let file = TapInputs::from_toml(
        "law = \"dmt\"\nradius = \"10nm\"\nstiffness = 2\nsample-modulus = \"2GPa\"\n",
    )
    .unwrap();
    let flags = TapInputs {
        stiffness: Some(5.0),
        ..Default::default()
    };
    let (setup, _) = flags.or(file).resolve().unwrap();
    assert_eq!(setup.law.kind, LawKind::Dmt);
    assert!((setup.contact.radius_m - 10e-9).abs() < 1e-20);
    assert_eq!(setup.cantilever.stiffness_n_m, 5.0);
    let e = params::composite_modulus(169e9, 0.28, 2e9, 0.4).unwrap();
    assert!((setup.contact.modulus_pa - e).abs() < 1e-3);
}

#[test]
fn toml_errors_name_the_problem() {
    let e = TapInputs::from_toml("radis = 1").unwrap_err().to_string();
    assert!(e.contains("unknown key") && e.contains("radius"), "{e}");
    let e = TapInputs::from_toml("radius = \"10 furlongs\"")
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown unit"), "{e}");
    let e = TapInputs::from_toml("radius = [1]")
        .unwrap_err()
        .to_string();
    assert!(e.contains("number or a string"), "{e}");
    assert!(TapInputs::from_toml("radius = ").is_err());
    let e = TapInputs::from_toml("law = \"magic\"")
        .unwrap_err()
        .to_string();
    assert!(e.contains("hybrid"), "{e}");
}
