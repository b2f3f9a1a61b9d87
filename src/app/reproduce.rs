//! `tapsim reproduce`: regenerate the paper's figures and a set of tapping-mode figures,
//! with a generated `README.md` that lists every file and the headline numbers.

use crate::analysis::identification::{self, Normalized};
use crate::analysis::sweep::{self, Direction, SweepPoint};
use crate::app::figures::{self, FigureOptions};
use crate::app::report::chart::{Axis, Chart, Corner, Series, Style};
use crate::app::report::{output, plot, records, sweep as sweep_report, tap as tap_report};
use crate::dynamics::modes::ModeSet;
use crate::dynamics::observables::{Observe, tap};
use crate::dynamics::setup::{Numerics, TapSetup, default_setup};
use crate::error::{Error, Result};
use crate::physics::contact::hybrid;
use crate::physics::contact::jkr;
use crate::physics::contact::lj::{self, Reach};
use crate::physics::contact::semi_rigid;
use crate::physics::law::{LawKind, LawSpec};
use crate::physics::params::{Contact, ELECTRONVOLT_J, composite_modulus};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The laws compared in the tapping figures.
const LAWS: [LawKind; 3] = [LawKind::Jkr, LawKind::Hybrid, LawKind::Lj];

/// The amplitude setpoint of the phase-contrast figure's marked states (the README's
/// Δφ), and the setpoints on each of its approach curves (`tapsim contrast`'s default).
const CONTRAST_SETPOINT: f64 = 0.8;
const CONTRAST_POINTS: usize = 50;

/// The viscous sample of the identification figure (Pa·s): one that settles on the
/// repulsive orbit at the defaults (from about 25 Pa·s it does not).
const IDENTIFICATION_VISCOSITY_PA_S: f64 = 10.0;

/// A second, stiffer and less adhesive polymer for the phase-contrast figure
/// (E = 1 GPa, ν = 0.4, Δγ = 0.08 J/m²: μ ≈ 1.5).
pub fn second_material() -> Contact {
    let e = composite_modulus(169e9, 0.28, 1e9, 0.4).expect("valid");
    Contact::new(20e-9, e, 0.08, 0.3e-9).expect("valid")
}

/// One generated file and what it shows.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Entry {
    /// File name in the output directory.
    pub file: String,
    /// What it shows.
    pub what: String,
}

/// What `reproduce` wrote and the headline numbers of its README, for machines.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Manifest {
    /// Every file written, in order (README.md last).
    pub files: Vec<Entry>,
    /// Ŵ_JKR, eq. (9).
    pub w_hat_jkr: f64,
    /// Ŵ_LJ(μ = 5) with its error estimate as `{value, error}`: deprecated, kept for one
    /// release; `lj_mu5.w_hat` and `lj_mu5.w_hat_error` are the same numbers in the
    /// convention every other document follows.
    pub w_hat_lj_mu5: lj::Estimate,
    /// Ŵ_hybrid(μ = 5), eq. (18).
    pub w_hat_hybrid_mu5: f64,
    /// The pull-off at μ = 5 over JKR's 3π/2.
    pub pull_off_over_jkr_mu5: f64,
    /// The default tap's observables.
    pub default_tap: crate::dynamics::observables::TapObservables,
    /// The Lennard-Jones solution at μ = 5 (every `tapsim lj --mu 5 --json` key).
    pub lj_mu5: crate::physics::summary::LjSummary,
}

fn approach(setup: &TapSetup, law: impl Into<LawSpec>, points: usize) -> Result<Vec<SweepPoint>> {
    let setup = TapSetup {
        law: law.into(),
        ..setup.clone()
    };
    let a0 = setup.cantilever.free_amplitude_m;
    let ramp = sweep::ramp(1.2 * a0, 0.4 * a0, points, true)?;
    let numerics = sweep::sweep_numerics(Numerics::default(), (false, false));
    sweep::approach_curve(&setup, &numerics, &ramp, |_, _| {})
}

/// `charts` stacked into `stem`.png and `stem`.svg in `out`; the two paths.
fn render_stack(out: &Path, stem: &str, charts: &[Chart]) -> Result<Vec<PathBuf>> {
    ["png", "svg"]
        .into_iter()
        .map(|ext| {
            let path = out.join(format!("{stem}.{ext}"));
            plot::render_stack(charts, &path)?;
            Ok(path)
        })
        .collect()
}

/// `records` as CSV into `stem`.csv in `out`; its path.
fn write_records<T: serde::Serialize>(out: &Path, stem: &str, records: &[T]) -> Result<PathBuf> {
    let path = out.join(format!("{stem}.csv"));
    output::write_bytes(&path, &records::records_csv(records)?)?;
    Ok(path)
}

/// The first mode's setpoints of the bimodal contrast (`tapsim contrast`'s default).
const BIMODAL_SETPOINTS: [f64; 5] = [0.9, 0.8, 0.7, 0.6, 0.5];

/// Grid points per axis of the two maps.
const MAP_STEPS: usize = 6;

/// The amplitude setpoint of the phase image at constant setpoint.
const MAP_SETPOINT: f64 = 0.8;

/// The first line of the generated README.md, which marks a directory as ours.
const README_TITLE: &str = "# tapsim results";

/// The file written into `out` before anything else and removed once README.md is
/// written: it marks a directory that a run which was interrupted was filling, so the
/// run can be repeated into it.
const MARKER: &str = ".tapsim-reproduce-running";

/// `out` must be new, empty, or an earlier output of this command (finished, with our
/// README.md, or interrupted, with [`MARKER`]): it is filled with some thirty files of
/// fixed names, which must not overwrite someone else's.
fn check_out_dir(out: &Path) -> Result<()> {
    let Ok(mut entries) = std::fs::read_dir(out) else {
        return Ok(());
    };
    let ours = std::fs::read_to_string(out.join("README.md"))
        .is_ok_and(|text| text.starts_with(README_TITLE))
        || std::fs::symlink_metadata(out.join(MARKER)).is_ok_and(|m| m.is_file());
    if entries.next().is_none() || ours {
        Ok(())
    } else {
        Err(Error::Output {
            path: out.to_path_buf(),
            reason: "the directory is not empty and holds no earlier `tapsim reproduce` \
                     output (no README.md of ours); give a new or empty directory"
                .into(),
        })
    }
}

/// Regenerate everything into `out`; `progress` is told what is being made. Returns the
/// files written (README.md last).
pub fn reproduce(out: &Path, mut progress: impl FnMut(&str)) -> Result<Manifest> {
    check_out_dir(out)?;
    output::ensure_dir(out)?;
    let marker = out.join(MARKER);
    output::write_bytes(
        &marker,
        b"tapsim reproduce is writing here (or was, and was interrupted)\n",
    )?;
    let mut entries: Vec<Entry> = Vec::new();
    let mut written: Vec<PathBuf> = Vec::new();
    let mut add = |paths: Vec<PathBuf>, what: &str, entries: &mut Vec<Entry>| {
        for p in paths {
            entries.push(Entry {
                file: p
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                what: what.into(),
            });
            written.push(p);
        }
    };
    // The paper's figures.
    let opts = FigureOptions::default();
    let captions = [
        "Fig. 1: JKR loading and unloading under rigid grips, eqs. (5), (8), (9)",
        "Fig. 2: Lennard-Jones force-separation curve for mu = 5 (numerical) beside JKR",
        "Fig. 3: jump-in separation vs mu: numerical LJ, semi-rigid (14)-(15), (16), fit (17)",
        "Fig. 4: hysteresis loss vs mu: numerical LJ, hybrid (18), JKR (9)",
        "Fig. 5: loading-unloading cycle with a compliant support (mu = 5, k_hat = 2), eq. (26)",
        "Fig. 6: hysteresis loss vs support stiffness for mu = 2, 5, 10, 20, eqs. (26), (27)",
    ];
    for (n, caption) in (1..=6).zip(captions) {
        progress(&format!("figure {n}"));
        let chart = figures::figure(n, &opts)?;
        add(chart.write_all(out)?, caption, &mut entries);
    }
    let solutions = figures::lj_solutions()?;
    let table = out.join("fig3_lj_vs_fit.csv");
    output::write_bytes(&table, &figures::lj_fit_table(&solutions)?)?;
    add(
        vec![table],
        "numerical alpha_A and W_LJ for mu = 1 ... 50 against the fit (17) and the hybrid (18)",
        &mut entries,
    );

    // Tapping: one trajectory on the defaults.
    progress("default tap");
    let setup = default_setup();
    let run = tap(&setup, &Numerics::default(), Observe::recording(3))?;
    let charts =
        tap_report::trajectory_charts(&run, "hybrid law, defaults (z_c = 16 nm, A₀ = 20 nm)");
    add(
        render_stack(out, "tap_trajectory", &charts)?,
        "default tap (hybrid law): deflection, force, force-separation loop",
        &mut entries,
    );
    let path = out.join("tap_trajectory.csv");
    output::write_bytes(&path, &tap_report::trajectory_csv(&run.trajectory)?)?;
    add(vec![path], "default tap: trajectory samples", &mut entries);

    // Approach curves and phase contrast for JKR, hybrid and LJ, two materials.
    let materials = [
        ("polymer A", setup.contact),
        ("polymer B", second_material()),
    ];
    progress("approach curves, polymers A and B, three laws (in parallel)");
    let curves: Vec<(String, LawKind, Vec<SweepPoint>)> = {
        use rayon::prelude::*;
        let pairs: Vec<(&str, Contact, LawKind)> = materials
            .iter()
            .flat_map(|&(name, contact)| LAWS.iter().map(move |&law| (name, contact, law)))
            .collect();
        pairs
            .par_iter()
            .map(|&(name, contact, law)| {
                let s = TapSetup {
                    contact,
                    ..setup.clone()
                };
                Ok((name.to_string(), law, approach(&s, law, 40)?))
            })
            .collect::<Result<_>>()?
    };
    let series_for =
        |material: &str, y: fn(&SweepPoint) -> f64, x: fn(&SweepPoint) -> f64| -> Vec<Series> {
            let xy = |p: &SweepPoint| (x(p), y(p));
            let mine: Vec<&(String, LawKind, Vec<SweepPoint>)> =
                curves.iter().filter(|(m, _, _)| m == material).collect();
            let mut series: Vec<Series> = mine
                .iter()
                .enumerate()
                .flat_map(|(i, (_, law, pts))| {
                    [
                        (Direction::Approach, Style::Line, "approach"),
                        (Direction::Retract, Style::Dashed, "retract"),
                    ]
                    .into_iter()
                    .flat_map(move |(dir, style, what)| {
                        let on: Vec<sweep_report::Located> = pts
                            .iter()
                            .filter(|p| p.direction == dir)
                            .map(|p| sweep_report::locate(p, &xy, i + 1))
                            .collect();
                        sweep_report::period_one_lines(&on, &format!("{law} {what}"), style, i + 1)
                    })
                })
                .collect();
            let all: Vec<sweep_report::Located> = mine
                .iter()
                .enumerate()
                .flat_map(|(i, c)| c.2.iter().map(move |p| sweep_report::locate(p, &xy, i + 1)))
                .collect();
            series.extend(sweep_report::not_period_one(&all));
            series
        };
    let zc = |p: &SweepPoint| p.separation_m * 1e9;
    let mut approach_charts = vec![
        Chart {
            name: "tap_approach_amplitude".into(),
            title: "Approach curves, polymer A: amplitude".into(),
            x: sweep_report::separation_axis(),
            y: Axis::linear("A/A₀", "amplitude_ratio"),
            series: series_for("polymer A", |p| p.observables.amplitude_ratio, zc),
            labels: vec![],
            legend: Corner::UpperRight,
        },
        Chart {
            name: "tap_approach_phase".into(),
            title: "Approach curves, polymer A: phase".into(),
            x: sweep_report::separation_axis(),
            y: Axis::linear("phase lag φ (deg)", "phase_deg"),
            series: series_for("polymer A", |p| p.observables.phase_deg, zc),
            labels: vec![],
            legend: Corner::LowerLeft,
        },
        Chart {
            name: "tap_approach_dissipation".into(),
            title: "Approach curves, polymer A: dissipation".into(),
            x: sweep_report::separation_axis(),
            y: Axis::linear("E_ts per cycle (eV)", "e_ts_ev"),
            series: series_for("polymer A", |p| p.observables.e_ts_ev, zc),
            labels: vec![],
            legend: Corner::UpperRight,
        },
    ];
    for chart in &mut approach_charts {
        chart.legend = Corner::quietest(&chart.series);
    }
    crate::app::report::chart::share_legends(&mut approach_charts);
    add(
        render_stack(out, "tap_approach_laws", &approach_charts)?,
        "approach-retract curves for the jkr, hybrid and lj laws (polymer A)",
        &mut entries,
    );
    let mut records = Vec::new();
    for (material, law, pts) in &curves {
        for p in pts {
            records.push(serde_json::json!({
                "material": material,
                "law": law.to_string(),
                "separation_m": p.separation_m,
                "direction": p.direction,
                "amplitude_ratio": p.observables.amplitude_ratio,
                "phase_deg": p.observables.phase_deg,
                "e_ts_j": p.observables.e_ts_j,
                "regime": p.observables.regime,
                "converged": p.observables.converged,
            }));
        }
    }
    add(
        vec![write_records(out, "tap_approach_laws", &records)?],
        "approach-retract curves, both polymers, all three laws",
        &mut entries,
    );
    // Phase contrast: phase vs A/A₀ on approach for both materials, per law, as
    // `tapsim contrast` computes it, with the states at the setpoint 0.8 and their Δφ.
    progress("phase contrast at A/A0 = 0.8");
    let contrast_materials = crate::app::config::MaterialSpec::defaults()?
        .iter()
        .map(|m| m.resolve(&crate::app::config::TapInputs::default()))
        .collect::<Result<Vec<_>>>()?;
    let (rows, law_curves) = crate::analysis::contrast::contrast(
        &contrast_materials,
        &LAWS,
        (&[CONTRAST_SETPOINT], CONTRAST_POINTS),
        None,
        |_| {},
    )?;
    let contrast: Vec<Chart> = LAWS
        .iter()
        .map(|&law| {
            let named: Vec<(String, &[SweepPoint])> = law_curves
                .iter()
                .filter(|c| c.law == law)
                .map(|c| (format!("polymer {}", c.material), c.points.as_slice()))
                .collect();
            let per_material: Vec<(&str, &[SweepPoint])> =
                named.iter().map(|(n, p)| (n.as_str(), *p)).collect();
            let mut chart = sweep_report::phase_vs_amplitude(
                &format!("contrast_{law}"),
                &format!("{law} law"),
                &per_material,
            );
            let of_law: Vec<&crate::analysis::contrast::ContrastRow> =
                rows.iter().filter(|r| r.law == law.to_string()).collect();
            crate::app::report::contrast::mark_setpoint_states(&mut chart, &of_law);
            chart
        })
        .collect();
    add(
        render_stack(out, "tap_phase_contrast", &contrast)?,
        "phase vs A/A0 for polymers A and B under the jkr, hybrid and lj laws, with the \
         states at A/A0 = 0.8 and their phase contrast",
        &mut entries,
    );

    // Bimodal contrast: the same polymers with a beam's second mode (A₀₂ = A₀/40), φ₁ and
    // φ₂ at the first mode's setpoints, as `tapsim contrast --modes 2` computes them.
    progress("bimodal phase contrast");
    let modes = ModeSet::euler_bernoulli(&contrast_materials[0].setup.cantilever, 2)?;
    let bimodal_rows = crate::analysis::bimodal::contrast(
        &contrast_materials,
        &modes,
        &LAWS,
        &BIMODAL_SETPOINTS,
        || {},
    )?;
    let law_names: Vec<String> = LAWS.iter().map(ToString::to_string).collect();
    let mut paths = render_stack(
        out,
        "tap_bimodal_contrast",
        &crate::app::report::modes::contrast_charts(&bimodal_rows, &law_names),
    )?;
    paths.push(write_records(out, "tap_bimodal_contrast", &bimodal_rows)?);
    add(
        paths,
        "bimodal phase contrast between polymers A and B under jkr, hybrid and lj, branch by branch: Δφ₂ of \
         a beam's second mode and Δφ₁ at the first mode's setpoints",
        &mut entries,
    );

    // Identification curves: adhesion hysteresis (hybrid) against a viscous sample
    // (Hertz + Kelvin–Voigt) and a capillary water neck (on Hertz), polymer A.
    progress("identification curves");
    let viscous = LawSpec {
        viscosity_pa_s: Some(IDENTIFICATION_VISCOSITY_PA_S),
        ..LawKind::Hertz.into()
    };
    let neck = LawSpec {
        rupture_distance_m: Some(1e-9),
        contact_angle_deg: Some(60.0),
        ..LawKind::Hertz.into()
    };
    let mechanisms = [
        (
            "hybrid: adhesion hysteresis",
            approach(&setup, LawKind::Hybrid, 40)?,
        ),
        (
            "hertz + kelvin-voigt 10 Pa·s: viscous",
            approach(&setup, viscous, 40)?,
        ),
        (
            "hertz + water neck (1 nm, 60°): capillary",
            approach(&setup, neck, 40)?,
        ),
    ];
    let normalized: Vec<Vec<Normalized>> = mechanisms
        .iter()
        .map(|(_, points)| identification::normalize(points))
        .collect();
    let curves: Vec<(&str, &[SweepPoint], &[Normalized])> = mechanisms
        .iter()
        .zip(&normalized)
        .map(|((name, points), n)| (*name, points.as_slice(), n.as_slice()))
        .collect();
    // (The CSV's law column: the legend's name before its colon.)
    let law_of = |name: &str| name.split(':').next().unwrap_or(name).to_string();
    let mut chart = sweep_report::identification_chart(
        "tap_identification",
        "Identification curves (approach, polymer A)",
        &curves,
    );
    // E/E_max from 0 to its plateau at 1, where the hysteresis and the neck step to
    // alike: said on the figure, since one line hides the other there.
    chart.y.range = Some((0.0, 1.1));
    chart.labels.push(crate::app::report::chart::Label {
        text: "hybrid and capillary plateaus coincide at 1".into(),
        x: 0.4,
        y: 1.05,
    });
    add(
        render_stack(out, "tap_identification", std::slice::from_ref(&chart))?,
        "E_ts/E_max vs A/A0 on approach: adhesion hysteresis (hybrid) and a capillary \
             neck step to a plateau, a viscous sample (hertz + kelvin-voigt) peaks inside",
        &mut entries,
    );
    let mut records = Vec::new();
    for ((law, points), n) in mechanisms.iter().zip(&normalized) {
        for (p, n) in points.iter().zip(n) {
            records.push(serde_json::json!({
                "law": law_of(law),
                "separation_m": p.separation_m,
                "direction": p.direction,
                "amplitude_ratio": p.observables.amplitude_ratio,
                "e_ts_j": p.observables.e_ts_j,
                "e_ts_adhesion_j": p.observables.e_ts_adhesion_j,
                "e_ts_viscous_j": p.observables.e_ts_viscous_j,
                "e_ts_capillary_j": p.observables.e_ts_capillary_j,
                "e_ts_norm": n.e_ts_norm,
                "regime": p.observables.regime,
            }));
        }
    }
    add(
        vec![write_records(out, "tap_identification", &records)?],
        "identification curves: each setpoint's dissipation by mechanism, normalized",
        &mut entries,
    );

    // Phase images: at one rest separation, and at a constant amplitude setpoint as an
    // AFM images (repulsive branch), over the same (Δγ, E*) grid.
    progress("maps at one separation and at a setpoint");
    let map_setup = default_setup();
    let map_numerics = Numerics::default();
    let works = sweep::log_grid("work of adhesion", 0.02, 0.2, MAP_STEPS)?;
    let moduli = sweep::log_grid("modulus", 0.3e9, 3e9, MAP_STEPS)?;
    let law = map_setup.law.to_string();
    let cells: Vec<usize> = (0..MAP_STEPS * MAP_STEPS).collect();
    let at_separation = sweep::map_cells(
        &map_setup,
        &map_numerics,
        (&works, &moduli),
        &cells,
        0,
        || {},
        None,
    )?;
    let setpoint = crate::app::report::part::MapSetpoint {
        amplitude_ratio: MAP_SETPOINT,
        branch: crate::analysis::setpoint::PhaseBranch::Repulsive,
    };
    let at_setpoint = crate::analysis::setpoint::map_cells(
        &map_setup,
        &map_numerics,
        (&works, &moduli),
        &cells,
        0,
        || {},
        (setpoint.amplitude_ratio, setpoint.branch),
        None,
    )?;
    for (stem, cells, caption, what) in [
        (
            "tap_map_separation",
            &at_separation,
            None,
            "map over (Δγ, E*) at the default rest separation 16 nm: E_ts, φ, A/A₀",
        ),
        (
            "tap_map_setpoint",
            &at_setpoint,
            Some(setpoint.caption()),
            "map over (Δγ, E*) at the amplitude setpoint A/A₀ = 0.8, repulsive branch: E_ts, \
             φ and the apparent height Δz_c",
        ),
    ] {
        let maps =
            crate::app::report::map::heat_maps(&law, caption.as_deref(), &works, &moduli, cells);
        let mut paths = Vec::new();
        for ext in ["png", "svg"] {
            let path = out.join(format!("{stem}.{ext}"));
            plot::render_heatmaps(&maps, &path)?;
            paths.push(path);
        }
        paths.push(write_records(out, stem, cells)?);
        add(paths, what, &mut entries);
    }

    // Headline numbers and the README.
    progress("README.md");
    let lj5 = crate::app::lj_cache::solve(5.0, Reach::Rigid, true)?;
    let w_jkr = jkr::w_hat_jkr();
    let w_h5 = hybrid::w_hat_fit(5.0);
    let o = &run.observables;
    let mut md = String::new();
    let _ = writeln!(md, "{README_TITLE}\n");
    let _ = writeln!(
        md,
        "Generated by `tapsim reproduce`; do not edit by hand.\n"
    );
    let _ = writeln!(md, "## Headline numbers\n");
    let _ = writeln!(md, "| quantity | value |\n| --- | --- |");
    let _ = writeln!(md, "| Ŵ_JKR, eq. (9) | {w_jkr:.4} |");
    let _ = writeln!(
        md,
        "| Ŵ_LJ(μ = 5), numerical | {:.5} ± {:.1e} (paper: 3.2482) |",
        lj5.w_hat.value, lj5.w_hat.error
    );
    let _ = writeln!(
        md,
        "| Ŵ_hybrid(μ = 5), eq. (18) | {w_h5:.5} ({:+.2} % against Ŵ_LJ) |",
        100.0 * (w_h5 - lj5.w_hat.value) / lj5.w_hat.value
    );
    let _ = writeln!(
        md,
        "| pull-off at μ = 5 / (3π/2) | {:.4} |",
        lj5.pull_off_hat.value / jkr::PULL_OFF_T_HAT
    );
    for s in solutions.iter().filter(|s| s.tabor_mu >= 2.0) {
        let fit = semi_rigid::alpha_hat_a_fit(s.tabor_mu);
        let _ = writeln!(
            md,
            "| fit (17) vs numerical α̂_A, μ = {} | {fit:.5} vs {:.5} ({:+.2} %) |",
            s.tabor_mu,
            s.alpha_hat_a.value,
            100.0 * (fit - s.alpha_hat_a.value) / s.alpha_hat_a.value
        );
    }
    let _ = writeln!(
        md,
        "| default tap (hybrid, μ = {:.2}): motion | {}{} |",
        o.tabor_mu,
        o.regime,
        match o.stable {
            Some(true) => ", stable",
            Some(false) => ", unstable",
            None => "",
        }
    );
    let _ = writeln!(md, "| default tap: A/A₀ | {:.5} |", o.amplitude_ratio);
    let _ = writeln!(
        md,
        "| default tap: φ (lock-in / from energy) | {:.4}° / {:.4}° |",
        o.phase_deg, o.phase_from_energy_deg
    );
    let _ = writeln!(
        md,
        "| default tap: E_ts per cycle | {:.4e} J = {:.3} eV |",
        o.e_ts_j,
        o.e_ts_j / ELECTRONVOLT_J
    );
    for r in bimodal_rows.iter().filter(|r| r.setpoint == 0.8) {
        let f = |v: Option<f64>| v.map_or("–".into(), |v| format!("{v:.3}°"));
        let _ = writeln!(
            md,
            "| bimodal contrast B − A at A₁/A₀₁ = 0.8, {}, {}: Δφ₂ / Δφ₁ | {} / {} |",
            r.law,
            r.branch,
            f(r.delta_phase2_deg),
            f(r.delta_phase1_deg)
        );
    }
    let _ = writeln!(md, "\n## Files\n");
    let _ = writeln!(md, "| file | shows |\n| --- | --- |");
    for e in &entries {
        let _ = writeln!(md, "| `{}` | {} |", e.file, e.what);
    }
    let _ = writeln!(
        md,
        "\nMaterials of the tapping figures: polymer A is the `tapsim tap` default (E = 0.5 GPa, \
         Δγ = 0.1 J/m², μ = {:.2}); polymer B has E = 1 GPa, Δγ = 0.08 J/m² (μ = {:.2}). \
         Cantilever: k = 40 N/m, f₀ = 300 kHz, Q = 400, A₀ = 20 nm; tip radius 20 nm, ε = 0.3 nm.",
        setup.contact.tabor_mu(),
        second_material().tabor_mu()
    );
    let readme = out.join("README.md");
    output::write_bytes(&readme, md.as_bytes())?;
    written.push(readme);
    // README.md marks the directory now.
    let _ = std::fs::remove_file(&marker);
    entries.push(Entry {
        file: "README.md".into(),
        what: "this list and the headline numbers".into(),
    });
    debug_assert_eq!(written.len(), entries.len());
    Ok(Manifest {
        files: entries,
        w_hat_jkr: w_jkr,
        w_hat_lj_mu5: lj5.w_hat,
        w_hat_hybrid_mu5: w_h5,
        pull_off_over_jkr_mu5: lj5.pull_off_hat.value / jkr::PULL_OFF_T_HAT,
        default_tap: run.observables.clone(),
        lj_mu5: crate::physics::summary::LjSummary::new(&lj5),
    })
}
