//! What `tapsim fit` draws: the measured amplitude and phase against the rest separation
//! they were fitted at, the fitted curve through them, and the weighted residuals.

use super::chart::{Axis, Chart, Corner, Series, Style};
use crate::analysis::fit::{FitReport, Measured, Parameter, Profile};
use serde::Serialize;

/// The data (read from `source`), the fit and the residuals, three panels.
pub fn charts(r: &FitReport, data: &Measured, source: &str, law: &str) -> Vec<Chart> {
    let measured_name = format!("measured ({source})");
    // Against z_c; setpoint data against the setpoint, the fit joined in its order.
    let (z, x_axis): (Vec<f64>, Axis) = match &data.setpoint_ratio {
        Some(s) => (
            s.clone(),
            Axis::linear("amplitude setpoint A/A₀", "setpoint"),
        ),
        None => (
            r.fitted.separation_m.iter().map(|z| z * 1e9).collect(),
            Axis::linear(
                "rest separation z_c = position + fitted offset (nm)",
                "separation_nm",
            ),
        ),
    };
    let n = z.len();
    // Where the fitted curve jumps (its phase by more than 10° between two points: the
    // onset of contact, the branch jump): a jump, not a ramp, so a gap.
    let jumps: Vec<usize> = (1..n)
        .filter(|&i| {
            r.fitted
                .phase_deg
                .get(i)
                .zip(r.fitted.phase_deg.get(i - 1))
                .is_some_and(|(a, b)| (a - b).abs() > 10.0)
        })
        .collect();
    // The fitted curve drawn per approach: a gap where the next begins or it jumps.
    let line = |ys: &[f64]| -> Vec<(f64, f64)> {
        let mut points = Vec::with_capacity(n + data.segments.len());
        if data.setpoint_ratio.is_some() {
            points.extend(z.iter().copied().zip(ys.iter().copied()));
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            return points;
        }
        for i in 0..n {
            if i > 0 && (data.segments.contains(&i) || jumps.contains(&i)) {
                points.push((f64::NAN, f64::NAN));
            }
            points.push((z[i], ys[i]));
        }
        points
    };
    let marks =
        |ys: &[f64]| -> Vec<(f64, f64)> { z.iter().copied().zip(ys.iter().copied()).collect() };
    let chart = |name: &str, title: String, y: Axis, series: Vec<Series>| Chart {
        name: name.into(),
        title,
        x: x_axis.clone(),
        y,
        legend: Corner::quietest(&series),
        series,
        labels: Vec::new(),
    };
    // The fitted points read as thermal averages, marked on the fitted line.
    let averaged_name = data.thermal.map(|t| {
        format!(
            "fitted: thermal average at {} K (grazing or not period-1)",
            t.temperature_k
        )
    });
    let averaged = |ys: &[f64]| -> Option<Series> {
        let points: Vec<(f64, f64)> = (0..n)
            .filter(|&i| r.fitted.averaged.get(i) == Some(&true))
            .map(|i| (z[i], ys[i]))
            .collect();
        let name = averaged_name.as_deref()?;
        (!points.is_empty()).then(|| Series::new(name, points, Style::Triangles, 1))
    };
    let mut out = Vec::new();
    let fitted_name = format!("fitted ({law} law)");
    if let Some(a) = &data.amplitude_m {
        let measured: Vec<f64> = a.iter().map(|v| v * 1e9).collect();
        let fitted: Vec<f64> = r.fitted.amplitude_m.iter().map(|v| v * 1e9).collect();
        out.push(chart(
            "amplitude",
            "amplitude: measured and fitted".into(),
            Axis::linear("amplitude A (nm)", "amplitude_nm"),
            [
                Some(Series::new(
                    &measured_name,
                    marks(&measured),
                    Style::Markers,
                    0,
                )),
                Some(Series::new(&fitted_name, line(&fitted), Style::Line, 1)),
                averaged(&fitted),
            ]
            .into_iter()
            .flatten()
            .collect(),
        ));
    }
    if let Some(p) = &data.phase_deg {
        out.push(chart(
            "phase",
            "phase: measured and fitted".into(),
            Axis::linear("phase lag φ (deg)", "phase_deg"),
            [
                Some(Series::new(&measured_name, marks(p), Style::Markers, 0)),
                Some(Series::new(
                    &fitted_name,
                    line(&r.fitted.phase_deg),
                    Style::Line,
                    1,
                )),
                averaged(&r.fitted.phase_deg),
            ]
            .into_iter()
            .flatten()
            .collect(),
        ));
    }
    if let Some(m) = &data.second_mode {
        if let Some(a) = &m.amplitude_m {
            let measured: Vec<f64> = a.iter().map(|v| v * 1e9).collect();
            let fitted: Vec<f64> = r.fitted.amplitude2_m.iter().map(|v| v * 1e9).collect();
            out.push(chart(
                "amplitude2",
                "second mode's amplitude: measured and fitted".into(),
                Axis::linear("amplitude A₂ (nm)", "amplitude2_nm"),
                vec![
                    Series::new(&measured_name, marks(&measured), Style::Markers, 0),
                    Series::new(&fitted_name, line(&fitted), Style::Line, 1),
                ],
            ));
        }
        if let Some(p) = &m.phase_deg {
            out.push(chart(
                "phase2",
                "second mode's phase: measured and fitted".into(),
                Axis::linear("phase lag φ₂ (deg)", "phase2_deg"),
                vec![
                    Series::new(&measured_name, marks(p), Style::Markers, 0),
                    Series::new(&fitted_name, line(&r.fitted.phase2_deg), Style::Line, 1),
                ],
            ));
        }
    }
    // The residuals, in the report's order: amplitude, phase, then the second mode's.
    let mut residuals = Vec::new();
    let mut k = 0;
    let second = data.second_mode.as_ref();
    for (present, name, style) in [
        (
            data.amplitude_m.is_some(),
            "amplitude residual",
            Style::Markers,
        ),
        (data.phase_deg.is_some(), "phase residual", Style::Squares),
        (
            second.is_some_and(|m| m.amplitude_m.is_some()),
            "second mode's amplitude residual",
            Style::Crosses,
        ),
        (
            second.is_some_and(|m| m.phase_deg.is_some()),
            "second mode's phase residual",
            Style::Triangles,
        ),
    ] {
        if present {
            residuals.push(Series::new(
                name,
                marks(&r.residuals[k..k + n]),
                style,
                residuals.len() + 2,
            ));
            k += n;
        }
    }
    out.push(chart(
        "residuals",
        format!("weighted residuals: χ²/dof = {:.3}", r.reduced_chi_square),
        Axis::linear("(fitted − measured)/σ", "residual"),
        residuals,
    ));
    out
}

/// One point of the data beside the fit, as `tapsim fit --csv` writes it.
#[derive(Debug, Serialize)]
pub struct Row {
    /// The measured position, m (empty for setpoint data).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub position_m: Option<f64>,
    /// The amplitude setpoint A/A₀ (empty for an approach curve).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub setpoint_ratio: Option<f64>,
    /// The fitted rest separation there (position + fitted offset), m.
    pub separation_m: f64,
    /// Which approach of the data it belongs to (0 the first).
    pub segment: usize,
    /// Measured amplitude, m (empty where the data have none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub amplitude_m: Option<f64>,
    /// Fitted amplitude, m.
    pub fitted_amplitude_m: f64,
    /// (fitted − measured)/σ of the amplitude.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub amplitude_residual: Option<f64>,
    /// Measured phase, degrees.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub phase_deg: Option<f64>,
    /// Fitted phase, degrees.
    pub fitted_phase_deg: f64,
    /// (fitted − measured)/σ of the phase.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub phase_residual: Option<f64>,
    /// The second mode's measured amplitude, m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub amplitude2_m: Option<f64>,
    /// Its fitted amplitude, m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fitted_amplitude2_m: Option<f64>,
    /// The second mode's measured phase, degrees.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub phase2_deg: Option<f64>,
    /// Its fitted phase, degrees.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fitted_phase2_deg: Option<f64>,
    /// Whether the fitted state is a stable period-1 orbit clear of the law's switches
    /// (or a thermal average, which is what the instrument reads there).
    pub well_defined: bool,
    /// With a temperature: whether the fitted value is the thermal average (the state
    /// grazes a switch or is not period-1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub thermal_average: Option<bool>,
    /// Its phase's standard error, degrees (0 where not averaged).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fitted_phase_std_err_deg: Option<f64>,
}

/// The data beside the fit, point by point.
pub fn rows(r: &FitReport, data: &Measured) -> Vec<Row> {
    let n = data.len();
    let (amp_at, phase_at) = match (data.amplitude_m.is_some(), data.phase_deg.is_some()) {
        (true, true) => (Some(0), Some(n)),
        (true, false) => (Some(0), None),
        _ => (None, Some(0)),
    };
    (0..n)
        .map(|i| Row {
            position_m: data.position_m.get(i).copied(),
            setpoint_ratio: data.setpoint_ratio.as_ref().map(|s| s[i]),
            separation_m: r.fitted.separation_m[i],
            segment: data.segments.iter().filter(|&&s| s <= i).count() - 1,
            amplitude_m: data.amplitude_m.as_ref().map(|a| a[i]),
            fitted_amplitude_m: r.fitted.amplitude_m[i],
            amplitude_residual: amp_at.map(|k| r.residuals[k + i]),
            phase_deg: data.phase_deg.as_ref().map(|p| p[i]),
            fitted_phase_deg: r.fitted.phase_deg[i],
            phase_residual: phase_at.map(|k| r.residuals[k + i]),
            amplitude2_m: data
                .second_mode
                .as_ref()
                .and_then(|m| m.amplitude_m.as_ref())
                .map(|a| a[i]),
            fitted_amplitude2_m: r.fitted.amplitude2_m.get(i).copied(),
            phase2_deg: data
                .second_mode
                .as_ref()
                .and_then(|m| m.phase_deg.as_ref())
                .map(|p| p[i]),
            fitted_phase2_deg: r.fitted.phase2_deg.get(i).copied(),
            well_defined: r.fitted.well_defined[i],
            thermal_average: r.fitted.averaged.get(i).copied(),
            fitted_phase_std_err_deg: r.fitted.phase_std_err_deg.get(i).copied(),
        })
        .collect()
}

/// A profile's Δχ² against the parameter held, with the levels of the 68 % and 95 %
/// intervals.
pub fn profile_chart(p: &Profile) -> Chart {
    let points: Vec<(f64, f64)> = p
        .values
        .iter()
        .copied()
        .zip(p.delta_chi_square.iter().copied())
        .collect();
    let (lo, hi) = (
        p.values.first().copied().unwrap_or(0.0),
        p.values.last().copied().unwrap_or(1.0),
    );
    let series = vec![
        Series::new(
            "profile: the others refitted at each value",
            points,
            Style::Markers,
            0,
        ),
        Series::new(
            "Δχ² = 1 (68 %)",
            vec![(lo, 1.0), (hi, 1.0)],
            Style::Dotted,
            1,
        ),
        Series::new(
            "Δχ² = 3.84 (95 %)",
            vec![(lo, 3.84), (hi, 3.84)],
            Style::Dashed,
            2,
        ),
    ];
    let label = Parameter::ALL
        .iter()
        .find(|q| q.key() == p.name)
        .map_or(p.name, |q| q.label());
    Chart {
        name: format!("profile_{}", p.name),
        title: format!("profile likelihood: {label}"),
        x: Axis::linear(label, p.name),
        y: Axis::linear("Δχ²", "delta_chi_square"),
        legend: Corner::quietest(&series),
        series,
        labels: Vec::new(),
    }
}
