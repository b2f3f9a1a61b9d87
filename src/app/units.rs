//! Reading physical quantities from text: a number with an optional SI unit, such as
//! `10e-9`, `10nm`, `50 MPa`, `0.05J/m^2`, `40 N/m`, `300kHz` or `300K`. A bare number is
//! taken in the base SI unit of the quantity.

use crate::error::{Error, Result};

/// The kinds of quantity tapsim reads, each with its base SI unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dimension {
    /// Metres.
    Length,
    /// Pascals.
    Pressure,
    /// Joules per square metre (also written N/m).
    SurfaceEnergy,
    /// Newtons per metre.
    Stiffness,
    /// Hertz.
    Frequency,
    /// Joules (or electronvolts).
    Energy,
    /// Pascal seconds (written Pa·s, Pa*s, Pa s or Pas).
    Viscosity,
    /// Seconds.
    Time,
    /// Kelvins.
    Temperature,
    /// Newtons.
    Force,
    /// Metres per second.
    Velocity,
    /// A plain number.
    Dimensionless,
}

impl Dimension {
    fn base_units(self) -> &'static [(&'static str, f64)] {
        match self {
            Dimension::Length => &[("m", 1.0)],
            Dimension::Pressure => &[("Pa", 1.0)],
            Dimension::SurfaceEnergy => &[("J/m^2", 1.0), ("J/m2", 1.0), ("N/m", 1.0)],
            Dimension::Stiffness => &[("N/m", 1.0)],
            Dimension::Frequency => &[("Hz", 1.0)],
            Dimension::Energy => &[("J", 1.0), ("eV", crate::physics::params::ELECTRONVOLT_J)],
            Dimension::Viscosity => &[("Pa·s", 1.0), ("Pa*s", 1.0), ("Pa s", 1.0), ("Pas", 1.0)],
            Dimension::Time => &[("s", 1.0)],
            Dimension::Temperature => &[("K", 1.0)],
            Dimension::Force => &[("N", 1.0)],
            Dimension::Velocity => &[("m/s", 1.0)],
            Dimension::Dimensionless => &[],
        }
    }
}

const PREFIXES: &[(&str, f64)] = &[
    ("", 1.0),
    ("f", 1e-15),
    ("p", 1e-12),
    ("n", 1e-9),
    ("u", 1e-6),
    ("µ", 1e-6),
    ("μ", 1e-6),
    ("m", 1e-3),
    ("c", 1e-2),
    ("k", 1e3),
    ("M", 1e6),
    ("G", 1e9),
];

/// The longest text read as a quantity (the number's digits and a unit).
const MAX_QUANTITY_CHARS: usize = 100;

/// Parse `text` as a quantity of dimension `dim`, returning its value in base SI
/// units. `name` names the quantity in error messages. Non-finite values are refused.
pub fn parse(name: &'static str, text: &str, dim: Dimension) -> Result<f64> {
    let err = |reason: String| Error::Parse {
        name,
        text: text.to_string(),
        reason,
    };
    let trimmed = text.trim();
    if trimmed.len() > MAX_QUANTITY_CHARS {
        return Err(err(format!(
            "{} characters is too long for a quantity (at most {MAX_QUANTITY_CHARS})",
            trimmed.chars().count()
        )));
    }
    // The longest leading part that reads as a number (so "1.5eV" is 1.5 and "eV").
    let (number, unit) = (1..=trimmed.len())
        .rev()
        .filter(|&i| trimmed.is_char_boundary(i))
        .find_map(|i| {
            trimmed[..i]
                .trim()
                .parse::<f64>()
                .ok()
                .map(|v| (v, trimmed[i..].trim()))
        })
        .ok_or_else(|| err("expected a number, optionally followed by a unit".into()))?;
    if !number.is_finite() {
        return Err(err("must be a finite number".into()));
    }
    if unit.is_empty() {
        return Ok(number);
    }
    for &(base, base_factor) in dim.base_units() {
        if let Some(prefix) = unit.strip_suffix(base) {
            if let Some(&(_, factor)) = PREFIXES.iter().find(|(p, _)| *p == prefix) {
                return Ok(number * factor * base_factor);
            }
        }
    }
    let known: Vec<&str> = dim.base_units().iter().map(|(u, _)| *u).collect();
    Err(err(if known.is_empty() {
        format!("unexpected unit {unit:?}: this is a plain number")
    } else {
        format!(
            "unknown unit {unit:?}: use {} with an optional prefix (p, n, u, m, k, M, G)",
            known.join(" or ")
        )
    }))
}
