//! The point-mass cantilever in dimensionless form (DESIGN.md §2).
//!
//! Time τ = ω₀t, deflection x = z/L for a length unit L (the free amplitude A₀ in tapping),
//! forces in units of kL, energies in units of kL². The equation of motion
//!
//!   x'' + 2γx' + x = f_ts + f_drive(τ),   γ = 1/(2Q),
//!
//! with f_ts = −T̂·RΔγ/(kL) and the tip–sample separation α̂ = a₀ + a₁(x + x_b(τ)),
//! where x_b is the support displacement of a base drive (zero for a force drive).

use crate::law::{Branch, ForceLaw};
use nalgebra::SVector;

/// ODE state: deflection, velocity, the per-cycle integrals carried along, and the drive
/// phasor (cos Ωτ, sin Ωτ), integrated as a rotation so the right-hand side needs no
/// trigonometric calls (it is reset to the exact values at every segment start).
pub type State = SVector<f64, 11>;

/// Index of the deflection x in [`State`].
pub const X: usize = 0;
/// Velocity x'.
pub const V: usize = 1;
/// Energy dissipated in the contact, ∫ −f_ts dα (in units of kL²).
pub const E_TS: usize = 2;
/// Energy dissipated by damping, ∫ 2γ x'² dτ.
pub const E_DAMP: usize = 3;
/// Energy put in by the drive.
pub const E_DRIVE: usize = 4;
/// Fourier projection ∫ x cos Ωτ dτ.
pub const SC: usize = 5;
/// Fourier projection ∫ x sin Ωτ dτ.
pub const SS: usize = 6;
/// ∫ f_ts dτ (mean force).
pub const F_INT: usize = 7;
/// ∫ f_ts x dτ (virial).
pub const VIRIAL: usize = 8;
/// cos Ωτ.
pub const COS: usize = 9;
/// sin Ωτ.
pub const SIN: usize = 10;

/// Set the drive phasor of `y` to its exact value at τ.
#[inline]
pub fn set_phasor(osc: &Oscillator, tau: f64, y: &mut State) {
    let (s, c) = (osc.omega * tau).sin_cos();
    y[COS] = c;
    y[SIN] = s;
}

/// How the cantilever is driven.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Drive {
    /// A force f₀ cos Ωτ on the tip (acoustic/dither drive as in tapping mode).
    Force {
        /// Amplitude f₀ in units of kL.
        amplitude: f64,
    },
    /// The support moves as x_b = b cos Ωτ (slow force–distance cycles).
    Base {
        /// Amplitude b in units of L.
        amplitude: f64,
    },
}

/// The oscillator: damping, drive frequency and drive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Oscillator {
    /// γ = 1/(2Q).
    pub gamma: f64,
    /// Ω = ω/ω₀.
    pub omega: f64,
    /// The drive.
    pub drive: Drive,
}

impl Oscillator {
    /// Drive period in τ.
    pub fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.omega
    }

    /// Whether free motion is underdamped enough for the closed form (Q > 0.55).
    pub fn underdamped(&self) -> bool {
        self.gamma < 0.9
    }

    /// Support displacement and velocity (x_b, x_b') at τ; no trigonometry for a force
    /// drive.
    #[inline]
    pub fn base_at(&self, tau: f64) -> (f64, f64) {
        match self.drive {
            Drive::Force { .. } => (0.0, 0.0),
            Drive::Base { amplitude } => {
                let (s, c) = (self.omega * tau).sin_cos();
                (amplitude * c, -amplitude * self.omega * s)
            }
        }
    }

    /// Drive force f_drive and support displacement and velocity (x_b, x_b') from
    /// (sin Ωτ, cos Ωτ).
    #[inline]
    pub fn drive_from(&self, (s, c): (f64, f64)) -> (f64, f64, f64) {
        match self.drive {
            Drive::Force { amplitude } => (amplitude * c, 0.0, 0.0),
            Drive::Base { amplitude } => (0.0, amplitude * c, -amplitude * self.omega * s),
        }
    }
}

/// Coupling of the cantilever to the contact: α̂ = a₀ + a₁(x + x_b), f_ts = −f_scale·T̂.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coupling {
    /// z_c/(με): rest separation in the contact's units.
    pub a0: f64,
    /// L/(με).
    pub a1: f64,
    /// RΔγ/(kL).
    pub f_scale: f64,
}

impl Coupling {
    /// Separation α̂ for deflection `x` and support displacement `x_b`.
    #[inline]
    pub fn alpha_hat(&self, x: f64, x_b: f64) -> f64 {
        self.a0 + self.a1 * (x + x_b)
    }

    /// Deflection at which α̂ equals `alpha_hat` (without base displacement).
    #[inline]
    pub fn x_at(&self, alpha_hat: f64) -> f64 {
        (alpha_hat - self.a0) / self.a1
    }
}

/// The right-hand side of the equation of motion and of the carried integrals.
#[inline]
pub fn rhs<L: ForceLaw>(
    law: &L,
    osc: &Oscillator,
    cpl: &Coupling,
    branch: Branch,
    tau: f64,
    y: &State,
    dy: &mut State,
) {
    let _ = tau;
    let (x, v) = (y[X], y[V]);
    let (s, c) = (y[SIN], y[COS]);
    let (drive, x_b, v_b) = osc.drive_from((s, c));
    let f = -cpl.f_scale * law.t_hat(cpl.alpha_hat(x, x_b), branch);
    dy[X] = v;
    dy[V] = -2.0 * osc.gamma * v - x + f + drive;
    dy[E_TS] = -f * (v + v_b);
    dy[E_DAMP] = 2.0 * osc.gamma * v * v;
    dy[E_DRIVE] = drive * v - f * v_b;
    dy[SC] = x * c;
    dy[SS] = x * s;
    dy[F_INT] = f;
    dy[VIRIAL] = f * x;
    dy[COS] = -osc.omega * s;
    dy[SIN] = osc.omega * c;
}
