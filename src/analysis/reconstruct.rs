//! AM force reconstruction: from the amplitude and phase an approach curve reads at each
//! rest separation back to the tip–sample force against the closest distance, and the
//! energy dissipated there (Hölscher, APL 89, 123109, 2006; Katan, van Es & Oosterkamp,
//! Nanotechnology 20, 165703, 2009).
//!
//! With the motion z ≈ z̄ + A cos θ (θ = ωt − φ) the steady state's projections onto
//! cos θ and sin θ give, at each z_c, two numbers of the force alone (docs/src/explanation/design.md,
//! "Force reconstruction"):
//!
//! - the in-phase force ⟨F_ts cos θ⟩ = k[A(1 − Ω²) − A₀F̂₀ cos φ]/2 (F̂₀ the drive in
//!   units of kA₀, Ω = ω/ω₀), which is an Abel-type integral of the force over the
//!   separations the tip passes, the mean of its approach and retract values;
//! - the energy dissipated per cycle, E_ts = πkA(A₀F̂₀ sin φ − AΩ/Q) (Cleveland et al.,
//!   APL 72, 2613, 1998).
//!
//! The first, as the relative frequency shift an FM measurement would read,
//! Ω_eff = −⟨F_ts cos θ⟩/(kA), is inverted by the Sader–Jarvis formula (APL 84, 1801,
//! 2004) with the amplitude of each distance inside the derivative, as in Hölscher's
//! large-amplitude inversion — in AM the amplitude changes along the curve:
//!
//!   F(D) = 2k ∫_D^∞ [(1 + √A/(8√(π(t − D)))) Ω_eff(t) − d(A^{3/2}Ω_eff)/dt / √(2(t − D))] dt.
//!
//! The integrals are exact for Ω_eff and A^{3/2}Ω_eff linear between the measured
//! distances (the 1/√(t − D) singularity integrated in closed form); past the farthest
//! point the force is taken as zero.
//!
//! The formula approximates the inverse of the first-order relation between force and
//! shift; where the force bends sharply (a contact's onset) it errs by a percent or so
//! of the force at a data spacing of 0.005 nm and more at coarser ones. The relation
//! itself can be inverted instead ([`Inversion::FirstOrder`], [`first_order_inverse`]):
//! exact for a force linear between the distances. Both rest on the first-order
//! relation, which holds while the force's gradient stays well below k.

use crate::error::{Error, Result};
use crate::physics::law::{Branch, ForceLaw};
use serde::Serialize;
use std::f64::consts::PI;

/// Most points a reconstruction takes (each force integrates over every farther point:
/// the work grows as the square of their number, 10⁸ steps here, well under a second).
pub const MAX_POINTS: usize = 10_000;

/// The cantilever as the reconstruction needs it (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Probe {
    /// Spring constant k, N/m.
    pub stiffness_n_m: f64,
    /// Quality factor Q.
    pub quality: f64,
    /// Free amplitude A₀, m.
    pub free_amplitude_m: f64,
    /// Drive frequency over resonance, Ω.
    pub frequency_ratio: f64,
}

impl Probe {
    /// The drive F₀/(kA₀) that gives the free amplitude at Ω: √((1 − Ω²)² + (Ω/Q)²).
    fn drive_hat(&self) -> f64 {
        let w = self.frequency_ratio;
        ((1.0 - w * w).powi(2) + (w / self.quality).powi(2)).sqrt()
    }
}

/// One branch of an AM curve: at each rest separation z_c, the amplitude and phase of the
/// fundamental and, if measured, the mean deflection.
#[derive(Debug, Clone, PartialEq)]
pub struct AmCurve {
    /// Rest separations z_c, m (any order; they must give distinct closest distances).
    pub separation_m: Vec<f64>,
    /// Amplitudes A, m.
    pub amplitude_m: Vec<f64>,
    /// Phase lags φ, degrees (90° free at resonance).
    pub phase_deg: Vec<f64>,
    /// Mean deflections z̄, m (the closest distance is z_c + z̄ − A); zero if not given.
    pub mean_deflection_m: Option<Vec<f64>>,
}

/// One branch of an FM curve: at each rest separation z_c, the frequency shift the PLL
/// reads and the excitation the amplitude controller needs, at a held amplitude.
#[derive(Debug, Clone, PartialEq)]
pub struct FmCurve {
    /// Rest separations z_c, m (any order; they must give distinct closest distances).
    pub separation_m: Vec<f64>,
    /// Frequency shifts Δf, Hz.
    pub frequency_shift_hz: Vec<f64>,
    /// Excitations over their free value at the same amplitude, F/F₀ (F₀ = kA/Q).
    pub excitation_ratio: Vec<f64>,
    /// Amplitudes held, m (the probe's free amplitude where not given).
    pub amplitude_m: Option<Vec<f64>>,
    /// Mean deflections z̄, m (the closest distance is z_c + z̄ − A); zero if not given.
    pub mean_deflection_m: Option<Vec<f64>>,
}

/// The reconstruction at one point of the curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReconstructedPoint {
    /// Rest separation z_c, m.
    pub separation_m: f64,
    /// Closest distance D = z_c + z̄ − A, m (negative: indentation).
    pub closest_m: f64,
    /// Amplitude A, m.
    pub amplitude_m: f64,
    /// Phase φ, degrees.
    pub phase_deg: f64,
    /// The in-phase force ⟨F_ts cos θ⟩, N.
    pub in_phase_force_n: f64,
    /// The equivalent relative frequency shift Ω_eff = −⟨F_ts cos θ⟩/(kA).
    pub frequency_shift: f64,
    /// The reconstructed force at D, N (repulsive positive); for a hysteretic law the
    /// mean of its approach and retract values, as far as one force explains the curve.
    pub force_n: f64,
    /// Energy dissipated per cycle, J.
    pub e_ts_j: f64,
}

/// A reconstructed curve, ordered by closest distance (nearest first).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reconstruction {
    /// How the force was inverted.
    pub inversion: Inversion,
    /// The points.
    pub points: Vec<ReconstructedPoint>,
    /// |Ω_eff| at the farthest point over its largest |Ω_eff|: how far from zero the
    /// force the inversion takes as zero beyond the curve still was.
    pub far_end_shift_ratio: f64,
    /// What the reader should know: a curve that does not reach free oscillation, a
    /// closest distance that does not fall with z_c, …
    pub notes: Vec<String>,
}

/// The in-phase force ⟨F_ts cos θ⟩ (N) and the energy dissipated per cycle (J) at
/// amplitude `amplitude_m` and phase lag `phase_deg`, from the harmonic balance of the
/// driven oscillator (docs/src/explanation/design.md, "Force reconstruction"; the second is Cleveland et
/// al., APL 72, 2613, 1998).
pub fn harmonic_balance(probe: &Probe, amplitude_m: f64, phase_deg: f64) -> (f64, f64) {
    let (k, a0, w, q) = (
        probe.stiffness_n_m,
        probe.free_amplitude_m,
        probe.frequency_ratio,
        probe.quality,
    );
    let f0 = probe.drive_hat() * a0;
    let (sin, cos) = phase_deg.to_radians().sin_cos();
    let in_phase = 0.5 * k * (amplitude_m * (1.0 - w * w) - f0 * cos);
    let e_ts = PI * k * amplitude_m * (f0 * sin - amplitude_m * w / q);
    (in_phase, e_ts)
}

/// How the equivalent frequency shifts become a force.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Inversion {
    /// The Sader–Jarvis formula ([`sader_jarvis`]).
    #[default]
    SaderJarvis,
    /// The first-order relation inverted exactly ([`first_order_inverse`]).
    FirstOrder,
}

impl Inversion {
    /// The force (N) at each of `closest_m` (increasing, m) from the shifts Ω_eff and
    /// amplitudes (m) there, by this inversion.
    pub fn force(
        self,
        stiffness_n_m: f64,
        closest_m: &[f64],
        amplitude_m: &[f64],
        shift: &[f64],
    ) -> Vec<f64> {
        match self {
            Self::SaderJarvis => sader_jarvis(stiffness_n_m, closest_m, amplitude_m, shift),
            Self::FirstOrder => first_order_inverse(stiffness_n_m, closest_m, amplitude_m, shift),
        }
    }
}

/// The force at each of `closest_m` (increasing) from the equivalent frequency shifts
/// `shift` and amplitudes there: the Sader–Jarvis inversion (APL 84, 1801, 2004) with
/// A^{3/2}Ω_eff differentiated (Hölscher, APL 89, 123109, 2006), exact for Ω_eff,
/// √A·Ω_eff and A^{3/2}Ω_eff linear between the points; zero force beyond the last.
pub fn sader_jarvis(
    stiffness_n_m: f64,
    closest_m: &[f64],
    amplitude_m: &[f64],
    shift: &[f64],
) -> Vec<f64> {
    let n = closest_m.len();
    (0..n)
        .map(|i| {
            let d = closest_m[i];
            let mut sum = 0.0;
            for j in i..n.saturating_sub(1) {
                let (t0, t1) = (closest_m[j], closest_m[j + 1]);
                let (u0, u1) = (t0 - d, t1 - d);
                let (r0, r1) = (u0.sqrt(), u1.sqrt());
                let h = t1 - t0;
                // ∫ Ω dt, trapezoid (exact for linear Ω).
                sum += 0.5 * (shift[j] + shift[j + 1]) * h;
                // ∫ √A Ω / (8√(π u)) dt with √A Ω linear in u.
                let g0 = amplitude_m[j].sqrt() * shift[j];
                let g1 = amplitude_m[j + 1].sqrt() * shift[j + 1];
                let slope = (g1 - g0) / h;
                let int_inv_sqrt = 2.0 * (r1 - r0);
                let int_u_over_sqrt = (2.0 / 3.0) * (u1 * r1 - u0 * r0);
                let int_lin = g0 * int_inv_sqrt + slope * (int_u_over_sqrt - u0 * int_inv_sqrt);
                sum += int_lin / (8.0 * PI.sqrt());
                // −∫ d(A^{3/2}Ω)/dt / √(2u) dt, the derivative constant on the segment.
                let p0 = amplitude_m[j].powf(1.5) * shift[j];
                let p1 = amplitude_m[j + 1].powf(1.5) * shift[j + 1];
                sum -= (p1 - p0) / h * int_inv_sqrt / 2f64.sqrt();
            }
            2.0 * stiffness_n_m * sum
        })
        .collect()
}

/// The force at each of `closest_m` (increasing) from the equivalent frequency shifts
/// `shift` and amplitudes there, by inverting the first-order relation itself rather
/// than an approximate formula for its inverse (Giessibl's matrix method, APL 78, 123,
/// 2001, with the force linear between the points rather than constant):
///
///   Ω_eff(D) = −1/(πkA²) ∫₀^{2A} F(D + u) (u − A)/√(u(2A − u)) du,
///
/// each point's row integrated in closed form over the segments its orbit spans (the
/// kernel's antiderivatives are −√(u(2A − u)) and, times u, (A²/2) asin((u − A)/A) −
/// (u + A)√(u(2A − u))/2), and the triangular system so made solved from the farthest
/// point in. Exact for a force linear between the points where Ω_eff is the first-order
/// shift; the Sader–Jarvis formula ([`sader_jarvis`]) is accurate to a few per cent of
/// the force where the force bends sharply (a contact's onset). Beyond the last point
/// the force is taken to fall linearly to zero over the widest orbit's span 2A.
pub fn first_order_inverse(
    stiffness_n_m: f64,
    closest_m: &[f64],
    amplitude_m: &[f64],
    shift: &[f64],
) -> Vec<f64> {
    let n = closest_m.len();
    let mut force = vec![0.0; n];
    let Some(&last) = closest_m.last() else {
        return force;
    };
    // Beyond the last point the force falls linearly to zero over the widest orbit: a
    // shift still read there is spread over the orbit's span, not put into the last
    // segment (which would magnify it by √(2A/h)).
    let beyond = last + 2.0 * amplitude_m.iter().fold(0.0f64, |m, &a| m.max(a));
    for i in (0..n).rev() {
        let (d, a) = (closest_m[i], amplitude_m[i]);
        // The kernel's antiderivatives at u (clamped to the orbit's span [0, 2A]).
        let r = |u: f64| (u * (2.0 * a - u)).max(0.0).sqrt();
        let p0 = |u: f64| -r(u);
        let p1 =
            |u: f64| 0.5 * a * a * ((u - a) / a).clamp(-1.0, 1.0).asin() - 0.5 * (u + a) * r(u);
        let mut diagonal = 0.0;
        let mut rest = 0.0;
        for j in i..n {
            let next = closest_m.get(j + 1).copied().unwrap_or(beyond);
            let (u0, u1) = (closest_m[j] - d, next - d);
            if u0 >= 2.0 * a {
                break;
            }
            let h = u1 - u0;
            let top = u1.min(2.0 * a);
            let (k0, k1) = (p0(top) - p0(u0), p1(top) - p1(u0));
            // F = F_j (u1 − u)/h + F_{j+1} (u − u0)/h on the segment.
            let w_j = (u1 * k0 - k1) / h;
            let w_next = (k1 - u0 * k0) / h;
            if j == i {
                diagonal = w_j;
            } else {
                rest += w_j * force[j];
            }
            if j + 1 < n {
                rest += w_next * force[j + 1];
            }
        }
        force[i] = (-PI * stiffness_n_m * a * a * shift[i] - rest) / diagonal;
    }
    force
}

/// Reconstruct the force and the dissipation against the closest distance from one
/// branch of an AM curve (module docs).
pub fn reconstruct(probe: &Probe, curve: &AmCurve, inversion: Inversion) -> Result<Reconstruction> {
    for (name, v) in [
        ("stiffness", probe.stiffness_n_m),
        ("quality factor", probe.quality),
        ("free amplitude", probe.free_amplitude_m),
        ("drive frequency ratio", probe.frequency_ratio),
    ] {
        crate::error::positive(name, v)?;
    }
    let n = curve.separation_m.len();
    let lengths_match = curve.amplitude_m.len() == n
        && curve.phase_deg.len() == n
        && curve
            .mean_deflection_m
            .as_ref()
            .is_none_or(|m| m.len() == n);
    if !lengths_match {
        return Err(Error::NotApplicable(
            "the curve's columns differ in length".into(),
        ));
    }
    check_count(n)?;
    let zero = vec![0.0; n];
    let deflection = curve.mean_deflection_m.as_deref().unwrap_or(&zero);
    let mut points = Vec::with_capacity(n);
    let rows = curve
        .separation_m
        .iter()
        .zip(&curve.amplitude_m)
        .zip(&curve.phase_deg)
        .zip(deflection);
    for (i, (((&z, &a), &phi), &zbar)) in rows.enumerate() {
        if ![z, a, phi, zbar].iter().all(|v| v.is_finite()) {
            return Err(Error::NotApplicable(format!(
                "point {}: a value is not a finite number",
                i + 1
            )));
        }
        if a <= 0.0 {
            return Err(Error::NotApplicable(format!(
                "point {}: the amplitude {a:e} m is not positive",
                i + 1
            )));
        }
        let (in_phase, e_ts) = harmonic_balance(probe, a, phi);
        points.push(ReconstructedPoint {
            separation_m: z,
            closest_m: z + zbar - a,
            amplitude_m: a,
            phase_deg: phi,
            in_phase_force_n: in_phase,
            frequency_shift: -in_phase / (probe.stiffness_n_m * a),
            force_n: 0.0,
            e_ts_j: e_ts,
        });
    }
    invert(probe, points, curve.mean_deflection_m.is_some(), inversion)
}

/// The points' count checked as a reconstruction takes it.
fn check_count(n: usize) -> Result<()> {
    if n < 3 {
        return Err(Error::NotApplicable(format!(
            "a reconstruction needs at least 3 points of the curve ({n} given)"
        )));
    }
    if n > MAX_POINTS {
        return Err(Error::OutOfRange(format!(
            "a reconstruction takes at most {MAX_POINTS} points (its integrals grow as the \
             square of their number), not {n}"
        )));
    }
    Ok(())
}

/// Reconstruct the force and the dissipation against the closest distance from one
/// branch of an FM curve: at each point the first harmonic's balance with the drive in
/// quadrature (the PLL's 90°) gives the in-phase force, −kA·Ω_eff with
/// Ω_eff = ((f/f₀)² − 1)/2 (to first order Δf/f₀, Giessibl 1997), and the excitation
/// the loss, E_ts = (πkA²/Q)(F/F₀ − f/f₀) (Anczykowski et al., Appl. Surf. Sci. 140,
/// 376, 1999); Ω_eff is inverted by `inversion` as for AM (module docs).
/// `resonance_hz` is f₀, the free cantilever's, which Δf is counted from.
pub fn reconstruct_fm(
    probe: &Probe,
    resonance_hz: f64,
    curve: &FmCurve,
    inversion: Inversion,
) -> Result<Reconstruction> {
    for (name, v) in [
        ("stiffness", probe.stiffness_n_m),
        ("quality factor", probe.quality),
        ("free amplitude", probe.free_amplitude_m),
        ("resonance frequency", resonance_hz),
    ] {
        crate::error::positive(name, v)?;
    }
    let n = curve.separation_m.len();
    let lengths_match = curve.frequency_shift_hz.len() == n
        && curve.excitation_ratio.len() == n
        && [&curve.amplitude_m, &curve.mean_deflection_m]
            .iter()
            .all(|c| c.as_ref().is_none_or(|c| c.len() == n));
    if !lengths_match {
        return Err(Error::NotApplicable(
            "the curve's columns differ in length".into(),
        ));
    }
    check_count(n)?;
    let (k, q) = (probe.stiffness_n_m, probe.quality);
    let mut points = Vec::with_capacity(n);
    for i in 0..n {
        let z = curve.separation_m[i];
        let a = curve
            .amplitude_m
            .as_ref()
            .map_or(probe.free_amplitude_m, |a| a[i]);
        let zbar = curve.mean_deflection_m.as_ref().map_or(0.0, |d| d[i]);
        let ratio = 1.0 + curve.frequency_shift_hz[i] / resonance_hz;
        let excitation = curve.excitation_ratio[i];
        if ![z, a, zbar, ratio, excitation]
            .iter()
            .all(|v| v.is_finite())
        {
            return Err(Error::NotApplicable(format!(
                "point {}: a value is not a finite number",
                i + 1
            )));
        }
        if a <= 0.0 || ratio <= 0.0 || excitation < 0.0 {
            return Err(Error::NotApplicable(format!(
                "point {}: the amplitude ({a:e} m), the frequency f₀ + Δf ({:e} Hz) and the \
                 excitation ({excitation}) must be positive",
                i + 1,
                ratio * resonance_hz
            )));
        }
        let shift = 0.5 * (ratio * ratio - 1.0);
        points.push(ReconstructedPoint {
            separation_m: z,
            closest_m: z + zbar - a,
            amplitude_m: a,
            phase_deg: 90.0,
            in_phase_force_n: -k * a * shift,
            frequency_shift: shift,
            force_n: 0.0,
            e_ts_j: PI * k * a * a / q * (excitation - ratio),
        });
    }
    invert(probe, points, curve.mean_deflection_m.is_some(), inversion)
}

/// The force by `inversion` from the points' in-phase parts, with the points kept that
/// give one force at one distance, and the notes a reader needs.
fn invert(
    probe: &Probe,
    points: Vec<ReconstructedPoint>,
    with_mean_deflection: bool,
    inversion: Inversion,
) -> Result<Reconstruction> {
    let n = points.len();
    let mut notes = Vec::new();
    // From the farthest z_c in: keep each point whose closest distance is nearer than
    // every farther point's (one force, one distance). On the attractive branch of AM
    // the amplitude follows z_c so closely that D hardly moves, and by picometres may
    // move back: such points measure distances already measured, differently only
    // because the amplitude differs, and a derivative across them would be noise.
    let mut by_z: Vec<usize> = (0..n).collect();
    by_z.sort_by(|&a, &b| points[b].separation_m.total_cmp(&points[a].separation_m));
    if by_z
        .windows(2)
        .any(|w| points[w[0]].separation_m == points[w[1]].separation_m)
    {
        return Err(Error::NotApplicable(
            "two points at one position: give one branch of the curve (an approach, or a \
             retract), not both"
                .into(),
        ));
    }
    let mut kept: Vec<ReconstructedPoint> = Vec::with_capacity(n);
    for &i in &by_z {
        if kept
            .last()
            .is_none_or(|last| points[i].closest_m < last.closest_m)
        {
            kept.push(points[i]);
        }
    }
    if kept.len() < 3 {
        return Err(Error::NotApplicable(format!(
            "the closest distance z_c + z̄ − A falls at only {} of the {n} positions: \
             nothing to invert",
            kept.len()
        )));
    }
    if kept.len() < n {
        notes.push(format!(
            "{} of the {n} points were left out: their closest distance was no nearer than \
             that of a point farther out (the amplitude followed z_c)",
            n - kept.len()
        ));
    }
    kept.reverse();
    let mut points = kept;
    let n = points.len();
    let d: Vec<f64> = points.iter().map(|p| p.closest_m).collect();
    let a: Vec<f64> = points.iter().map(|p| p.amplitude_m).collect();
    let shift: Vec<f64> = points.iter().map(|p| p.frequency_shift).collect();
    // The data hold some ten digits: a force below 1e-9 kA₀, an energy below 1e-9 of
    // the free cantilever's loss per cycle πkA₀²/Q, is their round-off, not a result.
    let force_floor = 1e-9 * probe.stiffness_n_m * probe.free_amplitude_m;
    let energy_floor =
        1e-9 * PI * probe.stiffness_n_m * probe.free_amplitude_m.powi(2) / probe.quality;
    let resolved = |v: f64, floor: f64| if v.abs() <= floor { 0.0 } else { v };
    for (p, f) in points
        .iter_mut()
        .zip(inversion.force(probe.stiffness_n_m, &d, &a, &shift))
    {
        p.force_n = resolved(f, force_floor);
        p.in_phase_force_n = resolved(p.in_phase_force_n, force_floor);
        p.e_ts_j = resolved(p.e_ts_j, energy_floor);
    }
    let largest_loss = points.iter().fold(0.0f64, |m, p| m.max(p.e_ts_j));
    let free_loss = energy_floor * 1e9;
    if largest_loss > 1e-3 * free_loss {
        notes.push(format!(
            "the tip–sample interaction dissipates (E_ts up to {largest_loss:.3e} J, {:.1} % \
             of the free cantilever's loss per cycle): the force reconstructed is the part \
             in phase with the motion — the mean of the approach and retract forces, and \
             that only where every orbit follows the same loop. A law that jumps into \
             contact (adhesion hysteresis) loses its loop only once the jump is reached, so \
             the inversion puts the loop's force into a spike near the jump-in distance: \
             read the force there as the loss's signature, not as a force",
            100.0 * largest_loss / free_loss
        ));
    }
    let largest = shift.iter().fold(0.0f64, |m, s| m.max(s.abs()));
    let far_end_shift_ratio = if largest > 0.0 {
        shift[n - 1].abs() / largest
    } else {
        0.0
    };
    if far_end_shift_ratio > 0.01 {
        notes.push(format!(
            "the curve's farthest point still feels the sample (its frequency shift is \
             {:.1} % of the largest): the force beyond it, taken as zero, is not, and every \
             reconstructed force is off by what it leaves out — start the curve farther out",
            100.0 * far_end_shift_ratio
        ));
    }
    if !with_mean_deflection {
        notes.push(
            "no mean deflection given: the closest distance is z_c − A (off by the static \
             deflection ⟨F_ts⟩/k)"
                .into(),
        );
    }
    Ok(Reconstruction {
        inversion,
        points,
        far_end_shift_ratio,
        notes,
    })
}

/// A law's force −T̂ (repulsive positive, units RΔγ) at separation `alpha_hat` on the way
/// in and on the way out, from a state far from the sample: the approach follows the free branch
/// down to the jump-in separation, the retract the contact branch up to the jump-out one
/// (the paper's loop, for a law with a loop).
pub fn law_branches_hat<L: ForceLaw>(law: &L, alpha_hat: f64) -> (f64, f64) {
    let approach = if alpha_hat > law.jump_in_alpha_hat() {
        Branch::Free
    } else {
        Branch::Contact
    };
    let retract = if alpha_hat < law.jump_out_alpha_hat() {
        Branch::Contact
    } else {
        Branch::Free
    };
    // + 0.0: a force-free branch reads 0, not −0.
    (
        -law.t_hat(alpha_hat, approach) + 0.0,
        -law.t_hat(alpha_hat, retract) + 0.0,
    )
}
