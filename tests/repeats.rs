//! Drive periods skipped where the loop repeats itself (issue 44): images against the
//! exact march (`scan --exact`) on the blend (one mode and two), the step sample
//! scanned fast and the discs image, and no period skipped where the motion does not
//! repeat each period.

use crate::common;
use common::column;

use tapsim::dynamics::setup::Prepared;
use tapsim::instrument::feedback::PiController;
use tapsim::instrument::lockin::LockIn;
use tapsim::instrument::repeats::{DEFAULT_TOLERANCE, Repeats};
use tapsim::instrument::scan::{Pixel, Region, row};
use tapsim::instrument::thermal::ThermalForce;

/// `scan` with `args`, and with `--exact`: every pixel's topography within 1 pm and
/// phase within 1e-3°. Returns both documents.
fn against_exact(args: &[&str]) -> (serde_json::Value, serde_json::Value) {
    let fast = common::json_of(&["scan", "--json", "--quiet"], args);
    let exact = common::json_of(&["scan", "--json", "--quiet", "--exact"], args);
    let (z, z_exact) = (
        column(&fast, "topography_m"),
        column(&exact, "topography_m"),
    );
    let (p, p_exact) = (column(&fast, "phase_deg"), column(&exact, "phase_deg"));
    assert_eq!(z.len(), z_exact.len());
    let dz = z
        .iter()
        .zip(&z_exact)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let dp = p
        .iter()
        .zip(&p_exact)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "{args:?}: {} pixels, largest differences {dz:e} m, {dp:e}°",
        z.len()
    );
    assert!(dz < 1e-12, "{args:?}: topography off by {dz:e} m");
    assert!(dp < 1e-3, "{args:?}: phase off by {dp:e}°");
    (fast, exact)
}

#[test]
#[ignore = "release: about 10 s in all (cargo test --release -- --ignored repeats::)"]
fn the_blend_images_as_the_exact_march_does() {
    against_exact(&["--pixels", "256", "--line-rate", "1", "--no-retrace"]);
    against_exact(&[]);
}

#[test]
#[ignore = "release: about 10 s in all (cargo test --release -- --ignored repeats::)"]
fn the_bimodal_blend_images_as_the_exact_march_does() {
    // Two modes over a common period of four drive periods: the loop repeats every four.
    let (fast, exact) = against_exact(&["--modes", "2", "--pixels", "16", "--line-rate", "20"]);
    let second = |v: &serde_json::Value| -> Vec<f64> {
        v["modes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| m[0]["phase_deg"].as_f64().unwrap())
            .collect()
    };
    let (a, b) = (second(&fast), second(&exact));
    let d = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(d < 1e-3, "second mode's phase off by {d:e}°");
}

#[test]
#[ignore = "release: about 10 s in all (cargo test --release -- --ignored repeats::)"]
fn the_discs_image_as_the_exact_march_does() {
    let discs = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/samples/discs.toml");
    let args = [
        "--sample",
        discs,
        "--lines",
        "16",
        "--pixels",
        "16",
        "--line-rate",
        "10",
    ];
    against_exact(&args);
}

#[test]
#[ignore = "release: about 10 s in all (cargo test --release -- --ignored repeats::)"]
fn the_step_scanned_fast_overshoots_and_loses_the_sample_as_exactly() {
    let step = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/samples/step.toml");
    let args = [
        "--sample",
        step,
        "--line-rate",
        "100",
        "--integral-gain",
        "0.01",
    ];
    let (fast, exact) = against_exact(&args);
    // The guide's artefacts: the overshoot after the step up (trace) and the amplitude
    // running away after the step down (retrace), within 1 % of their sizes.
    let artefacts = |v: &serde_json::Value| {
        let (z, ratio) = (column(v, "topography_m"), column(v, "amplitude_ratio"));
        let overshoot = z[16..32].iter().copied().fold(f64::MIN, f64::max) - z[31];
        let runaway = ratio[32..].iter().copied().fold(f64::MIN, f64::max) - 0.8;
        (overshoot, runaway)
    };
    let ((o, r), (o_exact, r_exact)) = (artefacts(&fast), artefacts(&exact));
    assert!(
        o_exact > 0.1e-9 && r_exact > 0.05,
        "{o_exact:e} m, {r_exact}"
    );
    assert!(
        (o - o_exact).abs() < 0.01 * o_exact,
        "overshoot {o:e} vs {o_exact:e} m"
    );
    assert!(
        (r - r_exact).abs() < 0.01 * r_exact,
        "runaway {r} vs {r_exact}"
    );
}

/// One trace over `regions` of the blend's materials at `setpoint` with `repeats`:
/// `pixels` of `per_pixel` periods after 3 000 periods of engaging.
fn trace(
    prepared: &[Prepared],
    regions: &[Region],
    setpoint: f64,
    (pixels, per_pixel): (usize, usize),
    repeats: &mut Repeats,
) -> Vec<Pixel> {
    let sim = prepared[0].simulation();
    let lockin = LockIn::new(4, 2.0 * sim.osc.period(), sim.osc.omega).unwrap();
    let controller = PiController::new(setpoint, 0.0, 0.002).unwrap();
    let loop_ = (lockin, controller, ThermalForce::none());
    let shape = (1e-6, pixels, per_pixel);
    row(
        prepared,
        regions,
        shape,
        loop_,
        (3000, repeats),
        false,
        |_| {},
    )
    .unwrap()
    .0
}

#[test]
fn a_loop_that_settles_skips_and_one_on_a_long_lock_marches_every_period() {
    let (sample, prepared) = common::blend();
    let regions = sample.layout.line_at(0.5 * sample.width_m, sample.length_m);
    // At 0.8 the loop settles on each polymer: most periods of a slow line are repeats.
    let mut repeats = Repeats::within(DEFAULT_TOLERANCE);
    trace(&prepared, &regions, 0.8, (8, 4000), &mut repeats);
    let share = repeats.skipped as f64 / (repeats.skipped + repeats.marched) as f64;
    assert!(
        share > 0.5,
        "{} of {} skipped",
        repeats.skipped,
        repeats.marched
    );
    // At 0.95 on the attractive branch the only motion is a long lock grazing the
    // jump-in (the guide): its state never repeats after one period, nothing is skipped,
    // and the pixels are the exact march's.
    let flat = [Region {
        until_m: 1e-6,
        material: 0,
        height_m: 0.0,
    }];
    let mut repeats = Repeats::within(DEFAULT_TOLERANCE);
    let fast = trace(&prepared, &flat, 0.95, (4, 1000), &mut repeats);
    assert_eq!(repeats.skipped, 0, "{} marched", repeats.marched);
    let exact = trace(&prepared, &flat, 0.95, (4, 1000), &mut Repeats::exact());
    assert_eq!(fast, exact);
}
