//! What `tapsim fit` draws: the measured amplitude and phase against the rest separation
//! they were fitted at, the fitted curve through them, and the weighted residuals.

use super::chart::{Axis, Chart, Corner, Series, Style};
use crate::fit::{FitReport, Measured};

/// The data (read from `source`), the fit and the residuals, three panels.
pub fn charts(r: &FitReport, data: &Measured, source: &str, law: &str) -> Vec<Chart> {
    let measured_name = format!("measured ({source})");
    let z: Vec<f64> = r.fitted.separation_m.iter().map(|z| z * 1e9).collect();
    let n = z.len();
    // The fitted curve drawn per approach: a gap where the next begins.
    let line = |ys: &[f64]| -> Vec<(f64, f64)> {
        let mut points = Vec::with_capacity(n + data.segments.len());
        for i in 0..n {
            if i > 0 && data.segments.contains(&i) {
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
        x: Axis::linear(
            "rest separation z_c = position + fitted offset (nm)",
            "separation_nm",
        ),
        y,
        legend: Corner::quietest(&series),
        series,
        labels: Vec::new(),
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
            vec![
                Series::new(&measured_name, marks(&measured), Style::Markers, 0),
                Series::new(&fitted_name, line(&fitted), Style::Line, 1),
            ],
        ));
    }
    if let Some(p) = &data.phase_deg {
        out.push(chart(
            "phase",
            "phase: measured and fitted".into(),
            Axis::linear("phase lag φ (deg)", "phase_deg"),
            vec![
                Series::new(&measured_name, marks(p), Style::Markers, 0),
                Series::new(&fitted_name, line(&r.fitted.phase_deg), Style::Line, 1),
            ],
        ));
    }
    // The residuals, amplitudes first (as the report lists them).
    let mut residuals = Vec::new();
    let mut k = 0;
    for (present, name, style) in [
        (
            data.amplitude_m.is_some(),
            "amplitude residual",
            Style::Markers,
        ),
        (data.phase_deg.is_some(), "phase residual", Style::Squares),
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
