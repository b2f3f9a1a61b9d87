//! Steady states that are not period-1: Newton's method on the period map with its exact
//! derivative, the classification of the motion, and what is reported for it.

use tapsim::dynamics::observables::{Observe, Starts, TapObservables, tap};
use tapsim::dynamics::setup::{Cantilever, Numerics, TapSetup, default_setup};
use tapsim::law::LawKind;
use tapsim::params::{Contact, composite_modulus};

/// The dForce 2.0 Hertz example: k = 0.9 N/m, f₀ = 100 kHz, A₀ = 15 nm, R = 5 nm,
/// E_s = 100 MPa, rest gap 9 nm, driven at resonance.
fn dforce_hertz(quality: f64) -> TapSetup {
    TapSetup {
        contact: Contact::new(
            5e-9,
            composite_modulus(169e9, 0.28, 100e6, 0.3).unwrap(),
            0.1,
            0.3e-9,
        )
        .unwrap(),
        cantilever: Cantilever {
            stiffness_n_m: 0.9,
            resonance_hz: 100e3,
            quality,
            free_amplitude_m: 15e-9,
            drive_frequency_hz: 100e3,
        },
        separation_m: 9e-9,
        law: LawKind::Hertz.into(),
    }
}

#[test]
fn high_q_orbits_settle_in_a_few_dozen_periods_and_match_the_time_marched_ones() {
    for quality in [1e3, 1e4, 1e5] {
        let setup = dforce_hertz(quality);
        let shot = tap(&setup, &Numerics::default(), Observe::default())
            .unwrap()
            .observables;
        // Brute force: integrate until the state at the drive phase lies within 1e-8 of
        // the orbit (~Q ln(1e8)/π periods).
        let marched = tap(
            &setup,
            &Numerics {
                shooting: false,
                tolerance: 1e-8,
                max_cycles: 2_000_000,
                max_steps: u64::MAX,
                ..Numerics::default()
            },
            Observe::default(),
        )
        .unwrap()
        .observables;
        println!(
            "Q {quality:e}: {} periods shooting, {} marching; A/A0 {:.10} vs {:.10}, \
             phase {:.7} vs {:.7}",
            shot.cycles,
            marched.cycles,
            shot.amplitude_ratio,
            marched.amplitude_ratio,
            shot.phase_deg,
            marched.phase_deg
        );
        assert!(shot.converged && marched.converged);
        assert_eq!(shot.regime, "period-1");
        assert_eq!(marched.regime, "period-1");
        assert!(shot.cycles <= 60, "Q {quality:e}: {} periods", shot.cycles);
        assert!(
            marched.cycles as f64 > quality,
            "the reference must really march"
        );
        let rel = (shot.amplitude_ratio / marched.amplitude_ratio - 1.0).abs();
        assert!(rel < 1e-6, "Q {quality:e}: amplitude off by {rel:e}");
        let dphi = (shot.phase_deg - marched.phase_deg).abs();
        assert!(dphi < 1e-4, "Q {quality:e}: phase off by {dphi:e} deg");
        // A stable orbit whose multipliers approach the unit circle as Q grows
        // (the free oscillator's are e^{-π/Q} in modulus).
        assert_eq!(shot.stable, Some(true));
        let largest = shot
            .floquet_multipliers
            .iter()
            .map(|m| m[0].hypot(m[1]))
            .fold(0.0, f64::max);
        assert!(largest < 1.0 && largest > (-10.0 * std::f64::consts::PI / quality).exp());
    }
}

/// JKR on the defaults with `numerics`.
/// JKR on the defaults driven at 305 kHz (f/f₀ = 1.017), rest separation 20 nm: the tip
/// touches once every 29 periods, but the state never repeats (after 12 000 periods it
/// has not returned within 10⁻³ after any n ≤ 2980): quasi-periodic motion, irregular.
fn quasi_periodic_with(numerics: Numerics) -> TapObservables {
    let mut setup = TapSetup {
        law: LawKind::Jkr.into(),
        separation_m: 20e-9,
        ..default_setup()
    };
    setup.cantilever.drive_frequency_hz = 305e3;
    tap(&setup, &numerics, Observe::default())
        .unwrap()
        .observables
}

fn quasi_periodic(average_tolerance: f64) -> TapObservables {
    quasi_periodic_with(Numerics {
        average_tolerance,
        ..Numerics::default()
    })
}

#[test]
fn jkr_on_the_defaults_locks_onto_a_long_period_that_grazes() {
    // The tip touches in about three periods of four; the turning point is pinned at the
    // jump-in (each touch loses the whole loop, more than the drive restores), so the
    // motion locks onto a long period whose stability rests on a grazing contact.
    let setup = TapSetup {
        law: LawKind::Jkr.into(),
        ..default_setup()
    };
    let observe = Observe {
        starts: Starts::WhereGrazing,
        ..Observe::default()
    };
    let run = tap(&setup, &Numerics::default(), observe).unwrap();
    let o = &run.observables;
    println!(
        "{}: A/A0 {:.6}, phase {:.4}, E_ts {:.3} eV, {} touches per period, margin {:?}",
        o.regime, o.amplitude_ratio, o.phase_deg, o.e_ts_ev, o.jumps_in, o.grazing_margin_m
    );
    let n = o.period.expect("a long period");
    assert!(n > 8, "{n}");
    assert_eq!(o.periods_averaged as usize, n, "one pass of the orbit");
    assert!(o.grazing && o.stable.is_none());
    assert!(o.grazing_margin_m.unwrap() < run.thermal_rms_m);
    // k touches in n periods, each losing the whole JKR loop.
    let touches = o.jumps_in * n as f64;
    assert!((touches - touches.round()).abs() < 1e-9 && o.jumps_in > 0.5 && o.jumps_in < 1.0);
    assert!((o.e_ts_j / (o.jumps_in * o.loop_area_j) - 1.0).abs() < 1e-6);
    assert!(o.energy_balance_rel < 1e-6);
    // Grazing: other starts reach other locks; all are listed, the free start's first.
    let list = run
        .attractors
        .as_ref()
        .expect("a grazing state lists its attractors");
    assert!(list.len() >= 2 && run.well_defined == Some(false));
    assert_eq!(list[0].regime, o.regime);
    assert_eq!(list.iter().map(|a| a.count).sum::<usize>(), 6);
    for a in list {
        // Every lock touches about as often and so loses about as much.
        assert!((a.touch_fraction - o.jumps_in).abs() < 0.01, "{a:?}");
        assert!((a.e_ts_j / o.e_ts_j - 1.0).abs() < 0.01, "{a:?}");
    }
}

#[test]
fn quasi_periodic_motion_is_named_and_averaged_over_a_window() {
    let o = quasi_periodic(1e-3);
    println!(
        "{}: {} periods averaged, A/A0 {:.6} ± {:?} m, phase {:.4} ± {:?} deg, \
         from energy {:.4}, E_ts {:.3} eV ({} touches per period), balance {:.1e}",
        o.regime,
        o.periods_averaged,
        o.amplitude_ratio,
        o.amplitude_std_err_m,
        o.phase_deg,
        o.phase_std_err_deg,
        o.phase_from_energy_deg,
        o.e_ts_ev,
        o.jumps_in,
        o.energy_balance_rel
    );
    assert!(o.converged);
    // One touch in 29 periods, the state never repeating: no period at all.
    assert_eq!(o.regime, "irregular");
    assert_eq!(o.period, None);
    assert_eq!(o.stable, None);
    assert!(o.floquet_multipliers.is_empty());
    assert!(o.jumps_in > 0.0 && o.jumps_in < 0.1);
    // Averaged over at least 8 batches of the oscillator's memory, QΩ/π periods (8 when
    // their standard errors are a quarter of the tolerance, else 16 or more).
    assert!(o.periods_averaged as f64 >= 8.0 * 400.0 * 1.017 / std::f64::consts::PI);
    // Not every period touches, so less than the full loop per period.
    assert!(o.e_ts_j > 0.0 && o.e_ts_j < o.loop_area_j);
    // Each touch dissipates the whole JKR loop; the window's ends may cut one touch
    // (here they fall in contact: the drive's phase differs from the defaults').
    let periods = f64::from(o.periods_averaged);
    let loops = o.e_ts_j * periods / o.loop_area_j;
    assert!(
        (loops - o.jumps_in * periods).abs() <= 1.0 + 1e-6,
        "{loops}"
    );
    assert!(o.energy_balance_rel < 1e-6);
    let se = o.phase_std_err_deg.unwrap();
    assert!(se > 0.0 && se < 0.057, "{se}");
    // The energy relation over the same window leaves out only the damping of the higher
    // harmonics; with it put back, it is the lock-in phase within the statistical error.
    let cant = Cantilever {
        drive_frequency_hz: 305e3,
        ..default_setup().cantilever
    };
    let (k, q, w) = (cant.stiffness_n_m, cant.quality, cant.omega_ratio());
    let a = o.amplitude_m;
    let f0 = k * cant.free_amplitude_m * cant.drive_over_k_a0();
    let damping_model = std::f64::consts::PI * k * w * a * a / q;
    let harmonics = o.e_damp_j - damping_model;
    let sin_energy =
        o.phase_from_energy_deg.to_radians().sin() + harmonics / (std::f64::consts::PI * f0 * a);
    let with_harmonics = 180.0 - sin_energy.asin().to_degrees();
    assert!(
        o.phase_deg > 90.0,
        "attractive: the quadrant from the virial"
    );
    assert!(
        (with_harmonics - o.phase_deg).abs() < 3.0 * se,
        "{with_harmonics} vs {} ± {se}",
        o.phase_deg
    );
    assert!((o.phase_from_energy_deg - o.phase_deg).abs() < 0.05);
}

/// A, φ and E_ts of two runs of the same irregular motion agree within three combined
/// standard errors.
fn assert_agree(a: &TapObservables, b: &TapObservables) {
    let agree = |x: f64, y: f64, sx: Option<f64>, sy: Option<f64>, what: &str| {
        let combined = sx.unwrap().hypot(sy.unwrap());
        println!("{what}: {x} vs {y}, combined error {combined:e}");
        assert!(
            (x - y).abs() <= 3.0 * combined,
            "{what}: {x} vs {y} ± {combined}"
        );
    };
    agree(
        a.amplitude_m,
        b.amplitude_m,
        a.amplitude_std_err_m,
        b.amplitude_std_err_m,
        "A",
    );
    agree(
        a.phase_deg,
        b.phase_deg,
        a.phase_std_err_deg,
        b.phase_std_err_deg,
        "phase",
    );
    agree(
        a.e_ts_j,
        b.e_ts_j,
        a.e_ts_std_err_j,
        b.e_ts_std_err_j,
        "E_ts",
    );
}

#[test]
fn two_windows_of_irregular_motion_agree_within_their_errors() {
    let (a, b) = (quasi_periodic(1e-3), quasi_periodic(1e-4));
    assert!(a.converged && a.regime == "irregular" && b.regime == "irregular");
    assert!(
        b.periods_averaged > a.periods_averaged,
        "{} vs {}",
        a.periods_averaged,
        b.periods_averaged
    );
    assert_agree(&a, &b);
}

#[test]
fn irregular_averages_marched_loosely_agree_with_exact_marching() {
    // With shooting (the default) irregular motion is marched at 1e-5 of the averages'
    // tolerance (rtol 1e-8); without, at the integrator's own (1e-9).
    let loose = quasi_periodic(1e-3);
    let exact = quasi_periodic_with(Numerics {
        shooting: false,
        ..Numerics::default()
    });
    assert!(loose.converged && exact.converged);
    assert_eq!(
        (loose.regime.as_str(), exact.regime.as_str()),
        ("irregular", "irregular")
    );
    assert_agree(&loose, &exact);
}

#[test]
fn no_value_is_one_period_of_motion_that_is_not_period_one() {
    // A soft cantilever near contact: period-n orbits and irregular motion side by side.
    let mut seen = std::collections::BTreeSet::new();
    for (law, z_nm) in [
        (LawKind::Jkr, 19.1),
        (LawKind::Jkr, 18.4),
        (LawKind::Dmt, 17.7),
        (LawKind::Hybrid, 14.0),
    ] {
        let mut setup = default_setup();
        setup.law = law.into();
        setup.separation_m = z_nm * 1e-9;
        setup.cantilever.stiffness_n_m = 1.0;
        setup.cantilever.quality = 5.0;
        let o = tap(&setup, &Numerics::default(), Observe::default())
            .unwrap()
            .observables;
        println!("{law} {z_nm} nm: {} over {}", o.regime, o.periods_averaged);
        match o.period {
            Some(n) => {
                assert_eq!(o.regime, format!("period-{n}"));
                assert_eq!(o.periods_averaged as usize, n, "one pass of the orbit");
                assert!(o.stable == Some(true) && o.floquet_multipliers.len() == 2);
            }
            None => assert!(o.periods_averaged >= 16),
        }
        seen.insert(o.regime.clone());
    }
    assert!(seen.len() >= 3, "{seen:?}");
}

#[test]
fn the_period_map_derivative_matches_finite_differences_across_switches() {
    use tapsim::dynamics::numeric::Ignore;
    use tapsim::dynamics::setup::Prepared;
    // In contact for part of the period, with the force jumping at both switches
    // (hybrid, jkr), continuous (dmt, hertz), or tabulated with an attractive approach.
    // And with a viscous sample: a force that depends on the velocity too.
    let viscous = |kind: LawKind| tapsim::law::LawSpec {
        viscosity_pa_s: Some(20.0),
        ..kind.into()
    };
    for (law, z_nm) in [
        (LawKind::Hybrid.into(), 16.0),
        (LawKind::Jkr.into(), 12.0),
        (LawKind::HybridAttractive.into(), 15.0),
        (LawKind::Dmt.into(), 14.0),
        (LawKind::Hertz.into(), 14.0),
        (viscous(LawKind::Hertz), 14.0),
        (viscous(LawKind::Hybrid), 14.0),
    ] {
        let setup = TapSetup {
            law,
            separation_m: z_nm * 1e-9,
            ..default_setup()
        };
        let numerics = Numerics {
            rtol: 1e-12,
            ..Numerics::default()
        };
        let p = Prepared::new(&setup, &numerics).unwrap();
        let sim = p.simulation();
        // A state on the settled motion, so the period touches the sample.
        let mut start = sim.free_steady_start();
        sim.steady_state(&mut start, &p.steady).unwrap();
        let (c, d) = sim.cycle_with_derivative(&mut start.clone()).unwrap();
        assert!(c.jumps_in >= 1, "{law}: the period must touch");
        let dim = sim.section_dim();
        assert_eq!(d.shape(), (dim, dim + 1), "{law}");
        assert_eq!(dim, 2, "{law}");
        // The map in the section's own units (Simulation::z), q last.
        let z0 = sim.z(&start);
        let map = |dz: &[f64]| {
            let mut s = sim;
            s.cpl.a0 += dz[dim] * s.cpl.a1;
            let z = z0.clone() + nalgebra::DVector::from_column_slice(&dz[..dim]);
            let mut ph = sim.at_z(&start, &z);
            s.cycle(&mut ph, &mut Ignore).unwrap();
            sim.z(&ph)
        };
        let h = 1e-6;
        for col in 0..=dim {
            let mut dz = vec![0.0; dim + 1];
            dz[col] = h;
            let plus = map(&dz);
            dz[col] = -h;
            let minus = map(&dz);
            for row in 0..dim {
                let fd = (plus[row] - minus[row]) / (2.0 * h);
                assert!(
                    (d[(row, col)] - fd).abs() < 1e-5 * (1.0 + fd.abs()),
                    "{law}: d[{row}, {col}] = {} vs finite differences {fd}",
                    d[(row, col)]
                );
            }
        }
    }
}
