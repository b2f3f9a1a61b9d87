//! Phase contrast between materials: the same cantilever and amplitude setpoints on two
//! or more samples, for several force laws side by side — how much contrast the classic
//! JKR law overstates against the hybrid and the exact Lennard-Jones law.

use crate::analysis::identification::Mechanism;
use crate::analysis::setpoint;
use crate::analysis::sweep::{self, Direction, SweepPoint};
use crate::dynamics::setup::{Numerics, Prepared, TapSetup};
use crate::error::{Error, Result};
use crate::instrument::noise::NoiseRequest;
use crate::physics::law::LawKind;
use serde::Serialize;

/// A named material: the whole setup and numerics of its sweeps (the application builds
/// them from a base and the material's own inputs).
#[derive(Debug, Clone)]
pub struct Material {
    /// Name used in tables and legends.
    pub name: String,
    /// The setup (its law is replaced by each law compared).
    pub setup: TapSetup,
    /// Numerics of each setpoint ([`sweep::sweep_numerics`]).
    pub numerics: Numerics,
}

pub use crate::analysis::setpoint::PhaseBranch;

/// φ at one amplitude setpoint on one branch for every material, and the contrast.
#[derive(Debug, Clone, Serialize)]
pub struct ContrastRow {
    /// Force law.
    pub law: String,
    /// The materials, in the order of `phase_deg`.
    pub materials: Vec<String>,
    /// Amplitude setpoint A/A₀.
    pub amplitude_ratio: f64,
    /// The branch the phases belong to (where a setpoint is bistable, both have a row).
    pub branch: PhaseBranch,
    /// φ of each material (degrees), in the order given; null where the material has no
    /// steady state on this branch at this setpoint.
    pub phase_deg: Vec<Option<f64>>,
    /// The motion each φ comes from: "period-1" from the continuation of the period-1
    /// family (stable orbits), else the regime of the approach-curve points it is
    /// interpolated between ("irregular", "period-3", …).
    pub regime: Vec<Option<String>>,
    /// Whether each φ comes from steady states that met their tolerance (both ends of
    /// the interpolation).
    pub converged: Vec<Option<bool>>,
    /// Whether either steady state each φ is interpolated between grazes a switch
    /// ([`crate::dynamics::grazing`]): its touch pattern, and so φ, is then set by
    /// perturbations below the thermal motion.
    pub grazing: Vec<Option<bool>>,
    /// φ(last material) − φ(first material), degrees, where both are on this branch.
    pub delta_phase_deg: Option<f64>,
    /// The rest separation z_c at which each material holds the setpoint on this branch
    /// (m): where the z feedback puts the sample.
    pub separation_m: Vec<Option<f64>>,
    /// The apparent height of the last material over the first, z_c(last) − z_c(first)
    /// (m): over a flat sample of both, the feedback moves the sample by this much
    /// between them, and the topography shows a step that is not there.
    pub apparent_height_m: Option<f64>,
    /// E_ts per cycle of each material (J), interpolated as φ is; null where φ is.
    pub e_ts_j: Vec<Option<f64>>,
    /// Its adhesion-hysteresis share (J).
    pub e_ts_adhesion_j: Vec<Option<f64>>,
    /// Its viscous share (J).
    pub e_ts_viscous_j: Vec<Option<f64>>,
    /// Its capillary share (J).
    pub e_ts_capillary_j: Vec<Option<f64>>,
    /// The thermal noise asked for (null: none).
    pub noise: Option<NoiseRequest>,
    /// The standard deviation of each material's lock-in phase at that noise (degrees;
    /// the linear theory about its stable period-1 orbit), null where none was asked
    /// for or its φ does not come from such an orbit.
    pub sigma_phase_deg: Vec<Option<f64>>,
    /// |Δφ|/√(σ_first² + σ_last²): the contrast over the noise of the difference of one
    /// reading on each material; null where either σ is.
    pub contrast_to_noise: Option<f64>,
}

/// One steady state at an amplitude setpoint.
#[derive(Debug, Clone)]
struct AtSetpoint {
    branch: PhaseBranch,
    separation_m: f64,
    phase_deg: f64,
    /// E_ts per mechanism ([`Mechanism::ALL`]), J.
    e_ts_j: [f64; 4],
    regime: String,
    converged: bool,
    grazing: bool,
    /// σ_φ (degrees) at the noise asked for, on a stable period-1 orbit.
    sigma_phase_deg: Option<f64>,
}

/// z_c, φ and E_ts per mechanism interpolated linearly in A/A₀ at A/A₀ = `r` between
/// two approach points, if they bracket it.
fn crossing(pa: &SweepPoint, pb: &SweepPoint, r: f64) -> Option<(f64, f64, [f64; 4])> {
    let (a, b) = (&pa.observables, &pb.observables);
    let (ra, rb) = (a.amplitude_ratio, b.amplitude_ratio);
    ((ra - r) * (rb - r) <= 0.0 && ra != rb).then(|| {
        let t = (r - ra) / (rb - ra);
        let at = |va: f64, vb: f64| va + t * (vb - va);
        (
            at(pa.separation_m, pb.separation_m),
            at(a.phase_deg, b.phase_deg),
            Mechanism::ALL.map(|m| at(m.energy_j(a), m.energy_j(b))),
        )
    })
}

/// The steady states of one material and law at amplitude setpoint `r`: every stable
/// period-1 orbit of its families there, solved exactly ([`setpoint::states_on`]), and,
/// on a branch with none, the approach curve's states (orbits of higher period or
/// irregular motion) interpolated there.
fn states_at(
    p: &Prepared,
    curve: &LawCurve,
    r: f64,
    noise: Option<&NoiseRequest>,
) -> Result<Vec<AtSetpoint>> {
    let mut out: Vec<AtSetpoint> = setpoint::states_on(p, &curve.family, r, None)?
        .into_iter()
        .map(|s| {
            let o = &s.observables;
            let sigma_phase_deg = match noise {
                Some(n) => Some(s.thermal_noise(p, n)?.sigma_phase_deg),
                None => None,
            };
            Ok(AtSetpoint {
                branch: s.branch,
                separation_m: s.separation_m,
                phase_deg: o.phase_deg,
                e_ts_j: Mechanism::ALL.map(|m| m.energy_j(o)),
                regime: o.regime.clone(),
                converged: o.converged,
                grazing: o.grazing,
                sigma_phase_deg,
            })
        })
        .collect::<Result<_>>()?;
    let approach: Vec<&SweepPoint> = curve
        .points
        .iter()
        .filter(|p| p.direction == Direction::Approach)
        .collect();
    for w in approach.windows(2) {
        let (a, b) = (&w[0].observables, &w[1].observables);
        if a.period == Some(1) && b.period == Some(1) {
            continue;
        }
        if let Some((separation_m, phase_deg, e_ts_j)) = crossing(w[0], w[1], r) {
            let branch = PhaseBranch::of(phase_deg, curve.free_phase_deg);
            if !out.iter().any(|s| s.branch == branch) {
                let nearer = if (a.amplitude_ratio - r).abs() < (b.amplitude_ratio - r).abs() {
                    a
                } else {
                    b
                };
                out.push(AtSetpoint {
                    branch,
                    separation_m,
                    phase_deg,
                    e_ts_j,
                    regime: nearer.regime.clone(),
                    converged: a.converged && b.converged,
                    grazing: a.grazing || b.grazing,
                    sigma_phase_deg: None,
                });
            }
        }
    }
    Ok(out)
}

/// The approach curve and the period-1 family of one material under one law.
#[derive(Debug, Clone)]
pub struct LawCurve {
    /// Material name.
    pub material: String,
    /// Force law.
    pub law: LawKind,
    /// The approach points.
    pub points: Vec<SweepPoint>,
    /// The stable period-1 families over the same range ([`setpoint::families`]).
    pub family: Vec<sweep::BranchRecord>,
    /// The material's setup under this law.
    pub setup: TapSetup,
    /// The free oscillator's phase in degrees, atan2(Ω/Q, 1 − Ω²): the border between
    /// the attractive and the repulsive branch.
    pub free_phase_deg: f64,
}

/// Approach curves and period-1 orbit families of every material under every law, and
/// the contrast table at the amplitude setpoints `ratios`: at each, every branch
/// (attractive, repulsive) on which some material has a steady state, with Δφ between
/// materials on the same branch, and with `noise` each phase's thermal noise and the
/// contrast over it. `progress` is told what is being computed.
pub fn contrast(
    materials: &[Material],
    laws: &[LawKind],
    (ratios, points): (&[f64], usize),
    noise: Option<&NoiseRequest>,
    mut progress: impl FnMut(&str),
) -> Result<(Vec<ContrastRow>, Vec<LawCurve>)> {
    contrast_reporting(materials, laws, (ratios, points), noise, &mut progress)
}

/// [`contrast`] compiled once: `progress` is a trait object, so a caller's closure does
/// not copy the whole computation into the caller's program.
fn contrast_reporting(
    materials: &[Material],
    laws: &[LawKind],
    (ratios, points): (&[f64], usize),
    noise: Option<&NoiseRequest>,
    progress: &mut dyn FnMut(&str),
) -> Result<(Vec<ContrastRow>, Vec<LawCurve>)> {
    if materials.len() < 2 {
        return Err(Error::NotApplicable(
            "phase contrast needs at least two materials".into(),
        ));
    }
    if ratios.is_empty() {
        return Err(Error::NotApplicable(
            "phase contrast needs at least one amplitude setpoint".into(),
        ));
    }
    for &r in ratios {
        if !(r > 0.0 && r < 1.0) {
            return Err(Error::InvalidParameter {
                name: "setpoint A/A0",
                value: r,
                reason: "an amplitude setpoint lies between 0 and 1 (the free amplitude)",
            });
        }
    }
    // Every material under every law, independently and in parallel (the same curves
    // on any number of threads), in material-then-law order.
    use rayon::prelude::*;
    progress(&format!(
        "{} materials × {} laws, in parallel",
        materials.len(),
        laws.len()
    ));
    let pairs: Vec<(&Material, LawKind)> = materials
        .iter()
        .flat_map(|m| laws.iter().map(move |&law| (m, law)))
        .collect();
    let curves = pairs
        .par_iter()
        .map(|&(m, law)| {
            let (setup, numerics) = (&m.setup, &m.numerics);
            let a0 = setup.cantilever.free_amplitude_m;
            let ramp = sweep::ramp(1.2 * a0, 0.3 * a0, points, false)?;
            let s = TapSetup {
                law: setup.law.with_kind(law),
                ..setup.clone()
            };
            Ok(LawCurve {
                material: m.name.clone(),
                law,
                points: sweep::approach_curve(&s, numerics, &ramp, |_, _| {})?,
                family: setpoint::families(
                    &Prepared::new(&s, numerics)?,
                    numerics,
                    (1.2 * a0, 0.3 * a0),
                )?,
                free_phase_deg: crate::analysis::setpoint::free_phase_deg(setup),
                setup: s,
            })
        })
        .collect::<Result<Vec<LawCurve>>>()?;
    let mut rows = Vec::new();
    for &law in laws {
        let of_law: Vec<&LawCurve> = materials
            .iter()
            .filter_map(|m| curves.iter().find(|c| c.material == m.name && c.law == law))
            .collect();
        // Each curve's simulation prepared once for all its setpoints.
        let prepared: Vec<Prepared> = of_law
            .iter()
            .zip(materials)
            .map(|(c, m)| Prepared::new(&c.setup, &m.numerics))
            .collect::<Result<_>>()?;
        for &r in ratios {
            let states: Vec<Vec<AtSetpoint>> = of_law
                .iter()
                .zip(&prepared)
                .map(|(c, p)| states_at(p, c, r, noise))
                .collect::<Result<_>>()?;
            for branch in [PhaseBranch::Attractive, PhaseBranch::Repulsive] {
                let on: Vec<Option<&AtSetpoint>> = states
                    .iter()
                    .map(|s| s.iter().find(|a| a.branch == branch))
                    .collect();
                if on.iter().all(Option::is_none) {
                    continue;
                }
                let phase_deg: Vec<Option<f64>> =
                    on.iter().map(|s| s.map(|a| a.phase_deg)).collect();
                let separation_m: Vec<Option<f64>> =
                    on.iter().map(|s| s.map(|a| a.separation_m)).collect();
                let share = |i: usize| -> Vec<Option<f64>> {
                    on.iter().map(|s| s.map(|a| a.e_ts_j[i])).collect()
                };
                let sigma_phase_deg: Vec<Option<f64>> = on
                    .iter()
                    .map(|s| s.and_then(|a| a.sigma_phase_deg))
                    .collect();
                let last = phase_deg.len() - 1;
                rows.push(ContrastRow {
                    law: law.to_string(),
                    materials: of_law.iter().map(|c| c.material.clone()).collect(),
                    amplitude_ratio: r,
                    branch,
                    delta_phase_deg: match (phase_deg[0], phase_deg[phase_deg.len() - 1]) {
                        (Some(first), Some(last)) => Some(last - first),
                        _ => None,
                    },
                    apparent_height_m: match (separation_m[0], separation_m[separation_m.len() - 1])
                    {
                        (Some(first), Some(last)) => Some(last - first),
                        _ => None,
                    },
                    separation_m,
                    regime: on.iter().map(|s| s.map(|a| a.regime.clone())).collect(),
                    e_ts_j: share(0),
                    e_ts_adhesion_j: share(1),
                    e_ts_viscous_j: share(2),
                    e_ts_capillary_j: share(3),
                    converged: on.iter().map(|s| s.map(|a| a.converged)).collect(),
                    grazing: on.iter().map(|s| s.map(|a| a.grazing)).collect(),
                    contrast_to_noise: match (
                        phase_deg[0],
                        phase_deg[last],
                        sigma_phase_deg[0],
                        sigma_phase_deg[last],
                    ) {
                        (Some(a), Some(b), Some(sa), Some(sb)) if sa.hypot(sb) > 0.0 => {
                            Some((b - a).abs() / sa.hypot(sb))
                        }
                        _ => None,
                    },
                    noise: noise.copied(),
                    sigma_phase_deg,
                    phase_deg,
                });
            }
        }
    }
    // A setpoint no material holds under any law on any branch is refused, with the
    // amplitudes the curves do reach.
    let unreached: Vec<String> = ratios
        .iter()
        .filter(|&&r| !rows.iter().any(|row| row.amplitude_ratio == r))
        .map(|r| r.to_string())
        .collect();
    if !unreached.is_empty() {
        let amplitudes = curves
            .iter()
            .flat_map(|c| c.points.iter().map(|p| p.observables.amplitude_ratio));
        let (lo, hi) = amplitudes.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), a| {
            (lo.min(a), hi.max(a))
        });
        return Err(Error::NotApplicable(format!(
            "no material holds the amplitude setpoint A/A₀ = {} under any of the laws, on \
             either branch: their approach curves from 1.2 A₀ in to 0.3 A₀ reach A/A₀ \
             {lo:.3} to {hi:.3}",
            unreached.join(", ")
        )));
    }
    Ok((rows, curves))
}
