//! What `tapsim reconstruct` draws: the reconstructed force against the closest
//! distance, with the law that made a simulated curve beside it, and the energy
//! dissipated per cycle.

use super::chart::{Axis, Chart, Corner, Series, Style};

/// One reconstructed point, in the plotted units.
#[derive(Debug, Clone, Copy)]
pub struct PlotRow {
    /// Closest distance D, nm.
    pub closest_nm: f64,
    /// Reconstructed force, nN.
    pub force_nn: f64,
    /// E_ts per cycle, eV.
    pub e_ts_ev: f64,
}

/// A law's force over a grid of distances, nN: on the way in and on the way out.
#[derive(Debug, Clone)]
pub struct LawCurves {
    /// The law's name.
    pub name: String,
    /// Distances, nm.
    pub closest_nm: Vec<f64>,
    /// Force on the approach, nN.
    pub approach_nn: Vec<f64>,
    /// Force on the retract, nN.
    pub retract_nn: Vec<f64>,
}

/// The force panel and the dissipation panel; `loss_from` names the channel the loss
/// was read from (the phase in AM, the excitation in FM).
pub fn charts(
    rows: &[PlotRow],
    source: &str,
    law: Option<&LawCurves>,
    loss_from: &str,
) -> Vec<Chart> {
    let reconstructed = format!("reconstructed from {source}");
    let x = || Axis::linear("closest distance D = z_c + z̄ − A (nm)", "closest_nm");
    let mut series = Vec::new();
    if let Some(l) = law {
        let line = |ys: &[f64]| -> Vec<(f64, f64)> {
            l.closest_nm
                .iter()
                .copied()
                .zip(ys.iter().copied())
                .collect()
        };
        if l.approach_nn == l.retract_nn {
            series.push(Series::new(
                &format!("{} law (the force that made the curve)", l.name),
                line(&l.approach_nn),
                Style::Line,
                1,
            ));
        } else {
            let mean: Vec<f64> = l
                .approach_nn
                .iter()
                .zip(&l.retract_nn)
                .map(|(a, b)| 0.5 * (a + b))
                .collect();
            series.push(Series::new(
                &format!("{} law, approach", l.name),
                line(&l.approach_nn),
                Style::Line,
                1,
            ));
            series.push(Series::new(
                &format!("{} law, retract", l.name),
                line(&l.retract_nn),
                Style::Dashed,
                2,
            ));
            series.push(Series::new(
                &format!("{} law, mean of the two", l.name),
                line(&mean),
                Style::Dotted,
                3,
            ));
        }
    }
    series.push(Series::new(
        &reconstructed,
        rows.iter().map(|r| (r.closest_nm, r.force_nn)).collect(),
        Style::Markers,
        0,
    ));
    let force = Chart {
        name: "force".into(),
        title: "tip–sample force against the closest distance".into(),
        x: x(),
        y: Axis::linear("force F_ts (nN, repulsive > 0)", "force_nn"),
        legend: Corner::quietest(&series),
        series,
        labels: Vec::new(),
    };
    let loss = vec![Series::new(
        &format!("E_ts from the {loss_from} ({source})"),
        rows.iter().map(|r| (r.closest_nm, r.e_ts_ev)).collect(),
        Style::Markers,
        0,
    )];
    let dissipation = Chart {
        name: "dissipation".into(),
        title: "energy dissipated per cycle against the closest distance".into(),
        x: x(),
        y: Axis::linear("E_ts (eV)", "e_ts_ev"),
        legend: Corner::quietest(&loss),
        series: loss,
        labels: Vec::new(),
    };
    vec![force, dissipation]
}
