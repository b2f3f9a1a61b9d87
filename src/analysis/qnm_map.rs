//! Maps of off-resonance tapping's QNM channels over material parameters: every cell of
//! a (Δγ, E*) grid solved at one peak-force setpoint ([`at_setpoint`]), as a PeakForce
//! QNM image of a blend of those materials would read them.

use crate::dynamics::setup::{Numerics, TapSetup};
use crate::error::{Error, Result};
use crate::instrument::peakforce::{Modulation, at_setpoint};
use crate::instrument::qnm::Analysis;
use serde::{Deserialize, Serialize};

/// One cell of a QNM map (None where the cell has no answer: `note` says why).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QnmCell {
    /// Δγ, J/m².
    pub work_of_adhesion_j_m2: f64,
    /// E*, Pa.
    pub modulus_pa: f64,
    /// Tabor parameter μ, eq. (2).
    pub tabor_mu: f64,
    /// The rest separation holding the setpoint, m.
    pub separation_m: Option<f64>,
    /// How the settled motion repeats ("period-1", "period-n", "irregular").
    pub regime: Option<String>,
    /// The channels of the settled motion's first cycle: peak force (N), adhesion (N),
    /// dissipation (J), deformation (m), DMT modulus (Pa).
    pub peak_force_n: Option<f64>,
    /// Adhesion, N.
    pub adhesion_n: Option<f64>,
    /// Dissipation, J.
    pub dissipation_j: Option<f64>,
    /// Deformation, m.
    pub deformation_m: Option<f64>,
    /// DMT modulus fitted to the retract, Pa.
    pub dmt_modulus_pa: Option<f64>,
    /// Why a cell is empty.
    pub note: Option<String>,
}

/// The QNM channels of the cells `cells` (indices into the (Δγ, E*) grid, Δγ fastest)
/// at the peak-force setpoint `setpoint_n` (in parallel on `threads`, 0: every core). A
/// cell the setpoint cannot be reached at, or whose law does not apply, is listed with
/// why.
#[allow(clippy::too_many_arguments)]
pub fn map_cells(
    setup: &TapSetup,
    numerics: &Numerics,
    (works_j_m2, moduli_pa): (&[f64], &[f64]),
    cells: &[usize],
    threads: usize,
    progress: impl Fn() + Sync,
    modulation: &Modulation,
    analysis: &Analysis,
    setpoint_n: f64,
) -> Result<Vec<QnmCell>> {
    modulation.check(&setup.cantilever)?;
    analysis.check()?;
    crate::analysis::sweep::over_grid(
        setup,
        (works_j_m2, moduli_pa),
        cells,
        threads,
        progress,
        |s, (w, e)| {
            let empty = |note: String| QnmCell {
                work_of_adhesion_j_m2: w,
                modulus_pa: e,
                tabor_mu: s.contact.tabor_mu(),
                separation_m: None,
                regime: None,
                peak_force_n: None,
                adhesion_n: None,
                dissipation_j: None,
                deformation_m: None,
                dmt_modulus_pa: None,
                note: Some(note),
            };
            Ok(
                match at_setpoint(s, numerics, modulation, analysis, setpoint_n) {
                    Ok(c) => {
                        let ch = c.cycles[0];
                        QnmCell {
                            work_of_adhesion_j_m2: w,
                            modulus_pa: e,
                            tabor_mu: s.contact.tabor_mu(),
                            separation_m: Some(c.separation_m),
                            regime: Some(c.regime),
                            peak_force_n: Some(ch.peak_force_n),
                            adhesion_n: Some(ch.adhesion_n),
                            dissipation_j: Some(ch.dissipation_j),
                            deformation_m: Some(ch.deformation_m),
                            dmt_modulus_pa: ch.dmt_modulus_pa,
                            note: None,
                        }
                    }
                    Err(why @ (Error::NotApplicable(_) | Error::Numerical(_))) => {
                        empty(why.to_string())
                    }
                    Err(other) => return Err(other),
                },
            )
        },
    )
}
