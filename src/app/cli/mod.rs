//! The `tapsim` command line: parse, call the library, print. Each subcommand lives in
//! its own module.
//!
//! May import: everything. One file a command (its flags, checks and run); what it
//! prints or writes comes from its presenter in [`crate::app::report`].

/// Refuse a plot file that is neither .png nor .svg, before any work is done.
pub fn check_plot_path(path: Option<&std::path::Path>) -> crate::Result<()> {
    let Some(path) = path else { return Ok(()) };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if matches!(ext.as_deref(), Some("png" | "svg")) {
        Ok(())
    } else {
        Err(crate::Error::NotApplicable(format!(
            "{}: the plot file must end in .png or .svg",
            path.display()
        )))
    }
}

/// `println!` that returns instead of panicking when standard output fails: a closed
/// pipe ends the command quietly ([`crate::Error::StdoutClosed`]), any other failure (a
/// full disk) is an error.
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::app::cli::emit(format_args!("{}\n", format_args!($($arg)*)))?
    };
}

/// `print!` that returns instead of panicking when standard output fails ([`outln!`]).
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::app::cli::emit(format_args!($($arg)*))?
    };
}

mod approach;
mod batch;
mod bifurcation;
mod branches;
mod contrast;
mod curve_data;
mod figure;
mod fit;
mod fm;
mod fm_scan;
mod force_curve;
mod generated;
mod hysteresis;
mod image;
mod lj;
mod map;
mod merge;
mod modal;
mod peakforce;
mod progress;
mod qnm;
mod reconstruct;
mod reproduce;
mod scan;
mod scan_lines;
mod shard;
mod tap;
mod thermal;
mod thermal_psd;

use clap::{Parser, Subcommand};

/// `tapsim --version`: the crate's version and the commit it was built from.
const VERSION: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (commit ",
    env!("TAPSIM_COMMIT"),
    ")"
);
use std::process::ExitCode;

/// tapsim — tapping-mode AFM with adhesion hysteresis done right.
///
/// Implements Ciavarella, Greenwood & Barber, "Effect of Tabor parameter on hysteresis
/// losses during adhesive contact". Dimensionless quantities carry hats: force
/// T̂ = T/(RΔγ), separation α̂ = α/(με), contact radius â = βa/R, energy Ŵ = W/(μεRΔγ),
/// support stiffness k̂ = μεk/(RΔγ). SI inputs accept unit suffixes (10nm, 1GPa,
/// 50mJ/m^2, 40N/m); bare numbers are SI base units.
#[derive(Debug, Parser)]
#[command(name = "tapsim", version = VERSION)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// The command line's definition as it parses and prints: every option's `-h` line is
/// the first clause of its help ([`first_clause`]), its value named by its unit or
/// FILE, `--help` the whole text — so `-h` is a summary a screen holds, generated from
/// the same definitions.
#[doc(hidden)]
pub fn command() -> clap::Command {
    command_for(None)
}

/// [`command`] with only the subcommand `only` summarised (`Some("")`: none): what a
/// command line that runs `only` parses and prints. Summarising all thirty took 8.6
/// of the 10.9 million instructions of `tapsim --version` (callgrind), about 1 ms that
/// every `tapsim tap` from a script paid.
#[doc(hidden)]
pub fn command_for(only: Option<&str>) -> clap::Command {
    summarised(<Cli as clap::CommandFactory>::command(), only)
}

/// `command` with its options' help summarised ([`command`]), and the subcommands
/// named `only` (all: `None`) with theirs, all the way down.
fn summarised(command: clap::Command, only: Option<&str>) -> clap::Command {
    let names: Vec<String> = command
        .get_subcommands()
        .map(|s| s.get_name().to_string())
        .filter(|name| only.is_none_or(|only| only == name))
        .collect();
    let mut command = summarised_args(command);
    for name in names {
        command = command.mut_subcommand(name, |sub| summarised(sub, None));
    }
    command
}

/// `command` with each of its own options' help summarised ([`command`]).
fn summarised_args(command: clap::Command) -> clap::Command {
    command.mut_args(|arg| {
        let Some(help) = arg.get_help().map(|h| h.to_string()) else {
            return arg;
        };
        // A value named by its unit where the help gives one ("[m; default 20nm]"):
        // `--radius <m>` rather than `--radius <RADIUS>`.
        let unnamed = arg.get_value_names().is_some_and(|names| {
            names.len() == 1 && *names[0] == arg.get_id().as_str().to_uppercase()
        });
        const UNITS: [&str; 10] = ["m", "Pa", "J/m²", "N/m", "Hz", "K", "s", "N", "m/s", "J"];
        let unit = help
            .split_once('[')
            .and_then(|(_, rest)| rest.split_once(';'))
            .and_then(|(unit, _)| UNITS.into_iter().find(|u| *u == unit));
        // A file is a FILE (`--plot <FILE>`, not `--plot <PLOT>`).
        let is_path =
            arg.get_value_parser().type_id() == clap::builder::ValueParser::path_buf().type_id();
        let arg = if is_path && unnamed {
            arg.value_name("FILE")
        } else {
            arg
        };
        let (arg, first) = match unit {
            Some(unit) if unnamed => (
                arg.value_name(unit),
                // The unit is the value's name: the summary keeps the value.
                first_clause(&help)
                    .replace(&format!("[{unit}; the built-in sample's "), "[")
                    .replace(&format!("[{unit}; "), "["),
            ),
            _ => (arg, first_clause(&help)),
        };
        let first = first_bracket_short(&first);
        if first == help || arg.get_long_help().is_some() {
            return arg;
        }
        arg.long_help(help).help(first)
    })
}

/// The subcommand a command line (the program's name first) runs, or whose help it
/// asks for (`tapsim help tap`): its first word that is not an option ("" if none).
#[doc(hidden)]
pub fn subcommand_named(args: &[std::ffi::OsString]) -> String {
    let mut words = args
        .iter()
        .skip(1)
        .filter_map(|a| a.to_str())
        .filter(|a| !a.starts_with('-'));
    match words.next() {
        Some("help") => words.next().unwrap_or_default().to_string(),
        Some(word) => word.to_string(),
        None => String::new(),
    }
}

/// `text` with its first bracket cut at its first comma: `[0.5GPa, a soft polymer]`
/// becomes `[0.5GPa]`.
fn first_bracket_short(text: &str) -> String {
    let Some(open) = text.find('[') else {
        return text.to_string();
    };
    let Some(close) = text[open..].find(']').map(|c| open + c) else {
        return text.to_string();
    };
    match text[open..close].find(", ") {
        Some(comma) => format!("{}]{}", &text[..open + comma], &text[close + 1..]),
        None => text.to_string(),
    }
}

/// The summary of `help`: its first clause — up to the first `: `, `; ` or sentence end
/// (`. ` before a capital) outside brackets, after at least 15 bytes — without its
/// parenthetical remarks (` (…)`); the rest is for `--help`.
#[doc(hidden)]
pub fn first_clause(help: &str) -> String {
    let chars: Vec<char> = help.chars().collect();
    let (mut out, mut depth, mut i) = (String::new(), 0i32, 0);
    while i < chars.len() {
        let c = chars[i];
        let next = chars.get(i + 1).copied();
        let spaced = next.is_some_and(char::is_whitespace);
        match c {
            '(' if depth == 0 && out.ends_with(' ') => {
                // Skip the remark to its closing parenthesis, and the space before it.
                let mut inner = 0;
                while i < chars.len() {
                    match chars[i] {
                        '(' => inner += 1,
                        ')' if inner == 1 => break,
                        ')' => inner -= 1,
                        _ => {}
                    }
                    i += 1;
                }
                out.pop();
                // "…, eq. (8)" loses its "eq." with the number.
                for word in [", eq.", " eq.", ", eqs.", " eqs."] {
                    if let Some(kept) = out.strip_suffix(word) {
                        out = kept.to_string();
                        break;
                    }
                }
                i += 1;
                continue;
            }
            '(' | '[' => depth += 1,
            ')' | ']' => depth -= 1,
            ':' | ';' if depth == 0 && out.len() >= 15 && spaced => return out,
            '.' if depth == 0
                && out.len() >= 15
                && spaced
                && chars
                    .get(i + 2)
                    .is_some_and(|n| n.is_uppercase() || n.is_ascii_digit()) =>
            {
                return out;
            }
            _ => {}
        }
        out.push(c);
        i += 1;
    }
    // A sentence's full stop goes; an ellipsis stays.
    match out.strip_suffix('.') {
        Some(kept) if !kept.ends_with("..") || kept.ends_with("...") => kept.to_string(),
        _ => out,
    }
}

/// Parse `args` (the program's name first) with [`command`].
fn parse<I, T>(args: I) -> std::result::Result<Cli, clap::Error>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let args: Vec<std::ffi::OsString> = args.into_iter().map(Into::into).collect();
    let matches = command_for(Some(&subcommand_named(&args))).try_get_matches_from(args)?;
    <Cli as clap::FromArgMatches>::from_arg_matches(&matches)
}

#[derive(Debug, Subcommand)]
enum Command {
    #[command(
        about = "A tapping cantilever's steady state: what a lock-in reads, the loss per cycle."
    )]
    Tap(tap::TapArgs),
    #[command(
        about = "Approach–retract curves: amplitude, phase and loss against the rest separation or setpoint."
    )]
    Approach(approach::ApproachArgs),
    #[command(
        about = "The period-1 orbit families through the rest separation, stable and unstable, through folds."
    )]
    Branches(branches::BranchesArgs),
    #[command(
        about = "A bifurcation diagram along an approach: period doublings, locks and irregular windows."
    )]
    Bifurcation(bifurcation::BifurcationArgs),
    #[command(about = "Phase contrast between materials at amplitude setpoints, law by law.")]
    Contrast(contrast::ContrastArgs),
    #[command(
        about = "FM-AFM approach: frequency shift and dissipation at constant amplitude, loops settled."
    )]
    Fm(fm::FmArgs),
    #[command(
        about = "Fit a measured approach curve: the material's parameters and which law the data support."
    )]
    Fit(fit::FitArgs),
    #[command(
        about = "The force and the loss a measured AM curve implies (Sader–Jarvis, Hölscher)."
    )]
    Reconstruct(reconstruct::ReconstructArgs),
    #[command(
        about = "A map over work of adhesion and modulus: phase, loss and height, in parallel or sharded."
    )]
    Map(map::MapArgs),
    #[command(
        about = "Scan a line or an image over a sample with the lock-in and z feedback in the loop."
    )]
    Scan(scan::ScanArgs),
    #[command(
        about = "The free cantilever's thermal spectrum, and the calibration of a simulated or measured one."
    )]
    Thermal(thermal::ThermalArgs),
    #[command(
        about = "Off-resonance (PeakForce-type) tapping: a force curve every cycle, the QNM channels."
    )]
    Peakforce(peakforce::PeakForceArgs),
    #[command(
        about = "A force–distance curve: snap-in, pull-off, adhesion, indentation and the energy books."
    )]
    ForceCurve(force_curve::ForceCurveArgs),
    #[command(about = "Run many cases from a file, in parallel or sharded.")]
    Batch(batch::BatchArgs),
    #[command(about = "Join the parts of a sharded map, batch or image into one run's outputs.")]
    Merge(merge::MergeArgs),
    #[command(
        about = "The paper's closed forms: jump-in, jump-out and the hysteresis loss of JKR and the hybrid law."
    )]
    Hysteresis(hysteresis::HysteresisArgs),
    #[command(
        about = "The full Lennard-Jones solution: the S-curve, its folds and the loss with an error estimate."
    )]
    Lj(lj::LjArgs),
    #[command(about = "Draw the paper's figures.")]
    Figure(figure::FigureArgs),
    #[command(
        about = "Regenerate results/: the paper's figures, the tapping figures and their headline numbers."
    )]
    Reproduce(reproduce::ReproduceArgs),
    #[command(about = "Print a shell's completion script.")]
    Completions(generated::CompletionsArgs),
    #[command(about = "Write man pages, or the Markdown command reference.")]
    Man(generated::ManArgs),
}

impl Command {
    /// Whether the command names each file it writes on stderr: unless --quiet, and not
    /// `reproduce` or `figure`, whose output on stdout is the list of files written.
    fn announces_writes(&self) -> bool {
        let quiet = match self {
            Command::Tap(a) => a.quiet,
            Command::Approach(a) => a.out.quiet,
            Command::Branches(a) => a.out.quiet,
            Command::Bifurcation(a) => a.out.quiet,
            Command::Contrast(a) => a.out.quiet,
            Command::Fm(a) => a.out.quiet,
            Command::Fit(a) => a.quiet,
            Command::Reconstruct(a) => a.quiet,
            Command::Map(a) => a.out.quiet,
            Command::Scan(a) => a.out.quiet,
            Command::Thermal(a) => a.out.quiet,
            Command::Peakforce(a) => a.out.quiet,
            Command::ForceCurve(a) => a.out.quiet,
            Command::Batch(a) => a.out.quiet,
            Command::Merge(a) => a.output.quiet,
            Command::Hysteresis(a) => a.quiet,
            Command::Lj(a) => a.quiet,
            Command::Man(a) => a.quiet,
            Command::Figure(_) | Command::Reproduce(_) | Command::Completions(_) => true,
        };
        !quiet
    }

    /// Refuse, before any work, an output path that cannot be written (a plot that is
    /// neither .png nor .svg, a missing directory, a directory, a socket): the files a
    /// run asks for, by flag; and lock-in settings given without a temperature.
    fn check_early(&self) -> crate::Result<()> {
        match self {
            Command::Tap(a) => {
                a.noise.check()?;
                check_plot_path(a.plot.as_deref())?;
                check_targets([a.plot.as_deref(), a.trajectory.as_deref()])
            }
            Command::Approach(a) => a.out.check(),
            Command::Fm(a) => a.out.check(),
            Command::Branches(a) => a.out.check(),
            Command::Bifurcation(a) => a.out.check(),
            Command::Contrast(a) => {
                a.noise.check()?;
                a.out.check()
            }
            Command::Map(a) => {
                a.noise.check()?;
                a.out.check()
            }
            Command::Scan(a) => {
                a.out.check()?;
                a.images.check()
            }
            Command::Thermal(a) => a.check(),
            Command::Peakforce(a) => a.check(),
            Command::ForceCurve(a) => a.check(),
            Command::Batch(a) => a.out.check(),
            Command::Merge(a) => a.output.check(),
            Command::Fit(_)
            | Command::Reconstruct(_)
            | Command::Hysteresis(_)
            | Command::Lj(_)
            | Command::Figure(_)
            | Command::Reproduce(_)
            | Command::Completions(_)
            | Command::Man(_) => Ok(()),
        }
    }
}

/// Refuse any of `paths` that cannot be written ([`crate::app::report::output::check_target`]).
fn check_targets<'a>(
    paths: impl IntoIterator<Item = Option<&'a std::path::Path>>,
) -> crate::Result<()> {
    paths
        .into_iter()
        .flatten()
        .try_for_each(crate::app::report::output::check_target)
}

/// The range of rest separations of the commands that sweep it (approach, branches,
/// bifurcation).
#[derive(Debug, clap::Args)]
pub struct SeparationRange {
    /// Farthest rest separation [m; default 1.2 A₀].
    #[arg(long, allow_hyphen_values = true, value_parser = crate::app::config::length)]
    pub from: Option<f64>,
    /// Nearest rest separation [m; default 0.4 A₀].
    #[arg(long, allow_hyphen_values = true, value_parser = crate::app::config::length)]
    pub to: Option<f64>,
}

impl SeparationRange {
    /// (from, to) in m, the defaults for free amplitude `a0_m` where unset.
    pub fn resolve(&self, a0_m: f64) -> (f64, f64) {
        (
            self.from.unwrap_or(1.2 * a0_m),
            self.to.unwrap_or(0.4 * a0_m),
        )
    }
}

/// What a sweep command starts from: the setup of its inputs (over a `--config` file),
/// the numerics with the per-setpoint defaults of a sweep, and the range of rest
/// separations.
pub struct SweepStart {
    /// The setup.
    pub setup: crate::dynamics::setup::TapSetup,
    /// The numerics as given.
    pub numerics: crate::dynamics::setup::Numerics,
    /// The numerics with the sweep defaults where unset.
    pub sweep_numerics: crate::dynamics::setup::Numerics,
    /// (from, to) in m.
    pub range: (f64, f64),
    /// The parameter file's eigenmodes.
    pub mode_file: crate::app::config::ModeFile,
}

impl SweepStart {
    /// Resolve `inputs` and `range` for `command` (which takes no amplitude setpoint).
    pub fn new(
        command: &str,
        inputs: crate::app::config::TapInputs,
        range: &SeparationRange,
    ) -> crate::error::Result<Self> {
        let inputs = inputs.with_config()?;
        inputs.no_setpoint(command)?;
        let (setup, numerics) = inputs.resolve()?;
        let sweep_numerics = inputs.sweep_numerics(numerics);
        let range = range.resolve(setup.cantilever.free_amplitude_m);
        Ok(Self {
            setup,
            numerics,
            sweep_numerics,
            range,
            mode_file: inputs.mode_file,
        })
    }
}

/// Draws a run's plot into a file.
pub type Draw<'a> = dyn Fn(&std::path::Path) -> crate::Result<()> + 'a;

/// Output flags shared by the sweep commands (approach, contrast, map).
#[derive(Debug, clap::Args)]
pub struct SweepOutput {
    /// Write the results as CSV.
    #[arg(long)]
    pub csv: Option<std::path::PathBuf>,
    /// Plot the results (.png or .svg).
    #[arg(long)]
    pub plot: Option<std::path::PathBuf>,
    /// Print JSON on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
    /// No progress report on stderr.
    #[arg(long, short = 'q')]
    pub quiet: bool,
}

/// The thermal noise flags of the commands that read it through a lock-in (tap,
/// contrast).
#[derive(Debug, Clone, clap::Args)]
pub struct NoiseArgs {
    /// Temperature [K; off unless given, 300K is room temperature]: report the thermal
    /// noise a lock-in reads on each stable period-1 orbit — the standard deviations of
    /// its amplitude and phase from the linear theory about the orbit (the thermal
    /// force of the cantilever's damping, S_F = 4k_BT·k/(ω₀Q), through the variational
    /// equations and the lock-in's filter).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::app::config::temperature, help_heading = "Thermal noise")]
    pub temperature: Option<f64>,
    /// The lock-in's equivalent noise bandwidth for --temperature [Hz; default 1kHz].
    #[arg(hide_short_help = true, long, allow_hyphen_values = true, value_parser = crate::app::config::frequency, help_heading = "Thermal noise")]
    pub enbw: Option<f64>,
    /// The lock-in's filter order (1–4) for --temperature [default 4].
    #[arg(hide_short_help = true, long, value_parser = clap::value_parser!(u8).range(1..=4), help_heading = "Thermal noise")]
    pub lockin_order: Option<u8>,
}

impl NoiseArgs {
    /// Refuse lock-in settings without the temperature they are for, and a bandwidth
    /// that is not a positive number.
    pub fn check(&self) -> crate::Result<()> {
        if self.temperature.is_none() && (self.enbw.is_some() || self.lockin_order.is_some()) {
            return Err(crate::Error::NotApplicable(
                "--enbw and --lockin-order set the lock-in that reads the thermal noise: give \
                 --temperature too, or leave them out"
                    .into(),
            ));
        }
        if let Some(enbw) = self.enbw {
            crate::error::positive("lock-in bandwidth (ENBW)", enbw)?;
        }
        Ok(())
    }

    /// The noise asked for (none without --temperature).
    pub fn request(&self) -> Option<crate::instrument::noise::NoiseRequest> {
        self.temperature
            .map(|temperature_k| crate::instrument::noise::NoiseRequest {
                temperature_k,
                lockin_order: self.lockin_order.map_or(4, usize::from),
                enbw_hz: self.enbw.unwrap_or(1000.0),
            })
    }
}

/// Drive periods of a thermal average unless told otherwise (`--thermal-periods`).
pub(crate) const DEFAULT_THERMAL_PERIODS: usize = 20_000;

/// The refusal of a rest separation beside an amplitude setpoint (tap, map, a batch
/// row): at a setpoint the separation is what is solved for.
pub(crate) fn separation_and_setpoint() -> crate::Error {
    crate::Error::NotApplicable(
        "give either a rest separation (--separation, a separation column) or an amplitude \
         setpoint (--setpoint), not both: at a setpoint the separation is what is solved for"
            .into(),
    )
}

impl SweepOutput {
    /// Refuse, before any work, a --plot that is neither .png nor .svg and a --csv or
    /// --plot that cannot be written.
    pub fn check(&self) -> crate::Result<()> {
        check_plot_path(self.plot.as_deref())?;
        check_targets([self.csv.as_deref(), self.plot.as_deref()])
    }

    /// Progress of `what` over `len` items on stderr ([`progress::Progress`]).
    pub(crate) fn progress(&self, what: &str, len: usize) -> progress::Progress {
        progress::Progress::counted(what, len, self.quiet)
    }

    /// Write `records` as CSV to --csv and the charts `charts` draws to --plot, where
    /// they were asked for.
    pub fn write_files<T: serde::Serialize>(
        &self,
        records: &[T],
        charts: impl FnOnce() -> Vec<crate::app::report::chart::Chart>,
    ) -> crate::Result<()> {
        self.write_files_drawn(records, |path| {
            crate::app::report::plot::render_stack(&charts(), path)
        })
    }

    /// [`SweepOutput::write_files`] with the plot drawn by `draw` into the file it is
    /// given.
    pub fn write_files_drawn<T: serde::Serialize>(
        &self,
        records: &[T],
        draw: impl FnOnce(&std::path::Path) -> crate::Result<()>,
    ) -> crate::Result<()> {
        use crate::app::report::{output, records};
        if let Some(path) = &self.csv {
            output::write_bytes(path, &records::records_csv(records)?)?;
        }
        if let Some(path) = &self.plot {
            draw(path)?;
        }
        Ok(())
    }

    /// Refuse a plot (--plot, or a .png/.svg among `extra`) for `command`, which has none.
    pub fn refuse_plots(&self, command: &str, extra: &[std::path::PathBuf]) -> crate::Result<()> {
        let plot_file = |p: &std::path::PathBuf| {
            p.extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("png") || e.eq_ignore_ascii_case("svg"))
        };
        if self.plot.is_some() || extra.iter().any(plot_file) {
            return Err(crate::Error::NotApplicable(format!(
                "a {command} has no plot: write .csv or .json"
            )));
        }
        Ok(())
    }

    /// Write a whole run's `records` where they were asked for: the CSV to --csv and to
    /// the .csv files of `extra`; the plot `draw` makes to --plot and the .png/.svg files
    /// of `extra` (refused, naming the `command`, where it has none); the JSON `json`
    /// builds to --json (stdout) and the .json files of `extra`; with none of these the
    /// CSV on stdout. `tapsim merge` writes through this too (with its --out files as
    /// `extra`), so its outputs are those of one whole run.
    pub fn emit<T: serde::Serialize>(
        &self,
        (command, extra): (&str, &[std::path::PathBuf]),
        records: &[T],
        json: impl Fn() -> crate::Result<serde_json::Value>,
        draw: Option<&Draw>,
    ) -> crate::Result<()> {
        use crate::app::report::{output, records as csv};
        let with = |ext: &'static str| {
            extra
                .iter()
                .filter(move |p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case(ext)))
        };
        let csv_files: Vec<_> = self.csv.iter().chain(with("csv")).collect();
        let plots: Vec<_> = self
            .plot
            .iter()
            .chain(with("png"))
            .chain(with("svg"))
            .collect();
        let json_files: Vec<_> = with("json").collect();
        if draw.is_none() {
            self.refuse_plots(command, extra)?;
        }
        for path in &csv_files {
            output::write_bytes(path, &csv::records_csv(records)?)?;
        }
        if let Some(draw) = draw {
            for path in &plots {
                draw(path)?;
            }
        }
        let text = || -> crate::Result<String> { crate::app::report::records::document(&json()?) };
        for path in &json_files {
            output::write_bytes(path, format!("{}\n", text()?).as_bytes())?;
        }
        if self.json {
            outln!("{}", text()?);
        } else if csv_files.is_empty() && plots.is_empty() && json_files.is_empty() {
            out!("{}", String::from_utf8_lossy(&csv::records_csv(records)?));
        }
        Ok(())
    }

    /// Print `records` on stdout as one JSON object of equal-length columns (--json).
    pub fn print_json<T: serde::Serialize>(&self, records: &[T]) -> crate::Result<()> {
        let columns = crate::app::report::records::columns_json(records)?;
        outln!("{}", crate::app::report::records::document(&columns)?);
        Ok(())
    }
}

thread_local! {
    /// What this thread's commands print while [`run_captured`] runs them: collected
    /// here, not written to standard output.
    static CAPTURED: std::cell::RefCell<Option<String>> = const { std::cell::RefCell::new(None) };
}

/// Write to standard output (what the `outln!` macro calls), or to the text
/// [`run_captured`] collects.
pub fn emit(text: std::fmt::Arguments) -> crate::Result<()> {
    use std::io::Write;
    let captured = CAPTURED.with_borrow_mut(|c| {
        c.as_mut()
            .map(|s| std::fmt::Write::write_fmt(s, text).is_ok())
    });
    if captured.is_some() {
        return Ok(());
    }
    let mut stdout = std::io::stdout().lock();
    stdout
        .write_fmt(text)
        .and_then(|()| stdout.flush())
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::BrokenPipe => crate::Error::StdoutClosed,
            _ => crate::Error::Output {
                path: "standard output".into(),
                reason: e.to_string(),
            },
        })
}

/// Why a command run by [`run_captured`] did not succeed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Refused {
    /// What the command line prints on stderr (without its `error: `).
    pub message: String,
}

/// Run `tapsim ARGS` in this process, on this thread, and return what it prints on
/// standard output: the same parsing, defaults, checks and numbers as the command line
/// (what the Python package calls, with `--json --quiet`). Progress and notes still go
/// to stderr unless `--quiet`. A refusal carries the command line's message.
pub fn run_captured(args: &[String]) -> std::result::Result<String, Refused> {
    let cli =
        parse(std::iter::once("tapsim".to_string()).chain(args.iter().cloned())).map_err(|e| {
            Refused {
                message: e
                    .render()
                    .to_string()
                    .trim_start_matches("error: ")
                    .trim_end()
                    .to_string(),
            }
        })?;
    crate::app::lj_cache::install();
    crate::app::report::output::announce_writes(cli.command.announces_writes());
    CAPTURED.with_borrow_mut(|c| *c = Some(String::new()));
    let outcome = dispatch(cli.command);
    let text = CAPTURED.with_borrow_mut(Option::take).unwrap_or_default();
    match outcome {
        Ok(()) => Ok(text),
        Err(e) => Err(Refused {
            message: e.to_string(),
        }),
    }
}

/// Run one parsed command: its files are put in place only if it succeeds (a command
/// that fails changes no file, [`crate::app::report::output::stage_writes`]) — but for
/// `reproduce` and `figure`, which fill a directory figure by figure, list each file as
/// it lands, and mark a directory they did not finish.
fn dispatch(command: Command) -> crate::Result<()> {
    use crate::app::report::output;
    command.check_early()?;
    if matches!(command, Command::Reproduce(_) | Command::Figure(_)) {
        return run_command(command);
    }
    output::stage_writes();
    match run_command(command) {
        Ok(()) => output::commit_writes(),
        Err(e) => {
            output::discard_writes();
            Err(e)
        }
    }
}

/// Run one parsed command, its writes staged.
fn run_command(command: Command) -> crate::Result<()> {
    match command {
        Command::Tap(args) => tap::run(args),
        Command::Approach(args) => approach::run(args),
        Command::Branches(args) => branches::run(args),
        Command::Bifurcation(args) => bifurcation::run(args),
        Command::Contrast(args) => contrast::run(args),
        Command::Fm(args) => fm::run(args),
        Command::Fit(args) => fit::run(args),
        Command::Reconstruct(args) => reconstruct::run(args),
        Command::Map(args) => map::run(args),
        Command::Scan(args) => scan::run(args),
        Command::Thermal(args) => thermal::run(args),
        Command::Peakforce(args) => peakforce::run(args),
        Command::ForceCurve(args) => force_curve::run(args),
        Command::Batch(args) => batch::run(args),
        Command::Merge(args) => merge::run(args),
        Command::Hysteresis(args) => hysteresis::run(args),
        Command::Lj(args) => lj::run(args),
        Command::Figure(args) => figure::run(args),
        Command::Reproduce(args) => reproduce::run(args),
        Command::Completions(args) => generated::completions(args),
        Command::Man(args) => generated::man(args),
    }
}

/// Run the command line with the process arguments; the exit code to return.
pub fn main() -> ExitCode {
    let cli = match parse(std::env::args_os()) {
        Ok(cli) => cli,
        Err(e) if e.use_stderr() => {
            // clap quotes the offending input: not a 10 000-character one whole.
            let text = e.render().to_string();
            let shortened: Vec<_> = text
                .split(' ')
                .map(|word| crate::error::abbreviate(word, 80))
                .collect();
            eprint!("{}", shortened.join(" "));
            return ExitCode::from(2);
        }
        Err(e) => e.exit(),
    };
    // Solutions of the Lennard-Jones problem come from the on-disk cache.
    crate::app::lj_cache::install();
    // An interrupted command leaves no half-written file behind: the exit code is the
    // shell's for a signal (128 + SIGINT).
    let _ = ctrlc::set_handler(|| {
        crate::app::report::output::remove_partial_files();
        std::process::exit(130);
    });
    // Every command names the files it writes on stderr unless --quiet; `reproduce` and
    // `figure` list them on stdout, their output.
    crate::app::report::output::announce_writes(cli.command.announces_writes());
    let outcome = dispatch(cli.command);
    match outcome {
        Ok(()) | Err(crate::Error::StdoutClosed) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            if matches!(e, crate::Error::Numerical(_)) && crate::app::lj_cache::cache_was_read() {
                eprintln!(
                    "note: Lennard-Jones solutions were read from the cache in {}: if one \
                     is damaged, `tapsim lj --mu <μ> --no-cache` solves it again and \
                     replaces it (or delete that directory)",
                    crate::app::lj_cache::cache_dir().display()
                );
            }
            ExitCode::FAILURE
        }
    }
}
