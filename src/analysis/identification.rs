//! Identification curves of the dissipation mechanism: the energy each mechanism
//! dissipates per drive cycle, normalized by its largest value over a sweep, against the
//! amplitude ratio A/A₀ (García, Gómez, Martínez et al., Phys. Rev. Lett. 97, 016103
//! (2006)). The shape tells the mechanisms apart: adhesion hysteresis — a loop traversed
//! whole on every touch — steps up to a plateau once the tip reaches the jump-in, while
//! a viscous sample dissipates most at an intermediate amplitude, where the tip indents
//! deep enough and still moves fast. A shape is a property of the mechanism: for
//! adhesion hysteresis the plateau does not move with A₀, k or Q (Gómez & García,
//! Ultramicroscopy 110, 626 (2010)). Not in the paper.

use crate::analysis::sweep::SweepPoint;
use crate::dynamics::observables::TapObservables;
use serde::Serialize;

/// A dissipation mechanism (a share of E_ts), or all of them together.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mechanism {
    /// E_ts itself.
    All,
    /// The contact law's own hysteresis (its branches' work functions).
    Adhesion,
    /// A viscous sample (Kelvin–Voigt).
    Viscous,
    /// A capillary neck.
    Capillary,
}

impl Mechanism {
    /// Every mechanism, E_ts first.
    pub const ALL: [Mechanism; 4] = [
        Mechanism::All,
        Mechanism::Adhesion,
        Mechanism::Viscous,
        Mechanism::Capillary,
    ];

    /// What a legend calls it.
    pub fn label(self) -> &'static str {
        match self {
            Mechanism::All => "E_ts, all mechanisms",
            Mechanism::Adhesion => "adhesion hysteresis",
            Mechanism::Viscous => "viscous sample",
            Mechanism::Capillary => "capillary neck",
        }
    }

    /// Its energy per drive period at a setpoint (J).
    pub fn energy_j(self, o: &TapObservables) -> f64 {
        match self {
            Mechanism::All => o.e_ts_j,
            Mechanism::Adhesion => o.e_ts_adhesion_j,
            Mechanism::Viscous => o.e_ts_viscous_j,
            Mechanism::Capillary => o.e_ts_capillary_j,
        }
    }
}

/// Each mechanism's energy at one setpoint over its largest in the sweep, E/E_max;
/// `None` for a mechanism that dissipates nothing anywhere in the sweep.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Normalized {
    /// E_ts/E_ts,max.
    pub e_ts_norm: Option<f64>,
    /// The adhesion hysteresis's share over its largest.
    pub e_ts_adhesion_norm: Option<f64>,
    /// The viscous sample's share over its largest.
    pub e_ts_viscous_norm: Option<f64>,
    /// The capillary neck's share over its largest.
    pub e_ts_capillary_norm: Option<f64>,
}

impl Normalized {
    /// E/E_max of `mechanism`.
    pub fn of(&self, mechanism: Mechanism) -> Option<f64> {
        match mechanism {
            Mechanism::All => self.e_ts_norm,
            Mechanism::Adhesion => self.e_ts_adhesion_norm,
            Mechanism::Viscous => self.e_ts_viscous_norm,
            Mechanism::Capillary => self.e_ts_capillary_norm,
        }
    }
}

/// The identification curves of a sweep: at every setpoint of `points`, each
/// mechanism's energy per drive period over its largest at any setpoint of the sweep.
pub fn normalize(points: &[SweepPoint]) -> Vec<Normalized> {
    let largest = Mechanism::ALL.map(|m| {
        let e_max = points
            .iter()
            .map(|p| m.energy_j(&p.observables))
            .filter(|e| e.is_finite())
            .fold(0.0, f64::max);
        (e_max > 0.0).then_some(e_max)
    });
    points
        .iter()
        .map(|p| {
            let [all, adhesion, viscous, capillary] = [0, 1, 2, 3].map(|i| {
                largest[i].map(|e_max| Mechanism::ALL[i].energy_j(&p.observables) / e_max)
            });
            Normalized {
                e_ts_norm: all,
                e_ts_adhesion_norm: adhesion,
                e_ts_viscous_norm: viscous,
                e_ts_capillary_norm: capillary,
            }
        })
        .collect()
}
