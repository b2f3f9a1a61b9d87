//! Whether a fit describes its data: χ² against its distribution where the standard
//! deviations are given, runs of one sign in the residuals (the Wald–Wolfowitz runs
//! test; Wald & Wolfowitz, Ann. Math. Stat. 11, 147, 1940), the branch jump in data and
//! model, and the points the model misses most; and whether the optimiser stopped at a
//! minimum (the decrease a Gauss–Newton step would still bring).

use super::features::Features;
use super::model::{Curve, Measured};
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// A runs test's z below this (too few runs of one sign) is structure, not noise
/// (one false alarm in some 4 000 channels that the model does describe).
const RUNS_Z: f64 = -3.5;
/// Fewest residuals of a channel for its runs test.
const RUNS_MIN: usize = 10;
/// A Gauss–Newton step that would still lower χ² by more than this (in units of the
/// variance factor) means the optimiser stalled: the minimum lies outside the 68 %
/// region about where it stopped (Δχ² = 1). Below it the stop is within its own error
/// (the forward-difference Jacobian at a point grazing a switch leaves a few tenths).
pub const STALL_DECREASE: f64 = 1.0;

/// A point the fit misses.
#[derive(Debug, Clone, Serialize)]
pub struct WorstPoint {
    /// The point (from 0, in the data's order).
    pub index: usize,
    /// Its position (m) or setpoint (A/A₀).
    pub at: f64,
    /// The channel: amplitude_m, phase_deg, amplitude2_m or phase2_deg.
    pub channel: &'static str,
    /// What was measured there.
    pub measured: f64,
    /// What the fit gives there.
    pub fitted: f64,
    /// (fitted − measured)/σ.
    pub weighted_residual: f64,
}

/// Where the approach from far jumps to the other branch, in the data and in the fit.
#[derive(Debug, Clone, Serialize)]
pub struct BranchJump {
    /// Between these two positions in the data (m; null: no jump).
    pub data_m: Option<[f64; 2]>,
    /// And in the fitted curve.
    pub fitted_m: Option<[f64; 2]>,
}

/// The verdict on a fit.
#[derive(Debug, Clone, Serialize)]
pub struct Diagnosis {
    /// Whether the fitted curve describes the data within their noise.
    pub describes_data: bool,
    /// Why not, in words (empty where it does).
    pub reasons: Vec<String>,
    /// The three points with the largest weighted residuals.
    pub worst_points: Vec<WorstPoint>,
    /// The branch jump, where data or fit has one.
    pub branch_jump: Option<BranchJump>,
    /// Runs of one sign in each channel's residuals: (channel, runs, expected, z).
    pub runs: Vec<RunsTest>,
}

/// One channel's runs test.
#[derive(Debug, Clone, Serialize)]
pub struct RunsTest {
    /// The channel.
    pub channel: &'static str,
    /// Runs of one sign counted.
    pub runs: usize,
    /// Expected for independent residuals.
    pub expected: f64,
    /// (runs − expected)/sd.
    pub z: f64,
}

/// The runs test of `r` (None below [`RUNS_MIN`] values or with one sign only).
fn runs_test(channel: &'static str, r: &[f64]) -> Option<RunsTest> {
    if r.len() < RUNS_MIN {
        return None;
    }
    let plus = r.iter().filter(|v| **v > 0.0).count() as f64;
    let n = r.len() as f64;
    let minus = n - plus;
    if plus == 0.0 || minus == 0.0 {
        return Some(RunsTest {
            channel,
            runs: 1,
            expected: 1.0,
            z: -(n.sqrt()),
        });
    }
    let runs = 1 + r
        .windows(2)
        .filter(|w| (w[0] > 0.0) != (w[1] > 0.0))
        .count();
    let mu = 2.0 * plus * minus / n + 1.0;
    let var = (mu - 1.0) * (mu - 2.0) / (n - 1.0);
    Some(RunsTest {
        channel,
        runs,
        expected: mu,
        z: (runs as f64 - mu) / var.sqrt(),
    })
}

/// Judge the fit `fitted` of `data` with weighted residuals `residuals` (χ² over `dof`
/// degrees of freedom), the standard deviations given or (`estimated`) not.
pub fn diagnose(
    data: &Measured,
    fitted: &Curve,
    residuals: &[f64],
    dof: usize,
    estimated: bool,
) -> Diagnosis {
    let n = data.len();
    let names = data.channel_names();
    let mut reasons = Vec::new();
    let chi_square: f64 = residuals.iter().map(|r| r * r).sum();
    let limit = dof as f64 + 5.0 * (2.0 * dof as f64).sqrt();
    if !estimated && chi_square > limit {
        reasons.push(format!(
            "χ²/dof = {:.4} is beyond five standard deviations of χ²'s distribution for \
             {dof} degrees of freedom (χ² {chi_square:.4e} > {limit:.1}): with the \
             standard deviations given, the fitted curve does not describe the data",
            chi_square / dof as f64
        ));
    }
    let at = |i: usize| {
        data.setpoint_ratio
            .as_ref()
            .map_or_else(|| data.position_m[i], |s| s[i])
    };
    // Each channel's residuals in the data's order, tested for runs.
    let mut runs = Vec::new();
    let mut worst: Vec<WorstPoint> = Vec::new();
    let channels = data.channel_values(fitted);
    for (c, (name, channel)) in names.iter().zip(&channels).enumerate() {
        let (measured, simulated) = (channel.measured, channel.simulated);
        let r = &residuals[c * n..(c + 1) * n];
        if data.setpoint_ratio.is_none() {
            if let Some(t) = runs_test(name, r) {
                if t.runs == 1 {
                    reasons.push(format!(
                        "the {name} residuals all have one sign: the fitted curve misses the \
                         data's shape, not their noise"
                    ));
                } else if t.z < RUNS_Z {
                    reasons.push(format!(
                        "the {name} residuals run in long stretches of one sign ({} runs \
                         where independent noise would give {:.1}, z = {:.1}): the fitted \
                         curve misses the data's shape, not their noise",
                        t.runs, t.expected, t.z
                    ));
                }
                runs.push(t);
            }
        }
        for (i, &w) in r.iter().enumerate() {
            worst.push(WorstPoint {
                index: i,
                at: at(i),
                channel: name,
                measured: measured[i],
                fitted: simulated[i],
                weighted_residual: w,
            });
        }
    }
    worst.sort_by(|a, b| {
        b.weighted_residual
            .abs()
            .total_cmp(&a.weighted_residual.abs())
    });
    worst.truncate(3);
    // The branch jump of the approach from far, in data and fit.
    let mut branch_jump = None;
    if data.setpoint_ratio.is_none() {
        let want = Features::of(data, data.phase_deg.as_deref(), data.amplitude_m.as_deref());
        let got = Features::of(
            data,
            data.phase_deg.as_ref().map(|_| fitted.phase_deg.as_slice()),
            data.amplitude_m
                .as_ref()
                .map(|_| fitted.amplitude_m.as_slice()),
        );
        let between = |j: Option<usize>| j.map(|i| [data.position_m[i], data.position_m[i + 1]]);
        if want.jump.is_some() || got.jump.is_some() {
            if want.jump != got.jump {
                let say = |j: Option<[f64; 2]>| {
                    j.map_or("nowhere".into(), |[a, b]| {
                        format!("between {:.3} and {:.3} nm", a * 1e9, b * 1e9)
                    })
                };
                reasons.push(format!(
                    "the data jump to the other branch {} (positions), the fitted curve {}",
                    say(between(want.jump)),
                    say(between(got.jump))
                ));
            }
            branch_jump = Some(BranchJump {
                data_m: between(want.jump),
                fitted_m: between(got.jump),
            });
        }
    }
    Diagnosis {
        describes_data: reasons.is_empty(),
        reasons,
        worst_points: worst,
        branch_jump,
        runs,
    }
}

/// The Gauss–Newton step from the end (weighted residuals `r`, Jacobian `j`, in the
/// fitted coordinates): −J⁺r over the directions the parameters move the residuals,
/// and the decrease of χ² it predicts (the squared length of r's projection on them;
/// zero at a stationary point).
pub fn gauss_newton_step(j: &DMatrix<f64>, r: &DVector<f64>) -> (DVector<f64>, f64) {
    let svd = j.clone().svd(true, true);
    let u = svd.u.expect("asked for U");
    let v_t = svd.v_t.expect("asked for V");
    let largest = svd.singular_values.max();
    let mut step = DVector::zeros(j.ncols());
    let mut decrease = 0.0;
    for k in 0..svd.singular_values.len() {
        let s = svd.singular_values[k];
        if s <= 1e-8 * largest || s == 0.0 {
            continue;
        }
        let c = u.column(k).dot(r);
        decrease += c * c;
        step -= v_t.row(k).transpose() * (c / s);
    }
    (step, decrease)
}
