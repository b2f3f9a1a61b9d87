//! The point-mass cantilever in dimensionless form (docs/src/explanation/design.md §2).
//!
//! Time τ = ω₀t, deflection x = z/L for a length unit L (the free amplitude A₀ in tapping),
//! forces in units of kL, energies in units of kL². The equation of motion
//!
//!   x'' + 2γx' + x = f_ts + f_drive(τ),   γ = 1/(2Q),
//!
//! with f_ts = −T̂·RΔγ/(kL) and the tip–sample separation α̂ = a₀ + a₁(x + x_b(τ)),
//! where x_b is the support displacement of a base drive (zero for a force drive).

use super::surface::{Surface, View};
use crate::physics::law::{Branch, ContactState, ForceLaw};
use nalgebra::{DMatrix, SVector};
use std::ops::{Index, IndexMut};

/// ODE state: each cantilever mode's deflection and velocity, the per-cycle integrals
/// carried along, and the drive phasor (cos Ωτ, sin Ωτ), integrated as a rotation so the
/// right-hand side needs no trigonometric calls (it is reset to the exact values at every
/// segment start). Four layouts, by `N`:
///
/// - [`BASE`]: just that, for a law whose force depends on the separation alone;
/// - [`TANGENT`]: also the variational matrix Φ = ∂z/∂(z₀, q) after the base parts,
///   z the section state (x, x') and q = z_c/L the rest separation
///   (α̂ = a₁(q + x + x_b)), for the derivative of the period map;
/// - [`RATE`] and [`RATE_TANGENT`]: the same with, last, the work done against a
///   rate-dependent force ([`dissipative_work_index`]).
///
/// The hot path of a law pays only for what it needs (the integrator's error norm, and
/// so every number, of an elastic law is that of its nine components). Parts are
/// addressed by name: `y[Part::Deflection(0)]` (or [`X`]), `y[Carried::Damping]`. One
/// mode today ([`MODES`]); the layout places further modes' deflections and velocities
/// before the carried integrals, and the section state grows with them
/// ([`SECTION_DIM`]).
///
/// The contact's elastic E_ts is not carried: it is exact from the branch work functions
/// at the segment ends. The drive's work follows from the Fourier projections by parts
/// ([`Oscillator::drive_work`]).
pub type State<const N: usize = BASE> = SVector<f64, N>;

/// Cantilever modes in the state.
pub const MODES: usize = 1;

/// A per-cycle integral carried in every layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Carried {
    /// Energy dissipated by damping, ∫ 2γ x'² dτ.
    Damping,
    /// Fourier projection ∫ x cos Ωτ dτ.
    CosProjection,
    /// Fourier projection ∫ x sin Ωτ dτ.
    SinProjection,
    /// ∫ f_ts dτ (mean force).
    Force,
    /// ∫ f_ts x dτ (virial).
    Virial,
}

impl Carried {
    /// How many there are.
    pub const COUNT: usize = 5;
}

/// A named part of the state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// Deflection of cantilever mode m (0: the first).
    Deflection(usize),
    /// Velocity of mode m.
    Velocity(usize),
    /// A carried integral.
    Carried(Carried),
    /// cos Ωτ.
    DriveCos,
    /// sin Ωτ.
    DriveSin,
}

impl Part {
    /// Where this part lives in the state vector.
    #[inline]
    pub const fn index(self) -> usize {
        match self {
            Part::Deflection(mode) => 2 * mode,
            Part::Velocity(mode) => 2 * mode + 1,
            Part::Carried(c) => 2 * MODES + c as usize,
            Part::DriveCos => 2 * MODES + Carried::COUNT,
            Part::DriveSin => 2 * MODES + Carried::COUNT + 1,
        }
    }
}

impl<const N: usize> Index<Part> for SVector<f64, N> {
    type Output = f64;
    #[inline]
    fn index(&self, part: Part) -> &f64 {
        &self[part.index()]
    }
}

impl<const N: usize> IndexMut<Part> for SVector<f64, N> {
    #[inline]
    fn index_mut(&mut self, part: Part) -> &mut f64 {
        &mut self[part.index()]
    }
}

impl<const N: usize> Index<Carried> for SVector<f64, N> {
    type Output = f64;
    #[inline]
    fn index(&self, c: Carried) -> &f64 {
        &self[Part::Carried(c)]
    }
}

impl<const N: usize> IndexMut<Carried> for SVector<f64, N> {
    #[inline]
    fn index_mut(&mut self, c: Carried) -> &mut f64 {
        &mut self[Part::Carried(c)]
    }
}

/// The first mode's deflection x.
pub const X: Part = Part::Deflection(0);
/// The first mode's velocity x'.
pub const V: Part = Part::Velocity(0);

/// Where the carried integrals live: quadratures, which the right-hand side never reads
/// ([`super::dopri5::System::QUADRATURES`]).
#[doc(hidden)]
pub const CARRIED: std::ops::Range<usize> = Part::Carried(Carried::Damping).index()
    ..Part::Carried(Carried::Damping).index() + Carried::COUNT;

/// Components of the plain state.
pub const BASE: usize = 2 * MODES + Carried::COUNT + 2;
/// Components of the state with the variational matrix.
pub const TANGENT: usize = BASE + phi_len(2 * MODES);
/// Components of the plain state of a rate-dependent law.
pub const RATE: usize = BASE + 1;
/// Components of the state of a rate-dependent law with the variational matrix.
pub const RATE_TANGENT: usize = TANGENT + 1;

/// Entries of Φ for a section state of dimension `d`: d × (d + 1).
const fn phi_len(d: usize) -> usize {
    d * (d + 1)
}

/// Whether layout `N` carries the variational matrix Φ.
#[inline]
pub const fn has_tangent(n: usize) -> bool {
    n == TANGENT || n == RATE_TANGENT
}

/// Dimension of the section state z (each mode's x and x'): what the period map maps.
pub const SECTION_DIM: usize = 2 * MODES;

/// Where layout `N` carries the work done against a rate-dependent force,
/// ∫ T̂_d dα̂ (dimensionless, the contact's units; what a viscous or relaxing sample
/// dissipates): the last component of the rate layouts, nowhere in the others.
#[inline]
pub const fn dissipative_work_index(n: usize) -> Option<usize> {
    if n == RATE || n == RATE_TANGENT {
        Some(n - 1)
    } else {
        None
    }
}

/// First entry of Φ in a layout with a tangent, stored column by column: ∂z/∂z₀ column
/// by column, then ∂z/∂q (right after the base parts).
const PHI_START: usize = BASE;

/// Φ of a state with a tangent ([`has_tangent`]) as a d × (d + 1) matrix.
pub fn phi<const N: usize>(y: &State<N>) -> DMatrix<f64> {
    let d = SECTION_DIM;
    DMatrix::from_column_slice(d, d + 1, &y.as_slice()[PHI_START..PHI_START + phi_len(d)])
}

/// Φ at the start of a span in a section of dimension `d`: the identity in z₀, nothing
/// yet from q.
pub(crate) fn phi_start(d: usize) -> DMatrix<f64> {
    DMatrix::identity(d, d + 1)
}

/// Where column `col` of Φ begins (its rows follow: x, x'); the last column,
/// [`SECTION_DIM`], is ∂z/∂q. Φ is updated in place through these, with no matrix built,
/// on the paths every shooting period takes.
#[inline]
#[doc(hidden)]
pub const fn phi_column(col: usize) -> usize {
    PHI_START + SECTION_DIM * col
}

/// Set Φ of `y` to its start ([`phi_start`]) in place.
#[doc(hidden)]
pub fn reset_phi<const N: usize>(y: &mut State<N>) {
    let d = SECTION_DIM;
    for col in 0..=d {
        for row in 0..d {
            y[phi_column(col) + row] = if row == col { 1.0 } else { 0.0 };
        }
    }
}

/// The derivative over two spans, `first` then `then` (each ∂z/∂(z₀, q)): the chain
/// rule, with q entering both.
pub fn chain(first: &DMatrix<f64>, then: &DMatrix<f64>) -> DMatrix<f64> {
    let d = then.nrows();
    let mut out = then.columns(0, d) * first;
    for row in 0..d {
        out[(row, d)] += then[(row, d)];
    }
    out
}

/// Set the drive phasor of `y` to its exact value at τ.
#[inline]
#[doc(hidden)]
pub fn set_phasor<const N: usize>(osc: &Oscillator, tau: f64, y: &mut State<N>) {
    let (s, c) = (osc.omega * tau).sin_cos();
    y[Part::DriveCos] = c;
    y[Part::DriveSin] = s;
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
    /// The support moves at a constant speed, x_b = p + uτ: one leg of a force–distance
    /// ramp (a triangular ramp is a sequence of them, its dwell a leg with u = 0; the
    /// Fourier phasor still turns at Ω, which only sets the span a call may cover).
    Ramp {
        /// p: x_b at τ = 0, in units of L.
        position: f64,
        /// u = dx_b/dτ, in units of L per 1/ω₀ (toward the sample negative).
        speed: f64,
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
    /// A constant force on the tip, in units of kL: the thermal force over one of its
    /// steps ([`crate::instrument::thermal`]); 0 otherwise.
    pub bias: f64,
}

impl Oscillator {
    /// Drive period in τ.
    pub fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.omega
    }

    /// Whether free motion is underdamped enough for the closed form (Q > 0.55).
    pub(crate) fn underdamped(&self) -> bool {
        self.gamma < 0.9
    }

    /// Support displacement and velocity (x_b, x_b') at τ; no trigonometry for a force
    /// drive.
    #[inline]
    pub fn base_at(&self, tau: f64) -> (f64, f64) {
        match self.drive {
            Drive::Force { .. } => (0.0, 0.0),
            Drive::Base { .. } => self.base_from(tau, (self.omega * tau).sin_cos()),
            Drive::Ramp { position, speed } => (position + speed * tau, speed),
        }
    }

    /// The support's acceleration x_b'' at τ (zero on a ramp's leg).
    #[inline]
    pub(crate) fn base_acceleration(&self, tau: f64) -> f64 {
        match self.drive {
            Drive::Base { .. } => -self.omega * self.omega * self.base_at(tau).0,
            Drive::Force { .. } | Drive::Ramp { .. } => 0.0,
        }
    }

    /// Work done by the drive between `start` and `end` (each (τ, x, x')), from the
    /// Fourier projections `sc` = ∫ x cos Ωτ dτ and `ss` = ∫ x sin Ωτ dτ over the span
    /// and the force's integral `force` = ∫ f_ts dτ.
    ///
    /// Force drive, by parts: ∫ f₀ cos Ωτ x' dτ = f₀([x cos Ωτ] + Ω·ss), exact for any
    /// path. Base drive: the work −∫ f_ts x_b' dτ = bΩ ∫ f_ts sin Ωτ dτ, with f_ts =
    /// x'' + 2γx' + x from the equation of motion and the same integration by parts:
    /// ∫ f_ts sin Ωτ dτ = [x' sin Ωτ] − Ω[x cos Ωτ] + 2γ[x sin Ωτ] + (1 − Ω²)·ss − 2γΩ·sc.
    /// A ramp's leg: −u ∫ f_ts dτ.
    pub fn drive_work(
        &self,
        start: (f64, f64, f64),
        end: (f64, f64, f64),
        (sc, ss): (f64, f64),
        force: f64,
    ) -> f64 {
        let w = self.omega;
        let span = |g: &dyn Fn(f64, f64, f64) -> f64| {
            g(end.0, end.1, end.2) - g(start.0, start.1, start.2)
        };
        match self.drive {
            Drive::Force { amplitude } => amplitude * (span(&|t, x, _| x * (w * t).cos()) + w * ss),
            Drive::Base { amplitude } => {
                let force_sin = span(&|t, x, v| {
                    let (s, c) = (w * t).sin_cos();
                    v * s - w * x * c + 2.0 * self.gamma * x * s
                }) + (1.0 - w * w) * ss
                    - 2.0 * self.gamma * w * sc;
                amplitude * w * force_sin
            }
            Drive::Ramp { speed, .. } => -speed * force,
        }
    }

    /// Support displacement and velocity (x_b, x_b') at τ, whose drive phasor is
    /// (sin Ωτ, cos Ωτ): no trigonometry.
    #[inline]
    pub(crate) fn base_from(&self, tau: f64, (s, c): (f64, f64)) -> (f64, f64) {
        match self.drive {
            Drive::Force { .. } => (0.0, 0.0),
            Drive::Base { amplitude } => (amplitude * c, -amplitude * self.omega * s),
            Drive::Ramp { position, speed } => (position + speed * tau, speed),
        }
    }

    /// Drive force f_drive and support displacement x_b at τ, whose cos Ωτ is `c`.
    #[inline]
    pub(crate) fn drive_from(&self, tau: f64, c: f64) -> (f64, f64) {
        match self.drive {
            Drive::Force { amplitude } => (amplitude * c, 0.0),
            Drive::Base { amplitude } => (0.0, amplitude * c),
            Drive::Ramp { position, speed } => (0.0, position + speed * tau),
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

    /// What the law sees at deflection and velocity `(x, v)` with the support at
    /// `(x_b, x_b')`: α̂ and its rate a₁(x' + x_b').
    #[inline]
    pub fn contact_state(
        &self,
        (x, v): (f64, f64),
        (x_b, v_b): (f64, f64),
        branch: Branch,
    ) -> ContactState {
        ContactState {
            alpha_hat: self.alpha_hat(x, x_b),
            rate_hat: self.a1 * (v + v_b),
            branch,
        }
    }

    /// Deflection at which α̂ equals `alpha_hat` (without base displacement).
    #[inline]
    pub(crate) fn x_at(&self, alpha_hat: f64) -> f64 {
        (alpha_hat - self.a0) / self.a1
    }
}

/// What a relaxing sample's surface sees of the tip at τ in state `y`
/// ([`super::surface::View`]): δ̂ = −α̂ and its rate.
#[inline]
#[doc(hidden)]
pub fn surface_view<const N: usize>(
    osc: &Oscillator,
    cpl: &Coupling,
    tau: f64,
    y: &State<N>,
) -> View {
    let (x_b, v_b) = osc.base_at(tau);
    [-cpl.alpha_hat(y[X], x_b), -cpl.a1 * (y[V] + v_b)]
}

/// The right-hand side of the equation of motion and of the carried integrals; for a
/// state with a tangent also of the variational equations δx'' + 2γδx' + δx =
/// (∂f_ts/∂x)δx + (∂f_ts/∂x')δx' (+ ∂f_ts/∂q for the q column),
/// ∂f_ts/∂x = ∂f_ts/∂q = −f_scale·a₁·∂T̂/∂α̂, ∂f_ts/∂x' = −f_scale·a₁·∂T̂/∂(dα̂/dτ) (a
/// rate-dependent law's).
///
/// A law with a surface ([`ForceLaw::surface`]) takes its rate-dependent force from
/// `surface`, the step the integrator has open on it.
#[inline]
#[allow(clippy::too_many_arguments)]
#[doc(hidden)]
pub fn rhs<L: ForceLaw, const N: usize>(
    law: &L,
    osc: &Oscillator,
    cpl: &Coupling,
    branch: Branch,
    tau: f64,
    y: &State<N>,
    dy: &mut State<N>,
    surface: Option<&Surface>,
) {
    let (x, v) = (y[X], y[V]);
    let (s, c) = (y[Part::DriveSin], y[Part::DriveCos]);
    let (drive, x_b) = osc.drive_from(tau, c);
    let alpha = cpl.alpha_hat(x, x_b);
    let (elastic, slope) = if has_tangent(N) {
        law.t_and_slope_hat(alpha, branch)
    } else {
        (law.t_hat(alpha, branch), 0.0)
    };
    let mut state = None;
    let dissipative = if law.is_rate_dependent() {
        let at = ContactState {
            alpha_hat: alpha,
            rate_hat: cpl.a1 * (v + osc.base_from(tau, (s, c)).1),
            branch,
        };
        state = Some(at);
        match surface {
            Some(s) => law.surface_t_hat(&at, s.force_at(tau, surface_view(osc, cpl, tau, y))),
            None => law.dissipative_t_hat(&at),
        }
    } else {
        0.0
    };
    let f = -cpl.f_scale * (elastic + dissipative);
    if has_tangent(N) {
        let (d_alpha, d_rate) = state.map_or((0.0, 0.0), |at| law.dissipative_slopes_hat(&at));
        let k = -cpl.f_scale * cpl.a1;
        let stiffness = k * (slope + d_alpha);
        let damping = k * d_rate;
        let d = SECTION_DIM;
        let first = PHI_START;
        // The q column's δx' row.
        let q_row = first + d * d + 1;
        // Section (x, x'): the columns ∂/∂x₀, ∂/∂x₀', ∂/∂q (a fixed list, unrolled).
        const _: () = assert!(MODES == 1, "the variational equations are one mode's");
        for col in [first, first + d, first + 2 * d] {
            let (dx, dv) = (y[col], y[col + 1]);
            dy[col] = dv;
            dy[col + 1] = -2.0 * osc.gamma * dv - dx + stiffness * dx + damping * dv;
        }
        dy[q_row] += stiffness;
    }
    dy[X] = v;
    dy[V] = -2.0 * osc.gamma * v - x + f + drive + osc.bias;
    dy[Carried::Damping] = 2.0 * osc.gamma * v * v;
    dy[Carried::CosProjection] = x * c;
    dy[Carried::SinProjection] = x * s;
    dy[Carried::Force] = f;
    dy[Carried::Virial] = f * x;
    if let (Some(i), Some(at)) = (dissipative_work_index(N), state) {
        dy[i] = dissipative * at.rate_hat;
    }
    dy[Part::DriveCos] = -osc.omega * s;
    dy[Part::DriveSin] = osc.omega * c;
}
