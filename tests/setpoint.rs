//! Steady states at an amplitude setpoint (issue 26): `tap --setpoint` solves for the
//! rest separations at which the amplitude is the setpoint, on each branch; each state
//! is then found again by a plain `tap` at that separation, marched from the documented
//! starts — a different path (time-marching and shooting from fixed starts, no
//! continuation, no root-finding).

use crate::common;
use common::{cells, json, num, scratch, tapsim};
use serde_json::Value;

#[test]
fn every_state_at_the_setpoint_is_a_state_tap_finds_at_its_separation() {
    let v = json(&["tap", "--setpoint", "0.8", "--json"]);
    let states = v["states"].as_array().unwrap();
    // The defaults are bistable at 0.8: both branches, attractive first.
    let branches: Vec<&str> = states
        .iter()
        .map(|s| s["branch"].as_str().unwrap())
        .collect();
    assert_eq!(branches, ["attractive", "repulsive"]);
    // The top-level keys are the first state's.
    assert_eq!(v["separation_m"], states[0]["separation_m"]);
    assert_eq!(v["phase_deg"], states[0]["phase_deg"]);
    assert_eq!(num(&v, "setpoint"), 0.8);
    // The guide's numbers.
    let at = |i: usize, key: &str| num(&states[i], key);
    assert!((at(0, "separation_m") * 1e9 - 16.7895).abs() < 5e-5);
    assert!((at(0, "phase_deg") - 123.632).abs() < 5e-4);
    assert!((at(1, "separation_m") * 1e9 - 12.9425).abs() < 5e-5);
    assert!((at(1, "phase_deg") - 56.368).abs() < 5e-4);
    for i in 0..2 {
        assert!((at(i, "e_ts_ev") - 20.46).abs() < 5e-3);
    }
    for s in states {
        assert!((num(s, "amplitude_ratio") - 0.8).abs() < 1e-6, "{s}");
        assert_eq!(s["regime"], "period-1");
        let phase = num(s, "phase_deg");
        match s["branch"].as_str().unwrap() {
            "attractive" => assert!(phase > 90.0, "{phase}"),
            _ => assert!(phase < 90.0, "{phase}"),
        }
        // Marched from the documented starts at that separation, tap reaches it.
        let z = format!("{:e}", num(s, "separation_m"));
        let t = json(&["tap", "--separation", &z, "--starts", "6", "--json"]);
        let mut found = vec![(num(&t, "phase_deg"), num(&t, "e_ts_j"))];
        for a in t["attractors"].as_array().unwrap() {
            found.push((num(a, "phase_deg"), num(a, "e_ts_j")));
        }
        let e = num(s, "e_ts_j");
        assert!(
            found
                .iter()
                .any(|&(p, et)| (p - phase).abs() < 1e-6 * phase && (et - e).abs() < 1e-6 * e),
            "{} state at {z} m (φ {phase}, E_ts {e}) not among tap's {found:?}",
            s["branch"]
        );
    }
}

#[test]
fn a_branch_can_be_asked_for_and_the_setpoint_given_as_an_amplitude() {
    let both = json(&["tap", "--setpoint", "0.8", "--json"]);
    let repulsive = json(&[
        "tap",
        "--amplitude-setpoint",
        "16nm",
        "--branch",
        "repulsive",
        "--json",
    ]);
    let states = repulsive["states"].as_array().unwrap();
    assert_eq!(states.len(), 1);
    assert_eq!(states[0]["branch"], "repulsive");
    assert_eq!(states[0]["separation_m"], both["states"][1]["separation_m"]);
}

#[test]
fn a_setpoint_is_refused_where_it_cannot_be_held() {
    for (args, says) in [
        (
            vec!["tap", "--setpoint", "0.8", "--separation", "16nm"],
            "not both",
        ),
        (vec!["tap", "--setpoint", "1.2"], "outside (0, 1)"),
        (vec!["tap", "--setpoint", "0"], "outside (0, 1)"),
        (
            vec!["tap", "--setpoint", "0.8", "--plot", "x.png"],
            "--separation <z_c>",
        ),
        (
            vec!["tap", "--setpoint", "0.8", "--law", "none"],
            "the amplitude does not reach it (A/A₀ = 1.0000",
        ),
        // Near the onset of contact a ramp meets long locks grazing the jump-in.
        (
            vec!["tap", "--setpoint", "0.95", "--branch", "attractive"],
            "not held either: the states that bracket it",
        ),
        // A contrast at a setpoint no material holds (it printed an empty table).
        (
            vec![
                "contrast",
                "--setpoints",
                "0.1",
                "--laws",
                "hybrid",
                "--points",
                "8",
                "--quiet",
            ],
            "no material holds the amplitude setpoint A/A₀ = 0.1",
        ),
    ] {
        let out = tapsim(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(out.stdout.is_empty());
    }
}

#[test]
fn contrast_and_tap_at_a_setpoint_agree_and_the_apparent_height_is_the_step_in_z_c() {
    let rows = json(&[
        "contrast",
        "--laws",
        "hybrid",
        "--setpoints",
        "0.8",
        "--json",
    ]);
    let tap = json(&["tap", "--setpoint", "0.8", "--json"]);
    let rows = &common::rows(&rows);
    assert_eq!(rows.len(), 2, "both branches at 0.8");
    for row in rows {
        // Material A is tap's defaults.
        let state = tap["states"]
            .as_array()
            .unwrap()
            .iter()
            .find(|s| s["branch"] == row["branch"])
            .expect("the same branches");
        let phase = row["phase_deg"][0].as_f64().unwrap();
        assert!((phase - num(state, "phase_deg")).abs() < 1e-6, "{row}");
        let z: Vec<f64> = row["separation_m"]
            .as_array()
            .unwrap()
            .iter()
            .map(|z| z.as_f64().unwrap())
            .collect();
        assert!((z[0] - num(state, "separation_m")).abs() < 1e-15, "{row}");
        assert_eq!(num(row, "apparent_height_m"), z[1] - z[0]);
        assert!(num(row, "apparent_height_m").abs() > 1e-11, "{row}");
    }
}

#[test]
fn readme_contrast_numbers() {
    // The guide: Δφ (deg) and Δz_c (nm) between the default polymers at 0.8 and 0.9.
    let rows = json(&["contrast", "--setpoints", "0.9,0.8", "--quiet", "--json"]);
    let row = |law: &str, r: f64, branch: &str| {
        common::rows(&rows)
            .iter()
            .find(|x| x["law"] == law && x["amplitude_ratio"] == r && x["branch"] == branch)
            .unwrap_or_else(|| panic!("{law} {r} {branch}"))
            .clone()
    };
    for (law, r, branch, dphi, dz_nm) in [
        ("jkr", 0.8, "repulsive", -8.17, Some(1.07)),
        ("hybrid", 0.8, "repulsive", -2.80, Some(1.19)),
        ("lj", 0.8, "repulsive", -2.83, None),
        ("jkr", 0.8, "attractive", 4.44, None),
        ("hybrid", 0.8, "attractive", 2.80, Some(-0.64)),
        ("lj", 0.8, "attractive", 2.83, None),
        ("jkr", 0.9, "attractive", 2.08, None),
        ("hybrid", 0.9, "attractive", 3.59, None),
        ("lj", 0.9, "attractive", 3.09, None),
    ] {
        let x = row(law, r, branch);
        assert!((num(&x, "delta_phase_deg") - dphi).abs() < 0.005, "{x}");
        if let Some(dz) = dz_nm {
            assert!(
                (num(&x, "apparent_height_m") * 1e9 - dz).abs() < 0.005,
                "{x}"
            );
        }
    }
}

#[test]
fn tap_names_the_other_stable_state_at_its_separation() {
    // The defaults are bistable: the free oscillation settles on the repulsive branch,
    // and tap lists the attractive state beside it, as marching from rest finds it.
    let v = json(&["tap", "--starts", "3", "--json"]);
    assert!(num(&v, "phase_deg") < 90.0);
    let other = v["coexisting"].as_array().unwrap();
    assert_eq!(other.len(), 1, "{other:?}");
    let o = &other[0];
    assert_eq!(o["branch"], "attractive");
    assert_eq!(num(o, "separation_m"), 16e-9);
    // The guide: A/A₀ = 0.7622, φ = 127.21°.
    assert!((num(o, "amplitude_ratio") - 0.7622).abs() < 5e-5);
    assert!((num(o, "phase_deg") - 127.21).abs() < 5e-3);
    let from_rest = v["attractors"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["starts"].as_array().unwrap().iter().any(|s| s == "rest"))
        .expect("the rest start's attractor");
    for key in ["amplitude_ratio", "phase_deg", "e_ts_j"] {
        let (a, b) = (num(o, key), num(from_rest, key));
        assert!((a - b).abs() <= 1e-6 * b.abs(), "{key}: {a} vs {b}");
    }
    // Far from the sample nothing else exists.
    let far = json(&["tap", "--separation", "23nm", "--json"]);
    assert!(far["coexisting"].as_array().unwrap().is_empty());
}

#[test]
fn a_map_at_a_setpoint_holds_it_in_every_cell_and_merges_like_any_map() {
    let dir = scratch("map");
    let at = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let common = [
        "map",
        "--setpoint",
        "0.8",
        "--branch",
        "repulsive",
        "--steps",
        "3",
    ];
    let v = json(&[
        "map",
        "--setpoint",
        "0.8",
        "--branch",
        "repulsive",
        "--steps",
        "10",
        "--json",
    ]);
    assert_eq!(v["setpoint"]["amplitude_ratio"], 0.8);
    let grid = &v["grid"];
    let (ratio, phase, z) = (
        cells(&grid["amplitude_ratio"]),
        cells(&grid["phase_deg"]),
        cells(&grid["separation_m"]),
    );
    let heights = cells(&v["apparent_height_m"]);
    let reference = z.iter().find_map(Value::as_f64).expect("a cell holds it");
    let mut held = 0;
    for k in 0..ratio.len() {
        let Some(r) = ratio[k].as_f64() else {
            assert!(heights[k].is_null());
            continue;
        };
        held += 1;
        assert!((r - 0.8).abs() < 1e-6, "cell {k}: {r}");
        // The repulsive branch throughout: no cell jumps to the other branch.
        assert!(phase[k].as_f64().unwrap() < 90.0, "cell {k}");
        // The apparent height is the cell's z_c less the reference cell's.
        let h = heights[k].as_f64().unwrap();
        assert_eq!(h, z[k].as_f64().unwrap() - reference, "cell {k}");
    }
    assert!(held >= 50, "{held} cells hold the setpoint");
    // φ varies smoothly: along each row (work of adhesion rising) it rises, down each
    // column (modulus rising) it falls, between every two neighbouring cells that hold
    // the setpoint.
    let rows = v["grid"]["phase_deg"].as_array().unwrap();
    let at_cell = |i: usize, j: usize| rows[i][j].as_f64();
    for i in 0..10 {
        for j in 0..10 {
            let Some(here) = at_cell(i, j) else { continue };
            if let Some(right) = (j < 9).then(|| at_cell(i, j + 1)).flatten() {
                assert!(right > here, "row {i}: {here} then {right}");
            }
            if let Some(below) = (i < 9).then(|| at_cell(i + 1, j)).flatten() {
                assert!(below < here, "column {j}: {here} then {below}");
            }
        }
    }
    // Split in two and merged: the whole map's CSV, byte for byte.
    let mut args: Vec<String> = common.iter().map(|s| s.to_string()).collect();
    args.extend(["--quiet".into(), "--csv".into(), at("whole.csv")]);
    let out = tapsim(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(out.status.success());
    let mut parts = Vec::new();
    for i in 0..2 {
        let part = at(&format!("p{i}.json"));
        let mut args: Vec<String> = common.iter().map(|s| s.to_string()).collect();
        args.extend([
            "--quiet".into(),
            "--shard".into(),
            format!("{i}/2"),
            "--part".into(),
            part.clone(),
        ]);
        let out = tapsim(&args.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        parts.push(part);
    }
    let merged = at("merged.csv");
    let out = tapsim(&["merge", &parts[0], &parts[1], "--quiet", "--out", &merged]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read(&merged).unwrap(),
        std::fs::read(at("whole.csv")).unwrap()
    );
    // A separation and a setpoint are not both given.
    let out = tapsim(&[
        "map",
        "--setpoint",
        "0.8",
        "--separation",
        "16nm",
        "--steps",
        "2",
    ]);
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn a_batch_row_at_a_setpoint_gives_the_states_tap_gives() {
    let dir = std::env::temp_dir().join(format!("tapsim-setpoint-batch-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let table = dir.join("t.csv");
    std::fs::write(
        &table,
        "name,setpoint,branch,separation\nboth,0.8,,\nrep,0.8,repulsive,\nz,,,16nm\n",
    )
    .unwrap();
    let v = json(&["batch", table.to_str().unwrap(), "--json"]);
    let col = |key: &str| v[key].as_array().unwrap().clone();
    let (case, branch, phase) = (col("case"), col("branch"), col("phase_deg"));
    assert_eq!(case, ["both", "both", "rep", "z"]);
    assert_eq!(branch[..3], ["attractive", "repulsive", "repulsive"]);
    let tap = json(&["tap", "--setpoint", "0.8", "--json"]);
    for (i, s) in [0, 1, 1].into_iter().enumerate() {
        let (a, b) = (
            phase[i].as_f64().unwrap(),
            num(&tap["states"][s], "phase_deg"),
        );
        assert!((a - b).abs() < 1e-6, "row {i}: {a} vs {b}");
    }
    // A setpoint beside a separation, or outside (0, 1), refuses the batch, naming the row.
    for (text, says) in [
        (
            "name,setpoint,separation\nx,0.8,16nm\n",
            "row 1: give either",
        ),
        ("name,setpoint\nx,1.5\n", "row 1: amplitude setpoint"),
        (
            "name,setpoint,branch\nx,0.8,up\n",
            "expected one of all, attractive, repulsive",
        ),
    ] {
        std::fs::write(&table, text).unwrap();
        let out = tapsim(&["batch", table.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(1));
        assert!(String::from_utf8_lossy(&out.stderr).contains(says));
    }
}

/// The search from the harmonic estimate of each branch's state (what `tap --setpoint`
/// runs first, in milliseconds) against the whole search of the period-1 families from
/// 1.2 A₀ in, seeded every 0.1 A₀ (what it falls back on): the same states, to the
/// refinement's 1e-9 in A/A₀, over setpoints from 0.2 to 0.95 and three laws, including
/// setpoints where the estimate leads nowhere and a branch that does not reach them.
#[test]
fn the_quick_search_at_a_setpoint_finds_what_the_whole_family_search_finds() {
    use tapsim::dynamics::setup::{Numerics, Prepared, TapSetup, default_setup};
    use tapsim::law::LawKind;
    use tapsim::setpoint::{families, states_at_setpoint, states_on};
    let numerics = Numerics::default();
    for (law, ratios) in [
        (LawKind::Hybrid, &[0.2, 0.5, 0.8, 0.9, 0.95][..]),
        (LawKind::Dmt, &[0.4, 0.85][..]),
        (LawKind::Hertz, &[0.7][..]),
    ] {
        let setup = TapSetup {
            law: law.into(),
            ..default_setup()
        };
        let a0 = setup.cantilever.free_amplitude_m;
        let p = Prepared::new(&setup, &numerics).unwrap();
        for &r in ratios {
            let range = (1.2 * a0, (r - 0.35f64).max(0.02) * a0);
            let family = families(&p, &numerics, range).unwrap();
            let whole = states_on(&p, &family, r, None).unwrap();
            let quick = states_at_setpoint(&setup, &numerics, r, None).unwrap();
            let show = |v: &[tapsim::setpoint::SetpointState]| {
                v.iter()
                    .map(|s| (s.branch, s.separation_m, s.observables.phase_deg))
                    .collect::<Vec<_>>()
            };
            assert_eq!(
                quick.len(),
                whole.len(),
                "{law:?} at {r}: {:?} vs {:?}",
                show(&quick),
                show(&whole)
            );
            for (q, w) in quick.iter().zip(&whole) {
                assert_eq!(q.branch, w.branch, "{law:?} at {r}");
                assert!(
                    (q.separation_m - w.separation_m).abs() < 1e-8 * a0,
                    "{law:?} at {r}: {:?} vs {:?}",
                    show(&quick),
                    show(&whole)
                );
                assert!(
                    (q.observables.phase_deg - w.observables.phase_deg).abs() < 1e-5,
                    "{law:?} at {r}"
                );
            }
        }
    }
}

/// A parameter file may hold the tip at a setpoint (`setpoint`, `amplitude-setpoint`,
/// `branch`) as the flags do; a flag that holds it (a separation or a setpoint) wins over
/// the file's; a file with a separation and a setpoint is refused, and so is a file
/// setpoint in a command that takes none.
#[test]
fn a_parameter_file_holds_a_setpoint_as_the_flags_do() {
    let dir = scratch("config");
    let file = |name: &str, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_string()
    };
    let at = file("at.toml", "setpoint = 0.8\nbranch = \"repulsive\"\n");
    let amp = file("amp.toml", "amplitude-setpoint = \"16nm\"\n");
    let sep = file("sep.toml", "separation = \"15nm\"\n");
    let both = file("both.toml", "setpoint = 0.8\nseparation = \"16nm\"\n");
    let flags = json(&["tap", "--setpoint", "0.8", "--json"]);
    let states = flags["states"].as_array().unwrap();
    // The file's setpoint and branch: the repulsive state the flags give.
    let v = json(&["tap", "--config", &at, "--json"]);
    assert_eq!(v["states"].as_array().unwrap().len(), 1);
    assert_eq!(v["branch"], "repulsive");
    assert_eq!(num(&v, "separation_m"), num(&states[1], "separation_m"));
    // A flag's branch over the file's.
    let v = json(&["tap", "--config", &at, "--branch", "all", "--json"]);
    assert_eq!(v["states"], flags["states"]);
    // An amplitude setpoint in the file: A/A₀ = 16 nm / 20 nm.
    let v = json(&["tap", "--config", &amp, "--json"]);
    assert_eq!(v["states"], flags["states"]);
    // A flag's setpoint over the file's separation, a flag's separation over its setpoint.
    let v = json(&["tap", "--config", &sep, "--setpoint", "0.8", "--json"]);
    assert_eq!(v["states"], flags["states"]);
    let v = json(&["tap", "--config", &at, "--separation", "15nm", "--json"]);
    assert_eq!(v, json(&["tap", "--separation", "15nm", "--json"]));
    assert!(v.get("states").is_none());
    // The map's cells at the file's setpoint are the flags'.
    let map = |extra: &[&str]| {
        let mut args = vec!["map", "--steps", "2", "--quiet", "--json"];
        args.extend_from_slice(extra);
        json(&args)
    };
    assert_eq!(map(&["--config", &at]), map(&["--setpoint", "0.8"]));
    // Refused: both in one file; a file setpoint where no setpoint is taken.
    let out = tapsim(&["tap", "--config", &both]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("separation and setpoint are exclusive"),
        "{err}"
    );
    for cmd in ["approach", "branches", "contrast"] {
        let out = tapsim(&[cmd, "--config", &at]);
        assert_eq!(out.status.code(), Some(1), "{cmd}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(&format!("`tapsim {cmd}` does not take")),
            "{err}"
        );
    }
}

/// An approach in setpoints (`approach --sweep setpoint`), as a z feedback lowers the
/// setpoint and raises it again: every state holds its setpoint; the states are those
/// a z_c sweep through the same rest separations reaches, carrying the oscillator the
/// same way (a plain ramp, no walking, no root-finding); and each is a state `tap
/// --setpoint` finds at that setpoint by continuation of the period-1 families (the
/// attractive one: lowered from far, the setpoint stays on the branch the free
/// oscillation starts on).
#[test]
fn an_approach_in_setpoints_gives_the_states_of_the_z_sweep_through_its_separations() {
    use tapsim::dynamics::setup::{Numerics, default_setup};
    use tapsim::setpoint::sweep_setpoints;
    use tapsim::sweep::{Direction, approach_curve, ramp};
    let setup = default_setup();
    let numerics = Numerics::default();
    let a0 = setup.cantilever.free_amplitude_m;
    let ratios = ramp(0.95, 0.4, 12, true).unwrap();
    let swept = sweep_setpoints(&setup, &numerics, &ratios, |_, _| {}).unwrap();
    // 0.95 lies in the window near the onset of contact where the motion locks onto long
    // periods: not held, with why, on the way in and out.
    assert!(swept.not_held.iter().any(|(r, d, why)| *r == 0.95
        && *d == Direction::Approach
        && why.contains("grazing a switch")));
    assert!(swept.points.len() >= 18, "{}", swept.points.len());
    for p in &swept.points {
        let r = ratios
            .iter()
            .filter(|(_, d)| *d == p.direction)
            .map(|(r, _)| *r)
            .min_by(|a, b| {
                (a - p.observables.amplitude_ratio)
                    .abs()
                    .total_cmp(&(b - p.observables.amplitude_ratio).abs())
            })
            .unwrap();
        assert!(
            (p.observables.amplitude_ratio - r).abs() < 1e-8,
            "{r}: {}",
            p.observables.amplitude_ratio
        );
    }
    // The z sweep from the free oscillation at 1.2 A₀ through the same separations.
    let mut through = vec![(1.2 * a0, Direction::Approach)];
    through.extend(swept.points.iter().map(|p| (p.separation_m, p.direction)));
    let plain = approach_curve(&setup, &numerics, &through, |_, _| {}).unwrap();
    for (s, z) in swept.points.iter().zip(&plain[1..]) {
        assert_eq!(s.separation_m, z.separation_m);
        let (a, b) = (&s.observables, &z.observables);
        assert!(
            (a.amplitude_ratio - b.amplitude_ratio).abs() < 1e-7,
            "{a:?} vs {b:?}"
        );
        assert!(
            (a.phase_deg - b.phase_deg).abs() < 1e-5,
            "{} vs {}",
            a.phase_deg,
            b.phase_deg
        );
        assert!((a.e_ts_j - b.e_ts_j).abs() < 1e-6 * a.e_drive_j);
    }
    // From the command line, each state is one `tap --setpoint` lists.
    let v = json(&[
        "approach",
        "--sweep",
        "setpoint",
        "--from",
        "0.9",
        "--to",
        "0.4",
        "--points",
        "3",
        "--no-retract",
        "--json",
    ]);
    let ratio = v["amplitude_ratio"].as_array().unwrap();
    assert_eq!(ratio.len(), 3);
    for (i, want) in [0.9, 0.65, 0.4].iter().enumerate() {
        let r = ratio[i].as_f64().unwrap();
        assert!((r - want).abs() < 1e-6, "{r} vs {want}");
        let phase = v["phase_deg"][i].as_f64().unwrap();
        let t = json(&["tap", "--setpoint", &want.to_string(), "--json"]);
        let phases: Vec<f64> = t["states"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| num(s, "phase_deg"))
            .collect();
        assert!(
            phases.iter().any(|p| (p - phase).abs() < 1e-5),
            "{phase} at {want} not among {phases:?}"
        );
    }
    // A setpoint sweep's range is in A/A₀, from far to near.
    for (args, says) in [
        (&["--from", "16nm"][..], "is an amplitude setpoint A/A₀"),
        (
            &["--from", "0.3", "--to", "0.5"][..],
            "an approach lowers the setpoint",
        ),
    ] {
        let mut all = vec!["approach", "--sweep", "setpoint"];
        all.extend_from_slice(args);
        let out = tapsim(&all);
        assert_eq!(out.status.code(), Some(1));
        assert!(String::from_utf8_lossy(&out.stderr).contains(says));
    }
}
