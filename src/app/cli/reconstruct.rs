//! `tapsim reconstruct`: from an AM approach curve back to the tip–sample force and the
//! dissipation against the closest distance.

use super::curve_data::{Columns, read_curve};
use crate::analysis::reconstruct::{
    AmCurve, FmCurve, Inversion, Probe, Reconstruction, law_branches_hat, reconstruct,
    reconstruct_fm,
};
use crate::app::config::TapInputs;
use crate::app::report::display::fixed;
use crate::app::report::reconstruct::{LawCurves, PlotRow, charts};
use crate::dynamics::setup::Prepared;
use crate::error::{Error, Result};
use crate::physics::law::ForceLaw;
use crate::physics::params::ELECTRONVOLT_J;
use clap::{Args, ValueEnum};
use serde::Serialize;
use std::path::PathBuf;

/// The force an AM curve implies (Hölscher 2006; Katan, van Es & Oosterkamp 2009): from
/// the amplitude A and phase φ read at each rest separation z_c, the tip–sample force
/// against the closest distance D = z_c + z̄ − A the tip reaches, and the energy it
/// loses there per cycle.
///
/// At each point the harmonic balance of the driven cantilever gives the force's
/// component in phase with the motion — the frequency shift an FM measurement would
/// read — and the energy dissipated (Cleveland et al. 1998). The first is inverted by
/// the Sader–Jarvis formula with each distance's own amplitude, so the amplitude may
/// change along the curve as it does in AM (--inversion first-order: the relation
/// inverted exactly, for forces that bend sharply; sample those finely either way). No law is assumed: for measured curves give
/// the cantilever (--stiffness, --quality, --free-amplitude, --resonance,
/// --drive-frequency); with --with-law the setup's law is listed and drawn beside, for
/// curves it simulated:
///
///   tapsim approach --law dmt --work-of-adhesion 0.02 --from 30nm --to 6nm \
///       --points 240 --no-retract --csv dmt.csv
///   tapsim reconstruct dmt.csv --law dmt --work-of-adhesion 0.02 --with-law --plot f.png
///
/// DATA is a CSV with a position (z_c_nm, z_m, separation_m, …; its zero shifts D by
/// the same), an amplitude (amplitude_nm, amplitude_m or amplitude_ratio), phase_deg,
/// and if measured the mean deflection (deflection_nm, deflection_m, or mean_force_n as
/// `tapsim approach --csv` writes it; without it D leaves out the static deflection).
/// Rows of a `direction` column other than --direction are left out. The curve must
/// start where the tip does not yet feel the sample (the force beyond it is taken as
/// zero); points whose D is no nearer than a farther point's are left out and counted.
///
/// With --mode fm the curve is an FM approach (as `tapsim fm --csv` writes it, or an
/// instrument's): a position, the frequency shift (frequency_shift_hz or df_hz, counted
/// from --resonance) and the excitation over its free value (excitation_ratio, F/F₀),
/// at the amplitude held (an amplitude column, else --free-amplitude). The in-phase
/// force is −kA((f/f₀)² − 1)/2 and the loss (πkA²/Q)(F/F₀ − f/f₀) (Anczykowski et al.
/// 1999):
///
///   tapsim fm --law dmt --from 30nm --to 17nm --points 200 --csv fm.csv
///   tapsim reconstruct fm.csv --mode fm --law dmt --with-law
///
/// What it makes of a hysteretic law: the inversion assumes one force at each distance.
/// A contact that loses energy gives the mean of its approach and retract forces only
/// where every orbit follows the same loop; a law that jumps in (adhesion hysteresis)
/// puts its loop into a spike near the jump-in distance. The report says so whenever the
/// curve dissipates.
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct ReconstructArgs {
    /// The curve (CSV with a header, see above).
    data: PathBuf,
    /// Which rows of a `direction` column to read.
    #[arg(long, value_enum, default_value_t = Branch::Approach)]
    direction: Branch,
    /// What the curve measured: amplitude and phase (am) or frequency shift and
    /// excitation at a held amplitude (fm).
    #[arg(long, value_enum, default_value_t = Mode::Am)]
    mode: Mode,
    /// How the shifts become a force: the Sader–Jarvis formula, or the first-order
    /// relation inverted exactly (Giessibl's matrix method, force linear between the
    /// points), which stays exact where the force bends sharply.
    #[arg(long, value_enum, default_value_t = InversionArg::SaderJarvis)]
    inversion: InversionArg,
    /// List and draw the setup's law at each D: its force on the way in (approach) and
    /// on the way out (retract), for curves it simulated.
    #[arg(long)]
    with_law: bool,
    #[command(flatten)]
    inputs: TapInputs,
    /// Write the reconstruction as CSV.
    #[arg(long, help_heading = "Output")]
    csv: Option<PathBuf>,
    /// Plot the force and E_ts against D (.png or .svg).
    #[arg(long, help_heading = "Output")]
    plot: Option<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long, help_heading = "Output")]
    json: bool,
    /// No notes on stderr.
    #[arg(long, short = 'q', help_heading = "Output")]
    pub(super) quiet: bool,
}

/// The branch of the curve to read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Branch {
    /// The approach rows.
    Approach,
    /// The retract rows.
    Retract,
}

/// The kind of curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Mode {
    /// Amplitude modulation: amplitude and phase at a fixed drive.
    Am,
    /// Frequency modulation: frequency shift and excitation at a held amplitude.
    Fm,
}

/// The inversion, as the command line names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum InversionArg {
    /// Sader & Jarvis, APL 84, 1801 (2004).
    SaderJarvis,
    /// The first-order relation inverted exactly (Giessibl, APL 78, 123, 2001).
    FirstOrder,
}

impl From<InversionArg> for Inversion {
    fn from(a: InversionArg) -> Self {
        match a {
            InversionArg::SaderJarvis => Self::SaderJarvis,
            InversionArg::FirstOrder => Self::FirstOrder,
        }
    }
}

/// One row of the output: the reconstruction, and the law's forces where asked for.
#[derive(Debug, Serialize)]
pub struct Row {
    #[serde(flatten)]
    point: crate::analysis::reconstruct::ReconstructedPoint,
    #[serde(skip_serializing_if = "Option::is_none")]
    law_approach_force_n: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    law_retract_force_n: Option<f64>,
}

/// Intervals of the grid the law is drawn on.
const LAW_GRID: usize = 800;

/// Run the subcommand.
pub fn run(args: ReconstructArgs) -> Result<()> {
    super::check_plot_path(args.plot.as_deref())?;
    let (setup, numerics) = args.inputs.clone().with_config()?.resolve()?;
    // The ranges `tap` enforces: a cantilever and a contact no instrument has give no
    // reconstruction, only overflow.
    setup.cantilever.validated()?;
    setup.check_plausible()?;
    let direction = match args.direction {
        Branch::Approach => "approach",
        Branch::Retract => "retract",
    };
    let Columns {
        position_m,
        setpoint_ratio,
        amplitude_m,
        phase_deg,
        mean_deflection_m,
        frequency_shift_hz,
        excitation_ratio,
        ..
    } = read_curve(
        &args.data,
        &setup.cantilever,
        None,
        direction,
        &super::curve_data::Reading::default(),
    )?;
    if setpoint_ratio.is_some() {
        return Err(Error::NotApplicable(format!(
            "{}: a reconstruction needs the positions the curve was taken at (setpoints \
             alone do not place the tip)",
            args.data.display()
        )));
    }
    let c = &setup.cantilever;
    let probe = Probe {
        stiffness_n_m: c.stiffness_n_m,
        quality: c.quality,
        free_amplitude_m: c.free_amplitude_m,
        frequency_ratio: c.omega_ratio(),
    };
    let r = match args.mode {
        Mode::Am => {
            let (Some(amplitude_m), Some(phase_deg)) = (amplitude_m, phase_deg) else {
                return Err(Error::NotApplicable(format!(
                    "{}: a reconstruction needs both the amplitude and the phase{}",
                    args.data.display(),
                    if frequency_shift_hz.is_some() {
                        " (this is an FM curve: --mode fm)"
                    } else {
                        ""
                    }
                )));
            };
            reconstruct(
                &probe,
                &AmCurve {
                    separation_m: position_m,
                    amplitude_m,
                    phase_deg,
                    mean_deflection_m,
                },
                args.inversion.into(),
            )?
        }
        Mode::Fm => {
            let (Some(frequency_shift_hz), Some(excitation_ratio)) =
                (frequency_shift_hz, excitation_ratio)
            else {
                return Err(Error::NotApplicable(format!(
                    "{}: an FM reconstruction needs the frequency shift (frequency_shift_hz \
                     or df_hz) and the excitation over its free value (excitation_ratio)",
                    args.data.display()
                )));
            };
            reconstruct_fm(
                &probe,
                c.resonance_hz,
                &FmCurve {
                    separation_m: position_m,
                    frequency_shift_hz,
                    excitation_ratio,
                    amplitude_m,
                    mean_deflection_m,
                },
                args.inversion.into(),
            )?
        }
    };
    let fm_resonance = (args.mode == Mode::Fm).then_some(c.resonance_hz);
    let law = if args.with_law {
        let p = Prepared::new(&setup, &numerics)?;
        let (scale, force) = (
            p.setup.contact.separation_scale_m(),
            p.setup.contact.force_scale_n(),
        );
        let mut notes = Vec::new();
        if p.law.is_rate_dependent() {
            notes.push(
                "the law has a rate-dependent part: its forces listed are the elastic part's"
                    .to_string(),
            );
        }
        let at = |d_m: f64| {
            let (a, b) = law_branches_hat(&p.law, d_m / scale);
            (a * force, b * force)
        };
        let forces: Vec<(f64, f64)> = r.points.iter().map(|q| at(q.closest_m)).collect();
        // The law drawn on a fine grid over the distances the curve reaches (its jumps
        // fall between the data's points).
        let (lo, hi) = (
            r.points[0].closest_m,
            r.points[r.points.len() - 1].closest_m,
        );
        let grid: Vec<f64> = (0..=LAW_GRID)
            .map(|i| lo + (hi - lo) * i as f64 / LAW_GRID as f64)
            .collect();
        let (approach_nn, retract_nn) = grid
            .iter()
            .map(|&d| {
                let (a, b) = at(d);
                (a * 1e9, b * 1e9)
            })
            .unzip();
        let curves = LawCurves {
            name: setup.law.to_string(),
            closest_nm: grid.iter().map(|d| d * 1e9).collect(),
            approach_nn,
            retract_nn,
        };
        Some((curves, forces, notes))
    } else {
        None
    };
    let rows: Vec<Row> = r
        .points
        .iter()
        .enumerate()
        .map(|(i, &point)| Row {
            point,
            law_approach_force_n: law.as_ref().map(|l| l.1[i].0),
            law_retract_force_n: law.as_ref().map(|l| l.1[i].1),
        })
        .collect();
    let mut notes = r.notes.clone();
    if let Some((_, _, n)) = &law {
        notes.extend(n.iter().cloned());
    }
    if let Some(path) = &args.csv {
        crate::app::report::output::write_bytes(
            path,
            &crate::app::report::records::records_csv(&rows)?,
        )?;
    }
    if let Some(path) = &args.plot {
        let source = args
            .data
            .file_name()
            .map_or("data".into(), |n| n.to_string_lossy().into_owned());
        let plotted: Vec<PlotRow> = rows
            .iter()
            .map(|r| PlotRow {
                closest_nm: r.point.closest_m * 1e9,
                force_nn: r.point.force_n * 1e9,
                e_ts_ev: r.point.e_ts_j / ELECTRONVOLT_J,
            })
            .collect();
        crate::app::report::plot::render_stack(
            &charts(
                &plotted,
                &source,
                law.as_ref().map(|l| &l.0),
                if fm_resonance.is_some() {
                    "excitation"
                } else {
                    "phase"
                },
            ),
            path,
        )?;
    }
    if args.json {
        let mut v = crate::app::report::records::columns_json(&rows)?;
        v["inversion"] = serde_json::json!(r.inversion);
        v["far_end_shift_ratio"] = r.far_end_shift_ratio.into();
        v["notes"] = notes.clone().into();
        outln!("{}", crate::app::report::records::document(&v)?);
    } else {
        out!(
            "{}",
            text(
                &r,
                &rows,
                law.as_ref().map(|l| l.0.name.as_str()),
                &notes,
                fm_resonance
            )
        );
    }
    Ok(())
}

/// The table; with `fm_resonance` (f₀, Hz) an FM curve's, its frequency shift in the
/// phase's place.
fn text(
    r: &Reconstruction,
    rows: &[Row],
    law: Option<&str>,
    notes: &[String],
    fm_resonance: Option<f64>,
) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "force reconstruction ({} on the in-phase force, {}) from {} points",
        match r.inversion {
            Inversion::SaderJarvis => "Sader–Jarvis",
            Inversion::FirstOrder => "first-order inverse",
        },
        if fm_resonance.is_some() {
            "FM: amplitude held"
        } else {
            "amplitude along the curve"
        },
        r.points.len()
    );
    let _ = write!(
        s,
        "{:>9} {:>9} {:>9} {:>9} {:>10} {:>11}",
        "z_c (nm)",
        "D (nm)",
        "A (nm)",
        if fm_resonance.is_some() {
            "Δf (Hz)"
        } else {
            "phi (deg)"
        },
        "F (nN)",
        "E_ts (eV)"
    );
    if let Some(law) = law {
        let _ = write!(
            s,
            "  {:>12} {:>12}",
            format!("{law} in"),
            format!("{law} out")
        );
    }
    let _ = writeln!(s);
    for row in rows {
        let p = &row.point;
        let cells = [
            (p.separation_m * 1e9, 9),
            (p.closest_m * 1e9, 9),
            (p.amplitude_m * 1e9, 9),
            // (Δf back from Ω_eff = ((f/f₀)² − 1)/2.)
            (
                fm_resonance.map_or(p.phase_deg, |f0| {
                    ((1.0 + 2.0 * p.frequency_shift).sqrt() - 1.0) * f0
                }),
                9,
            ),
            (p.force_n * 1e9, 10),
            (p.e_ts_j / ELECTRONVOLT_J, 11),
        ];
        for (i, (v, w)) in cells.into_iter().enumerate() {
            let sep = if i == 0 { "" } else { " " };
            let _ = write!(s, "{sep}{:>w$}", fixed(v, 4));
        }
        if let (Some(a), Some(b)) = (row.law_approach_force_n, row.law_retract_force_n) {
            let _ = write!(s, "  {:>12} {:>12}", fixed(a * 1e9, 4), fixed(b * 1e9, 4));
        }
        let _ = writeln!(s);
    }
    for note in notes {
        let _ = writeln!(s, "note: {note}");
    }
    s
}
