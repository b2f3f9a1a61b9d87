//! The several-mode outputs: `tap --modes` as a table, the approach curve's rows and
//! charts (φ₁ and φ₂ against A₁/A₀₁), and the bimodal contrast table and chart.

use super::chart::{Axis, Chart, Corner, Series, Style};
use crate::analysis::bimodal::{BimodalRow, ModalPoint, PhaseBranch};
use crate::analysis::sweep::Direction;
use crate::dynamics::modes::{ModalObservables, ModeSet, WindowedModes};
use crate::physics::params::ELECTRONVOLT_J;
use serde::Serialize;
use std::fmt::Write as _;

/// The first line of a several-mode state: modes, law, Tabor μ, z_c.
fn heading(s: &mut String, modes: usize, law: &str, tabor_mu: f64, separation_m: f64) {
    let _ = writeln!(
        s,
        "{modes} eigenmodes, {law} law (Tabor μ = {tabor_mu:.3}), z_c = {:.4} nm",
        separation_m * 1e9
    );
}

/// `tap --modes N` for people.
pub fn tap_text(set: &ModeSet, o: &ModalObservables) -> String {
    let mut s = String::new();
    let ev = |j: f64| j / ELECTRONVOLT_J;
    heading(&mut s, o.modes.len(), &o.law, o.tabor_mu, o.separation_m);
    for (mode, asked) in o.modes.iter().skip(1).zip(&set.higher) {
        let moved = mode.resonance_hz / asked.resonance_hz - 1.0;
        let _ = writeln!(
            s,
            "mode {}: resonance {:.6} kHz asked, {:.6} kHz simulated ({:+.3} %: a ratio p/{} \
             of the first drive frequency, so the motion repeats every {} drive periods)",
            mode.mode,
            asked.resonance_hz * 1e-3,
            mode.resonance_hz * 1e-3,
            100.0 * moved,
            o.common_period_periods,
            o.common_period_periods
        );
    }
    let _ = writeln!(
        s,
        "{:>4} {:>12} {:>10} {:>8} {:>9} {:>10} {:>9} {:>10} {:>11} {:>11} {:>11} {:>9}",
        "mode",
        "f (kHz)",
        "k (N/m)",
        "Q",
        "A0 (nm)",
        "A (nm)",
        "A/A0",
        "phi (deg)",
        "E_drive(eV)",
        "E_damp(eV)",
        "E_tip (eV)",
        "balance"
    );
    for m in &o.modes {
        let _ = writeln!(
            s,
            "{:>4} {:>12.4} {:>10.4} {:>8.1} {:>9.4} {:>10.5} {:>9} {:>10.4} {:>11.4} {:>11.4} {:>11.4} {:>9.1e}",
            m.mode,
            m.drive_frequency_hz * 1e-3,
            m.stiffness_n_m,
            m.quality,
            m.free_amplitude_m * 1e9,
            m.amplitude_m * 1e9,
            m.amplitude_ratio.map_or("-".into(), |r| format!("{r:.6}")),
            m.phase_deg,
            ev(m.e_drive_j),
            ev(m.e_damp_j),
            ev(m.e_exchange_j),
            m.energy_balance_rel
        );
    }
    let _ = writeln!(
        s,
        "(energies per first-mode drive period; E_tip = ∮F_ts q̇ᵢ dt, the work the tip force \
         does on the mode: negative where the mode gives energy to the contact)"
    );
    let _ = writeln!(
        s,
        "E_ts = {:.4} eV per first-mode period (adhesion {:.4}, capillary {:.4}); drives − \
         damping − E_ts balance to {:.1e}",
        o.e_ts_ev,
        ev(o.e_ts_adhesion_j),
        ev(o.e_ts_capillary_j),
        o.energy_balance_rel
    );
    let _ = writeln!(
        s,
        "in contact {:.2} % of the time, {} jump(s) in per first-mode period; mean force \
         {:.4} nN",
        100.0 * o.contact_fraction,
        o.jumps_in,
        o.mean_force_n * 1e9
    );
    let largest = o
        .floquet_multipliers
        .iter()
        .map(|m| m[0].hypot(m[1]))
        .fold(0.0f64, f64::max);
    let _ = writeln!(
        s,
        "a periodic orbit of {} drive periods, {} (largest Floquet multiplier |μ| = {:.6}); \
         returns to {:.1e} of each mode's free motion",
        o.common_period_periods,
        if o.stable { "stable" } else { "UNSTABLE" },
        largest,
        o.return_distance_rel
    );
    s
}

/// `tap --modes` for drives with no common period: the window averages, each with its
/// standard error.
pub fn windowed_text(set: &ModeSet, o: &WindowedModes) -> String {
    let mut s = String::new();
    // A standard error of 0: the batch means agree to round-off.
    let pm = |v: String, e: f64| {
        if e > 0.0 {
            format!("{v} ± {e:.1e}")
        } else {
            v
        }
    };
    let ev = |j: f64| j / ELECTRONVOLT_J;
    heading(&mut s, o.modes.len(), &o.law, o.tabor_mu, o.separation_m);
    let ratios: Vec<String> = o
        .modes
        .iter()
        .skip(1)
        .map(|m| {
            format!(
                "{:.6}",
                m.drive_frequency_hz / o.modes[0].drive_frequency_hz
            )
        })
        .collect();
    let _ = writeln!(
        s,
        "drive frequency ratios {} have no common period (no p/q, q ≤ 32, within the \
         tolerance {}): the motion is not periodic. Time averages over whole periods of \
         each mode, weighted across each of {} windows of {} first-mode periods (± the \
         standard error of the windows' values; none where they agree to round-off), \
         started from the one-mode steady state with the higher modes' free motion on \
         top: another start may find another attractor.",
        ratios.join(", "),
        set.ratio_tolerance,
        o.windows,
        o.window_periods
    );
    let _ = writeln!(
        s,
        "{:>4} {:>12} {:>10} {:>8} {:>9} {:>21} {:>21} {:>11} {:>11} {:>21}",
        "mode",
        "f (kHz)",
        "k (N/m)",
        "Q",
        "A0 (nm)",
        "A/A0",
        "phi (deg)",
        "E_drive(eV)",
        "E_damp(eV)",
        "E_tip (eV)"
    );
    for m in &o.modes {
        let ratio = match (m.amplitude_ratio, m.amplitude_ratio_std_err) {
            (Some(r), Some(e)) => pm(format!("{r:.6}"), e),
            _ => pm(
                format!("{:.5} nm", m.amplitude_m * 1e9),
                m.amplitude_std_err_m * 1e9,
            ),
        };
        let _ = writeln!(
            s,
            "{:>4} {:>12.4} {:>10.4} {:>8.1} {:>9.4} {:>21} {:>21} {:>11.4} {:>11.4} {:>21}",
            m.mode,
            m.drive_frequency_hz * 1e-3,
            m.stiffness_n_m,
            m.quality,
            m.free_amplitude_m * 1e9,
            ratio,
            pm(format!("{:.4}", m.phase_deg), m.phase_std_err_deg),
            ev(m.e_drive_j),
            ev(m.e_damp_j),
            pm(
                format!("{:.4}", ev(m.e_exchange_j)),
                ev(m.e_exchange_std_err_j)
            ),
        );
    }
    let _ = writeln!(
        s,
        "(energies per first-mode drive period; E_tip = ∫F_ts q̇ᵢ dt, the work the tip force \
         does on the mode)"
    );
    let _ = writeln!(
        s,
        "E_ts = {} eV per first-mode period (adhesion {:.4}, capillary {:.4}); drives − \
         damping − E_ts = {:.1e} of the drives' work (the modes' stored energy differs at \
         the window's ends)",
        pm(format!("{:.4}", o.e_ts_ev), ev(o.e_ts_std_err_j)),
        ev(o.e_ts_adhesion_j),
        ev(o.e_ts_capillary_j),
        o.energy_balance_rel
    );
    let _ = writeln!(
        s,
        "in contact {:.2} % of the time, {:.3} jump(s) in per first-mode period; mean force \
         {:.4} nN",
        100.0 * o.contact_fraction,
        o.jumps_in,
        o.mean_force_n * 1e9
    );
    let _ = writeln!(
        s,
        "averaged over {:.0} first-mode periods, {:.0} integrated{}",
        o.periods_averaged,
        o.periods_integrated,
        if o.converged {
            String::new()
        } else {
            " — NOT converged: the budget (of drive periods or integration steps) ran out before every \
             error was below the average tolerance"
                .to_string()
        }
    );
    s
}

/// One point of a several-mode approach curve, flat (a CSV row).
#[derive(Debug, Clone, Serialize)]
pub struct ModalRow {
    /// z_c, m.
    pub separation_m: f64,
    /// approach or retract.
    pub direction: &'static str,
    /// A₁/A₀₁.
    pub amplitude1_ratio: Option<f64>,
    /// φ₁, degrees.
    pub phase1_deg: Option<f64>,
    /// A₂/A₀₂.
    pub amplitude2_ratio: Option<f64>,
    /// φ₂, degrees.
    pub phase2_deg: Option<f64>,
    /// A₃/A₀₃ (three modes).
    pub amplitude3_ratio: Option<f64>,
    /// φ₃, degrees.
    pub phase3_deg: Option<f64>,
    /// E_ts per first-mode period, J.
    pub e_ts_j: Option<f64>,
    /// Work of the tip force on mode 1 and 2 per first-mode period, J.
    pub e_tip1_j: Option<f64>,
    /// On mode 2.
    pub e_tip2_j: Option<f64>,
    /// Fraction of the time in contact.
    pub contact_fraction: Option<f64>,
    /// Whether the orbit is stable.
    pub stable: Option<bool>,
    /// Why there is no state.
    pub note: Option<String>,
}

/// The rows of an approach curve.
pub fn rows(points: &[(ModalPoint, Direction)]) -> Vec<ModalRow> {
    points
        .iter()
        .map(|(p, d)| {
            let s = p.state.as_ref();
            let mode = |i: usize| s.and_then(|s| s.modes.get(i));
            ModalRow {
                separation_m: p.separation_m,
                direction: match d {
                    Direction::Approach => "approach",
                    Direction::Retract => "retract",
                },
                amplitude1_ratio: mode(0).and_then(|m| m.amplitude_ratio),
                phase1_deg: mode(0).map(|m| m.phase_deg),
                amplitude2_ratio: mode(1).and_then(|m| m.amplitude_ratio),
                phase2_deg: mode(1).map(|m| m.phase_deg),
                amplitude3_ratio: mode(2).and_then(|m| m.amplitude_ratio),
                phase3_deg: mode(2).map(|m| m.phase_deg),
                e_ts_j: s.map(|s| s.e_ts_j),
                e_tip1_j: mode(0).map(|m| m.e_exchange_j),
                e_tip2_j: mode(1).map(|m| m.e_exchange_j),
                contact_fraction: s.map(|s| s.contact_fraction),
                stable: s.map(|s| s.stable),
                note: p.note.clone(),
            }
        })
        .collect()
}

/// A value read off a row.
type Column<'a> = &'a dyn Fn(&ModalRow) -> Option<f64>;

/// The approach curve's charts: φ₁ and φ₂ against A₁/A₀₁, then A₁/A₀₁ and A₂/A₀₂ and
/// E_ts against z_c; approach and retract apart.
pub fn approach_charts(rows: &[ModalRow], title: &str) -> Vec<Chart> {
    // A point without a state (no orbit of the common period) breaks the line there.
    let pick = |dir: &str, f: &dyn Fn(&ModalRow) -> Option<(f64, f64)>| -> Vec<(f64, f64)> {
        rows.iter()
            .filter(|r| r.direction == dir)
            .map(|r| f(r).unwrap_or((f64::NAN, f64::NAN)))
            .collect()
    };
    let series =
        |dir: &str, name: &str, color: usize, f: &dyn Fn(&ModalRow) -> Option<(f64, f64)>| {
            let style = if dir == "approach" {
                Style::Line
            } else {
                Style::Dashed
            };
            Series::new(&format!("{name}, {dir}"), pick(dir, f), style, color)
        };
    let dirs = ["approach", "retract"];
    let with = |x: &dyn Fn(&ModalRow) -> Option<f64>, ys: &[(&str, Column)]| {
        let mut out = Vec::new();
        for dir in dirs {
            for (c, (name, y)) in ys.iter().enumerate() {
                let s = series(dir, name, c, &|r| Some((x(r)?, y(r)?)));
                if s.points.iter().any(|p| p.0.is_finite()) {
                    out.push(s);
                }
            }
        }
        out
    };
    let a1 = |r: &ModalRow| r.amplitude1_ratio;
    let z = |r: &ModalRow| Some(r.separation_m * 1e9);
    let phases = with(&a1, &[("φ₁", &|r| r.phase1_deg), ("φ₂", &|r| r.phase2_deg)]);
    let amplitudes = with(&z, &[("A₁/A₀₁", &a1), ("A₂/A₀₂", &|r| r.amplitude2_ratio)]);
    let dissipation = with(&z, &[("E_ts", &|r| r.e_ts_j.map(|e| e / ELECTRONVOLT_J))]);
    let gaps = if rows.iter().any(|r| r.note.is_some()) {
        " (gaps: no orbit of the common period)"
    } else {
        ""
    };
    let chart = |name: &str, t: &str, x: Axis, y: Axis, series: Vec<Series>| Chart {
        name: name.into(),
        title: format!("{title}: {t}{gaps}"),
        x,
        y,
        legend: Corner::quietest(&series),
        series,
        labels: Vec::new(),
    };
    vec![
        chart(
            "phases",
            "phase of each mode vs the first mode's amplitude",
            Axis::linear("A₁/A₀₁", "amplitude1_ratio"),
            Axis::linear("phase lag (deg)", "phase_deg"),
            phases,
        ),
        chart(
            "amplitudes",
            "amplitudes vs rest separation",
            Axis::linear("z_c (nm)", "separation_nm"),
            Axis::linear("A/A₀ of the mode", "amplitude_ratio"),
            amplitudes,
        ),
        chart(
            "dissipation",
            "energy dissipated vs rest separation",
            Axis::linear("z_c (nm)", "separation_nm"),
            Axis::linear("E_ts per first-mode cycle (eV)", "e_ts_ev"),
            dissipation,
        ),
    ]
}

/// The bimodal contrast for people.
pub fn contrast_text(rows: &[BimodalRow]) -> String {
    let mut s = String::new();
    let Some(first) = rows.first() else {
        return s;
    };
    let names = &first.materials;
    let _ = write!(s, "{:>8} {:>7} {:>10}", "law", "A1/A01", "branch");
    for n in names {
        let _ = write!(
            s,
            " {:>12} {:>12}",
            format!("phi1 {n}"),
            format!("phi2 {n}")
        );
    }
    let _ = writeln!(s, " {:>10} {:>10}", "d_phi1", "d_phi2");
    let f = |v: Option<f64>, w: usize, p: usize| {
        v.map_or(format!("{:>w$}", "-"), |v| format!("{v:>w$.p$}"))
    };
    for r in rows {
        let _ = write!(
            s,
            "{:>8} {:>7.3} {:>10}",
            r.law,
            r.setpoint,
            r.branch.to_string()
        );
        for (p1, p2) in r.phase1_deg.iter().zip(&r.phase2_deg) {
            let _ = write!(s, " {} {}", f(*p1, 12, 4), f(*p2, 12, 4));
        }
        let _ = writeln!(
            s,
            " {} {}",
            f(r.delta_phase1_deg, 10, 4),
            f(r.delta_phase2_deg, 10, 4)
        );
    }
    let _ = writeln!(
        s,
        "(φ in degrees; d_phi = φ({}) − φ({}) between states on the same branch; branch: the \
         first mode's, attractive with φ₁ above the free phase; where both hold the setpoint \
         they coexist, and which one an AFM images on depends on how it got there)",
        names.last().map_or("", String::as_str),
        names.first().map_or("", String::as_str)
    );
    for r in rows {
        for (name, note) in r.materials.iter().zip(&r.notes) {
            if let Some(note) = note {
                let _ = writeln!(
                    s,
                    "note: {} law, A1/A01 = {}, {}, {name}: {note}",
                    r.law, r.setpoint, r.branch
                );
            }
        }
    }
    s
}

/// The bimodal contrast charts, one per branch: Δφ₂ (and Δφ₁) against the setpoint, a
/// line per law.
pub fn contrast_charts(rows: &[BimodalRow], laws: &[String]) -> Vec<Chart> {
    let names = rows.first().map_or(Vec::new(), |r| r.materials.clone());
    let mut charts = Vec::new();
    for branch in [PhaseBranch::Repulsive, PhaseBranch::Attractive] {
        if !rows.iter().any(|r| r.branch == branch) {
            continue;
        }
        let mut series = Vec::new();
        // The attractive branch holds few setpoints, often not neighbours: markers.
        let (second, first) = match branch {
            PhaseBranch::Repulsive => (Style::Line, Style::Dashed),
            PhaseBranch::Attractive => (Style::Markers, Style::Squares),
        };
        for (c, law) in laws.iter().enumerate() {
            let of_law = || {
                rows.iter()
                    .filter(move |r| &r.law == law && r.branch == branch)
            };
            for (name, style, pick) in [
                (
                    "Δφ₂",
                    second,
                    (|r: &BimodalRow| r.delta_phase2_deg) as fn(_) -> _,
                ),
                ("Δφ₁", first, |r: &BimodalRow| r.delta_phase1_deg),
            ] {
                let points: Vec<(f64, f64)> = of_law()
                    .filter_map(|r| Some((r.setpoint, pick(r)?)))
                    .collect();
                if !points.is_empty() {
                    series.push(Series::new(&format!("{name}, {law}"), points, style, c));
                }
            }
        }
        if series.is_empty() && !charts.is_empty() {
            continue;
        }
        charts.push(Chart {
            name: format!("bimodal_contrast_{branch}"),
            title: format!(
                "bimodal contrast {} − {}, {branch} branch: second mode ({}), first ({})",
                names.last().map_or("", String::as_str),
                names.first().map_or("", String::as_str),
                if second == Style::Line {
                    "solid"
                } else {
                    "circles"
                },
                if first == Style::Dashed {
                    "dashed"
                } else {
                    "squares"
                },
            ),
            x: Axis::linear("first-mode setpoint A₁/A₀₁", "amplitude1_ratio"),
            y: Axis::linear("phase contrast Δφ (deg)", "delta_phase_deg"),
            legend: Corner::quietest(&series),
            series,
            labels: Vec::new(),
        });
    }
    charts
}

/// A several-mode map's heat maps: φ₁, φ₂, A₂/A₀₂ and E_ts over (Δγ, E*).
pub fn map_heat_maps(
    title: &str,
    works: &[f64],
    moduli: &[f64],
    cells: &[crate::analysis::bimodal::ModalCell],
) -> Vec<super::heatmap::HeatMap> {
    use super::heatmap::HeatMap;
    use crate::analysis::bimodal::ModalCell;
    let panel = |what: &str, label: &str, value: &dyn Fn(&ModalCell) -> Option<f64>| {
        HeatMap::parameter_grid(
            (
                format!("{title}: {what}"),
                label,
                "no periodic state, or law n/a",
            ),
            (works, moduli),
            cells
                .chunks(works.len())
                .map(|row| row.iter().map(|c| value(c).map(|v| (v, true))).collect())
                .collect(),
        )
    };
    vec![
        panel("second-mode phase", "φ₂ (deg)", &|c| c.phase2_deg),
        panel("first-mode phase", "φ₁ (deg)", &|c| c.phase1_deg),
        panel("second-mode amplitude", "A₂/A₀₂", &|c| {
            c.amplitude2_ratio
        }),
        panel(
            "energy dissipated",
            "E_ts per first-mode cycle (eV)",
            &|c| c.e_ts_j.map(|e| e / ELECTRONVOLT_J),
        ),
    ]
}
