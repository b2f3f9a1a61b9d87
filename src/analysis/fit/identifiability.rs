//! What a fit's Jacobian says of its parameters (Bates & Watts, Nonlinear Regression
//! Analysis, 1988, ch. 2: the linearised covariance (JᵀJ)⁻¹ of weighted residuals; its
//! singular values, whose ratio is the condition number, tell which combinations of
//! the parameters the data fix and which they leave free).

use super::model::Parameter;
use nalgebra::DMatrix;
use serde::Serialize;

/// A parameter whose standard error in its fitted coordinate (the logarithm of a
/// scale, so a factor e; an offset in nm) exceeds this is not identifiable from the
/// data: the data leave it free by more than itself.
pub const UNIDENTIFIABLE_STD_ERR: f64 = 1.0;

/// Singular values below this fraction of the largest are the data's null directions.
pub const NULL_SINGULAR: f64 = 1e-8;

/// Two parameters whose correlation exceeds this in magnitude trade off: the data fix
/// a combination of them better than either.
pub const TRADE_OFF: f64 = 0.95;

/// One parameter's estimate.
#[derive(Debug, Clone, Serialize)]
pub struct ParameterEstimate {
    /// Its key (unit included).
    pub name: &'static str,
    /// The starting value.
    pub start: f64,
    /// The fitted value (null where the data do not determine it: never given a value).
    pub value: Option<f64>,
    /// Its linearised standard error, in its unit (for a scale, value × the standard
    /// error of its logarithm, to first order).
    pub std_err: Option<f64>,
    /// The 68 % interval [lo, hi] (linearised; for a scale, exp(ln value ± σ)).
    pub interval_68: Option<[f64; 2]>,
    /// The 95 % interval (± 1.96 σ).
    pub interval_95: Option<[f64; 2]>,
    /// Whether the data determine it.
    pub identifiable: bool,
}

/// The Jacobian's account of the fit.
#[derive(Debug, Clone, Serialize)]
pub struct Identifiability {
    /// Singular values of the weighted Jacobian (in the fitted coordinates), largest
    /// first.
    pub singular_values: Vec<f64>,
    /// Largest over smallest (null where the smallest is zero: a parameter the data do
    /// not see at all).
    pub condition_number: Option<f64>,
    /// Correlations of the fitted coordinates (rows and columns in the parameters'
    /// order; null for a parameter that is not identifiable).
    pub correlations: Vec<Vec<Option<f64>>>,
    /// The combination the data fix worst: the right singular vector of the smallest
    /// singular value, one entry per parameter.
    pub weakest_direction: Vec<f64>,
    /// What the data leave open, and what would close it.
    pub notes: Vec<String>,
}

/// The linearised statistics at the solution: `jacobian` of the weighted residuals in
/// the fitted coordinates `x`, `variance_factor` 1 where the standard deviations are
/// known, χ²/dof where they are estimated from the residuals, and none where they
/// cannot be (residuals at the simulation's own precision: no intervals then, the
/// identifiability judged at the weights given; likewise where the fit does not
/// describe its data), `physical` each coordinate's value in SI.
#[doc(hidden)]
pub fn assess(
    params: &[Parameter],
    jacobian: &DMatrix<f64>,
    variance_factor: Option<f64>,
    physical: &[f64],
    starts: &[f64],
) -> (Vec<ParameterEstimate>, Identifiability) {
    let scales: Vec<bool> = params.iter().map(|p| p.is_scale()).collect();
    let names: Vec<&'static str> = params.iter().map(|p| p.key()).collect();
    let n = names.len();
    let svd = jacobian.clone().svd(false, true);
    let v_t = svd.v_t.expect("asked for V");
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
    let singular: Vec<f64> = order.iter().map(|&k| svd.singular_values[k]).collect();
    let largest = singular.first().copied().unwrap_or(0.0);
    let smallest = singular.last().copied().unwrap_or(0.0);
    // Covariance V diag(1/s²) Vᵀ over the directions the data see.
    let mut cov = DMatrix::<f64>::zeros(n, n);
    let mut blind = vec![false; n];
    for (k, &s) in svd.singular_values.iter().enumerate() {
        let row = v_t.row(k);
        if s <= NULL_SINGULAR * largest || s == 0.0 {
            // A null direction: every parameter in it is unseen.
            for j in 0..n {
                if row[j].abs() > 0.1 {
                    blind[j] = true;
                }
            }
            continue;
        }
        for a in 0..n {
            for b in 0..n {
                cov[(a, b)] += row[a] * row[b] / (s * s);
            }
        }
    }
    cov *= variance_factor.unwrap_or(1.0);
    let sigma: Vec<f64> = (0..n).map(|j| cov[(j, j)].sqrt()).collect();
    let intervals = variance_factor.is_some();
    let identifiable: Vec<bool> = (0..n)
        .map(|j| !blind[j] && sigma[j].is_finite() && sigma[j] <= UNIDENTIFIABLE_STD_ERR)
        .collect();
    let estimates = (0..n)
        .map(|j| {
            let ok = identifiable[j];
            let v = physical[j];
            let interval = |z: f64| {
                if scales[j] {
                    [v * (-z * sigma[j]).exp(), v * (z * sigma[j]).exp()]
                } else {
                    // An offset's coordinate is in its unit (nm, degrees).
                    let u = params[j].unit();
                    [v - z * sigma[j] * u, v + z * sigma[j] * u]
                }
            };
            ParameterEstimate {
                name: names[j],
                start: starts[j],
                value: ok.then_some(v),
                std_err: (ok && intervals).then(|| {
                    if scales[j] {
                        v * sigma[j]
                    } else {
                        sigma[j] * params[j].unit()
                    }
                }),
                interval_68: (ok && intervals).then(|| interval(1.0)),
                interval_95: (ok && intervals).then(|| interval(1.96)),
                identifiable: ok,
            }
        })
        .collect();
    let correlations: Vec<Vec<Option<f64>>> = (0..n)
        .map(|a| {
            (0..n)
                .map(|b| {
                    (identifiable[a] && identifiable[b])
                        .then(|| cov[(a, b)] / (sigma[a] * sigma[b]))
                })
                .collect()
        })
        .collect();
    let weakest: Vec<f64> = order
        .last()
        .map(|&k| v_t.row(k).iter().copied().collect())
        .unwrap_or_default();
    let mut notes = Vec::new();
    for j in (0..n).filter(|&j| !identifiable[j]) {
        notes.push(if blind[j] {
            format!(
                "{} does not change the data (the Jacobian has no component along it): \
                 not identifiable, no value given — {} would show it",
                names[j],
                params[j].seen_in()
            )
        } else {
            let factor = sigma[j].exp();
            format!(
                "{} is not identifiable from these data: its standard error would be a \
                 factor {} — no value given",
                names[j],
                if factor < 1e3 {
                    format!("{factor:.3}")
                } else {
                    "above 1000".into()
                }
            )
        });
    }
    // Parameters the data see, but too weakly to be given a value: name the direction
    // along which they trade off (the data fix the combination across it).
    let weak: Vec<usize> = (0..n).filter(|&j| !identifiable[j] && !blind[j]).collect();
    if !weak.is_empty() && n > 1 {
        let terms: Vec<String> = weakest
            .iter()
            .zip(&names)
            .filter(|(c, _)| c.abs() > 0.1)
            .map(|(c, name)| format!("{c:+.2}·{name}"))
            .collect();
        notes.push(format!(
            "the parameters trade off along {} (in their logarithms; the Jacobian's weakest \
             direction): the data fix what lies across it, not the parameters themselves — \
             data that move them differently (the other branch, positions as well as \
             setpoints, the jump-in, a second mode) would separate them",
            terms.join(" ")
        ));
    }
    for a in 0..n {
        for b in a + 1..n {
            if let Some(r) = correlations[a][b] {
                if r.abs() > TRADE_OFF {
                    notes.push(format!(
                        "{} and {} trade off (correlation {r:+.3}): the data fix a \
                         combination of them better than either; data that the two move \
                         differently — the other branch, the jump-in position, a second \
                         mode — would separate them",
                        names[a], names[b]
                    ));
                }
            }
        }
    }
    let identifiability = Identifiability {
        singular_values: singular,
        condition_number: (smallest > 0.0).then(|| largest / smallest),
        correlations,
        weakest_direction: weakest,
        notes,
    };
    (estimates, identifiability)
}
