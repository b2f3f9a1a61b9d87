//! The instrument's pieces (issue 27) against what they must reproduce without
//! sharing their code: the lock-in's filter against the closed-form step response of an
//! RC cascade, and its reading of a settled orbit against `tap`'s amplitude and phase
//! (integrals over the period carried by the integrator).

use crate::common;
use common::column;
use tapsim::dynamics::observables::TapObservables;
use tapsim::dynamics::setup::{Numerics, Prepared, default_setup};
use tapsim::instrument::lockin::{LockIn, step_response};
use tapsim::instrument::repeats::Repeats;
use tapsim::instrument::thermal::ThermalForce;

#[test]
fn the_lock_in_filter_has_the_step_response_of_an_rc_cascade() {
    for order in 1..=4 {
        for t_const in [0.3, 7.0] {
            let mut lockin = LockIn::new(order, t_const, 1.0).unwrap();
            let h = lockin.sample_interval_hat();
            // A step of (1, −2) at t = 0, sampled every h; read after k intervals.
            lockin.feed((1.0, -2.0));
            let mut worst: f64 = 0.0;
            for k in 1..=(60.0 * t_const / h) as usize {
                lockin.feed((1.0, -2.0));
                let want = step_response(order, k as f64 * h / t_const);
                let (i, q) = lockin.output();
                worst = worst
                    .max((i - want).abs())
                    .max((q + 2.0 * want).abs() / 2.0);
            }
            assert!(worst < 1e-6, "n {order}, T {t_const}: off by {worst:e}");
        }
    }
    // Refused: an order outside 1–4, a time constant that is not positive.
    assert!(LockIn::new(0, 1.0, 1.0).is_err());
    assert!(LockIn::new(5, 1.0, 1.0).is_err());
    assert!(LockIn::new(2, 0.0, 1.0).is_err());
    assert!(LockIn::new(2, f64::NAN, 1.0).is_err());
}

#[test]
fn the_lock_in_reads_a_settled_orbit_as_tap_does() {
    let setup = default_setup();
    let p = Prepared::new(&setup, &Numerics::default()).unwrap();
    let sim = p.simulation();
    let mut phase = sim.free_steady_start();
    let state = sim.steady_state(&mut phase, &p.steady).unwrap();
    let o = TapObservables::new(&p, &state).unwrap();
    assert_eq!(o.period, Some(1));
    let omega = sim.osc.omega;
    let period = 2.0 * std::f64::consts::PI / omega;
    // Fourth order, T = 20 periods: after 50 T the start is forgotten (below 1e-15) and
    // the ripple at 2Ω is (1 + (2ΩT)²)^(−2) ≈ 2.5e-10 of A.
    let mut lockin = LockIn::new(4, 20.0 * period, omega).unwrap();
    sim.march(&mut phase, 1000, &mut lockin).unwrap();
    let (a, phi) = (lockin.amplitude(), lockin.phase_deg());
    eprintln!(
        "lock-in A {a} (tap {}, rel {:e}), φ {phi} (tap {}, {:e}°)",
        o.amplitude_ratio,
        a / o.amplitude_ratio - 1.0,
        o.phase_deg,
        phi - o.phase_deg
    );
    assert!(
        (a - o.amplitude_ratio).abs() < 1e-6 * o.amplitude_ratio,
        "A {a} vs {}",
        o.amplitude_ratio
    );
    assert!(
        (phi - o.phase_deg).abs() < 1e-4,
        "φ {phi} vs {}",
        o.phase_deg
    );
}

/// The z feedback on a flat homogeneous sample (the defaults), approached from the free
/// oscillation at 1.2 A₀ with the loop closed at A/A₀ = 0.8: the error settles below
/// 1e-4 of the setpoint, and the piezo rests at the rest separation the setpoint solver
/// finds on the branch a falling setpoint stays on (continuation and root-finding, no
/// marching in time) within 0.01 nm.
#[test]
fn the_z_feedback_rests_where_the_setpoint_solver_puts_the_state() {
    use tapsim::instrument::feedback::PiController;
    use tapsim::setpoint::{PhaseBranch, states_at_setpoint};
    let setup = default_setup();
    let numerics = Numerics::default();
    let mut controller = PiController::new(0.8, 0.0, 0.002).unwrap();
    let samples = hold_on_defaults(&mut controller, 1.2, 8000);
    // It starts free, far from the sample.
    assert!((samples[0].amplitude_ratio - 1.0).abs() < 1e-4);
    let tail = &samples[7500..];
    for s in tail {
        assert!(s.error.abs() < 1e-4 * 0.8, "{s:?}");
    }
    let z = tail.last().unwrap().separation_m;
    let solved = states_at_setpoint(&setup, &numerics, 0.8, Some(PhaseBranch::Attractive)).unwrap();
    let want = solved[0].separation_m;
    assert!(
        (z - want).abs() < 0.01e-9,
        "piezo at {z:e} m, solver {want:e} m"
    );
    eprintln!("feedback rests at {z:e} m, the solver's state at {want:e} m");
    // Refused: a setpoint outside (0, 1), a negative gain, both gains zero.
    assert!(PiController::new(1.2, 0.0, 0.002).is_err());
    assert!(PiController::new(0.8, -1.0, 0.002).is_err());
    assert!(PiController::new(0.8, 0.0, 0.0).is_err());
}

/// `controller` holding the defaults for `periods` drive periods, read by a fourth-order
/// lock-in of T = 2 periods, from the free oscillation at `start` A₀: what it read and
/// where it put the piezo, period by period.
fn hold_on_defaults(
    controller: &mut tapsim::instrument::feedback::PiController,
    start: f64,
    periods: usize,
) -> Vec<tapsim::instrument::feedback::LoopSample> {
    let setup = default_setup();
    let p = Prepared::new(&setup, &Numerics::default()).unwrap();
    let omega = p.simulation().osc.omega;
    let period = 2.0 * std::f64::consts::PI / omega;
    let mut lockin = LockIn::new(4, 2.0 * period, omega).unwrap();
    let mut phase = p.simulation().free_steady_start();
    let (samples, _) = tapsim::instrument::feedback::hold(
        &p,
        (start * setup.cantilever.free_amplitude_m, &mut phase),
        &mut lockin,
        controller,
        &mut ThermalForce::none(),
        periods,
    )
    .unwrap();
    samples
}

/// The modes of `set` on `setup`, prepared at the instrument's marching tolerances.
fn marched_modes(
    setup: &tapsim::dynamics::setup::TapSetup,
    set: &tapsim::dynamics::modes::ModeSet,
) -> [(
    tapsim::dynamics::setup::Prepared,
    tapsim::dynamics::modes::Modal,
); 1] {
    let marched = Numerics {
        rtol: tapsim::instrument::MARCH_RTOL,
        atol: 1e-2 * tapsim::instrument::MARCH_RTOL,
        ..Numerics::default()
    };
    [tapsim::dynamics::modes::prepare(setup, set, &marched).unwrap()]
}

/// The first two modes' lock-in readings (A/A₀, φ) averaged over `periods` drive
/// periods at `z`: the ripple of lines beating through the filter averaged away.
fn mean_readings(
    probe: &mut impl tapsim::instrument::probe::Probe,
    z: f64,
    periods: usize,
) -> [(f64, f64); 2] {
    let mut read = [(0.0, 0.0); 2];
    for _ in 0..periods {
        let r = probe.march(0, z, 1).unwrap();
        for (sum, r) in read.iter_mut().zip(r) {
            sum.0 += r.0 / periods as f64;
            sum.1 += r.1 / periods as f64;
        }
    }
    read
}

/// The instrument on two eigenmodes (the hybrid defaults with a beam's second mode,
/// A₀₂ = A₀/40): the loop on the first mode's lock-in, engaged from 1.2 A₀, rests at the
/// separation where the several-mode steady-state solver (Newton on the common period,
/// a method the march shares only its equations with) puts A₁/A₀₁ = 0.8, and the
/// second mode's lock-in then reads the solver's φ₂ and A₂/A₀₂.
#[test]
fn the_bimodal_feedback_rests_where_the_modal_steady_state_is() {
    use tapsim::bimodal::{PhaseBranch, states_at_setpoint};
    use tapsim::dynamics::modes::ModeSet;
    use tapsim::instrument::feedback::{PiController, hold_probe};
    use tapsim::instrument::modal::ModalProbe;
    let setup = default_setup();
    let set = ModeSet::euler_bernoulli(&setup.cantilever, 2).unwrap();
    let numerics = Numerics::default();
    let materials = marched_modes(&setup, &set);
    let period = materials[0].1.drive_period();
    let mut probe = ModalProbe::new(&materials, 4, 2.0 * period).unwrap();
    let mut controller = PiController::new(0.8, 0.0, 0.002).unwrap();
    let a0 = setup.cantilever.free_amplitude_m;
    let started = std::time::Instant::now();
    let (samples, _) = hold_probe(
        &mut probe,
        0,
        1.2 * a0,
        (&mut controller, &mut Repeats::exact()),
        6000,
    )
    .unwrap();
    eprintln!("6000 periods in {:?}", started.elapsed());
    assert!((samples[0].amplitude_ratio - 1.0).abs() < 1e-4);
    let tail = &samples[5500..];
    for s in tail {
        assert!(s.error.abs() < 1e-4 * 0.8, "{s:?}");
    }
    let z = tail.last().unwrap().separation_m;
    // The lock-ins' outputs ripple at the common period's frequency (the orbit repeats
    // every 4 drive periods: lines at Ωᵢ ± Ω₁/4 beat through the filter); a pixel's mean
    // over whole common periods is what an image shows.
    let read = mean_readings(&mut probe, z, 400);
    // The loop engages from above, onto the attractive branch (φ₁ > 90°), as with one
    // mode; the solver's state there.
    let (branch, found) = states_at_setpoint(&setup, &set, &numerics, 0.8, None)
        .unwrap()
        .remove(0);
    assert_eq!(branch, PhaseBranch::Attractive);
    let solved = found.unwrap().observables;
    let want = solved.separation_m;
    eprintln!(
        "bimodal loop rests at {z:e} m (solver {want:e} m); φ₁ {} ({}), φ₂ {} ({}), A₂/A₀₂ {} ({})",
        read[0].1,
        solved.modes[0].phase_deg,
        read[1].1,
        solved.modes[1].phase_deg,
        read[1].0,
        solved.modes[1].amplitude_ratio.unwrap()
    );
    assert!(
        (z - want).abs() < 0.01e-9,
        "piezo at {z:e} m, solver {want:e} m"
    );
    assert!((read[0].1 - solved.modes[0].phase_deg).abs() < 0.01);
    assert!((read[1].1 - solved.modes[1].phase_deg).abs() < 0.01);
    assert!((read[1].0 - solved.modes[1].amplitude_ratio.unwrap()).abs() < 1e-4);
}

/// A line scanned slowly with the loop closed at A/A₀ = 0.8 over (1) a flat sample of
/// two materials and (2) a 2 nm step in the height of one: the image shows the apparent
/// step the setpoint solver predicts (the two materials' z_c at the setpoint on the
/// branch the loop sits on) within 1 % and their phase difference within 0.05°, and the
/// true step within 0.1 %.
#[test]
fn a_slow_scan_images_material_contrast_and_a_height_step() {
    use tapsim::config::TapInputs;
    use tapsim::instrument::feedback::{PiController, hold};
    use tapsim::instrument::scan::{Region, line};
    use tapsim::setpoint::{PhaseBranch, states_at_setpoint};
    let numerics = Numerics::default();
    let material = |pairs: &[(&str, &str)]| {
        let mut inputs = TapInputs::default();
        for (k, v) in pairs {
            inputs.set(k, v).unwrap();
        }
        inputs.resolve().unwrap().0
    };
    let a = material(&[]);
    let b = material(&[("sample-modulus", "1GPa"), ("work-of-adhesion", "0.08")]);
    let prepared = [
        Prepared::new(&a, &numerics).unwrap(),
        Prepared::new(&b, &numerics).unwrap(),
    ];
    let omega = prepared[0].simulation().osc.omega;
    let period = 2.0 * std::f64::consts::PI / omega;
    let a0 = a.cantilever.free_amplitude_m;
    let scan = |regions: &[Region]| {
        let mut lockin = LockIn::new(4, 2.0 * period, omega).unwrap();
        let mut controller = PiController::new(0.8, 0.0, 0.002).unwrap();
        let mut phase = prepared[0].simulation().free_steady_start();
        let (_, z) = hold(
            &prepared[0],
            (1.2 * a0, &mut phase),
            &mut lockin,
            &mut controller,
            &mut ThermalForce::none(),
            8000,
        )
        .unwrap();
        line(
            &prepared,
            regions,
            (1e-6, 4, 6000),
            (&mut lockin, &mut controller, &mut ThermalForce::none()),
            (z, &mut Repeats::exact()),
            &mut phase,
            |_| {},
        )
        .unwrap()
        .0
    };
    // (1) Material contrast on a flat sample.
    let pixels = scan(&[
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
    ]);
    let solved = |s| states_at_setpoint(s, &numerics, 0.8, Some(PhaseBranch::Attractive)).unwrap();
    let (sa, sb) = (solved(&a).remove(0), solved(&b).remove(0));
    let step = pixels[3].topography_m - pixels[1].topography_m;
    let want = sb.separation_m - sa.separation_m;
    assert!(
        (step - want).abs() < 0.01 * want.abs(),
        "apparent step {step:e} m vs {want:e} m"
    );
    let dphi = pixels[3].phase_deg - pixels[1].phase_deg;
    let want_dphi = sb.observables.phase_deg - sa.observables.phase_deg;
    assert!((dphi - want_dphi).abs() < 0.05, "Δφ {dphi} vs {want_dphi}");
    eprintln!("apparent step {step:e} m (solver {want:e}), Δφ {dphi}° (solver {want_dphi}°)");
    // (2) A 2 nm step up on one material.
    let pixels = scan(&[
        Region {
            until_m: 0.5e-6,
            material: 0,
            height_m: 0.0,
        },
        Region {
            until_m: 1e-6,
            material: 0,
            height_m: 2e-9,
        },
    ]);
    let imaged = pixels[3].topography_m - pixels[1].topography_m;
    assert!(
        (imaged - 2e-9).abs() < 1e-3 * 2e-9,
        "imaged step {imaged:e} m"
    );
    eprintln!("imaged height step {imaged:e} m");
}

/// `tapsim scan` on the built-in blend: trace and retrace, each pixel at the setpoint
/// where the loop has settled, B imaged lower than A (its apparent step) and with the
/// larger phase lag (the attractive branch); bad samples and settings are refused.
#[test]
fn scan_images_the_built_in_blend_and_refuses_bad_samples() {
    let v = common::json(&[
        "scan",
        "--pixels",
        "4",
        "--line-rate",
        "20",
        "--json",
        "--quiet",
    ]);
    let col = |k: &str| column(&v, k);
    let dirs: Vec<&str> = v["direction"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d.as_str().unwrap())
        .collect();
    assert_eq!(
        dirs,
        ["trace"; 4]
            .iter()
            .chain(["retrace"; 4].iter())
            .copied()
            .collect::<Vec<_>>()
    );
    let (z, phase, ratio) = (
        col("topography_m"),
        col("phase_deg"),
        col("amplitude_ratio"),
    );
    // Settled pixels (the second of each material on the trace) hold the setpoint.
    for i in [1, 3] {
        assert!((ratio[i] - 0.8).abs() < 1e-4, "pixel {i}: {}", ratio[i]);
    }
    assert!(
        z[3] < z[1] - 0.5e-9,
        "B imaged {:e} m against A {:e} m",
        z[3],
        z[1]
    );
    assert!(
        phase[3] > phase[1] + 2.0,
        "φ {} on B, {} on A",
        phase[3],
        phase[1]
    );
    // The retrace meets B first, at the x it left it.
    let x = col("x_m");
    assert_eq!(x[4], x[3]);
    let dir = common::scratch("scan");
    let sample = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let material = "[[material]]\nname = \"A\"\n";
    let region = "[[region]]\nuntil = \"1um\"\nmaterial = \"A\"\n";
    for (args, says) in [
        (
            vec!["--pixels", "0"],
            "--pixels and --lines are from 1 to 4096",
        ),
        (
            vec!["--lines", "5000"],
            "--pixels and --lines are from 1 to 4096",
        ),
        (
            vec!["--lines", "2048", "--pixels", "1024"],
            "an image holds at most 1048576 pixels",
        ),
        (vec!["--line-rate", "0"], "line rate"),
        (vec!["--line-rate", "1e-3"], "drive periods a pixel"),
        (
            vec!["--separation", "16nm"],
            "the feedback sets the separation",
        ),
        (vec!["--lockin-order", "5"], "lock-in filter order"),
        (
            vec![
                "--sample",
                &sample(
                    "a.toml",
                    &format!("length = \"1um\"\ndepth = 3\n{material}{region}"),
                ),
            ],
            "unknown key depth",
        ),
        (
            vec![
                "--sample",
                &sample(
                    "b.toml",
                    &format!(
                        "length = \"1um\"\n{material}[[region]]\nuntil = \"1um\"\nmaterial = \"C\"\n"
                    ),
                ),
            ],
            "names material C, which is not given",
        ),
        (
            vec![
                "--sample",
                &sample("c.toml", &format!("length = \"2um\"\n{material}{region}")),
            ],
            "short of the line",
        ),
        (
            vec![
                "--sample",
                &sample(
                    "d.toml",
                    &format!("length = \"1um\"\n{material}separation = \"10nm\"\n{region}"),
                ),
            ],
            "is the instrument's, not a material's",
        ),
        (
            vec![
                "--sample",
                &sample(
                    "e.toml",
                    &format!(
                        "length = \"1um\"\n{material}[[material]]\nname = \"B\"\nstiffness = \"2N/m\"\n{region}"
                    ),
                ),
            ],
            "differ in the cantilever",
        ),
        (
            vec![
                "--sample",
                &sample(
                    "f.toml",
                    &format!(
                        "length = \"1um\"\n{material}{region}[[disc]]\nx = \"1nm\"\ny = \"1nm\"\nradius = \"-5nm\"\nmaterial = \"A\"\n"
                    ),
                ),
            ],
            "its radius (-5e-9 m) positive",
        ),
        (
            vec![
                "--sample",
                &sample(
                    "g.toml",
                    &format!(
                        "length = \"1um\"\n{material}{region}[[disc]]\nx = \"1nm\"\ny = \"1nm\"\nmaterial = \"A\"\n"
                    ),
                ),
            ],
            "every [[disc]] gives its radius",
        ),
    ] {
        let mut all = vec!["scan", "--quiet"];
        all.extend(args.iter().copied());
        let out = common::tapsim(&all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{all:?}: {err}");
        assert!(err.contains(says), "{all:?}: {err}");
    }
}

/// Scanned fast over a 2 nm step (94 drive periods a pixel, a stiffer loop), the known
/// artefacts of the z feedback appear: the topography overshoots the step up, and after
/// the step down (on the retrace) the amplitude runs above the setpoint while the tip
/// loses the sample.
#[test]
fn a_fast_scan_shows_the_feedback_artefacts() {
    let v = common::json(&[
        "scan",
        "--sample",
        concat!(env!("CARGO_MANIFEST_DIR"), "/examples/samples/step.toml"),
        "--line-rate",
        "100",
        "--integral-gain",
        "0.01",
        "--json",
        "--quiet",
    ]);
    let col = |k: &str| column(&v, k);
    let (z, ratio) = (col("topography_m"), col("amplitude_ratio"));
    let (trace, retrace) = (&z[..32], &ratio[32..]);
    let settled = trace[31];
    let peak = trace[16..].iter().copied().fold(f64::MIN, f64::max);
    assert!(peak > settled + 0.1e-9, "overshoot {:e} m", peak - settled);
    let high = retrace.iter().copied().fold(f64::MIN, f64::max);
    assert!(high > 0.85, "highest amplitude on the retrace {high}");
}

/// The I gain an instrument panel shows (m of z per m of amplitude error and second) is
/// the rate at which the piezo moves per metre of error, in physical time: far from the
/// sample the error stands still at (1 − setpoint)·A₀, and z_c falls at I·that, in
/// m/s — the march's own periods converted by the drive frequency.
#[test]
fn the_integral_gain_per_second_is_the_rate_the_piezo_moves_per_metre_of_error() {
    use tapsim::instrument::feedback::PiController;
    let setup = default_setup();
    let mut controller = PiController::new(0.8, 0.0, 0.002).unwrap();
    let drive_hz = setup.cantilever.drive_frequency_hz;
    let i_gain = controller.integral_gain_per_s(drive_hz);
    assert!((i_gain - 600.0).abs() < 1e-9, "{i_gain}");
    assert_eq!(controller.integral_time_s(drive_hz), None);
    let a0 = setup.cantilever.free_amplitude_m;
    let samples = hold_on_defaults(&mut controller, 1.5, 400);
    // The lock-in settled on the free oscillation (A = A₀), still far out.
    let (a, b) = (&samples[100], &samples[300]);
    assert!(b.separation_m > 1.1 * a0, "{b:?}");
    let error_m = (a.amplitude_ratio - 0.8) * a0;
    let rate = (b.separation_m - a.separation_m) / (200.0 / drive_hz);
    assert!(
        (rate + i_gain * error_m).abs() < 1e-6 * rate.abs(),
        "z_c moves at {rate:e} m/s; I gain × error = {:e} m/s",
        i_gain * error_m
    );
    let pi = PiController::new(0.8, 0.5, 0.002).unwrap();
    let t = pi.integral_time_s(drive_hz).unwrap();
    assert!((t - 0.5 / 600.0).abs() < 1e-15, "{t}");
}

/// `--integral-gain` in the units of an instrument panel (per second) is the same loop as
/// K_i per drive period, the scan says both, and a gain past the most is refused in the
/// units it was given.
#[test]
fn scan_takes_the_integral_gain_per_second_as_a_panel_shows_it() {
    let per_period = common::tapsim(&["scan", "--pixels", "8", "--integral-gain", "0.004"]);
    let per_second = common::tapsim(&["scan", "--pixels", "8", "--integral-gain", "1200/s"]);
    assert!(per_period.status.success() && per_second.status.success());
    assert_eq!(per_period.stdout, per_second.stdout);
    let text = String::from_utf8_lossy(&per_second.stdout);
    assert!(
        text.contains("z feedback: I gain 1200 s⁻¹ (K_i = 0.004 a drive period), P gain 0 m/m"),
        "{text}"
    );
    common::refused(
        &["scan", "--integral-gain", "4e5/s"],
        "an integral gain of 400000/s is K_i = 1.333 a drive period at 300 kHz: from 0 to 300000/s",
    );
    common::refused(&["scan", "--integral-gain", "-1/s"], "from 0 to 300000/s");
}

/// A sample whose first region is raised: the loop engages there and the line starts
/// with the piezo that much higher (rest separation of the defaults at 0.8 plus the
/// height), holding the setpoint from the first pixel on.
#[test]
fn a_scan_over_a_raised_first_region_starts_at_its_height() {
    use tapsim::setpoint::{PhaseBranch, states_at_setpoint};
    let dir = common::scratch("raised");
    let path = dir.join("raised.toml");
    std::fs::write(
        &path,
        "length = \"1um\"\n[[material]]\nname = \"A\"\n[[region]]\nuntil = \"1um\"\n\
         material = \"A\"\nheight = \"1nm\"\n",
    )
    .unwrap();
    let v = common::json(&[
        "scan",
        "--sample",
        path.to_str().unwrap(),
        "--pixels",
        "2",
        "--line-rate",
        "1e3",
        "--no-retrace",
        "--json",
        "--quiet",
    ]);
    let rest = states_at_setpoint(
        &default_setup(),
        &Numerics::default(),
        0.8,
        Some(PhaseBranch::Attractive),
    )
    .unwrap()[0]
        .separation_m;
    for (z, ratio) in column(&v, "topography_m")
        .into_iter()
        .zip(column(&v, "amplitude_ratio"))
    {
        assert!(
            (z - (rest + 1e-9)).abs() < 0.01e-9,
            "piezo {z:e} m, want {:e}",
            rest + 1e-9
        );
        assert!((ratio - 0.8).abs() < 1e-4, "A/A₀ {ratio}");
    }
}

/// An image of a disc of B in A: every line engaged and scanned on its own, so the same
/// bytes on one thread and on two; pixels well inside the disc read B's phase, those
/// well outside A's (as a one-line scan over each material reads them), and the
/// topography steps down over the disc as over B in the blend.
#[test]
fn an_image_of_a_disc_shows_it_where_it_lies_on_any_number_of_threads() {
    let dir = common::scratch("scan_image");
    let sample = dir.join("disc.toml");
    std::fs::write(
        &sample,
        format!(
            "length = \"1um\"\n{TWO_POLYMERS}\n[[disc]]\nx = \"500nm\"\ny = \"500nm\"\n\
             radius = \"300nm\"\nmaterial = \"B\"\n"
        ),
    )
    .unwrap();
    let image = |threads: &str, csv: &str| {
        let path = dir.join(csv);
        let out = common::tapsim(&[
            "scan",
            "--sample",
            sample.to_str().unwrap(),
            "--lines",
            "4",
            "--pixels",
            "8",
            "--line-rate",
            "20",
            "--no-retrace",
            "--threads",
            threads,
            "--csv",
            path.to_str().unwrap(),
            "--quiet",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        std::fs::read_to_string(path).unwrap()
    };
    let (one, two) = (image("1", "one.csv"), image("2", "two.csv"));
    assert_eq!(one, two, "the image depends on the thread count");
    let mut reader = csv::Reader::from_reader(one.as_bytes());
    let head = reader.headers().unwrap().clone();
    let at = |k: &str| head.iter().position(|h| h == k).unwrap();
    let (x, y, phase, z) = (at("x_m"), at("y_m"), at("phase_deg"), at("topography_m"));
    let (mut inside, mut outside) = (Vec::new(), Vec::new());
    for rec in reader.records() {
        let rec = rec.unwrap();
        let v = |i: usize| rec[i].parse::<f64>().unwrap();
        let r = (v(x) - 500e-9).hypot(v(y) - 500e-9);
        // Well inside, and past the first pixel of the disc (the loop settles there).
        if r < 200e-9 && v(x) > 400e-9 {
            inside.push((v(phase), v(z)));
        } else if r > 400e-9 && v(x) < 500e-9 {
            outside.push((v(phase), v(z)));
        }
    }
    assert!(
        inside.len() >= 2 && outside.len() >= 4,
        "{inside:?} {outside:?}"
    );
    // Each material's one-line reading (the blend's halves, trace).
    let blend = common::json(&[
        "scan",
        "--pixels",
        "4",
        "--line-rate",
        "20",
        "--no-retrace",
        "--json",
        "--quiet",
    ]);
    let (bp, bz) = (column(&blend, "phase_deg"), column(&blend, "topography_m"));
    for &(p, h) in &inside {
        assert!((p - bp[3]).abs() < 0.05, "inside: φ {p} vs B {}", bp[3]);
        assert!(
            (h - bz[3]).abs() < 0.01e-9,
            "inside: z {h:e} vs B {:e}",
            bz[3]
        );
    }
    for &(p, h) in &outside {
        assert!((p - bp[1]).abs() < 0.05, "outside: φ {p} vs A {}", bp[1]);
        assert!(
            (h - bz[1]).abs() < 0.01e-9,
            "outside: z {h:e} vs A {:e}",
            bz[1]
        );
    }
}

/// Two polymers over a stripe of A, for the image and mask tests.
const TWO_POLYMERS: &str = r#"
[[material]]
name = "A"
sample-modulus = "0.5GPa"
work-of-adhesion = 0.1
[[material]]
name = "B"
sample-modulus = "1GPa"
work-of-adhesion = 0.08
[[region]]
until = "1um"
material = "A"
"#;

/// Scan two lines of four pixels of the sample `head` (its mask lines) over
/// [`TWO_POLYMERS`], written into `dir`.
fn scan_masked(dir: &std::path::Path, head: &str) -> std::process::Output {
    let sample = dir.join("masked.toml");
    std::fs::write(&sample, format!("length = \"1um\"\n{head}\n{TWO_POLYMERS}")).unwrap();
    common::tapsim(&[
        "scan",
        "--sample",
        sample.to_str().unwrap(),
        "--lines",
        "2",
        "--pixels",
        "4",
        "--line-rate",
        "20",
        "--no-retrace",
        "--json",
        "--quiet",
    ])
}

/// A mask CSV beside the sample file: its cells lay materials over the stripes, the first
/// row at the top of the image; a ragged row, an unknown material or a bad height is
/// refused with where it is.
#[test]
fn a_mask_lays_its_materials_where_its_cells_say() {
    let dir = common::scratch("scan_mask");
    let scan = |mask: &str| {
        std::fs::write(dir.join("mask.csv"), mask).unwrap();
        scan_masked(&dir, "mask = \"mask.csv\"")
    };
    // Top row (line 1, y = 750 nm): A then B; bottom row (line 0): B then A.
    let out = scan("A,B\nB,\n");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let phase = column(&v, "phase_deg");
    let (line0, line1) = (&phase[..4], &phase[4..]);
    // Settled pixels: the second of each half.
    assert!((line0[1] - line1[3]).abs() < 0.05, "B: {line0:?} {line1:?}");
    assert!((line0[3] - line1[1]).abs() < 0.05, "A: {line0:?} {line1:?}");
    assert!((line0[1] - line0[3]).abs() > 1.0, "no contrast: {line0:?}");
    for (mask, says) in [
        ("A,B\nB\n", "row 2 has 1 cells, the first 2"),
        ("A,C\n", "row 1, column 2: mask cell names material C"),
        ("A,B@2um\n", "row 1, column 2: a surface height"),
        ("", "no cells"),
    ] {
        let out = scan(mask);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{mask:?}: {err}");
        assert!(err.contains(says), "{mask:?}: {err}");
    }
}

/// A mask image is the same grid as a mask CSV: the PNG of the CSV above (its colours
/// named in [mask-colours], a transparent pixel for the empty cell) scans to the same
/// bytes; a colour not named, a partly transparent pixel, an image without its colours,
/// colours for a CSV and a file that is not a PNG are refused with what is wrong.
#[test]
fn a_mask_image_lays_the_same_grid_as_its_csv() {
    let dir = common::scratch("scan_mask_png");
    let scan = |head: &str| scan_masked(&dir, head);
    std::fs::write(dir.join("mask.csv"), "A,B\nB,\n").unwrap();
    let png = |pixels: [[u8; 4]; 4]| {
        let image =
            image::RgbaImage::from_fn(2, 2, |c, r| image::Rgba(pixels[(2 * r + c) as usize]));
        image.save(dir.join("mask.png")).unwrap();
    };
    let (black, red, clear) = ([0, 0, 0, 255], [255, 0, 0, 255], [0, 0, 0, 0]);
    png([black, red, red, clear]);
    let colours = "mask = \"mask.png\"\n[mask-colours]\n\"#000000\" = \"A\"\n\"#FF0000\" = \"B\"\n";
    let from_csv = scan("mask = \"mask.csv\"");
    let from_png = scan(colours);
    for out in [&from_csv, &from_png] {
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    assert_eq!(
        String::from_utf8_lossy(&from_csv.stdout),
        String::from_utf8_lossy(&from_png.stdout)
    );
    let refused = |head: &str, says: &str| {
        let out = scan(head);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{head:?}: {err}");
        assert!(err.contains(says), "{head:?}: {err}");
    };
    png([black, red, [0, 255, 0, 255], clear]);
    refused(
        colours,
        "row 2, column 1 (#00ff00): a colour [mask-colours] does not name",
    );
    png([black, red, [255, 0, 0, 128], clear]);
    refused(
        colours,
        "row 2, column 1 (#ff0000): partly transparent (alpha 128)",
    );
    refused("mask = \"mask.png\"", "needs its colours named");
    refused(
        "mask = \"mask.csv\"\n[mask-colours]\n\"#000000\" = \"A\"",
        "[mask-colours] is for a mask image",
    );
    refused(
        "mask = \"mask.png\"\n[mask-colours]\n\"black\" = \"A\"",
        "black is not a colour #rrggbb",
    );
    refused(
        "mask = \"mask.png\"\n[mask-colours]\n\"#000000\" = \"C\"",
        "mask cell names material C",
    );
    std::fs::write(dir.join("mask.png"), "A,B\n").unwrap();
    refused(colours, "not a PNG image");
    // Too wide a mask is refused before it is decoded.
    image::RgbaImage::new(4097, 1)
        .save(dir.join("mask.png"))
        .unwrap();
    refused(colours, "within 4096 pixels a side");
    // The shipped examples: the T of mask.csv and of mask.png image alike.
    let shipped = |name: &str| {
        let sample = format!("{}/examples/samples/{name}", env!("CARGO_MANIFEST_DIR"));
        let out = common::tapsim(&[
            "scan",
            "--sample",
            &sample,
            "--lines",
            "3",
            "--pixels",
            "8",
            "--line-rate",
            "20",
            "--no-retrace",
            "--json",
            "--quiet",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        out.stdout
    };
    assert_eq!(shipped("mask.toml"), shipped("mask_png.toml"));
}

/// An image sharded over three runs and merged is byte for byte the image one run
/// writes (CSV and heat maps); a part missing, or one whose pixels were moved to another
/// line, is refused.
#[test]
fn a_sharded_image_merges_into_the_whole_run_byte_for_byte() {
    let dir = common::scratch("scan_shards");
    let path = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let sample = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/samples/discs.toml");
    let scan = |extra: &[&str]| {
        let mut args = vec![
            "scan",
            "--sample",
            sample,
            "--lines",
            "3",
            "--pixels",
            "4",
            "--line-rate",
            "40",
            "--no-retrace",
            "--quiet",
        ];
        args.extend_from_slice(extra);
        let out = common::tapsim(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let (whole_csv, whole_png) = (path("whole.csv"), path("whole.png"));
    scan(&["--csv", &whole_csv, "--plot", &whole_png]);
    let parts: Vec<String> = (0..3).map(|i| path(&format!("part{i}.json"))).collect();
    for (i, part) in parts.iter().enumerate() {
        scan(&["--shard", &format!("{i}/3"), "--part", part]);
    }
    let (csv, png) = (path("merged.csv"), path("merged.png"));
    let out = common::tapsim(&[
        "merge", &parts[0], &parts[1], &parts[2], "--out", &csv, "--out", &png,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read(&csv).unwrap(),
        std::fs::read(&whole_csv).unwrap()
    );
    assert_eq!(
        std::fs::read(&png).unwrap(),
        std::fs::read(&whole_png).unwrap()
    );
    let out = common::tapsim(&["merge", &parts[0], &parts[2], "--out", &csv]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("1 of 3 parts missing: 1"));
    // Part 1 holds line 1; its pixels relabelled as line 0 are refused.
    let text = std::fs::read_to_string(&parts[1]).unwrap();
    let moved = path("moved.json");
    std::fs::write(&moved, text.replace("\"line\":1", "\"line\":0")).unwrap();
    let out = common::tapsim(&["merge", &parts[0], &moved, &parts[2], "--out", &csv]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("hold for line 1 a pixel of line 0"), "{err}");
}

/// The instrument on two eigenmodes whose drives have no common period (a beam's exact
/// f₂/f₁, a ratio tolerance of 0; Q₁ = 100 to settle soon): marched at a fixed z_c, each
/// mode's lock-in (a filter on the motion as it goes) reads, averaged over 400 periods,
/// what the window averages (whole periods of each mode, bump-weighted) give there
/// (measured: A₂/A₀₂ within 1.4e-5, φ₂ within 3e-4°; the march's looser tolerance and
/// the filter's ripple, averaged, are what is left).
#[test]
fn lock_ins_on_modes_without_a_common_period_read_the_window_averages() {
    use tapsim::dynamics::modes::{ModeSet, modal_windowed, prepare};
    use tapsim::instrument::modal::ModalProbe;
    use tapsim::instrument::probe::Probe;
    let mut setup = default_setup();
    setup.cantilever.quality = 100.0;
    let set = ModeSet {
        ratio_tolerance: 0.0,
        ..ModeSet::euler_bernoulli(&setup.cantilever, 2).unwrap()
    };
    let numerics = Numerics::default();
    let (p, modal) = prepare(&setup, &set, &numerics).unwrap();
    assert_eq!(modal.periods, None);
    let averaged = modal_windowed(&p, &modal, &numerics).unwrap();
    let materials = marched_modes(&setup, &set);
    let period = materials[0].1.drive_period();
    let mut probe = ModalProbe::new(&materials, 4, 2.0 * period).unwrap();
    let z = setup.separation_m;
    probe.march(0, z, 800).unwrap();
    let read = mean_readings(&mut probe, z, 400);
    for (i, (a, phi)) in read.iter().enumerate() {
        let m = &averaged.modes[i];
        eprintln!(
            "mode {}: lock-in A/A0 {a:.6}, phi {phi:.4}; window averages {:.6} ± {:.1e}, {:.4} ± \
             {:.1e}",
            i + 1,
            m.amplitude_ratio.unwrap(),
            m.amplitude_ratio_std_err.unwrap(),
            m.phase_deg,
            m.phase_std_err_deg
        );
        // The guide: A₂/A₀₂ within 1.4e-5, φ₂ within 3e-4°.
        assert!((a - m.amplitude_ratio.unwrap()).abs() < 2e-5);
        assert!((phi - m.phase_deg).abs() < 4e-4);
    }
}
