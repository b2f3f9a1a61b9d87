//! SI description of a tapping-mode experiment — cantilever, contact, rest separation and
//! force law — and its translation into the dimensionless [`Simulation`].

use super::budget;
use super::grazing::{ROOM_TEMPERATURE_K, thermal_rms_m};
use super::march::Simulation;
use super::model::{Coupling, Drive, Oscillator};
use super::numeric::Tolerances;
use super::steady::{MARCHING_TOLERANCE, MIN_CYCLES, SteadyOptions};
use crate::error::{Error, Result, finite, positive};
use crate::physics::law::{AnyLaw, LawKind, LawSpec};
use crate::physics::params::{Contact, composite_modulus};
use serde::{Deserialize, Serialize};

/// A cantilever in SI units, driven by a force at `drive_frequency_hz` whose strength
/// gives the free amplitude A₀ at that frequency.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Cantilever {
    /// Spring constant k in N/m.
    pub stiffness_n_m: f64,
    /// Resonance frequency f₀ in Hz.
    pub resonance_hz: f64,
    /// Quality factor Q.
    pub quality: f64,
    /// Free amplitude A₀ in m.
    pub free_amplitude_m: f64,
    /// Drive frequency in Hz.
    pub drive_frequency_hz: f64,
}

impl Cantilever {
    /// Validate: every value finite and positive.
    pub fn validated(self) -> Result<Self> {
        positive("stiffness", self.stiffness_n_m)?;
        positive("resonance frequency", self.resonance_hz)?;
        positive("quality factor", self.quality)?;
        positive("free amplitude", self.free_amplitude_m)?;
        positive("drive frequency", self.drive_frequency_hz)?;
        Ok(self)
    }

    /// Drive frequency over resonance, Ω = ω/ω₀.
    pub fn omega_ratio(&self) -> f64 {
        self.drive_frequency_hz / self.resonance_hz
    }

    /// Drive amplitude F₀/(kA₀) that gives the free amplitude A₀ at the drive frequency:
    /// √((1 − Ω²)² + (Ω/Q)²).
    pub fn drive_over_k_a0(&self) -> f64 {
        let w = self.omega_ratio();
        ((1.0 - w * w).powi(2) + (w / self.quality).powi(2)).sqrt()
    }
}

/// A complete tapping experiment in SI units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TapSetup {
    /// The tip–sample contact.
    pub contact: Contact,
    /// The cantilever.
    pub cantilever: Cantilever,
    /// Rest separation z_c in m (α = z_c + z).
    pub separation_m: f64,
    /// Tip–sample force law, with its own parameters.
    pub law: LawSpec,
}

/// Built-in defaults: a silicon tapping cantilever (k = 40 N/m, f₀ = 300 kHz, Q = 400,
/// A₀ = 20 nm, driven at resonance) with a 20 nm silicon tip (E = 169 GPa, ν = 0.28) on
/// a soft polymer (E = 0.5 GPa, ν = 0.4), Δγ = 0.1 J/m², ε = 0.3 nm, at rest separation
/// z_c = 16 nm; hybrid law. Tabor parameter μ ≈ 2.8.
pub fn default_setup() -> TapSetup {
    let modulus = composite_modulus(169e9, 0.28, 0.5e9, 0.4).expect("valid defaults");
    TapSetup {
        contact: Contact::new(20e-9, modulus, 0.1, 0.3e-9).expect("valid defaults"),
        cantilever: Cantilever {
            stiffness_n_m: 40.0,
            resonance_hz: 300e3,
            quality: 400.0,
            free_amplitude_m: 20e-9,
            drive_frequency_hz: 300e3,
        },
        separation_m: 16e-9,
        law: LawKind::Hybrid.into(),
    }
}

/// Integrator and steady-state settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Numerics {
    /// Relative tolerance of Dopri5.
    pub rtol: f64,
    /// Absolute tolerance of Dopri5 (units of A₀).
    pub atol: f64,
    /// Steps per drive period at most.
    pub min_steps_per_period: f64,
    /// Periodic orbits: the largest |Pⁿ(z) − z| accepted, in units of A₀ (Newton aims
    /// 100× lower); time-marching: how close to the orbit the state must be.
    pub tolerance: f64,
    /// Irregular motion: the standard error its averages must reach (A relative, φ in
    /// rad, E_ts relative to E_drive).
    pub average_tolerance: f64,
    /// Cycles at most.
    pub max_cycles: usize,
    /// Look for periodic orbits by Newton's method on the period map (else only
    /// integrate).
    pub shooting: bool,
    /// The work budget of one steady state, in integrator steps (see
    /// [`super::budget`]).
    pub max_steps: u64,
}

impl Default for Numerics {
    fn default() -> Self {
        Self {
            rtol: 1e-9,
            atol: 1e-11,
            min_steps_per_period: 40.0,
            tolerance: 1e-9,
            average_tolerance: 1e-3,
            max_cycles: 20_000,
            shooting: true,
            max_steps: budget::STEPS,
        }
    }
}

impl Numerics {
    /// Validate the settings.
    pub fn validated(self) -> Result<Self> {
        positive("rtol", self.rtol)?;
        positive("atol", self.atol)?;
        positive("steps per period", self.min_steps_per_period)?;
        positive("convergence tolerance", self.tolerance)?;
        positive("average tolerance", self.average_tolerance)?;
        let round_off = "near round-off the integration cannot meet it";
        Range {
            what: "relative tolerance rtol",
            unit: "",
            lo: 1e-13,
            hi: 1e-3,
            why: round_off,
            meant: None,
        }
        .check(self.rtol)?;
        Range {
            what: "periodic-orbit tolerance",
            unit: "",
            lo: 1e-12,
            hi: 1e-2,
            why: round_off,
            meant: None,
        }
        .check(self.tolerance)?;
        Range {
            what: "average tolerance",
            unit: "",
            lo: 1e-6,
            hi: 0.5,
            why: "a standard error below 1e-6 would take billions of periods",
            meant: None,
        }
        .check(self.average_tolerance)?;
        if self.max_cycles < MIN_CYCLES {
            return Err(Error::InvalidParameter {
                name: "max cycles",
                value: self.max_cycles as f64,
                reason: "must be at least 32: classifying the steady state and averaging \
                         irregular motion need that many periods",
            });
        }
        Ok(self)
    }
}

/// `value` to four significant digits, without trailing zeros: 0.5, 1e-13, 3.333e-6.
#[doc(hidden)]
pub fn significant(value: f64) -> String {
    let magnitude = value.abs();
    if magnitude == 0.0 {
        "0".into()
    } else if (1e-3..1e5).contains(&magnitude) {
        let decimals = (3 - magnitude.log10().floor() as i32).clamp(0, 6) as usize;
        let text = format!("{value:.decimals$}");
        if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').into()
        } else {
            text
        }
    } else {
        let text = format!("{value:.3e}");
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        format!("{mantissa}e{exponent}")
    }
}

/// `value` with an SI prefix where it has a unit: 2e-8 m → "20 nm".
#[doc(hidden)]
pub fn with_prefix(value: f64, unit: &str) -> String {
    const PREFIXES: [(f64, &str); 9] = [
        (1e12, "T"),
        (1e9, "G"),
        (1e6, "M"),
        (1e3, "k"),
        (1.0, ""),
        (1e-3, "m"),
        (1e-6, "µ"),
        (1e-9, "n"),
        (1e-12, "p"),
    ];
    if unit.is_empty() {
        return significant(value);
    }
    let magnitude = value.abs();
    match PREFIXES.iter().find(|(f, _)| magnitude >= *f * 0.999_999) {
        Some((f, p)) if magnitude < 1e15 => format!("{} {p}{unit}", significant(value / f)),
        _ => format!("{} {unit}", significant(value)),
    }
}

/// A quantity of a tapping experiment and the range tapsim accepts it in: wide enough
/// for every AFM, narrow enough that a computation ends within seconds and a bare number
/// meant in nm or GPa is caught.
struct Range {
    what: &'static str,
    unit: &'static str,
    lo: f64,
    hi: f64,
    /// Who lives at the ends of the range.
    why: &'static str,
    /// The unit a user most likely meant with a bare number, and its factor.
    meant: Option<(&'static str, f64)>,
}

impl Range {
    fn check(&self, value: f64) -> Result<()> {
        if (self.lo..=self.hi).contains(&value) {
            return Ok(());
        }
        let mut message = format!(
            "{} = {} is outside {} to {} ({})",
            self.what,
            with_prefix(value, self.unit),
            with_prefix(self.lo, self.unit),
            with_prefix(self.hi, self.unit),
            self.why
        );
        if let Some((unit, factor)) = self.meant {
            if (self.lo..=self.hi).contains(&(value * factor)) {
                message += &format!(
                    "; bare numbers are in {}: did you mean {value}{unit}?",
                    self.unit
                );
            }
        }
        Err(Error::OutOfRange(message))
    }
}

/// The rest separations tapsim accepts for free amplitude `a0_m`: −10 A₀ to 1000 A₀.
fn separation_in_range(separation_m: f64, a0_m: f64) -> Result<()> {
    finite("separation", separation_m)?;
    if (-10.0 * a0_m..=1000.0 * a0_m).contains(&separation_m) {
        return Ok(());
    }
    Err(Error::OutOfRange(format!(
        "rest separation z_c = {} is outside −10 A₀ to 1000 A₀ ({} to {}): farther the tip \
         never reaches the sample, deeper it indents far beyond where the contact models hold",
        with_prefix(separation_m, "m"),
        with_prefix(-10.0 * a0_m, "m"),
        with_prefix(1000.0 * a0_m, "m")
    )))
}

impl TapSetup {
    /// Refuse values outside what an AFM can be (SI slips like `--radius 20`, meaning
    /// 20 m) and regimes tapsim cannot resolve within seconds; the message explains.
    #[doc(hidden)]
    pub fn check_plausible(&self) -> Result<()> {
        let (c, k) = (&self.contact, &self.cantilever);
        let length = |what, lo, hi, why| Range {
            what,
            unit: "m",
            lo,
            hi,
            why,
            meant: Some(("nm", 1e-9)),
        };
        length(
            "tip radius R",
            0.5e-9,
            50e-6,
            "from the sharpest tips to colloidal probes",
        )
        .check(c.radius_m)?;
        length(
            "range ε",
            0.05e-9,
            5e-9,
            "the equilibrium gap of surface forces, a fraction of a nm",
        )
        .check(c.range_m)?;
        length(
            "free amplitude A₀",
            0.05e-9,
            10e-6,
            "from sub-nm small-amplitude work to the largest tapping amplitudes",
        )
        .check(k.free_amplitude_m)?;
        Range {
            what: "composite modulus E*",
            unit: "Pa",
            lo: 1e3,
            hi: 2e12,
            why: "from living cells to diamond",
            meant: Some(("GPa", 1e9)),
        }
        .check(c.modulus_pa)?;
        Range {
            what: "work of adhesion Δγ",
            unit: "J/m²",
            lo: 1e-5,
            hi: 10.0,
            why: "from weak van der Waals contacts in liquid to clean metals",
            meant: Some(("mJ/m^2", 1e-3)),
        }
        .check(c.work_of_adhesion_j_m2)?;
        Range {
            what: "stiffness k",
            unit: "N/m",
            lo: 1e-3,
            hi: 1e4,
            why: "from the softest contact-mode cantilevers to the stiffest sensors; far \
                  softer than the contact, the motion is too stiff to resolve",
            meant: None,
        }
        .check(k.stiffness_n_m)?;
        Range {
            what: "resonance frequency f₀",
            unit: "Hz",
            lo: 1e3,
            hi: 1e8,
            why: "the range of AFM cantilevers, from soft levers in liquid up",
            meant: Some(("kHz", 1e3)),
        }
        .check(k.resonance_hz)?;
        Range {
            what: "quality factor Q",
            unit: "",
            lo: 0.5,
            hi: 1e7,
            why: "from critical damping, below which the cantilever has no resonance to tap \
                  with, to the best cantilevers in vacuum",
            meant: None,
        }
        .check(k.quality)?;
        Range {
            what: "drive frequency over resonance f/f₀",
            unit: "",
            lo: 0.05,
            hi: 20.0,
            why: "tapping mode drives near resonance; far from it, a drive period spans \
                  many free oscillations or a small part of one",
            meant: None,
        }
        .check(k.omega_ratio())?;
        separation_in_range(self.separation_m, k.free_amplitude_m)?;
        for (param, value) in self.law.params() {
            if let Some(value) = value {
                let (lo, hi, why) = param.range;
                Range {
                    what: param.name,
                    unit: param.unit,
                    lo,
                    hi,
                    why,
                    meant: None,
                }
                .check(value)?;
            }
        }
        self.law.check()?;
        Ok(())
    }
}

/// A setup made ready to integrate.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The validated setup.
    pub setup: TapSetup,
    /// The force law.
    pub law: AnyLaw,
    /// The oscillator.
    pub osc: Oscillator,
    /// Coupling to the contact.
    pub cpl: Coupling,
    /// Integrator settings.
    pub tol: Tolerances,
    /// Steady-state settings.
    pub steady: SteadyOptions,
}

impl Prepared {
    /// Validate `setup` and build the law and the dimensionless model.
    pub fn new(setup: &TapSetup, numerics: &Numerics) -> Result<Self> {
        let cantilever = setup.cantilever.validated()?;
        let numerics = numerics.validated()?;
        let c = Contact::new(
            setup.contact.radius_m,
            setup.contact.modulus_pa,
            setup.contact.work_of_adhesion_j_m2,
            setup.contact.range_m,
        )?;
        setup.check_plausible()?;
        let law = AnyLaw::new(&setup.law, &c, cantilever.resonance_hz)?;
        let osc = Oscillator {
            gamma: 0.5 / cantilever.quality,
            omega: cantilever.omega_ratio(),
            drive: Drive::Force {
                amplitude: cantilever.drive_over_k_a0(),
            },
            bias: 0.0,
        };
        let a0_m = cantilever.free_amplitude_m;
        let cpl = Coupling {
            a0: setup.separation_m / c.separation_scale_m(),
            a1: a0_m / c.separation_scale_m(),
            f_scale: c.force_scale_n() / (cantilever.stiffness_n_m * a0_m),
        };
        let tol = Tolerances {
            rtol: numerics.rtol,
            atol: numerics.atol,
            h_max: osc.period() / numerics.min_steps_per_period,
        };
        let steady = SteadyOptions {
            tolerance: numerics.tolerance,
            average_tolerance: numerics.average_tolerance,
            max_cycles: numerics.max_cycles,
            shooting: numerics.shooting,
            max_steps: numerics.max_steps,
            marching_fraction: MARCHING_TOLERANCE,
            grazing_threshold: thermal_rms_m(cantilever.stiffness_n_m, ROOM_TEMPERATURE_K) / a0_m,
        };
        Ok(Self {
            setup: TapSetup {
                contact: c,
                cantilever,
                ..setup.clone()
            },
            law,
            osc,
            cpl,
            tol,
            steady,
        })
    }

    /// The simulation over this setup.
    pub fn simulation(&self) -> Simulation<'_, AnyLaw> {
        Simulation {
            law: &self.law,
            osc: self.osc,
            cpl: self.cpl,
            tol: self.tol,
        }
    }

    /// The simulation driven at Ω = `omega` with the force amplitude `drive` (units of
    /// kA₀), its step bound h_max taken from that drive period as [`Prepared::new`]
    /// takes it from its own: the experiment at another drive without building the law
    /// again (FM's loops move both every period).
    pub fn simulation_driven(&self, omega: f64, drive: f64) -> Simulation<'_, AnyLaw> {
        let mut sim = self.simulation();
        sim.osc.omega = omega;
        sim.osc.drive = Drive::Force { amplitude: drive };
        sim.tol.h_max = self.tol.h_max * self.osc.omega / omega;
        sim
    }

    /// The simulation with the rest separation moved to `separation_m` (a sweep step).
    pub(crate) fn simulation_at(&self, separation_m: f64) -> Result<Simulation<'_, AnyLaw>> {
        separation_in_range(separation_m, self.setup.cantilever.free_amplitude_m)?;
        let mut sim = self.simulation();
        sim.cpl.a0 = separation_m / self.setup.contact.separation_scale_m();
        Ok(sim)
    }
}
