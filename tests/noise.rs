//! Thermal noise through the lock-in (issue 28): the linear theory against the
//! oscillator's thermal spectrum for a free cantilever (narrow- and wide-band limits),
//! and against the Monte Carlo of the marcher watched by the lock-in on tapping orbits.

use crate::common;

use tapsim::dynamics::grazing::{BOLTZMANN_J_K, ROOM_TEMPERATURE_K};
use tapsim::dynamics::setup::{Numerics, Prepared, default_setup};
use tapsim::instrument::MARCH_RTOL;
use tapsim::instrument::lockin::LockIn;
use tapsim::instrument::noise::{
    PARTS_PER_PERIOD, linear_noise, monte_carlo_noise, time_constant_for_enbw,
};
use tapsim::instrument::thermal::{STEPS_PER_PERIOD, intensity_hat};
use tapsim::law::LawKind;

/// A setup on the defaults' cantilever, marched 3 000 periods onto its orbit.
fn settled(setup: tapsim::TapSetup) -> (Prepared, tapsim::dynamics::march::Phase) {
    let numerics = Numerics {
        rtol: MARCH_RTOL,
        atol: 1e-2 * MARCH_RTOL,
        ..Numerics::default()
    };
    let p = Prepared::new(&setup, &numerics).unwrap();
    let sim = p.simulation();
    let mut phase = sim.free_steady_start();
    sim.march(&mut phase, 3000, &mut tapsim::dynamics::numeric::Ignore)
        .unwrap();
    (p, phase)
}

/// The phase noise a lock-in of order n and time constant τ reads off a cantilever of
/// thermal rms √(k_BT/k) oscillating at resonance with amplitude A, from its quadratures'
/// Lorentzian spectrum (an Ornstein–Uhlenbeck process of rate Γ = ω₀/2Q, Q ≫ 1):
/// σ² = (1/A²)∫₀^∞ 4⟨b²⟩Γ/(Γ² + ω²)·(1 + ω²τ²)⁻ⁿ df = (2⟨b²⟩/πA²)∫₀^{π/2}
/// (1 + (Γτ tan θ)²)⁻ⁿ dθ, by Simpson's rule.
fn lorentzian_sigma_phase(rms_m: f64, amplitude_m: f64, gamma: f64, tau: f64, n: i32) -> f64 {
    let m = 20_000;
    let h = std::f64::consts::FRAC_PI_2 / m as f64;
    let f = |t: f64| (1.0 + (gamma * tau * t.tan()).powi(2)).powi(-n);
    let mut sum = f(0.0);
    for i in 1..m {
        sum += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    // f(π/2) = 0.
    let integral = sum * h / 3.0;
    (2.0 * rms_m * rms_m / std::f64::consts::PI * integral).sqrt() / amplitude_m
}

/// A free cantilever driven at resonance (A = 18.83 nm, the defaults' tapping
/// amplitude): the linear theory's phase noise is the Lorentzian spectrum's at every
/// bandwidth (within 2 %), its amplitude noise A times it, and it reaches both limits:
/// √(4k_BTQ·ENBW/(πk f₀A²)) = 0.0128° at 100 Hz within 5 % (narrow band), and
/// √(k_BT/k)/A within 5 % at 10 kHz (wide band).
#[test]
fn the_linear_theory_reads_a_free_cantilever_as_its_thermal_spectrum_does() {
    let mut setup = default_setup();
    setup.law.kind = LawKind::None;
    setup.cantilever.free_amplitude_m = 18.83e-9;
    let (p, phase) = settled(setup);
    let sim = p.simulation();
    let c = p.setup.cantilever;
    let a0 = c.free_amplitude_m;
    let d = intensity_hat(ROOM_TEMPERATURE_K, c.stiffness_n_m, c.quality, a0);
    let kt_over_k = BOLTZMANN_J_K * ROOM_TEMPERATURE_K / c.stiffness_n_m;
    let gamma = std::f64::consts::PI * c.resonance_hz / c.quality;
    let omega0 = 2.0 * std::f64::consts::PI * c.resonance_hz;
    for (order, enbw) in [
        (4, 10.0),
        (4, 100.0),
        (1, 100.0),
        (4, 1000.0),
        (4, 10_000.0),
    ] {
        let tau_s = time_constant_for_enbw(order, enbw);
        let noise =
            linear_noise(&sim, &phase, d, (order, tau_s * omega0), PARTS_PER_PERIOD).unwrap();
        let amplitude_m = noise.amplitude_hat * a0;
        let expected =
            lorentzian_sigma_phase(kt_over_k.sqrt(), amplitude_m, gamma, tau_s, order as i32);
        eprintln!(
            "order {order}, ENBW {enbw} Hz: σ_φ {:.5}° (Lorentzian {:.5}°), σ_A {:.4} pm",
            noise.sigma_phase_rad.to_degrees(),
            expected.to_degrees(),
            noise.sigma_amplitude_hat * a0 * 1e12
        );
        assert!((amplitude_m / 18.83e-9 - 1.0).abs() < 1e-6);
        assert!(
            (noise.sigma_phase_rad / expected - 1.0).abs() < 0.02,
            "order {order}, {enbw} Hz"
        );
        let sigma_a_m = noise.sigma_amplitude_hat * a0;
        assert!((sigma_a_m / (noise.sigma_phase_rad * amplitude_m) - 1.0).abs() < 0.02);
        if (order, enbw) == (4, 100.0) {
            let narrow = (4.0 * kt_over_k * c.quality * enbw
                / (std::f64::consts::PI * c.resonance_hz * amplitude_m * amplitude_m))
                .sqrt();
            assert_eq!(format!("{:.4}", narrow.to_degrees()), "0.0128");
            assert!((noise.sigma_phase_rad / narrow - 1.0).abs() < 0.05);
        }
        if enbw == 10_000.0 {
            let wide = kt_over_k.sqrt() / amplitude_m;
            assert!((noise.sigma_phase_rad / wide - 1.0).abs() < 0.05);
        }
    }
}

/// On two tapping period-1 orbits (the hybrid defaults at z_c = 16 nm, φ = 75.7°; a
/// stiffer polymer, E = 1 GPa, Δγ = 0.08 J/m², at 14 nm, φ = 53.0°), at 300 K, the
/// linear theory's σ_A and σ_φ equal the Monte Carlo's — the marcher under the thermal
/// force watched by the lock-in, 400 windows on four streams, each window farther from
/// the last than the filter and the orbit remember — within 10 %, at ENBW 1 and 3 kHz
/// (fourth order). Its Φ sampled at 256 parts of the period is converged (512 parts:
/// within 1e-3).
#[test]
#[ignore = "slow (400 thermal windows on four orbits, about 27 s in release): run with cargo test --release -- --ignored noise::"]
fn the_linear_theory_matches_the_monte_carlo_on_tapping_orbits() {
    let mut stiff = default_setup();
    stiff.contact.modulus_pa = tapsim::params::composite_modulus(169e9, 0.28, 1e9, 0.4).unwrap();
    stiff.contact.work_of_adhesion_j_m2 = 0.08;
    stiff.separation_m = 14e-9;
    for (name, setup) in [("defaults", default_setup()), ("stiff polymer", stiff)] {
        let (p, phase) = settled(setup);
        let sim = p.simulation();
        let c = p.setup.cantilever;
        let a0 = c.free_amplitude_m;
        let d = intensity_hat(ROOM_TEMPERATURE_K, c.stiffness_n_m, c.quality, a0);
        let omega0 = 2.0 * std::f64::consts::PI * c.resonance_hz;
        for (enbw, spacing) in [(1000.0, 600), (3000.0, 400)] {
            let tau_hat = time_constant_for_enbw(4, enbw) * omega0;
            let linear = linear_noise(&sim, &phase, d, (4, tau_hat), PARTS_PER_PERIOD).unwrap();
            let finer = linear_noise(&sim, &phase, d, (4, tau_hat), 2 * PARTS_PER_PERIOD).unwrap();
            assert!((finer.sigma_phase_rad / linear.sigma_phase_rad - 1.0).abs() < 1e-3);
            assert!((finer.sigma_amplitude_hat / linear.sigma_amplitude_hat - 1.0).abs() < 1e-3);
            let lockin = LockIn::new(4, tau_hat, sim.osc.omega).unwrap();
            let mc = monte_carlo_noise(
                &sim,
                &phase,
                (d, STEPS_PER_PERIOD),
                lockin,
                (spacing, 400, spacing),
                (17, 4),
            )
            .unwrap();
            eprintln!(
                "{name}, ENBW {enbw} Hz: φ {:.3}°; σ_φ linear {:.5}° MC {:.5}°; σ_A linear \
                 {:.4} pm MC {:.4} pm ({} windows)",
                linear.phase_rad.to_degrees(),
                linear.sigma_phase_rad.to_degrees(),
                mc.sigma_phase_rad.to_degrees(),
                linear.sigma_amplitude_hat * a0 * 1e12,
                mc.sigma_amplitude_hat * a0 * 1e12,
                mc.windows
            );
            assert_eq!(mc.windows, 400);
            assert!((mc.sigma_phase_rad / linear.sigma_phase_rad - 1.0).abs() < 0.10);
            assert!((mc.sigma_amplitude_hat / linear.sigma_amplitude_hat - 1.0).abs() < 0.10);
            // The mean reading is the orbit's.
            assert!((mc.phase_rad - linear.phase_rad).abs() < 3.0 * linear.sigma_phase_rad);
        }
    }
}

/// `tap --temperature` prints the linear theory's noise for the state it reports (the
/// same numbers as the library's), 0 at 0 K, nothing without it, and refuses what it
/// cannot read (a bandwidth not far below the drive, a negative temperature).
#[test]
fn tap_reports_the_thermal_noise_of_its_orbit() {
    let json = |args: &[&str]| common::json_of(&["tap", "--json"], args);
    let v = json(&["--temperature", "300K", "--enbw", "1kHz"]);
    let noise = &v["thermal_noise"];
    let (p, phase) = {
        let p = Prepared::new(&default_setup(), &Numerics::default()).unwrap();
        let sim = p.simulation();
        let mut phase = sim.free_steady_start();
        sim.steady_state(&mut phase, &p.steady).unwrap();
        (p, phase)
    };
    let c = p.setup.cantilever;
    let tau_hat = time_constant_for_enbw(4, 1000.0) * 2.0 * std::f64::consts::PI * c.resonance_hz;
    let d = intensity_hat(
        ROOM_TEMPERATURE_K,
        c.stiffness_n_m,
        c.quality,
        c.free_amplitude_m,
    );
    let lib = linear_noise(&p.simulation(), &phase, d, (4, tau_hat), PARTS_PER_PERIOD).unwrap();
    let sigma_phi = noise["sigma_phase_deg"].as_f64().unwrap();
    assert!((sigma_phi / lib.sigma_phase_rad.to_degrees() - 1.0).abs() < 1e-9);
    assert_eq!(noise["lockin_order"].as_u64(), Some(4));
    // The guide's numbers: the defaults at 1 kHz and at 100 Hz.
    let sigma_a_pm = noise["sigma_amplitude_m"].as_f64().unwrap() * 1e12;
    assert_eq!(format!("{sigma_phi:.4} {sigma_a_pm:.2}"), "0.1413 4.49");
    let narrow = &json(&["--temperature", "300K", "--enbw", "100Hz"])["thermal_noise"];
    assert_eq!(
        format!(
            "{:.4} {:.2}",
            narrow["sigma_phase_deg"].as_f64().unwrap(),
            narrow["sigma_amplitude_m"].as_f64().unwrap() * 1e12
        ),
        "0.0416 0.71"
    );
    // √T: a quarter of the temperature, half the noise.
    let cold = json(&["--temperature", "75K"]);
    let ratio = cold["thermal_noise"]["sigma_phase_deg"].as_f64().unwrap() / sigma_phi;
    assert!((ratio - 0.5).abs() < 1e-9, "{ratio}");
    let zero = json(&["--temperature", "0K"]);
    assert_eq!(zero["thermal_noise"]["sigma_phase_deg"].as_f64(), Some(0.0));
    assert_eq!(zero["phase_deg"], v["phase_deg"]);
    assert!(json(&[]).get("thermal_noise").is_none());
    for (args, says) in [
        (
            &["--temperature", "300K", "--enbw", "20kHz"][..],
            "a thirtieth of the drive",
        ),
        (&["--temperature", "-3K"], "not negative"),
    ] {
        let mut all = vec!["tap"];
        all.extend_from_slice(args);
        common::refused(&all, says);
    }
}

/// `contrast --temperature`: each phase on a stable period-1 orbit carries its thermal
/// noise, each row |Δφ|/√(σ_first² + σ_last²); a phase from a long mode lock none. The
/// The guide's answer: on the defaults (polymers A and B at A/A₀ = 0.8, repulsive branch)
/// the hybrid's contrast is 99, 24 and 13 times its noise at ENBW 100 Hz, 1 kHz and
/// 10 kHz, and JKR's Δφ lies 190, 46 and 25 σ_Δ from the hybrid's.
#[test]
fn contrast_weighs_each_phase_difference_against_its_thermal_noise() {
    let mut answers = Vec::new();
    for enbw in ["100Hz", "1kHz", "10kHz"] {
        let rows = common::json(&[
            "contrast",
            "--setpoints",
            "0.8",
            "--laws",
            "jkr,hybrid",
            "--temperature",
            "300K",
            "--enbw",
            enbw,
            "--json",
            "--quiet",
        ]);
        let row = |law: &str, branch: &str| {
            common::rows(&rows)
                .iter()
                .find(|r| r["law"] == law && r["branch"] == branch)
                .unwrap()
                .clone()
        };
        for r in &common::rows(&rows) {
            let sigma: Vec<Option<f64>> = r["sigma_phase_deg"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64())
                .collect();
            let regimes: Vec<Option<&str>> = r["regime"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_str())
                .collect();
            for (s, g) in sigma.iter().zip(&regimes) {
                // A σ exactly where the phase comes from a period-1 orbit.
                assert_eq!(s.is_some(), *g == Some("period-1"), "{r}");
            }
            match (r["delta_phase_deg"].as_f64(), sigma[0], sigma[1]) {
                (Some(d), Some(a), Some(b)) => {
                    let c = r["contrast_to_noise"].as_f64().unwrap();
                    assert!((c - d.abs() / a.hypot(b)).abs() < 1e-9 * c);
                }
                _ => assert!(r["contrast_to_noise"].is_null()),
            }
        }
        let hybrid = row("hybrid", "repulsive");
        let jkr = row("jkr", "repulsive");
        let sigma = |r: &serde_json::Value, i: usize| r["sigma_phase_deg"][i].as_f64().unwrap();
        let gap = (jkr["delta_phase_deg"].as_f64().unwrap()
            - hybrid["delta_phase_deg"].as_f64().unwrap())
        .abs();
        answers.push(format!(
            "{:.0} {:.0}",
            hybrid["contrast_to_noise"].as_f64().unwrap(),
            gap / sigma(&hybrid, 0).hypot(sigma(&hybrid, 1))
        ));
        // The attractive JKR state of A is a long mode lock: no σ.
        assert!(row("jkr", "attractive")["sigma_phase_deg"][0].is_null());
    }
    assert_eq!(answers, ["99 190", "24 46", "13 25"]);
}

/// `tap --setpoint --temperature` reads the noise of every state it lists: the repulsive
/// state at A/A₀ = 0.8 has the σ `tap --separation` reads at its z_c (the free
/// oscillation settles on the same orbit there).
#[test]
fn tap_at_a_setpoint_reads_each_states_noise() {
    let json = |args: &[&str]| common::json_of(&["tap", "--json", "--temperature", "300K"], args);
    let listed = json(&["--setpoint", "0.8"]);
    let states = listed["states"].as_array().unwrap();
    assert_eq!(states.len(), 2);
    let repulsive = states.iter().find(|s| s["branch"] == "repulsive").unwrap();
    let z = format!("{:e}", repulsive["separation_m"].as_f64().unwrap());
    let direct = json(&["--separation", &z]);
    assert!(
        (direct["phase_deg"].as_f64().unwrap() - repulsive["phase_deg"].as_f64().unwrap()).abs()
            < 1e-4
    );
    let sigma = |v: &serde_json::Value| v["thermal_noise"]["sigma_phase_deg"].as_f64().unwrap();
    assert!(
        (sigma(&direct) / sigma(repulsive) - 1.0).abs() < 1e-4,
        "{} vs {}",
        sigma(&direct),
        sigma(repulsive)
    );
    assert!(states.iter().all(|s| sigma(s) > 0.0));
}

/// A scan under the thermal force (`scan --temperature`): at 0 K it is the noise-free
/// scan byte for byte; at 300 K each line draws its own stream (the same image on one
/// thread and on two), and over the blend each material's settled pixels scatter as the
/// linear theory predicts for a reading averaged over a pixel (ENBW = 1/(2·t_pixel),
/// 80 Hz here), within the sampling error of ~15 pixels (ratio 0.6–1.6).
#[test]
fn a_scan_under_the_thermal_force_scatters_as_the_linear_theory_says() {
    let scan = |extra: &[&str]| {
        let mut all = vec!["scan", "--no-retrace", "--quiet"];
        all.extend_from_slice(extra);
        let out = common::tapsim(&all);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let small = ["--pixels", "4", "--line-rate", "40", "--json"];
    assert_eq!(
        scan(&small),
        scan(&[&small[..], &["--temperature", "0K"]].concat())
    );
    let image = [&small[..], &["--lines", "2", "--temperature", "300K"]].concat();
    assert_eq!(
        scan(&[&image[..], &["--threads", "1"]].concat()),
        scan(&[&image[..], &["--threads", "2"]].concat())
    );
    assert_ne!(
        scan(&small),
        scan(&[&small[..], &["--temperature", "300K"]].concat())
    );
    // The summary of a 32-pixel line at 5 lines/s (1 875 periods a pixel).
    let text = scan(&[
        "--pixels",
        "32",
        "--line-rate",
        "5",
        "--temperature",
        "300K",
    ]);
    let sigma_of = |name: &str| -> f64 {
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("{name}: φ =")))
            .unwrap_or_else(|| panic!("{text}"));
        let sd = line.split('±').nth(1).unwrap().trim();
        sd[..sd.find('°').unwrap()].parse().unwrap()
    };
    for (name, modulus, adhesion) in [("A", "0.5GPa", "0.1"), ("B", "1GPa", "0.08")] {
        let theory = common::json(&[
            "tap",
            "--setpoint",
            "0.8",
            "--branch",
            "attractive",
            "--sample-modulus",
            modulus,
            "--work-of-adhesion",
            adhesion,
            "--temperature",
            "300K",
            "--enbw",
            "80Hz",
            "--json",
        ]);
        let predicted = theory["states"][0]["thermal_noise"]["sigma_phase_deg"]
            .as_f64()
            .unwrap();
        let seen = sigma_of(name);
        eprintln!("{name}: pixel scatter {seen:.4}°, linear theory at 80 Hz {predicted:.4}°");
        assert!(seen / predicted > 0.6 && seen / predicted < 1.6);
        // The guide's numbers.
        let expected = if name == "A" {
            ("0.0151", "0.0183")
        } else {
            ("0.0145", "0.0160")
        };
        assert_eq!(
            (
                format!("{seen:.4}").as_str(),
                format!("{predicted:.4}").as_str()
            ),
            expected
        );
    }
}

/// `map --setpoint --temperature`: every cell that holds the setpoint carries its phase
/// noise, the one `tap --setpoint` reads for that material; the heat maps are drawn. (At
/// a rest separation the temperature averages grazing cells instead: `tests/thermal.rs`.)
#[test]
fn a_map_at_a_setpoint_reads_each_cells_noise() {
    let dir = common::scratch("map_noise");
    let png = dir.join("map.png");
    let v = common::json(&[
        "map",
        "--setpoint",
        "0.8",
        "--steps",
        "3",
        "--temperature",
        "300K",
        "--json",
        "--quiet",
        "--plot",
        png.to_str().unwrap(),
    ]);
    let field = |key: &str| common::cells(&v["grid"][key]);
    let (phase, sigma_of, works, moduli) = (
        field("phase_deg"),
        field("sigma_phase_deg"),
        field("work_of_adhesion_j_m2"),
        field("modulus_pa"),
    );
    let held: Vec<usize> = (0..phase.len()).filter(|&k| phase[k].is_f64()).collect();
    assert!(held.len() >= 3);
    for k in 0..phase.len() {
        assert_eq!(phase[k].is_f64(), sigma_of[k].is_f64(), "cell {k}");
    }
    let k = held[0];
    let w = format!("{:e}", works[k].as_f64().unwrap());
    let e = format!("{:e}", moduli[k].as_f64().unwrap());
    let tap = common::json(&[
        "tap",
        "--setpoint",
        "0.8",
        "--branch",
        "repulsive",
        "--work-of-adhesion",
        &w,
        "--modulus",
        &e,
        "--temperature",
        "300K",
        "--json",
    ]);
    let sigma = tap["states"][0]["thermal_noise"]["sigma_phase_deg"]
        .as_f64()
        .unwrap();
    assert!((sigma_of[k].as_f64().unwrap() / sigma - 1.0).abs() < 1e-9);
    assert!(std::fs::metadata(&png).unwrap().len() > 10_000);
}
