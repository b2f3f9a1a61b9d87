//! `tapsim fit`: a measured approach curve fitted by the simulator, and what the data
//! determine.

use super::curve_data::{Columns, PhaseConvention, read_curve};
use crate::analysis::fit::{
    FitOptions, FitReport, Measured, Nuisance, Parameter, Progress, Search, SecondMode, Stage,
    compare, fit, profile,
};
use crate::app::config::{TapInputs, length, number};
use crate::error::{Error, Result};
use crate::instrument::average::AverageRequest;
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use std::sync::Mutex;

/// From a measured approach curve back to the material, and which law the data
/// support. You recorded amplitude and phase while the piezo moved the tip toward the
/// sample; tapsim simulates that approach — each point a converged steady state,
/// started from the last as an approach goes, so the curve jumps from the attractive
/// to the repulsive branch where a real one does — and finds the modulus E*, the work
/// of adhesion Δγ and the piezo offset (or, with --fit, the range ε, the dmt law's
/// Hamaker constant, a viscosity, a relaxation time, and the nuisance parameters k, Q,
/// the detector's sensitivity and the phase offset) that match it by weighted least
/// squares, and says how sure the data let one be.
///
/// How: a global stage first — a design of starts spread over ×/÷ --search-factor
/// about your start, each with the offset that puts its onset of contact where the
/// data's is — then Levenberg–Marquardt from the best few, each point simulated on the
/// branch the data show (the points after the data's branch jump as an approach begun
/// there); every distinct minimum found is listed. A fit that does not describe the data (χ² far
/// above its noise, residuals in runs of one sign, the branch jump in the wrong place)
/// says so, shows the worst points and gives no intervals. With --law a,b,... each law
/// is fitted and the laws are ranked by AIC and BIC, with a verdict in words. With
/// --modes 2 both modes are simulated and the second's channels fitted too.
///
/// DATA is a CSV whose header names the columns with their units: a position
/// (z_nm, z_m, z_c_nm, z_c_m, separation_nm, separation_m, position_nm or position_m;
/// from far to near, its zero unknown: the offset is fitted), and an amplitude
/// (amplitude_nm, amplitude_m, amplitude_ratio as A/A₀, or amplitude_v in volts with
/// --invols) and/or a phase (phase_deg, in the convention --phase-convention names).
/// Rows of a `direction` column other than "approach" are left out, so the CSV
/// `tapsim approach --csv curve.csv` writes is read as it is. A `segment` column joins
/// several approaches: a new one begins where its label changes, each simulated from
/// the free oscillation at its first position. Or phase against amplitude setpoint, as
/// phase imaging records it: a `setpoint` column (A/A₀) with phase_deg and no position.
/// Every parameter not fitted is the setup's (the usual flags), and the fitted ones
/// start there.
///
/// Reported: each parameter with its standard error and 68 % and 95 % intervals;
/// χ²/dof (and, without --sigma-*, the noise the residuals imply); the minima found;
/// the Jacobian's singular values and condition number; the correlations; and what the
/// data leave open. --csv writes the data beside the fit point by point, --plot draws
/// them (and the profiles). Example (the truth: E* 0.593 GPa, Δγ 0.1 J/m²):
///
///   tapsim approach --from 18.5nm --to 8nm --points 30 --no-retract --csv curve.csv
///   tapsim fit curve.csv --modulus 1GPa --work-of-adhesion 0.2J/m^2
///   tapsim fit curve.csv --law hybrid,dmt
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
    /// Starting phase offset: phase read = true phase + offset [degrees; default 0].
    #[arg(long, allow_hyphen_values = true, value_parser = number)]
    phase_offset: Option<f64>,
    /// How the data's phase is defined: lag (tapsim's: the tip's lag behind the drive,
    /// 90° free at resonance, above 90° where the tip feels attraction), lead (the
    /// negative of the lag, −90° free) or shift (90° − lag: 0 free, negative where the
    /// tip feels attraction).
    #[arg(long, value_enum, default_value_t = PhaseConvention::Lag)]
    phase_convention: PhaseConvention,
    /// Deflection sensitivity (InvOLS) for amplitudes in volts (an amplitude_v column)
    /// [m/V, e.g. 50nm]; fit `sensitivity` if you doubt it.
    #[arg(long, value_parser = length)]
    invols: Option<f64>,
    /// Fit the rows a `grazing` column flags too, and the points whose state at the
    /// fitted parameters grazes a switch. By default both are left out (with a note):
    /// where a curve grazes a switch of the law, its value is one draw among coexisting
    /// mode locks that perturbations below the thermal motion pick, which a fitted
    /// curve cannot match point for point. With --temperature such points are fitted
    /// as the thermal averages an instrument reads instead.
    #[arg(long)]
    keep_grazing: bool,
    /// The temperature the data were read at [K; off unless given, 300K is room
    /// temperature]: each point whose state grazes a switch or is not a stable
    /// period-1 orbit (the onset of contact, a mode lock) is simulated as the average
    /// over the thermal motion an instrument reads there (`tapsim approach
    /// --temperature`), its standard error added to the data's — such points are fitted,
    /// not left out; a row's thermal_average_amplitude_ratio and
    /// thermal_average_phase_deg, where filled (that command's CSV), are read as its
    /// amplitude and phase. Costs a thermal average for each such point of every
    /// simulated curve.
    #[arg(long, allow_hyphen_values = true, value_parser = crate::app::config::temperature, help_heading = "Thermal noise")]
    temperature: Option<f64>,
    /// Drive periods of each thermal average (eight records, each after ten decay times
    /// of settling; their spread gives the standard errors). Each point draws its own
    /// noise, the same for every parameter set (seed 1, from the point's place).
    #[arg(hide_short_help = true, long, default_value_t = DEFAULT_FIT_THERMAL_PERIODS, help_heading = "Thermal noise")]
    thermal_periods: usize,
    /// The amplitude's standard deviation [m]. With --sigma-phase: the weights, taken as
    /// given. Without either: 0.02 nm and 0.05° relative weights, the scale estimated
    /// from the residuals (χ²/dof; the noise they imply is reported).
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
    /// How the minimum is looked for: global (a design over the plausible ranges, then
    /// Levenberg–Marquardt from the best few) or local (from the start alone).
    #[arg(long, value_enum, default_value_t = SearchKind::Global)]
    search: SearchKind,
    /// The global design spans [start/factor, start·factor] in each material parameter.
    #[arg(long, default_value_t = 4.0)]
    search_factor: f64,
    /// Design points of the global stage (the start is one more).
    #[arg(long, default_value_t = 48)]
    search_points: usize,
    /// Local runs of the global stage at most, from its best distinct design points
    /// (the next runs only while no minimum found describes the data).
    #[arg(long, default_value_t = 3)]
    starts: usize,
    /// Also profile each identifiable material parameter: χ² with it held at values
    /// about the estimate and the others refitted, and the intervals where χ² rises
    /// by 1 and 3.84 — exact where the linearised ones assume the model straight (each
    /// profile some ten fits; a value the law cannot take is a point without a value).
    #[arg(long)]
    profile: bool,
    /// Most simulated curves of each local run (each residual evaluation or Jacobian
    /// column is one) [default 400].
    #[arg(long, default_value_t = 400)]
    max_curves: usize,
    /// The higher eigenmodes, for second-mode channels (amplitude2_nm, amplitude2_m or
    /// amplitude2_ratio; phase2_deg) read beside the first mode's.
    #[command(flatten)]
    modes: crate::app::config::ModeInputs,
    #[command(flatten)]
    inputs: TapInputs,
    /// Plot the measured and fitted amplitude and phase against z_c, the weighted
    /// residuals, and with --profile each profile's Δχ² (.png or .svg; the best law's
    /// with several).
    #[arg(long, help_heading = "Output")]
    plot: Option<PathBuf>,
    /// Write the data beside the fit as CSV: per point the position, the fitted z_c,
    /// the measured and fitted amplitude and phase, the weighted residuals, and whether
    /// the fitted state there is a stable period-1 orbit clear of the law's switches
    /// (the best law's with several).
    #[arg(long, help_heading = "Output")]
    csv: Option<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long, help_heading = "Output")]
    json: bool,
    /// No progress on stderr.
    #[arg(long, short = 'q', help_heading = "Output")]
    pub(super) quiet: bool,
}

/// Drive periods of each thermal average a fit simulates (--thermal-periods): a tenth
/// of a single average's default, since a fit simulates each averaged point on every
/// curve it tries (the settling, ten decay times a record, costs more: 10 200 periods
/// on the built-in lever).
const DEFAULT_FIT_THERMAL_PERIODS: usize = 2_000;

/// How the fit looks for its minimum, on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum SearchKind {
    /// A design over the plausible ranges first, then local runs from the best.
    Global,
    /// Levenberg–Marquardt from the start alone.
    Local,
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
    /// An offset of the phase channel, degrees (a nuisance parameter, from
    /// --phase-offset).
    PhaseOffset,
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
            FitParameter::PhaseOffset => Parameter::PhaseOffset,
            FitParameter::ZOffset => Parameter::ZOffset,
        }
    }
}

/// Progress on stderr: a spinner with the stage, curves, best χ² and time left on a
/// terminal; otherwise a line where the stage changes and every half minute within one;
/// nothing with --quiet.
struct Reporter {
    bar: indicatif::ProgressBar,
    lines: bool,
    last: Mutex<Option<(Stage, std::time::Instant)>>,
    what: String,
}

impl Reporter {
    fn new(what: &str, quiet: bool) -> Self {
        let shown = super::progress::shown(quiet);
        Self {
            bar: match shown {
                Some(true) => super::progress::spinner(what),
                _ => indicatif::ProgressBar::hidden(),
            },
            lines: shown == Some(false),
            last: Mutex::new(None),
            what: what.to_string(),
        }
    }

    fn report(&self, p: &Progress) {
        let stage = match p.stage {
            Stage::Design { done, total } => format!("global stage, design point {done}/{total}"),
            Stage::Local { index, of } => format!("local run {index}/{of}"),
            Stage::Continue { index, of } => format!("continuing cut run {index}/{of}"),
            Stage::WithoutGrazing { left_out } => {
                format!("again without the {left_out} grazing point(s)")
            }
            Stage::Assess => "the Jacobian at the best minimum".into(),
            Stage::Profile => "profile".into(),
        };
        let best = p
            .best_chi_square
            .map_or(String::new(), |c| format!(", best χ² {c:.4e}"));
        let left = p
            .remaining_s
            .map_or(String::new(), |s| format!(", about {s:.0} s left"));
        let message = format!(
            "{}: {stage}, {} curves in {:.1} s{best}{left}",
            self.what, p.curves, p.elapsed_s
        );
        self.bar.set_message(message.clone());
        if self.lines {
            let key = match p.stage {
                Stage::Design { total, .. } => Stage::Design { done: 0, total },
                other => other,
            };
            let mut last = self.last.lock().expect("progress lock");
            let due = match *last {
                Some((stage, at)) => stage != key || at.elapsed().as_secs() >= 30,
                None => true,
            };
            if due {
                *last = Some((key, std::time::Instant::now()));
                eprintln!("{message}");
            }
        }
    }

    fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// Run the subcommand.
pub fn run(args: FitArgs) -> Result<()> {
    super::check_plot_path(args.plot.as_deref())?;
    let mut inputs = args.inputs.clone().with_config()?;
    inputs.takes_modes = true;
    let laws = inputs.law.clone();
    let law_inputs = |law: Option<crate::physics::law::LawKind>| {
        let mut i = inputs.clone();
        i.law = law.into_iter().collect();
        i
    };
    let first = law_inputs(laws.first().copied());
    let (setup, numerics) = first.resolve()?;
    let modes = args.modes.mode_set(&first.mode_file, &setup.cantilever)?;
    let numerics = crate::analysis::sweep::sweep_numerics(numerics, (false, false));
    let (data, grazing_left_out) = measured(&args, &setup, modes)?;
    if args.max_curves == 0 {
        return Err(Error::NotApplicable(
            "--max-curves must be at least 1".into(),
        ));
    }
    let options = options(&args, &data);
    // Each law fitted in turn (one: the law the setup gives).
    let mut fits: Vec<(String, crate::dynamics::setup::TapSetup, FitReport)> = Vec::new();
    let several = laws.len() > 1;
    for law in if several {
        laws.clone()
    } else {
        vec![setup.law.kind]
    } {
        let (setup, _) = law_inputs(Some(law)).resolve()?;
        let name = setup.law.to_string();
        let what = if several {
            format!("fitting ({name})")
        } else {
            "fitting".into()
        };
        let reporter = Reporter::new(&what, args.quiet);
        let report = fit(&setup, &numerics, &data, &options, |p| reporter.report(p));
        reporter.finish();
        let report = match report {
            Ok(r) => r,
            Err(e) if several => {
                return Err(Error::NotApplicable(format!("fitting the {name} law: {e}")));
            }
            Err(e) => return Err(e),
        };
        fits.push((name, setup, report));
    }
    let comparison = several.then(|| {
        compare(
            &fits
                .iter()
                .map(|(n, _, r)| (n.clone(), r))
                .collect::<Vec<_>>(),
        )
    });
    // The best law's fit (the only one's) is the one profiled, written and drawn.
    let best = comparison
        .as_ref()
        .and_then(|c| c.ranking.first())
        .and_then(|b| fits.iter().position(|(n, _, _)| *n == b.law))
        .unwrap_or(0);
    let (law, setup, report) = &fits[best];
    // The points the fit took (without those it left out as grazing).
    let fitted_data = data.without(&report.left_out);
    let mut profiles = Vec::new();
    if args.profile {
        for (p, e) in options.parameters.iter().zip(&report.parameters) {
            if !p.is_material() || e.std_err.is_none() {
                continue;
            }
            let reporter = Reporter::new(&format!("profiling {}", p.key()), args.quiet);
            let done = profile(setup, &numerics, &fitted_data, &options, report, *p, |q| {
                reporter.report(q)
            });
            reporter.finish();
            profiles.push(done?);
        }
    }
    if let Some(path) = &args.csv {
        crate::app::report::output::write_bytes(
            path,
            &crate::app::report::records::records_csv(&crate::app::report::fit::rows(
                report,
                &fitted_data,
            ))?,
        )?;
    }
    if let Some(path) = &args.plot {
        let source = args
            .data
            .file_name()
            .map_or("data".into(), |n| n.to_string_lossy().into_owned());
        let mut charts = crate::app::report::fit::charts(report, &fitted_data, &source, law);
        charts.extend(profiles.iter().map(crate::app::report::fit::profile_chart));
        crate::app::report::plot::render_stack(&charts, path)?;
    }
    if args.json {
        let mut v = if let Some(c) = &comparison {
            let mut laws = serde_json::Map::new();
            for (name, _, r) in &fits {
                laws.insert(
                    name.clone(),
                    serde_json::to_value(r).expect("a report serialises"),
                );
            }
            serde_json::json!({ "laws": laws, "comparison": c })
        } else {
            serde_json::to_value(report).expect("a report serialises")
        };
        if args.profile {
            v["profiles"] = serde_json::to_value(&profiles).expect("profiles serialise");
        }
        v["grazing_points_left_out"] = grazing_left_out.into();
        outln!("{}", crate::app::report::records::document(&v)?);
    } else {
        use crate::app::report::fit_text;
        for (i, (name, _, r)) in fits.iter().enumerate() {
            if i > 0 {
                outln!("");
            }
            out!("{}", fit_text::report(r, name, &data.without(&r.left_out)));
            if !r.left_out.is_empty() {
                let at: Vec<String> = r
                    .left_out
                    .iter()
                    .filter_map(|&i| data.position_m.get(i))
                    .map(|z| format!("{:.3}", z * 1e9))
                    .collect();
                outln!(
                    "note: left out, and the fit run again without them: {} point(s) whose \
                     state at the fitted parameters grazes a switch of the law (one draw \
                     among coexisting states, a step the intervals cannot see){}; \
                     --keep-grazing fits them too",
                    r.left_out.len(),
                    if at.is_empty() {
                        String::new()
                    } else {
                        format!(" (at {} nm)", at.join(", "))
                    }
                );
            }
        }
        out!("{}", fit_text::profiles(report, &profiles));
        if let Some(c) = &comparison {
            outln!("");
            out!("{}", fit_text::comparison(c));
        }
        if grazing_left_out > 0 {
            outln!(
                "note: {grazing_left_out} of the file's points are flagged grazing (one draw \
                 among coexisting mode locks near a switch of the law) and were left out of \
                 the fit; --keep-grazing fits them too"
            );
        }
    }
    Ok(())
}

/// The data file read as `args` describe it, with the weights they give.
fn measured(
    args: &FitArgs,
    setup: &crate::dynamics::setup::TapSetup,
    modes: Option<crate::dynamics::modes::ModeSet>,
) -> Result<(Measured, usize)> {
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
        grazing_left_out,
        ..
    } = read_curve(
        &args.data,
        &setup.cantilever,
        second_a0,
        "approach",
        &super::curve_data::Reading {
            phase: args.phase_convention,
            invols_m_per_v: args.invols,
            skip_grazing: !args.keep_grazing && args.temperature.is_none(),
            thermal_averages: args.temperature.is_some(),
        },
    )?;
    if amplitude_m.is_none() && phase_deg.is_none() {
        return Err(Error::NotApplicable(format!(
            "{}: fit reads AM curves (an amplitude or a phase column); an FM curve's \
             frequency shift is inverted by `tapsim reconstruct --mode fm`",
            args.data.display()
        )));
    }
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
    if sigmas_given(args) && missing {
        return Err(Error::NotApplicable(
            "give the standard deviation of every channel the data hold (--sigma-amplitude \
             and --sigma-phase, and for the second mode --sigma-amplitude2 and \
             --sigma-phase2), or none (then estimated from the residuals)"
                .into(),
        ));
    }
    let data = Measured {
        second_mode,
        position_m,
        setpoint_ratio,
        segments,
        amplitude_m,
        phase_deg,
        sigma_amplitude_m: args.sigma_amplitude.unwrap_or(0.02e-9),
        sigma_phase_deg: args.sigma_phase.unwrap_or(0.05),
        thermal: args.temperature.map(|temperature_k| AverageRequest {
            temperature_k,
            periods: args.thermal_periods,
            seed: 1,
        }),
    };
    Ok((data, grazing_left_out))
}

/// Whether any standard deviation was given.
fn sigmas_given(args: &FitArgs) -> bool {
    [
        args.sigma_amplitude,
        args.sigma_phase,
        args.sigma_amplitude2,
        args.sigma_phase2,
    ]
    .iter()
    .any(Option::is_some)
}

/// The fit's options from `args`, for `data`.
fn options(args: &FitArgs, data: &Measured) -> FitOptions {
    let parameters: Vec<Parameter> = if args.fit.is_empty() {
        let mut default = vec![Parameter::Modulus, Parameter::WorkOfAdhesion];
        if data.setpoint_ratio.is_none() {
            default.push(Parameter::ZOffset);
        }
        default
    } else {
        args.fit.iter().map(|&p| p.into()).collect()
    };
    FitOptions {
        parameters,
        start: Nuisance {
            offset_m: args.offset.unwrap_or(0.0),
            sensitivity: 1.0,
            phase_offset_deg: args.phase_offset.unwrap_or(0.0),
        },
        estimate_sigma: !sigmas_given(args),
        max_curves: args.max_curves,
        keep_grazing: args.keep_grazing,
        search: match args.search {
            SearchKind::Local => Search::Local,
            SearchKind::Global => Search::Global {
                factor: args.search_factor,
                points: args.search_points,
                starts: args.starts,
            },
        },
    }
}
