//! `tapsim contrast`: phase contrast between materials under several laws.

use crate::config::TapInputs;
use crate::contrast::{self, Material};
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
/// cantilever and tip. φ(A/A₀) comes from an approach curve per material and law; Δφ is
/// φ(last material) − φ(first) at each setpoint.
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct ContrastArgs {
    #[command(flatten)]
    inputs: TapInputs,
    #[command(flatten)]
    out: super::SweepOutput,
    /// A material, name:key=value,... (repeat; at least two).
    #[arg(long = "material", value_parser = Material::parse)]
    materials: Vec<Material>,
    /// Laws to compare.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [LawKind::Jkr, LawKind::Hybrid, LawKind::Lj])]
    laws: Vec<LawKind>,
    /// Amplitude setpoints A/A₀.
    #[arg(long, value_delimiter = ',', default_values_t = [0.9, 0.8, 0.7, 0.6, 0.5])]
    setpoints: Vec<f64>,
    /// Setpoints on each approach curve.
    #[arg(long, default_value_t = 50)]
    points: usize,
}

/// Run the subcommand.
pub fn run(args: ContrastArgs) -> Result<()> {
    let base = args.inputs.with_config()?;
    let materials = if args.materials.is_empty() {
        vec![
            Material::parse("A:sample-modulus=0.5GPa,work-of-adhesion=0.1")?,
            Material::parse("B:sample-modulus=1GPa,work-of-adhesion=0.08")?,
        ]
    } else {
        args.materials.clone()
    };
    let quiet = args.out.quiet;
    let (rows, curves) = contrast::contrast(
        &base,
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
        let mut header = vec!["law".to_string(), "amplitude_ratio".into()];
        header.extend(materials.iter().map(|m| format!("phase_deg_{}", m.name)));
        header.push("delta_phase_deg".into());
        let fail = |e: csv::Error| crate::Error::Output {
            path: path.clone(),
            reason: e.to_string(),
        };
        w.write_record(&header).map_err(fail)?;
        for r in &rows {
            let mut rec = vec![r.law.clone(), r.amplitude_ratio.to_string()];
            rec.extend(r.phase_deg.iter().map(|p| p.to_string()));
            rec.push(r.delta_phase_deg.to_string());
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
                .map(|(i, law)| {
                    let pts = rows
                        .iter()
                        .filter(|r| r.law == law.to_string() && r.delta_phase_deg.is_finite())
                        .map(|r| (r.amplitude_ratio, r.delta_phase_deg))
                        .collect();
                    Series::new(&law.to_string(), pts, Style::Line, i + 1)
                })
                .collect(),
            labels: vec![],
            legend: Corner::UpperRight,
        });
        plot::render_stack(&charts, path)?;
    }
    if args.out.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&rows).expect("serialises")
        );
    } else {
        println!("{:>18} {:>8} {:>12}", "law", "A/A0", "Δφ (deg)");
        for r in &rows {
            println!(
                "{:>18} {:>8.3} {:>12.3}",
                r.law, r.amplitude_ratio, r.delta_phase_deg
            );
        }
    }
    Ok(())
}
