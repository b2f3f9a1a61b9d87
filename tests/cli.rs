//! The `tapsim` command line, run as a user would.

use crate::common;
use common::{cells, json, json_of, num, scratch, tapsim};
use std::path::PathBuf;
use std::process::{Command, Output};

/// Run `args`, asserting success.
fn succeeds(args: &[&str]) -> Output {
    let out = tapsim(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Each command fails, and says what its needle says.
fn refused(cases: &[(Vec<&str>, &str)]) {
    for (args, needle) in cases {
        let out = tapsim(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains(needle),
            "{args:?}: {err}"
        );
    }
}

/// Run `args` with the Lennard-Jones cache in `cache` (a test's own), asserting success.
fn succeeds_with_cache(args: &[&str], cache: &std::path::Path) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_tapsim"))
        .args(args)
        .env("TAPSIM_CACHE", cache)
        .output()
        .expect("the binary runs");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// `tap --json` on a parameter file holding `toml` (written in a scratch directory
/// `name`) gives the E_ts that `from_flags` reported.
fn a_file_gives_what_the_flags_give(name: &str, toml: &str, from_flags: &serde_json::Value) {
    let dir = scratch(name);
    let cfg = dir.join("parameters.toml");
    std::fs::write(&cfg, toml).unwrap();
    let w = json(&["tap", "--config", cfg.to_str().unwrap(), "--json"]);
    assert_eq!(w["e_ts_j"], from_flags["e_ts_j"], "{toml}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn hysteresis_json_has_the_documented_keys() {
    let v = json(&["hysteresis", "--mu", "5", "--json"]);
    for key in [
        "tabor_mu",
        "alpha_hat_a",
        "a_hat_a",
        "alpha_hat_c",
        "a_hat_c",
        "t_hat_c",
        "w_hat_hybrid",
        "w_hat_jkr",
    ] {
        num(&v, key);
    }
    assert_eq!(num(&v, "tabor_mu"), 5.0);
    assert!((num(&v, "w_hat_jkr") - 7.0922).abs() < 5e-5);
    assert!((num(&v, "w_hat_hybrid") - 3.2062).abs() < 5e-4);
    assert!(v.get("k_hat").is_none() && v.get("w_j").is_none());
}

#[test]
fn hysteresis_with_stiffness_adds_the_spring_keys() {
    let v = json(&["hysteresis", "--mu", "5", "--k-hat", "2", "--json"]);
    for key in ["k_hat", "a_hat_b_spring", "a_hat_c_spring", "w_hat_spring"] {
        num(&v, key);
    }
    assert!(num(&v, "w_hat_spring") > num(&v, "w_hat_hybrid"));
}

#[test]
fn si_inputs_derive_mu_and_give_joules() {
    // R = 10 nm, E* = 1 GPa, Δγ = 50 mJ/m², ε = 0.3 nm, k = 40 N/m.
    let v = json(&[
        "hysteresis",
        "--radius",
        "10nm",
        "--modulus",
        "1GPa",
        "--work-of-adhesion",
        "50mJ/m^2",
        "--range",
        "0.3nm",
        "--stiffness",
        "40N/m",
        "--json",
    ]);
    let mu = (10e-9f64 * 0.05 * 0.05 / 1e18).cbrt() / 0.3e-9;
    assert!((num(&v, "tabor_mu") - mu).abs() < 1e-12 * mu);
    let k_hat = mu * 0.3e-9 * 40.0 / (10e-9 * 0.05);
    assert!((num(&v, "k_hat") - k_hat).abs() < 1e-9 * k_hat);
    let scale = mu * 0.3e-9 * 10e-9 * 0.05;
    assert!((num(&v, "w_j") - num(&v, "w_hat_spring") * scale).abs() < 1e-12 * num(&v, "w_j"));
    assert!((num(&v, "w_ev") * 1.602_176_634e-19 - num(&v, "w_j")).abs() < 1e-30);
    // The old key, kept for one release, is the same number.
    assert_eq!(num(&v, "w_joule"), num(&v, "w_j"));
    // Same result with plain SI numbers.
    let plain = json(&[
        "hysteresis",
        "--radius",
        "1e-8",
        "--modulus",
        "1e9",
        "--work-of-adhesion",
        "0.05",
        "--range",
        "3e-10",
        "--stiffness",
        "40",
        "--json",
    ]);
    assert!((num(&plain, "w_j") - num(&v, "w_j")).abs() < 1e-9 * num(&v, "w_j"));
}

#[test]
fn tip_and_sample_moduli_combine() {
    let v = json(&[
        "hysteresis",
        "--radius",
        "10nm",
        "--tip-modulus",
        "169GPa",
        "--tip-poisson",
        "0.28",
        "--sample-modulus",
        "2GPa",
        "--sample-poisson",
        "0.4",
        "--work-of-adhesion",
        "0.05",
        "--range",
        "0.3nm",
        "--json",
    ]);
    let e_star = 1.0 / ((1.0 - 0.28f64.powi(2)) / 169e9 + (1.0 - 0.4f64.powi(2)) / 2e9);
    assert!((num(&v, "modulus_pa") - e_star).abs() < 1e-6 * e_star);
}

#[test]
fn small_mu_reports_no_hysteresis_with_a_reason() {
    let v = json(&["hysteresis", "--mu", "0.8", "--json"]);
    assert_eq!(v["hysteresis"], serde_json::Value::Bool(false));
    assert_eq!(num(&v, "w_hat_hybrid"), 0.0);
    assert!(v["a_hat_a"].is_null());
    assert!(v["note"].as_str().unwrap().contains("no hysteresis"));
    let text = tapsim(&["hysteresis", "--mu", "0.8"]);
    assert!(text.status.success());
    assert!(String::from_utf8_lossy(&text.stdout).contains("no hysteresis"));
}

#[test]
fn default_run_uses_mu_5_and_says_so() {
    let out = tapsim(&["hysteresis"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("5.000000  (default"), "{text}");
    assert!(text.contains("7.092196"), "{text}");
}

#[test]
fn bad_input_is_a_clear_error_not_a_panic() {
    let cases: &[&[&str]] = &[
        &["hysteresis", "--mu", "0"],
        &["hysteresis", "--mu", "-2"],
        &["hysteresis", "--mu", "NaN"],
        &["hysteresis", "--mu", "five"],
        &["hysteresis", "--mu", "5", "--k-hat", "0"],
        &["hysteresis", "--mu", "5", "--k-hat", "-1"],
        &["hysteresis", "--mu", "5", "--stiffness", "40"],
        &[
            "hysteresis",
            "--radius",
            "-10nm",
            "--modulus",
            "1GPa",
            "--work-of-adhesion",
            "0.05",
            "--range",
            "0.3nm",
        ],
        &[
            "hysteresis",
            "--radius",
            "0",
            "--modulus",
            "1GPa",
            "--work-of-adhesion",
            "0.05",
            "--range",
            "0.3nm",
        ],
        &["hysteresis", "--radius", "10nm", "--modulus", "1GPa"],
        &[
            "hysteresis",
            "--radius",
            "10 parsecs",
            "--modulus",
            "1GPa",
            "--work-of-adhesion",
            "0.05",
            "--range",
            "0.3nm",
        ],
        &["hysteresis", "--mu", "5", "--radius", "10nm"],
        &["figure", "0", "--out", "/tmp/tapsim-never-written"],
        &["figure", "9"],
        &["figure", "seven"],
    ];
    for args in cases {
        let out = tapsim(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(stderr.contains("error"), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(out.stdout.is_empty(), "{args:?} printed to stdout");
    }
    assert!(!std::path::Path::new("/tmp/tapsim-never-written").exists());
}

#[test]
fn negative_values_are_refused_with_the_reason() {
    for (args, needle) in [
        (
            &["hysteresis", "--mu", "-2"][..],
            "mu = -2: must be greater than zero",
        ),
        (
            &["hysteresis", "--mu", "5", "--k-hat", "-1"][..],
            "k_hat = -1: must be greater than zero",
        ),
        (
            &[
                "hysteresis",
                "--radius",
                "-10nm",
                "--modulus",
                "1GPa",
                "--work-of-adhesion",
                "0.05",
                "--range",
                "0.3nm",
            ][..],
            "radius",
        ),
    ] {
        let out = tapsim(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.contains(needle) && stderr.contains("greater than zero"),
            "{args:?}: {stderr}"
        );
    }
}

#[test]
fn figure_all_writes_csv_png_svg_for_each_figure() {
    let dir = scratch("figures");
    // A cache of its own, so the Lennard-Jones points of Figs. 2-4 are computed here.
    let out = succeeds_with_cache(
        &["figure", "all", "--out", dir.to_str().unwrap()],
        &dir.join("cache"),
    );
    let listed: Vec<PathBuf> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(PathBuf::from)
        .collect();
    assert_eq!(listed.len(), 19, "{listed:?}");
    for path in &listed {
        let bytes = std::fs::read(path).unwrap();
        assert!(!bytes.is_empty(), "{path:?} empty");
        match path.extension().and_then(|e| e.to_str()) {
            Some("png") => assert_eq!(&bytes[1..4], b"PNG"),
            Some("svg") => assert!(String::from_utf8_lossy(&bytes).contains("<svg")),
            Some("csv") => {
                let mut r = csv::Reader::from_reader(bytes.as_slice());
                let columns = r.headers().unwrap().len();
                assert!(
                    columns == 3 || path.ends_with("fig3_lj_vs_fit.csv"),
                    "{path:?}"
                );
                let rows = r.records().map(|r| r.unwrap()).collect::<Vec<_>>();
                assert!(rows.len() > 5, "{path:?}");
                for row in rows {
                    // Every cell but the series name is a number.
                    for cell in row.iter().skip(usize::from(columns == 3)) {
                        cell.parse::<f64>().unwrap();
                    }
                }
            }
            other => panic!("unexpected file {other:?}"),
        }
    }
    // The cache was filled, and no temporary files are left behind.
    assert!(std::fs::read_dir(dir.join("cache")).unwrap().count() >= 6);
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .filter(|n| n != "cache")
        .collect();
    assert_eq!(names.len(), 19, "{names:?}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn fig6_csv_holds_the_curves_of_eq_26() {
    let dir = scratch("fig6");
    let out = tapsim(&["figure", "6", "--out", dir.to_str().unwrap()]);
    assert!(out.status.success());
    let mut r = csv::Reader::from_path(dir.join("fig6_hysteresis_vs_stiffness.csv")).unwrap();
    let mut checked = 0;
    for row in r.records() {
        let row = row.unwrap();
        if row[0].starts_with("μ = 5 (26)") {
            let (k, w): (f64, f64) = (row[1].parse().unwrap(), row[2].parse().unwrap());
            let expect = tapsim::contact::spring::hysteresis(5.0, k, Default::default())
                .unwrap()
                .w_hat;
            // To the CSV's 10 significant digits (docs/src/reference/output.md): half a unit
            // of the tenth digit in Ŵ, and as much again through k̂, whose rounding moves
            // Ŵ by at most as much relatively (|d ln Ŵ/d ln k̂| ≤ 1: Ŵ = Ŵ_rigid + c/k̂).
            assert!((w - expect).abs() <= 1e-9 * expect, "{k}: {w} {expect}");
            checked += 1;
        }
    }
    assert_eq!(checked, 200);
    // The numerical Lennard-Jones points through the same spring, for μ = 2, 5, 10, 20.
    let solution = tapsim::contact::lj::solve(5.0, tapsim::contact::lj::Reach::Springs).unwrap();
    let mut r = csv::Reader::from_path(dir.join("fig6_hysteresis_vs_stiffness.csv")).unwrap();
    let mut lj = std::collections::BTreeMap::new();
    for row in r.records() {
        let row = row.unwrap();
        if row[0].contains("Lennard-Jones") {
            *lj.entry(row[0].to_string()).or_insert(0) += 1;
            if row[0].starts_with("μ = 5,") {
                let (k, w): (f64, f64) = (row[1].parse().unwrap(), row[2].parse().unwrap());
                let expect = solution.spring_loop(k).unwrap().w_hat;
                // To the CSV's digits, as above.
                assert!((w - expect).abs() <= 1e-9 * expect, "{k}: {w} {expect}");
            }
        }
    }
    assert_eq!(lj.len(), 4, "{lj:?}");
    let per_mu = tapsim::figures::FIG6_LJ_K_HATS.len();
    assert!(lj.values().all(|&n| n == per_mu), "{lj:?}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn help_teaches_units_and_equations() {
    let out = tapsim(&["hysteresis", "--help"]);
    let text = String::from_utf8_lossy(&out.stdout);
    for needle in ["eq. (2)", "(22)", "N/m", "--json", "w_hat_spring"] {
        assert!(text.contains(needle), "help lacks {needle}");
    }
}

#[test]
fn tap_json_has_the_documented_keys() {
    let v = json(&["tap", "--json"]);
    for key in [
        "amplitude_m",
        "amplitude_ratio",
        "phase_deg",
        "phase_from_energy_deg",
        "e_ts_j",
        "e_ts_ev",
        "e_damp_j",
        "e_drive_j",
        "energy_balance_rel",
        "virial_j",
        "mean_force_n",
        "peak_force_n",
        "min_separation_m",
        "contact_fraction",
        "loop_area_j",
        "tabor_mu",
    ] {
        num(&v, key);
    }
    // Settled by Newton's method on the period map: at most 20 periods in all.
    let cycles = v["cycles"].as_u64().unwrap();
    assert!((3..=20).contains(&cycles), "{cycles} cycles");
    assert_eq!(v["converged"], serde_json::Value::Bool(true));
    assert_eq!(v["law"], "hybrid");
    // A stable period-1 orbit, reported over its one period with no statistical error.
    assert_eq!(v["regime"], "period-1");
    assert_eq!(v["period"], 1);
    assert_eq!(v["periods_averaged"], 1);
    assert_eq!(v["stable"], serde_json::Value::Bool(true));
    // Harmonics 2…10 of the orbit, each with its amplitudes and phases.
    let harmonics = v["harmonics"].as_array().expect("harmonics");
    assert_eq!(harmonics.len(), 9);
    for (n, h) in (2..).zip(harmonics) {
        assert_eq!(h["order"], n);
        for key in ["deflection_amplitude_m", "force_amplitude_n"] {
            assert!(num(h, key) > 0.0, "harmonic {n}: {key}");
        }
        for key in ["deflection_phase_deg", "force_phase_deg"] {
            assert!(num(h, key).abs() <= 180.0, "harmonic {n}: {key}");
        }
    }
    let multipliers = v["floquet_multipliers"].as_array().unwrap();
    assert_eq!(multipliers.len(), 2);
    for m in multipliers {
        let (re, im) = (m[0].as_f64().unwrap(), m[1].as_f64().unwrap());
        assert!(re.hypot(im) < 1.0, "{m}");
    }
    for key in ["amplitude_std_err_m", "phase_std_err_deg", "e_ts_std_err_j"] {
        assert_eq!(num(&v, key), 0.0, "{key}");
    }
    // The default tap is in contact and dissipates the hybrid loop.
    assert!((num(&v, "e_ts_j") / num(&v, "loop_area_j") - 1.0).abs() < 1e-5);
}

#[test]
fn tap_writes_trajectory_and_plots() {
    let dir = scratch("tap");
    let traj = dir.join("traj.csv");
    let png = dir.join("tap.png");
    let svg = dir.join("tap.svg");
    for plot in [&png, &svg] {
        let out = tapsim(&[
            "tap",
            "--law",
            "jkr",
            "--separation",
            "12nm",
            "--trajectory",
            traj.to_str().unwrap(),
            "--plot",
            plot.to_str().unwrap(),
            "--record-cycles",
            "2",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let mut r = csv::Reader::from_path(&traj).unwrap();
    assert_eq!(
        r.headers().unwrap().iter().collect::<Vec<_>>(),
        ["t_s", "z_m", "v_m_s", "alpha_m", "force_n", "branch"]
    );
    let rows: Vec<_> = r.records().map(|r| r.unwrap()).collect();
    let t_end: f64 = rows.last().unwrap()[0].parse().unwrap();
    // Two periods of a 300 kHz cantilever.
    assert!((t_end - 2.0 / 300e3).abs() < 1e-9, "{t_end}");
    assert!(rows.iter().any(|r| &r[5] == "contact") && rows.iter().any(|r| &r[5] == "free"));
    assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");
    assert!(String::from_utf8_lossy(&std::fs::read(&svg).unwrap()).contains("<svg"));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn tap_reads_a_toml_config_and_flags_win() {
    let dir = scratch("config");
    std::fs::create_dir_all(&dir).unwrap();
    let cfg = dir.join("p.toml");
    std::fs::write(
        &cfg,
        "law = \"hertz\"\nseparation = \"14nm\"\nquality = 300\nstiffness = \"2N/m\"\n",
    )
    .unwrap();
    let v = json(&[
        "tap",
        "--config",
        cfg.to_str().unwrap(),
        "--stiffness",
        "40",
        "--json",
    ]);
    assert_eq!(v["law"], "hertz");
    let direct = json(&[
        "tap",
        "--law",
        "hertz",
        "--separation",
        "14e-9",
        "--quality",
        "300",
        "--json",
    ]);
    assert_eq!(num(&v, "amplitude_m"), num(&direct, "amplitude_m"));
    std::fs::write(&cfg, "radius = \"10 parsecs\"\n").unwrap();
    let out = tapsim(&["tap", "--config", cfg.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("unknown unit") && stderr.contains("p.toml"),
        "{stderr}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn tap_bad_input_is_a_clear_error() {
    let cases: &[(&[&str], &str)] = &[
        (&["tap", "--stiffness", "0"], "stiffness"),
        (&["tap", "--quality", "0"], "quality"),
        (&["tap", "--quality", "-5"], "quality"),
        (&["tap", "--free-amplitude", "-1nm"], "free amplitude"),
        (&["tap", "--resonance", "NaN"], "finite"),
        (&["tap", "--separation", "inf"], "finite"),
        (
            &["tap", "--config", "/nonexistent/p.toml"],
            "/nonexistent/p.toml",
        ),
        (&["tap", "--plot", "/tmp/x.gif"], ".png or .svg"),
        (
            &["tap", "--work-of-adhesion", "0.01", "--modulus", "3GPa"],
            "use the DMT law",
        ),
    ];
    for (args, needle) in cases {
        let out = tapsim(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    assert!(!std::path::Path::new("/tmp/x.gif").exists());
}

#[test]
fn shipped_example_config_runs() {
    let cfg = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/polymer.toml");
    let v = json(&["tap", "--config", cfg, "--json"]);
    assert_eq!(v["converged"], serde_json::Value::Bool(true));
    assert!((num(&v, "amplitude_ratio") - 0.9).abs() < 0.02);
}

#[test]
fn approach_json_is_one_object_of_equal_length_arrays() {
    let v = json(&[
        "approach", "--points", "6", "--from", "22nm", "--to", "12nm", "--json", "--quiet",
    ]);
    let obj = v.as_object().unwrap();
    for key in [
        "separation_m",
        "direction",
        "amplitude_m",
        "amplitude_ratio",
        "phase_deg",
        "e_ts_j",
        "virial_j",
        "mean_force_n",
        "peak_force_n",
        "converged",
    ] {
        assert_eq!(
            obj[key].as_array().unwrap_or_else(|| panic!("{key}")).len(),
            12,
            "{key}"
        );
    }
    assert_eq!(obj["direction"][0], "approach");
    assert_eq!(obj["direction"][11], "retract");
}

/// `approach --normalize` adds each mechanism's E/E_max (null for one that dissipates
/// nothing in the sweep) and draws the identification curves first.
#[test]
fn approach_normalize_adds_each_mechanisms_share_of_its_largest() {
    let args = [
        "approach",
        "--points",
        "6",
        "--from",
        "22nm",
        "--to",
        "12nm",
        "--json",
        "--quiet",
        "--normalize",
    ];
    let v = json(&args);
    let (norm, e_ts) = (
        v["e_ts_norm"].as_array().unwrap(),
        v["e_ts_j"].as_array().unwrap(),
    );
    assert_eq!(norm.len(), 12);
    let e_max = e_ts.iter().map(|e| e.as_f64().unwrap()).fold(0.0, f64::max);
    assert!(e_max > 0.0);
    for (n, e) in norm.iter().zip(e_ts) {
        let expected = e.as_f64().unwrap() / e_max;
        assert!((n.as_f64().unwrap() - expected).abs() <= 1e-12 * expected.max(1.0));
    }
    assert_eq!(
        v["e_ts_adhesion_norm"], v["e_ts_norm"],
        "the hybrid's one mechanism"
    );
    assert!(
        v["e_ts_viscous_norm"]
            .as_array()
            .unwrap()
            .iter()
            .all(|x| x.is_null())
    );
    // The table gains a column; the plot its identification panel.
    let table = tapsim(&[
        "approach",
        "--points",
        "6",
        "--from",
        "22nm",
        "--to",
        "12nm",
        "--quiet",
        "--normalize",
    ]);
    let text = String::from_utf8_lossy(&table.stdout);
    assert!(
        text.lines().next().unwrap().ends_with("E_ts/E_max"),
        "{text}"
    );
    let dir = scratch("normalize");
    let csv = dir.join("id.csv");
    succeeds(&[
        "approach",
        "--points",
        "4",
        "--quiet",
        "--normalize",
        "--plot",
        dir.join("id.svg").to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ]);
    let svg = std::fs::read_to_string(dir.join("id.svg")).unwrap();
    assert!(svg.contains("identification curves"));
    let header = std::fs::read_to_string(&csv).unwrap();
    assert!(header.lines().next().unwrap().contains("e_ts_viscous_norm"));
}

#[test]
#[ignore = "slow (every figure and table of results/ regenerated, about 35 s in release): run with cargo test --release -- --ignored cli::"]
fn reproduce_regenerates_every_file_its_readme_lists() {
    let dir = scratch("reproduce");
    let out = succeeds_with_cache(
        &[
            "reproduce",
            "--quiet",
            "--json",
            "--out",
            dir.to_str().unwrap(),
        ],
        &std::env::temp_dir().join(format!("tapsim-test-cache-{}", std::process::id())),
    );
    let manifest: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let readme = std::fs::read_to_string(dir.join("README.md")).unwrap();
    let listed: Vec<&str> = readme
        .lines()
        .filter_map(|l| l.strip_prefix("| `").and_then(|r| r.split('`').next()))
        .collect();
    assert!(listed.len() >= 25, "{listed:?}");
    for name in &listed {
        let path = dir.join(name);
        let bytes = std::fs::read(&path).unwrap_or_else(|_| panic!("{name} listed but missing"));
        assert!(!bytes.is_empty(), "{name} is empty");
        if name.ends_with(".csv") {
            let mut r = csv::Reader::from_reader(bytes.as_slice());
            let width = r.headers().unwrap().len();
            let rows: Vec<_> = r.records().map(|r| r.unwrap()).collect();
            assert!(
                !rows.is_empty() && rows.iter().all(|row| row.len() == width),
                "{name}"
            );
        }
    }
    // Every file written is listed.
    let on_disk = std::fs::read_dir(&dir).unwrap().count();
    assert_eq!(
        on_disk,
        listed.len() + 1,
        "README.md lists every other file"
    );
    for needle in ["Ŵ_JKR", "Ŵ_LJ(μ = 5)", "fit (17)", "default tap"] {
        assert!(readme.contains(needle), "{needle}");
    }
    // The manifest (--json) lists the same files, README.md last, and its numbers.
    let files: Vec<&str> = manifest["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["file"].as_str().unwrap())
        .collect();
    assert_eq!(files[..files.len() - 1], listed[..]);
    assert_eq!(files.last(), Some(&"README.md"));
    let w = num(&manifest["w_hat_lj_mu5"], "value");
    assert!(readme.contains(&format!("{w:.5}")), "{w}");
    assert_eq!(manifest["default_tap"]["regime"], "period-1");
    // And it is what `results/` holds: `results/` cannot drift from the code that
    // writes it. The README exactly; every CSV cell alike, numbers to 1e-9 relative.
    let committed = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("results");
    assert_eq!(
        readme,
        std::fs::read_to_string(committed.join("README.md")).unwrap(),
        "results/README.md is stale: run `tapsim reproduce --out results`"
    );
    for name in listed.iter().filter(|n| n.ends_with(".csv")) {
        let read = |dir: &std::path::Path| -> Vec<csv::StringRecord> {
            let mut r = csv::Reader::from_path(dir.join(name)).unwrap();
            let mut rows = vec![r.headers().unwrap().clone()];
            rows.extend(r.records().map(|r| r.unwrap()));
            rows
        };
        let (fresh, old) = (read(&dir), read(&committed));
        assert_eq!(fresh.len(), old.len(), "{name}: rows");
        for (i, (a, b)) in fresh.iter().zip(&old).enumerate() {
            assert_eq!(a.len(), b.len(), "{name}, row {i}");
            for (x, y) in a.iter().zip(b.iter()) {
                match (x.parse::<f64>(), y.parse::<f64>()) {
                    (Ok(x), Ok(y)) => assert!(
                        (x - y).abs() <= 1e-9 * x.abs().max(y.abs()) || x == y,
                        "{name}, row {i}: {x} now, {y} in results/ \
                         (run `tapsim reproduce --out results`)"
                    ),
                    _ => assert_eq!(x, y, "{name}, row {i}"),
                }
            }
        }
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn map_is_bit_identical_whatever_the_thread_count() {
    let dir = scratch("map");
    std::fs::create_dir_all(&dir).unwrap();
    let run = |threads: &str| {
        let path = dir.join(format!("map{threads}.csv"));
        let out = tapsim(&[
            "map",
            "--steps",
            "3",
            "--threads",
            threads,
            "--quiet",
            "--csv",
            path.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        std::fs::read(path).unwrap()
    };
    let (one, two) = (run("1"), run("2"));
    assert_eq!(one, two);
    let text = String::from_utf8(one).unwrap();
    assert_eq!(text.lines().count(), 10, "header and 9 cells");
    // Cells where the hybrid law does not apply are kept, empty, with the reason.
    assert!(text.contains("does not apply"));
    std::fs::remove_dir_all(dir).unwrap();
}

/// A viscous sample's E_ts in the contrast table is its viscous share plus its adhesion
/// share, each interpolated at the setpoint as φ is; its CSV has a column per material.
#[test]
fn contrast_splits_the_dissipation_of_a_viscous_sample() {
    let v = json(&[
        "contrast",
        "--laws",
        "hertz,jkr",
        "--setpoints",
        "0.8",
        "--points",
        "12",
        "--quiet",
        "--json",
        "--viscosity",
        "10",
    ]);
    let mut viscous_seen = 0;
    for r in &common::rows(&v) {
        let pick = |key: &str| r[key].as_array().unwrap().clone();
        let (all, adhesion, viscous) = (
            pick("e_ts_j"),
            pick("e_ts_adhesion_j"),
            pick("e_ts_viscous_j"),
        );
        for i in 0..all.len() {
            let Some(e) = all[i].as_f64() else { continue };
            let (a, w) = (adhesion[i].as_f64().unwrap(), viscous[i].as_f64().unwrap());
            assert!((a + w - e).abs() <= 1e-12 * e, "{r}");
            if r["law"] == "hertz" {
                // Hertz has no hysteresis: the sample's viscosity is all of it.
                assert_eq!(a, 0.0);
                assert!(w > 0.0);
                viscous_seen += 1;
            }
        }
    }
    assert_eq!(viscous_seen, 2, "{v}");
    let dir = scratch("contrast-split");
    let csv = dir.join("c.csv");
    succeeds(&[
        "contrast",
        "--laws",
        "hertz",
        "--setpoints",
        "0.8",
        "--points",
        "8",
        "--quiet",
        "--viscosity",
        "10",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&csv).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    for column in ["e_ts_j_", "e_ts_adhesion_j_", "e_ts_viscous_j_"] {
        assert_eq!(
            header.iter().filter(|h| h.starts_with(column)).count(),
            2,
            "{header:?}"
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn contrast_reports_a_row_per_law_and_setpoint() {
    let v = json(&[
        "contrast",
        "--laws",
        "jkr,hybrid",
        "--setpoints",
        "0.9,0.7",
        "--points",
        "12",
        "--quiet",
        "--json",
        "--material",
        "soft:sample-modulus=0.5GPa,work-of-adhesion=0.1",
        "--material",
        "stiff:sample-modulus=1GPa,work-of-adhesion=80mJ/m^2",
    ]);
    let rows = &common::rows(&v);
    // A row per law, setpoint and branch on which some material has a steady state.
    assert!(rows.len() >= 4, "{rows:?}");
    for law in ["jkr", "hybrid"] {
        for r in [0.9, 0.7] {
            assert!(
                rows.iter()
                    .any(|x| x["law"] == law && x["amplitude_ratio"] == r)
            );
        }
    }
    for r in rows {
        assert!(r["branch"] == "attractive" || r["branch"] == "repulsive");
        let phases = r["phase_deg"].as_array().unwrap();
        let regimes = r["regime"].as_array().unwrap();
        assert_eq!(phases.len(), 2);
        assert_eq!(regimes.len(), 2);
        // Each phase lies on the row's branch (above or below 90° at resonance).
        for (p, g) in phases.iter().zip(regimes) {
            assert_eq!(p.is_null(), g.is_null());
            if let Some(p) = p.as_f64() {
                assert_eq!(p > 90.0, r["branch"] == "attractive", "{r}");
            }
        }
        // Δφ only between materials on the same branch.
        match (phases[0].as_f64(), phases[1].as_f64()) {
            (Some(a), Some(b)) => {
                assert!((r["delta_phase_deg"].as_f64().unwrap() - (b - a)).abs() < 1e-9)
            }
            _ => assert!(r["delta_phase_deg"].is_null()),
        }
    }
    // E_ts of each material, split by mechanism, null exactly where φ is.
    for r in rows {
        let pick = |key: &str| r[key].as_array().unwrap().clone();
        let (all, adhesion, viscous) = (
            pick("e_ts_j"),
            pick("e_ts_adhesion_j"),
            pick("e_ts_viscous_j"),
        );
        for (i, phase) in r["phase_deg"].as_array().unwrap().iter().enumerate() {
            assert_eq!(all[i].is_null(), phase.is_null(), "{r}");
            if let Some(e) = all[i].as_f64() {
                assert!(e >= 0.0 && e.is_finite());
                // Elastic samples: all of it is adhesion hysteresis.
                assert_eq!(viscous[i].as_f64(), Some(0.0));
                assert_eq!(adhesion[i].as_f64(), Some(e));
            }
        }
    }
    // Under the hybrid law both polymers stay attractive at A/A0 = 0.9, on period-1 orbits.
    let h = rows
        .iter()
        .find(|x| {
            x["law"] == "hybrid" && x["amplitude_ratio"] == 0.9 && x["branch"] == "attractive"
        })
        .unwrap();
    assert_eq!(h["regime"][0], "period-1");
    assert!(h["delta_phase_deg"].as_f64().unwrap().abs() > 0.1);
    for bad in ["nocolon", "x:modulus", "x:radius=ten", ":modulus=1GPa"] {
        let out = tapsim(&[
            "contrast",
            "--material",
            bad,
            "--material",
            "y:modulus=1GPa",
        ]);
        assert!(!out.status.success(), "{bad}");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains("material")
                || String::from_utf8_lossy(&out.stderr).contains("radius"),
            "{bad}"
        );
    }
}

#[test]
fn branches_lists_the_folds_of_a_bistable_case_and_writes_every_output() {
    let dir = scratch("branches");
    let (csv, png) = (dir.join("branches.csv"), dir.join("branches.png"));
    let dmt = [
        "--law",
        "dmt",
        "--hamaker",
        "1.5e-19",
        "--sample-modulus",
        "2GPa",
        "--from",
        "22nm",
        "--to",
        "14nm",
    ];
    let mut args = vec!["branches"];
    args.extend(dmt);
    args.extend([
        "--csv",
        csv.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
    ]);
    let out = tapsim(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.matches("fold").count(), 2, "{text}");
    assert!(text.contains("reached the end separation"), "{text}");
    assert!(std::fs::read_to_string(&csv).unwrap().lines().count() > 20);
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
    let mut args = vec!["branches", "--json"];
    args.extend(dmt);
    let v = json(&args);
    let kinds = v["point"].as_array().unwrap();
    let n = kinds.len();
    for key in [
        "separation_m",
        "stable",
        "floquet_multipliers",
        "phase_deg",
        "segment",
    ] {
        assert_eq!(v[key].as_array().unwrap().len(), n, "{key}");
    }
    let folds: Vec<usize> = (0..n).filter(|&i| kinds[i] == "fold").collect();
    assert_eq!(folds.len(), 2);
    // Unstable between the folds, stable outside them.
    assert!(v["stable"][folds[0] + 1] == false && v["stable"][0] == true);
    assert!(
        v["notes"]
            .as_array()
            .unwrap()
            .iter()
            .any(|s| s.as_str().unwrap().contains("reached"))
    );
    // A bad step is refused with a message.
    let out = tapsim(&["branches", "--max-step", "-1nm"]);
    assert!(!out.status.success());
}

#[test]
fn branches_flags_the_orbits_that_graze_where_a_piece_ends() {
    // On the hybrid defaults the first piece ends where the free orbit first reaches the
    // jump-in separation: that orbit grazes (its margin past α_A below the thermal rms of
    // about 10 pm), its stability is not claimed, and orbits far from it are not flagged.
    let v = json(&["branches", "--json"]);
    let n = v["separation_m"].as_array().unwrap().len();
    let seg = |i: usize| v["segment"][i].as_u64().unwrap();
    let last_of_first = (0..n).rev().find(|&i| seg(i) == 0).unwrap();
    assert_eq!(v["grazing"][last_of_first], true);
    let margin = v["grazing_margin_m"][last_of_first].as_f64().unwrap();
    assert!(margin < 10e-12, "margin {margin:e} m");
    let flagged: Vec<usize> = (0..n).filter(|&i| v["grazing"][i] == true).collect();
    assert!(flagged.len() < n / 4, "{} of {n} flagged", flagged.len());
    for &i in &flagged {
        let m = v["grazing_margin_m"][i].as_f64().unwrap();
        assert!(m < 20e-12, "point {i}: margin {m:e} m yet flagged");
    }
    // The deepest orbit (8 nm) is far from any switch.
    assert_eq!(v["grazing"][n - 1], false);
    let text = String::from_utf8_lossy(&tapsim(&["branches"]).stdout).to_string();
    assert!(
        text.contains(&format!("{} graze a switch", flagged.len())),
        "{text}"
    );
}

#[test]
fn map_counts_its_grazing_cells_where_readme_says() {
    // The guide (Speed): on the 10 x 10 default grid, 64 cells where the law applies: 52
    // period-1 and 12 long locks, every lock grazing a switch, none irregular; the note
    // on stderr counts them.
    let out = tapsim(&["map", "--steps", "10", "--json"]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let (regimes, grazing) = (cells(&v["grid"]["regime"]), cells(&v["grid"]["grazing"]));
    let count =
        |f: &dyn Fn(&str) -> bool| regimes.iter().filter(|r| r.as_str().is_some_and(f)).count();
    assert_eq!(count(&|r| r == "period-1"), 52);
    assert_eq!(count(&|r| r == "irregular"), 0);
    assert_eq!(count(&|r| r.starts_with("period-") && r != "period-1"), 12);
    for (r, g) in regimes.iter().zip(&grazing) {
        if r.as_str().is_some_and(|r| r != "period-1") {
            assert_eq!(g, true, "{r}");
        }
    }
    let flagged = grazing.iter().filter(|g| **g == true).count();
    assert_eq!(flagged, 12);
    assert_eq!(v["grazing_cells"], 12);
    let note = String::from_utf8_lossy(&out.stderr);
    assert!(note.contains("12 of 100 cells graze a switch"), "{note}");
}

#[test]
fn bifurcation_samples_every_period_and_names_the_motion() {
    let v = json(&[
        "bifurcation",
        "--law",
        "jkr",
        "--from",
        "21nm",
        "--to",
        "14nm",
        "--points",
        "8",
        "--samples",
        "5",
        "--json",
        "--quiet",
    ]);
    let regimes = v["regime"].as_array().unwrap();
    assert_eq!(regimes.len(), 40);
    for key in ["separation_m", "deflection_m", "min_separation_m"] {
        let col = v[key].as_array().unwrap();
        assert_eq!(col.len(), 40, "{key}");
        assert!(col.iter().all(|x| x.as_f64().unwrap().is_finite()));
    }
    // Far out period-1 (one value, repeated); near contact other kinds of motion.
    assert_eq!(regimes[0], "period-1");
    let d = v["deflection_m"].as_array().unwrap();
    assert!((d[0].as_f64().unwrap() - d[4].as_f64().unwrap()).abs() < 1e-15);
    assert!(regimes.iter().any(|r| r != "period-1"));
    let out = tapsim(&["bifurcation", "--samples", "0"]);
    assert!(!out.status.success());
}

#[test]
fn branches_refuses_steps_that_would_not_finish() {
    for args in [
        vec!["branches", "--max-step", "1e-300"],
        vec!["branches", "--max-step", "1m"],
        vec!["branches", "--from", "10nm", "--to", "10nm"],
    ] {
        let out = tapsim(&args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("max step") || err.contains("must differ"),
            "{err}"
        );
    }
}

#[test]
fn a_closed_pipe_ends_quietly_and_a_full_disk_is_an_error() {
    use std::process::Stdio;
    // The reader goes away before anything is written (`tapsim … | head -0`).
    let mut child = Command::new(env!("CARGO_BIN_EXE_tapsim"))
        .args(["approach", "--points", "6", "--quiet"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("it ends");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    // A full disk: an error message and exit code 1, no panic.
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        println!("no /dev/full here: the full-disk case is not checked");
        return;
    };
    let out = Command::new(env!("CARGO_BIN_EXE_tapsim"))
        .arg("tap")
        .stdout(full)
        .output()
        .expect("the binary runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("cannot write standard output") && !err.contains("panicked"),
        "{err}"
    );
}

#[test]
fn a_cached_lennard_jones_solution_prints_the_same_bytes_as_a_fresh_one() {
    let dir = scratch("lj-cache");
    let run = || succeeds_with_cache(&["lj", "--mu", "2", "--json"], &dir.join("cache")).stdout;
    let cold = run();
    let cached: Vec<_> = std::fs::read_dir(dir.join("cache")).unwrap().collect();
    assert_eq!(cached.len(), 1, "one solution cached");
    let warm = run();
    assert_eq!(
        String::from_utf8_lossy(&cold),
        String::from_utf8_lossy(&warm)
    );
}

#[test]
fn below_the_critical_mu_lj_reports_no_hysteresis_not_an_error() {
    let v = json(&["lj", "--mu", "0.6", "--json"]);
    assert_eq!(v["hysteresis"], false);
    assert_eq!(num(&v, "w_hat"), 0.0);
    let v = json(&["lj", "--mu", "0.8", "--json"]);
    assert_eq!(v["hysteresis"], true);
    assert!(num(&v, "w_hat") > 0.0);
}

#[test]
fn map_json_is_a_grid_and_its_plot_a_heat_map() {
    let v = json(&["map", "--steps", "3", "--json", "--quiet"]);
    let axis = |k: &str| v[k].as_array().unwrap().len();
    assert_eq!((axis("work_of_adhesion_j_m2"), axis("modulus_pa")), (3, 3));
    let phase = v["grid"]["phase_deg"].as_array().unwrap();
    assert_eq!(phase.len(), 3);
    assert!(phase.iter().all(|row| row.as_array().unwrap().len() == 3));
    // A cell where the law does not apply is null, with its note beside it.
    assert!(phase[2][0].is_null());
    assert!(
        v["grid"]["note"][2][0]
            .as_str()
            .unwrap()
            .contains("does not apply")
    );
    assert_eq!(v["grid"]["modulus_pa"][1][2], v["modulus_pa"][1]);
    let dir = scratch("heatmap");
    for ext in ["png", "svg"] {
        let path = dir.join(format!("map.{ext}"));
        let out = tapsim(&[
            "map",
            "--steps",
            "3",
            "--quiet",
            "--plot",
            path.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(std::fs::metadata(&path).unwrap().len() > 10_000);
    }
    let svg = std::fs::read_to_string(dir.join("map.svg")).unwrap();
    for needle in [
        "E_ts per cycle (eV)",
        "phase lag φ (deg)",
        "A/A₀",
        "not period-1",
    ] {
        assert!(svg.contains(needle), "{needle}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn figure_json_is_a_manifest_of_the_files_written() {
    let dir = scratch("figure-json");
    let v = json(&["figure", "1", "--json", "--out", dir.to_str().unwrap()]);
    let fig = &v["figures"][0];
    assert_eq!(fig["number"], 1);
    assert!(fig["title"].as_str().unwrap().starts_with("Fig. 1"));
    let files = fig["files"].as_array().unwrap();
    assert_eq!(files.len(), 3);
    for f in files {
        assert!(std::path::Path::new(f.as_str().unwrap()).is_file(), "{f}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// A capillary neck is put on by its rupture distance, from a flag or a parameter file,
/// on the laws without hysteresis of their own; the rest is refused with the reason.
#[test]
fn a_capillary_neck_is_a_law_parameter_checked_against_the_law() {
    let v = json(&[
        "tap",
        "--law",
        "dmt",
        "--rupture-distance",
        "2nm",
        "--contact-angle",
        "30",
        "--separation",
        "9nm",
        "--json",
    ]);
    assert_eq!(v["law"], "dmt+capillary");
    let (e, cap) = (num(&v, "e_ts_j"), num(&v, "e_ts_capillary_j"));
    assert!(cap > 0.0 && (e - cap).abs() <= 1e-9 * e, "{v}");
    a_file_gives_what_the_flags_give(
        "capillary-config",
        "law = \"dmt\"\nrupture-distance = \"2nm\"\ncontact-angle = 30\nseparation = \"9nm\"\n",
        &v,
    );
    refused(&[
        (
            vec!["tap", "--law", "none", "--rupture-distance", "2nm"],
            "the none law takes no rupture-distance parameter",
        ),
        (
            vec!["tap", "--law", "jkr", "--rupture-distance", "0.1nm"],
            "must break beyond the separation where the contact lets go",
        ),
        (
            vec!["tap", "--law", "hertz", "--surface-tension", "72mN/m"],
            "give its rupture-distance too",
        ),
        (
            vec![
                "tap",
                "--law",
                "hertz",
                "--rupture-distance",
                "2nm",
                "--contact-angle",
                "95",
            ],
            "contact angle = 95 deg is outside",
        ),
        (
            vec!["tap", "--law", "dmt", "--rupture-distance", "0.2nm"],
            "the neck breaks beyond contact",
        ),
    ]);
}

#[test]
fn a_relaxing_sample_is_a_law_parameter_checked_against_the_law() {
    // Flag and parameter file alike; the law's name says the sample relaxes.
    let args = [
        "tap",
        "--law",
        "hertz",
        "--unrelaxed-modulus",
        "1.8GPa",
        "--relaxation-time",
        "100ns",
        "--json",
    ];
    let v = json(&args);
    assert_eq!(v["law"], "hertz+sls");
    // With a capillary neck too: every channel but the law's own (it has no loop). (Over
    // 64 periods: on the sunk surface this neck holds the tip in an attractive state the
    // march does not settle within its budget; tests/relaxing.rs runs a neck that does.)
    let mut necked = args.to_vec();
    necked.extend(["--rupture-distance", "2nm", "--max-cycles", "64"]);
    let n = json(&necked);
    assert_eq!(n["law"], "hertz+capillary+sls");
    assert!(
        num(&n, "e_ts_capillary_j") > 0.0 && num(&n, "e_ts_viscous_j") > 0.0,
        "{n}"
    );
    assert_eq!(v["e_ts_viscous_j"], v["e_ts_j"]);
    assert!(num(&v, "e_ts_j") > 0.0 && num(&v, "energy_balance_rel") < 1e-6);
    // Its orbit is marched to (the surface remembers every tap): no Floquet multipliers,
    // stable because the march reached it.
    assert_eq!(
        v["floquet_multipliers"].as_array().map(Vec::len),
        Some(0),
        "{v}"
    );
    assert_eq!(v["stable"], true);
    a_file_gives_what_the_flags_give(
        "relaxing-config",
        "law = \"hertz\"\nunrelaxed-modulus = \"1.8GPa\"\nrelaxation-time = \"100ns\"\n",
        &v,
    );
    let sls = |extra: &[&'static str]| {
        let mut a = vec!["tap", "--law", "hertz"];
        a.extend_from_slice(extra);
        a
    };
    refused(&[
        (
            vec![
                "tap",
                "--law",
                "jkr",
                "--unrelaxed-modulus",
                "3GPa",
                "--relaxation-time",
                "1us",
            ],
            "the jkr law takes no unrelaxed-modulus parameter (the laws that do: dmt, hertz)",
        ),
        (sls(&["--relaxation-time", "1us"]), "needs both"),
        (sls(&["--unrelaxed-modulus", "3GPa"]), "needs both"),
        (
            sls(&[
                "--unrelaxed-modulus",
                "3GPa",
                "--relaxation-time",
                "1us",
                "--viscosity",
                "5",
            ]),
            "takes no viscosity",
        ),
        (
            sls(&["--unrelaxed-modulus", "0.3GPa", "--relaxation-time", "1us"]),
            "must exceed the relaxed one",
        ),
        (
            sls(&["--unrelaxed-modulus", "3GPa", "--relaxation-time", "10s"]),
            "relaxation time = 10 s is outside",
        ),
        (
            sls(&["--unrelaxed-modulus", "3GPa", "--relaxation-time", "1kg"]),
            "unknown unit",
        ),
    ]);
}

#[test]
fn a_viscous_sample_is_a_law_parameter_checked_against_the_law() {
    // Flag and parameter file alike; the law's name says the sample is viscous.
    let v = json(&["tap", "--law", "hertz", "--viscosity", "50 Pa·s", "--json"]);
    assert_eq!(v["law"], "hertz+kelvin-voigt");
    assert!(num(&v, "e_ts_j") > 0.0 && num(&v, "energy_balance_rel") < 1e-6);
    a_file_gives_what_the_flags_give(
        "viscous-config",
        "law = \"hertz\"\nviscosity = \"50Pa*s\"\n",
        &v,
    );
    // A parameter the law does not take is refused, naming the laws that take it.
    refused(&[
        (
            vec!["tap", "--law", "none", "--viscosity", "5"],
            "the none law takes no viscosity parameter",
        ),
        (
            vec!["tap", "--law", "hertz", "--hamaker", "1e-20"],
            "the hertz law takes no hamaker parameter (the laws that do: dmt)",
        ),
        (
            vec!["tap", "--viscosity", "1e9"],
            "sample viscosity = 1 GPa·s is outside",
        ),
        (vec!["tap", "--viscosity", "5kg"], "unknown unit"),
    ]);
    // `--law` lists every registered law with its help.
    let help = String::from_utf8_lossy(&tapsim(&["tap", "--help"]).stdout).to_string();
    for law in tapsim::law::LAWS {
        assert!(help.contains(&format!("- {}:", law.name)), "{}", law.name);
    }
}

/// `tapsim` with the Slurm array variables removed (a test run inside a job array must
/// not shard its maps).
fn tapsim_here(args: &[&str], dir: &std::path::Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tapsim"))
        .args(args)
        .current_dir(dir)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("SLURM_ARRAY_TASK_COUNT")
        .env_remove("SLURM_ARRAY_TASK_MIN")
        .output()
        .expect("the binary runs")
}

/// [`tapsim_here`], asserting success; its standard output.
fn succeeds_here(args: &[&str], dir: &std::path::Path) -> Vec<u8> {
    let out = tapsim_here(args, dir);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

/// A map over a viscous sample adds the heat map of E_ts's viscous share, the same
/// whether computed whole or merged from parts; an elastic sample's map has none.
#[test]
fn a_viscous_maps_plot_shows_the_viscous_share_merged_or_whole() {
    let dir = scratch("viscous-map");
    let ok = |args: &[&str]| succeeds_here(args, &dir);
    let grid = [
        "map",
        "--steps",
        "3",
        "--quiet",
        "--law",
        "hertz",
        "--viscosity",
        "10",
    ];
    ok(&[&grid[..], &["--plot", "whole.svg"]].concat());
    for i in 0..2 {
        let shard = format!("{i}/2");
        let part = format!("p{i}.json");
        ok(&[&grid[..], &["--shard", &shard, "--part", &part]].concat());
    }
    ok(&["merge", "p1.json", "p0.json", "--out", "merged.svg"]);
    let whole = std::fs::read_to_string(dir.join("whole.svg")).unwrap();
    assert!(whole.contains("viscous share of the dissipation"));
    assert_eq!(
        std::fs::read_to_string(dir.join("merged.svg")).unwrap(),
        whole
    );
    ok(&[
        "map",
        "--steps",
        "3",
        "--quiet",
        "--law",
        "hertz",
        "--plot",
        "elastic.svg",
    ]);
    let elastic = std::fs::read_to_string(dir.join("elastic.svg")).unwrap();
    assert!(!elastic.contains("viscous share"));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn sharded_maps_merge_to_the_whole_map_byte_for_byte() {
    let dir = scratch("shards");
    let ok = |args: &[&str]| succeeds_here(args, &dir);
    // A 5 × 5 grid: 10 cells where the law does not apply, 4 that are not period-1.
    let grid = ["map", "--steps", "5", "--quiet"];
    fn with<'a>(grid: &[&'a str], extra: &[&'a str]) -> Vec<&'a str> {
        [grid, extra].concat()
    }
    ok(&with(&grid, &["--csv", "whole.csv", "--plot", "whole.png"]));
    let whole_json = ok(&with(&grid, &["--json"]));
    let whole_csv = std::fs::read(dir.join("whole.csv")).unwrap();
    let csv_text = String::from_utf8_lossy(&whole_csv);
    assert!(csv_text.lines().filter(|l| l.contains(",,")).count() >= 5);
    assert!(csv_text.contains("irregular") || csv_text.contains("period-2"));
    for n in [1usize, 2, 3, 7] {
        let mut parts = Vec::new();
        for i in 0..n {
            let part = format!("part-{i}-of-{n}.json");
            ok(&with(
                &grid,
                &["--shard", &format!("{i}/{n}"), "--part", &part],
            ));
            parts.push(part);
        }
        // Given in any order.
        parts.reverse();
        let mut merge: Vec<&str> = vec!["merge"];
        merge.extend(parts.iter().map(String::as_str));
        let outs = [
            format!("m{n}.csv"),
            format!("m{n}.png"),
            format!("m{n}.json"),
        ];
        let mut args = merge.clone();
        for o in &outs {
            args.extend(["--out", o.as_str()]);
        }
        ok(&args);
        assert_eq!(
            std::fs::read(dir.join(&outs[0])).unwrap(),
            whole_csv,
            "N = {n}"
        );
        assert_eq!(
            std::fs::read(dir.join(&outs[1])).unwrap(),
            std::fs::read(dir.join("whole.png")).unwrap(),
            "N = {n}"
        );
        assert_eq!(
            std::fs::read(dir.join(&outs[2])).unwrap(),
            whole_json,
            "N = {n}"
        );
        let mut args = merge.clone();
        args.push("--json");
        assert_eq!(ok(&args), whole_json, "N = {n}");
    }
    // A part missing: named as sbatch --array= takes it.
    let out = tapsim_here(
        &[
            "merge",
            "part-0-of-7.json",
            "part-1-of-7.json",
            "part-2-of-7.json",
            "part-5-of-7.json",
        ],
        &dir,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("3 of 7 parts missing: 3-4,6") && err.contains("--array=3-4,6"),
        "{err}"
    );
    // A part of another map (another grid) is refused.
    ok(&[
        "map",
        "--steps",
        "6",
        "--quiet",
        "--shard",
        "1/2",
        "--part",
        "other.json",
    ]);
    let out = tapsim_here(&["merge", "part-0-of-2.json", "other.json"], &dir);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("belongs to another job"),
        "{err}"
    );
    // Slurm's array variables shard a run with no flag.
    let out = Command::new(env!("CARGO_BIN_EXE_tapsim"))
        .args(with(&grid, &["--part", "slurm.json"]))
        .current_dir(&dir)
        .env("SLURM_ARRAY_TASK_ID", "12")
        .env("SLURM_ARRAY_TASK_MIN", "10")
        .env("SLURM_ARRAY_TASK_COUNT", "3")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read(dir.join("slurm.json")).unwrap(),
        std::fs::read(dir.join("part-2-of-3.json")).unwrap()
    );
}

#[test]
fn a_sharded_batch_merges_to_the_whole_batch_and_a_toml_table_reads_as_the_csv() {
    let dir = scratch("batch");
    let ok = |args: &[&str]| succeeds_here(args, &dir);
    // Tap cases on several laws (one irregular, one where the law does not apply, one
    // viscous) and an approach case, whose setpoints stay together.
    std::fs::write(
        dir.join("cases.csv"),
        "name,law,separation,sample-modulus,work-of-adhesion,viscosity,command,points\n\
         soft,hybrid,16nm,,,,,\n\
         stiff,hybrid,16nm,2GPa,,,,\n\
         irregular,jkr,16nm,,,,,\n\
         viscous,hertz,12nm,,,50Pa·s,,\n\
         ramp,hybrid,,,,,approach,4\n\
         nothing,hybrid,,100GPa,0.02,,,\n\
         lj,lj,14nm,,,,,\n\
         dmt,dmt,,,,,,\n",
    )
    .unwrap();
    let whole = ok(&["batch", "cases.csv", "--quiet"]);
    let text = String::from_utf8_lossy(&whole).to_string();
    assert_eq!(text.lines().count(), 1 + 7 + 8, "{text}");
    assert!(text.contains("irregular,tap,jkr") && text.contains("does not apply"));
    assert!(text.contains("hertz+kelvin-voigt"));
    let whole_json = ok(&["batch", "cases.csv", "--quiet", "--json"]);
    for n in [1usize, 2, 3, 7] {
        let mut merge = vec!["merge".to_string()];
        for i in 0..n {
            let part = format!("b-{i}-of-{n}.json");
            ok(&[
                "batch",
                "cases.csv",
                "--quiet",
                "--shard",
                &format!("{i}/{n}"),
                "--part",
                &part,
            ]);
            merge.push(part);
        }
        let merge: Vec<&str> = merge.iter().map(String::as_str).collect();
        assert_eq!(ok(&merge), whole, "N = {n}");
        assert_eq!(
            ok(&[&merge[..], &["--json"]].concat()),
            whole_json,
            "N = {n}"
        );
    }
    // A missing part is named; a map's part does not merge with a batch's.
    let out = tapsim_here(&["merge", "b-0-of-3.json", "b-2-of-3.json"], &dir);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("--array=1"), "{err}");
    // The same cases as TOML.
    std::fs::write(
        dir.join("cases.toml"),
        "[[case]]\nname = \"viscous\"\nlaw = \"hertz\"\nseparation = \"12nm\"\n\
         viscosity = \"50Pa·s\"\n\n[[case]]\nname = \"ramp\"\ncommand = \"approach\"\n\
         points = 4\n",
    )
    .unwrap();
    let toml = String::from_utf8_lossy(&ok(&["batch", "cases.toml", "--quiet"])).to_string();
    let rows = |t: &str, name: &str| -> Vec<String> {
        t.lines()
            .filter(|l| l.starts_with(&format!("{name},")))
            .map(|l| l.trim_end_matches(',').to_string())
            .collect()
    };
    for name in ["viscous", "ramp"] {
        assert_eq!(rows(&toml, name), rows(&text, name), "{name}");
    }
    // A column nobody knows is refused, naming the row.
    std::fs::write(dir.join("bad.csv"), "name,colour\nx,blue\n").unwrap();
    let out = tapsim_here(&["batch", "bad.csv"], &dir);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("row 1") && err.contains("unknown column"),
        "{err}"
    );
}

#[test]
fn merge_refuses_what_is_not_a_part_file_of_a_job_tapsim_can_run() {
    let dir = scratch("hostile-parts");
    let write = |name: &str, text: &str| std::fs::write(dir.join(name), text).unwrap();
    write("garbage.json", "{ not json");
    write("other.json", "{\"format\": \"something-else\"}");
    let header = |shards: &str, axes: &str| {
        format!(
            "{{\"format\":\"tapsim-part\",\"tapsim_version\":\"0.1.0\",\"config_hash\":\"0\",\
             \"shards\":{shards},\"shard\":0,\"job\":{{\"kind\":\"map\",\"law\":\"hybrid\",\
             \"work_of_adhesion_j_m2\":{axes},\"modulus_pa\":{axes}}},\"config\":[],\
             \"item_configs\":[],\"items\":[],\"records\":[],\"records_checksum\":\"0\"}}"
        )
    };
    write("many-shards.json", &header("1000000000000000000", "[1,2]"));
    let big_axis = format!("[{}]", vec!["1"; 5000].join(","));
    write("huge-grid.json", &header("2", &big_axis));
    write("cut-short.json", &header("1", "[1,2]"));
    for (file, needle) in [
        ("garbage.json", "not a tapsim part file"),
        ("other.json", "not a tapsim part file"),
        ("many-shards.json", "parts"),
        ("huge-grid.json", "is not an axis tapsim map takes"),
        ("cut-short.json", "changed or cut short"),
        ("missing.json", "No such file"),
        (".", "not a regular file"),
    ] {
        let out = tapsim_here(&["merge", file], &dir);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            out.status.code() == Some(1) && err.contains(needle),
            "{file}: {:?} {err}",
            out.status
        );
    }
}

/// One command-line surface: every command takes --quiet; every command that writes a
/// file names it on stderr ("wrote PATH") unless --quiet (`reproduce` and `figure` list
/// theirs on stdout, as their output); a value of an enumerated option is taken in any
/// case (`--law DMT`).
#[test]
fn every_command_takes_quiet_and_names_the_files_it_writes() {
    let dir = common::scratch("announce");
    let file = |name: &str| dir.join(name).to_string_lossy().into_owned();
    let (csv, png, curve, part) = (
        file("out.csv"),
        file("out.png"),
        file("curve.csv"),
        file("part.json"),
    );
    let runs: Vec<Vec<&str>> = vec![
        vec!["tap", "--trajectory", &csv],
        vec!["approach", "--points", "2", "--no-retract", "--csv", &csv],
        vec!["map", "--steps", "2", "--csv", &csv],
        vec!["map", "--steps", "2", "--shard", "0/2", "--part", &part],
        vec!["lj", "--mu", "3", "--curve", &curve],
        vec!["thermal", "--duration", "0.12s", "--plot", &png],
    ];
    for args in &runs {
        let named = args.last().unwrap();
        let loud = common::tapsim(args);
        let err = String::from_utf8_lossy(&loud.stderr);
        assert!(loud.status.success(), "{args:?}: {err}");
        assert!(err.contains(&format!("wrote {named}")), "{args:?}: {err}");
        let mut quiet = args.clone();
        quiet.push("--quiet");
        let out = common::tapsim(&quiet);
        assert!(out.status.success(), "{quiet:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("wrote"), "{quiet:?}: {err}");
    }
    for command in [
        "tap",
        "approach",
        "branches",
        "bifurcation",
        "contrast",
        "map",
        "scan",
        "thermal",
        "peakforce",
        "batch",
        "merge",
        "hysteresis",
        "lj",
        "figure",
        "reproduce",
    ] {
        let out = common::tapsim(&[command, "--quiet", "--help"]);
        assert!(out.status.success(), "{command} --quiet");
    }
    let v = common::json(&["tap", "--law", "DMT", "--separation", "30nm", "--json"]);
    assert_eq!(v["law"], "dmt");
    // The usual short spellings, and bare numbers meant in kHz or GPa caught with the
    // number the user typed.
    let short = common::json(&[
        "tap", "--k", "3", "--Q", "100", "--f0", "70kHz", "--A0", "10nm", "--zc", "8nm", "--json",
    ]);
    let long = common::json(&[
        "tap",
        "--stiffness",
        "3",
        "--quality",
        "100",
        "--resonance",
        "70kHz",
        "--free-amplitude",
        "10nm",
        "--separation",
        "8nm",
        "--json",
    ]);
    assert_eq!(short, long);
    common::refused(&["tap", "--resonance", "300"], "did you mean 300kHz?");
    common::refused(&["tap", "--sample-modulus", "2"], "did you mean 2GPa?");
}

/// The reference a terminal gives, generated from the command line's own definitions:
/// `--version` names the commit (the one git itself reports, where this is a checkout);
/// `completions` knows every command and flag; `man` writes a page per command; `--help`
/// wraps to the terminal's width (every command's page within 80 columns at
/// COLUMNS=80) and the sample's flags show their defaults.
#[test]
fn version_completions_man_pages_and_help_come_from_the_definitions() {
    let bin = env!("CARGO_BIN_EXE_tapsim");
    let run = |args: &[&str]| {
        let out = std::process::Command::new(bin)
            .args(args)
            .env("COLUMNS", "80")
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let version = run(&["--version"]);
    assert!(
        version.starts_with(&format!("tapsim {} (commit ", env!("CARGO_PKG_VERSION"))),
        "{version}"
    );
    let git = std::process::Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output();
    if let Some(git) = git.ok().filter(|o| o.status.success()) {
        let commit = String::from_utf8(git.stdout).unwrap();
        assert!(version.contains(commit.trim()), "{version} vs {commit}");
    }
    // The commands, as --help lists them.
    let help = run(&["--help"]);
    let commands: Vec<&str> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter(|l| !l.starts_with("   "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .collect();
    assert!(commands.len() >= 20, "{commands:?}");
    let bash = run(&["completions", "bash"]);
    for c in &commands {
        assert!(bash.contains(c), "bash completions lack {c}");
    }
    assert!(bash.contains("--psd") && bash.contains("--setpoint"));
    assert!(run(&["completions", "zsh"]).starts_with("#compdef tapsim"));
    let dir = common::scratch("man");
    run(&["man", "--out", dir.to_str().unwrap(), "--quiet"]);
    for c in
        std::iter::once("tapsim".to_string()).chain(commands.iter().map(|c| format!("tapsim-{c}")))
    {
        let page = std::fs::read_to_string(dir.join(format!("{c}.1"))).unwrap_or_default();
        assert!(
            page.starts_with(".ie") || page.contains(".TH"),
            "{c}.1: {}",
            &page[..page.len().min(80)]
        );
    }
    let tap = std::fs::read_to_string(dir.join("tapsim-tap.1")).unwrap();
    assert!(tap.contains("setpoint"));
    for c in &commands {
        let text = run(&[c, "--help"]);
        let widest = text.lines().map(|l| l.chars().count()).max().unwrap_or(0);
        assert!(widest <= 80, "{c} --help: a line of {widest} columns");
    }
    // -h is the summary: the common flags, a fraction of --help's page; the numerics and
    // the laws' own parameters wait for --help.
    for c in [
        "tap",
        "approach",
        "contrast",
        "map",
        "scan",
        "fit",
        "force-curve",
    ] {
        let (short, long) = (run(&[c, "-h"]), run(&[c, "--help"]));
        let (s, l) = (short.lines().count(), long.lines().count());
        assert!(2 * s < l, "{c}: -h {s} lines, --help {l}");
    }
    let short = run(&["tap", "-h"]);
    assert!(
        !short.contains("--rtol") && !short.contains("--hamaker"),
        "{short}"
    );
    // One screen: each option a line, its value named by its unit, its default kept; the
    // rest of its help in --help.
    assert!(short.lines().count() <= 40, "tap -h: {short}");
    for line in [
        "--radius <m>               Tip radius R [20nm]",
        "--work-of-adhesion <J/m²>  Work of adhesion Δγ [0.1J/m^2]",
        "--plot <FILE>",
    ] {
        assert!(short.contains(line), "tap -h lacks {line:?}: {short}");
    }
    let tap_help = run(&["tap", "--help"]);
    assert!(tap_help.contains("--rtol") && tap_help.contains("--hamaker"));
    assert!(tap_help.contains("Range ε of the Lennard-Jones law [m; the built-in sample's 0.3nm]"));
    for default in [
        "20nm",
        "0.5GPa",
        "0.1J/m^2",
        "0.3nm",
        "default 40",
        "default 400",
    ] {
        assert!(
            tap_help.contains(default),
            "tap --help does not show {default}"
        );
    }
    common::refused(
        &["man", "--out", dir.join("missing").to_str().unwrap()],
        "existing directory",
    );
}

/// A relaxing sample lets go of a withdrawing tip (Ting's receding contact): on an
/// outside check's case (Hertz, E* 1 → 3 GPa, τ_r = 100 ns at z_c = 12 nm), where Lee &
/// Radok's integral run through unloading pulled the tip to −5.72 nN, the most tensile
/// force `tap` reports is none on Hertz: the sample adds no pull of its own.
#[test]
fn tap_on_a_relaxing_sample_never_pulls() {
    let args = [
        "tap",
        "--law",
        "hertz",
        "--modulus",
        "1GPa",
        "--separation",
        "12nm",
        "--unrelaxed-modulus",
        "3GPa",
        "--relaxation-time",
        "100ns",
        "--json",
    ];
    let json = json_of(&args, &[]);
    let pull = num(&json, "peak_attractive_force_n");
    assert!(pull == 0.0, "{pull:e}");
    assert!(num(&json, "e_ts_viscous_j") > 0.0, "the sample loses");
}
