//! The `tapsim contrast` outputs: the Δφ table as CSV and for people, and the charts
//! (phase against amplitude per law, Δφ per law and branch).

use super::chart::{Axis, Chart, Corner, Series, Style};
use super::sweep::{phase_vs_amplitude, vs_amplitude};
use crate::analysis::contrast::{ContrastRow, LawCurve, Material, PhaseBranch};
use crate::physics::law::LawKind;
use std::fmt::Write as _;

/// How a branch is named in every output.
pub fn branch_name(b: PhaseBranch) -> &'static str {
    match b {
        PhaseBranch::Attractive => "attractive",
        PhaseBranch::Repulsive => "repulsive",
    }
}

/// The rows as CSV: law, setpoint, branch, each material's phase, regime and grazing
/// flag, Δφ, each material's z_c at the setpoint and the apparent height (the last
/// material's z_c less the first's), then
/// each material's E_ts and its adhesion and viscous shares (J). An error is the CSV
/// writer's reason.
pub fn contrast_csv(
    rows: &[ContrastRow],
    materials: &[Material],
) -> std::result::Result<Vec<u8>, String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec!["law".to_string(), "amplitude_ratio".into(), "branch".into()];
    header.extend(materials.iter().map(|m| format!("phase_deg_{}", m.name)));
    header.extend(materials.iter().map(|m| format!("regime_{}", m.name)));
    header.extend(materials.iter().map(|m| format!("grazing_{}", m.name)));
    header.push("delta_phase_deg".into());
    header.extend(materials.iter().map(|m| format!("separation_m_{}", m.name)));
    header.push("apparent_height_m".into());
    let noisy = rows.iter().any(|r| r.noise.is_some());
    if noisy {
        header.extend(
            materials
                .iter()
                .map(|m| format!("sigma_phase_deg_{}", m.name)),
        );
        header.push("contrast_to_noise".into());
    }
    for column in [
        "e_ts_j",
        "e_ts_adhesion_j",
        "e_ts_viscous_j",
        "e_ts_capillary_j",
    ] {
        header.extend(materials.iter().map(|m| format!("{column}_{}", m.name)));
    }
    w.write_record(&header).map_err(|e| e.to_string())?;
    for r in rows {
        let cell = |x: Option<f64>| x.map_or(String::new(), super::records::csv_number);
        let mut rec = vec![
            r.law.clone(),
            super::records::csv_number(r.amplitude_ratio),
            branch_name(r.branch).into(),
        ];
        rec.extend(r.phase_deg.iter().map(|&p| cell(p)));
        rec.extend(r.regime.iter().map(|g| g.clone().unwrap_or_default()));
        rec.extend(
            r.grazing
                .iter()
                .map(|g| g.map_or(String::new(), |g| g.to_string())),
        );
        rec.push(cell(r.delta_phase_deg));
        rec.extend(r.separation_m.iter().map(|&z| cell(z)));
        rec.push(cell(r.apparent_height_m));
        if noisy {
            rec.extend(r.sigma_phase_deg.iter().map(|&p| cell(p)));
            rec.push(cell(r.contrast_to_noise));
        }
        for shares in [
            &r.e_ts_j,
            &r.e_ts_adhesion_j,
            &r.e_ts_viscous_j,
            &r.e_ts_capillary_j,
        ] {
            rec.extend(shares.iter().map(|&e| cell(e)));
        }
        w.write_record(&rec).map_err(|e| e.to_string())?;
    }
    w.into_inner().map_err(|e| e.to_string())
}

/// Phase against amplitude for each law (a curve per material), E_ts against amplitude
/// for each law (and its viscous share, where a sample is viscous), then Δφ against the
/// setpoint for every law and branch.
pub fn contrast_charts(
    laws: &[LawKind],
    materials: &[Material],
    rows: &[ContrastRow],
    curves: &[LawCurve],
) -> Vec<Chart> {
    let per_material = |law: LawKind| -> Vec<(&str, &[crate::analysis::sweep::SweepPoint])> {
        curves
            .iter()
            .filter(|c| c.law == law)
            .map(|c| (c.material.as_str(), c.points.as_slice()))
            .collect()
    };
    let mut charts: Vec<Chart> = laws
        .iter()
        .map(|&law| {
            phase_vs_amplitude(
                &format!("phase_{law}"),
                &format!("{law} law: phase vs amplitude"),
                &per_material(law),
            )
        })
        .collect();
    for &law in laws {
        let of_law = per_material(law);
        charts.push(vs_amplitude(
            (
                &format!("e_ts_{law}"),
                &format!("{law} law: dissipation vs amplitude"),
            ),
            Axis::linear("E_ts per cycle (eV)", "e_ts_ev"),
            |o| o.e_ts_ev,
            &of_law,
        ));
        let viscous = of_law
            .iter()
            .any(|(_, points)| points.iter().any(|p| p.observables.e_ts_viscous_j > 0.0));
        if viscous {
            charts.push(vs_amplitude(
                (
                    &format!("e_ts_viscous_{law}"),
                    &format!("{law} law: viscous share of the dissipation"),
                ),
                Axis::linear(
                    "E_ts in the viscous sample per cycle (eV)",
                    "e_ts_viscous_ev",
                ),
                |o| o.e_ts_viscous_j / crate::physics::params::ELECTRONVOLT_J,
                &of_law,
            ));
        }
    }
    // Room below the curves for the legend, which would otherwise cover some of them.
    let (lo, hi) = rows
        .iter()
        .filter_map(|r| r.delta_phase_deg)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), d| {
            (lo.min(d), hi.max(d))
        });
    let span = (hi - lo).max(1.0);
    let mut delta_axis = Axis::linear("Δφ (deg)", "delta_phase_deg");
    if lo.is_finite() {
        delta_axis = delta_axis.with_range(lo - 0.7 * span, hi + 0.05 * span);
    }
    charts.push(Chart {
        name: "contrast".into(),
        title: format!(
            "phase contrast Δφ = φ({}) − φ({})",
            materials[materials.len() - 1].name,
            materials[0].name
        ),
        x: Axis::linear("amplitude setpoint A/A₀", "amplitude_ratio"),
        y: delta_axis,
        series: laws
            .iter()
            .enumerate()
            .flat_map(|(i, law)| {
                [
                    (PhaseBranch::Attractive, Style::Line),
                    (PhaseBranch::Repulsive, Style::Dashed),
                ]
                .into_iter()
                .filter_map(move |(branch, style)| {
                    let pts: Vec<(f64, f64)> = rows
                        .iter()
                        .filter(|r| r.law == law.to_string() && r.branch == branch)
                        .filter_map(|r| r.delta_phase_deg.map(|d| (r.amplitude_ratio, d)))
                        .collect();
                    // Markers at the setpoints, circles and squares by turns, so a law
                    // whose Δφ coincides with another's still shows; the legend says
                    // which.
                    let (marks, shape) = if i % 2 == 0 {
                        (Style::Markers, "○")
                    } else {
                        (Style::Squares, "□")
                    };
                    let name = format!("{law} {shape}, {}", branch_name(branch));
                    (!pts.is_empty()).then(|| {
                        [
                            Series::new(&name, pts.clone(), style, i + 1),
                            Series::new("", pts, marks, i + 1),
                        ]
                    })
                })
                .flatten()
            })
            .collect(),
        labels: vec![],
        legend: Corner::UpperRight,
    });
    super::chart::share_legends(&mut charts);
    charts
}

/// The table for people (Δφ and the apparent height Δz_c of the last material over the
/// first), then how much more (or less) contrast JKR shows than each other law, branch
/// by branch (only materials on the same branch are compared).
pub fn contrast_text(laws: &[LawKind], rows: &[ContrastRow]) -> String {
    let mut s = String::new();
    let noise = rows.iter().find_map(|r| r.noise);
    if let Some(n) = noise {
        let _ = writeln!(
            s,
            "thermal noise at {} K through a lock-in of order {}, ENBW {} Hz: σ_φ of each \
             material (first/last), and Δφ/σ = |Δφ|/√(σ_first² + σ_last²)",
            n.temperature_k, n.lockin_order, n.enbw_hz
        );
    }
    let _ = write!(
        s,
        "{:>18} {:>8} {:>11} {:>10} {:>10}",
        "law", "A/A0", "branch", "Δφ (deg)", "Δz_c (nm)"
    );
    if noise.is_some() {
        let _ = write!(s, " {:>17} {:>8}", "σ_φ (deg)", "Δφ/σ");
    }
    let _ = writeln!(s, "  motion");
    for r in rows {
        let regimes: Vec<String> = r
            .regime
            .iter()
            .zip(&r.grazing)
            .map(|(g, grazing)| {
                let mark = if *grazing == Some(true) {
                    " (grazing)"
                } else {
                    ""
                };
                format!("{}{mark}", g.as_deref().unwrap_or("none"))
            })
            .collect();
        let _ = write!(
            s,
            "{:>18} {:>8.3} {:>11} {:>10} {:>10}",
            r.law,
            r.amplitude_ratio,
            branch_name(r.branch),
            r.delta_phase_deg.map_or("—".into(), |d| format!("{d:.3}")),
            r.apparent_height_m
                .map_or("—".into(), |h| format!("{:.3}", h * 1e9)),
        );
        if noise.is_some() {
            let sigma = |p: Option<f64>| p.map_or("—".into(), |p| format!("{p:.4}"));
            let pair = format!(
                "{}/{}",
                sigma(r.sigma_phase_deg[0]),
                sigma(r.sigma_phase_deg[r.sigma_phase_deg.len() - 1])
            );
            let _ = write!(
                s,
                " {pair:>17} {:>8}",
                r.contrast_to_noise
                    .map_or("—".into(), |c| format!("{c:.1}"))
            );
        }
        let _ = writeln!(s, "  {}", regimes.join(", "));
    }
    for other in laws.iter().filter(|l| **l != LawKind::Jkr) {
        for r in rows.iter().filter(|r| r.law == "jkr") {
            let same = rows.iter().find(|o| {
                o.law == other.to_string()
                    && o.branch == r.branch
                    && o.amplitude_ratio == r.amplitude_ratio
            });
            if let (Some(j), Some(o)) = (r.delta_phase_deg, same.and_then(|o| o.delta_phase_deg)) {
                let _ = writeln!(
                    s,
                    "A/A0 = {:.3}, {} branch: Δφ = {j:.3}° under jkr, {o:.3}° under {other} \
                     (jkr {:+.3}°)",
                    r.amplitude_ratio,
                    branch_name(r.branch),
                    j.abs() - o.abs(),
                );
            }
        }
    }
    s
}

/// Marks on a φ-against-A/A₀ chart of one law the states `rows` (that law's contrast
/// rows, at one setpoint) list: each material's state on each branch as a triangle in
/// its curve's colour (material i in colour i + 1, as the curves), in a square where it
/// grazes a switch, and Δφ (last material − first) on each branch after the title.
pub fn mark_setpoint_states(chart: &mut Chart, rows: &[&ContrastRow]) {
    let Some(first) = rows.first() else {
        return;
    };
    let deltas: Vec<String> = rows
        .iter()
        .filter_map(|r| {
            let d = r.delta_phase_deg?;
            let sign = if d >= 0.0 { "+" } else { "−" };
            Some(format!("{sign}{:.2}° {}", d.abs(), branch_name(r.branch)))
        })
        .collect();
    if !deltas.is_empty() {
        write!(
            chart.title,
            ", A/A₀ = {}: Δφ = {}",
            first.amplitude_ratio,
            deltas.join(", ")
        )
        .expect("a String takes text");
    }
    let names = &first.materials;
    chart.series.push(Series::new(
        &format!(
            "state at the setpoint, in its curve's colour (Δφ = {} − {})",
            names[names.len() - 1],
            names[0]
        ),
        vec![],
        Style::Triangles,
        0,
    ));
    for (i, _) in names.iter().enumerate() {
        let at = |grazing: bool| -> Vec<(f64, f64)> {
            rows.iter()
                .filter(|r| !grazing || r.grazing[i] == Some(true))
                .filter_map(|r| r.phase_deg[i].map(|p| (r.amplitude_ratio, p)))
                .collect()
        };
        let (all, grazing) = (at(false), at(true));
        if !all.is_empty() {
            chart
                .series
                .push(Series::new("", all, Style::Triangles, i + 1));
        }
        if !grazing.is_empty() {
            chart
                .series
                .push(Series::new("", grazing, Style::Squares, i + 1));
        }
    }
    chart.legend = Corner::quietest(&chart.series);
}
