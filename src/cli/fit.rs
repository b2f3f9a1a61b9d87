//! `tapsim fit`: a measured approach curve fitted by the simulator, and what the data
//! determine.

use super::curve_data::{Columns, read_curve};
use crate::config::{TapInputs, length, number};
use crate::error::{Error, Result};
use crate::fit::{FitOptions, FitReport, Measured, Parameter, Profile, SecondMode, fit, profile};
use clap::{Args, ValueEnum};
use std::path::PathBuf;

/// From a measured approach curve back to the material: which modulus and work of
/// adhesion (and piezo offset; or, with --fit, the range ε, the dmt law's Hamaker
/// constant, a viscous sample's viscosity, a relaxing one's relaxation time, and the
/// nuisance parameters k, Q and the detector's sensitivity) make the simulated
/// approach — each point a converged steady state, started from the last as an
/// approach goes — match the amplitude and phase measured, by weighted least squares
/// (Levenberg–Marquardt), and how sure the data let one be. With --modes 2 both modes
/// are simulated and the second's channels (amplitude2_*, phase2_deg) fitted too.
///
/// DATA is a CSV whose header names the columns with their units: a position
/// (z_nm, z_m, z_c_nm, z_c_m, separation_nm, separation_m, position_nm or position_m;
/// from far to near, its zero unknown: the offset is fitted), and an amplitude
/// (amplitude_nm, amplitude_m or amplitude_ratio, A/A₀) and/or a phase (phase_deg).
/// Rows of a `direction` column other than "approach" are left out, so the CSV
/// `tapsim approach --csv curve.csv` writes is read as it is. A `segment` column joins
/// several approaches: a new one begins where its label changes, each simulated from
/// the free oscillation at its first position (as `tapsim approach --from` starts) — an
/// approach begun near the sample reaches the repulsive branch, one from far stays on
/// the attractive. Or phase against amplitude setpoint, as phase imaging records it: a
/// `setpoint` column (A/A₀) with phase_deg and no position — each point the state a z
/// feedback finds at that setpoint on the branch its phase shows (no offset then).
/// Every parameter not fitted is the setup's (the usual flags), and the fitted ones
/// start there.
///
/// Reported: each parameter with its linearised standard error and 68 % and 95 %
/// intervals; χ²/dof; the Jacobian's singular values and condition number; the
/// correlations; and what the data leave open — a parameter they do not determine is
/// flagged and given no value (with what data would show it), two that trade off are
/// named. --csv writes the data beside the fit point by point, --plot draws them (and
/// the profiles). Example:
///
///   tapsim approach --from 18.5nm --to 8nm --points 30 --no-retract --csv curve.csv
///   tapsim fit curve.csv --modulus 1GPa --work-of-adhesion 0.2J/m^2
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct FitArgs {
    /// The measured curve (CSV with a header, see above).
    data: PathBuf,
    /// Parameters to fit, comma-separated [default: modulus,work-of-adhesion,z-offset].
    #[arg(long, value_delimiter = ',', value_enum)]
    fit: Vec<FitParameter>,
    /// Starting offset of the positions: z_c = position + offset [m; default 0].
    #[arg(long, allow_hyphen_values = true, value_parser = length)]
    offset: Option<f64>,
    /// The amplitude's standard deviation [m]. With --sigma-phase: the weights, taken as
    /// given. Without either: 0.02 nm and 0.05° relative weights, the scale estimated
    /// from the residuals (χ²/dof).
    #[arg(long, allow_hyphen_values = true, value_parser = length)]
    sigma_amplitude: Option<f64>,
    /// The phase's standard deviation [degrees].
    #[arg(long, allow_hyphen_values = true, value_parser = number)]
    sigma_phase: Option<f64>,
    /// The second mode's amplitude standard deviation [m; default as the first's
    /// relative weight, 0.02 nm].
    #[arg(long, allow_hyphen_values = true, value_parser = length)]
    sigma_amplitude2: Option<f64>,
    /// The second mode's phase standard deviation [degrees; default 0.05].
    #[arg(long, allow_hyphen_values = true, value_parser = number)]
    sigma_phase2: Option<f64>,
    /// Also profile each identifiable material parameter: χ² with it held at values
    /// about the estimate and the others refitted, and the intervals where χ² rises
    /// by 1 and 3.84 — exact where the linearised ones assume the model straight (each
    /// profile some ten fits).
    #[arg(long)]
    profile: bool,
    /// Most simulated curves (each residual evaluation or Jacobian column is one)
    /// [default 400].
    #[arg(long, default_value_t = 400)]
    max_curves: usize,
    /// The higher eigenmodes, for second-mode channels (amplitude2_nm, amplitude2_m or
    /// amplitude2_ratio; phase2_deg) read beside the first mode's.
    #[command(flatten)]
    modes: crate::config::ModeInputs,
    #[command(flatten)]
    inputs: TapInputs,
    /// Plot the measured and fitted amplitude and phase against z_c, the weighted
    /// residuals, and with --profile each profile's Δχ² (.png or .svg).
    #[arg(long, help_heading = "Output")]
    plot: Option<PathBuf>,
    /// Write the data beside the fit as CSV: per point the position, the fitted z_c,
    /// the measured and fitted amplitude and phase, the weighted residuals, and whether
    /// the fitted state there is a stable period-1 orbit clear of the law's switches.
    #[arg(long, help_heading = "Output")]
    csv: Option<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long, help_heading = "Output")]
    json: bool,
    /// No progress on stderr.
    #[arg(long, short = 'q', help_heading = "Output")]
    pub(super) quiet: bool,
}

/// A parameter on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum FitParameter {
    /// Composite modulus E*.
    Modulus,
    /// Work of adhesion Δγ.
    WorkOfAdhesion,
    /// Range ε (the Lennard-Jones equilibrium gap).
    Range,
    /// The dmt law's Hamaker constant H.
    Hamaker,
    /// A viscous sample's viscosity η (start from --viscosity).
    Viscosity,
    /// A relaxing sample's relaxation time (start from --relaxation-time, with
    /// --unrelaxed-modulus).
    RelaxationTime,
    /// The cantilever's spring constant k (a nuisance parameter, from --stiffness).
    Stiffness,
    /// The cantilever's quality factor Q (a nuisance parameter, from --quality).
    Quality,
    /// The detector's sensitivity: amplitudes read over true amplitudes, A₀ included
    /// (a nuisance parameter, from 1).
    Sensitivity,
    /// The positions' offset.
    ZOffset,
}

impl From<FitParameter> for Parameter {
    fn from(p: FitParameter) -> Self {
        match p {
            FitParameter::Modulus => Parameter::Modulus,
            FitParameter::WorkOfAdhesion => Parameter::WorkOfAdhesion,
            FitParameter::Range => Parameter::Range,
            FitParameter::Hamaker => Parameter::Hamaker,
            FitParameter::Viscosity => Parameter::Viscosity,
            FitParameter::RelaxationTime => Parameter::RelaxationTime,
            FitParameter::Stiffness => Parameter::Stiffness,
            FitParameter::Quality => Parameter::Quality,
            FitParameter::Sensitivity => Parameter::Sensitivity,
            FitParameter::ZOffset => Parameter::ZOffset,
        }
    }
}

/// Run the subcommand.
pub fn run(args: FitArgs) -> Result<()> {
    super::check_plot_path(args.plot.as_deref())?;
    let mut inputs = args.inputs.clone().with_config()?;
    inputs.takes_modes = true;
    let (setup, numerics) = inputs.resolve()?;
    let modes = args.modes.mode_set(&inputs.mode_file, &setup.cantilever)?;
    let numerics = crate::sweep::sweep_numerics(numerics, (false, false));
    let second_a0 = modes
        .as_ref()
        .and_then(|m| m.higher.first())
        .map(|m| m.free_amplitude_m);
    let Columns {
        position_m,
        setpoint_ratio,
        segments,
        amplitude_m,
        phase_deg,
        amplitude2_m,
        phase2_deg,
        ..
    } = read_curve(&args.data, &setup.cantilever, second_a0, "approach")?;
    // Several modes simulated (--modes 2) whether or not the data hold the second's
    // channels; those channels without the modes are refused.
    let second_mode = match (amplitude2_m.is_some() || phase2_deg.is_some(), modes) {
        (false, None) => None,
        (true, None) => {
            return Err(Error::NotApplicable(
                "the data hold second-mode channels: simulate the modes too (--modes 2)".into(),
            ));
        }
        (_, Some(modes)) => Some(SecondMode {
            modes,
            amplitude_m: amplitude2_m,
            phase_deg: phase2_deg,
            sigma_amplitude_m: args.sigma_amplitude2.unwrap_or(0.02e-9),
            sigma_phase_deg: args.sigma_phase2.unwrap_or(0.05),
        }),
    };
    let given = [
        args.sigma_amplitude,
        args.sigma_phase,
        args.sigma_amplitude2,
        args.sigma_phase2,
    ]
    .iter()
    .any(Option::is_some);
    let second = second_mode.as_ref();
    let missing = [
        (amplitude_m.is_some(), args.sigma_amplitude),
        (phase_deg.is_some(), args.sigma_phase),
        (
            second.is_some_and(|m| m.amplitude_m.is_some()),
            args.sigma_amplitude2,
        ),
        (
            second.is_some_and(|m| m.phase_deg.is_some()),
            args.sigma_phase2,
        ),
    ]
    .iter()
    .any(|(held, sigma)| *held && sigma.is_none());
    if given && missing {
        return Err(Error::NotApplicable(
            "give the standard deviation of every channel the data hold (--sigma-amplitude \
             and --sigma-phase, and for the second mode --sigma-amplitude2 and \
             --sigma-phase2), or none (then estimated from the residuals)"
                .into(),
        ));
    }
    let at_setpoints = setpoint_ratio.is_some();
    let data = Measured {
        second_mode,
        position_m,
        setpoint_ratio,
        segments,
        amplitude_m,
        phase_deg,
        sigma_amplitude_m: args.sigma_amplitude.unwrap_or(0.02e-9),
        sigma_phase_deg: args.sigma_phase.unwrap_or(0.05),
    };
    let parameters: Vec<Parameter> = if args.fit.is_empty() {
        let mut default = vec![Parameter::Modulus, Parameter::WorkOfAdhesion];
        if !at_setpoints {
            default.push(Parameter::ZOffset);
        }
        default
    } else {
        args.fit.iter().map(|&p| p.into()).collect()
    };
    if args.max_curves == 0 {
        return Err(Error::NotApplicable(
            "--max-curves must be at least 1".into(),
        ));
    }
    let options = FitOptions {
        parameters,
        offset_start_m: args.offset.unwrap_or(0.0),
        sensitivity_start: 1.0,
        estimate_sigma: !given,
        max_curves: args.max_curves,
    };
    let busy = super::tap::spinner("fitting: simulating approach curves", args.quiet);
    let report = fit(&setup, &numerics, &data, &options, |n| {
        busy.set_message(format!("fitting: {n} approach curves simulated"));
    });
    busy.finish_and_clear();
    let report = report?;
    let mut profiles = Vec::new();
    if args.profile {
        for (p, e) in options.parameters.iter().zip(&report.parameters) {
            if !p.is_scale() || e.std_err.is_none() {
                continue;
            }
            let busy = super::tap::spinner(&format!("profiling {}", p.key()), args.quiet);
            let done = profile(&setup, &numerics, &data, &options, &report, *p, |n| {
                busy.set_message(format!("profiling {}: {n} curves", p.key()));
            });
            busy.finish_and_clear();
            profiles.push(done?);
        }
    }
    if let Some(path) = &args.csv {
        crate::report::output::write_bytes(
            path,
            &crate::report::records::records_csv(&crate::report::fit::rows(&report, &data))?,
        )?;
    }
    if let Some(path) = &args.plot {
        let source = args
            .data
            .file_name()
            .map_or("data".into(), |n| n.to_string_lossy().into_owned());
        let mut charts =
            crate::report::fit::charts(&report, &data, &source, &setup.law.to_string());
        charts.extend(profiles.iter().map(crate::report::fit::profile_chart));
        crate::report::plot::render_stack(&charts, path)?;
    }
    if args.json {
        let mut v = serde_json::to_value(&report).expect("a report serialises");
        if args.profile {
            v["profiles"] = serde_json::to_value(&profiles).expect("profiles serialise");
        }
        outln!("{}", crate::report::records::document(&v)?);
    } else {
        out!("{}", text(&report, &setup.law.to_string(), &data));
        out!("{}", profile_text(&report, &profiles));
    }
    Ok(())
}

fn profile_text(r: &FitReport, profiles: &[Profile]) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let g = |v: Option<f64>| v.map_or("open".to_string(), |v| format!("{v:.5e}"));
    for p in profiles {
        let lin = r.parameters.iter().find(|e| e.name == p.name);
        let _ = writeln!(
            s,
            "profile of {} ({} points): 68 % [{}, {}] (linearised {}), 95 % [{}, {}] \
             (linearised {})",
            p.name,
            p.values.len(),
            g(p.interval_68[0]),
            g(p.interval_68[1]),
            lin.and_then(|e| e.interval_68)
                .map_or("-".into(), |[a, b]| format!("[{a:.5e}, {b:.5e}]")),
            g(p.interval_95[0]),
            g(p.interval_95[1]),
            lin.and_then(|e| e.interval_95)
                .map_or("-".into(), |[a, b]| format!("[{a:.5e}, {b:.5e}]")),
        );
    }
    if profiles.iter().any(|p| {
        p.interval_95.iter().any(Option::is_none) || p.interval_68.iter().any(Option::is_none)
    }) {
        let _ = writeln!(
            s,
            "(open: χ² does not rise that far within 4.5 standard errors on that side — the \
             data do not bound the parameter there)"
        );
    }
    s
}

fn text(r: &FitReport, law: &str, data: &Measured) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let first = match (data.amplitude_m.is_some(), data.phase_deg.is_some()) {
        (true, true) => "amplitude and phase",
        (true, false) => "amplitude",
        _ => "phase",
    };
    let second = data.second_mode.as_ref().map_or("", |m| {
        match (m.amplitude_m.is_some(), m.phase_deg.is_some()) {
            (true, true) => "; the second mode's amplitude and phase",
            (true, false) => "; the second mode's amplitude",
            (false, true) => "; the second mode's phase",
            (false, false) => "; two modes simulated",
        }
    });
    let at = if data.setpoint_ratio.is_some() {
        " at amplitude setpoints"
    } else {
        ""
    };
    let channels = format!("{first}{at}{second}");
    let _ = writeln!(
        s,
        "fit of {} points ({channels}), {law} law: {} simulated curves, {} ({})",
        data.len(),
        r.curves,
        if r.converged {
            "converged"
        } else {
            "NOT converged"
        },
        r.termination
    );
    let _ = writeln!(
        s,
        "{:<24} {:>13} {:>13} {:>11} {:>29} {:>29}",
        "parameter", "start", "fitted", "±1σ", "68 % interval", "95 % interval"
    );
    for p in &r.parameters {
        // The offset in nm, to 1e-4 nm (far below any data's resolution); the others
        // to six digits.
        let offset = p.name == Parameter::ZOffset.key();
        let g = |v: f64| {
            if offset {
                format!("{:.4} nm", v * 1e9)
            } else {
                format!("{v:.5e}")
            }
        };
        let iv =
            |i: Option<[f64; 2]>| i.map_or("-".into(), |[a, b]| format!("[{}, {}]", g(a), g(b)));
        let _ = writeln!(
            s,
            "{:<24} {:>13} {:>13} {:>11} {:>29} {:>29}",
            p.name,
            g(p.start),
            p.value.map_or("not identifiable".into(), g),
            p.std_err.map_or("-".into(), |e| if offset {
                format!("{:.4} nm", e * 1e9)
            } else {
                format!("{e:.2e}")
            }),
            iv(p.interval_68),
            iv(p.interval_95)
        );
    }
    let _ = writeln!(
        s,
        "χ²/dof = {} ({} degrees of freedom; σ {})",
        if r.reduced_chi_square >= 1e-3 {
            format!("{:.3}", r.reduced_chi_square)
        } else {
            format!("{:.1e}", r.reduced_chi_square)
        },
        r.degrees_of_freedom,
        if r.sigma_estimated {
            "estimated from the residuals: the intervals are scaled by it"
        } else {
            "as given"
        }
    );
    let id = &r.identifiability;
    let _ = writeln!(
        s,
        "singular values of the weighted Jacobian [{}]; condition number {}",
        id.singular_values
            .iter()
            .map(|v| format!("{v:.3e}"))
            .collect::<Vec<_>>()
            .join(", "),
        id.condition_number
            .map_or("— (a parameter the data do not see)".into(), |c| format!(
                "{c:.3e}"
            ))
    );
    let names: Vec<&str> = r.parameters.iter().map(|p| p.name).collect();
    let _ = writeln!(s, "correlations:");
    for (name, row) in names.iter().zip(&id.correlations) {
        let cells: Vec<String> = row
            .iter()
            .map(|c| c.map_or("     -".into(), |c| format!("{c:+.3}")))
            .collect();
        let _ = writeln!(s, "  {name:<24} {}", cells.join(" "));
    }
    for note in &id.notes {
        let _ = writeln!(s, "note: {note}");
    }
    if r.fitted.well_defined.iter().any(|w| !w) {
        let _ = writeln!(
            s,
            "note: {} of the fitted curve's points are not stable period-1 orbits clear of \
             the law's switches: their values are averages perturbations can change, and \
             the fit there is less sure than its intervals say",
            r.fitted.well_defined.iter().filter(|w| !**w).count()
        );
    }
    s
}
