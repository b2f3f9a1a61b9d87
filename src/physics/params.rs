//! SI inputs of a sphere-on-flat adhesive contact, their validation, and the
//! dimensionless groups and scales of the paper: μ (2), β (4), k̂ (22), s₀ (20).

use crate::error::{Error, Result, positive};
use crate::physics::contact::length_scale;
use serde::{Deserialize, Serialize};

/// One electronvolt in joules (exact, SI 2019).
pub const ELECTRONVOLT_J: f64 = 1.602_176_634e-19;

/// A validated sphere-on-flat contact in SI units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Contact {
    /// Tip radius R in m.
    pub radius_m: f64,
    /// Composite modulus E* in Pa.
    pub modulus_pa: f64,
    /// Work of adhesion Δγ in J/m².
    pub work_of_adhesion_j_m2: f64,
    /// Range ε of the Lennard-Jones law (10) (equilibrium gap) in m.
    pub range_m: f64,
}

impl Contact {
    /// Validate and build a contact: every input must be finite and positive.
    pub fn new(
        radius_m: f64,
        modulus_pa: f64,
        work_of_adhesion_j_m2: f64,
        range_m: f64,
    ) -> Result<Self> {
        Ok(Self {
            radius_m: positive("radius", radius_m)?,
            modulus_pa: positive("modulus", modulus_pa)?,
            work_of_adhesion_j_m2: positive("work of adhesion", work_of_adhesion_j_m2)?,
            range_m: positive("range", range_m)?,
        })
    }

    /// Tabor parameter μ = (RΔγ²/E*²)^{1/3}/ε, eq. (2).
    pub fn tabor_mu(&self) -> f64 {
        (self.radius_m * self.work_of_adhesion_j_m2.powi(2) / self.modulus_pa.powi(2)).cbrt()
            / self.range_m
    }

    /// β = (E*R/Δγ)^{1/3} = √(R/(με)), eq. (4).
    pub fn beta(&self) -> f64 {
        (self.modulus_pa * self.radius_m / self.work_of_adhesion_j_m2).cbrt()
    }

    /// Force scale RΔγ in N (T̂ = T/(RΔγ), eq. (3)).
    pub fn force_scale_n(&self) -> f64 {
        self.radius_m * self.work_of_adhesion_j_m2
    }

    /// Separation scale με = R/β² in m (α̂ = α/(με), eq. (3)).
    pub fn separation_scale_m(&self) -> f64 {
        self.tabor_mu() * self.range_m
    }

    /// Contact-radius scale R/β in m (â = βa/R, eq. (3)).
    pub fn contact_radius_scale_m(&self) -> f64 {
        self.radius_m / self.beta()
    }

    /// Energy scale μεRΔγ in J (Ŵ = W/(μεRΔγ), eq. (6)).
    pub fn energy_scale_j(&self) -> f64 {
        self.separation_scale_m() * self.force_scale_n()
    }

    /// Dimensionless support stiffness k̂ = μεk/(RΔγ), eq. (22), for k in N/m.
    pub fn k_hat(&self, stiffness_n_m: f64) -> Result<f64> {
        positive("stiffness", stiffness_n_m)?;
        Ok(self.separation_scale_m() * stiffness_n_m / self.force_scale_n())
    }

    /// Adhesive length scale s₀ = E*ε²/(πΔγ) in m, eq. (20).
    pub fn s0_m(&self) -> f64 {
        length_scale::s0_m(self.modulus_pa, self.range_m, self.work_of_adhesion_j_m2)
    }
}

/// Composite modulus 1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂ in Pa, from the Young's moduli
/// (Pa) and Poisson ratios of tip and sample.
pub fn composite_modulus(
    tip_modulus_pa: f64,
    tip_poisson: f64,
    sample_modulus_pa: f64,
    sample_poisson: f64,
) -> Result<f64> {
    positive("tip modulus", tip_modulus_pa)?;
    positive("sample modulus", sample_modulus_pa)?;
    for (name, nu) in [
        ("tip Poisson ratio", tip_poisson),
        ("sample Poisson ratio", sample_poisson),
    ] {
        if !(nu > -1.0 && nu <= 0.5) {
            return Err(Error::InvalidParameter {
                name,
                value: nu,
                reason: "must lie in (-1, 0.5]",
            });
        }
    }
    let compliance = (1.0 - tip_poisson * tip_poisson) / tip_modulus_pa
        + (1.0 - sample_poisson * sample_poisson) / sample_modulus_pa;
    Ok(1.0 / compliance)
}

/// Validate a Tabor parameter given directly.
pub fn tabor_mu(value: f64) -> Result<f64> {
    positive("Tabor parameter mu", value)
}

/// Validate a dimensionless support stiffness k̂ given directly.
pub fn k_hat(value: f64) -> Result<f64> {
    positive("k_hat", value)
}
