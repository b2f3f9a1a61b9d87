//! The guide's CLI tour (docs/src/reference/cli-tour.md), run as a new user runs it:
//! every command of the tour block succeeds, and the commands that name an effect show it (a touch, a neck, a viscous
//! share, a non-empty contrast).

use crate::common;

use std::path::Path;

/// Run a tour command in `dir` (the tour's example files from the repository), with
/// `extra` arguments; its stdout.
fn run(args: &[String], extra: &[&str], dir: &Path) -> String {
    let mut all = common::with_examples(args);
    all.extend(extra.iter().map(|s| s.to_string()));
    let r = common::run_limited(&all, dir, std::time::Duration::from_secs(120));
    assert_eq!(r.code, Some(0), "tapsim {}: {}", all.join(" "), r.stderr);
    r.stdout
}

fn has(args: &[String], flag: &str) -> bool {
    args.iter().any(|a| a == flag)
}

/// Every tour command runs, and each shows what its comment says it shows. The tap
/// commands are run again with --json for their numbers: a rest-separation state
/// touches the sample (or, where a law's effect is named, dissipates through it); the
/// two-material contrast has a Δφ on the repulsive branch at every setpoint, JKR's 5 to
/// 7 times the hybrid's (the guide).
#[test]
fn every_tour_command_runs_and_shows_its_effect() {
    // (The README's tour shows what each command prints: tests/docs.rs runs it.)
    let commands = common::tour_block("docs/src/reference/cli-tour.md", "# CLI tour");
    assert!(commands.len() > 30, "{}", commands.len());
    let dir = common::scratch("tour");
    // Two at a time from one queue, as the machine has two cores.
    // (`reproduce --out results --json` is the one command left out: tests/cli.rs runs
    // it as written, checks every file it lists and compares them with results/.)
    let commands: Vec<_> = commands
        .into_iter()
        .filter(|c| c[0] != "reproduce")
        .collect();
    // The commands that read what others write (a merge its parts, a fit its curve) run
    // after them.
    let (merges, rest): (Vec<_>, Vec<_>) = commands
        .into_iter()
        .partition(|c| matches!(c[0].as_str(), "merge" | "fit" | "reconstruct"));
    common::two_at_a_time(&rest, |args| check(args, &dir));
    for args in &merges {
        check(args, &dir);
    }
    // Every CSV the tour wrote (approach, map, merge, batch, …).
    let csvs = csv_files(&dir);
    for path in &csvs {
        assert_clean_csv(&std::fs::read_to_string(path).unwrap(), path);
    }
    // (reproduce's own CSV files are checked in results/ by the test below.)
    assert!(csvs.len() >= 6, "the tour wrote {} CSV files", csvs.len());
}

/// The CSV files under `dir`, in its subdirectories too.
fn csv_files(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            found.extend(csv_files(&path));
        } else if path.extension().is_some_and(|e| e == "csv") {
            found.push(path);
        }
    }
    found
}

/// The CSV files `reproduce` wrote into results/ are as clean as the tour's.
#[test]
fn the_results_csv_files_are_clean() {
    let csvs = csv_files(&Path::new(env!("CARGO_MANIFEST_DIR")).join("results"));
    for path in &csvs {
        assert_clean_csv(&std::fs::read_to_string(path).unwrap(), path);
    }
    assert!(csvs.len() >= 10, "{}", csvs.len());
}

/// A CSV file holds no JSON in a cell, and every number in it is clean: no negative zero,
/// no exponent below −30 (round-off as data), at most 10 significant digits (no binary
/// artefact such as 89.99999999999999 for 90).
fn assert_clean_csv(text: &str, path: &Path) {
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let header = reader.headers().unwrap().clone();
    for (row, record) in reader.records().enumerate() {
        let record = record.unwrap();
        for (column, cell) in header.iter().zip(record.iter()) {
            let at = || format!("{}: row {} {column} = {cell:?}", path.display(), row + 1);
            assert!(!cell.starts_with(['[', '{']), "{}: JSON in a cell", at());
            if cell.parse::<f64>().is_err() {
                continue;
            }
            let unsigned = cell.trim_start_matches('-');
            let (mantissa, exponent) = match unsigned.split_once(['e', 'E']) {
                Some((m, e)) => (m, e.parse::<i32>().unwrap()),
                None => (unsigned, 0),
            };
            let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
            let significant = digits.trim_start_matches('0').trim_end_matches('0');
            assert!(
                !(cell.starts_with('-') && significant.is_empty()),
                "{}: negative zero",
                at()
            );
            assert!(significant.len() <= 10, "{}: float artefact", at());
            assert!(
                significant.is_empty() || exponent > -30,
                "{}: round-off as data",
                at()
            );
        }
    }
}

fn check(args: &[String], dir: &Path) {
    let started = std::time::Instant::now();
    let stdout = run(args, &[], dir);
    assert_no_round_off(&stdout, &args.join(" "));
    eprintln!(
        "{:5.1} s  tapsim {}",
        started.elapsed().as_secs_f64(),
        args.join(" ")
    );
    let command = args[0].as_str();
    let is_tap_at_separation = command == "tap"
        && !has(args, "--setpoint")
        && !has(args, "--json")
        && !has(args, "--temperature")
        && !has(args, "--plot");
    if is_tap_at_separation {
        let v: serde_json::Value = serde_json::from_str(&run(args, &["--json"], dir)).unwrap();
        let num = |k: &str| common::num(&v, k);
        let what = args.join(" ");
        assert!(num("jumps_in") > 0.0, "{what}: the tip never touches");
        if has(args, "--viscosity") {
            assert!(num("e_ts_viscous_j") > 0.0, "{what}: no viscous share");
        }
        if has(args, "--rupture-distance") {
            assert!(num("e_ts_capillary_j") > 0.0, "{what}: no neck");
            assert_eq!(v["grazing"], false, "{what}");
        }
        if has(args, "--law") && args.iter().any(|a| a == "hybrid") {
            assert!(num("e_ts_adhesion_j") > 0.0, "{what}: no hysteresis");
        }
        if has(args, "--hamaker") {
            // "a soft lever tapping; an attractive state coexists"
            assert!(
                num("phase_deg") < 90.0,
                "{what}: not on the repulsive branch"
            );
            let others = v["coexisting"].as_array().expect("coexisting");
            assert!(
                others.iter().any(|o| o["branch"] == "attractive"),
                "{what}: no attractive state beside it"
            );
        }
    }
    if command == "contrast" && has(args, "--material") {
        let v: serde_json::Value = serde_json::from_str(&run(args, &["--json"], dir)).unwrap();
        let rows = &common::rows(&v);
        let delta = |law: &str, setpoint: f64| {
            rows.iter()
                .find(|r| {
                    r["law"] == law
                        && r["branch"] == "repulsive"
                        && (common::num(r, "amplitude_ratio") - setpoint).abs() < 1e-9
                })
                .and_then(|r| r["delta_phase_deg"].as_f64())
        };
        for setpoint in [0.9, 0.8, 0.7, 0.6, 0.5] {
            let (jkr, hybrid) = (delta("jkr", setpoint), delta("hybrid", setpoint));
            let (Some(jkr), Some(hybrid)) = (jkr, hybrid) else {
                panic!("no repulsive contrast at {setpoint}: {jkr:?} {hybrid:?}")
            };
            let ratio = jkr / hybrid;
            assert!((5.0..=7.0).contains(&ratio), "{setpoint}: {jkr} / {hybrid}");
        }
    }
}

/// A table shows no negative zero (`-0.0000`) and no round-off as data (an exponent
/// below −30, as in `-3.0e-34 J`).
fn assert_no_round_off(text: &str, what: &str) {
    for word in text.split(|c: char| c.is_whitespace() || c == ',' || c == '(' || c == ')') {
        let digits = word.trim_start_matches(['-', '−']);
        let negative_zero = digits.len() < word.len()
            && digits.starts_with("0.")
            && digits
                .trim_end_matches(|c: char| !c.is_ascii_digit())
                .chars()
                .all(|c| c == '0' || c == '.');
        assert!(!negative_zero, "{what}: negative zero {word:?}");
        if let Some(exponent) = digits.split(['e', 'E']).nth(1) {
            if let Ok(e) = exponent.parse::<i32>() {
                assert!(
                    e > -30 || !digits.starts_with(|c: char| c.is_ascii_digit()),
                    "{what}: round-off {word:?}"
                );
            }
        }
    }
}

/// Where the tip never reaches the sample, tap says so and prints its zeros as zeros, and
/// an approach plot says why it has no peak-force panels.
#[test]
fn a_state_out_of_reach_says_so_and_prints_zeros_as_zero() {
    let out = common::tapsim(&["tap", "--separation", "30nm"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("the tip never comes into contact"), "{text}");
    assert!(text.contains("0 J = 0 eV"), "{text}");
    assert!(text.contains("none / none"), "{text}");
    assert_no_round_off(&text, "tap --separation 30nm");
    let out = common::tapsim(&[
        "tap",
        "--law",
        "dmt",
        "--hamaker",
        "1e-19",
        "--separation",
        "25nm",
    ]);
    assert_no_round_off(&String::from_utf8_lossy(&out.stdout), "dmt far out");
    let plot = common::scratch("out_of_reach").join("far.png");
    let out = common::tapsim(&[
        "approach",
        "--from",
        "30nm",
        "--to",
        "22nm",
        "--points",
        "3",
        "--plot",
        plot.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no peak-force panels"), "{err}");
}

/// The guide ("Built-in defaults of `tapsim tap`"): a stable period-1 orbit found in 11
/// periods, A/A₀ = 0.9415, φ = 75.739°, E_ts = 20.46 eV, grazing margin 3.77 nm — as
/// `tap --json` prints them.
#[test]
fn the_readme_numbers_of_the_defaults_are_what_tap_prints() {
    let v = common::json(&["tap", "--json"]);
    let num = |k: &str| common::num(&v, k);
    assert_eq!(v["regime"], "period-1");
    assert_eq!(v["stable"], true);
    assert_eq!(
        format!(
            "{} {:.4} {:.3} {:.2} {:.2}",
            num("cycles"),
            num("amplitude_ratio"),
            num("phase_deg"),
            num("e_ts_ev"),
            num("grazing_margin_m") * 1e9
        ),
        "11 0.9415 75.739 20.46 3.77"
    );
}
