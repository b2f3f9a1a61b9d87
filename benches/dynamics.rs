//! Simulated steady-state tapping cycles per second with the hybrid law (default setup),
//! at integrator tolerances whose energy-balance error is below 1e-6 (checked before
//! measuring, at the default setpoint and at five others from 0.6 to 1.2 times its rest
//! separation, so a lucky cancellation at one setpoint cannot pass).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use tapsim::dynamics::numeric::Ignore;
use tapsim::dynamics::observables::TapObservables;
use tapsim::dynamics::setup::{Numerics, Prepared, TapSetup, default_setup};

const CYCLES: u64 = 200;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("tap_hybrid_cycles");
    group.throughput(Throughput::Elements(CYCLES));
    // (rtol, atol): the defaults, then looser settings that still keep the energy
    // balance below 1e-6 (checked below; the balance is not monotonic in the tolerances,
    // so each pair is checked rather than assumed).
    for (rtol, atol) in [(1e-9, 1e-11), (1e-8, 1e-10), (1e-7, 1e-9), (2e-7, 2e-9)] {
        let numerics = Numerics {
            rtol,
            atol,
            ..Numerics::default()
        };
        // The default setpoint last: its prepared experiment and steady phase are timed.
        let mut worst: f64 = 0.0;
        let mut timed = None;
        for factor in [0.6, 0.8, 0.9, 1.1, 1.2, 1.0] {
            let mut setup = default_setup();
            setup.separation_m *= factor;
            let p = Prepared::new(&setup, &numerics).expect("defaults are valid");
            let sim = p.simulation();
            let mut phase = sim.free_steady_start();
            let state = sim
                .steady_state(&mut phase, &p.steady)
                .expect("steady state");
            let o = TapObservables::new(&p, &state).unwrap();
            assert!(
                o.converged && o.energy_balance_rel < 1e-6,
                "rtol {rtol}, separation x{factor}: {o:?}"
            );
            worst = worst.max(o.energy_balance_rel);
            timed = Some((p, phase, o));
        }
        let (p, mut phase, o) = timed.expect("six setpoints");
        let sim = p.simulation();
        eprintln!(
            "rtol {rtol:e}, atol {atol:e}: energy balance {:.1e} (worst of six setpoints \
             {worst:.1e}), E_ts/loop - 1 = {:.1e}",
            o.energy_balance_rel,
            o.e_ts_j / o.loop_area_j - 1.0
        );
        group.bench_function(format!("rtol={rtol:e},atol={atol:e}"), |b| {
            b.iter(|| {
                for _ in 0..CYCLES {
                    sim.cycle(&mut phase, &mut Ignore).expect("cycle");
                }
            })
        });
    }
    group.finish();
}

/// Whole `tap` runs from the free oscillation to the reported steady state: the defaults
/// (period-1, found by Newton's method on the period map) and dForce's Hertz case at
/// Q = 1e5 (time-marching needs ~580 000 periods there). The periods each takes are
/// printed and bounded (20 and 60) before timing.
fn settle(c: &mut Criterion) {
    use tapsim::dynamics::observables::{Observe, tap};
    use tapsim::dynamics::setup::{Cantilever, TapSetup};
    use tapsim::law::LawKind;
    use tapsim::params::{Contact, composite_modulus};
    let hertz = TapSetup {
        contact: Contact::new(
            5e-9,
            composite_modulus(169e9, 0.28, 100e6, 0.3).expect("valid"),
            0.1,
            0.3e-9,
        )
        .expect("valid"),
        cantilever: Cantilever {
            stiffness_n_m: 0.9,
            resonance_hz: 100e3,
            quality: 1e5,
            free_amplitude_m: 15e-9,
            drive_frequency_hz: 100e3,
        },
        separation_m: 9e-9,
        law: LawKind::Hertz.into(),
    };
    // The defaults on a viscous sample (Kelvin–Voigt, 10 Pa·s: the repulsive orbit, away
    // from the fold near 25 Pa·s where it ends and the motion drifts for hundreds of
    // periods to the attractive one).
    let viscous = TapSetup {
        law: tapsim::law::LawSpec {
            viscosity_pa_s: Some(10.0),
            ..LawKind::Hybrid.into()
        },
        ..default_setup()
    };
    let mut group = c.benchmark_group("settle");
    for (name, setup, most) in [
        ("hybrid defaults", default_setup(), 20),
        ("dforce hertz Q=1e5", hertz, 60),
        ("hybrid + kelvin-voigt 10 Pa·s defaults", viscous, 20),
    ] {
        let o = tap(&setup, &Numerics::default(), Observe::default())
            .expect("tap")
            .observables;
        eprintln!("{name}: {} in {} periods", o.regime, o.cycles);
        assert!(
            o.converged && o.cycles <= most,
            "{name}: {} periods",
            o.cycles
        );
        group.bench_function(name, |b| {
            b.iter(|| tap(&setup, &Numerics::default(), Observe::default()).expect("tap"))
        });
    }
    group.finish();
}

/// `tapsim map` on its default ranges (Δγ 0.02–0.2 J/m², E* 0.3–3 GPa, hybrid law) on one
/// thread: the default 8 × 8 grid and a 10 × 10 one. Every cell is classified (period-n,
/// irregular or not applicable), checked before timing.
fn map(c: &mut Criterion) {
    use tapsim::sweep::{SETPOINT_MAX_CYCLES, SETPOINT_TOLERANCE, adhesion_modulus_map, log_grid};
    let setup = default_setup();
    let numerics = Numerics {
        tolerance: SETPOINT_TOLERANCE,
        max_cycles: SETPOINT_MAX_CYCLES,
        ..Numerics::default()
    };
    let mut group = c.benchmark_group("map");
    group.sample_size(10);
    for steps in [8, 10] {
        let works = log_grid("work of adhesion", 0.02, 0.2, steps).expect("grid");
        let moduli = log_grid("modulus", 0.3e9, 3e9, steps).expect("grid");
        let run = || adhesion_modulus_map(&setup, &numerics, &works, &moduli, 1, || {});
        let cells = run().expect("map");
        let periods: usize = cells
            .iter()
            .filter_map(|c| c.observables.as_ref())
            .inspect(|o| assert!(o.converged, "{o:?}"))
            .map(|o| o.cycles)
            .sum();
        eprintln!("map {steps}x{steps}: {periods} periods in all");
        group.bench_function(format!("{steps}x{steps}, one thread"), |b| {
            b.iter(|| run().expect("map"))
        });
    }
    group.finish();
}

/// States at an amplitude setpoint (issue 26) on the defaults: `tapsim tap --setpoint 0.8`
/// (both branches, each state refined until A/A₀ is the setpoint to 1e-9) and `tapsim map
/// --setpoint 0.8 --steps 10` on one thread (repulsive branch, the map's default; every
/// cell solved or noted as unreachable), checked before timing.
fn setpoint(c: &mut Criterion) {
    use tapsim::setpoint::{PhaseBranch, map_cells, states_at_setpoint};
    use tapsim::sweep::log_grid;
    let setup = default_setup();
    let numerics = Numerics::default();
    let mut group = c.benchmark_group("setpoint");
    let states = states_at_setpoint(&setup, &numerics, 0.8, None).expect("states");
    assert_eq!(states.len(), 2);
    group.bench_function("tap --setpoint 0.8", |b| {
        b.iter(|| states_at_setpoint(&setup, &numerics, 0.8, None).expect("states"))
    });
    group.sample_size(10);
    let works = log_grid("work of adhesion", 0.02, 0.2, 10).expect("grid");
    let moduli = log_grid("modulus", 0.3e9, 3e9, 10).expect("grid");
    let all: Vec<usize> = (0..100).collect();
    let run = || {
        let axes = (&works[..], &moduli[..]);
        map_cells(
            &setup,
            &numerics,
            axes,
            &all,
            1,
            || {},
            (0.8, PhaseBranch::Repulsive),
            None,
        )
    };
    let cells = run().expect("map");
    let held = cells.iter().filter(|c| c.observables.is_some()).count();
    eprintln!("map at A/A0 = 0.8, repulsive, 10x10: {held} cells hold it");
    group.bench_function("map --setpoint 0.8, 10x10, one thread", |b| {
        b.iter(|| run().expect("map"))
    });
    group.finish();
}

/// The numerics the instrument marches at: rtol `instrument::MARCH_RTOL` (2e-7), atol
/// 1e-2 of it.
fn march_numerics() -> Numerics {
    Numerics {
        rtol: tapsim::instrument::MARCH_RTOL,
        atol: 1e-2 * tapsim::instrument::MARCH_RTOL,
        ..Numerics::default()
    }
}

/// The marcher as the instrument drives it (`Simulation::march`), a thousand drive periods
/// on the defaults with the hybrid and the Hertz law, and the two laws that pull out of
/// contact (DMT's van der Waals, the semi-rigid attraction), at (rtol, atol) = (2e-7, 2e-9), the
/// loosest pair whose energy balance stays below 1e-6 (checked first on the settled
/// state): bare, and watched by a fourth-order lock-in (T = 2 periods), as `scan`
/// marches.
fn march(c: &mut Criterion) {
    use tapsim::instrument::lockin::LockIn;
    use tapsim::law::LawKind;
    const PERIODS: u64 = 1000;
    let mut group = c.benchmark_group("march");
    group.throughput(Throughput::Elements(PERIODS));
    group.sample_size(20);
    for (name, kind) in [
        ("hybrid", LawKind::Hybrid),
        ("hertz", LawKind::Hertz),
        ("dmt", LawKind::Dmt),
        ("hybrid-attractive", LawKind::HybridAttractive),
    ] {
        let mut setup = default_setup();
        setup.law.kind = kind;
        let numerics = march_numerics();
        let p = Prepared::new(&setup, &numerics).expect("defaults are valid");
        let sim = p.simulation();
        let mut phase = sim.free_steady_start();
        let state = sim
            .steady_state(&mut phase, &p.steady)
            .expect("steady state");
        let o = TapObservables::new(&p, &state).unwrap();
        // (The laws that pull out of contact integrate their free flight at this
        // tolerance too, and balance their energy less well: reported, not asserted.)
        let pulls_out_of_contact = matches!(name, "dmt" | "hybrid-attractive");
        assert!(
            o.energy_balance_rel < 1e-6 || pulls_out_of_contact,
            "{name}: {o:?}"
        );
        eprintln!("{name}: energy balance {:.1e}", o.energy_balance_rel);
        group.bench_function(format!("{name}, bare"), |b| {
            b.iter(|| {
                sim.march(&mut phase, PERIODS as usize, &mut Ignore)
                    .unwrap()
            })
        });
        let omega = sim.osc.omega;
        let mut lockin = LockIn::new(4, 2.0 * sim.osc.period(), omega).unwrap();
        group.bench_function(format!("{name}, with the lock-in"), |b| {
            b.iter(|| {
                sim.march(&mut phase, PERIODS as usize, &mut lockin)
                    .unwrap()
            })
        });
    }
    group.finish();
}

/// The line: 256 pixels over the built-in two-polymer blend at 1 line/s on the
/// default 300 kHz cantilever (1 172 drive periods a pixel, 300 032 in the trace), the
/// loop engaged first (10 000 periods), as `tapsim scan --pixels 256 --line-rate 1
/// --no-retrace` runs it.
fn scan_line(c: &mut Criterion) {
    use tapsim::config::TapInputs;
    use tapsim::instrument::feedback::PiController;
    use tapsim::instrument::lockin::LockIn;
    use tapsim::instrument::repeats::{DEFAULT_TOLERANCE, Repeats};
    use tapsim::instrument::scan::row;
    use tapsim::sample::{BLEND, Sample};
    let sample = Sample::from_toml(BLEND, &TapInputs::default()).unwrap();
    let numerics = march_numerics();
    let prepared: Vec<Prepared> = sample
        .materials
        .iter()
        .map(|(_, s)| Prepared::new(s, &numerics).unwrap())
        .collect();
    let sim = prepared[0].simulation();
    let lockin = LockIn::new(4, 2.0 * sim.osc.period(), sim.osc.omega).unwrap();
    let controller = PiController::new(0.8, 0.0, 0.002).unwrap();
    let regions = sample.layout.line_at(0.5 * sample.width_m, sample.length_m);
    let per_pixel = (300e3_f64 / 256.0).round() as usize;
    let mut group = c.benchmark_group("scan");
    group.sample_size(10);
    for (name, exact) in [
        ("256-pixel line at 1 line/s", false),
        ("256-pixel line at 1 line/s, --exact", true),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| {
                let mut repeats = if exact {
                    Repeats::exact()
                } else {
                    Repeats::within(DEFAULT_TOLERANCE)
                };
                row(
                    &prepared,
                    &regions,
                    (sample.length_m, 256, per_pixel),
                    (
                        lockin,
                        controller,
                        tapsim::instrument::thermal::ThermalForce::none(),
                    ),
                    (10_000, &mut repeats),
                    false,
                    |_| {},
                )
                .unwrap()
            })
        });
    }
    // The same line with two modes (`scan --modes 2`): the loop repeats over the common
    // period of four drive periods.
    use tapsim::dynamics::modes::{ModeSet, with_modes};
    use tapsim::instrument::modal::ModalProbe;
    use tapsim::instrument::scan::row_probe;
    let set = ModeSet::euler_bernoulli(&prepared[0].setup.cantilever, 2).unwrap();
    let modal: Vec<_> = prepared
        .iter()
        .map(|p| with_modes(p.clone(), &set).unwrap())
        .collect();
    group.bench_function("256-pixel bimodal line at 1 line/s", |b| {
        b.iter(|| {
            let mut probe = ModalProbe::new(&modal, 4, lockin.time_constant_hat()).unwrap();
            let mut repeats = Repeats::within(DEFAULT_TOLERANCE);
            let shape = (sample.length_m, 256, per_pixel);
            let engage = (10_000, &mut repeats);
            row_probe(
                &mut probe,
                &regions,
                shape,
                controller,
                engage,
                false,
                |_| {},
            )
            .unwrap()
        })
    });
    group.finish();
}

/// Thermal noise on the defaults at 300 K: the linear theory's σ_A and σ_φ through a
/// fourth-order lock-in of ENBW 1 kHz about the settled orbit (256 parts of the period;
/// the target 5 ms), and a thousand drive periods of the marcher under the
/// thermal force (64 steps a period) watched by that lock-in, at rtol 2e-7.
fn noise(c: &mut Criterion) {
    use tapsim::instrument::lockin::LockIn;
    use tapsim::instrument::noise::{PARTS_PER_PERIOD, linear_noise, time_constant_for_enbw};
    use tapsim::instrument::thermal::{STEPS_PER_PERIOD, ThermalForce, intensity_hat};
    let numerics = march_numerics();
    let p = Prepared::new(&default_setup(), &numerics).expect("defaults are valid");
    let sim = p.simulation();
    let mut phase = sim.free_steady_start();
    sim.steady_state(&mut phase, &p.steady)
        .expect("steady state");
    let cant = p.setup.cantilever;
    let d = intensity_hat(
        300.0,
        cant.stiffness_n_m,
        cant.quality,
        cant.free_amplitude_m,
    );
    let tau_hat =
        time_constant_for_enbw(4, 1000.0) * 2.0 * std::f64::consts::PI * cant.resonance_hz;
    let mut group = c.benchmark_group("noise");
    group.sample_size(20);
    group.bench_function("linear theory, defaults, 1 kHz", |b| {
        b.iter(|| linear_noise(&sim, &phase, d, (4, tau_hat), PARTS_PER_PERIOD).unwrap())
    });
    const PERIODS: u64 = 1000;
    group.throughput(Throughput::Elements(PERIODS));
    let mut force = ThermalForce::new(d, STEPS_PER_PERIOD, 1, 0).unwrap();
    let mut lockin = LockIn::new(4, tau_hat, sim.osc.omega).unwrap();
    group.bench_function("noisy march with the lock-in", |b| {
        b.iter(|| {
            force
                .march(&sim, &mut phase, PERIODS as usize, &mut lockin)
                .unwrap()
        })
    });
    group.finish();
}

/// A bimodal `tap` on the defaults (a beam's second mode, A₀₂ = A₀/40; the issue's
/// target 20 ms): the one-mode orbit, then Newton's method on the common period of four
/// drive periods, and the observables; and a third mode on top.
fn modes(c: &mut Criterion) {
    use tapsim::dynamics::modes::{ModeSet, tap_modes};
    let setup = default_setup();
    let numerics = Numerics::default();
    let mut group = c.benchmark_group("modes");
    group.sample_size(20);
    for count in [2, 3] {
        let set = ModeSet::euler_bernoulli(&setup.cantilever, count).expect("defaults");
        group.bench_function(format!("tap --modes {count}, defaults"), |b| {
            b.iter(|| tap_modes(&setup, &set, &numerics).expect("steady state"))
        });
    }
    group.finish();
    // Drives with no common period (`tap --modes 2 --ratio-tolerance 0`): twenty memories
    // of settling and eight bump-weighted windows, some 3 600 drive periods.
    let set = ModeSet {
        ratio_tolerance: 0.0,
        ..ModeSet::euler_bernoulli(&setup.cantilever, 2).expect("defaults")
    };
    let (p, modal) = tapsim::dynamics::modes::prepare(&setup, &set, &numerics).expect("defaults");
    let mut group = c.benchmark_group("modes");
    group.sample_size(10);
    group.bench_function("tap --modes 2 --ratio-tolerance 0, defaults", |b| {
        b.iter(|| tapsim::dynamics::modes::modal_windowed(&p, &modal, &numerics).expect("averages"))
    });
    group.finish();
    // The bimodal instrument (`scan --modes 2`): a hundred drive periods of the modes
    // at rtol 2e-7 on the state the loop holds at A₁/A₀₁ = 0.8 on polymer A, each read
    // by its lock-in, as a scan marches them.
    use tapsim::dynamics::modes::prepare;
    use tapsim::instrument::feedback::{PiController, hold_probe};
    use tapsim::instrument::modal::ModalProbe;
    use tapsim::instrument::probe::Probe;
    use tapsim::instrument::repeats::Repeats;
    const PERIODS: u64 = 100;
    let set = ModeSet::euler_bernoulli(&setup.cantilever, 2).expect("defaults");
    let materials = [prepare(&setup, &set, &march_numerics()).expect("defaults")];
    let period = materials[0].1.drive_period();
    let mut probe = ModalProbe::new(&materials, 4, 2.0 * period).expect("defaults");
    let mut controller = PiController::new(0.8, 0.0, 0.002).expect("defaults");
    let a0 = setup.cantilever.free_amplitude_m;
    let (_, z) = hold_probe(
        &mut probe,
        0,
        1.2 * a0,
        (&mut controller, &mut Repeats::exact()),
        6000,
    )
    .expect("engaged");
    let mut group = c.benchmark_group("scan");
    group.throughput(Throughput::Elements(PERIODS));
    group.sample_size(10);
    group.bench_function("bimodal loop, 100 drive periods", |b| {
        b.iter(|| probe.march(0, z, PERIODS as usize).expect("marched"))
    });
    group.finish();
}

/// A noisy approach curve: `n` points from z_c = `from` to 8 nm of `truth`, the piezo's
/// zero 3 nm off, 0.02 nm and 0.05° of noise (seed 7).
fn noisy_curve(
    truth: &TapSetup,
    numerics: &Numerics,
    from_m: f64,
    n: u32,
) -> tapsim::fit::Measured {
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    let offset = 3e-9;
    let positions: Vec<f64> = (0..n)
        .map(|i| from_m - (from_m - 8e-9) * f64::from(i) / f64::from(n - 1) - offset)
        .collect();
    let clean = tapsim::fit::model::curve(truth, numerics, &positions, offset).expect("curve");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let (na, np) = (
        Normal::new(0.0, 0.02e-9).expect("sigma"),
        Normal::new(0.0, 0.05).expect("sigma"),
    );
    tapsim::fit::Measured {
        position_m: positions,
        setpoint_ratio: None,
        second_mode: None,
        segments: vec![0],
        amplitude_m: Some(
            clean
                .amplitude_m
                .iter()
                .map(|a| a + na.sample(&mut rng))
                .collect(),
        ),
        phase_deg: Some(
            clean
                .phase_deg
                .iter()
                .map(|p| p + np.sample(&mut rng))
                .collect(),
        ),
        sigma_amplitude_m: 0.02e-9,
        sigma_phase_deg: 0.05,
        thermal: None,
    }
}

/// `tapsim fit`: the issue-32 round trip (30 points of the hybrid defaults' attractive
/// branch, E*, Δγ and the offset fitted from E* doubled, Δγ halved, the offset 1 nm off,
/// local search; target under 10 s), and issue 43's branch-jumping curve (E* 0.8 GPa,
/// Δγ 0.07 J/m², 40 points from 24 nm to 8 nm) fitted from half and twice the truth
/// with the global stage, on one thread (target under 10 s on one core).
fn fit(c: &mut Criterion) {
    use tapsim::fit::{FitOptions, Nuisance, Parameter, Search};
    let numerics = tapsim::sweep::sweep_numerics(Numerics::default(), (false, false));
    let truth = default_setup();
    let data = noisy_curve(&truth, &numerics, 18.5e-9, 30);
    let mut start = truth.clone();
    start.contact.modulus_pa *= 2.0;
    start.contact.work_of_adhesion_j_m2 *= 0.5;
    let parameters = vec![
        Parameter::Modulus,
        Parameter::WorkOfAdhesion,
        Parameter::ZOffset,
    ];
    let options = FitOptions {
        start: Nuisance::offset(2e-9),
        search: Search::Local,
        ..FitOptions::new(parameters.clone(), 0.0)
    };
    let mut group = c.benchmark_group("fit");
    group.sample_size(10);
    group.bench_function("round trip, 30 points, start 2x off", |b| {
        b.iter(|| tapsim::fit::fit(&start, &numerics, &data, &options, |_| {}).expect("fit"))
    });
    let mut truth = default_setup();
    truth.contact.modulus_pa = 0.8e9;
    truth.contact.work_of_adhesion_j_m2 = 0.07;
    let data = noisy_curve(&truth, &numerics, 24e-9, 40);
    let mut start = truth.clone();
    start.contact.modulus_pa *= 0.5;
    start.contact.work_of_adhesion_j_m2 *= 2.0;
    let options = FitOptions::new(parameters, 0.0);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a thread pool");
    group.bench_function(
        "branch jump, 40 points, global stage, start 0.5x/2x, one thread",
        |b| {
            b.iter(|| {
                one.install(|| {
                    tapsim::fit::fit(&start, &numerics, &data, &options, |_| {}).expect("fit")
                })
            })
        },
    );
    group.finish();
}

/// The `tapsim` command of the build these benchmarks belong to (`target/release/tapsim`
/// beside `target/release/deps/` where they run): `cargo build --release` makes it, as
/// the benchmarks' package does not.
fn tapsim_binary() -> String {
    let exe = std::env::current_exe().expect("the benchmark knows where it runs");
    let binary = exe
        .parent()
        .and_then(|deps| deps.parent())
        .map(|dir| dir.join(format!("tapsim{}", std::env::consts::EXE_SUFFIX)))
        .expect("the benchmark runs in target/<profile>/deps");
    assert!(
        binary.is_file(),
        "{} is missing: run `cargo build --release` before these benchmarks",
        binary.display()
    );
    binary.to_string_lossy().into_owned()
}

/// `tapsim tap` as a whole process (what a script pays per call): on the defaults and
/// on issue 44's soft sample. With `TAPSIM_BEFORE` naming another build's binary (the
/// one before the search for coexisting states, issue 44), that build side by side.
fn process(c: &mut Criterion) {
    use std::process::{Command, Stdio};
    let soft = [
        "--radius",
        "10nm",
        "--modulus",
        "50MPa",
        "--work-of-adhesion",
        "0.05",
        "--separation",
        "10nm",
    ];
    let cases: [(&str, &[&str]); 2] = [("defaults", &[]), ("soft sample, z_c 10 nm", &soft)];
    let mut binaries = vec![("", tapsim_binary())];
    if let Ok(before) = std::env::var("TAPSIM_BEFORE") {
        binaries.push((", before", before));
    }
    let mut group = c.benchmark_group("process");
    for (tag, binary) in &binaries {
        for (name, args) in cases {
            let run = || {
                let status = Command::new(binary)
                    .arg("tap")
                    .args(args)
                    .stdout(Stdio::null())
                    .stderr(Stdio::null())
                    .status()
                    .expect("tapsim runs");
                assert!(status.success());
            };
            group.bench_function(format!("tap, {name}{tag}"), |b| b.iter(run));
        }
    }
    group.finish();
}

/// Off-resonance tapping on the defaults (hybrid law, 2 kHz by 150 nm at z_c = 148 nm):
/// one settled cycle, from rest through the cycles marched until the motion repeats
/// (47) and the recorded one; the cost of a modulation cycle is this over 48.
fn peakforce(c: &mut Criterion) {
    use tapsim::instrument::peakforce::{Analysis, Modulation, cycle};
    let setup = default_setup();
    let mut group = c.benchmark_group("peakforce");
    group.sample_size(10);
    group.bench_function(
        "settled cycle at 148 nm (48 modulation cycles marched)",
        |b| {
            b.iter(|| {
                cycle(
                    &setup,
                    &Numerics::default(),
                    &Modulation::default(),
                    &Analysis::default(),
                    148e-9,
                )
                .unwrap()
            })
        },
    );
    group.finish();
}

/// A 128 × 128 QNM image (issue 47: under 2 min on two threads): `tapsim scan --mode
/// peakforce` on the built-in blend at 1 line/s (16 modulation cycles a pixel, trace and
/// retrace, each line engaged on its own), the repeats of a settled loop taken, and
/// with --exact every cycle marched (trace only: 262 144 cycles).
fn qnm_image(c: &mut Criterion) {
    use std::process::{Command, Stdio};
    let image = [
        "scan",
        "--mode",
        "peakforce",
        "--lines",
        "128",
        "--pixels",
        "128",
        "--line-rate",
        "1",
        "--threads",
        "2",
        "--quiet",
    ];
    let binary = tapsim_binary();
    let mut group = c.benchmark_group("qnm_image");
    group.sample_size(10);
    for (name, extra) in [
        ("128 x 128, trace and retrace", &[][..]),
        (
            "128 x 128, trace, every cycle (--exact)",
            &["--exact", "--no-retrace"][..],
        ),
    ] {
        let run = || {
            let status = Command::new(&binary)
                .args(image)
                .args(extra)
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .status()
                .expect("tapsim runs");
            assert!(status.success());
        };
        group.bench_function(name, |b| b.iter(run));
    }
    group.finish();
}

criterion_group!(
    benches, bench, settle, map, setpoint, march, scan_line, noise, modes, fit, process, peakforce,
    qnm_image
);
criterion_main!(benches);
