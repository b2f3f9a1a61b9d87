//! Command-line arguments shared by several subcommands.

use crate::error::{Error, Result};
use crate::params::{self, Contact};
use crate::units::{self, Dimension};
use clap::Args;

fn quantity(
    name: &'static str,
    dim: Dimension,
) -> impl Fn(&str) -> std::result::Result<f64, String> + Clone {
    move |s| units::parse(name, s, dim).map_err(|e| e.to_string())
}

pub fn length(s: &str) -> std::result::Result<f64, String> {
    quantity("length", Dimension::Length)(s)
}
pub fn pressure(s: &str) -> std::result::Result<f64, String> {
    quantity("modulus", Dimension::Pressure)(s)
}
pub fn surface_energy(s: &str) -> std::result::Result<f64, String> {
    quantity("work of adhesion", Dimension::SurfaceEnergy)(s)
}
pub fn stiffness(s: &str) -> std::result::Result<f64, String> {
    quantity("stiffness", Dimension::Stiffness)(s)
}
pub fn number(s: &str) -> std::result::Result<f64, String> {
    quantity("value", Dimension::Dimensionless)(s)
}

/// A sphere-on-flat contact in SI units.
#[derive(Debug, Clone, Args)]
pub struct ContactArgs {
    /// Tip radius R [m; e.g. 10nm].
    #[arg(long, allow_hyphen_values = true, value_parser = length, help_heading = "Contact (SI)")]
    pub radius: Option<f64>,
    /// Composite modulus E* [Pa; e.g. 1GPa]. Or give --tip-modulus/--sample-modulus.
    #[arg(long, allow_hyphen_values = true, value_parser = pressure, help_heading = "Contact (SI)",
          conflicts_with_all = ["tip_modulus", "sample_modulus"])]
    pub modulus: Option<f64>,
    /// Young's modulus of the tip [Pa; e.g. 169GPa for silicon].
    #[arg(long, allow_hyphen_values = true, value_parser = pressure, requires = "sample_modulus", help_heading = "Contact (SI)")]
    pub tip_modulus: Option<f64>,
    /// Poisson ratio of the tip.
    #[arg(long, allow_hyphen_values = true, value_parser = number, default_value_t = 0.28, help_heading = "Contact (SI)")]
    pub tip_poisson: f64,
    /// Young's modulus of the sample [Pa; e.g. 1GPa].
    #[arg(long, allow_hyphen_values = true, value_parser = pressure, requires = "tip_modulus", help_heading = "Contact (SI)")]
    pub sample_modulus: Option<f64>,
    /// Poisson ratio of the sample.
    #[arg(long, allow_hyphen_values = true, value_parser = number, default_value_t = 0.4, help_heading = "Contact (SI)")]
    pub sample_poisson: f64,
    /// Work of adhesion Δγ [J/m²; e.g. 50mJ/m^2].
    #[arg(long, allow_hyphen_values = true, value_parser = surface_energy, help_heading = "Contact (SI)")]
    pub work_of_adhesion: Option<f64>,
    /// Range ε of the Lennard-Jones law (10), the equilibrium gap [m; e.g. 0.3nm].
    #[arg(long, allow_hyphen_values = true, value_parser = length, help_heading = "Contact (SI)")]
    pub range: Option<f64>,
}

impl ContactArgs {
    /// Whether any SI contact input was given.
    pub fn any(&self) -> bool {
        self.radius.is_some()
            || self.modulus.is_some()
            || self.tip_modulus.is_some()
            || self.work_of_adhesion.is_some()
            || self.range.is_some()
    }

    /// The validated contact; an error naming what is missing.
    pub fn contact(&self) -> Result<Contact> {
        let missing = |what: &str| {
            Error::NotApplicable(format!(
                "the SI contact needs {what} (give --radius, --modulus or \
                 --tip-modulus/--sample-modulus, --work-of-adhesion and --range)"
            ))
        };
        let modulus = match (self.modulus, self.tip_modulus, self.sample_modulus) {
            (Some(e), _, _) => e,
            (None, Some(tip), Some(sample)) => {
                params::composite_modulus(tip, self.tip_poisson, sample, self.sample_poisson)?
            }
            _ => return Err(missing("--modulus")),
        };
        Contact::new(
            self.radius.ok_or_else(|| missing("--radius"))?,
            modulus,
            self.work_of_adhesion
                .ok_or_else(|| missing("--work-of-adhesion"))?,
            self.range.ok_or_else(|| missing("--range"))?,
        )
    }
}
