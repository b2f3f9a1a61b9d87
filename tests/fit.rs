//! Fitting measured approach curves (issue 32): the round trip — a curve simulated with
//! known parameters, noise added, fitted back — and what the fit says of what the data
//! determine.

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use tapsim::dynamics::setup::{Numerics, TapSetup, default_setup};
use tapsim::fit::{FitOptions, Measured, Nuisance, Parameter, Search, fit, model::curve};
use tapsim::sweep::sweep_numerics;

/// The true offset of the piezo's zero: z_c = position + 3 nm.
const OFFSET_M: f64 = 3e-9;
/// The noise: 0.02 nm in amplitude, 0.05° in phase.
const SIGMA_A_M: f64 = 0.02e-9;
const SIGMA_PHI_DEG: f64 = 0.05;

fn numerics() -> Numerics {
    sweep_numerics(Numerics::default(), (false, false))
}

/// `n` points from `from` down to `to`, evenly spaced.
fn span(from: f64, to: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| from - (from - to) * i as f64 / (n - 1) as f64)
        .collect()
}

/// Piezo positions of an approach from z_c = 18.5 nm to 8 nm in `n` points (the hybrid
/// defaults tap period-1 there, on the attractive branch).
fn positions(n: usize) -> Vec<f64> {
    span(18.5e-9, 8e-9, n)
        .iter()
        .map(|z| z - OFFSET_M)
        .collect()
}

/// The curve of `truth` at `positions` with noise drawn from `seed`.
fn measured(truth: &TapSetup, positions: &[f64], seed: u64) -> Measured {
    let (c, data) = noisy(truth, positions, seed);
    assert!(c.well_defined.iter().all(|&w| w), "{:?}", c.well_defined);
    data
}

/// The curve of `truth` at `positions`, and it with noise drawn from `seed`.
fn noisy(truth: &TapSetup, positions: &[f64], seed: u64) -> (tapsim::fit::model::Curve, Measured) {
    let c = curve(truth, &numerics(), positions, OFFSET_M).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let (na, np) = (
        Normal::new(0.0, SIGMA_A_M).unwrap(),
        Normal::new(0.0, SIGMA_PHI_DEG).unwrap(),
    );
    let data = Measured {
        position_m: positions.to_vec(),
        setpoint_ratio: None,
        second_mode: None,
        segments: vec![0],
        amplitude_m: Some(
            c.amplitude_m
                .iter()
                .map(|a| a + na.sample(&mut rng))
                .collect(),
        ),
        phase_deg: Some(
            c.phase_deg
                .iter()
                .map(|p| p + np.sample(&mut rng))
                .collect(),
        ),
        sigma_amplitude_m: SIGMA_A_M,
        sigma_phase_deg: SIGMA_PHI_DEG,
        thermal: None,
    };
    (c, data)
}

/// A fit of `parameters` with the standard deviations as given, at most `max_curves`
/// simulated curves, the offset from 0 and the calibration holding.
fn fitting(parameters: Vec<Parameter>, max_curves: usize) -> FitOptions {
    FitOptions {
        parameters,
        start: Nuisance::offset(0.0),
        estimate_sigma: false,
        max_curves,
        search: Search::Local,
        keep_grazing: false,
    }
}

/// E*, Δγ and the offset, the offset from `offset_start_m`.
fn options(offset_start_m: f64) -> FitOptions {
    FitOptions {
        start: Nuisance::offset(offset_start_m),
        ..fitting(
            vec![
                Parameter::Modulus,
                Parameter::WorkOfAdhesion,
                Parameter::ZOffset,
            ],
            400,
        )
    }
}

/// Noise-free data are the limit: fitted from a start 50 % and 20 % off (and 0.5 nm in
/// the offset), the truth comes back to 1e-6 — the forward model and the optimiser,
/// with nothing between them and the answer.
#[test]
fn noise_free_data_give_back_the_truth() {
    let truth = default_setup();
    let mut data = measured(&truth, &positions(30), 0);
    let clean = curve(&truth, &numerics(), &data.position_m, OFFSET_M).unwrap();
    data.amplitude_m = Some(clean.amplitude_m);
    data.phase_deg = Some(clean.phase_deg);
    let mut start = truth.clone();
    start.contact.modulus_pa *= 1.5;
    start.contact.work_of_adhesion_j_m2 *= 1.2;
    let r = fit(
        &start,
        &numerics(),
        &data,
        &options(OFFSET_M + 0.5e-9),
        |_| {},
    )
    .unwrap();
    assert!(r.converged, "{}", r.termination);
    let got: Vec<f64> = r.parameters.iter().map(|p| p.value.unwrap()).collect();
    eprintln!("{got:?} in {} curves", r.curves);
    assert!((got[0] / truth.contact.modulus_pa - 1.0).abs() < 1e-6);
    assert!((got[1] / truth.contact.work_of_adhesion_j_m2 - 1.0).abs() < 1e-6);
    assert!((got[2] - OFFSET_M).abs() < 1e-6 * 1e-9);
    assert!(r.chi_square < 1e-6);
}

/// With 0.02 nm and 0.05° of noise on 30 points of the attractive branch, fitted from
/// three starts (E* and Δγ off by factors of 2 and 1.5, the offset by 1–3 nm): each
/// start ends on the same minimum (to 1e-4), χ²/dof is what noise of the stated size
/// gives (within 3 standard deviations of 1), and the truth lies inside the 95 %
/// intervals. The data fix E*·Δγ-like combinations better than either — the report says
/// so (correlation above 0.95) and the intervals are wide accordingly (E* to about
/// 2.3 %, Δγ to 1.4 %): within 1 % the issue asks for, the attractive branch alone does
/// not determine them at this noise.
#[test]
#[ignore = "slow (about 20 s in release: three fits of 70 to 140 curves each): run with cargo test --release -- --ignored fit::"]
fn a_noisy_approach_curve_is_fitted_back_from_three_starts() {
    let truth = default_setup();
    let data = measured(&truth, &positions(30), 7);
    let mut found: Vec<Vec<f64>> = Vec::new();
    for (e, w, off) in [(2.0, 0.5, 2e-9), (1.5, 1.5, 5e-9), (0.7, 1.2, 1e-9)] {
        let mut start = truth.clone();
        start.contact.modulus_pa *= e;
        start.contact.work_of_adhesion_j_m2 *= w;
        let r = fit(&start, &numerics(), &data, &options(off), |_| {}).unwrap();
        let got: Vec<f64> = r.parameters.iter().map(|p| p.value.unwrap()).collect();
        eprintln!(
            "start ({e}, {w}, {off:e}): {got:?} ± {:?}, chi2/dof {:.3} in {} curves",
            r.parameters
                .iter()
                .map(|p| p.std_err.unwrap())
                .collect::<Vec<_>>(),
            r.reduced_chi_square,
            r.curves
        );
        assert!(r.converged, "{}", r.termination);
        let dof = r.degrees_of_freedom as f64;
        assert!((r.reduced_chi_square - 1.0).abs() < 3.0 * (2.0 / dof).sqrt());
        // The guide: χ²/dof = 0.76, E* to ±2.3 %, Δγ to ±1.4 %, correlation +0.991.
        assert!((r.reduced_chi_square - 0.76).abs() < 5e-3);
        let rel = |k: usize| r.parameters[k].std_err.unwrap() / r.parameters[k].value.unwrap();
        assert!((rel(0) - 0.023).abs() < 5e-4 && (rel(1) - 0.014).abs() < 5e-4);
        let truths = [
            truth.contact.modulus_pa,
            truth.contact.work_of_adhesion_j_m2,
            OFFSET_M,
        ];
        for (p, t) in r.parameters.iter().zip(truths) {
            let [lo, hi] = p.interval_95.unwrap();
            assert!(lo <= t && t <= hi, "{}: {t} outside [{lo}, {hi}]", p.name);
        }
        let corr = r.identifiability.correlations[0][1].unwrap();
        assert!((corr - 0.991).abs() < 5e-4);
        assert!(
            r.identifiability
                .notes
                .iter()
                .any(|n| n.contains("trade off"))
        );
        if let Some(first) = found.first() {
            for (a, b) in got.iter().zip(first) {
                assert!((a / b - 1.0).abs() < 1e-4, "{got:?} against {first:?}");
            }
        }
        found.push(got);
    }
}

/// The round trip, met where the curve covers both branches: an approach from
/// far (18.5 to 8 nm, attractive) and one begun near the sample (12 to 4 nm, repulsive),
/// 30 points each, 0.02 nm and 0.05° of noise. From the three starts above, each fit
/// ends on one minimum (to 1e-4) with E* and Δγ within 1 % of the truth (here within
/// 0.1 %); their standard errors are ±0.44 % and ±0.35 % — the repulsive branch sees
/// the contact's stiffness, the attractive its adhesion, and together they undo the
/// trade-off the attractive branch alone leaves (±2.3 %, ±1.4 % above).
#[test]
#[ignore = "slow (three fits of some 60 curves of 60 points, about 20 s in release): run with cargo test --release -- --ignored fit::"]
fn a_curve_over_both_branches_is_fitted_back_within_one_percent_from_three_starts() {
    let truth = default_setup();
    let position_m: Vec<f64> = [span(18.5e-9, 8e-9, 30), span(12e-9, 4e-9, 30)]
        .concat()
        .iter()
        .map(|z| z - OFFSET_M)
        .collect();
    let mut data = Measured {
        position_m,
        setpoint_ratio: None,
        second_mode: None,
        segments: vec![0, 30],
        amplitude_m: None,
        phase_deg: None,
        sigma_amplitude_m: SIGMA_A_M,
        sigma_phase_deg: SIGMA_PHI_DEG,
        thermal: None,
    };
    let c = data
        .simulate(&truth, &numerics(), &Nuisance::offset(OFFSET_M))
        .unwrap();
    assert!(c.well_defined.iter().all(|&w| w));
    assert!(c.phase_deg[..30].iter().all(|&p| p > 90.0));
    assert!(c.phase_deg[30..].iter().all(|&p| p < 90.0));
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let (na, np) = (
        Normal::new(0.0, SIGMA_A_M).unwrap(),
        Normal::new(0.0, SIGMA_PHI_DEG).unwrap(),
    );
    data.amplitude_m = Some(
        c.amplitude_m
            .iter()
            .map(|a| a + na.sample(&mut rng))
            .collect(),
    );
    data.phase_deg = Some(
        c.phase_deg
            .iter()
            .map(|p| p + np.sample(&mut rng))
            .collect(),
    );
    let truths = [
        truth.contact.modulus_pa,
        truth.contact.work_of_adhesion_j_m2,
        OFFSET_M,
    ];
    let mut found: Vec<Vec<f64>> = Vec::new();
    for (e, w, off) in [(2.0, 0.5, 2e-9), (1.5, 1.5, 5e-9), (0.7, 1.2, 1e-9)] {
        let mut start = truth.clone();
        start.contact.modulus_pa *= e;
        start.contact.work_of_adhesion_j_m2 *= w;
        let r = fit(&start, &numerics(), &data, &options(off), |_| {}).unwrap();
        assert!(r.converged, "{}", r.termination);
        let got: Vec<f64> = r.parameters.iter().map(|p| p.value.unwrap()).collect();
        let rel = |k: usize| got[k] / truths[k] - 1.0;
        eprintln!(
            "start ({e}, {w}, {off:e}): E* {:+.4} %, Δγ {:+.4} %, χ²/dof {:.3}",
            100.0 * rel(0),
            100.0 * rel(1),
            r.reduced_chi_square
        );
        assert!(rel(0).abs() < 0.01 && rel(1).abs() < 0.01, "{got:?}");
        // The guide: within 0.1 %, ±0.44 % and ±0.35 %.
        assert!(rel(0).abs() < 1e-3 && rel(1).abs() < 1e-3, "{got:?}");
        let err = |k: usize| 100.0 * r.parameters[k].std_err.unwrap() / got[k];
        assert_eq!(
            (format!("{:.2}", err(0)), format!("{:.2}", err(1))),
            ("0.44".into(), "0.35".into())
        );
        let dof = r.degrees_of_freedom as f64;
        assert!((r.reduced_chi_square - 1.0).abs() < 3.0 * (2.0 / dof).sqrt());
        for (p, t) in r.parameters.iter().zip(truths) {
            let [lo, hi] = p.interval_95.unwrap();
            assert!(lo <= t && t <= hi, "{}: {t} outside [{lo}, {hi}]", p.name);
        }
        if let Some(first) = found.first() {
            for (a, b) in got.iter().zip(first) {
                assert!((a / b - 1.0).abs() < 1e-4, "{got:?} against {first:?}");
            }
        }
        found.push(got);
    }
}

/// Data from far from the sample (the free oscillation at every point) do not see the
/// material: E* and Δγ are flagged, given no value, and the Jacobian's smallest
/// singular values are zero (no condition number). A fit never puts a number on what
/// the data cannot tell.
#[test]
fn a_parameter_the_data_do_not_see_is_given_no_value() {
    let truth = default_setup();
    let far: Vec<f64> = (0..8).map(|i| 40e-9 - 1e-9 * i as f64).collect();
    let c = curve(&truth, &numerics(), &far, 0.0).unwrap();
    let data = Measured {
        position_m: far,
        setpoint_ratio: None,
        second_mode: None,
        segments: vec![0],
        amplitude_m: Some(c.amplitude_m),
        phase_deg: Some(c.phase_deg),
        sigma_amplitude_m: SIGMA_A_M,
        sigma_phase_deg: SIGMA_PHI_DEG,
        thermal: None,
    };
    let r = fit(&truth, &numerics(), &data, &options(0.0), |_| {}).unwrap();
    for p in &r.parameters {
        assert!(!p.identifiable && p.value.is_none(), "{p:?}");
    }
    assert_eq!(r.identifiability.condition_number, None);
    assert!(
        r.identifiability
            .notes
            .iter()
            .any(|n| n.contains("does not change the data"))
    );
}

/// A parameter that does not change the data is reported unidentifiable and given no
/// value (the example): a viscous sample (η = 10 Pa·s under the hybrid law)
/// that the tip never indents — on the attractive branch it jumps into contact at a
/// positive separation and leaves again, the Kelvin–Voigt force acting only on
/// indentation. The report says what data would show it. On the repulsive branch, where
/// the tip indents, the same fit gives the viscosity a value with an interval holding
/// the truth.
#[test]
fn a_viscosity_the_tip_never_indents_is_given_no_value() {
    let mut truth = default_setup();
    truth.law.viscosity_pa_s = Some(10.0);
    let opts = fitting(
        vec![
            Parameter::Modulus,
            Parameter::WorkOfAdhesion,
            Parameter::Viscosity,
        ],
        40,
    );
    let fitted = |position_m: Vec<f64>| {
        let mut data = Measured {
            position_m,
            setpoint_ratio: None,
            second_mode: None,
            segments: vec![0],
            amplitude_m: None,
            phase_deg: None,
            sigma_amplitude_m: SIGMA_A_M,
            sigma_phase_deg: SIGMA_PHI_DEG,
            thermal: None,
        };
        let c = data
            .simulate(&truth, &numerics(), &Nuisance::offset(0.0))
            .unwrap();
        data.amplitude_m = Some(c.amplitude_m);
        data.phase_deg = Some(c.phase_deg.clone());
        (
            fit(&truth, &numerics(), &data, &opts, |_| {}).unwrap(),
            c.phase_deg,
        )
    };
    let (attractive, phases) = fitted(span(18.5e-9, 8e-9, 16));
    assert!(phases.iter().all(|&p| p > 90.0), "{phases:?}");
    let eta = &attractive.parameters[2];
    assert_eq!(eta.name, "viscosity_pa_s");
    assert!(eta.value.is_none() && eta.interval_95.is_none(), "{eta:?}");
    let notes = attractive.identifiability.notes.join("\n");
    assert!(
        notes.contains("viscosity_pa_s does not change the data") && notes.contains("indents"),
        "{notes}"
    );
    // E* and Δγ are still seen (their values come back).
    assert!(attractive.parameters[..2].iter().all(|p| p.value.is_some()));
    let (repulsive, phases) = fitted(span(8e-9, 3e-9, 16));
    assert!(phases.iter().all(|&p| p < 90.0), "{phases:?}");
    let eta = &repulsive.parameters[2];
    let [lo, hi] = eta.interval_95.expect("identifiable where the tip indents");
    assert!(lo < 10.0 && 10.0 < hi, "[{lo}, {hi}]");
}

/// Phase against the amplitude setpoint, as phase imaging records it (no positions:
/// each point the state a z feedback finds at its setpoint, on the branch its phase
/// shows), noise-free at A/A₀ = 0.55 … 0.75 on the attractive branch of the hybrid
/// defaults and 0.75 … 0.93 on the repulsive (where each has stable period-1 states).
/// Such data fix the loss per cycle — sin φ follows from A/A₀ and E_ts, and the
/// hybrid's E_ts is its loop, Ŵ(μ)·μεRΔγ, wherever the loop is traversed — not E* and
/// Δγ apart: fitted together, both are reported unidentifiable, with the direction
/// along which they trade off. With E* known, Δγ comes back to 1e-6 from 20 % off.
#[test]
fn phases_at_setpoints_fix_the_loss_not_modulus_and_adhesion_apart() {
    let truth = default_setup();
    let ratios = vec![0.55, 0.6, 0.65, 0.7, 0.75, 0.75, 0.8, 0.85, 0.9, 0.93];
    // The first five on the attractive branch (φ above 90°), the rest repulsive.
    let guess: Vec<f64> = (0..10).map(|i| if i < 5 { 120.0 } else { 60.0 }).collect();
    let c = tapsim::fit::model::at_setpoints(&truth, &numerics(), &ratios, &guess).unwrap();
    assert!(
        c.phase_deg[..5].iter().all(|&p| p > 90.0),
        "{:?}",
        c.phase_deg
    );
    assert!(
        c.phase_deg[5..].iter().all(|&p| p < 90.0),
        "{:?}",
        c.phase_deg
    );
    let data = Measured {
        position_m: Vec::new(),
        setpoint_ratio: Some(ratios),
        second_mode: None,
        segments: vec![0],
        amplitude_m: None,
        phase_deg: Some(c.phase_deg),
        sigma_amplitude_m: SIGMA_A_M,
        sigma_phase_deg: SIGMA_PHI_DEG,
        thermal: None,
    };
    let opts = |parameters: Vec<Parameter>| fitting(parameters, 100);
    let mut start = truth.clone();
    start.contact.work_of_adhesion_j_m2 *= 0.8;
    let both = fit(
        &start,
        &numerics(),
        &data,
        &opts(vec![Parameter::Modulus, Parameter::WorkOfAdhesion]),
        |_| {},
    )
    .unwrap();
    assert!(
        both.parameters.iter().all(|p| p.value.is_none()),
        "{:?}",
        both.parameters
    );
    let notes = both.identifiability.notes.join("\n");
    assert!(notes.contains("trade off along"), "{notes}");
    let r = fit(
        &start,
        &numerics(),
        &data,
        &opts(vec![Parameter::WorkOfAdhesion]),
        |_| {},
    )
    .unwrap();
    assert!(r.converged, "{}", r.termination);
    let w = r.parameters[0].value.unwrap() / truth.contact.work_of_adhesion_j_m2 - 1.0;
    assert!(w.abs() < 1e-6, "{w:e}");
    assert!(r.parameters[0].interval_95.is_some());
    // The fitted states sit where the feedback would hold them (0 < z_c < A₀).
    assert!(r.fitted.separation_m.iter().all(|&z| z > 0.0 && z < 20e-9));
    // The offset is not a parameter of such data.
    let err = fit(
        &truth,
        &numerics(),
        &data,
        &opts(vec![Parameter::WorkOfAdhesion, Parameter::ZOffset]),
        |_| {},
    )
    .unwrap_err();
    assert!(err.to_string().contains("no offset"), "{err}");
}

/// Nuisance parameters. A detector reading amplitudes 3 % high (the free amplitude it
/// reports, 20.6 nm, included): with the sensitivity fitted beside E* and Δγ on an
/// approach over both branches (noise-free, 20 + 20 points), all three come back to
/// 1e-6. Add the spring constant k and the model has an exact symmetry, which the
/// report finds: scaling E*,
/// Δγ and k by one factor leaves the Tabor parameter and every force over kA₀ — so the
/// motion — unchanged; the three get no value and the direction along which they trade
/// off is (1, 1, 1)/√3 in their logarithms, while the sensitivity keeps its value.
#[test]
fn nuisance_parameters_are_fitted_and_the_stiffness_symmetry_is_found() {
    let truth = default_setup();
    let s = 1.03;
    let (far, near) = (span(18.5e-9, 8e-9, 20), span(12e-9, 4e-9, 20));
    // The true motion, read 3 % high.
    let (cf, cn) = (
        curve(&truth, &numerics(), &far, 0.0).unwrap(),
        curve(&truth, &numerics(), &near, 0.0).unwrap(),
    );
    let read = |c: &tapsim::fit::Curve| c.amplitude_m.iter().map(|a| a * s).collect::<Vec<_>>();
    let data = Measured {
        position_m: [far, near].concat(),
        setpoint_ratio: None,
        second_mode: None,
        segments: vec![0, 20],
        amplitude_m: Some([read(&cf), read(&cn)].concat()),
        phase_deg: Some([cf.phase_deg, cn.phase_deg].concat()),
        sigma_amplitude_m: SIGMA_A_M,
        sigma_phase_deg: SIGMA_PHI_DEG,
        thermal: None,
    };
    let mut start = truth.clone();
    start.cantilever.free_amplitude_m = 20e-9 * s;
    start.contact.modulus_pa *= 1.2;
    let opts = |parameters: Vec<Parameter>| fitting(parameters, 200);
    let r = fit(
        &start,
        &numerics(),
        &data,
        &opts(vec![
            Parameter::Modulus,
            Parameter::WorkOfAdhesion,
            Parameter::Sensitivity,
        ]),
        |_| {},
    )
    .unwrap();
    let truths = [truth.contact.modulus_pa, 0.1, s];
    for (p, t) in r.parameters.iter().zip(truths) {
        let v = p.value.unwrap();
        assert!((v / t - 1.0).abs() < 1e-6, "{}: {v} against {t}", p.name);
    }
    let r = fit(
        &start,
        &numerics(),
        &data,
        &opts(vec![
            Parameter::Modulus,
            Parameter::WorkOfAdhesion,
            Parameter::Stiffness,
            Parameter::Sensitivity,
        ]),
        |_| {},
    )
    .unwrap();
    assert!(
        r.parameters[..3].iter().all(|p| p.value.is_none()),
        "{:?}",
        r.parameters
    );
    assert!((r.parameters[3].value.unwrap() / s - 1.0).abs() < 1e-6);
    let w = &r.identifiability.weakest_direction;
    let sign = w[0].signum();
    for (k, c) in w[..3].iter().enumerate() {
        assert!(
            (sign * c - 1.0 / 3f64.sqrt()).abs() < 0.05,
            "component {k}: {w:?}"
        );
    }
    assert!(w[3].abs() < 0.05, "{w:?}");
    assert!(
        r.identifiability
            .notes
            .iter()
            .any(|n| n.contains("trade off along")),
        "{:?}",
        r.identifiability.notes
    );
}

/// A second eigenmode lifts the trade-off (bimodal AFM; the issue's "mode-2
/// channels"): an approach of the hybrid defaults with the beam's second mode driven to
/// 0.5 nm (16 points from 16.5 to 8.5 nm, both modes simulated, noise-free), fitted
/// for E*, Δγ and ε from the truth. With the first mode's amplitude and phase alone, E*
/// and Δγ correlate above 0.95 (a trade-off, named); adding the second mode's amplitude
/// and phase brings that below 0.8 and shrinks both standard errors more than fivefold
/// (the second mode's phase follows the force gradient the first averages over). From
/// a start 20 % off in E* and Δγ the fit with both modes gives back the truth to 1e-6.
#[test]
#[ignore = "slow (two-mode approach curves, about 16 s in release): run with cargo test --release -- --ignored fit::"]
fn a_second_mode_lifts_the_trade_off_between_modulus_and_adhesion() {
    use tapsim::dynamics::modes::ModeSet;
    use tapsim::fit::SecondMode;
    let truth = default_setup();
    let modes = ModeSet::euler_bernoulli(&truth.cantilever, 2).unwrap();
    let position_m = span(16.5e-9, 8.5e-9, 16);
    let c = tapsim::fit::model::modal_curve(&truth, &numerics(), &modes, &position_m, 0.0).unwrap();
    assert!(c.well_defined.iter().all(|&w| w));
    let data = |with_second: bool| Measured {
        position_m: position_m.clone(),
        setpoint_ratio: None,
        segments: vec![0],
        amplitude_m: Some(c.amplitude_m.clone()),
        phase_deg: Some(c.phase_deg.clone()),
        sigma_amplitude_m: SIGMA_A_M,
        sigma_phase_deg: SIGMA_PHI_DEG,
        second_mode: Some(SecondMode {
            modes: modes.clone(),
            amplitude_m: with_second.then(|| c.amplitude2_m.clone()),
            phase_deg: with_second.then(|| c.phase2_deg.clone()),
            sigma_amplitude_m: SIGMA_A_M,
            sigma_phase_deg: SIGMA_PHI_DEG,
        }),
        thermal: None,
    };
    let opts = fitting(
        vec![
            Parameter::Modulus,
            Parameter::WorkOfAdhesion,
            Parameter::Range,
        ],
        100,
    );
    let first = fit(&truth, &numerics(), &data(false), &opts, |_| {}).unwrap();
    let both = fit(&truth, &numerics(), &data(true), &opts, |_| {}).unwrap();
    let corr = |r: &tapsim::fit::FitReport| r.identifiability.correlations[0][1].unwrap();
    let rel = |r: &tapsim::fit::FitReport, k: usize| {
        r.parameters[k].std_err.unwrap() / r.parameters[k].value.unwrap()
    };
    eprintln!(
        "first mode: corr {:+.3}, E* ±{:.2} %, Δγ ±{:.2} %; both: corr {:+.3}, E* ±{:.2} %, \
         Δγ ±{:.2} %",
        corr(&first),
        100.0 * rel(&first, 0),
        100.0 * rel(&first, 1),
        corr(&both),
        100.0 * rel(&both, 0),
        100.0 * rel(&both, 1)
    );
    assert!(corr(&first).abs() > 0.95);
    // The guide: +0.978 and −0.590; ±1.16 %, ±1.34 % and ±0.14 %, ±0.14 %.
    assert_eq!(
        format!(
            "{:+.3} {:+.3} {:.2} {:.2} {:.2} {:.2}",
            corr(&first),
            corr(&both),
            100.0 * rel(&first, 0),
            100.0 * rel(&first, 1),
            100.0 * rel(&both, 0),
            100.0 * rel(&both, 1)
        ),
        "+0.978 -0.590 1.16 1.34 0.14 0.14"
    );
    assert!(
        first
            .identifiability
            .notes
            .iter()
            .any(|n| n.contains("trade off"))
    );
    assert!(corr(&both).abs() < 0.8);
    for k in 0..2 {
        assert!(rel(&both, k) < rel(&first, k) / 5.0);
    }
    let mut start = truth.clone();
    start.contact.modulus_pa *= 1.2;
    start.contact.work_of_adhesion_j_m2 *= 0.8;
    let r = fit(&start, &numerics(), &data(true), &opts, |_| {}).unwrap();
    let truths = [truth.contact.modulus_pa, 0.1, 0.3e-9];
    for (p, t) in r.parameters.iter().zip(truths) {
        let v = p.value.unwrap();
        assert!((v / t - 1.0).abs() < 1e-6, "{}: {v} against {t}", p.name);
    }
}

/// The profile likelihood of E* and Δγ (each held, the others refitted) against the
/// linearised intervals on the noisy data above: the model is nearly straight over
/// them here, so the two agree — each endpoint within 5 % of the interval's half-width.
#[test]
#[ignore = "slow (some 20 fits in release): run with cargo test --release -- --ignored fit::"]
fn profile_intervals_meet_the_linearised_ones_where_the_model_is_straight() {
    use tapsim::fit::profile;
    let truth = default_setup();
    let data = measured(&truth, &positions(30), 7);
    let opts = options(OFFSET_M);
    let best = fit(&truth, &numerics(), &data, &opts, |_| {}).unwrap();
    for which in [Parameter::Modulus, Parameter::WorkOfAdhesion] {
        let p = profile(&truth, &numerics(), &data, &opts, &best, which, |_| {}).unwrap();
        let lin = best.parameters.iter().find(|e| e.name == p.name).unwrap();
        for (prof, lin) in [
            (p.interval_68, lin.interval_68.unwrap()),
            (p.interval_95, lin.interval_95.unwrap()),
        ] {
            let half = 0.5 * (lin[1] - lin[0]);
            eprintln!("{}: profile {prof:?}, linearised {lin:?}", p.name);
            for (a, b) in prof.iter().zip(lin) {
                assert!((a.unwrap() - b).abs() < 0.05 * half);
            }
        }
    }
}

/// Coverage: over 200 replicas of the noise (seeds 1000–1199), each fitted from the
/// truth, the 68 % intervals of E* and of Δγ hold the truth in 68 ± 5 % of them — the
/// stated errors are the errors.
#[test]
#[ignore = "slow (200 fits in release, about a minute on two cores): run with cargo test --release -- --ignored fit::"]
fn the_68_percent_intervals_cover_the_truth_in_68_percent_of_replicas() {
    use rayon::prelude::*;
    let truth = default_setup();
    let pos = positions(30);
    let covered: Vec<(bool, bool)> = (1000..1200u64)
        .into_par_iter()
        .map(|seed| {
            let data = measured(&truth, &pos, seed);
            let r = fit(&truth, &numerics(), &data, &options(OFFSET_M), |_| {}).unwrap();
            let inside = |k: usize, t: f64| {
                let [lo, hi] = r.parameters[k].interval_68.unwrap();
                lo <= t && t <= hi
            };
            (
                inside(0, truth.contact.modulus_pa),
                inside(1, truth.contact.work_of_adhesion_j_m2),
            )
        })
        .collect();
    let share = |f: &dyn Fn(&(bool, bool)) -> bool| {
        covered.iter().filter(|c| f(c)).count() as f64 / covered.len() as f64
    };
    let (e, w) = (share(&|c| c.0), share(&|c| c.1));
    eprintln!(
        "68 % intervals cover E* in {:.1} %, Δγ in {:.1} %",
        100.0 * e,
        100.0 * w
    );
    assert!((e - 0.68).abs() <= 0.05, "E*: {e}");
    assert!((w - 0.68).abs() <= 0.05, "Δγ: {w}");
    // The guide: 68.0 % and 67.5 % (these seeds).
    assert_eq!((e, w), (0.68, 0.675));
}

/// A degeneracy, flagged and lifted (the test): fitting E*, Δγ and ε to an
/// approach that reaches the repulsive branch (begun at z_c = 8 nm, down to 2 nm), the
/// three trade off — E_ts ∝ Ŵ(μ)·μεRΔγ and the contact's stiffness move together —
/// and the report names the pairs; the condition number is above 1000. Adding an
/// approach from far (18.5 to 8 nm, the attractive branch) lifts it: the condition
/// number falls more than tenfold (measured 1125 → 11).
#[test]
fn a_degeneracy_on_the_repulsive_branch_is_flagged_and_the_attractive_branch_lifts_it() {
    let truth = default_setup();
    let opts = fitting(
        vec![
            Parameter::Modulus,
            Parameter::WorkOfAdhesion,
            Parameter::Range,
        ],
        60,
    );
    let assess = |position_m: Vec<f64>, segments: Vec<usize>| {
        let mut data = Measured {
            position_m,
            setpoint_ratio: None,
            second_mode: None,
            segments,
            amplitude_m: None,
            phase_deg: None,
            sigma_amplitude_m: SIGMA_A_M,
            sigma_phase_deg: SIGMA_PHI_DEG,
            thermal: None,
        };
        let c = data
            .simulate(&truth, &numerics(), &Nuisance::offset(0.0))
            .unwrap();
        assert!(c.well_defined.iter().all(|&w| w));
        data.amplitude_m = Some(c.amplitude_m);
        data.phase_deg = Some(c.phase_deg.clone());
        (
            fit(&truth, &numerics(), &data, &opts, |_| {}).unwrap(),
            c.phase_deg,
        )
    };
    let (repulsive, phases) = assess(span(8e-9, 2e-9, 20), vec![0]);
    assert!(phases.iter().all(|&p| p < 90.0), "{phases:?}");
    let mut both = span(18.5e-9, 8e-9, 20);
    both.extend(span(8e-9, 2e-9, 20));
    let (combined, phases) = assess(both, vec![0, 20]);
    assert!(phases[..20].iter().all(|&p| p > 90.0), "{phases:?}");
    let (c_rep, c_both) = (
        repulsive.identifiability.condition_number.unwrap(),
        combined.identifiability.condition_number.unwrap(),
    );
    eprintln!("condition number: repulsive {c_rep:.1}, with the attractive branch {c_both:.1}");
    let notes = repulsive.identifiability.notes.join("\n");
    assert!(
        notes.contains("work_of_adhesion_j_m2 and range_m trade off"),
        "{notes}"
    );
    assert!(c_both < c_rep / 10.0);
    // The guide: 1125 and 11.
    assert_eq!((c_rep.round(), c_both.round()), (1125.0, 11.0));
}

/// Assert that `r` gives no standard error or interval for any parameter, and that a
/// note says why (holding `why`).
fn gives_no_intervals_because(r: &tapsim::fit::FitReport, why: &str) {
    for p in &r.parameters {
        assert!(
            p.std_err.is_none() && p.interval_68.is_none() && p.interval_95.is_none(),
            "{p:?}"
        );
    }
    let notes = r.identifiability.notes.join(" ");
    assert!(notes.contains(why), "{notes}");
}

/// Issue 43: a curve of long mode locks (JKR on the defaults' approach from 24 to 8 nm,
/// 12 points, nine of them mode locks or grazing touches), fitted with the law that made
/// it from the truth: the fit gives no intervals and says why. Their values step as the
/// parameters move; the linearised intervals claimed 1e-4 while a fit of the 60-point
/// curve from 5 % off ended 26 % from the truth with χ²/dof 1.3.
#[test]
fn a_curve_of_mode_locks_gets_no_intervals() {
    let mut truth = default_setup();
    truth.law.kind = tapsim::law::LawKind::Jkr;
    let z: Vec<f64> = span(24e-9, 8e-9, 12).iter().map(|z| z - OFFSET_M).collect();
    let (clean, data) = noisy(&truth, &z, 5);
    let unsettled = clean.well_defined.iter().filter(|w| !**w).count();
    assert!(4 * unsettled > z.len(), "{:?}", clean.well_defined);
    let options = FitOptions {
        start: Nuisance::offset(OFFSET_M),
        ..fitting(vec![Parameter::Modulus, Parameter::WorkOfAdhesion], 100)
    };
    let r = fit(&truth, &numerics(), &data, &options, |_| {}).unwrap();
    // (The data are described: without the locks' account the intervals would be
    // given.)
    assert!(r.diagnosis.describes_data, "{:?}", r.diagnosis.reasons);
    gives_no_intervals_because(&r, "mode locks or graze");
}

/// Issue 43: the same curve of long mode locks read at 300 K, each lock the thermal
/// average an instrument reads (the data's noise seed 99 and 0.02 nm, 0.05° on top; the
/// model's seed 1), fitted with the temperature from the truth: every point is kept and
/// nine are averages, yet no intervals are given and the fit says why — the averages'
/// noise moves with the parameters and ripples χ². (A fit of these data from 5 % off
/// ended at +9 % in E* and Δγ with χ²/dof 1.4, intervals 5 σ from the truth.)
#[test]
#[ignore = "slow (a fit of thermal averages, about a minute in release): run with cargo test --release -- --ignored fit::"]
fn a_curve_of_thermal_averages_gets_no_intervals() {
    use tapsim::instrument::average::AverageRequest;
    let mut truth = default_setup();
    truth.law.kind = tapsim::law::LawKind::Jkr;
    let z: Vec<f64> = span(24e-9, 8e-9, 12).iter().map(|z| z - OFFSET_M).collect();
    let at = |seed| AverageRequest {
        temperature_k: 300.0,
        periods: 800,
        seed,
    };
    let read = tapsim::fit::model::curve_while(
        &truth,
        &numerics(),
        &z,
        OFFSET_M,
        Some(&at(99)),
        |_, _| true,
    )
    .unwrap();
    let averaged = read.averaged.iter().filter(|a| **a).count();
    assert!(4 * averaged > z.len(), "{:?}", read.averaged);
    let (clean, mut data) = noisy(&truth, &z, 5);
    for (i, (a, p)) in data
        .amplitude_m
        .iter_mut()
        .flatten()
        .zip(data.phase_deg.iter_mut().flatten())
        .enumerate()
    {
        *a += read.amplitude_m[i] - clean.amplitude_m[i];
        *p += read.phase_deg[i] - clean.phase_deg[i];
    }
    data.thermal = Some(at(1));
    let options = FitOptions {
        start: Nuisance::offset(OFFSET_M),
        ..fitting(vec![Parameter::Modulus, Parameter::WorkOfAdhesion], 12)
    };
    let r = fit(&truth, &numerics(), &data, &options, |_| {}).unwrap();
    assert!(r.left_out.is_empty(), "{:?}", r.left_out);
    assert!(4 * r.fitted.averaged.iter().filter(|a| **a).count() > z.len());
    assert!(r.fitted.well_defined.iter().all(|w| *w));
    gives_no_intervals_because(&r, "thermal averages");
}
