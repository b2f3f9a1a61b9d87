//! `tapsim contrast`: phase contrast between materials under several laws.

use crate::config::MaterialSpec;
use crate::config::TapInputs;
use crate::contrast::{self, PhaseBranch};
use crate::error::Result;
use crate::law::LawKind;
use crate::report::chart::{Axis, Chart, Corner, Series, Style};
use crate::report::{output, plot, sweep as report};
use clap::Args;

/// Phase contrast between two or more materials at the same cantilever and amplitude
/// setpoints, for several force laws side by side: how much phase contrast the classic
/// JKR law overstates relative to the hybrid and the exact Lennard-Jones law.
///
/// Each material is `name:key=value,...` with the flags' names as keys, e.g.
///   --material a:sample-modulus=0.5GPa,work-of-adhesion=0.1
///   --material b:sample-modulus=1GPa,work-of-adhesion=0.08
/// (without --material: these two). Every other `tapsim tap` option sets the common
/// cantilever and tip.
///
/// At each amplitude setpoint every steady state of each material is found: the stable
/// orbits of its period-1 family (continued through z_c as `tapsim branches` does), or,
/// on a branch where there is none, the approach curve's states there (orbits of
/// higher period, irregular motion). Each lies on the attractive (φ above the free
/// phase, 90° at resonance) or the repulsive branch. Δφ = φ(last material) − φ(first)
/// is taken only between materials on the same branch; where a setpoint is bistable,
/// both branches get a row. The table names the motion behind every φ and compares
/// JKR's contrast with the other laws', branch by branch.
///
/// JSON (--json): one object per law, setpoint and branch with law, materials,
/// amplitude_ratio, branch, phase_deg, regime and converged (one entry per material,
/// null where it has no steady state on that branch) and delta_phase_deg.
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct ContrastArgs {
    #[command(flatten)]
    inputs: TapInputs,
    #[command(flatten)]
    out: super::SweepOutput,
    /// A material, name:key=value,... (repeat; at least two).
    #[arg(long = "material", value_parser = MaterialSpec::parse)]
    materials: Vec<MaterialSpec>,
    /// Laws to compare.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [LawKind::Jkr, LawKind::Hybrid, LawKind::Lj])]
    laws: Vec<LawKind>,
    /// Amplitude setpoints A/A₀, each between 0 and 1.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true,
          value_parser = crate::config::number, default_values_t = [0.9, 0.8, 0.7, 0.6, 0.5])]
    setpoints: Vec<f64>,
    /// Setpoints on each approach curve.
    #[arg(long, allow_hyphen_values = true, default_value_t = 50)]
    points: usize,
}

/// Run the subcommand.
pub fn run(args: ContrastArgs) -> Result<()> {
    let base = args.inputs.with_config()?;
    let materials = if args.materials.is_empty() {
        vec![
            MaterialSpec::parse("A:sample-modulus=0.5GPa,work-of-adhesion=0.1")?,
            MaterialSpec::parse("B:sample-modulus=1GPa,work-of-adhesion=0.08")?,
        ]
    } else {
        args.materials.clone()
    };
    let quiet = args.out.quiet;
    let materials = materials
        .iter()
        .map(|m| m.resolve(&base))
        .collect::<Result<Vec<_>>>()?;
    let (rows, curves) = contrast::contrast(
        &materials,
        &args.laws,
        &args.setpoints,
        args.points,
        |what| {
            if !quiet {
                eprintln!("approach curve: {what}");
            }
        },
    )?;
    if let Some(path) = &args.out.csv {
        let mut w = csv::Writer::from_writer(Vec::new());
        let mut header = vec!["law".to_string(), "amplitude_ratio".into(), "branch".into()];
        header.extend(materials.iter().map(|m| format!("phase_deg_{}", m.name)));
        header.extend(materials.iter().map(|m| format!("regime_{}", m.name)));
        header.push("delta_phase_deg".into());
        let fail = |e: csv::Error| crate::Error::Output {
            path: path.clone(),
            reason: e.to_string(),
        };
        w.write_record(&header).map_err(fail)?;
        for r in &rows {
            let cell = |x: Option<f64>| x.map_or(String::new(), |v| v.to_string());
            let mut rec = vec![
                r.law.clone(),
                r.amplitude_ratio.to_string(),
                branch_name(r.branch).into(),
            ];
            rec.extend(r.phase_deg.iter().map(|&p| cell(p)));
            rec.extend(r.regime.iter().map(|g| g.clone().unwrap_or_default()));
            rec.push(cell(r.delta_phase_deg));
            w.write_record(&rec).map_err(fail)?;
        }
        let bytes = w.into_inner().map_err(|e| crate::Error::Output {
            path: path.clone(),
            reason: e.to_string(),
        })?;
        output::write_bytes(path, &bytes)?;
    }
    if let Some(path) = &args.out.plot {
        let mut charts: Vec<Chart> = args
            .laws
            .iter()
            .map(|law| {
                let per_material: Vec<(&str, &[crate::sweep::SweepPoint])> = curves
                    .iter()
                    .filter(|c| c.law == *law)
                    .map(|c| (c.material.as_str(), c.points.as_slice()))
                    .collect();
                report::phase_vs_amplitude(
                    &format!("phase_{law}"),
                    &format!("{law} law: phase vs amplitude"),
                    &per_material,
                )
            })
            .collect();
        charts.push(Chart {
            name: "contrast".into(),
            title: format!(
                "phase contrast Δφ = φ({}) − φ({})",
                materials[materials.len() - 1].name,
                materials[0].name
            ),
            x: Axis::linear("amplitude setpoint A/A₀", "amplitude_ratio"),
            y: Axis::linear("Δφ (deg)", "delta_phase_deg"),
            series: args
                .laws
                .iter()
                .enumerate()
                .flat_map(|(i, law)| {
                    let rows = &rows;
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
                        let name = format!("{law}, {}", branch_name(branch));
                        // Markers at the setpoints, circles and squares by turns, so a
                        // law whose Δφ coincides with another's still shows.
                        let marks = if i % 2 == 0 {
                            Style::Markers
                        } else {
                            Style::Squares
                        };
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
        plot::render_stack(&charts, path)?;
    }
    if args.out.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&rows).expect("serialises")
        );
    } else {
        outln!(
            "{:>18} {:>8} {:>11} {:>10}  motion",
            "law",
            "A/A0",
            "branch",
            "Δφ (deg)"
        );
        for r in &rows {
            let regimes: Vec<&str> = r
                .regime
                .iter()
                .map(|g| g.as_deref().unwrap_or("none"))
                .collect();
            outln!(
                "{:>18} {:>8.3} {:>11} {:>10}  {}",
                r.law,
                r.amplitude_ratio,
                branch_name(r.branch),
                r.delta_phase_deg.map_or("—".into(), |d| format!("{d:.3}")),
                regimes.join(", ")
            );
        }
        // How much more (or less) contrast JKR shows than each other law, branch by
        // branch: only materials on the same branch are compared.
        for other in args.laws.iter().filter(|l| **l != LawKind::Jkr) {
            for r in rows.iter().filter(|r| r.law == "jkr") {
                let same = rows.iter().find(|o| {
                    o.law == other.to_string()
                        && o.branch == r.branch
                        && o.amplitude_ratio == r.amplitude_ratio
                });
                if let (Some(j), Some(o)) =
                    (r.delta_phase_deg, same.and_then(|o| o.delta_phase_deg))
                {
                    outln!(
                        "A/A0 = {:.3}, {} branch: Δφ = {j:.3}° under jkr, {o:.3}° under {other} \
                         (jkr {:+.3}°)",
                        r.amplitude_ratio,
                        branch_name(r.branch),
                        j.abs() - o.abs(),
                    );
                }
            }
        }
    }
    Ok(())
}

fn branch_name(b: PhaseBranch) -> &'static str {
    match b {
        PhaseBranch::Attractive => "attractive",
        PhaseBranch::Repulsive => "repulsive",
    }
}
