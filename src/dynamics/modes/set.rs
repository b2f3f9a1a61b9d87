//! The cantilever's eigenmodes in SI units, the rectangular-beam defaults, and the
//! dimensionless model they make with the first mode's units (docs/src/explanation/design.md §2b).

use crate::dynamics::setup::Cantilever;
use crate::error::{Error, Result, positive};
use serde::{Deserialize, Serialize};

/// The first roots βᵢ of cos β cosh β = −1: a clamped–free Euler–Bernoulli beam's modes
/// have fᵢ ∝ βᵢ² (Rao, Vibration of Continuous Systems, §11.5).
pub const EULER_BERNOULLI_ROOTS: [f64; 3] = [
    1.875_104_068_711_961,
    4.694_091_132_974_175,
    7.854_757_438_237_613,
];

/// Most eigenmodes simulated together.
pub const MAX_MODES: usize = EULER_BERNOULLI_ROOTS.len();

/// A higher eigenmode (the second, third) in SI units, driven at its own resonance.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Eigenmode {
    /// Modal spring constant kᵢ in N/m.
    pub stiffness_n_m: f64,
    /// Resonance frequency fᵢ in Hz.
    pub resonance_hz: f64,
    /// Quality factor Qᵢ.
    pub quality: f64,
    /// Free amplitude A₀ᵢ in m, at resonance (0: the mode is not driven).
    pub free_amplitude_m: f64,
}

impl Eigenmode {
    /// Mode `n` (2 or 3) of a rectangular beam whose first mode is `first`: fₙ =
    /// f₁(βₙ/β₁)², kₙ = k₁(fₙ/f₁)² (equal modal masses), Qₙ = Q₁ fₙ/f₁ (damping by the
    /// surrounding fluid, whose force grows with the velocity at a fixed drag
    /// coefficient), driven to a free amplitude of A₀₁/40.
    pub fn euler_bernoulli(first: &Cantilever, n: usize) -> Result<Self> {
        if !(2..=MAX_MODES).contains(&n) {
            return Err(Error::OutOfRange(format!(
                "a cantilever has modes 2 to {MAX_MODES} here, not {n}"
            )));
        }
        let ratio = (EULER_BERNOULLI_ROOTS[n - 1] / EULER_BERNOULLI_ROOTS[0]).powi(2);
        Ok(Self {
            stiffness_n_m: first.stiffness_n_m * ratio * ratio,
            resonance_hz: first.resonance_hz * ratio,
            quality: first.quality * ratio,
            free_amplitude_m: first.free_amplitude_m / 40.0,
        })
    }

    /// Validate: stiffness, frequency and Q positive, the amplitude finite and ≥ 0.
    pub fn validated(self) -> Result<Self> {
        positive("mode stiffness", self.stiffness_n_m)?;
        positive("mode resonance frequency", self.resonance_hz)?;
        positive("mode quality factor", self.quality)?;
        if !(self.free_amplitude_m.is_finite() && self.free_amplitude_m >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "mode free amplitude",
                value: self.free_amplitude_m,
                reason: "must be finite and at least 0",
            });
        }
        Ok(self)
    }
}

/// Default relative tolerance within which a higher mode's frequency is moved to a
/// rational multiple of the first mode's drive frequency.
pub const RATIO_TOLERANCE: f64 = 5e-3;

/// The highest resonance of a higher mode, in first-mode drive frequencies.
pub const MAX_RATIO: f64 = 100.0;

/// Largest common denominator tried (the common period, in first-mode drive periods).
pub const MAX_DENOMINATOR: u32 = 32;

/// The higher modes of a simulation (the first is the [`Cantilever`]) and how their
/// frequencies are made commensurate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModeSet {
    /// Modes 2, 3 (none: the one-mode model).
    pub higher: Vec<Eigenmode>,
    /// The relative tolerance of the rational approximation of fᵢ/f_drive,1.
    pub ratio_tolerance: f64,
}

impl ModeSet {
    /// `count` modes of a rectangular beam ([`Eigenmode::euler_bernoulli`]).
    pub fn euler_bernoulli(first: &Cantilever, count: usize) -> Result<Self> {
        if !(1..=MAX_MODES).contains(&count) {
            return Err(Error::OutOfRange(format!(
                "1 to {MAX_MODES} eigenmodes are simulated, not {count}"
            )));
        }
        Ok(Self {
            higher: (2..=count)
                .map(|n| Eigenmode::euler_bernoulli(first, n))
                .collect::<Result<_>>()?,
            ratio_tolerance: RATIO_TOLERANCE,
        })
    }

    /// Number of modes, the first included.
    pub fn count(&self) -> usize {
        1 + self.higher.len()
    }
}

/// The smallest denominator q ≤ [`MAX_DENOMINATOR`] with every ratio rᵢ within
/// `tolerance`·rᵢ of some pᵢ/q, and those pᵢ (Stern–Brocot would find each ratio's best
/// approximations; one common q is what a common period needs, and q ≤ 32 is few enough
/// to try in turn).
pub fn common_denominator(ratios: &[f64], tolerance: f64) -> Option<(u32, Vec<u32>)> {
    (1..=MAX_DENOMINATOR).find_map(|q| {
        let p: Vec<u32> = ratios
            .iter()
            .map(|r| (r * f64::from(q)).round().max(1.0) as u32)
            .collect();
        ratios
            .iter()
            .zip(&p)
            .all(|(r, &p)| (f64::from(p) / f64::from(q) - r).abs() <= tolerance * r)
            .then_some((q, p))
    })
}

/// One mode of the dimensionless model, in the first mode's units (τ = ω₁t, lengths A₀₁,
/// forces k₁A₀₁): q″ + (rᵢ/Qᵢ)q′ + rᵢ²q = cᵢ(f_ts + fᵢ cos Ωᵢτ), cᵢ = rᵢ²k₁/kᵢ (the
/// inverse modal mass).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeModel {
    /// rᵢ = ωᵢ/ω₁.
    pub r: f64,
    /// Damping rᵢ/Qᵢ.
    pub damping: f64,
    /// cᵢ = rᵢ²k₁/kᵢ.
    pub gain: f64,
    /// Drive frequency Ωᵢ = ω_dᵢ/ω₁.
    pub omega: f64,
    /// Drive amplitude fᵢ (units of k₁A₀₁).
    pub drive: f64,
}

impl ModeModel {
    /// Qᵢ = rᵢ/(rᵢ/Qᵢ).
    pub fn quality(&self) -> f64 {
        self.r / self.damping
    }

    /// The free amplitude at the drive (units of A₀₁): cᵢfᵢ/|rᵢ² − Ωᵢ² + i rᵢΩᵢ/Qᵢ|.
    pub fn free_amplitude(&self) -> f64 {
        self.gain * self.drive
            / (self.r * self.r - self.omega * self.omega).hypot(self.damping * self.omega)
    }

    /// Mode with resonance ratio `r`, quality `q`, stiffness ratio kᵢ/k₁, driven at
    /// `omega` to a free amplitude `free` (units of A₀₁): the drive that gives it,
    /// fᵢ = free·|rᵢ² − Ωᵢ² + i rᵢΩᵢ/Qᵢ|/cᵢ.
    pub fn new(r: f64, quality: f64, stiffness_ratio: f64, omega: f64, free: f64) -> Self {
        let gain = r * r / stiffness_ratio;
        let response = (r * r - omega * omega).hypot(r * omega / quality);
        Self {
            r,
            damping: r / quality,
            gain,
            omega,
            drive: free * response / gain,
        }
    }
}

/// The modes made dimensionless and commensurate.
#[derive(Debug, Clone, PartialEq)]
pub struct Modal {
    /// Every mode, the first first.
    pub modes: Vec<ModeModel>,
    /// The common period in first-mode drive periods (the common denominator q); none
    /// where the drives have no common period (window averages only).
    pub periods: Option<u32>,
    /// The higher modes' resonance (= drive) frequencies as simulated, in Hz.
    pub resonance_hz: Vec<f64>,
    /// The tolerance the ratios were made commensurate within.
    pub ratio_tolerance: f64,
}

impl Modal {
    /// The model of `first` and `set`: each higher mode's resonance moved to pᵢ/q times
    /// the first mode's drive frequency (within the set's tolerance; q ≤
    /// [`MAX_DENOMINATOR`]) and driven there, or, where no such q exists (or the
    /// tolerance is 0 and the ratios are not exactly rational), kept as given.
    pub fn new(first: &Cantilever, set: &ModeSet) -> Result<Self> {
        let first = first.validated()?;
        if set.higher.len() >= MAX_MODES {
            return Err(Error::OutOfRange(format!(
                "at most {MAX_MODES} modes are simulated together, not {}",
                set.higher.len() + 1
            )));
        }
        if !(set.ratio_tolerance.is_finite()
            && set.ratio_tolerance >= 0.0
            && set.ratio_tolerance < 0.1)
        {
            return Err(Error::InvalidParameter {
                name: "frequency-ratio tolerance",
                value: set.ratio_tolerance,
                reason: "must be at least 0 (the frequencies as given) and below 0.1",
            });
        }
        let higher = set
            .higher
            .iter()
            .map(|m| m.validated())
            .collect::<Result<Vec<_>>>()?;
        let drive_hz = first.drive_frequency_hz;
        let ratios: Vec<f64> = higher.iter().map(|m| m.resonance_hz / drive_hz).collect();
        if let Some(m) = higher.iter().find(|m| !(0.5..=1e7).contains(&m.quality)) {
            return Err(Error::OutOfRange(format!(
                "a higher mode's quality factor Q = {} is outside 0.5 to 1e7 (as the first \
                 mode's)",
                m.quality
            )));
        }
        if let Some(r) = ratios.iter().find(|&&r| r > MAX_RATIO) {
            return Err(Error::OutOfRange(format!(
                "a higher mode's resonance is {r:.4e} times the first mode's drive frequency: \
                 at most {MAX_RATIO} are resolved (a beam's third mode is at 17.5)"
            )));
        }
        if let Some((m, r)) = higher.iter().zip(&ratios).find(|(m, r)| {
            let mass = m.stiffness_n_m / first.stiffness_n_m / (*r * *r);
            mass < 1e-3
        }) {
            return Err(Error::OutOfRange(format!(
                "a higher mode of stiffness {} N/m at {r:.4} times the drive frequency has a \
                 modal mass {:.3e} times the first mode's: at least 1e-3 is simulated (the \
                 tip force would throw so light a mode about; a rectangular beam's modes \
                 have equal masses, k_i = k₁(f_i/f₁)²)",
                m.stiffness_n_m,
                m.stiffness_n_m / first.stiffness_n_m / (r * r)
            )));
        }
        if let Some(r) = ratios.iter().find(|&&r| r < 1.5) {
            return Err(Error::OutOfRange(format!(
                "a higher mode's resonance is {r:.3} times the first mode's drive frequency: \
                 the modes must be ordered, each above 1.5 f_drive,1"
            )));
        }
        let omega1 = first.omega_ratio();
        let mut modes = vec![ModeModel::new(1.0, first.quality, 1.0, omega1, 1.0)];
        let mut resonance_hz = Vec::new();
        // Commensurate: each higher mode moved to pᵢ/q of the drive frequency. Otherwise
        // the frequencies as given, and no common period.
        let common = common_denominator(&ratios, set.ratio_tolerance);
        for (i, m) in higher.iter().enumerate() {
            // (Products taken in this order: the commensurate model bit for bit as
            // before window averages existed.)
            let (omega, hz) = match &common {
                Some((q, p)) => (
                    omega1 * f64::from(p[i]) / f64::from(*q),
                    drive_hz * f64::from(p[i]) / f64::from(*q),
                ),
                None => (omega1 * ratios[i], m.resonance_hz),
            };
            modes.push(ModeModel::new(
                omega,
                m.quality,
                m.stiffness_n_m / first.stiffness_n_m,
                omega,
                m.free_amplitude_m / first.free_amplitude_m,
            ));
            resonance_hz.push(hz);
        }
        Ok(Self {
            modes,
            periods: common.map(|(q, _)| q),
            resonance_hz,
            ratio_tolerance: set.ratio_tolerance,
        })
    }

    /// The common period: q first-mode drive periods, and in τ. Refuses drives with no
    /// common period (no pᵢ/q with q ≤ [`MAX_DENOMINATOR`] within the tolerance).
    pub fn common_period(&self) -> Result<(u32, f64)> {
        let q = self.periods.ok_or_else(|| {
            let ratios: Vec<f64> = self.modes[1..]
                .iter()
                .map(|m| m.omega / self.modes[0].omega)
                .collect();
            Error::NotApplicable(format!(
                "the frequency ratios {ratios:.6?} have no common denominator up to \
                 {MAX_DENOMINATOR} within a relative tolerance of {}: the motion is not \
                 periodic, and has no orbit to find or follow; its averages over windows \
                 are computed at one rest separation (the tap command), or allow a larger \
                 frequency-ratio tolerance",
                self.ratio_tolerance
            ))
        })?;
        Ok((q, self.periods_hat(q)))
    }

    /// `q` first-mode drive periods in τ (the common period's arithmetic, kept as it
    /// was: 2πq/Ω₁).
    fn periods_hat(&self, q: u32) -> f64 {
        2.0 * std::f64::consts::PI * f64::from(q) / self.modes[0].omega
    }

    /// The period a march goes by: the common period over q where there is one (so the
    /// commensurate instrument is bit for bit as before), else the first mode's drive
    /// period. Builds no refusal (a hot path: every march of the instrument).
    pub fn march_period(&self) -> f64 {
        self.periods
            .map_or(self.drive_period(), |q| self.periods_hat(q) / f64::from(q))
    }

    /// Mode i's resonance (Hz), stiffness (N/m) and Q, the first mode's `first`'s:
    /// kᵢ = k₁rᵢ²/cᵢ, a higher mode's resonance as simulated.
    pub fn in_si(&self, first: &Cantilever, i: usize) -> (f64, f64, f64) {
        let m = &self.modes[i];
        if i == 0 {
            (first.resonance_hz, first.stiffness_n_m, first.quality)
        } else {
            (
                self.resonance_hz[i - 1],
                first.stiffness_n_m * m.r * m.r / m.gain,
                m.quality(),
            )
        }
    }

    /// The first mode's drive period in τ.
    pub fn drive_period(&self) -> f64 {
        self.own_period(0)
    }

    /// Mode i's own drive period in τ.
    pub fn own_period(&self, i: usize) -> f64 {
        2.0 * std::f64::consts::PI / self.modes[i].omega
    }
}
