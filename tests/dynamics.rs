//! Tapping-mode dynamics (docs/src/explanation/design.md §2): free response, conservative and hysteretic laws,
//! energy balance, phase from energy, and the quasi-static limit (26).

use std::f64::consts::PI;
use tapsim::contact::hybrid::JumpIn;
use tapsim::dynamics::base_drive::{self, BaseDriveOptions};
use tapsim::dynamics::march::{Phase, Simulation};
use tapsim::dynamics::model::{Coupling, Drive, Oscillator};
use tapsim::dynamics::numeric::Tolerances;
use tapsim::dynamics::observables::{Observe, TapObservables, tap};
use tapsim::dynamics::setup::{Numerics, TapSetup, default_setup};
use tapsim::dynamics::steady::SteadyOptions;
use tapsim::law::{Branch, ForceLaw, LawKind, LawSpec, NoForce};

/// The observables of `law` on the defaults at rest separation `separation_nm`.
fn observe(law: LawSpec, separation_nm: f64) -> TapObservables {
    let setup = TapSetup {
        law,
        separation_m: separation_nm * 1e-9,
        ..default_setup()
    };
    tap(&setup, &Numerics::default(), Observe::default())
        .unwrap()
        .observables
}

/// The rigid law of eq. (12): a law the code names nowhere but in its file and the
/// registry, found by its name as a user's `--law rigid` is.
fn rigid() -> LawKind {
    LawKind::from_name("rigid").unwrap()
}

fn run(law: LawKind, separation_nm: f64) -> TapObservables {
    let o = observe(law.into(), separation_nm);
    assert!(o.converged, "{law} at {separation_nm} nm did not converge");
    o
}

/// No force, but declared not force-free: the free flight goes through Dopri5.
struct NumericNoForce;

impl ForceLaw for NumericNoForce {
    fn t_hat(&self, _: f64, _: Branch) -> f64 {
        0.0
    }
    fn slope_hat(&self, _: f64, _: Branch) -> f64 {
        0.0
    }
    fn work_hat(&self, _: f64, _: Branch) -> f64 {
        0.0
    }
    fn jump_in_alpha_hat(&self) -> f64 {
        f64::NEG_INFINITY
    }
    fn jump_out_alpha_hat(&self) -> f64 {
        f64::INFINITY
    }
    fn free_branch_is_force_free(&self) -> bool {
        false
    }
    fn loop_area_hat(&self) -> f64 {
        0.0
    }
}

fn free_response<L: ForceLaw>(law: &L, omega: f64, q: f64) -> (f64, f64) {
    let f0 = ((1.0 - omega * omega).powi(2) + (omega / q).powi(2)).sqrt();
    let osc = Oscillator {
        gamma: 0.5 / q,
        omega,
        drive: Drive::Force { amplitude: f0 },
        bias: 0.0,
    };
    let sim = Simulation {
        law,
        osc,
        cpl: Coupling {
            a0: 100.0,
            a1: 1.0,
            f_scale: 1.0,
        },
        tol: Tolerances {
            rtol: 1e-10,
            atol: 1e-12,
            h_max: osc.period() / 40.0,
        },
    };
    // From rest: the transient must die out.
    let mut phase = Phase::at_rest();
    let opts = SteadyOptions {
        tolerance: 1e-10,
        average_tolerance: 1e-3,
        max_cycles: 100_000,
        shooting: false,
        max_steps: tapsim::dynamics::budget::STEPS,
        marching_fraction: tapsim::dynamics::steady::MARCHING_TOLERANCE,
        grazing_threshold: 0.0,
    };
    let state = sim.steady_state(&mut phase, &opts).unwrap();
    assert!(state.converged);
    assert_eq!(state.motion.period(), Some(1));
    (state.window.amplitude(), state.window.phase().to_degrees())
}

#[test]
fn without_force_the_response_is_the_analytic_driven_oscillator() {
    // The drive is set so that the free amplitude is 1 at any frequency.
    for &(omega, q) in &[(1.0f64, 400.0f64), (0.98, 100.0), (1.03, 50.0)] {
        let phi = (omega / q).atan2(1.0 - omega * omega).to_degrees();
        let (a, p) = free_response(&NoForce, omega, q);
        assert!(
            (a - 1.0).abs() < 1e-6,
            "closed form, omega {omega}: A = {a}"
        );
        assert!(
            (p - phi).abs() < 1e-4,
            "closed form, omega {omega}: {p} vs {phi}"
        );
        let (a, p) = free_response(&NumericNoForce, omega, q);
        assert!((a - 1.0).abs() < 1e-6, "Dopri5, omega {omega}: A = {a}");
        assert!(
            (p - phi).abs() < 1e-4,
            "Dopri5, omega {omega}: {p} vs {phi}"
        );
    }
    // Through the CLI's path too: the free cantilever at resonance.
    let o = run(LawKind::None, 16.0);
    assert!((o.amplitude_ratio - 1.0).abs() < 1e-6 && (o.phase_deg - 90.0).abs() < 1e-4);
}

#[test]
fn conservative_laws_dissipate_nothing() {
    for (law, z) in [
        (LawKind::Hertz, 14.0),
        (LawKind::Hertz, 18.0),
        (LawKind::Dmt, 14.0),
        (LawKind::Dmt, 18.0),
        (rigid(), 14.0),
        (rigid(), 18.0),
    ] {
        let o = run(law, z);
        assert!(
            o.jumps_in >= 1.0 || law == LawKind::Dmt,
            "{law} at {z} nm never touched"
        );
        assert!(
            o.e_ts_j.abs() < 1e-6 * o.e_drive_j,
            "{law} {z}: E_ts {} vs E_drive {}",
            o.e_ts_j,
            o.e_drive_j
        );
        assert!(
            o.energy_balance_rel < 1e-6,
            "{law} {z}: balance {}",
            o.energy_balance_rel
        );
        // At resonance, sin φ = (ω/ω₀)(A/A₀) up to higher harmonics.
        let sin_phi = o.phase_deg.to_radians().sin();
        assert!(
            (sin_phi - o.amplitude_ratio).abs() < 2e-3,
            "{law} {z}: sin φ {sin_phi} vs A/A₀ {}",
            o.amplitude_ratio
        );
        assert!(
            o.amplitude_ratio < 0.99,
            "{law} {z}: the tip should feel the sample"
        );
    }
}

/// The rigid law (eq. (12), added as one file and one registry line, called through
/// the law dispatch's pointer) is DMT's −HR/(6d²) with H = 16πε²Δγ wherever the gap
/// stays several ε wide (its repulsive 1/h̄⁸ term is then some 10⁻⁵ of the pull): on
/// the defaults at z_c = 21 nm (least gap 1.05 nm, h̄ ≈ 4.5) the two orbits agree,
/// while DMT's default H = 12πε²Δγ, a quarter weaker, moves them measurably.
#[test]
fn the_rigid_law_far_from_contact_is_dmts_attraction_with_its_hamaker_constant() {
    let contact = default_setup().contact;
    let hamaker_j =
        16.0 * std::f64::consts::PI * contact.range_m.powi(2) * contact.work_of_adhesion_j_m2;
    let rigid = run(rigid(), 21.0);
    let dmt = |hamaker_j| {
        observe(
            LawSpec {
                hamaker_j: Some(hamaker_j),
                ..LawKind::Dmt.into()
            },
            21.0,
        )
    };
    let (same, weaker) = (dmt(hamaker_j), dmt(0.75 * hamaker_j));
    assert!(rigid.min_separation_m > 3.0 * contact.range_m, "{rigid:?}");
    let gap = |o: &TapObservables| {
        (
            (o.amplitude_m / rigid.amplitude_m - 1.0).abs(),
            (o.phase_deg - rigid.phase_deg).abs(),
        )
    };
    let (da, dphi) = gap(&same);
    assert!(da < 1e-6 && dphi < 1e-3, "same H: {da:e}, {dphi}°");
    let (da, dphi) = gap(&weaker);
    assert!(da > 1e-6 && dphi > 1e-2, "weaker H: {da:e}, {dphi}°");
}

#[test]
fn hysteretic_laws_dissipate_their_loop_area() {
    for (law, z) in [
        (LawKind::Hybrid, 12.0),
        (LawKind::Hybrid, 16.0),
        (LawKind::Hybrid, 18.0),
        (LawKind::HybridAttractive, 14.0),
        (LawKind::Jkr, 12.0),
        (LawKind::Jkr, 14.0),
    ] {
        let o = run(law, z);
        assert_eq!(
            o.jumps_in, 1.0,
            "{law} {z}: the loop must be traversed once a cycle"
        );
        let rel = (o.e_ts_j - o.loop_area_j).abs() / o.loop_area_j;
        assert!(
            rel < 1e-5,
            "{law} {z}: E_ts {} vs loop {} ({rel:e})",
            o.e_ts_j,
            o.loop_area_j
        );
        assert!(
            o.energy_balance_rel < 1e-6,
            "{law} {z}: balance {}",
            o.energy_balance_rel
        );
        // In contact for part of the cycle, below the jump-in separation (in the
        // attractive regime the JKR contact can stay tensile: α > 0 throughout).
        let setup = default_setup();
        let jump_in_m = match law {
            LawKind::Jkr => 0.0,
            _ => 1.2 * setup.contact.separation_scale_m(),
        };
        assert!(
            o.contact_fraction > 0.0 && o.min_separation_m < jump_in_m,
            "{law} {z}: {o:?}"
        );
    }
}

#[test]
fn jkr_overstates_the_loss_of_the_hybrid_law() {
    let (h, j) = (run(LawKind::Hybrid, 14.0), run(LawKind::Jkr, 14.0));
    // Same contact and setpoint: the classic JKR loop is Ŵ_JKR/Ŵ_hybrid(μ) times larger.
    let ratio = j.e_ts_j / h.e_ts_j;
    let expect = tapsim::contact::jkr::w_hat_jkr() / tapsim::contact::hybrid::w_hat_fit(h.tabor_mu);
    assert!(
        (ratio - expect).abs() < 1e-4 * expect,
        "{ratio} vs {expect}"
    );
    assert!(
        j.phase_deg > h.phase_deg + 5.0,
        "JKR's extra loss shows in the phase"
    );
}

#[test]
fn lock_in_and_energy_phase_agree_for_the_hybrid_law() {
    let o = run(LawKind::Hybrid, 15.0);
    assert!(
        (o.amplitude_ratio - 0.9).abs() < 0.03,
        "A/A₀ = {}",
        o.amplitude_ratio
    );
    assert!(o.e_ts_j > 0.0);
    let diff = (o.phase_deg - o.phase_from_energy_deg).abs();
    assert!(
        diff < 0.05,
        "lock-in {} vs energy {}",
        o.phase_deg,
        o.phase_from_energy_deg
    );
    // Attractive regime: both above 90°, and still consistent.
    let o = run(LawKind::Hybrid, 18.0);
    assert!(o.phase_deg > 90.0 && o.phase_from_energy_deg > 90.0);
    assert!((o.phase_deg - o.phase_from_energy_deg).abs() < 0.05);
}

#[test]
fn slow_base_drive_loses_the_finite_stiffness_hysteresis_26() {
    for (mu, k_hat) in [(5.0, 2.0), (10.0, 0.5)] {
        let r =
            base_drive::hybrid_cycle(mu, k_hat, JumpIn::Fit, &BaseDriveOptions::default()).unwrap();
        let rel = (r.w_hat_dynamic - r.w_hat_closed_form).abs() / r.w_hat_closed_form;
        assert!(
            rel < 0.01,
            "mu {mu}, k {k_hat}: {} vs (26) {} ({rel:.2e})",
            r.w_hat_dynamic,
            r.w_hat_closed_form
        );
        assert_eq!(r.jumps_in, 1);
        // The contact itself loses the rigid hybrid loop; the spring's share rings out.
        let rigid = tapsim::contact::hybrid::w_hat_fit(mu);
        assert!((r.w_hat_contact - rigid).abs() < 1e-6 * rigid);
    }
}

#[test]
fn amplitude_phase_and_energy_are_self_consistent() {
    let o = run(LawKind::Hybrid, 16.0);
    let k = default_setup().cantilever.stiffness_n_m;
    let a0 = default_setup().cantilever.free_amplitude_m;
    // Damping loss of a harmonic motion, πkA²/Q at resonance, within the harmonics' share.
    let e_damp = PI * k * o.amplitude_m.powi(2) / 400.0;
    assert!(
        (o.e_damp_j - e_damp).abs() < 1e-3 * e_damp,
        "{} vs {e_damp}",
        o.e_damp_j
    );
    assert!((o.amplitude_m / a0 - o.amplitude_ratio).abs() < 1e-15);
    assert!((o.e_ts_ev * 1.602_176_634e-19 - o.e_ts_j).abs() < 1e-30);
}

#[test]
fn laws_refuse_where_they_do_not_apply() {
    // μ ≈ 0.5: the hybrid law has no contact branch to land on.
    let mut setup = default_setup();
    setup.contact.work_of_adhesion_j_m2 = 0.02;
    setup.contact.modulus_pa = 2e9;
    assert!(setup.contact.tabor_mu() < 1.0);
    let err = tap(&setup, &Numerics::default(), Observe::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("does not apply") && err.contains("DMT"),
        "{err}"
    );
    setup.law = LawKind::Dmt.into();
    assert!(tap(&setup, &Numerics::default(), Observe::default()).is_ok());
}

#[test]
fn tabulated_lj_law_dissipates_the_numerical_loop() {
    let setup = TapSetup {
        law: LawKind::Lj.into(),
        separation_m: 14e-9,
        ..default_setup()
    };
    let o = tap(&setup, &Numerics::default(), Observe::default())
        .unwrap()
        .observables;
    assert!(o.converged && o.jumps_in == 1.0);
    // The law is the production mesh's curve: it dissipates that curve's loop exactly,
    // which lies within the discretisation error of the extrapolated Ŵ_LJ.
    let rel = (o.e_ts_j - o.loop_area_j).abs() / o.loop_area_j;
    println!(
        "E_ts {:.6e} J vs the law's loop {:.6e} J ({rel:.1e})",
        o.e_ts_j, o.loop_area_j
    );
    assert!(rel < 1e-5, "{rel:e}");
    let s = tapsim::contact::lj::solve(
        setup.contact.tabor_mu(),
        tapsim::contact::lj::Reach::Springs,
    )
    .unwrap();
    let w = s.w_hat.value * setup.contact.energy_scale_j();
    let mesh = (o.loop_area_j - w).abs() / w;
    println!("the law's loop vs the extrapolated W_LJ·μεRΔγ {w:.6e} J: {mesh:.1e}");
    assert!(mesh < 1e-3, "{mesh:e}");
    assert!(o.energy_balance_rel < 1e-6);
    // At μ = 2.76 the hybrid theory underestimates the loss the LJ law gives.
    let hybrid = run(LawKind::Hybrid, 14.0);
    assert!(o.e_ts_j > hybrid.e_ts_j);
}

#[test]
fn shooting_finds_the_same_steady_state_as_the_transient() {
    for (law, z) in [
        (LawKind::Hybrid, 16.0),
        (LawKind::Hybrid, 18.0),
        (LawKind::Dmt, 14.0),
        (LawKind::Hertz, 14.0),
    ] {
        let setup = TapSetup {
            law: law.into(),
            separation_m: z * 1e-9,
            ..default_setup()
        };
        let fast = tap(&setup, &Numerics::default(), Observe::default())
            .unwrap()
            .observables;
        let slow = tap(
            &setup,
            &Numerics {
                shooting: false,
                ..Numerics::default()
            },
            Observe::default(),
        )
        .unwrap()
        .observables;
        assert!(fast.converged && slow.converged);
        assert!(
            (fast.amplitude_ratio - slow.amplitude_ratio).abs() < 1e-7,
            "{law} {z}"
        );
        assert!((fast.phase_deg - slow.phase_deg).abs() < 1e-5, "{law} {z}");
        assert!(
            (fast.e_ts_j - slow.e_ts_j).abs() <= 1e-7 * slow.e_drive_j,
            "{law} {z}"
        );
        println!(
            "{law} {z} nm: {} cycles with shooting, {} without",
            fast.cycles, slow.cycles
        );
        assert!(
            fast.cycles * 4 < slow.cycles,
            "{law} {z}: {} vs {} cycles",
            fast.cycles,
            slow.cycles
        );
    }
}

/// The harmonics observer against the equation of motion: on a periodic orbit the n-th
/// harmonic of the deflection is the force's n-th harmonic through the point-mass
/// transfer function, X_n = F_n/(k(1 − (nΩ)² + 2iγnΩ)) for n ≥ 2 (no drive there). The
/// two are integrated independently (the force from the law at the interpolated
/// separation), so this checks the integration and the quadrature together.
#[test]
fn deflection_harmonics_are_the_force_harmonics_through_the_transfer_function() {
    type Complex64 = nalgebra::Complex<f64>;
    let viscous = |kind: LawKind| LawSpec {
        viscosity_pa_s: Some(50.0),
        ..kind.into()
    };
    for (law, separation_nm) in [
        (LawKind::Hybrid.into(), 16.0),
        (LawKind::Jkr.into(), 14.0),
        (LawKind::Dmt.into(), 14.0),
        (LawKind::Hertz.into(), 12.0),
        (LawKind::Lj.into(), 14.0),
        (viscous(LawKind::Hertz), 12.0),
        (viscous(LawKind::Hybrid), 14.0),
    ] {
        let setup = TapSetup {
            law,
            separation_m: separation_nm * 1e-9,
            ..default_setup()
        };
        let observe = Observe {
            harmonics: true,
            ..Observe::default()
        };
        let run = tap(&setup, &Numerics::default(), observe).unwrap();
        assert_eq!(run.observables.regime, "period-1", "{law}");
        let harmonics = run.harmonics.expect("a periodic orbit has harmonics");
        assert_eq!(
            harmonics.iter().map(|h| h.order).collect::<Vec<_>>(),
            (2..=10).collect::<Vec<_>>()
        );
        let cant = &setup.cantilever;
        let (omega, gamma) = (
            cant.drive_frequency_hz / cant.resonance_hz,
            0.5 / cant.quality,
        );
        let a0 = cant.free_amplitude_m;
        let mut worst: f64 = 0.0;
        for h in &harmonics {
            let w = h.order as f64 * omega;
            let transfer = Complex64::new(1.0 - w * w, 2.0 * gamma * w).inv();
            let x = Complex64::from_polar(
                h.deflection_amplitude_m,
                -h.deflection_phase_deg.to_radians(),
            );
            let f = Complex64::from_polar(h.force_amplitude_n, -h.force_phase_deg.to_radians());
            let predicted = transfer * f / cant.stiffness_n_m;
            worst = worst.max((x - predicted).norm() / a0);
        }
        // In units of the free amplitude; the second harmonic is ~1e-3 of it.
        let second = harmonics[0].deflection_amplitude_m / a0;
        eprintln!("{law}: worst |X_n - H F_n| = {worst:.1e} A0 (second harmonic {second:.1e} A0)");
        assert!(worst < 1e-6, "{law}: {worst:e}");
        assert!(
            second > 1e-5,
            "{law}: a tapping orbit has a second harmonic ({second:e})"
        );
    }
}

/// A Kelvin–Voigt sample on every contact law: the viscous work is carried as an
/// integral, so the energy balance (drive = damping + E_ts) checks it; E_ts exceeds the
/// elastic law's own loss; and the viscous force does what it should, adding loss.
#[test]
fn a_viscous_sample_adds_loss_and_keeps_the_energy_balance_on_every_law() {
    // Every law with a contact (all but none).
    for kind in LawKind::ALL.into_iter().filter(|k| *k != LawKind::None) {
        let at = |viscosity: Option<f64>| {
            let law = LawSpec {
                viscosity_pa_s: viscosity,
                ..kind.into()
            };
            observe(law, 12.0)
        };
        let (elastic, viscous) = (at(None), at(Some(20.0)));
        assert!(viscous.converged, "{kind}");
        assert_eq!(viscous.law, format!("{kind}+kelvin-voigt"));
        assert!(
            viscous.energy_balance_rel < 1e-6,
            "{kind}: {:e}",
            viscous.energy_balance_rel
        );
        // Per touch the elastic law loses its loop; the sample adds to it. E_ts splits
        // into the two channels, each from its own integral: the adhesion channel is the
        // law's loop per touch, the viscous one the rest.
        let elastic_loss = viscous.loop_area_j * viscous.jumps_in;
        assert_eq!(elastic.e_ts_viscous_j, 0.0, "{kind}");
        let sum = viscous.e_ts_adhesion_j + viscous.e_ts_viscous_j;
        assert!(
            (sum - viscous.e_ts_j).abs() <= 1e-12 * viscous.e_ts_j,
            "{kind}"
        );
        assert!(
            (viscous.e_ts_adhesion_j - elastic_loss).abs() <= 1e-6 * viscous.e_ts_j,
            "{kind}: adhesion channel {:e} vs loop per touch {:e}",
            viscous.e_ts_adhesion_j,
            elastic_loss
        );
        assert!(viscous.e_ts_viscous_j > 0.0, "{kind}");
        assert!(
            viscous.e_ts_j > elastic_loss + 1e-3 * viscous.e_ts_j,
            "{kind}: {:e} vs {:e}",
            viscous.e_ts_j,
            elastic_loss
        );
        assert!(viscous.e_ts_j > elastic.e_ts_j, "{kind}");
        eprintln!(
            "{kind}: E_ts {:.3} eV elastic, {:.3} eV with 20 Pa·s; phase {:.2}° → {:.2}°",
            elastic.e_ts_ev, viscous.e_ts_ev, elastic.phase_deg, viscous.phase_deg
        );
    }
}

/// At small viscosity the viscous loss is η times the integral ∮√(Rδ)·δ̇² dt over the
/// elastic orbit (first order in η): the carried integral against a quadrature of the
/// recorded elastic trajectory.
#[test]
fn a_small_viscosity_loses_eta_times_the_elastic_orbits_rate_integral() {
    let base = TapSetup {
        law: LawKind::Hertz.into(),
        separation_m: 12e-9,
        ..default_setup()
    };
    let elastic = tap(&base, &Numerics::default(), Observe::recording(1)).unwrap();
    // ∮ √(R δ) δ̇² dt by the trapezoidal rule on the recorded samples (δ = −α).
    let radius = base.contact.radius_m;
    let integrand = |s: &tapsim::dynamics::observables::TrajectorySample| {
        let delta = (-s.alpha_m).max(0.0);
        (radius * delta).sqrt() * s.v_m_s * s.v_m_s
    };
    let rate_integral: f64 = elastic
        .trajectory
        .windows(2)
        .map(|w| 0.5 * (integrand(&w[0]) + integrand(&w[1])) * (w[1].t_s - w[0].t_s))
        .sum();
    let mut ratios = Vec::new();
    for eta in [1e-1, 1e-2, 1e-3] {
        let setup = TapSetup {
            law: LawSpec {
                viscosity_pa_s: Some(eta),
                ..base.law
            },
            ..base.clone()
        };
        let o = tap(&setup, &Numerics::default(), Observe::default())
            .unwrap()
            .observables;
        ratios.push(o.e_ts_j / (eta * rate_integral));
    }
    eprintln!("E_visc/(eta I) at eta = 0.1, 0.01, 0.001 Pa·s: {ratios:?}");
    // First order: the ratio tends to 1 (to the trapezoidal rule's error on the recorded
    // samples, ~1e-4), and its departure is linear in η (tenfold per decade).
    assert!((ratios[2] - 1.0).abs() < 2e-4, "{ratios:?}");
    let decade = (ratios[0] - ratios[1]) / (ratios[1] - ratios[2]);
    assert!((decade - 10.0).abs() < 1.0, "{decade}: {ratios:?}");
}

/// A capillary neck (VEDA's model) on Hertz and DMT, alone and with a viscous sample
/// (with a relaxing one: tests/relaxing.rs): every cycle in which the neck forms and breaks loses exactly its
/// closed-form loop 2πRγ cos θ (D₀ − a₀), the channels add up to E_ts, and the energy
/// balance holds.
#[test]
fn a_capillary_neck_loses_its_closed_form_loop_per_touch_on_every_combination() {
    let contact = default_setup().contact;
    let elastic = LawSpec::default();
    let samples = [
        elastic,
        LawSpec {
            viscosity_pa_s: Some(10.0),
            ..elastic
        },
    ];
    for (kind, a0) in [(LawKind::Hertz, 0.0), (LawKind::Dmt, contact.range_m)] {
        for sample in samples {
            for (rupture, angle, separation) in [(2e-9, 0.0, 12e-9), (3e-9, 40.0, 9e-9)] {
                let setup = TapSetup {
                    law: LawSpec {
                        kind,
                        rupture_distance_m: Some(rupture),
                        contact_angle_deg: Some(angle),
                        ..sample
                    },
                    separation_m: separation,
                    ..default_setup()
                };
                let o = tap(&setup, &Numerics::default(), Observe::default())
                    .unwrap()
                    .observables;
                let name = format!("{} D0 {rupture:e} θ {angle} z_c {separation:e}", o.law);
                assert!(o.converged, "{name}");
                assert!(
                    o.energy_balance_rel < 1e-6,
                    "{name}: {:e}",
                    o.energy_balance_rel
                );
                // The neck's loop, from the parameters alone.
                let loop_j =
                    2.0 * PI * contact.radius_m * 0.072 * angle.to_radians().cos() * (rupture - a0);
                assert!(
                    (o.loop_area_j - loop_j).abs() <= 1e-12 * loop_j,
                    "{name}: {:e} vs {loop_j:e}",
                    o.loop_area_j
                );
                assert!(o.jumps_in > 0.0, "{name}: the tip must touch");
                // Each touch forms the neck, each retreat breaks it: the loop per touch.
                let per_touch = o.e_ts_capillary_j / o.jumps_in;
                assert!(
                    (per_touch - loop_j).abs() <= 1e-9 * loop_j,
                    "{name}: {per_touch:e} per touch vs {loop_j:e}"
                );
                let sum = o.e_ts_adhesion_j + o.e_ts_viscous_j + o.e_ts_capillary_j;
                assert!((sum - o.e_ts_j).abs() <= 1e-12 * o.e_ts_j, "{name}");
                // Hertz and DMT have no hysteresis of their own.
                // (No loop of its own: the adhesion channel is round-off, E_ts − E_viscous.)
                assert!(o.e_ts_adhesion_j.abs() <= 1e-12 * o.e_drive_j, "{name}");
                assert_eq!(o.e_ts_viscous_j > 0.0, sample != elastic, "{name}");
                eprintln!(
                    "{name}: {} , {:.3} touches/period, E_cap {:.4} eV, E_visc {:.4} eV",
                    o.regime,
                    o.jumps_in,
                    o.e_ts_capillary_j / 1.602176634e-19,
                    o.e_ts_viscous_j / 1.602176634e-19
                );
            }
        }
    }
}

/// On a hysteretic law (JKR, hybrid, LJ) the neck outlives the contact: it forms at the
/// law's jump-in α_A, holds through the contact and past its let-go, and breaks at D₀.
/// Each touch then loses the law's own loop (the adhesion channel) plus the neck's
/// ∫_{α_A}^{D₀} F_cap dα (the capillary channel), each to 1e-9, alone and with a viscous
/// sample; the energy balance holds.
#[test]
fn a_neck_on_a_hysteretic_law_loses_both_loops_per_touch() {
    let contact = default_setup().contact;
    let (rupture, angle) = (2e-9, 20.0);
    let pull = 4.0 * PI * contact.radius_m * 0.072 * f64::cos(angle * PI / 180.0);
    // ∫ F_cap dα from α_A to D₀: F_ad below contact, falling linearly to 0 at D₀.
    let neck_work = |alpha: f64| {
        if alpha < 0.0 {
            pull * alpha
        } else {
            pull * (alpha - 0.5 * alpha * alpha / rupture)
        }
    };
    for (kind, separation) in [
        (LawKind::Jkr, 10e-9),
        (LawKind::Hybrid, 10e-9),
        (LawKind::Lj, 10e-9),
    ] {
        for viscosity in [None, Some(10.0)] {
            let spec = LawSpec {
                viscosity_pa_s: viscosity,
                ..kind.into()
            };
            let setup = TapSetup {
                law: spec,
                separation_m: separation,
                ..default_setup()
            };
            let plain_run = tap(&setup, &Numerics::default(), Observe::default()).unwrap();
            let plain = plain_run.observables;
            let necked = TapSetup {
                law: LawSpec {
                    rupture_distance_m: Some(rupture),
                    contact_angle_deg: Some(angle),
                    ..spec
                },
                ..setup.clone()
            };
            let o = tap(&necked, &Numerics::default(), Observe::default())
                .unwrap()
                .observables;
            let name = format!("{} ({})", o.law, o.regime);
            assert!(o.converged, "{name}");
            assert!(
                o.energy_balance_rel < 1e-6,
                "{name}: {:e}",
                o.energy_balance_rel
            );
            assert!(o.jumps_in > 0.0, "{name}: the tip must touch");
            // The neck forms where the law jumps in (its own switch separations).
            let alpha_a = plain_run.switch_separations_m.0;
            let neck_loop = neck_work(rupture) - neck_work(alpha_a);
            let per_touch = o.e_ts_capillary_j / o.jumps_in;
            assert!(
                (per_touch - neck_loop).abs() <= 1e-9 * neck_loop,
                "{name}: {per_touch:e} per touch vs {neck_loop:e}"
            );
            // The law's own loop, as without the neck.
            let adhesion = o.e_ts_adhesion_j / o.jumps_in;
            assert!(
                (adhesion - plain.loop_area_j).abs() <= 1e-9 * plain.loop_area_j,
                "{name}: {adhesion:e} vs {:e}",
                plain.loop_area_j
            );
            assert!(
                (o.loop_area_j - plain.loop_area_j - neck_loop).abs() <= 1e-9 * o.loop_area_j,
                "{name}"
            );
            let sum = o.e_ts_adhesion_j + o.e_ts_viscous_j + o.e_ts_capillary_j;
            assert!((sum - o.e_ts_j).abs() <= 1e-12 * o.e_ts_j, "{name}");
            assert_eq!(o.e_ts_viscous_j > 0.0, viscosity.is_some(), "{name}");
            eprintln!(
                "{name}: {:.3} touches/period, E_cap {:.4} eV, E_adh {:.4} eV per touch",
                o.jumps_in,
                per_touch / 1.602176634e-19,
                adhesion / 1.602176634e-19
            );
        }
    }
}
