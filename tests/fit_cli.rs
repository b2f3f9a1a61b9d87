//! `tapsim fit` from the command line: the CSV `tapsim approach --csv` writes, fitted
//! back, and data refused with a message that says why.

use crate::common;
use common::{json, num, refused, scratch, tapsim};

/// The built-in E*, written out: 1/E* = (1 − ν_tip²)/E_tip + (1 − ν²)/E, silicon on
/// the built-in polymer.
fn built_in_modulus() -> f64 {
    1.0 / ((1.0 - 0.28f64.powi(2)) / 169e9 + (1.0 - 0.4f64.powi(2)) / 0.5e9)
}

/// Issue 43's branch-jumping curve as `tapsim approach` makes it: E* 0.8 GPa, Δγ
/// 0.07 J/m², 40 points from 24 to 8 nm, approach only.
const ISSUE_CURVE: [&str; 11] = [
    "--modulus",
    "0.8GPa",
    "--work-of-adhesion",
    "0.07J/m^2",
    "--from",
    "24nm",
    "--to",
    "8nm",
    "--points",
    "40",
    "--no-retract",
];

/// `tapsim approach ARGS -q --csv CSV`, which must succeed.
fn approach_csv(csv: &str, args: &[&str]) {
    let out = tapsim(&[&["approach"], args, &["-q", "--csv", csv]].concat());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// An approach curve `tapsim approach` writes (noise-free, the hybrid defaults) is read
/// as it is and fitted back from a start 35 % and 20 % off: E* = 593.31 MPa and
/// Δγ = 0.1 J/m² to 1e-6; without standard deviations given and no noise to estimate
/// them from, the report gives no intervals and says why, and names the E*–Δγ trade-off.
#[test]
fn an_approach_curve_is_fitted_back() {
    let dir = scratch("fit-roundtrip");
    let csv = dir.join("curve.csv");
    let csv = csv.to_str().unwrap();
    approach_csv(
        csv,
        &[
            "--from",
            "18.5nm",
            "--to",
            "8nm",
            "--points",
            "12",
            "--no-retract",
        ],
    );
    let v = json(&[
        "fit",
        csv,
        "--modulus",
        "0.8GPa",
        "--work-of-adhesion",
        "0.12J/m^2",
        "--search",
        "local",
        "--offset",
        "0.3nm",
        "--json",
    ]);
    let params = v["parameters"].as_array().unwrap();
    let truth = built_in_modulus();
    assert!((num(&params[0], "value") / truth - 1.0).abs() < 1e-6);
    assert!((num(&params[1], "value") / 0.1 - 1.0).abs() < 1e-6);
    assert!(num(&params[2], "value").abs() < 1e-15);
    assert!(params.iter().all(|p| p["interval_95"].is_null()));
    let notes = v["identifiability"]["notes"].to_string();
    assert!(notes.contains("own precision"), "{notes}");
    assert!(notes.contains("trade off"), "{notes}");
    let plot = dir.join("fit.svg");
    let text = String::from_utf8(
        tapsim(&[
            "fit",
            csv,
            "--modulus",
            "0.8GPa",
            "--work-of-adhesion",
            "0.12J/m^2",
            "--search",
            "local",
            "--plot",
            plot.to_str().unwrap(),
        ])
        .stdout,
    )
    .unwrap();
    assert!(text.contains("5.93312e8"), "{text}");
    let svg = std::fs::read_to_string(&plot).unwrap();
    for label in [
        "measured (curve.csv)",
        "fitted (hybrid law)",
        "phase residual",
    ] {
        assert!(svg.contains(label), "{label}");
    }
    // A law that cannot describe the data: the fit's steps leave the plausible range
    // (E* below 1 kPa) and it stops, saying why, instead of printing a fit.
    // Hybrid data fitted with a law that cannot describe them: a verdict, not an
    // interval — its trials outside the law's range refused as steps.
    let out = tapsim(&[
        "fit",
        csv,
        "--law",
        "dmt",
        "--work-of-adhesion",
        "0.02",
        "--fit",
        "modulus",
        "--search",
        "local",
        "--max-curves",
        "60",
        "-q",
    ]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(out.status.success(), "{text}");
    assert!(text.contains("NOT converged"), "{text}");
    assert!(
        text.contains("THE FIT DOES NOT DESCRIBE THE DATA"),
        "{text}"
    );
    assert!(text.contains("worst points"), "{text}");
    let row = text.lines().find(|l| l.starts_with("modulus_pa")).unwrap();
    assert!(row.trim_end().ends_with('-') && !row.contains('['), "{row}");
    // --csv: the data beside the fit, one row per point; the fitted values are the
    // JSON's curve, the residuals its residuals (amplitudes first).
    let rows = dir.join("fit.csv");
    let out = tapsim(&[
        "fit",
        csv,
        "--modulus",
        "0.8GPa",
        "--work-of-adhesion",
        "0.12J/m^2",
        "--search",
        "local",
        "--offset",
        "0.3nm",
        "-q",
        "--csv",
        rows.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let table = Table::read(&rows);
    assert_eq!(table.rows.len(), 12);
    let fitted_phase = v["fitted"]["phase_deg"].as_array().unwrap();
    let residuals = v["residuals"].as_array().unwrap();
    for (i, row) in table.rows.iter().enumerate() {
        let cell = |name: &str| row[table.at(name)].parse::<f64>().unwrap();
        let same = |a: f64, b: &serde_json::Value| (a / b.as_f64().unwrap() - 1.0).abs() < 1e-9;
        assert!(same(cell("fitted_phase_deg"), &fitted_phase[i]));
        // (fitted − measured)/σ, σ the default weights 0.02 nm and 0.05°.
        let (ra, rp) = (cell("amplitude_residual"), cell("phase_residual"));
        let expect_a = (cell("fitted_amplitude_m") - cell("amplitude_m")) / 0.02e-9;
        let expect_p = (cell("fitted_phase_deg") - cell("phase_deg")) / 0.05;
        assert!((ra - expect_a).abs() < 1e-6 && (rp - expect_p).abs() < 1e-6);
        assert!(
            same(ra, &residuals[i]) || ra == 0.0,
            "{ra} {}",
            residuals[i]
        );
        assert!(same(rp, &residuals[12 + i]) || rp == 0.0);
        assert_eq!(&row[table.at("well_defined")], "true");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn bad_data_are_refused_with_why() {
    let dir = scratch("fit-refusals");
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let rising = write("rising.csv", "z_nm,phase_deg\n8,120\n9,121\n10,122\n");
    refused(&["fit", &rising], "from far to near");
    let within = write(
        "within.csv",
        "segment,z_nm,phase_deg\na,10,120\na,9,121\nb,10,120\nb,11,121\n",
    );
    refused(&["fit", &within], "point 4");
    let nameless = write("nameless.csv", "height,phase_deg\n10,120\n9,121\n8,122\n");
    refused(&["fit", &nameless], "no position column");
    let words = write("words.csv", "z_nm,phase_deg\n10,120\n9,abc\n8,122\n");
    refused(&["fit", &words], "row 3: the phase \"abc\" is not a number");
    let short = write("short.csv", "z_nm,phase_deg\n10,120\n9,121\n");
    refused(&["fit", &short], "3 to 2000 measured points");
    let good = write(
        "good.csv",
        "z_nm,amplitude_nm,phase_deg\n10,15,120\n9,14,121\n8,13,122\n",
    );
    refused(
        &["fit", &good, "--sigma-phase", "0.05"],
        "--sigma-amplitude",
    );
    refused(&["fit", &good, "--fit", "modulus,modulus"], "chosen twice");
    refused(&["fit", "/nonexistent/data.csv"], "No such file");
    refused(
        &["fit", &good, "--plot", "fit.txt"],
        "must end in .png or .svg",
    );
    let second = write(
        "second.csv",
        "z_nm,amplitude_nm,phase_deg,phase2_deg\n10,15,120,30\n9,14,121,29\n8,13,122,28\n",
    );
    refused(&["fit", &second], "simulate the modes too (--modes 2)");
    refused(
        &["fit", &second, "--modes", "2", "--temperature", "300K"],
        "thermal averages are simulated for one mode",
    );
    let setpoints = write(
        "setpoints.csv",
        "setpoint,phase_deg\n0.9,100\n0.8,105\n0.7,110\n",
    );
    refused(
        &["fit", &setpoints, "--temperature", "300K"],
        "a temperature averages the points of an approach curve",
    );
    refused(
        &[
            "fit",
            &good,
            "--temperature",
            "300K",
            "--thermal-periods",
            "10",
        ],
        "a thermal average spans 800",
    );
    refused(
        &["fit", &good, "--fit", "viscosity"],
        "needs a viscous sample to start from",
    );
    refused(&["fit", &good, "--fit", "hamaker"], "needs the dmt law");
    std::fs::remove_dir_all(dir).unwrap();
}

/// Two approaches in one file (a `segment` column): one from far (the attractive
/// branch) and one begun at 8 nm (the repulsive), fitted for E*, Δγ and ε together —
/// the data determine all three (condition number below 100) and give back the truth.
#[test]
fn approaches_joined_by_a_segment_column_are_fitted_together() {
    let dir = scratch("fit-segments");
    let mut joined = String::from("segment,z_m,amplitude_m,phase_deg\n");
    for (label, from, to) in [("far", "18.5nm", "8nm"), ("near", "8nm", "2nm")] {
        let csv = dir.join(format!("{label}.csv"));
        let csv = csv.to_str().unwrap();
        approach_csv(
            csv,
            &["--from", from, "--to", to, "--points", "10", "--no-retract"],
        );
        let table = Table::read(csv.as_ref());
        let col = |name: &str| table.at(name);
        let (z, a, p) = (col("separation_m"), col("amplitude_m"), col("phase_deg"));
        for row in &table.rows {
            joined.push_str(&format!("{label},{},{},{}\n", &row[z], &row[a], &row[p]));
        }
    }
    let data = dir.join("joined.csv");
    std::fs::write(&data, joined).unwrap();
    let v = json(&[
        "fit",
        data.to_str().unwrap(),
        "--fit",
        "modulus,work-of-adhesion,range",
        "--sigma-amplitude",
        "0.02nm",
        "--sigma-phase",
        "0.05",
        "--work-of-adhesion",
        "0.11J/m^2",
        "--json",
    ]);
    let cond = num(&v["identifiability"], "condition_number");
    assert!(cond < 100.0, "{cond}");
    let params = v["parameters"].as_array().unwrap();
    assert!((num(&params[1], "value") / 0.1 - 1.0).abs() < 1e-5);
    assert!((num(&params[2], "value") / 0.3e-9 - 1.0).abs() < 1e-5);
    std::fs::remove_dir_all(dir).unwrap();
}

/// Phase against the amplitude setpoint (a `setpoint` column, no positions), as phase
/// imaging records it: `tapsim approach --sweep setpoint` gives the phases; fitted for
/// Δγ (E* known) they give it back; E* and Δγ together are flagged as trading off, with
/// no values; the offset, which such data do not have, is refused.
#[test]
fn phases_at_setpoints_are_fitted() {
    let dir = scratch("fit-setpoints");
    let sweep = dir.join("sweep.csv");
    approach_csv(
        sweep.to_str().unwrap(),
        &[
            "--sweep",
            "setpoint",
            "--from",
            "0.75",
            "--to",
            "0.55",
            "--points",
            "5",
            "--no-retract",
        ],
    );
    let table = Table::read(&sweep);
    let (a, p) = (table.at("amplitude_ratio"), table.at("phase_deg"));
    let mut text = String::from("setpoint,phase_deg\n");
    for row in &table.rows {
        text.push_str(&format!("{},{}\n", &row[a], &row[p]));
    }
    let data = dir.join("phase_vs_setpoint.csv");
    std::fs::write(&data, text).unwrap();
    let data = data.to_str().unwrap();
    let sigma = ["--sigma-phase", "0.05"];
    let mut args = vec![
        "fit",
        data,
        "--search",
        "local",
        "--fit",
        "work-of-adhesion",
    ];
    args.extend(["--work-of-adhesion", "0.08J/m^2", "--json"]);
    args.extend(sigma);
    let v = json(&args);
    let params = v["parameters"].as_array().unwrap();
    assert!(
        (num(&params[0], "value") / 0.1 - 1.0).abs() < 1e-5,
        "{params:?}"
    );
    let mut args = vec!["fit", data, "--search", "local", "--json"];
    args.extend(sigma);
    let v = json(&args);
    let params = v["parameters"].as_array().unwrap();
    assert_eq!(params.len(), 2, "E* and Δγ, no offset by default");
    assert!(params.iter().all(|p| p["value"].is_null()), "{params:?}");
    assert!(
        v["identifiability"]["notes"]
            .to_string()
            .contains("trade off along")
    );
    refused(&["fit", data, "--fit", "z-offset"], "no offset");
    std::fs::remove_dir_all(dir).unwrap();
}

/// Several laws are for `tapsim fit` alone: another command refuses them and says
/// where they belong.
#[test]
fn several_laws_are_refused_outside_fit() {
    refused(
        &["tap", "--law", "hybrid,jkr", "-q"],
        "tapsim fit --law a,b",
    );
}

/// A CSV tapsim wrote: its header and its rows.
struct Table {
    headers: csv::StringRecord,
    rows: Vec<csv::StringRecord>,
}

impl Table {
    fn read(path: &std::path::Path) -> Self {
        let mut reader = csv::Reader::from_path(path).unwrap();
        let headers = reader.headers().unwrap().clone();
        let rows = reader.records().map(|r| r.unwrap()).collect();
        Self { headers, rows }
    }

    /// Where column `name` is.
    fn at(&self, name: &str) -> usize {
        self.headers.iter().position(|h| h == name).unwrap()
    }

    /// The cells of column `name`, row by row.
    fn column(&self, name: &str) -> Vec<&str> {
        let at = self.at(name);
        self.rows.iter().map(|r| &r[at]).collect()
    }
}

/// The curve a new user fits first — `tapsim approach --csv` on the defaults, from 24 nm
/// in, crossing the onset of contact — holds points that graze a switch of the law (mode
/// locks one draw among several): the fit leaves out the rows the file flags (counted
/// here from the file itself), says so, and from a start at 1 GPa and 0.2 J/m² comes
/// back to the truth — E* from the tip's and the sample's moduli — to 1e-5.
/// `--keep-grazing` fits every row.
#[test]
fn the_rows_a_curve_flags_as_grazing_are_left_out_of_the_fit() {
    let dir = scratch("fit-grazing");
    let csv = dir.join("approach.csv");
    let csv = csv.to_str().unwrap();
    approach_csv(csv, &["--points", "40", "--no-retract"]);
    let table = Table::read(csv.as_ref());
    let rows = table.rows.len();
    let grazing = table
        .column("grazing")
        .iter()
        .filter(|g| **g == "true")
        .count();
    assert!(grazing >= 1 && grazing < rows / 2, "{grazing}");
    let start = [
        "fit",
        csv,
        "--fit",
        "modulus,work-of-adhesion",
        "--modulus",
        "1GPa",
        "--work-of-adhesion",
        "0.2J/m^2",
    ];
    let v = json(&[&start[..], &["--json", "--quiet"]].concat());
    assert_eq!(num(&v, "grazing_points_left_out"), grazing as f64);
    assert_eq!(
        num(&v, "degrees_of_freedom"),
        (2 * (rows - grazing) - 2) as f64
    );
    assert_eq!(v["converged"], true);
    let modulus = built_in_modulus();
    let fitted = |i: usize| v["parameters"][i]["value"].as_f64().unwrap();
    assert!((fitted(0) / modulus - 1.0).abs() < 1e-5, "{}", fitted(0));
    assert!((fitted(1) / 0.1 - 1.0).abs() < 1e-5, "{}", fitted(1));
    let text =
        String::from_utf8_lossy(&tapsim(&[&start[..], &["--quiet"]].concat()).stdout).into_owned();
    assert!(
        text.contains(&format!(
            "note: {grazing} of the file's points are flagged grazing"
        )),
        "{text}"
    );
    let kept = json(
        &[
            &start[..],
            &["--keep-grazing", "--max-curves", "3", "--json", "--quiet"],
        ]
        .concat(),
    );
    assert_eq!(num(&kept, "grazing_points_left_out"), 0.0);
    assert_eq!(num(&kept, "degrees_of_freedom"), (2 * rows - 2) as f64);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A curve as an instrument writes it, without a `grazing` column: issue 43's
/// branch-jumping curve (E* 0.8 GPa, Δγ 0.07 J/m², 40 points from 24 to 8 nm), whose
/// first touching point grazes the jump-in. Fitted from 0.6 GPa and 0.1 J/m², the fit
/// finds that point grazing at its own best parameters, leaves it out (`left_out`, the
/// row `tapsim approach` flagged, and a note naming where), runs again without it and
/// ends on the truth to 1e-6; `--keep-grazing` fits all 40.
#[test]
fn a_point_grazing_at_the_fitted_parameters_is_left_out() {
    let dir = scratch("fit-left-out");
    let full = dir.join("full.csv");
    approach_csv(full.to_str().unwrap(), &ISSUE_CURVE);
    let table = Table::read(&full);
    let (headers, rows, at) = (&table.headers, &table.rows, table.at("grazing"));
    let flagged: Vec<f64> = (0..rows.len())
        .filter(|&i| &rows[i][at] == "true")
        .map(|i| i as f64)
        .collect();
    assert_eq!(flagged.len(), 1, "{flagged:?}");
    let bare = dir.join("bare.csv");
    let mut writer = csv::Writer::from_path(&bare).unwrap();
    let others = |r: &csv::StringRecord| {
        r.iter()
            .enumerate()
            .filter(|(i, _)| *i != at)
            .map(|(_, v)| v.to_string())
            .collect::<Vec<_>>()
    };
    writer.write_record(others(headers)).unwrap();
    for r in rows {
        writer.write_record(others(r)).unwrap();
    }
    writer.flush().unwrap();
    let start = [
        "fit",
        bare.to_str().unwrap(),
        "--fit",
        "modulus,work-of-adhesion",
        "--modulus",
        "0.6GPa",
        "--work-of-adhesion",
        "0.1J/m^2",
    ];
    let v = json(&[&start[..], &["--json", "--quiet"]].concat());
    assert_eq!(common::column(&v, "left_out"), flagged);
    assert_eq!(
        num(&v, "degrees_of_freedom"),
        (2 * (rows.len() - 1) - 2) as f64
    );
    assert_eq!(v["converged"], true);
    for (i, truth) in [0.8e9, 0.07].into_iter().enumerate() {
        let f = v["parameters"][i]["value"].as_f64().unwrap();
        assert!((f / truth - 1.0).abs() < 1e-6, "{f}");
    }
    let out = tapsim(&start);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    // The log says what the second run is (one line a stage where stderr is a file).
    let log = String::from_utf8_lossy(&out.stderr);
    assert!(
        log.lines()
            .any(|l| l.starts_with("fitting: again without the 1 grazing point(s), ")),
        "{log}"
    );
    let z = rows[flagged[0] as usize][table.at("separation_m")]
        .parse::<f64>()
        .unwrap();
    assert!(
        text.contains("1 point(s) whose state at the fitted parameters grazes")
            && text.contains(&format!("(at {:.3} nm)", z * 1e9)),
        "{text}"
    );
    let kept = json(
        &[
            &start[..],
            &["--keep-grazing", "--max-curves", "3", "--json", "--quiet"],
        ]
        .concat(),
    );
    assert!(common::column(&kept, "left_out").is_empty());
    assert_eq!(
        num(&kept, "degrees_of_freedom"),
        (2 * rows.len() - 2) as f64
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 43's new user: the 100-point CSV `tapsim approach --points 100 --csv` writes
/// (noise-free), fitted with `tapsim fit FILE --modulus 1GPa --work-of-adhesion
/// 0.2J/m^2` and nothing else (the global stage, σ estimated). The first local run that
/// reaches the data's own precision ends the search: one run, no continuation from a
/// "stalled" end (a Gauss–Newton step at round-off gains round-off), and the truth to
/// 1e-6. Before, the residuals' round-off pattern failed the runs test, so two more
/// local runs and two continuations followed: 290 curves in 41 s instead of 139 in 3 s.
#[test]
fn a_fit_that_resolves_the_data_searches_no_further() {
    let dir = scratch("fit-resolved");
    let csv = dir.join("approach.csv");
    let csv = csv.to_str().unwrap();
    approach_csv(csv, &["--points", "100"]);
    let v = json(&[
        "fit",
        csv,
        "--modulus",
        "1GPa",
        "--work-of-adhesion",
        "0.2J/m^2",
        "--json",
    ]);
    let params = v["parameters"].as_array().unwrap();
    let truth = built_in_modulus();
    assert!((num(&params[0], "value") / truth - 1.0).abs() < 1e-6, "{v}");
    assert!((num(&params[1], "value") / 0.1 - 1.0).abs() < 1e-6, "{v}");
    assert_eq!(v["converged"], true);
    let minima = v["minima"].as_array().unwrap();
    let runs: u64 = minima.iter().map(|m| m["runs"].as_u64().unwrap()).sum();
    assert_eq!(runs, 1, "{minima:?}");
    let curves = v["curves"].as_u64().unwrap();
    assert!(curves < 200, "{curves} curves");
}

/// The round trip at a temperature: `tapsim approach --temperature 300K --csv` writes
/// each grazing point's thermal average beside its deterministic state, and `tapsim
/// fit --temperature 300K` reads the average there (what an instrument reads). With
/// the same periods each point draws the same noise in both (seed 1, its place along
/// the curve), so the issue's branch-jumping curve comes back from 2 % off to 1e-4,
/// every row kept and the averaged ones marked; read without the temperature, the
/// deterministic columns and the grazing rows left out, as before. The rows `--csv`
/// writes mark the averaged points (`thermal_average`).
#[test]
#[ignore = "slow (two approaches and fits at 300 K, about 13 s in release): run with cargo test --release -- --ignored fit_cli::"]
fn a_curve_written_at_a_temperature_is_fitted_back_at_it() {
    let dir = scratch("fit-warm-roundtrip");
    let csv = dir.join("warm.csv");
    let csv = csv.to_str().unwrap();
    let thermal = ["--temperature", "300K", "--thermal-periods", "800"];
    approach_csv(csv, &[&ISSUE_CURVE[..], &thermal].concat());
    let table = Table::read(csv.as_ref());
    let averaged: Vec<bool> = table
        .column("thermal_average_phase_deg")
        .iter()
        .map(|p| !p.is_empty())
        .collect();
    let flagged: Vec<bool> = table
        .column("grazing")
        .iter()
        .map(|g| *g == "true")
        .collect();
    assert!(averaged.contains(&true));
    assert_eq!(averaged, flagged);
    let fit = [
        "fit",
        csv,
        "--fit",
        "modulus,work-of-adhesion",
        "--search",
        "local",
        "--modulus",
        "0.816GPa",
        "--work-of-adhesion",
        "0.0714J/m^2",
        "--json",
        "--quiet",
    ];
    let rows_csv = dir.join("rows.csv");
    let rows_at = ["--csv", rows_csv.to_str().unwrap()];
    let v = json(&[&fit[..], &thermal, &rows_at].concat());
    assert_eq!(num(&v, "grazing_points_left_out"), 0.0);
    let written: Vec<bool> = Table::read(&rows_csv)
        .column("thermal_average")
        .iter()
        .map(|a| *a == "true")
        .collect();
    assert_eq!(written, averaged);
    let marked: Vec<bool> = v["fitted"]["averaged"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a.as_bool().unwrap())
        .collect();
    assert_eq!(marked, averaged);
    let fitted = |v: &serde_json::Value, i: usize| v["parameters"][i]["value"].as_f64().unwrap();
    assert!(
        (fitted(&v, 0) / 0.8e9 - 1.0).abs() < 1e-4,
        "{}",
        fitted(&v, 0)
    );
    assert!(
        (fitted(&v, 1) / 0.07 - 1.0).abs() < 1e-4,
        "{}",
        fitted(&v, 1)
    );
    let cold = json(&fit);
    let left_out = flagged.iter().filter(|f| **f).count();
    assert_eq!(num(&cold, "grazing_points_left_out"), left_out as f64);
    let _ = std::fs::remove_dir_all(&dir);
}
