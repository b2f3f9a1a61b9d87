//! Several eigenmodes from the command line: `tap`, `approach` and `contrast` with
//! `--modes`, parameter files with `[[mode]]` tables, refusals, and the guide's
//! numbers.

use crate::common;
use common::{json, num, refused, rows, scratch, tapsim};

#[test]
fn one_mode_is_todays_model_byte_for_byte() {
    let plain = tapsim(&["tap", "--json"]);
    let one = tapsim(&["tap", "--modes", "1", "--json"]);
    assert!(plain.status.success());
    assert_eq!(plain.stdout, one.stdout);
}

#[test]
fn bimodal_tap_reports_every_mode_and_the_readme_numbers() {
    let v = json(&["tap", "--modes", "2", "--json"]);
    assert_eq!(num(&v, "format_version"), 2.0);
    assert_eq!(num(&v, "common_period_periods"), 4.0);
    let modes = v["modes"].as_array().expect("a list of modes");
    assert_eq!(modes.len(), 2);
    for (i, m) in modes.iter().enumerate() {
        assert_eq!(num(m, "mode"), (i + 1) as f64);
        for key in [
            "resonance_hz",
            "drive_frequency_hz",
            "stiffness_n_m",
            "quality",
            "free_amplitude_m",
            "amplitude_m",
            "amplitude_ratio",
            "phase_deg",
            "e_drive_j",
            "e_damp_j",
            "e_exchange_j",
            "virial_j",
            "energy_balance_rel",
        ] {
            assert!(m[key].is_number(), "{key} of mode {}", i + 1);
        }
        assert!(num(m, "energy_balance_rel") <= 1e-6);
    }
    // The guide: φ₁ = 75.775°, A₂/A₀₂ = 0.4959 and φ₂ = 29.73° on the defaults; the second
    // mode at 1.875 MHz (25/4 f₀, the beam's 1.880 MHz moved by −0.27 %); E_ts 20.46 eV.
    assert!((num(&modes[0], "phase_deg") - 75.775).abs() < 5e-4);
    assert!((num(&modes[1], "amplitude_ratio") - 0.4959).abs() < 5e-5);
    assert!((num(&modes[1], "phase_deg") - 29.73).abs() < 5e-3);
    assert_eq!(num(&modes[1], "resonance_hz"), 1.875e6);
    assert!((num(&v, "e_ts_ev") - 20.46).abs() < 5e-3);
    assert_eq!(v["stable"], true);
    // The table says the same.
    let text = String::from_utf8(tapsim(&["tap", "--modes", "2"]).stdout).unwrap();
    assert!(
        text.contains("1875.000000 kHz simulated (-0.270 %"),
        "{text}"
    );
    assert!(text.contains("29.7323"), "{text}");
}

/// Drives with no common period (`--ratio-tolerance 0`: the beam's f₂ = 6.266893 f₀ as
/// it is): `tap` reports window averages, each with its error, and says what they are.
/// The guide: φ₂ = 29.80° and A₂/A₀₂ = 0.4972 there (29.73° and 0.4959 at 25/4).
/// The least separation is the orbit's, turning points inside integrator steps
/// included (issue 45: it was taken at segment ends only, the jump-in level on the
/// defaults). Against an independent integration of the same equations: −3.044 nm on
/// the defaults, −1.905 nm under Hertz at 14 nm; the one-mode orbit reaches −2.845 nm.
#[test]
fn the_least_separation_of_several_modes_is_the_orbits() {
    for (args, want_nm) in [
        (&[][..], -3.044),
        (&["--law", "hertz", "--separation", "14nm"][..], -1.905),
    ] {
        let v = json(&[&["tap", "--modes", "2", "--json"][..], args].concat());
        let got = num(&v, "min_separation_m") * 1e9;
        assert!((got - want_nm).abs() < 0.02, "{args:?}: {got} nm");
    }
}

#[test]
fn modes_without_a_common_period_are_averaged_over_windows() {
    let v = json(&["tap", "--modes", "2", "--ratio-tolerance", "0", "--json"]);
    assert!(v["motion"].as_str().unwrap().contains("no common period"));
    assert_eq!(v["converged"], true);
    assert_eq!(num(&v, "windows"), 8.0);
    let modes = v["modes"].as_array().expect("a list of modes");
    // The beam's second mode as it is, not moved to 25/4 f₀.
    assert!((num(&modes[1], "resonance_hz") - 1880.0679e3).abs() < 0.1);
    for m in modes {
        for key in [
            "amplitude_ratio",
            "amplitude_ratio_std_err",
            "phase_deg",
            "phase_std_err_deg",
            "e_exchange_j",
            "e_exchange_std_err_j",
        ] {
            assert!(m[key].is_number(), "{key}");
        }
        // The guide: errors below 1e-6°, far below the digits printed.
        assert!(num(m, "phase_std_err_deg") < 1e-6);
    }
    assert!((num(&modes[1], "phase_deg") - 29.80).abs() < 5e-3);
    assert!((num(&modes[1], "amplitude_ratio") - 0.4972).abs() < 5e-5);
    assert!((num(&modes[0], "phase_deg") - 75.772).abs() < 5e-4);
    let text = String::from_utf8(tapsim(&["tap", "--modes", "2", "--ratio-tolerance", "0"]).stdout)
        .unwrap();
    assert!(text.contains("have no common period"), "{text}");
}

#[test]
fn a_parameter_files_modes_are_its_flags() {
    let dir = scratch("modes");
    let cfg = dir.join("bimodal.toml");
    std::fs::write(
        &cfg,
        "modes = 2\nratio-tolerance = 0.001\n[[mode]]\nquality = 500\nfree-amplitude = \"0.2 nm\"\n",
    )
    .unwrap();
    let from_file = json(&["tap", "--config", cfg.to_str().unwrap(), "--json"]);
    let from_flags = json(&[
        "tap",
        "--modes",
        "2",
        "--ratio-tolerance",
        "0.001",
        "--mode2-quality",
        "500",
        "--drive2-amplitude",
        "0.2nm",
        "--json",
    ]);
    assert_eq!(from_file, from_flags);
    assert_eq!(num(&from_file, "common_period_periods"), 11.0);
    assert_eq!(num(&from_file["modes"][1], "quality"), 500.0);
    // A command that does not simulate several modes refuses the file.
    refused(
        &["branches", "--config", cfg.to_str().unwrap()],
        "asks for several eigenmodes",
    );
    // Flags win over the file: one mode.
    let one = json(&[
        "tap",
        "--config",
        cfg.to_str().unwrap(),
        "--modes",
        "1",
        "--json",
    ]);
    assert!(one.get("modes").is_none());
    for (toml, says) in [
        ("modes = 7\n", "whole number from 1 to 3"),
        (
            "[[mode]]\nfoo = 1\n",
            "unknown key `foo` in a [[mode]] table",
        ),
        ("mode = 3\n", "`[[mode]]` tables"),
    ] {
        std::fs::write(&cfg, toml).unwrap();
        refused(&["tap", "--config", cfg.to_str().unwrap()], says);
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn several_modes_refuse_what_they_do_not_report() {
    refused(
        &["tap", "--modes", "2", "--plot", "x.png"],
        "--plot is for one mode",
    );
    refused(
        &["tap", "--modes", "2", "--temperature", "300K"],
        "--temperature is for one mode",
    );
    refused(&["tap", "--drive2-amplitude", "1nm"], "need --modes 2 or 3");
    let out = tapsim(&["tap", "--modes", "4"]);
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("1..=3"));
    refused(
        &["tap", "--modes", "2", "--mode2-quality", "-3"],
        "mode quality factor",
    );
    refused(
        &["tap", "--modes", "2", "--mode2-quality", "1e12"],
        "outside 0.5 to 1e7",
    );
    refused(
        &["tap", "--modes", "2", "--mode2-resonance", "1e12"],
        "at most 100",
    );
    refused(
        &["tap", "--modes", "2", "--mode2-stiffness", "1e-9"],
        "modal mass",
    );
    refused(
        &["tap", "--modes", "2", "--mode2-resonance", "310kHz"],
        "must be ordered",
    );
    // Drives with no common period have no orbit to follow or hold at a setpoint:
    // only `tap` at a separation averages them over windows.
    for command in [
        &["approach", "--modes", "2"][..],
        &["contrast", "--modes", "2"],
        &["map", "--modes", "2"],
        &["tap", "--modes", "2", "--setpoint", "0.8"],
    ] {
        let mut args = command.to_vec();
        args.extend([
            "--mode2-resonance",
            "1.88312345MHz",
            "--ratio-tolerance",
            "1e-9",
        ]);
        refused(&args, "no common denominator");
    }
    refused(
        &["approach", "--modes", "2", "--sweep", "setpoint"],
        "--sweep setpoint is for one mode",
    );
    refused(
        &["tap", "--modes", "2", "--law", "hertz", "--viscosity", "1"],
        "rate-independent",
    );
    refused(
        &["scan", "--modes", "2", "--temperature", "300K"],
        "--temperature is for one mode",
    );
    refused(
        &["scan", "--modes", "2", "--drive2-amplitude", "0"],
        "mode 2 is not driven",
    );
    refused(
        &[
            "map",
            "--modes",
            "2",
            "--setpoint",
            "0.8",
            "--branch",
            "all",
        ],
        "a map is solved on one branch",
    );
}

#[test]
fn a_bimodal_approach_lists_both_phases() {
    let dir = scratch("modes-approach");
    let csv = dir.join("a.csv");
    let v = json(&[
        "approach",
        "--modes",
        "2",
        "--points",
        "4",
        "--from",
        "16nm",
        "--to",
        "10nm",
        "--no-retract",
        "--csv",
        csv.to_str().unwrap(),
        "--json",
        "-q",
    ]);
    let points = rows(&v);
    assert_eq!(points.len(), 4);
    let mut last = f64::INFINITY;
    for p in &points {
        let a1 = num(p, "amplitude1_ratio");
        assert!(a1 < last, "the amplitude falls on approach");
        last = a1;
        assert!(
            num(p, "phase2_deg") < 90.0,
            "the contact stiffens the second mode"
        );
    }
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("separation_m,direction,amplitude1_ratio,phase1_deg"));
    std::fs::remove_dir_all(dir).unwrap();
}

/// The guide: the bimodal contrast B − A at A₁/A₀₁ = 0.8 under each law, on the repulsive
/// branch; on the attractive one, under the hybrid law, B's higher modes hold the setpoint
/// in two coexisting states, and no phase of B is given.
#[test]
fn the_readme_bimodal_contrast() {
    let v = json(&[
        "contrast",
        "--modes",
        "2",
        "--setpoints",
        "0.8",
        "--json",
        "-q",
    ]);
    let expect = [
        ("jkr", -5.542, -8.166),
        ("hybrid", -4.717, -2.807),
        ("lj", -5.018, -2.834),
    ];
    let rows = rows(&v);
    let repulsive: Vec<_> = rows.iter().filter(|r| r["branch"] == "repulsive").collect();
    assert_eq!(repulsive.len(), 3);
    for (row, (law, d2, d1)) in repulsive.into_iter().zip(expect) {
        assert_eq!(row["law"], law);
        assert!((num(row, "delta_phase2_deg") - d2).abs() < 5e-4, "{row}");
        assert!((num(row, "delta_phase1_deg") - d1).abs() < 5e-4, "{row}");
    }
    // The guide: on the attractive branch under the hybrid law, Δφ₂ = −25.498°,
    // Δφ₁ = +2.632° (what the scan shows, `a_bimodal_scan_rests_on_…`).
    let hybrid = rows
        .iter()
        .find(|r| r["branch"] == "attractive" && r["law"] == "hybrid")
        .expect("the hybrid law's attractive row");
    assert!(
        (num(hybrid, "delta_phase2_deg") + 25.498).abs() < 5e-4,
        "{hybrid}"
    );
    assert!(
        (num(hybrid, "delta_phase1_deg") - 2.632).abs() < 5e-4,
        "{hybrid}"
    );
}

/// `scan --modes 2` over the built-in blend: the loop engaged from above rests on each
/// polymer in a state `tap --modes 2 --setpoint 0.8` lists for it (the attractive one),
/// its topography at that state's z_c within 0.01 nm and φ₁, φ₂ within 0.01°.
#[test]
fn a_bimodal_scan_rests_on_states_the_setpoint_solver_lists() {
    let v = json(&[
        "scan",
        "--modes",
        "2",
        "--pixels",
        "8",
        "--line-rate",
        "40",
        "--no-retrace",
        "--json",
        "-q",
    ]);
    let pixels = rows(&v);
    assert_eq!(pixels.len(), 8);
    for (pixel, material) in [
        (3, &[][..]),
        (
            7,
            &["--sample-modulus", "1GPa", "--work-of-adhesion", "0.08"][..],
        ),
    ] {
        let p = &pixels[pixel];
        let (phi1, phi2, z) = (
            num(p, "phase_deg"),
            num(&p["modes"][0], "phase_deg"),
            num(p, "topography_m"),
        );
        let listed = json(
            &[
                &["tap", "--modes", "2", "--setpoint", "0.8", "--json"][..],
                material,
            ]
            .concat(),
        );
        let states = listed["states"].as_array().unwrap();
        let matching = states.iter().find(|s| {
            (num(&s["modes"][0], "phase_deg") - phi1).abs() < 0.01
                && (num(&s["modes"][1], "phase_deg") - phi2).abs() < 0.01
                && (num(s, "separation_m") - z).abs() < 0.01e-9
        });
        assert!(
            matching.is_some(),
            "pixel {pixel}: φ₁ {phi1}, φ₂ {phi2}, z {z:e} among {states:?}"
        );
    }
    // The guide: the scan's contrast B − A, Δφ₂ = −25.5°, Δφ₁ = +2.6°.
    let delta = |f: &dyn Fn(&serde_json::Value) -> f64| f(&pixels[7]) - f(&pixels[3]);
    let d2 = delta(&|p| num(&p["modes"][0], "phase_deg"));
    let d1 = delta(&|p| num(p, "phase_deg"));
    assert!(
        (d2 + 25.5).abs() < 0.05 && (d1 - 2.6).abs() < 0.05,
        "{d2} {d1}"
    );
}

/// `map --modes 2`: every cell with a state is `tap --modes 2` at that cell, bit for bit;
/// a cell without one says why.
#[test]
fn a_bimodal_map_is_tap_cell_by_cell() {
    let v = json(&["map", "--modes", "2", "--steps", "3", "--json", "-q"]);
    let cells = rows(&v);
    assert_eq!(cells.len(), 9);
    let mut compared = 0;
    for c in &cells {
        if c["phase2_deg"].is_null() {
            assert!(c["note"].is_string(), "{c}");
            continue;
        }
        let (w, e) = (num(c, "work_of_adhesion_j_m2"), num(c, "modulus_pa"));
        let t = json(&[
            "tap",
            "--modes",
            "2",
            "--work-of-adhesion",
            &w.to_string(),
            "--modulus",
            &e.to_string(),
            "--json",
        ]);
        assert_eq!(c["phase2_deg"], t["modes"][1]["phase_deg"]);
        assert_eq!(c["phase1_deg"], t["modes"][0]["phase_deg"]);
        assert_eq!(c["e_ts_j"], t["e_ts_j"]);
        compared += 1;
    }
    assert!(compared >= 3, "{compared} cells with a state");
}
