//! User inputs — command-line flags and TOML parameter files — and their resolution into
//! validated setups. Quantities accept unit suffixes (see [`crate::app::units`]); a TOML file
//! uses the flags' names as keys, with numbers in SI base units or strings with units:
//!
//! ```toml
//! law = "hybrid"
//! radius = "20nm"
//! sample-modulus = "0.5GPa"
//! work-of-adhesion = 0.1
//! stiffness = "40N/m"
//! ```
//!
//! Flags override the file; the file overrides the built-in defaults.

use crate::analysis::setpoint::PhaseBranch;
use crate::app::units::{self, Dimension};
use crate::dynamics::modes::set::MAX_MODES;
use crate::dynamics::modes::{Eigenmode, ModeSet};
use crate::dynamics::setup::{Cantilever, Numerics, TapSetup, default_setup};
use crate::error::{Error, Result};
use crate::physics::law::{LAW_PARAMS, LawKind, LawParam, LawSpec};
use crate::physics::params::{self, Contact};
use clap::Args;
use std::path::{Path, PathBuf};

macro_rules! unit_parser {
    ($(#[$doc:meta])* $name:ident, $what:literal, $dim:expr) => {
        $(#[$doc])*
        pub fn $name(s: &str) -> std::result::Result<f64, String> {
            units::parse($what, s, $dim).map_err(|e| e.to_string())
        }
    };
}

unit_parser!(/// A length (m).
    length, "length", Dimension::Length);
unit_parser!(/// A pressure or modulus (Pa).
    pressure, "modulus", Dimension::Pressure);
unit_parser!(/// A work of adhesion (J/m²).
    surface_energy, "work of adhesion", Dimension::SurfaceEnergy);
unit_parser!(/// A stiffness (N/m).
    stiffness, "stiffness", Dimension::Stiffness);
unit_parser!(/// A frequency (Hz).
    frequency, "frequency", Dimension::Frequency);
unit_parser!(/// An energy (J or eV).
    energy, "energy", Dimension::Energy);
unit_parser!(/// A viscosity (Pa·s).
    viscosity, "viscosity", Dimension::Viscosity);
unit_parser!(/// A time (s).
    time, "time", Dimension::Time);
unit_parser!(/// A temperature (K).
    temperature, "temperature", Dimension::Temperature);
unit_parser!(/// A force (N).
    force, "force", Dimension::Force);
unit_parser!(/// A velocity (m/s).
    velocity, "velocity", Dimension::Velocity);
unit_parser!(/// A plain number.
    number, "value", Dimension::Dimensionless);

/// Default Poisson ratio of a silicon tip.
pub const DEFAULT_TIP_POISSON: f64 = 0.28;
/// Default Poisson ratio of a polymer sample.
pub const DEFAULT_SAMPLE_POISSON: f64 = 0.4;
/// Default Young's modulus of a silicon tip, Pa.
pub const DEFAULT_TIP_MODULUS: f64 = 169e9;

/// A sphere-on-flat contact in SI units, every field optional.
#[derive(Debug, Clone, Default, Args)]
pub struct ContactInputs {
    /// Tip radius R [m; the built-in sample's 20nm].
    #[arg(long, allow_hyphen_values = true, value_parser = length, help_heading = "Contact (SI)")]
    pub radius: Option<f64>,
    /// Composite modulus E* [Pa; the built-in sample's 0.593GPa, from the tip's and the
    /// sample's moduli]. Or give --tip-modulus/--sample-modulus.
    #[arg(long, allow_hyphen_values = true, value_parser = pressure, help_heading = "Contact (SI)",
          conflicts_with_all = ["tip_modulus", "sample_modulus"])]
    pub modulus: Option<f64>,
    /// Young's modulus of the tip [Pa; default 169GPa, silicon].
    #[arg(hide_short_help = true, long, allow_hyphen_values = true, value_parser = pressure, help_heading = "Contact (SI)")]
    pub tip_modulus: Option<f64>,
    /// Poisson ratio of the tip [default 0.28].
    #[arg(hide_short_help = true, long, allow_hyphen_values = true, value_parser = number, help_heading = "Contact (SI)")]
    pub tip_poisson: Option<f64>,
    /// Young's modulus of the sample [Pa; the built-in sample's 0.5GPa, a soft polymer].
    #[arg(long, allow_hyphen_values = true, value_parser = pressure, help_heading = "Contact (SI)")]
    pub sample_modulus: Option<f64>,
    /// Poisson ratio of the sample [default 0.4].
    #[arg(hide_short_help = true, long, allow_hyphen_values = true, value_parser = number, help_heading = "Contact (SI)")]
    pub sample_poisson: Option<f64>,
    /// Work of adhesion Δγ [J/m²; the built-in sample's 0.1J/m^2].
    #[arg(long, allow_hyphen_values = true, value_parser = surface_energy, help_heading = "Contact (SI)")]
    pub work_of_adhesion: Option<f64>,
    /// Range ε of the Lennard-Jones law [m; the built-in sample's 0.3nm]: the
    /// equilibrium gap of eq. (10).
    #[arg(long, allow_hyphen_values = true, value_parser = length, help_heading = "Contact (SI)")]
    pub range: Option<f64>,
}

impl ContactInputs {
    /// Whether any SI contact input was given.
    pub fn any(&self) -> bool {
        self.radius.is_some()
            || self.modulus.is_some()
            || self.tip_modulus.is_some()
            || self.sample_modulus.is_some()
            || self.work_of_adhesion.is_some()
            || self.range.is_some()
    }

    /// Composite modulus E* from --modulus, or from tip and sample (a missing tip modulus
    /// is silicon's, missing Poisson ratios 0.28 and 0.4); `None` if neither is given.
    pub fn composite_modulus(&self) -> Result<Option<f64>> {
        if let Some(e) = self.modulus {
            return Ok(Some(e));
        }
        let Some(sample) = self.sample_modulus else {
            if self.tip_modulus.is_some() {
                return Err(Error::NotApplicable(
                    "--tip-modulus needs --sample-modulus as well".into(),
                ));
            }
            return Ok(None);
        };
        // A bare number meant in GPa, caught before it becomes a composite modulus the
        // user never typed.
        for (flag, modulus) in [
            ("--sample-modulus", Some(sample)),
            ("--tip-modulus", self.tip_modulus),
        ] {
            if let Some(e) = modulus.filter(|&e| e > 0.0 && e < 1e3) {
                return Err(Error::OutOfRange(format!(
                    "{flag} {e} Pa is below 1 kPa (living cells); bare numbers are in Pa: did \
                     you mean {e}GPa?"
                )));
            }
        }
        params::composite_modulus(
            self.tip_modulus.unwrap_or(DEFAULT_TIP_MODULUS),
            self.tip_poisson.unwrap_or(DEFAULT_TIP_POISSON),
            sample,
            self.sample_poisson.unwrap_or(DEFAULT_SAMPLE_POISSON),
        )
        .map(Some)
    }

    /// The contact, every input required; an error naming what is missing.
    pub fn contact(&self) -> Result<Contact> {
        let missing = |what: &str| {
            Error::NotApplicable(format!(
                "the SI contact needs {what} (give --radius, --modulus or \
                 --sample-modulus, --work-of-adhesion and --range)"
            ))
        };
        Contact::new(
            self.radius.ok_or_else(|| missing("--radius"))?,
            self.composite_modulus()?
                .ok_or_else(|| missing("--modulus"))?,
            self.work_of_adhesion
                .ok_or_else(|| missing("--work-of-adhesion"))?,
            self.range.ok_or_else(|| missing("--range"))?,
        )
    }

    /// Field-wise: `self` where given, else `base`.
    pub fn or(self, base: Self) -> Self {
        Self {
            radius: self.radius.or(base.radius),
            modulus: self.modulus.or(
                if self.tip_modulus.is_some() || self.sample_modulus.is_some() {
                    None
                } else {
                    base.modulus
                },
            ),
            tip_modulus: self.tip_modulus.or(base.tip_modulus),
            tip_poisson: self.tip_poisson.or(base.tip_poisson),
            sample_modulus: self.sample_modulus.or(if self.modulus.is_some() {
                None
            } else {
                base.sample_modulus
            }),
            sample_poisson: self.sample_poisson.or(base.sample_poisson),
            work_of_adhesion: self.work_of_adhesion.or(base.work_of_adhesion),
            range: self.range.or(base.range),
        }
    }
}

/// `--law` takes the registry's names and shows its help.
impl clap::ValueEnum for LawKind {
    fn value_variants<'a>() -> &'a [Self] {
        &LawKind::ALL
    }
    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        let info = self.info();
        Some(clap::builder::PossibleValue::new(info.name).help(info.help))
    }
}

/// The law parameters of the registry ([`LAW_PARAMS`]), in its order: each one a flag
/// and a parameter-file key named by its registry key, read in its registry unit, with
/// its registry help. A new law parameter needs nothing here.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LawParamInputs(pub [Option<f64>; LAW_PARAMS.len()]);

impl LawParamInputs {
    /// The parameters `spec` sets.
    pub fn of(spec: &LawSpec) -> Self {
        Self(spec.params().map(|(_, value)| value))
    }

    /// Parameter-wise: `self` where given, else `base`.
    pub fn or(self, base: Self) -> Self {
        let mut out = self;
        for (value, base) in out.0.iter_mut().zip(base.0) {
            *value = value.or(base);
        }
        out
    }
}

/// The dimension a law parameter is read in, from its registry unit.
#[doc(hidden)]
pub fn dimension(param: &LawParam) -> Dimension {
    match param.unit {
        "m" => Dimension::Length,
        "Pa" => Dimension::Pressure,
        "J" => Dimension::Energy,
        "J/m²" => Dimension::SurfaceEnergy,
        "Pa·s" => Dimension::Viscosity,
        "s" => Dimension::Time,
        _ => Dimension::Dimensionless,
    }
}

impl clap::FromArgMatches for LawParamInputs {
    fn from_arg_matches(matches: &clap::ArgMatches) -> std::result::Result<Self, clap::Error> {
        let mut inputs = Self::default();
        inputs.update_from_arg_matches(matches)?;
        Ok(inputs)
    }

    fn update_from_arg_matches(
        &mut self,
        matches: &clap::ArgMatches,
    ) -> std::result::Result<(), clap::Error> {
        for (value, param) in self.0.iter_mut().zip(LAW_PARAMS) {
            if let Some(v) = matches.get_one::<f64>(param.key) {
                *value = Some(*v);
            }
        }
        Ok(())
    }
}

impl Args for LawParamInputs {
    fn augment_args(command: clap::Command) -> clap::Command {
        LAW_PARAMS.iter().fold(command, |command, &param| {
            let dim = dimension(param);
            command.arg(
                clap::Arg::new(param.key)
                    .long(param.key)
                    .value_name(param.unit)
                    .allow_hyphen_values(true)
                    .value_parser(move |text: &str| {
                        units::parse(param.name, text, dim).map_err(|e| e.to_string())
                    })
                    .help(param.help)
                    .help_heading("Contact (SI)")
                    // The laws' own parameters: in --help, not in -h's summary.
                    .hide_short_help(true),
            )
        })
    }

    fn augment_args_for_update(command: clap::Command) -> clap::Command {
        Self::augment_args(command)
    }
}

/// Everything a tapping simulation takes, every field optional (defaults fill in).
#[derive(Debug, Clone, Default, Args)]
pub struct TapInputs {
    /// TOML parameter file (keys: the flags' names; values in SI or strings with units).
    /// Flags override it.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Tip–sample force law (`tapsim fit` takes several, comma-separated, and ranks
    /// them).
    #[arg(long, value_enum, ignore_case = true, value_delimiter = ',')]
    pub law: Vec<LawKind>,
    /// The contact.
    #[command(flatten)]
    pub contact: ContactInputs,
    /// The law parameters of the registry, one flag each.
    #[command(flatten)]
    pub law_params: LawParamInputs,
    /// Cantilever spring constant k [N/m; default 40]. (Also --k.)
    #[arg(long, alias = "k", allow_hyphen_values = true, value_parser = stiffness, help_heading = "Cantilever")]
    pub stiffness: Option<f64>,
    /// Resonance frequency f₀ [Hz; default 300kHz]. (Also --f0.)
    #[arg(long, alias = "f0", allow_hyphen_values = true, value_parser = frequency, help_heading = "Cantilever")]
    pub resonance: Option<f64>,
    /// Quality factor Q [default 400]. (Also --Q.)
    #[arg(long, aliases = ["Q", "q"], allow_hyphen_values = true, value_parser = number, help_heading = "Cantilever")]
    pub quality: Option<f64>,
    /// Free amplitude A₀ [m; default 20nm]. (Also --A0.)
    #[arg(long, aliases = ["A0", "a0"], allow_hyphen_values = true, value_parser = length, help_heading = "Cantilever")]
    pub free_amplitude: Option<f64>,
    /// Drive frequency [Hz; default: the resonance frequency].
    #[arg(hide_short_help = true, long, allow_hyphen_values = true, value_parser = frequency, help_heading = "Cantilever")]
    pub drive_frequency: Option<f64>,
    /// Rest tip–sample separation z_c [m; default 16nm]; the gap is α = z_c + z. (Also --zc.)
    #[arg(long, alias = "zc", allow_hyphen_values = true, value_parser = length, help_heading = "Cantilever")]
    pub separation: Option<f64>,
    /// Relative tolerance of the integrator [default 1e-9; absolute: 1e-2 of it].
    #[arg(hide_short_help = true, long, allow_hyphen_values = true, value_parser = number, help_heading = "Numerics")]
    pub rtol: Option<f64>,
    /// Most cycles to integrate looking for the steady state [default 20000].
    #[arg(hide_short_help = true, long, allow_hyphen_values = true, value_parser = number, help_heading = "Numerics")]
    pub max_cycles: Option<f64>,
    /// Periodic steady state: how closely the state must return after n periods, in
    /// units of A₀ [default 1e-9 for tap, 1e-7 per setpoint for sweeps].
    #[arg(hide_short_help = true, long, allow_hyphen_values = true, value_parser = number, help_heading = "Numerics")]
    pub tolerance: Option<f64>,
    /// Irregular (not periodic) motion: standard error the averages must reach, A and
    /// E_ts relative, φ in rad [default 1e-3].
    #[arg(hide_short_help = true, long, allow_hyphen_values = true, value_parser = number, help_heading = "Numerics")]
    pub average_tolerance: Option<f64>,
    /// The amplitude setpoint A/A₀ (a parameter file's `setpoint`, or `tap`'s and `map`'s
    /// --setpoint): exclusive with `separation`.
    #[arg(skip)]
    pub setpoint: Option<f64>,
    /// The amplitude setpoint as an amplitude in m (`amplitude-setpoint`).
    #[arg(skip)]
    pub amplitude_setpoint: Option<f64>,
    /// Which branch at the setpoint (`branch`).
    #[arg(skip)]
    pub branch: Option<BranchChoice>,
    /// A parameter file's eigenmodes (`modes`, `[[mode]]`, `ratio-tolerance`).
    #[arg(skip)]
    pub mode_file: ModeFile,
    /// Whether the command reading these inputs simulates several modes ([`ModeInputs`]);
    /// if not, a file that asks for them is refused.
    #[arg(skip)]
    pub takes_modes: bool,
}

/// Which branch's states at an amplitude setpoint (`--branch`, a parameter file's
/// `branch`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum BranchChoice {
    /// Both branches.
    All,
    /// φ above the free phase: the tip feels a net attraction.
    Attractive,
    /// φ below the free phase: the tip presses into the sample.
    Repulsive,
}

impl BranchChoice {
    /// The one branch asked for (`None`: both).
    pub fn only(self) -> Option<PhaseBranch> {
        match self {
            Self::All => None,
            Self::Attractive => Some(PhaseBranch::Attractive),
            Self::Repulsive => Some(PhaseBranch::Repulsive),
        }
    }
}

/// A TOML value of `key` as the text a quantity is parsed from (a number, or a string
/// with a unit); anything else is refused as a `what` (the file's kind of value).
pub fn value_text(value: &toml::Value, key: &str, what: &'static str) -> Result<String> {
    match value {
        toml::Value::Float(f) => Ok(f.to_string()),
        toml::Value::Integer(i) => Ok(i.to_string()),
        toml::Value::String(s) => Ok(s.clone()),
        other => Err(Error::Parse {
            name: what,
            text: other.to_string(),
            reason: format!("{key} must be a number or a string with a unit"),
        }),
    }
}

/// The largest parameter file read, in bytes.
pub const MAX_CONFIG_BYTES: u64 = 64 * 1024;

/// The input file `path` read whole. Only a regular file of at most `max_bytes` is read
/// (a FIFO would block, a device never end); `refuse` makes the error for one that is
/// not, failures to read are [`Error::Io`].
pub fn read_input(
    path: &Path,
    max_bytes: u64,
    refuse: impl Fn(String) -> Error,
) -> Result<Vec<u8>> {
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(refuse("not a regular file".into()));
    }
    if meta.len() > max_bytes {
        return Err(refuse(format!(
            "{} bytes; at most {max_bytes} are read",
            meta.len()
        )));
    }
    std::fs::read(path).map_err(io)
}

/// [`read_input`] as UTF-8 text.
pub fn read_text(path: &Path, max_bytes: u64, refuse: impl Fn(String) -> Error) -> Result<String> {
    let bytes = read_input(path, max_bytes, &refuse)?;
    String::from_utf8(bytes).map_err(|_| refuse("not UTF-8 text".into()))
}

/// A CSV data file at `path` (at most `max_bytes`, [`read_input`]): its header and its
/// rows, cells trimmed; `fail` words a refusal (a row's names it, counting the header as
/// row 1).
pub fn read_csv(
    path: &Path,
    max_bytes: u64,
    fail: impl Fn(String) -> Error,
) -> Result<(csv::StringRecord, Vec<csv::StringRecord>)> {
    let bytes = read_input(path, max_bytes, &fail)?;
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(bytes.as_slice());
    let headers = reader
        .headers()
        .map_err(|e| fail(format!("no CSV header: {e}")))?
        .clone();
    let rows = reader
        .records()
        .enumerate()
        .map(|(row, record)| record.map_err(|e| fail(format!("row {}: {e}", row + 2))))
        .collect::<Result<Vec<_>>>()?;
    Ok((headers, rows))
}

/// A settable quantity: its key (a flag's name, also the TOML key), its dimension, and
/// where it lives in [`TapInputs`].
type Field = (
    &'static str,
    Dimension,
    fn(&mut TapInputs) -> &mut Option<f64>,
);

/// One list of every numeric key: `key => Dimension => |inputs| place`.
macro_rules! fields {
    ($($key:literal => $dim:ident => |$i:ident| $place:expr),* $(,)?) => {
        &[$((
            $key,
            Dimension::$dim,
            {
                fn slot($i: &mut TapInputs) -> &mut Option<f64> {
                    &mut $place
                }
                slot
            },
        )),*]
    };
}

/// The numeric keys of the command line and of parameter files.
#[doc(hidden)]
pub const FIELDS: &[Field] = fields![
    "radius" => Length => |i| i.contact.radius,
    "modulus" => Pressure => |i| i.contact.modulus,
    "tip-modulus" => Pressure => |i| i.contact.tip_modulus,
    "tip-poisson" => Dimensionless => |i| i.contact.tip_poisson,
    "sample-modulus" => Pressure => |i| i.contact.sample_modulus,
    "sample-poisson" => Dimensionless => |i| i.contact.sample_poisson,
    "work-of-adhesion" => SurfaceEnergy => |i| i.contact.work_of_adhesion,
    "range" => Length => |i| i.contact.range,
    "stiffness" => Stiffness => |i| i.stiffness,
    "resonance" => Frequency => |i| i.resonance,
    "quality" => Dimensionless => |i| i.quality,
    "free-amplitude" => Length => |i| i.free_amplitude,
    "drive-frequency" => Frequency => |i| i.drive_frequency,
    "separation" => Length => |i| i.separation,
    "setpoint" => Dimensionless => |i| i.setpoint,
    "amplitude-setpoint" => Length => |i| i.amplitude_setpoint,
    "rtol" => Dimensionless => |i| i.rtol,
    "max-cycles" => Dimensionless => |i| i.max_cycles,
    "tolerance" => Dimensionless => |i| i.tolerance,
    "average-tolerance" => Dimensionless => |i| i.average_tolerance,
];

impl TapInputs {
    /// Set the quantity named `key` (a flag's name) from `text` (a number with an
    /// optional unit; for `branch`, all, attractive or repulsive).
    pub fn set(&mut self, key: &str, text: &str) -> Result<()> {
        if key == "branch" {
            let choice = <BranchChoice as clap::ValueEnum>::from_str(text.trim(), true);
            self.branch = Some(choice.map_err(|_| Error::Parse {
                name: "branch",
                text: text.to_string(),
                reason: "expected one of all, attractive, repulsive".into(),
            })?);
            return Ok(());
        }
        if let Some(&(name, dim, slot)) = FIELDS.iter().find(|(k, _, _)| *k == key) {
            *slot(self) = Some(units::parse(name, text, dim)?);
            return Ok(());
        }
        if let Some(i) = LAW_PARAMS.iter().position(|p| p.key == key) {
            let param = LAW_PARAMS[i];
            self.law_params.0[i] = Some(units::parse(param.name, text, dimension(param))?);
            return Ok(());
        }
        let known: Vec<&str> = FIELDS
            .iter()
            .map(|(k, _, _)| *k)
            .chain(LAW_PARAMS.iter().map(|p| p.key))
            .collect();
        Err(Error::Parse {
            name: "key",
            text: key.to_string(),
            reason: format!("unknown key; known keys: law, branch, {}", known.join(", ")),
        })
    }

    /// Read a TOML parameter file (keys as the flags' names), at most
    /// [`MAX_CONFIG_BYTES`] ([`read_input`]).
    pub fn from_toml_file(path: &Path) -> Result<Self> {
        let refuse = |reason: String| Error::Parse {
            name: "config",
            text: path.display().to_string(),
            reason,
        };
        let text = read_text(path, MAX_CONFIG_BYTES, refuse)?;
        Self::from_toml(&text).map_err(|e| match e {
            Error::Parse {
                name: "config",
                reason,
                ..
            } => refuse(reason),
            Error::Parse { name, text, reason } => Error::Parse {
                name,
                text,
                reason: format!("{reason} (in {})", path.display()),
            },
            other => other,
        })
    }

    /// Parse TOML text (keys as the flags' names).
    pub fn from_toml(text: &str) -> Result<Self> {
        let table: toml::Table = text.parse().map_err(|e: toml::de::Error| Error::Parse {
            name: "config",
            text: String::new(),
            reason: format!("not valid TOML: {}", e.to_string().trim_end()),
        })?;
        let mut inputs = Self::default();
        for (key, value) in &table {
            if matches!(key.as_str(), "modes" | "mode" | "ratio-tolerance") {
                inputs.mode_file.set(key, value)?;
                continue;
            }
            if key == "law" {
                let name = value.as_str().unwrap_or_default();
                inputs.law = vec![LawKind::from_name(name).ok_or_else(|| Error::Parse {
                    name: "law",
                    text: value.to_string(),
                    reason: format!("expected one of {}", LawKind::names().join(", ")),
                })?];
                continue;
            }
            inputs.set(key, &value_text(value, key, "config value")?)?;
        }
        let held = [
            ("separation", inputs.separation),
            ("setpoint", inputs.setpoint),
            ("amplitude-setpoint", inputs.amplitude_setpoint),
        ];
        let given: Vec<&str> = held
            .iter()
            .filter(|(_, v)| v.is_some())
            .map(|(k, _)| *k)
            .collect();
        if given.len() > 1 {
            return Err(Error::Parse {
                name: "config",
                text: String::new(),
                reason: format!(
                    "{} are exclusive: a rest separation, or the amplitude setpoint the z \
                     feedback holds (A/A₀ or an amplitude), not both",
                    given.join(" and ")
                ),
            });
        }
        Ok(inputs)
    }

    /// Refuse an amplitude setpoint (from a parameter file) in `command`, which does
    /// not take one.
    pub fn no_setpoint(&self, command: &str) -> Result<()> {
        if self.setpoint.is_none() && self.amplitude_setpoint.is_none() {
            return Ok(());
        }
        Err(Error::NotApplicable(format!(
            "the parameter file sets an amplitude setpoint, which `tapsim {command}` does \
             not take: `tapsim tap` and `tapsim map` work at it (remove `setpoint` from \
             the file for this command)"
        )))
    }

    /// Field-wise: `self` where given, else `base`.
    pub fn or(self, base: Self) -> Self {
        let holds = self.separation.is_some()
            || self.setpoint.is_some()
            || self.amplitude_setpoint.is_some();
        Self {
            config: self.config.or(base.config),
            law: if self.law.is_empty() {
                base.law
            } else {
                self.law
            },
            contact: self.contact.or(base.contact),
            law_params: self.law_params.or(base.law_params),
            stiffness: self.stiffness.or(base.stiffness),
            resonance: self.resonance.or(base.resonance),
            quality: self.quality.or(base.quality),
            free_amplitude: self.free_amplitude.or(base.free_amplitude),
            drive_frequency: self.drive_frequency.or(base.drive_frequency),
            // Where the flags hold the tip (a separation or a setpoint), the file's
            // separation and setpoint give way together.
            separation: if holds {
                self.separation
            } else {
                base.separation
            },
            setpoint: if holds { self.setpoint } else { base.setpoint },
            amplitude_setpoint: if holds {
                self.amplitude_setpoint
            } else {
                base.amplitude_setpoint
            },
            branch: self.branch.or(base.branch),
            mode_file: if self.mode_file == ModeFile::default() {
                base.mode_file
            } else {
                self.mode_file
            },
            takes_modes: self.takes_modes || base.takes_modes,
            rtol: self.rtol.or(base.rtol),
            max_cycles: self.max_cycles.or(base.max_cycles),
            tolerance: self.tolerance.or(base.tolerance),
            average_tolerance: self.average_tolerance.or(base.average_tolerance),
        }
    }

    /// `numerics` with the sweep defaults per setpoint ([`crate::analysis::sweep::sweep_numerics`])
    /// for whichever of --tolerance and --max-cycles these inputs leave unset.
    pub fn sweep_numerics(&self, numerics: Numerics) -> Numerics {
        crate::analysis::sweep::sweep_numerics(
            numerics,
            (self.tolerance.is_some(), self.max_cycles.is_some()),
        )
    }

    /// These inputs holding the tip at the setpoint of a command's own flags (`tap`'s
    /// and `map`'s --setpoint, --amplitude-setpoint, --branch), over the `--config`
    /// file ([`Self::with_config`]).
    pub fn holding(
        self,
        setpoint: Option<f64>,
        amplitude_setpoint: Option<f64>,
        branch: Option<BranchChoice>,
    ) -> Result<Self> {
        Self {
            setpoint,
            amplitude_setpoint,
            branch,
            ..self
        }
        .with_config()
    }

    /// The amplitude setpoint A/A₀ these inputs hold the tip at, if any: `setpoint`, or
    /// `amplitude-setpoint` over the free amplitude `free_amplitude_m`.
    pub fn setpoint_ratio(&self, free_amplitude_m: f64) -> Option<f64> {
        self.setpoint
            .or(self.amplitude_setpoint.map(|a| a / free_amplitude_m))
    }

    /// Whether the tip is held at an amplitude setpoint (as A/A₀ or an amplitude).
    pub fn holds_setpoint(&self) -> bool {
        self.setpoint.is_some() || self.amplitude_setpoint.is_some()
    }

    /// Flags over the `--config` file, if one was given.
    pub fn with_config(self) -> Result<Self> {
        Ok(match self.config.clone() {
            Some(path) => self.or(Self::from_toml_file(&path)?),
            None => self,
        })
    }

    /// The setup and numerics: these inputs over the built-in defaults
    /// ([`default_setup`], [`Numerics::default`]).
    pub fn resolve(&self) -> Result<(TapSetup, Numerics)> {
        if self.law.len() > 1 {
            return Err(Error::NotApplicable(format!(
                "one law at a time here, not {}: `tapsim fit --law a,b` fits several and \
                 ranks them",
                self.law.len()
            )));
        }
        if !self.takes_modes
            && self
                .mode_file
                .count
                .map_or(!self.mode_file.tables.is_empty(), |n| n > 1)
        {
            return Err(Error::NotApplicable(
                "the parameter file asks for several eigenmodes (`modes`), which this command \
                 does not simulate: `tapsim tap`, `approach`, `contrast` and `map` do (remove \
                 `modes` from the file for this command)"
                    .into(),
            ));
        }
        let d = default_setup();
        let c = &self.contact;
        let contact = Contact {
            radius_m: c.radius.unwrap_or(d.contact.radius_m),
            modulus_pa: c.composite_modulus()?.unwrap_or(d.contact.modulus_pa),
            work_of_adhesion_j_m2: c
                .work_of_adhesion
                .unwrap_or(d.contact.work_of_adhesion_j_m2),
            range_m: c.range.unwrap_or(d.contact.range_m),
        };
        let resonance = self.resonance.unwrap_or(d.cantilever.resonance_hz);
        let mut cantilever = d.cantilever;
        cantilever.stiffness_n_m = self.stiffness.unwrap_or(cantilever.stiffness_n_m);
        cantilever.resonance_hz = resonance;
        cantilever.quality = self.quality.unwrap_or(cantilever.quality);
        cantilever.free_amplitude_m = self.free_amplitude.unwrap_or(cantilever.free_amplitude_m);
        cantilever.drive_frequency_hz = self.drive_frequency.unwrap_or(resonance);
        let setup = TapSetup {
            contact,
            cantilever,
            separation_m: self.separation.unwrap_or(d.separation_m),
            law: LawSpec::from_values(
                self.law.first().copied().unwrap_or(d.law.kind),
                self.law_params.or(LawParamInputs::of(&d.law)).0,
            ),
        };
        let mut numerics = Numerics::default();
        if let Some(rtol) = self.rtol {
            numerics.rtol = rtol;
            numerics.atol = rtol * 1e-2;
        }
        if let Some(t) = self.tolerance {
            numerics.tolerance = t;
        }
        if let Some(t) = self.average_tolerance {
            numerics.average_tolerance = t;
        }
        if let Some(n) = self.max_cycles {
            if !(n >= 32.0 && n.fract() == 0.0 && n <= 1e9) {
                return Err(Error::InvalidParameter {
                    name: "max cycles",
                    value: n,
                    reason: "must be a whole number from 32 to 1e9 (classifying the steady \
                             state and averaging irregular motion need at least 32 periods)",
                });
            }
            numerics.max_cycles = n as usize;
        }
        Ok((setup, numerics))
    }
}

/// One `[[mode]]` table of a parameter file: a higher mode's values (modes 2, 3 in the
/// order of the tables), each optional over the rectangular-beam defaults.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ModeTable {
    /// `stiffness` (N/m).
    pub stiffness: Option<f64>,
    /// `resonance` (Hz).
    pub resonance: Option<f64>,
    /// `quality`.
    pub quality: Option<f64>,
    /// `free-amplitude` (m; 0: not driven).
    pub free_amplitude: Option<f64>,
}

/// A parameter file's eigenmodes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ModeFile {
    /// `modes`: how many.
    pub count: Option<usize>,
    /// `[[mode]]`: modes 2, 3.
    pub tables: Vec<ModeTable>,
    /// `ratio-tolerance`.
    pub ratio_tolerance: Option<f64>,
}

impl ModeFile {
    fn set(&mut self, key: &str, value: &toml::Value) -> Result<()> {
        let bad = |reason: String| Error::Parse {
            name: "config",
            text: key.to_string(),
            reason,
        };
        match key {
            "modes" => {
                let n = value
                    .as_integer()
                    .filter(|n| (1..=MAX_MODES as i64).contains(n))
                    .ok_or_else(|| {
                        bad(format!("`modes` is a whole number from 1 to {MAX_MODES}"))
                    })?;
                self.count = Some(n as usize);
            }
            "ratio-tolerance" => {
                self.ratio_tolerance = Some(units::parse(
                    "ratio tolerance",
                    &value_text(value, key, "config value")?,
                    Dimension::Dimensionless,
                )?);
            }
            _ => {
                let tables = value
                    .as_array()
                    .filter(|a| a.iter().all(toml::Value::is_table));
                let tables = tables.ok_or_else(|| {
                    bad(
                        "`[[mode]]` tables: one per higher mode (2, then 3), with stiffness, \
                         resonance, quality and free-amplitude"
                            .into(),
                    )
                })?;
                if tables.len() >= MAX_MODES {
                    return Err(bad(format!(
                        "{} `[[mode]]` tables: modes 2 to {MAX_MODES} have one each",
                        tables.len()
                    )));
                }
                for table in tables.iter().filter_map(toml::Value::as_table) {
                    let mut mode = ModeTable::default();
                    for (k, v) in table {
                        let (slot, name, dim) = match k.as_str() {
                            "stiffness" => {
                                (&mut mode.stiffness, "mode stiffness", Dimension::Stiffness)
                            }
                            "resonance" => {
                                (&mut mode.resonance, "mode resonance", Dimension::Frequency)
                            }
                            "quality" => {
                                (&mut mode.quality, "mode quality", Dimension::Dimensionless)
                            }
                            "free-amplitude" => (
                                &mut mode.free_amplitude,
                                "mode free amplitude",
                                Dimension::Length,
                            ),
                            other => {
                                return Err(bad(format!(
                                    "unknown key `{other}` in a [[mode]] table; known: \
                                     stiffness, resonance, quality, free-amplitude"
                                )));
                            }
                        };
                        *slot = Some(units::parse(name, &value_text(v, k, "mode value")?, dim)?);
                    }
                    self.tables.push(mode);
                }
            }
        }
        Ok(())
    }
}

/// The eigenmodes of a simulation (`--modes` and the second mode's flags), over a
/// parameter file's `modes`, `[[mode]]` and `ratio-tolerance`.
#[derive(Debug, Clone, Default, Args)]
pub struct ModeInputs {
    /// Eigenmodes simulated together [1 to 3; default 1]. They share the tip force; 2
    /// is bimodal AFM: the first mode taps at the drive frequency while
    /// the second, driven at its own resonance with a small amplitude, feels the force
    /// gradient over the first mode's orbit (its phase φ₂ is the compositional
    /// contrast). Higher modes default to a rectangular beam's (f₂ = 6.267 f₀,
    /// k₂ = k (f₂/f₀)², Q₂ = Q f₂/f₀, A₀₂ = A₀/40), each overridable; in a parameter
    /// file: `modes = 2` and a `[[mode]]` table per higher mode (stiffness, resonance,
    /// quality, free-amplitude).
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=3), help_heading = "Eigenmodes")]
    pub modes: Option<u8>,
    /// Free amplitude A₀₂ of the second mode at its resonance [m; default A₀/40; 0: not
    /// driven].
    #[arg(hide_short_help = true, long, value_name = "A02", allow_hyphen_values = true, value_parser = length, help_heading = "Eigenmodes")]
    pub drive2_amplitude: Option<f64>,
    /// Spring constant k₂ of the second mode [N/m; default k (f₂/f₀)²].
    #[arg(hide_short_help = true, long, allow_hyphen_values = true, value_parser = stiffness, help_heading = "Eigenmodes")]
    pub mode2_stiffness: Option<f64>,
    /// Resonance f₂ of the second mode [Hz; default 6.267 f₀, a rectangular beam's].
    #[arg(hide_short_help = true, long, allow_hyphen_values = true, value_parser = frequency, help_heading = "Eigenmodes")]
    pub mode2_resonance: Option<f64>,
    /// Quality factor Q₂ of the second mode [default Q f₂/f₀].
    #[arg(hide_short_help = true, long, allow_hyphen_values = true, value_parser = number, help_heading = "Eigenmodes")]
    pub mode2_quality: Option<f64>,
    /// How far (relative) a higher mode's resonance may be moved so that it is a
    /// ratio p/q of the first drive frequency (q ≤ 32), making the motion periodic over
    /// q drive periods; the frequencies simulated are reported [default 0.005: the
    /// beam's f₂ = 6.267 f₀ becomes 25/4 f₀]. 0 keeps every frequency as given: with no
    /// common period, `tap` reports averages over windows, each with its error, and
    /// `scan` marches the modes as they are.
    #[arg(hide_short_help = true, long, allow_hyphen_values = true, value_parser = number, help_heading = "Eigenmodes")]
    pub ratio_tolerance: Option<f64>,
}

impl ModeInputs {
    /// Mark `inputs` as read by a command that simulates several modes.
    pub fn taken_by(inputs: &mut TapInputs) {
        inputs.takes_modes = true;
    }

    /// The higher modes asked for (none: one mode), flags over `file`, over the
    /// rectangular-beam defaults of `first`.
    pub fn mode_set(&self, file: &ModeFile, first: &Cantilever) -> Result<Option<ModeSet>> {
        let count =
            self.modes
                .map(usize::from)
                .or(file.count)
                .unwrap_or(if file.tables.is_empty() {
                    1
                } else {
                    1 + file.tables.len()
                });
        let second_flags = self.drive2_amplitude.is_some()
            || self.mode2_stiffness.is_some()
            || self.mode2_resonance.is_some()
            || self.mode2_quality.is_some();
        if count == 1 {
            if second_flags || self.ratio_tolerance.is_some() {
                return Err(Error::NotApplicable(
                    "the second mode's flags (--drive2-amplitude, --mode2-*, \
                     --ratio-tolerance) need --modes 2 or 3"
                        .into(),
                ));
            }
            return Ok(None);
        }
        let mut set = ModeSet::euler_bernoulli(first, count)?;
        for (mode, table) in set.higher.iter_mut().zip(&file.tables) {
            apply(mode, table);
        }
        apply(
            &mut set.higher[0],
            &ModeTable {
                stiffness: self.mode2_stiffness,
                resonance: self.mode2_resonance,
                quality: self.mode2_quality,
                free_amplitude: self.drive2_amplitude,
            },
        );
        if let Some(t) = self.ratio_tolerance.or(file.ratio_tolerance) {
            set.ratio_tolerance = t;
        }
        Ok(Some(set))
    }
}

fn apply(mode: &mut Eigenmode, table: &ModeTable) {
    if let Some(k) = table.stiffness {
        mode.stiffness_n_m = k;
    }
    if let Some(f) = table.resonance {
        mode.resonance_hz = f;
    }
    if let Some(q) = table.quality {
        mode.quality = q;
    }
    if let Some(a) = table.free_amplitude {
        mode.free_amplitude_m = a;
    }
}

/// A material of `tapsim contrast` as given on the command line: a name and the inputs
/// that differ from the common setup.
#[derive(Debug, Clone)]
pub struct MaterialSpec {
    /// Name used in tables and legends.
    pub name: String,
    /// Inputs overriding the common ones (contact keys).
    pub inputs: TapInputs,
}

impl MaterialSpec {
    /// The two polymers `tapsim contrast` compares when given none (and `reproduce`'s
    /// phase-contrast figure): A, the `tap` defaults' sample; B, stiffer and less
    /// adhesive.
    pub fn defaults() -> Result<Vec<Self>> {
        [
            "A:sample-modulus=0.5GPa,work-of-adhesion=0.1",
            "B:sample-modulus=1GPa,work-of-adhesion=0.08",
        ]
        .into_iter()
        .map(Self::parse)
        .collect()
    }

    /// Parse `name:key=value,key=value` (keys: the flags' names, values with units),
    /// e.g. `b:sample-modulus=1GPa,work-of-adhesion=0.08`.
    pub fn parse(text: &str) -> Result<Self> {
        let bad = |reason: &str| Error::Parse {
            name: "material",
            text: text.to_string(),
            reason: reason.into(),
        };
        let (name, rest) = text
            .split_once(':')
            .ok_or_else(|| bad("expected name:key=value,key=value"))?;
        if name.trim().is_empty() {
            return Err(bad("the material needs a name before ':'"));
        }
        let mut inputs = TapInputs::default();
        for pair in rest.split(',').filter(|p| !p.trim().is_empty()) {
            let (key, value) = pair
                .split_once('=')
                .ok_or_else(|| bad("each property is key=value"))?;
            inputs.set(key.trim(), value.trim())?;
        }
        Ok(Self {
            name: name.trim().to_string(),
            inputs,
        })
    }

    /// The material's setup and sweep numerics: its inputs over `base`'s.
    pub fn resolve(&self, base: &TapInputs) -> Result<crate::analysis::contrast::Material> {
        let inputs = self.inputs.clone().or(base.clone());
        let (setup, numerics) = inputs.resolve()?;
        Ok(crate::analysis::contrast::Material {
            name: self.name.clone(),
            setup,
            numerics: inputs.sweep_numerics(numerics),
        })
    }
}
