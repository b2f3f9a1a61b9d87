//! Tests of `tapsim::analysis::fit::search` (src/analysis/fit/search.rs).

use tapsim::analysis::fit::features::Features;
use tapsim::analysis::fit::model::{Measured, Nuisance, Parameter};
use tapsim::analysis::fit::progress::Tracker;
use tapsim::analysis::fit::search::*;
use tapsim::dynamics::setup::Numerics;
use tapsim::dynamics::setup::default_setup;
use tapsim::instrument::average::AverageRequest;

/// The screen's χ², summed as the curve comes, is the χ² the local stage minimises
/// ([`Measured::chi_square`] of [`Measured::simulate`]) on two approaches read at
/// 300 K through the onset of contact, where points are thermal averages: each
/// approach's own noise, each average's standard error beside σ.
#[test]
fn the_screen_sums_the_chi_square_the_fit_minimises() {
    let setup = default_setup();
    let numerics = Numerics::default();
    let z: Vec<f64> = [24.0, 20.2, 19.5, 21.0, 20.0, 19.5]
        .iter()
        .map(|z| z * 1e-9)
        .collect();
    let mut data = Measured {
        position_m: z.clone(),
        setpoint_ratio: None,
        segments: vec![0, 3],
        amplitude_m: None,
        phase_deg: None,
        sigma_amplitude_m: 0.02e-9,
        sigma_phase_deg: 0.05,
        second_mode: None,
        thermal: Some(AverageRequest {
            temperature_k: 300.0,
            periods: 800,
            seed: 3,
        }),
    };
    let nuisance = Nuisance::offset(0.0);
    let model = data.simulate(&setup, &numerics, &nuisance).unwrap();
    assert!(
        model.averaged.iter().filter(|a| **a).count() >= 2
            && model.amplitude_std_err_m.iter().any(|e| *e > 0.0),
        "the onset is read as thermal averages: {:?}",
        model.averaged
    );
    // Measured values a little off the model's, so that every residual counts.
    data.amplitude_m = Some(
        model
            .amplitude_m
            .iter()
            .enumerate()
            .map(|(i, a)| a + (i as f64 - 2.5) * 0.01e-9)
            .collect(),
    );
    data.phase_deg = Some(
        model
            .phase_deg
            .iter()
            .enumerate()
            .map(|(i, p)| p + (2.0 - i as f64) * 0.03)
            .collect(),
    );
    let expected = data.chi_square(&model);
    let report = |_: &tapsim::analysis::fit::Progress| {};
    let tracker = Tracker::new(&report);
    let wanted = Features {
        jump: None,
        onset_m: None,
    };
    let screened = screen_plain(
        &data,
        &numerics,
        &[Parameter::Modulus],
        &wanted,
        (setup.clone(), nuisance),
        f64::INFINITY,
        &tracker,
    );
    assert!(
        (screened.chi_square - expected).abs() <= 1e-9 * expected,
        "screen {} against the fit's {expected}",
        screened.chi_square
    );
}
