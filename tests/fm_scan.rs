//! FM-AFM images (issue 48: `scan --mode fm`): the loops marched period by period
//! under a z feedback on the frequency shift, checked against the settled states Newton's
//! method finds for each material (a different method: no loops, no march), the
//! dissipation channel against the law's own loop, the periods taken as repeats against
//! the exact march, and what the command refuses.

use crate::common;
use common::column;

use tapsim::analysis::fm::{at_shift, engagement};
use tapsim::config::TapInputs;
use tapsim::dynamics::setup::Numerics;
use tapsim::instrument::fm_scan::{FmPixel, FmScanner, ShiftFeedback};
use tapsim::instrument::scan::Region;
use tapsim::sample::{BLEND, Sample};

const SETPOINT_HZ: f64 = -200.0;

/// A trace over the blend (A on the first half, B on the second) at −200 Hz: 16 pixels
/// of 2 344 periods (4 lines/s at 300 kHz), engaged on A; and the scanner's periods
/// (marched, skipped).
fn blend_trace(exact: bool) -> (Vec<FmPixel>, (u64, u64)) {
    let (sample, prepared) = common::blend();
    let a = &sample.materials[0].1;
    let range = (24e-9, 8e-9);
    let (at, slope) = engagement(a, &Numerics::default(), SETPOINT_HZ, range, 40).unwrap();
    let feedback = ShiftFeedback::with_time_constant(SETPOINT_HZ, slope, 400.0).unwrap();
    let mut scanner = FmScanner::new(&prepared, feedback).unwrap();
    if exact {
        scanner = scanner.exact();
    }
    scanner.engage(&at, 0.0);
    let regions = [
        Region {
            until_m: 0.5e-6,
            material: 0,
            height_m: 0.0,
        },
        Region {
            until_m: 1e-6,
            material: 1,
            height_m: 0.0,
        },
    ];
    let pixels = scanner.line(&regions, (1e-6, 16, 2344), |_| {}).unwrap();
    (pixels, scanner.periods())
}

#[test]
fn the_marched_loops_hold_each_material_where_newtons_method_settles_it() {
    let (pixels, _) = blend_trace(false);
    let sample = Sample::from_toml(BLEND, &TapInputs::default()).unwrap();
    for (material, pixel) in [(0, 6), (0, 7), (1, 14), (1, 15)] {
        let setup = &sample.materials[material].1;
        let settled =
            at_shift(setup, &Numerics::default(), SETPOINT_HZ, (24e-9, 8e-9), 40).unwrap();
        let p = &pixels[pixel];
        let loop_loss = settled.observables.loop_area_j * settled.observables.jumps_in;
        eprintln!(
            "material {material}, pixel {pixel}: z {:.6} nm vs settled {:.6} nm; Δf error \
             {:.2e} Hz; dissipation {:.6e} J vs the law's loop {:.6e} J; A/A {:.3e}",
            p.topography_m * 1e9,
            settled.separation_m * 1e9,
            p.error_hz,
            p.dissipation_j,
            loop_loss,
            p.amplitude_ratio - 1.0
        );
        // The piezo where the settled state sits (the march at 2e-7, Newton at 1e-9).
        assert!((p.topography_m - settled.separation_m).abs() < 1e-12);
        assert!(p.error_hz.abs() < 1e-4, "{}", p.error_hz);
        assert!((p.frequency_shift_hz - SETPOINT_HZ).abs() < 1e-4);
        assert!((p.amplitude_ratio - 1.0).abs() < 1e-6);
        // The dissipation channel reads the law's loop, touch by touch.
        assert!((p.dissipation_j / loop_loss - 1.0).abs() < 1e-3);
    }
    // The contrast: A (Δγ 0.1 J/m², 0.5 GPa) loses seven times what B does, and holds
    // the setpoint farther out.
    let (a, b) = (&pixels[7], &pixels[15]);
    assert!(a.dissipation_j > 5.0 * b.dissipation_j);
    assert!(a.topography_m > b.topography_m + 0.5e-9);
}

#[test]
fn periods_taken_as_repeats_change_no_pixel_beyond_the_tolerance() {
    let (fast, (marched, skipped)) = blend_trace(false);
    let (exact, (all, none)) = blend_trace(true);
    assert_eq!(none, 0);
    assert_eq!(all, 16 * 2344);
    assert_eq!(marched + skipped, all);
    // Most periods repeat: the loops settle within a few thousand periods of a change.
    assert!(skipped > all / 2, "{marched} marched, {skipped} skipped");
    let most = |f: fn(&FmPixel) -> f64| {
        fast.iter()
            .zip(&exact)
            .map(|(a, b)| (f(a) - f(b)).abs())
            .fold(0.0, f64::max)
    };
    let (dz, df, de) = (
        most(|p| p.topography_m),
        most(|p| p.frequency_shift_hz),
        most(|p| p.dissipation_j / 1.602e-19),
    );
    eprintln!(
        "{marched} marched, {skipped} skipped; against the exact march: {dz:.2e} m, \
         {df:.2e} Hz, {de:.2e} eV"
    );
    // The tolerance: the frequency shift within 0.1 µHz of the loops' fixed point.
    assert!(df <= 3e-7, "{df}");
    assert!(dz < 1e-15, "{dz}");
    assert!(de < 1e-6, "{de}");
}

#[test]
fn fm_images_through_the_command_line() {
    // A line: the step between the materials is the difference of the rest separations
    // at which `tapsim fm` settles each at the setpoint.
    let v = common::json(&["scan", "--mode", "fm", "--pixels", "8", "--json", "--quiet"]);
    let (z, dissipation) = (column(&v, "topography_m"), column(&v, "dissipation_j"));
    assert_eq!(z.len(), 16);
    let held = |modulus: &str, work: &str| {
        let s = common::json(&[
            "fm",
            "--setpoint",
            "-200Hz",
            "--sample-modulus",
            modulus,
            "--work-of-adhesion",
            work,
            "--json",
        ]);
        common::num(&s, "separation_m")
    };
    let (a, b) = (held("0.5GPa", "0.1"), held("1GPa", "0.08"));
    eprintln!("A {a:e} m, B {b:e} m; the scan: {:e}, {:e}", z[3], z[7]);
    assert!((z[3] - a).abs() < 1e-12 && (z[7] - b).abs() < 1e-12);
    assert!(dissipation[3] > 5.0 * dissipation[7]);
    // An image, sharded and merged: byte for byte the whole run's JSON; and its
    // Gwyddion file.
    let dir = common::scratch("fm_image");
    let run = |args: &[&str]| {
        let out = common::run_limited(args, &dir, std::time::Duration::from_secs(120));
        assert_eq!(out.code, Some(0), "{args:?}: {}", out.stderr);
        out
    };
    let image = [
        "scan", "--mode", "fm", "--lines", "2", "--pixels", "4", "--quiet",
    ];
    let whole = run(&[&image[..], &["--json", "--gwy", "fm.gwy"]].concat());
    for i in 0..2 {
        let (shard, part) = (format!("{i}/2"), format!("part{i}.json"));
        run(&[&image[..], &["--shard", &shard, "--part", &part]].concat());
    }
    run(&[
        "merge",
        "part0.json",
        "part1.json",
        "--out",
        "merged.json",
        "--quiet",
    ]);
    let merged = std::fs::read_to_string(dir.join("merged.json")).unwrap();
    assert_eq!(merged, whole.stdout);
    let gwy = std::fs::read(dir.join("fm.gwy")).unwrap();
    for channel in ["Frequency shift (trace)", "Dissipation (retrace)"] {
        assert!(
            gwy.windows(channel.len()).any(|w| w == channel.as_bytes()),
            "{channel}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
    // What it refuses.
    for (args, says) in [
        (
            &["scan", "--frequency-shift", "-100Hz"][..],
            "add --mode fm",
        ),
        (
            &["scan", "--mode", "fm", "--temperature", "300K"],
            "--temperature is tapping's",
        ),
        (
            &["scan", "--mode", "fm", "--frequency-shift", "-1000Hz"],
            "material A does not hold the frequency shift -1000 Hz",
        ),
        (
            &["scan", "--mode", "fm", "--frequency-shift", "0Hz"],
            "finite shift",
        ),
        (
            &["scan", "--mode", "fm", "--z-time-constant", "-1ms"],
            "time constant",
        ),
        (&["map", "--mode", "fm"], "tapsim scan --mode fm"),
    ] {
        common::refused(args, says);
    }
}

#[test]
fn a_step_up_past_the_turning_point_of_the_frequency_shift_is_refused_not_imaged() {
    // 4 nm up on A at −200 Hz carries the tip from 20.75 nm to 16.75 nm, where Δf is
    // positive: the loop's sign is wrong there and it runs the tip in.
    let dir = common::scratch("fm_step");
    std::fs::write(
        dir.join("step.toml"),
        "length = \"1um\"\n[[material]]\nname = \"A\"\nsample-modulus = \"0.5GPa\"\n\
         work-of-adhesion = 0.1\n[[region]]\nuntil = \"0.5um\"\nmaterial = \"A\"\n\
         [[region]]\nuntil = \"1um\"\nmaterial = \"A\"\nheight = \"4nm\"\n",
    )
    .unwrap();
    let out = common::run_limited(
        &[
            "scan",
            "--mode",
            "fm",
            "--sample",
            "step.toml",
            "--pixels",
            "8",
        ],
        &dir,
        std::time::Duration::from_secs(60),
    );
    assert_eq!(out.code, Some(1), "{}", out.stderr);
    assert!(
        out.stderr
            .contains("the FM loops lost the cantilever at x = 5")
            && out.stderr.contains("turning point"),
        "{}",
        out.stderr
    );
    let _ = std::fs::remove_dir_all(&dir);
}
