//! The fit on the curve users record most (issue 43): an approach from far that jumps
//! from the attractive to the repulsive branch on the way in. The global stage and the
//! split at the data's branch jump bring every start back; a law that cannot describe
//! the data gets a verdict, not intervals; the laws are ranked by AIC.

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use tapsim::dynamics::setup::{Numerics, TapSetup, default_setup};
use tapsim::fit::{FitOptions, Measured, Nuisance, Parameter, Search, compare, fit, model::curve};
use tapsim::law::{LawKind, LawSpec};
use tapsim::sweep::sweep_numerics;

/// The piezo's zero lies 3 nm from the rest separation's.
const OFFSET_M: f64 = 3e-9;
const SIGMA_A_M: f64 = 0.02e-9;
const SIGMA_PHI_DEG: f64 = 0.05;

fn numerics() -> Numerics {
    sweep_numerics(Numerics::default(), (false, false))
}

/// The issue's setup: E* = 0.8 GPa, Δγ = 0.07 J/m², the hybrid law, the built-in lever.
fn issue_setup(modulus_pa: f64, work_j_m2: f64) -> TapSetup {
    let mut s = default_setup();
    s.contact.modulus_pa = modulus_pa;
    s.contact.work_of_adhesion_j_m2 = work_j_m2;
    s
}

/// `n` piezo positions of an approach from z_c = 24 nm to 8 nm.
fn positions(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| 24e-9 - 16e-9 * i as f64 / (n - 1) as f64 - OFFSET_M)
        .collect()
}

/// The approach of `truth` at `positions`, noise from `seed` (none for seed 0).
fn measured(truth: &TapSetup, positions: &[f64], seed: u64) -> Measured {
    let c = curve(truth, &numerics(), positions, OFFSET_M).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let (na, np) = (
        Normal::new(0.0, SIGMA_A_M).unwrap(),
        Normal::new(0.0, SIGMA_PHI_DEG).unwrap(),
    );
    let noisy = seed != 0;
    Measured {
        position_m: positions.to_vec(),
        setpoint_ratio: None,
        second_mode: None,
        segments: vec![0],
        amplitude_m: Some(
            c.amplitude_m
                .iter()
                .map(|a| a + if noisy { na.sample(&mut rng) } else { 0.0 })
                .collect(),
        ),
        phase_deg: Some(
            c.phase_deg
                .iter()
                .map(|p| p + if noisy { np.sample(&mut rng) } else { 0.0 })
                .collect(),
        ),
        sigma_amplitude_m: SIGMA_A_M,
        sigma_phase_deg: SIGMA_PHI_DEG,
        thermal: None,
    }
}

fn options() -> FitOptions {
    FitOptions::new(
        vec![
            Parameter::Modulus,
            Parameter::WorkOfAdhesion,
            Parameter::ZOffset,
        ],
        0.0,
    )
}

/// The phase falls from above the free phase to below it once on the way in.
fn jumps_once(data: &Measured) -> bool {
    let p = data.phase_deg.as_ref().unwrap();
    p.windows(2).filter(|w| w[0] > 95.0 && w[1] < 85.0).count() == 1
}

/// The issue's curve (E* 0.8 GPa, Δγ 0.07 J/m², 40 points 24 → 8 nm, 0.02 nm and
/// 0.05° of noise) and one whose jump lies elsewhere (E* 0.5 GPa, Δγ 0.05 J/m²), each
/// fitted from starts 0.5× and 2× the truth in both parameters (the offset from 0, 3 nm
/// off): every start ends within 1 % of the truth, χ²/dof within [0.5, 2], the 95 %
/// intervals hold the truth, and the fit is called converged. Before the global stage
/// these fits ended at E* ≈ 0.35 GPa with χ²/dof ≈ 8·10⁵ and called it converged.
#[test]
#[ignore = "slow (eight fits with their global stage, about two minutes in release): run with cargo test --release -- --ignored fit_global::"]
fn a_branch_jumping_curve_is_fitted_back_from_starts_half_and_twice_the_truth() {
    for (e, w, seed) in [(0.8e9, 0.07, 11), (0.5e9, 0.05, 12)] {
        let truth = issue_setup(e, w);
        let data = measured(&truth, &positions(40), seed);
        assert!(jumps_once(&data), "{:?}", data.phase_deg);
        for (fe, fw) in [(0.5, 0.5), (2.0, 2.0), (0.5, 2.0), (2.0, 0.5)] {
            let start = issue_setup(e * fe, w * fw);
            let r = fit(&start, &numerics(), &data, &options(), |_| {}).unwrap();
            let v: Vec<f64> = r.parameters.iter().map(|p| p.value.unwrap()).collect();
            eprintln!(
                "truth ({e:e}, {w}) start ×({fe}, {fw}): {v:?}, χ²/dof {:.3}, {} curves",
                r.reduced_chi_square, r.curves
            );
            assert!(
                r.converged,
                "{}: {:?} {:?}",
                r.termination, r.diagnosis.reasons, r.minima
            );
            assert!((v[0] / e - 1.0).abs() < 0.01, "{v:?}");
            assert!((v[1] / w - 1.0).abs() < 0.01, "{v:?}");
            assert!((0.5..=2.0).contains(&r.reduced_chi_square));
            for (p, t) in r.parameters.iter().zip([e, w, OFFSET_M]) {
                let [lo, hi] = p.interval_95.unwrap();
                assert!(lo <= t && t <= hi, "{}: {t} outside [{lo}, {hi}]", p.name);
            }
        }
    }
}

/// `tapsim fit --help`'s own example: the hybrid defaults' attractive branch (18.5 → 8
/// nm, 30 points, noise-free) fitted from E* = 1 GPa and Δγ = 0.2 J/m² (truth 0.593 GPa
/// and 0.1 J/m²): back to 1 % — it used to stall at the start after 138 curves and call
/// that convergence.
#[test]
#[ignore = "slow (a fit with its global stage, some 5 s in release): run with cargo test --release -- --ignored fit_global::"]
fn the_help_example_fits_to_one_percent() {
    let truth = default_setup();
    let z: Vec<f64> = (0..30)
        .map(|i| 18.5e-9 - 10.5e-9 * i as f64 / 29.0)
        .collect();
    let c = curve(&truth, &numerics(), &z, 0.0).unwrap();
    let data = Measured {
        amplitude_m: Some(c.amplitude_m),
        phase_deg: Some(c.phase_deg),
        ..measured(&truth, &z, 0)
    };
    let start = issue_setup(1e9, 0.2);
    let r = fit(&start, &numerics(), &data, &options(), |_| {}).unwrap();
    let v: Vec<f64> = r.parameters.iter().map(|p| p.value.unwrap()).collect();
    assert!(
        (v[0] / truth.contact.modulus_pa - 1.0).abs() < 0.01,
        "{v:?}"
    );
    assert!((v[1] / 0.1 - 1.0).abs() < 0.01, "{v:?}");
    assert!(r.converged, "{}", r.termination);
}

/// Data from the hybrid law fitted with DMT, a law that cannot describe them: the fit
/// is not called converged, gives no interval, and says why (residuals of one sign, the
/// worst points) — its trials outside the law's range refused as steps.
#[test]
fn a_law_that_cannot_describe_the_data_gets_a_verdict_not_intervals() {
    let truth = default_setup();
    let z: Vec<f64> = (0..12).map(|i| 18.5e-9 - 0.95e-9 * i as f64).collect();
    let data = measured(&truth, &z, 5);
    let mut dmt = truth.clone();
    dmt.law = LawSpec::from_values(LawKind::Dmt, [None; tapsim::law::LAW_PARAMS.len()]);
    dmt.contact.work_of_adhesion_j_m2 = 0.02;
    let options = FitOptions {
        search: Search::Local,
        max_curves: 60,
        ..FitOptions::new(vec![Parameter::Modulus], OFFSET_M)
    };
    let r = fit(&dmt, &numerics(), &data, &options, |_| {}).unwrap();
    assert!(!r.converged);
    assert!(!r.diagnosis.describes_data);
    assert!(!r.diagnosis.reasons.is_empty());
    assert_eq!(r.diagnosis.worst_points.len(), 3);
    assert!(r.parameters.iter().all(|p| p.interval_95.is_none()));
    // χ² far above its distribution, said in words.
    assert!(r.reduced_chi_square > 100.0);
    assert!(
        r.diagnosis.reasons.iter().any(|s| s.contains("χ²/dof")),
        "{:?}",
        r.diagnosis.reasons
    );
}

/// A phase channel with an offset (3°, as electronics set it) is fitted back as a
/// nuisance parameter beside E* (noise-free, to 1e-3° and a fifth of its standard
/// error): the free points far from the sample fix it.
#[test]
fn a_phase_offset_is_fitted_back() {
    let truth = default_setup();
    let z: Vec<f64> = (0..12).map(|i| 24e-9 - 1.4e-9 * i as f64).collect();
    let mut data = measured(&truth, &z, 0);
    for p in data.phase_deg.iter_mut().flatten() {
        *p += 3.0;
    }
    let mut start = truth.clone();
    start.contact.modulus_pa *= 1.1;
    let options = FitOptions {
        search: Search::Local,
        ..FitOptions::new(vec![Parameter::Modulus, Parameter::PhaseOffset], OFFSET_M)
    };
    let r = fit(&start, &numerics(), &data, &options, |_| {}).unwrap();
    let v: Vec<f64> = r.parameters.iter().map(|p| p.value.unwrap()).collect();
    let why = format!("{v:?}: {} (χ² {:e})", r.termination, r.chi_square);
    assert!(r.converged, "{why}");
    // Noise-free: at the truth to a small fraction of the standard errors 0.02 nm and
    // 0.05° of noise would give.
    for (p, t) in r.parameters.iter().zip([truth.contact.modulus_pa, 3.0]) {
        let e = p.std_err.unwrap();
        assert!(
            (p.value.unwrap() - t).abs() < 0.2 * e,
            "{}: {why}, σ {e}",
            p.name
        );
    }
    assert!((v[1] - 3.0).abs() < 1e-3, "{why}");
}

/// Law selection: data simulated with the hybrid law (the issue's curve) and fitted
/// with hybrid and JKR prefer the hybrid law decisively; data simulated with JKR (E*
/// 0.3 GPa, Δγ 0.02 J/m², μ = 1.49: period-1 along the curve) prefer JKR; a curve
/// that never reaches the sample (both laws give the free oscillation) cannot tell
/// them apart, and the verdict says so.
#[test]
#[ignore = "slow (six fits, about three minutes in release): run with cargo test --release -- --ignored fit_global::"]
fn the_law_that_made_the_data_is_preferred() {
    let law = |k| LawSpec::from_values(k, [None; tapsim::law::LAW_PARAMS.len()]);
    let cases = [
        (
            LawKind::Hybrid,
            (0.8e9, 0.07),
            (0.6e9, 0.1),
            (24e-9, 8e-9),
            Some(LawKind::Hybrid),
        ),
        (
            LawKind::Jkr,
            (0.3e9, 0.02),
            (0.4e9, 0.03),
            (24e-9, 8e-9),
            Some(LawKind::Jkr),
        ),
        (
            LawKind::Hybrid,
            (0.8e9, 0.07),
            (0.6e9, 0.1),
            (40e-9, 30e-9),
            None,
        ),
    ];
    for (made_by, (e, w), (e0, w0), (from, to), preferred) in cases {
        let mut truth = issue_setup(e, w);
        truth.law = law(made_by);
        let z: Vec<f64> = (0..40)
            .map(|i| from - (from - to) * i as f64 / 39.0 - OFFSET_M)
            .collect();
        let data = measured(&truth, &z, 21);
        let mut fits = Vec::new();
        for k in [LawKind::Hybrid, LawKind::Jkr] {
            let mut start = issue_setup(e0, w0);
            start.law = law(k);
            let r = fit(&start, &numerics(), &data, &options(), |_| {}).unwrap();
            fits.push((start.law.to_string(), r));
        }
        let c = compare(&fits.iter().map(|(n, r)| (n.clone(), r)).collect::<Vec<_>>());
        eprintln!("made by {made_by:?}, {from:e} to {to:e} m: {}", c.verdict);
        match preferred {
            Some(k) => {
                assert_eq!(c.ranking[0].law, law(k).to_string(), "{}", c.verdict);
                assert!(c.decided, "{}", c.verdict);
                assert!(c.ranking[1].delta_aic > 10.0, "{}", c.verdict);
            }
            None => {
                assert!(!c.decided, "{}", c.verdict);
                assert!(c.verdict.contains("cannot tell"), "{}", c.verdict);
            }
        }
    }
}

/// A profile whose trials leave the law's range (the hybrid law at μ ≈ 1.24, near its
/// lower end, with noise of 1 nm and 3° making the steps wide) is not the end of the
/// fit: the values the law cannot take are points without a value, that side of the
/// profile stops, and the other side still gives its interval.
#[test]
#[ignore = "slow (a profile of some ten fits, about 10 s in release): run with cargo test --release -- --ignored fit_global::"]
fn a_profile_survives_a_trial_outside_the_law() {
    let truth = issue_setup(default_setup().contact.modulus_pa, 0.03);
    let z: Vec<f64> = (0..20).map(|i| 24e-9 - 16e-9 * i as f64 / 19.0).collect();
    let mut data = measured(&truth, &z, 0);
    data.sigma_amplitude_m = 1e-9;
    data.sigma_phase_deg = 3.0;
    let options = FitOptions {
        search: Search::Local,
        ..options()
    };
    let options = FitOptions {
        start: Nuisance::offset(OFFSET_M),
        ..options
    };
    let best = fit(&truth, &numerics(), &data, &options, |_| {}).unwrap();
    let p = tapsim::fit::profile(
        &truth,
        &numerics(),
        &data,
        &options,
        &best,
        Parameter::WorkOfAdhesion,
        |_| {},
    )
    .unwrap();
    eprintln!("{p:?}");
    assert!(!p.unavailable.is_empty(), "{p:?}");
    // Below the estimate the law ends (μ falls with Δγ); above, the interval closes.
    assert!(p.unavailable.iter().all(|&v| v < 0.03));
    assert!(p.interval_68[1].is_some_and(|hi| hi > 0.03));
}

/// Coverage on the branch-jumping curve: over 100 noisy replicas of the issue's curve
/// (E* 0.8 GPa, Δγ 0.07 J/m², 40 points, 0.02 nm and 0.05°), fitted from near the
/// truth, every fit converges and both 68 % intervals hold the truth in 68 ± 7 % of them
/// (a binomial's standard deviation at 100 replicas is 4.7 %; measured: E* 66, pulls
/// +0.07 ± 0.97; Δγ 72, pulls +0.14 ± 1.03). The curve's first touching point grazes
/// the jump-in: every fit leaves it out (its state at the fitted parameters is one draw
/// among coexisting ones, a step in Δγ the linearised intervals cannot see). With it
/// kept, Δγ's interval held the truth in 58 of 100, its pulls +0.28 ± 2.02 with tails to
/// −11 and +5.5.
#[test]
#[ignore = "slow (100 fits, about two minutes in release on two cores): run with cargo test --release -- --ignored fit_global::"]
fn the_intervals_cover_the_branch_jumping_truth_in_68_percent_of_replicas() {
    use rayon::prelude::*;
    let (e, w) = (0.8e9, 0.07);
    let truth = issue_setup(e, w);
    let z = positions(40);
    let start = issue_setup(e * 1.05, w * 0.95);
    let options = FitOptions {
        search: Search::Local,
        start: Nuisance::offset(OFFSET_M + 0.1e-9),
        ..options()
    };
    // Per replica: whether each 68 % interval holds the truth, and the pull
    // (estimate − truth)/standard error.
    let held: Vec<([bool; 2], [f64; 2])> = (0..100u64)
        .into_par_iter()
        .map(|seed| {
            let data = measured(&truth, &z, 1000 + seed);
            let r = fit(&start, &numerics(), &data, &options, |_| {}).unwrap();
            assert!(r.converged, "seed {seed}: {}", r.termination);
            // The first touching point (the ninth) and no other.
            assert_eq!(r.left_out, [8], "seed {seed}");
            let inside = |k: usize, t: f64| {
                let [lo, hi] = r.parameters[k].interval_68.unwrap();
                lo <= t && t <= hi
            };
            let pull = |k: usize, t: f64| {
                let p = &r.parameters[k];
                (p.value.unwrap() - t) / p.std_err.unwrap()
            };
            ([inside(0, e), inside(1, w)], [pull(0, e), pull(1, w)])
        })
        .collect();
    for (k, name) in ["E*", "Δγ"].iter().enumerate() {
        let n = held.iter().filter(|h| h.0[k]).count();
        let pulls: Vec<f64> = held.iter().map(|h| h.1[k]).collect();
        let mean = pulls.iter().sum::<f64>() / 100.0;
        let sd = (pulls.iter().map(|p| (p - mean).powi(2)).sum::<f64>() / 99.0).sqrt();

        eprintln!(
            "{name}: the 68 % interval holds the truth in {n} of 100 replicas; pulls {mean:+.3} ± {sd:.3}"
        );
        assert!((61..=75).contains(&n), "{name}: {n} of 100");
    }
}

/// Issue 43 item 6: the branch-jumping curve read at 300 K. Its onset of contact grazes
/// a switch — no instrument reads a deterministic state there — so the data hold the
/// thermal average at that point (made with noise of their own, seed 99, plus the
/// channels' noise). Fitted with the temperature (the model's averages from seed 1, so
/// the two agree only within their standard errors), the point is kept and read as an
/// average, its standard error added to σ; the fit ends at the truth within its 95 %
/// intervals with χ²/dof in [0.5, 2]. Without the temperature the same point is left
/// out as a draw among coexisting states. The model's average at the truth agrees with
/// the data's (independent noise) within four standard errors of their difference.
#[test]
fn the_onset_read_at_a_temperature_is_fitted_as_its_thermal_average() {
    use tapsim::instrument::average::AverageRequest;
    use tapsim::sweep::{Direction, approach_curve_at};
    let truth = issue_setup(0.8e9, 0.07);
    let z = positions(40);
    let ramp: Vec<(f64, Direction)> = z
        .iter()
        .map(|p| (p + OFFSET_M, Direction::Approach))
        .collect();
    let at = |seed| AverageRequest {
        temperature_k: 300.0,
        periods: 2000,
        seed,
    };
    let read = approach_curve_at(&truth, &numerics(), &ramp, Some(&at(99)), |_, _| {}).unwrap();
    let averaged: Vec<usize> = (0..read.len())
        .filter(|&i| read[i].thermal_average.is_some())
        .collect();
    assert!(!averaged.is_empty(), "the onset grazes nowhere");
    let a0 = truth.cantilever.free_amplitude_m;
    let mut data = measured(&truth, &z, 21);
    let clean = measured(&truth, &z, 0);
    for &i in &averaged {
        let t = read[i].thermal_average.unwrap();
        let (a, p) = (
            data.amplitude_m.as_mut().unwrap(),
            data.phase_deg.as_mut().unwrap(),
        );
        a[i] += t.amplitude_ratio * a0 - clean.amplitude_m.as_ref().unwrap()[i];
        p[i] += t.phase_deg - clean.phase_deg.as_ref().unwrap()[i];
    }
    let options = FitOptions {
        search: Search::Local,
        ..FitOptions::new(
            vec![
                Parameter::Modulus,
                Parameter::WorkOfAdhesion,
                Parameter::ZOffset,
            ],
            OFFSET_M,
        )
    };
    let start = issue_setup(0.8e9 * 1.05, 0.07 * 1.05);
    let without = fit(&start, &numerics(), &data, &options, |_| {}).unwrap();
    assert_eq!(without.left_out, averaged, "the grazing onset is left out");
    data.thermal = Some(at(1));
    // The model's average at the truth against the data's, each with its own noise.
    let model = data
        .simulate(&truth, &numerics(), &Nuisance::offset(OFFSET_M))
        .unwrap();
    for &i in &averaged {
        let t = read[i].thermal_average.unwrap();
        assert!(model.averaged[i]);
        let se = t.phase_std_err_deg.hypot(model.phase_std_err_deg[i]);
        assert!(
            (model.phase_deg[i] - t.phase_deg).abs() < 4.0 * se,
            "point {i}: {} against {} ± {se}",
            model.phase_deg[i],
            t.phase_deg
        );
    }
    let r = fit(&start, &numerics(), &data, &options, |_| {}).unwrap();
    eprintln!(
        "with 300 K: {:?}, χ²/dof {:.3}, {} curves; without: {:?}",
        r.parameters
            .iter()
            .map(|p| (p.value, p.std_err))
            .collect::<Vec<_>>(),
        r.reduced_chi_square,
        r.curves,
        without
            .parameters
            .iter()
            .map(|p| (p.value, p.std_err))
            .collect::<Vec<_>>()
    );
    assert!(r.left_out.is_empty(), "{:?}", r.left_out);
    for &i in &averaged {
        assert!(
            r.fitted.averaged[i] && r.fitted.well_defined[i],
            "point {i}"
        );
        assert!(r.fitted.phase_std_err_deg[i] > 0.0);
    }
    assert!(r.converged, "{}: {:?}", r.termination, r.diagnosis.reasons);
    assert!(
        (0.5..=2.0).contains(&r.reduced_chi_square),
        "{}",
        r.reduced_chi_square
    );
    for (p, t) in r.parameters.iter().zip([0.8e9, 0.07, OFFSET_M]) {
        let [lo, hi] = p.interval_95.unwrap();
        assert!(lo <= t && t <= hi, "{}: {t} outside [{lo}, {hi}]", p.name);
    }
}

/// The global stage's best-ranked start on the issue's curve (from half E* and twice
/// Δγ) heads for a wrong minimum (E* ≈ 1.34 GPa, χ²/dof ≈ 134) and crawls there — χ²
/// from 10 051 to 10 034 over sixty curves. It is cut once χ² falls by less than 1 %
/// over three iterations far from the data, listed as cut, and the next start reaches
/// the truth: the fit ends within 1 % of it.
#[test]
#[ignore = "slow (a 40-point fit with its global stage, about 13 s in release): run with cargo test --release -- --ignored fit_global::"]
fn a_start_that_crawls_far_from_the_data_is_cut() {
    let truth = issue_setup(0.8e9, 0.07);
    let data = measured(&truth, &positions(40), 11);
    let start = issue_setup(0.4e9, 0.14);
    let r = fit(&start, &numerics(), &data, &options(), |_| {}).unwrap();
    let v: Vec<f64> = r.parameters.iter().map(|p| p.value.unwrap()).collect();
    assert!((v[0] / 0.8e9 - 1.0).abs() < 0.01, "{v:?}");
    assert!((v[1] / 0.07 - 1.0).abs() < 0.01, "{v:?}");
    assert!(r.converged, "{}", r.termination);
    let cut: Vec<_> = r
        .minima
        .iter()
        .filter(|m| m.cut_short && m.termination.starts_with("cut: χ² fell"))
        .collect();
    assert_eq!(cut.len(), 1, "{:?}", r.minima);
    assert!(cut[0].reduced_chi_square > 100.0, "{:?}", cut[0]);
}
