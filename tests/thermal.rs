//! The thermal force (issue 28): equipartition of the free cantilever's motion, the
//! marcher's noisy free flight against the exact step recursion, reproducible streams,
//! no noise at T = 0, and the energy balance of a noisy tapping march.

use crate::common;

use tapsim::dynamics::free::FreeFlight;
use tapsim::dynamics::grazing::{BOLTZMANN_J_K, ROOM_TEMPERATURE_K};
use tapsim::dynamics::march::{Phase, Simulation};
use tapsim::dynamics::model::{Coupling, Drive, Oscillator, X};
use tapsim::dynamics::numeric::{StepEnd, StepObserver, Tolerances};
use tapsim::dynamics::setup::{Numerics, Prepared, default_setup};
use tapsim::instrument::thermal::{
    FreeThermal, STEPS_PER_PERIOD, ThermalForce, free_variance_hat, intensity_hat,
};
use tapsim::law::{Branch, NoForce};

/// The defaults (at rest separation `z_c` where given) settled over `periods`
/// noise-free periods, and the thermal force's D̂ at 300 K on their lever.
fn settled_at_room_temperature(z_c: Option<f64>, periods: usize) -> (Prepared, Phase, f64) {
    let mut setup = default_setup();
    if let Some(z_c) = z_c {
        setup.separation_m = z_c;
    }
    let p = Prepared::new(&setup, &Numerics::default()).unwrap();
    let mut phase = p.simulation().free_steady_start();
    p.simulation()
        .march(&mut phase, periods, &mut tapsim::dynamics::numeric::Ignore)
        .unwrap();
    let c = &p.setup.cantilever;
    let d = intensity_hat(
        ROOM_TEMPERATURE_K,
        c.stiffness_n_m,
        c.quality,
        c.free_amplitude_m,
    );
    (p, phase, d)
}

/// The mean of `x²` and its standard error from the means of 50 batches (each far longer
/// than the motion's correlation time when the record is).
fn mean_square(x: &[f64]) -> (f64, f64) {
    const BATCHES: usize = 50;
    let per = x.len() / BATCHES;
    let means: Vec<f64> = x
        .chunks_exact(per)
        .map(|c| c.iter().map(|v| v * v).sum::<f64>() / per as f64)
        .collect();
    let m = means.iter().sum::<f64>() / means.len() as f64;
    let var = means.iter().map(|b| (b - m).powi(2)).sum::<f64>() / (means.len() - 1) as f64;
    (m, (var / means.len() as f64).sqrt())
}

/// Equipartition: the free cantilever's ⟨z²⟩ is k_BT/k (10.18 pm rms at 40 N/m and
/// 300 K), within its standard error, at three stiffnesses. The record: Q = 20, 64 force
/// steps a period, 40 000 periods (about 2 000 correlation times of the amplitude).
#[test]
fn the_free_cantilever_holds_equipartition() {
    let (q, length_m) = (20.0, 1e-9);
    let step = 2.0 * std::f64::consts::PI / STEPS_PER_PERIOD as f64;
    for (k, seed) in [(40.0, 1), (2.0, 2), (0.1, 3)] {
        let d = intensity_hat(ROOM_TEMPERATURE_K, k, q, length_m);
        let mut force = ThermalForce::new(d, STEPS_PER_PERIOD, seed, 0).unwrap();
        let x = FreeThermal::new(q, step).record(40_000 * STEPS_PER_PERIOD, 1, &mut force);
        let (m, se) = mean_square(&x);
        let (m_m2, se_m2) = (m * length_m * length_m, se * length_m * length_m);
        let kt_over_k = BOLTZMANN_J_K * ROOM_TEMPERATURE_K / k;
        // The force held over steps falls short of white by (π/64)²/3 = 8e-4.
        let exact = free_variance_hat(q, step, d) * length_m * length_m;
        assert!((exact / kt_over_k - 1.0).abs() < 1e-3);
        // The rms's standard error (half the mean square's, relative) under 1 %.
        assert!(se_m2 < 0.02 * m_m2, "k = {k}: error {se_m2:e} too large");
        assert!(
            (m_m2 - kt_over_k).abs() < 3.0 * se_m2,
            "k = {k}: <z²> = {m_m2:e} ± {se_m2:e} vs k_BT/k = {kt_over_k:e}"
        );
        eprintln!(
            "k = {k} N/m: rms {:.4} pm ± {:.2} % (k_BT/k: {:.4} pm)",
            m_m2.sqrt() * 1e12,
            50.0 * se_m2 / m_m2,
            kt_over_k.sqrt() * 1e12
        );
        if k == 40.0 {
            assert_eq!(format!("{:.2}", kt_over_k.sqrt() * 1e12), "10.18");
        }
    }
}

/// Records the deflection at the end of each free flight.
/// The deflection at the end of each force step, whether the step is shown as a
/// closed-form flight or (taken from the precomputed transition) as a step; a free
/// cantilever far from the sample takes no integrator step.
struct Ends(Vec<f64>);
impl StepObserver for Ends {
    fn step<const N: usize>(&mut self, _: &StepEnd<N>, to: &StepEnd<N>, branch: Branch) {
        assert_eq!(branch, Branch::Free, "no contact far from the sample");
        self.0.push(to.y[X]);
    }
    fn free_flight(&mut self, flight: &FreeFlight, _from: f64, to: f64) {
        self.0.push(flight.at(to).0);
    }
}

/// The marcher under the thermal force (each step's force held, the free flight in
/// closed form) moves the free cantilever as the exact step recursion does, force for
/// force, to round-off: two independent routes to the same motion.
#[test]
fn the_noisy_marcher_moves_the_free_cantilever_as_the_step_recursion_does() {
    let q = 20.0;
    let sim = Simulation {
        law: &NoForce,
        osc: Oscillator {
            gamma: 0.5 / q,
            omega: 1.0,
            drive: Drive::Force { amplitude: 0.0 },
            bias: 0.0,
        },
        cpl: Coupling {
            a0: 1e3,
            a1: 1.0,
            f_scale: 1.0,
        },
        tol: Tolerances {
            rtol: 1e-9,
            atol: 1e-11,
            h_max: 0.1,
        },
    };
    let d = intensity_hat(ROOM_TEMPERATURE_K, 2.0, q, 1e-9);
    let periods = 50;
    let step = sim.osc.period() / STEPS_PER_PERIOD as f64;
    let mut again = ThermalForce::new(d, STEPS_PER_PERIOD, 7, 3).unwrap();
    let record = FreeThermal::new(q, step).record(periods * STEPS_PER_PERIOD, 1, &mut again);
    let scale = record.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    assert!(scale > 0.0);
    // Both ways of marching: most steps from the precomputed transition, and every step
    // a closed-form flight of its own (`exact`).
    for exact in [false, true] {
        let mut ends = Ends(Vec::new());
        let mut phase = sim.free_steady_start();
        let force = ThermalForce::new(d, STEPS_PER_PERIOD, 7, 3).unwrap();
        let mut force = if exact { force.exact() } else { force };
        force.march(&sim, &mut phase, periods, &mut ends).unwrap();
        assert_eq!(ends.0.len(), record.len());
        for (i, (a, b)) in ends.0.iter().zip(&record).enumerate() {
            assert!(
                (a - b).abs() < 1e-9 * scale,
                "exact {exact}, step {i}: {a:e} vs {b:e}"
            );
        }
    }
}

/// On the tapping defaults the steps of free flight taken from the precomputed
/// transition (the default) march as the reference does, every step a closed-form
/// flight located against the contact (`exact`), force for force: after 100 periods
/// at 300 K and at 30 000 K (three seeds each) the state and every integral of the march
/// agree to round-off, and a lock-in watching it, which reads those steps' cubic Hermite
/// interpolants instead of the closed form, within that interpolant's error bound,
/// (ΩΔ)⁴/384 = 2.4e-7 of the amplitude at 64 steps a period (1.1e-7 measured).
#[test]
fn free_steps_from_the_precomputed_transition_march_as_the_exact_march_does() {
    use tapsim::instrument::lockin::LockIn;
    let (p, mut settled, d_room) = settled_at_room_temperature(None, 200);
    let sim = p.simulation();
    // Off the lock-in's sampling grid (at τ = 0 the force steps would end where it
    // samples, and the interpolants would be read only at their ends).
    sim.advance(
        &mut settled,
        0.37 * sim.osc.period() / STEPS_PER_PERIOD as f64,
        &mut tapsim::dynamics::numeric::Ignore,
    )
    .unwrap();
    for hotter in [1.0, 100.0] {
        // D̂ grows as the temperature.
        let (d, temperature) = (hotter * d_room, hotter * ROOM_TEMPERATURE_K);
        for seed in 1..=3 {
            let run = |exact: bool| {
                let force = ThermalForce::new(d, STEPS_PER_PERIOD, seed, 0).unwrap();
                let mut force = if exact { force.exact() } else { force };
                let mut phase = settled.clone();
                let mut lockin = LockIn::new(2, 30.0, sim.osc.omega).unwrap();
                let (total, work) = force.march(&sim, &mut phase, 100, &mut lockin).unwrap();
                (phase, total.unwrap(), work, lockin.output())
            };
            let (fast, reference) = (run(false), run(true));
            let (p, q) = (fast.0, reference.0);
            assert!(
                (p.x - q.x).abs() < 1e-10 && (p.v - q.v).abs() < 1e-10 && p.branch == q.branch,
                "{temperature} K, seed {seed}: ({}, {}) vs ({}, {})",
                p.x,
                p.v,
                q.x,
                q.v
            );
            let (a, b) = (fast.1, reference.1);
            assert_eq!((a.jumps_in, a.jumps_out), (b.jumps_in, b.jumps_out));
            let close = |x: f64, y: f64, scale: f64| (x - y).abs() <= 1e-9 * scale;
            for (name, x, y, scale) in [
                ("E_ts", a.e_ts, b.e_ts, b.e_ts.abs()),
                ("E_damp", a.e_damp, b.e_damp, b.e_damp),
                ("E_drive", a.e_drive, b.e_drive, b.e_drive),
                ("ΔE_osc", a.delta_mechanical, b.delta_mechanical, b.e_drive),
                ("sc", a.sc, b.sc, b.sc.hypot(b.ss)),
                ("ss", a.ss, b.ss, b.sc.hypot(b.ss)),
                ("min α̂", a.min_alpha_hat, b.min_alpha_hat, 1.0),
                ("thermal work", fast.2, reference.2, b.e_drive),
            ] {
                assert!(
                    close(x, y, scale),
                    "{temperature} K, seed {seed}, {name}: {x:e} vs {y:e}"
                );
            }
            for (x, y) in [
                (a.grazing.any, b.grazing.any),
                (a.grazing.jump, b.grazing.jump),
            ] {
                assert!(
                    close(x, y, 1.0),
                    "the margins come from the located steps: {x} vs {y}"
                );
            }
            let (l, m) = (fast.3, reference.3);
            let amplitude = m.0.hypot(m.1);
            let lockin_gap = (l.0 - m.0).hypot(l.1 - m.1);
            eprintln!(
                "{temperature} K, seed {seed}: lock-in differs by {:.2e} of A",
                lockin_gap / amplitude
            );
            // The cubic Hermite's error, (ΩΔ)⁴/384 of a sinusoid's amplitude.
            let hermite = (std::f64::consts::TAU / STEPS_PER_PERIOD as f64).powi(4) / 384.0;
            assert!(lockin_gap < hermite * amplitude, "lock-in {l:?} vs {m:?}");
        }
    }
}

/// Where the fast steps' bounds are tightest — the onset of contact on the defaults,
/// where the orbit grazes the jump-in level and the noise decides each period whether
/// the tip touches (19.5 and 20.2 nm, touching in about 94 % and 65 % of periods) — the
/// march with them touches in the same periods as the reference that locates every
/// step, its state within 1e-8 at every period's end over 2 000 periods at 300 K.
#[test]
fn at_the_grazing_onset_the_fast_steps_touch_when_the_located_ones_do() {
    for z_c in [19.5e-9, 20.2e-9] {
        let (p, start, d) = settled_at_room_temperature(Some(z_c), 3000);
        let sim = p.simulation();
        let run = |exact: bool| {
            let force = ThermalForce::new(d, STEPS_PER_PERIOD, 5, 0).unwrap();
            let mut force = if exact { force.exact() } else { force };
            let mut phase = start.clone();
            (0..2000)
                .map(|_| {
                    let (t, _) = force
                        .march(&sim, &mut phase, 1, &mut tapsim::dynamics::numeric::Ignore)
                        .unwrap();
                    (t.unwrap().jumps_in, phase.x)
                })
                .collect::<Vec<_>>()
        };
        let (fast, reference) = (run(false), run(true));
        let touched = reference.iter().filter(|(j, _)| *j > 0).count();
        assert!(
            (100..1900).contains(&touched),
            "{z_c:e}: the noise decides the touches ({touched} of 2000)"
        );
        for (k, (a, b)) in fast.iter().zip(&reference).enumerate() {
            assert!(
                a.0 == b.0 && (a.1 - b.1).abs() < 1e-8,
                "{z_c:e}, period {k}: {a:?} vs {b:?}"
            );
        }
    }
}

/// The same seed and stream draw the same forces; another stream others; D̂ = 0 marches
/// exactly as the noise-free marcher does.
#[test]
fn streams_are_reproducible_and_zero_temperature_is_noise_free() {
    let draw = |seed, stream| {
        let mut f = ThermalForce::new(1.0, 64, seed, stream).unwrap();
        (0..5).map(|_| f.draw(0.1)).collect::<Vec<_>>()
    };
    assert_eq!(draw(1, 0), draw(1, 0));
    assert_ne!(draw(1, 0), draw(1, 1));
    assert_ne!(draw(1, 0), draw(2, 0));
    let p = Prepared::new(&default_setup(), &Numerics::default()).unwrap();
    let sim = p.simulation();
    let mut plain = sim.free_steady_start();
    sim.march(&mut plain, 30, &mut tapsim::dynamics::numeric::Ignore)
        .unwrap();
    let mut noisy = sim.free_steady_start();
    let mut cold = ThermalForce::new(0.0, 64, 1, 0).unwrap();
    let (_, work) = cold
        .march(&sim, &mut noisy, 30, &mut tapsim::dynamics::numeric::Ignore)
        .unwrap();
    assert_eq!(plain, noisy);
    assert_eq!(work, 0.0);
}

/// A tapping march at 300 K on the defaults keeps its books: the drive's and the thermal
/// force's work less damping and the contact's loss is the change of the oscillator's
/// energy, to 1e-6 of the drive's work — the held forces are integrated exactly through
/// free flight and contact alike.
#[test]
fn a_noisy_tapping_march_balances_its_energy() {
    let (p, mut phase, d) = settled_at_room_temperature(None, 200);
    let sim = p.simulation();
    let mut force = ThermalForce::new(d, STEPS_PER_PERIOD, 11, 0).unwrap();
    let (total, work) = force
        .march(&sim, &mut phase, 20, &mut tapsim::dynamics::numeric::Ignore)
        .unwrap();
    let t = total.unwrap();
    assert_eq!(t.periods, 20);
    assert!(
        t.jumps_in == 20,
        "the tip taps every period: {}",
        t.jumps_in
    );
    assert!(work != 0.0);
    let residual = t.e_drive + work - t.e_damp - t.e_ts - t.delta_mechanical;
    eprintln!(
        "E_drive {:e}, thermal work {work:e}, residual {residual:e}",
        t.e_drive
    );
    assert!(
        residual.abs() < 1e-6 * t.e_drive,
        "residual {residual:e} of {:e}",
        t.e_drive
    );
}

/// `tapsim thermal` recovers the cantilever it records (the defaults' 300 kHz and
/// 40 N/m at Q = 30, 10⁶ periods): f₀ and Q within 1 %, k within 2 %, over three seeds;
/// the record's rms is equipartition's; the CSV holds the spectrum and the plot is
/// drawn; bad settings are refused.
#[test]
fn thermal_calibrates_the_cantilever_it_records() {
    let dir = common::scratch("thermal");
    for seed in ["1", "2", "3"] {
        let csv = dir.join("spectrum.csv");
        let png = dir.join("spectrum.png");
        let out = common::tapsim(&[
            "thermal",
            "--quality",
            "30",
            "--duration",
            "3.3333333s",
            "--seed",
            seed,
            "--json",
            "--quiet",
            "--csv",
            csv.to_str().unwrap(),
            "--plot",
            png.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let off =
            |fit: &str, truth: &str| v[fit].as_f64().unwrap() / v[truth].as_f64().unwrap() - 1.0;
        assert_eq!(v["periods"].as_u64(), Some(1_000_000));
        eprintln!(
            "seed {seed}: f0 {:+.4} %, Q {:+.3} %, k {:+.3} %, rms {:+.3} %",
            100.0 * off("fit_resonance_hz", "resonance_hz"),
            100.0 * off("fit_quality", "quality"),
            100.0 * off("fit_stiffness_n_m", "stiffness_n_m"),
            100.0 * off("rms_m", "equipartition_rms_m")
        );
        assert!(off("fit_resonance_hz", "resonance_hz").abs() < 0.01);
        assert!(off("fit_quality", "quality").abs() < 0.01);
        assert!(off("fit_stiffness_n_m", "stiffness_n_m").abs() < 0.02);
        assert!(off("rms_m", "equipartition_rms_m").abs() < 0.01);
        let text = std::fs::read_to_string(&csv).unwrap();
        assert!(text.starts_with("freq_hz,welch_m2_hz,sho_m2_hz,fit_m2_hz\n"));
        assert!(std::fs::metadata(&png).unwrap().len() > 10_000);
    }
    for (args, says) in [
        (&["--quality", "5"][..], "Q from 10"),
        (&["--steps", "12"], "multiple of 8"),
        (&["--temperature", "-1K"], "temperature"),
        (&["--duration", "1us"], "spans"),
        (&["--duration", "1e9s"], "beyond reach"),
    ] {
        let mut all = vec!["thermal", "--quiet"];
        all.extend_from_slice(args);
        common::refused(&all, says);
    }
}

/// Near grazing (the hybrid defaults at z_c = 20 nm, where the deterministic answer is a
/// period-41 lock whose touches a perturbation below the thermal motion decides), the
/// thermal average — what an instrument reads — does not depend on the integrator's
/// tolerance (rtol 1e-9 and 1e-11) nor on the seed, within its standard errors; at 0 K
/// it is the deterministic lock's.
#[test]
fn the_thermal_average_near_grazing_is_independent_of_the_tolerance() {
    use tapsim::instrument::average::{AverageRequest, thermal_average};
    let mut setup = default_setup();
    setup.separation_m = 20e-9;
    let numerics = |rtol: f64| Numerics {
        rtol,
        atol: 1e-2 * rtol,
        ..Numerics::default()
    };
    let run = |rtol: f64, seed: u64, t: f64| {
        let request = AverageRequest {
            temperature_k: t,
            periods: 20_000,
            seed,
        };
        thermal_average(&setup, &numerics(rtol), &request).unwrap()
    };
    let base = run(1e-9, 1, ROOM_TEMPERATURE_K);
    let ev = 1.602_176_634e-19;
    for (what, other) in [
        ("rtol 1e-11", run(1e-11, 1, ROOM_TEMPERATURE_K)),
        ("seed 2", run(1e-9, 2, ROOM_TEMPERATURE_K)),
    ] {
        eprintln!(
            "{what}: E_ts {:.3} ± {:.3} eV vs {:.3} ± {:.3}; φ {:.3} ± {:.3}° vs {:.3} ± {:.3}",
            other.e_ts_j / ev,
            other.e_ts_std_err_j / ev,
            base.e_ts_j / ev,
            base.e_ts_std_err_j / ev,
            other.phase_deg,
            other.phase_std_err_deg,
            base.phase_deg,
            base.phase_std_err_deg
        );
        let within = |a: f64, b: f64, sa: f64, sb: f64| (a - b).abs() <= 3.0 * sa.hypot(sb);
        assert!(within(
            other.e_ts_j,
            base.e_ts_j,
            other.e_ts_std_err_j,
            base.e_ts_std_err_j
        ));
        assert!(within(
            other.phase_deg,
            base.phase_deg,
            other.phase_std_err_deg,
            base.phase_std_err_deg
        ));
        assert!(other.e_ts_std_err_j < 0.01 * other.e_ts_j);
    }
    // Some periods touch, some do not: the thermal motion decides.
    assert!(base.touch_fraction > 0.1 && base.touch_fraction < 0.95);
    // At 0 K the deterministic lock, averaged over the same record.
    let cold = run(1e-9, 1, 0.0);
    let state = tapsim::tap(&setup, &numerics(1e-9), Default::default()).unwrap();
    assert!(
        (cold.e_ts_j / state.observables.e_ts_j - 1.0).abs() < 1e-3,
        "{} vs {}",
        cold.e_ts_j,
        state.observables.e_ts_j
    );
}

/// The thermal average's standard errors are the spread of independent records: over
/// six seeds the means of E_ts and φ scatter by their quoted standard error (the ratio
/// of the seeds' standard deviation to the mean standard error within 0.4–2).
#[test]
fn the_thermal_averages_errors_are_the_spread_of_seeds() {
    use tapsim::instrument::average::{AverageRequest, thermal_average};
    let mut setup = default_setup();
    setup.separation_m = 20e-9;
    let numerics = Numerics::default();
    let runs: Vec<_> = (10..16)
        .map(|seed| {
            let request = AverageRequest {
                temperature_k: ROOM_TEMPERATURE_K,
                periods: 8_000,
                seed,
            };
            thermal_average(&setup, &numerics, &request).unwrap()
        })
        .collect();
    let check = |value: &dyn Fn(&tapsim::instrument::average::ThermalAverage) -> (f64, f64)| {
        let v: Vec<(f64, f64)> = runs.iter().map(value).collect();
        let n = v.len() as f64;
        let m = v.iter().map(|x| x.0).sum::<f64>() / n;
        let sd = (v.iter().map(|x| (x.0 - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let se = (v.iter().map(|x| x.1 * x.1).sum::<f64>() / n).sqrt();
        eprintln!("spread {sd:e}, quoted {se:e}");
        assert!(sd / se > 0.4 && sd / se < 2.0, "{sd:e} vs {se:e}");
    };
    check(&|a| (a.e_ts_j, a.e_ts_std_err_j));
    check(&|a| (a.phase_deg, a.phase_std_err_deg));
}

/// `tap --temperature` averages over the thermal motion where the deterministic state
/// grazes a switch (the guide: the hybrid defaults at 20 nm), and not on a stable period-1
/// orbit away from every switch (the defaults, where the linear noise theory speaks).
#[test]
fn tap_averages_a_grazing_state_over_the_thermal_motion() {
    let json = |args: &[&str]| common::json_of(&["tap", "--json", "--temperature", "300K"], args);
    let v = json(&["--separation", "20nm"]);
    assert_eq!(v["grazing"], true);
    let a = &v["thermal_average"];
    let ev = 1.602_176_634e-19;
    let f = |key: &str| a[key].as_f64().unwrap();
    assert_eq!(
        format!(
            "{} {:.3} {:.3} | {:.3} ± {:.3} {:.3} ± {:.3} {:.1} %",
            v["regime"].as_str().unwrap(),
            v["e_ts_ev"].as_f64().unwrap(),
            v["phase_deg"].as_f64().unwrap(),
            f("e_ts_j") / ev,
            f("e_ts_std_err_j") / ev,
            f("phase_deg"),
            f("phase_std_err_deg"),
            100.0 * f("touch_fraction")
        ),
        "period-41 15.471 102.976 | 15.380 ± 0.008 103.018 ± 0.005 75.2 %"
    );
    assert_eq!(a["records"].as_u64(), Some(8));
    assert_eq!(a["periods"].as_u64(), Some(20_000));
    assert!(json(&[]).get("thermal_average").is_none());
}

/// `approach --temperature` averages the points that graze a switch over the thermal
/// motion, started from the sweep's state: the same average, within its statistical
/// errors, as `tap --temperature` finds at that z_c from the free oscillation (another
/// start, another route to the same thermal state). Points on a stable period-1 orbit
/// away from every switch get none, a run without a temperature none at all; the CSV
/// carries the average as columns; a setpoint sweep refuses the flag.
#[test]
fn approach_averages_the_grazing_points_over_the_thermal_motion() {
    let csv = common::scratch("approach_thermal").join("sweep.csv");
    let csv_arg = csv.to_str().unwrap();
    let head = [
        "approach",
        "--from",
        "20.6nm",
        "--to",
        "17nm",
        "--points",
        "2",
        "--no-retract",
        "--json",
    ];
    let sweep = |extra: &[&str]| common::json_of(&head, extra);
    let v = sweep(&[
        "--temperature",
        "300K",
        "--thermal-periods",
        "4000",
        "--csv",
        csv_arg,
    ]);
    let averages = v["thermal_average"].as_array().unwrap();
    assert_eq!(v["grazing"], serde_json::json!([true, false]));
    assert!(averages[1].is_null(), "{:?}", averages[1]);
    let a = &averages[0];
    assert_eq!(a["periods"].as_u64(), Some(4000));
    let tap = common::json(&[
        "tap",
        "--separation",
        "20.6nm",
        "--temperature",
        "300K",
        "--thermal-periods",
        "4000",
        "--json",
    ]);
    let t = &tap["thermal_average"];
    for (value, error) in [
        ("e_ts_j", "e_ts_std_err_j"),
        ("phase_deg", "phase_std_err_deg"),
        ("touch_fraction", "touch_fraction_std_err"),
    ] {
        let (x, y) = (common::num(a, value), common::num(t, value));
        let sigma = common::num(a, error).hypot(common::num(t, error));
        eprintln!("{value}: approach {x:e}, tap {y:e}, σ {sigma:e}");
        assert!(sigma > 0.0 && (x - y).abs() <= 4.0 * sigma);
    }
    // Some periods touch, some do not.
    let touches = common::num(a, "touch_fraction");
    assert!(touches > 0.05 && touches < 0.95, "{touches}");
    let mut reader = csv::Reader::from_path(&csv).unwrap();
    let column = reader
        .headers()
        .unwrap()
        .iter()
        .position(|h| h == "thermal_average_e_ts_j")
        .expect("the average's columns");
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    // The same number, to the CSV's 10 significant digits (docs/src/reference/output.md).
    let (in_csv, in_json) = (
        rows[0][column].parse::<f64>().unwrap(),
        common::num(a, "e_ts_j"),
    );
    assert!(
        (in_csv - in_json).abs() <= 5e-10 * in_json,
        "{in_csv} {in_json}"
    );
    assert_eq!(&rows[1][column], "");
    assert!(sweep(&[]).get("thermal_average").is_none());
    common::refused(
        &["approach", "--sweep", "setpoint", "--temperature", "300K"],
        "separation sweep",
    );
    common::refused(
        &[
            "approach",
            "--temperature",
            "300K",
            "--thermal-periods",
            "10",
        ],
        "thermal average spans",
    );
}

/// `map --temperature` at one z_c averages exactly the cells an instrument reads only as
/// a thermal average (grazing or not a stable period-1 orbit), each as `tap
/// --temperature` does at that cell's parameters (the same records, to the last digit),
/// and adds the heat maps of E_ts and φ as read; `--enbw` without a setpoint is refused.
#[test]
fn map_averages_its_grazing_cells_over_the_thermal_motion() {
    let grid = [
        "map",
        "--separation",
        "20nm",
        "--adhesion-from",
        "0.02",
        "--adhesion-to",
        "0.2",
        "--modulus-from",
        "0.3GPa",
        "--modulus-to",
        "0.5GPa",
        "--steps",
        "2",
        "--temperature",
        "300K",
        "--thermal-periods",
        "1600",
    ];
    let v = common::json(&[&grid[..], &["--json"]].concat());
    // The grid holds a row-by-row array per field: one object per cell from them.
    let column = |key: &str| common::cells(&v["grid"][key]);
    let fields = [
        "grazing",
        "period",
        "stable",
        "work_of_adhesion_j_m2",
        "modulus_pa",
        "thermal_average",
    ];
    let columns: Vec<Vec<serde_json::Value>> = fields.iter().map(|k| column(k)).collect();
    let cells: Vec<serde_json::Value> = (0..columns[0].len())
        .map(|i| {
            serde_json::Value::Object(
                fields
                    .iter()
                    .zip(&columns)
                    .map(|(k, c)| (k.to_string(), c[i].clone()))
                    .collect(),
            )
        })
        .collect();
    let (mut averaged, mut plain) = (0, 0);
    let mut seeds = Vec::new();
    for cell in cells.iter().filter(|c| !c["grazing"].is_null()) {
        let reads_as_average =
            cell["grazing"] == true || cell["period"].as_u64() != Some(1) || cell["stable"] != true;
        let average = &cell["thermal_average"];
        assert_eq!(!average.is_null(), reads_as_average, "{cell}");
        if average.is_null() {
            plain += 1;
            continue;
        }
        averaged += 1;
        seeds.push(average["seed"].as_u64().unwrap());
        let w = format!("{}", common::num(cell, "work_of_adhesion_j_m2"));
        let e = format!("{}", common::num(cell, "modulus_pa"));
        let tap = common::json(&[
            "tap",
            "--separation",
            "20nm",
            "--work-of-adhesion",
            &w,
            "--modulus",
            &e,
            "--temperature",
            "300K",
            "--thermal-periods",
            "1600",
            "--json",
        ]);
        assert_eq!(&tap["thermal_average"], average);
    }
    assert!(
        averaged > 0 && plain > 0,
        "{averaged} averaged, {plain} not"
    );
    // Each cell draws its own noise (issue 45: one stream for all made the errors of
    // neighbouring cells move together).
    let n = seeds.len();
    seeds.sort_unstable();
    seeds.dedup();
    assert_eq!(seeds.len(), n, "cells share a seed");
    common::refused(&[&grid[..], &["--enbw", "100Hz"]].concat(), "--enbw");
}

/// `thermal --psd`: a spectrum `thermal --csv` wrote of a lever with known k (40 N/m,
/// 300 kHz, Q = 30), read back as a measured one, gives k within 3 % and f₀ and Q
/// within 1 %, each within three of its reported standard errors — and so does the same
/// record under a white background (the detector's noise, 3 % of the peak, scattering
/// as the bins do), whose level the fit recovers; in V²/Hz with the InvOLS the numbers are the m²/Hz ones;
/// --save-config writes a lever `tap --config` runs with.
#[test]
fn a_measured_spectrum_calibrates_its_cantilever() {
    let dir = common::scratch("thermal_psd");
    let written = dir.join("written.csv");
    let out = common::tapsim(&[
        "thermal",
        "--quality",
        "30",
        "--duration",
        "1s",
        "--quiet",
        "--csv",
        written.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&written).unwrap();
    let rows: Vec<(f64, f64, f64)> = text
        .lines()
        .skip(1)
        .map(|l| {
            let c: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (c[0], c[1], c[2])
        })
        .collect();
    // S₀ = 2k_BT/(πkf₀Q): the resonance's level at f = 0; its peak is S₀Q².
    let white = 2.0 * 1.380649e-23 * 300.0 / (std::f64::consts::PI * 40.0 * 3e5 * 30.0);
    let background = 0.03 * white * 900.0;
    let invols = 50e-9;
    let write = |name: &str, header: &str, f: &dyn Fn(f64, f64) -> f64| {
        let path = dir.join(name);
        let mut s = format!("freq_khz,{header}\n");
        for &(freq, p, truth) in &rows {
            s.push_str(&format!("{},{:.12e}\n", freq * 1e-3, f(p, truth)));
        }
        std::fs::write(&path, s).unwrap();
        path
    };
    // The background scatters as the bin it adds to: each bin's estimate (the record's
    // P over the cantilever's own S) times S + B.
    let plain = write("plain.csv", "psd_m2_hz", &|p, _| p);
    let noisy = write("noisy.csv", "psd_pm2_hz", &|p, s| {
        p / s * (s + background) * 1e24
    });
    let volts = write("volts.csv", "deflection_v2_hz", &|p, _| {
        p / (invols * invols)
    });
    let lever = dir.join("lever.toml");
    let fit = |file: &std::path::Path, extra: &[&str]| {
        let mut args = vec!["thermal", "--psd", file.to_str().unwrap(), "--json"];
        args.extend_from_slice(extra);
        common::json(&args)
    };
    let check = |v: &serde_json::Value, name: &str| {
        for (key, truth, tolerance) in [
            ("fit_stiffness_n_m", 40.0, 0.03),
            ("fit_resonance_hz", 3e5, 0.01),
            ("fit_quality", 30.0, 0.01),
        ] {
            let got = common::num(v, key);
            let sd = common::num(
                v,
                &key.replace("_n_m", "_sd_n_m")
                    .replace("_hz", "_sd_hz")
                    .replace("quality", "quality_sd"),
            );
            eprintln!("{name}: {key} {got} ± {sd}");
            assert!((got / truth - 1.0).abs() < tolerance, "{name}: {key} {got}");
            assert!((got - truth).abs() < 3.0 * sd, "{name}: {key} {got} ± {sd}");
        }
    };
    let a = fit(&plain, &["--save-config", lever.to_str().unwrap()]);
    check(&a, "plain");
    let b = fit(&noisy, &[]);
    check(&b, "with background");
    let (bg, bg_sd) = (
        common::num(&b, "fit_background_m2_hz"),
        common::num(&b, "fit_background_sd_m2_hz"),
    );
    assert!(
        (bg - background).abs() < 3.0 * bg_sd && bg_sd < 0.1 * background,
        "{bg} ± {bg_sd}"
    );
    let c = fit(&volts, &["--invols", "50nm"]);
    for key in ["fit_stiffness_n_m", "fit_resonance_hz", "fit_quality"] {
        let (x, y) = (common::num(&a, key), common::num(&c, key));
        assert!((x / y - 1.0).abs() < 1e-6, "{key}: {x} vs {y}");
    }
    assert!((common::num(&c, "invols_m_per_v") / invols - 1.0).abs() < 1e-12);
    assert!(a["sader"].is_null());
    // The saved lever drives tap.
    let toml = std::fs::read_to_string(&lever).unwrap();
    assert!(
        toml.contains("stiffness = ") && toml.contains("quality = "),
        "{toml}"
    );
    let tap = common::tapsim(&["tap", "--config", lever.to_str().unwrap(), "--quiet"]);
    let table = String::from_utf8_lossy(&tap.stdout);
    let k = common::num(&a, "fit_stiffness_n_m");
    assert!(table.contains(&format!("{k:.5} N/m")), "{table}");
}

/// Sader's method beside the thermal fit: `--lever-length/--lever-width` give k from
/// the fitted f₀ and Q and air's hydrodynamic function (the formula's own checks, beam
/// theory and the Bessel functions, are in `instrument::sader`); water's denser,
/// more viscous fluid gives another k for the same resonance.
#[test]
fn sader_stands_beside_the_thermal_calibration() {
    let dir = common::scratch("thermal_sader");
    let psd = dir.join("psd.csv");
    let out = common::tapsim(&[
        "thermal",
        "--quality",
        "30",
        "--duration",
        "0.2s",
        "--quiet",
        "--csv",
        psd.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let run = |fluid: &str| {
        common::json(&[
            "thermal",
            "--psd",
            psd.to_str().unwrap(),
            "--lever-length",
            "125um",
            "--lever-width",
            "30um",
            "--fluid",
            fluid,
            "--json",
        ])
    };
    let air = run("air");
    let s = &air["sader"];
    let re = common::num(s, "reynolds");
    let f = common::num(&air, "fit_resonance_hz");
    let expected_re = 1.18 * 2.0 * std::f64::consts::PI * f * (30e-6f64).powi(2) / (4.0 * 1.86e-5);
    assert!(
        (re / expected_re - 1.0).abs() < 1e-12,
        "{re} vs {expected_re}"
    );
    let k = common::num(s, "stiffness_n_m");
    let k_water = common::num(&run("water")["sader"], "stiffness_n_m");
    assert!(k > 0.0 && k_water > 10.0 * k, "{k} {k_water}");
}

/// Bad spectra and settings: a clear refusal, and no file written (--save-config into a
/// directory is refused before the fit; a failed fit writes nothing).
#[test]
fn bad_spectra_are_refused() {
    let dir = common::scratch("thermal_psd_bad");
    let file = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let good_rows: String = (1..100)
        .map(|i| format!("{},1e-30\n", i as f64 * 100.0))
        .collect();
    let cases = [
        (
            file("nofreq.csv", &format!("x,psd_m2_hz\n{good_rows}")),
            vec![],
            "no frequency column",
        ),
        (
            file("nodens.csv", &format!("freq_hz,psd\n{good_rows}")),
            vec![],
            "no density column",
        ),
        (
            file("volts.csv", &format!("freq_hz,psd_v2_hz\n{good_rows}")),
            vec![],
            "--invols",
        ),
        (
            file("m.csv", &format!("freq_hz,psd_m2_hz\n{good_rows}")),
            vec!["--invols", "50nm"],
            "deflection already",
        ),
        (
            file("nan.csv", "freq_hz,psd_m2_hz\n100,1e-30\n200,NaN\n"),
            vec![],
            "not a number",
        ),
        (
            file("neg.csv", "freq_hz,psd_m2_hz\n100,1e-30\n200,-1e-30\n"),
            vec![],
            "negative",
        ),
        (
            file("down.csv", "freq_hz,psd_m2_hz\n200,1e-30\n100,1e-30\n"),
            vec![],
            "rise",
        ),
        (
            file("few.csv", "freq_hz,psd_m2_hz\n100,1e-30\n200,1e-30\n"),
            vec![],
            "at least 16",
        ),
        (
            file(
                "uneven.csv",
                &format!("freq_hz,psd_m2_hz\n{good_rows}100000,1e-30\n"),
            ),
            vec![],
            "evenly spaced",
        ),
        (
            file("flat.csv", &format!("freq_hz,psd_m2_hz\n{good_rows}")),
            vec![],
            "cannot be fitted",
        ),
    ];
    let saved = dir.join("never.toml");
    for (path, extra, says) in &cases {
        let mut args = vec![
            "thermal",
            "--psd",
            path.as_str(),
            "--save-config",
            saved.to_str().unwrap(),
        ];
        args.extend(extra.iter().copied());
        common::refused(&args, says);
        assert!(
            !saved.exists(),
            "{path}: a failed calibration wrote its config"
        );
    }
    let plain = cases[3].0.as_str();
    // Flags that do not go together: a usage error (exit 2) naming them.
    for (args, says) in [
        (
            &["--psd", plain, "--quality", "30"][..],
            "cannot be used with",
        ),
        (&["--invols", "50nm"], "--psd"),
        (
            &["--psd", plain, "--lever-length", "100um"],
            "--lever-width",
        ),
    ] {
        let mut all = vec!["thermal"];
        all.extend_from_slice(args);
        let out = common::tapsim(&all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{all:?}: {err}");
        assert!(err.contains(says), "{all:?}: {err}");
    }
    let d = dir.join("a_directory");
    std::fs::create_dir_all(&d).unwrap();
    common::refused(
        &[
            "thermal",
            "--duration",
            "0.2s",
            "--save-config",
            d.to_str().unwrap(),
        ],
        "",
    );
    assert!(d.is_dir());
}

// The thermal fit's bias and errors, over many spectra.
use rand::SeedableRng;
use rand_distr::{Distribution, Gamma};
use tapsim::instrument::spectrum::{Calibration, Psd, SpectralWindow, calibrate, sho_psd};

/// A spectrum as a rectangular-window estimate of `m` independent segments draws it:
/// each bin the SHO spectrum (k = 2 N/m, f₀ = 300 kHz, Q = 50) plus `background`,
/// times a Gamma(m, 1/m) variate.
fn draw(seed: u64, m: f64, background: f64) -> Psd {
    let (f0, q, k, t) = (3e5, 50.0, 2.0, 300.0);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let gamma = Gamma::new(m, 1.0 / m).unwrap();
    let df = f0 / q / 16.0;
    let freq_hz: Vec<f64> = (1..4000).map(|i| i as f64 * df).collect();
    let density = freq_hz
        .iter()
        .map(|&f| (sho_psd(f, f0, q, k, t) + background) * gamma.sample(&mut rng))
        .collect();
    Psd {
        freq_hz,
        density,
        segments: m as usize,
        window: SpectralWindow::Rectangular,
    }
}

/// The mean, the spread (standard deviation) and the rms of the reported standard
/// errors of one fitted quantity over `fits`.
fn spread(
    fits: &[Calibration],
    value: impl Fn(&Calibration) -> f64,
    error: impl Fn(&Calibration) -> f64,
) -> (f64, f64, f64) {
    let n = fits.len() as f64;
    let mean = fits.iter().map(&value).sum::<f64>() / n;
    let sd = (fits.iter().map(|c| (value(c) - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let reported = (fits.iter().map(|c| error(c).powi(2)).sum::<f64>() / n).sqrt();
    (mean, sd, reported)
}

/// Over 200 spectra of 16 segments each (25 % scatter a bin), with no background
/// and with one of 14 % of the peak: the fit is unbiased (its mean within three
/// standard errors of the truth, where least squares on P/S − 1 would be 6 % low)
/// and the errors it reports are the spread of its results within 15 %.
#[test]
fn the_fit_is_unbiased_and_its_errors_are_its_scatter() {
    for background in [0.0, 3e-26] {
        let fits: Vec<Calibration> = (0..200)
            .map(|s| calibrate(&draw(s, 16.0, background), 300.0).unwrap())
            .collect();
        let n = fits.len() as f64;
        let checks = [
            (
                "k",
                2.0,
                spread(&fits, |c| c.stiffness_n_m, |c| c.stiffness_sd_n_m),
            ),
            (
                "f0",
                3e5,
                spread(&fits, |c| c.resonance_hz, |c| c.resonance_sd_hz),
            ),
            ("Q", 50.0, spread(&fits, |c| c.quality, |c| c.quality_sd)),
            (
                "B",
                background,
                spread(&fits, |c| c.background_m2_hz, |c| c.background_sd_m2_hz),
            ),
        ];
        for (name, truth, (mean, sd, reported)) in checks {
            assert!(
                (mean - truth).abs() < 3.0 * sd / n.sqrt(),
                "{name}: {mean} vs {truth} ± {sd}"
            );
            assert!(
                (sd / reported - 1.0).abs() < 0.15,
                "{name}: spread {sd}, reported {reported}"
            );
        }
    }
}

/// The thermal record's own Welch estimate (Hann, half-overlapping segments) over
/// 48 seeds: the reported errors of k and Q, widened for Hann's correlated bins,
/// are the spread of the results within 25 % (without the widening they fall
/// short by its 1.39).
#[test]
fn errors_of_a_hann_welch_estimate_are_its_seeds_scatter() {
    let fits: Vec<Calibration> = (0..48)
        .map(|seed| {
            tapsim::instrument::thermal::thermal_spectrum(
                (40.0, 3e5, 30.0),
                300.0,
                (10_000, 64),
                seed,
                |_| {},
            )
            .unwrap()
            .calibration
        })
        .collect();
    for (name, (mean, sd, reported)) in [
        (
            "k",
            spread(&fits, |c| c.stiffness_n_m, |c| c.stiffness_sd_n_m),
        ),
        ("Q", spread(&fits, |c| c.quality, |c| c.quality_sd)),
        (
            "f0",
            spread(&fits, |c| c.resonance_hz, |c| c.resonance_sd_hz),
        ),
    ] {
        eprintln!("{name}: mean {mean}, spread {sd}, reported {reported}");
        assert!(
            (sd / reported - 1.0).abs() < 0.25,
            "{name}: spread {sd}, reported {reported}"
        );
    }
}

/// The noisy march at the instrument's tolerance (rtol 2e-7, what `scan` marches at):
/// 200 tapping periods under one force sequence end where the same march at rtol 1e-11
/// ends, and their integrals (the lock-in's projections, the losses, the mean force and
/// the virial) agree, each within 1e-5 of its size (measured: 8e-7 at most, 7e-6 for
/// the mean force). The carried integrals in the error norm are what holds the contact
/// to that: with the motion alone in the norm the contact took 18 steps a period
/// instead of 33, but the march ended 1.7e-4 from the reference and its mean force
/// 1.4e-3 — at equal steps (rtol 2e-8 then) six times less accurate.
#[test]
fn the_noisy_march_is_as_accurate_as_its_tolerance_says() {
    let (p, start, d) = settled_at_room_temperature(None, 200);
    let sim = p.simulation();
    let run = |rtol: f64| {
        let at = Simulation {
            tol: Tolerances {
                rtol,
                atol: 1e-2 * rtol,
                ..sim.tol
            },
            ..sim
        };
        let mut phase = start.clone();
        let mut force = ThermalForce::new(d, STEPS_PER_PERIOD, 5, 0).unwrap();
        let (total, _) = force
            .march(&at, &mut phase, 200, &mut tapsim::dynamics::numeric::Ignore)
            .unwrap();
        (phase, total.unwrap())
    };
    let (end, t) = run(tapsim::instrument::MARCH_RTOL);
    let (fine_end, fine) = run(1e-11);
    assert_eq!(t.jumps_in, 200, "the tip taps every period");
    assert_eq!(t.jumps_in, fine.jumps_in);
    let amplitude = t.sc.hypot(t.ss);
    for (what, a, b, size) in [
        ("x", end.x, fine_end.x, 1.0),
        ("x'", end.v, fine_end.v, 1.0),
        ("∫x cos", t.sc, fine.sc, amplitude),
        ("∫x sin", t.ss, fine.ss, amplitude),
        ("E_ts", t.e_ts, fine.e_ts, t.e_ts),
        ("E_damp", t.e_damp, fine.e_damp, t.e_damp),
        ("∫f_ts", t.f_int, fine.f_int, t.f_int.abs()),
        ("virial", t.virial_int, fine.virial_int, t.virial_int.abs()),
    ] {
        eprintln!("{what}: {:.2e} of its size", (a - b).abs() / size);
        assert!((a - b).abs() < 1e-5 * size, "{what}: {a} against {b}");
    }
}
