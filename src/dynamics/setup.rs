//! SI description of a tapping-mode experiment — cantilever, contact, rest separation and
//! force law — and its translation into the dimensionless [`Simulation`].

use super::model::{Coupling, Drive, Oscillator};
use super::numeric::Tolerances;
use super::steady::{MIN_CYCLES, Simulation, SteadyOptions};
use crate::error::{Error, Result, finite, positive};
use crate::law::{AnyLaw, LawKind};
use crate::params::{Contact, composite_modulus};
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
    /// Tip–sample force law.
    pub law: LawKind,
    /// Hamaker constant for the DMT law in J (default 12πε²Δγ).
    pub hamaker_j: Option<f64>,
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
        law: LawKind::Hybrid,
        hamaker_j: None,
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
        finite("separation", setup.separation_m)?;
        let law = AnyLaw::new(setup.law, &c, setup.hamaker_j)?;
        let osc = Oscillator {
            gamma: 0.5 / cantilever.quality,
            omega: cantilever.omega_ratio(),
            drive: Drive::Force {
                amplitude: cantilever.drive_over_k_a0(),
            },
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

    /// The simulation with the rest separation moved to `separation_m` (a sweep step).
    pub fn simulation_at(&self, separation_m: f64) -> Result<Simulation<'_, AnyLaw>> {
        finite("separation", separation_m)?;
        let mut sim = self.simulation();
        sim.cpl.a0 = separation_m / self.setup.contact.separation_scale_m();
        Ok(sim)
    }
}
