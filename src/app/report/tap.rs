//! Reports of a tapping run: a table for people, the trajectory as CSV, and the
//! trajectory charts (deflection and force vs time, force vs separation).

use super::chart::{Axis, Chart, Corner, Label, Series, Style};
use super::display::{fixed, sci};
use crate::analysis::coexist::Search;
use crate::dynamics::attractors::Attractor;
use crate::dynamics::harmonics::Harmonic;
use crate::dynamics::observables::{TapObservables, TapRun, TrajectorySample};
use crate::dynamics::setup::TapSetup;
use crate::error::Result;
use crate::physics::law::Branch;
use crate::physics::params::ELECTRONVOLT_J;
use std::fmt::Write as _;

/// A table of the setup and the observables (and the harmonics, if computed).
pub fn to_text(setup: &TapSetup, run: &TapRun) -> String {
    let o = &run.observables;
    let c = &setup.contact;
    let k = &setup.cantilever;
    let mut s = String::new();
    let mut line = |label: &str, value: String| {
        let _ = writeln!(s, "  {label:<34} {value}");
    };
    line("law", o.law.clone());
    line("tip radius R", format!("{:.4} nm", c.radius_m * 1e9));
    line(
        "composite modulus E*",
        format!("{:.4} GPa", c.modulus_pa * 1e-9),
    );
    line(
        "work of adhesion Δγ",
        format!("{:.4} J/m²", c.work_of_adhesion_j_m2),
    );
    line("LJ range ε", format!("{:.4} nm", c.range_m * 1e9));
    line("Tabor parameter μ (2)", format!("{:.4}", o.tabor_mu));
    line(
        "cantilever k, f₀, Q",
        format!(
            "{} N/m, {:.4} kHz, {}",
            k.stiffness_n_m,
            k.resonance_hz * 1e-3,
            k.quality
        ),
    );
    line(
        "free amplitude A₀, drive f/f₀",
        format!(
            "{:.4} nm, {:.6}",
            k.free_amplitude_m * 1e9,
            o.frequency_ratio
        ),
    );
    line(
        "rest separation z_c",
        format!("{:.4} nm", setup.separation_m * 1e9),
    );
    let _ = writeln!(s, "Steady state");
    let mut line = |label: &str, value: String| {
        let _ = writeln!(s, "  {label:<34} {value}");
    };
    line("motion", motion_text(o));
    line(
        "cycles (converged)",
        format!("{} ({})", o.cycles, if o.converged { "yes" } else { "NO" }),
    );
    let err = |e: Option<f64>, scale: f64, digits: usize| match (o.period, e) {
        (Some(_), _) => String::new(),
        (None, Some(e)) => format!(" ± {:.*e}", digits, e * scale),
        (None, None) => " ± ?".into(),
    };
    line(
        "amplitude A, A/A₀",
        format!(
            "{:.4} nm{}, {:.6}",
            o.amplitude_m * 1e9,
            err(o.amplitude_std_err_m, 1e9, 1),
            o.amplitude_ratio
        ),
    );
    line(
        "phase φ (lock-in)",
        format!("{:.4}°{}", o.phase_deg, err(o.phase_std_err_deg, 1.0, 1)),
    );
    line(
        "phase φ (from energy)",
        format!("{:.4}°", o.phase_from_energy_deg),
    );
    // Energies are round-off below 1e-12 of the drive's work a cycle, forces below
    // 1e-12 of kA₀.
    let energy = o.e_drive_j.abs().max(o.e_damp_j.abs());
    let joules = |e: f64| format!("{} J", sci(e, 4, energy));
    let nanonewtons = |f: f64| {
        let scale = k.stiffness_n_m * k.free_amplitude_m;
        if f.abs() <= 1e-12 * scale {
            "0 nN".to_string()
        } else {
            format!("{} nN", fixed(f * 1e9, 4))
        }
    };
    let e_ts_round_off = sci(o.e_ts_j, 4, energy) == "0";
    line(
        "E_ts per cycle",
        if e_ts_round_off && o.period.is_some() {
            "0 J = 0 eV".into()
        } else {
            format!(
                "{:.4e} J{} = {} eV",
                o.e_ts_j,
                err(o.e_ts_std_err_j, 1.0, 1),
                fixed(o.e_ts_ev, 4)
            )
        },
    );
    if o.e_ts_viscous_j != 0.0 || o.e_ts_capillary_j != 0.0 {
        line(
            "  adhesion/viscous/capillary",
            format!(
                "{}, {}, {}",
                joules(o.e_ts_adhesion_j),
                joules(o.e_ts_viscous_j),
                joules(o.e_ts_capillary_j)
            ),
        );
    }
    line("law's loop area", joules(o.loop_area_j));
    line(
        "E_damp, E_drive",
        format!("{:.4e} J, {:.4e} J", o.e_damp_j, o.e_drive_j),
    );
    line("energy balance error", sci(o.energy_balance_rel, 2, 0.0));
    line("virial ⟨F_ts z⟩", joules(o.virial_j));
    line("mean force", nanonewtons(o.mean_force_n));
    line(
        "peak repulsive / attractive force",
        format!(
            "{} / {}",
            if o.peak_force_n > 0.0 {
                nanonewtons(o.peak_force_n)
            } else {
                "none".into()
            },
            if o.peak_attractive_force_n < 0.0 {
                nanonewtons(o.peak_attractive_force_n)
            } else {
                "none".into()
            }
        ),
    );
    line(
        "min separation",
        format!("{} nm", fixed(o.min_separation_m * 1e9, 4)),
    );
    line("contact fraction", fixed(o.contact_fraction, 4));
    line("jumps into contact per cycle", fixed(o.jumps_in, 4));
    if let Some(margin) = o.grazing_margin_m {
        line(
            "grazing margin",
            format!(
                "{} (thermal rms at 300 K {}, integration {})",
                picometres(margin),
                picometres(run.thermal_rms_m),
                picometres(run.integration_error_m)
            ),
        );
    }
    if let Some(h) = &run.harmonics {
        let amplitudes = |pick: fn(&Harmonic) -> f64, scale: f64| {
            h.iter()
                .take(3)
                .map(|h| fixed(pick(h) * scale, 3))
                .collect::<Vec<_>>()
                .join(", ")
        };
        line(
            "harmonics 2–4 of z (of F_ts)",
            format!(
                "{} pm ({} nN); 2–10 in --json",
                amplitudes(|h| h.deflection_amplitude_m, 1e12),
                amplitudes(|h| h.force_amplitude_n, 1e9)
            ),
        );
    }
    if let Some(g) = run.mean_force_gradient_n_m {
        line(
            "force gradient ⟨∂F_ts/∂z⟩ (orbit)",
            format!(
                "{} N/m (what a small second mode feels: cot φ₂ = −Q₂⟨∂F_ts/∂z⟩/k₂)",
                fixed(g, 4)
            ),
        );
    }
    if o.grazing {
        let _ = writeln!(
            s,
            "note: grazing — a turning point of the separation comes closer to a switch of the \
             force law than the thermal motion (or the integration's resolution): which \
             touches a period makes is decided by perturbations nothing controls, so the \
             state above is one of possibly several{}",
            if o.stable.is_none() && o.period.is_some() {
                "; the orbit's stability rests on the grazing contact"
            } else {
                ""
            }
        );
    }
    if o.contact_fraction == 0.0 && o.jumps_in == 0.0 && o.law != "none" {
        let _ = writeln!(
            s,
            "note: the tip never comes into contact at this rest separation (its closest \
             separation is {:.3} nm): at most the law's long-range attraction acts; bring \
             z_c below about A₀ ({:.3} nm) to tap",
            o.min_separation_m * 1e9,
            k.free_amplitude_m * 1e9
        );
    }
    if let Some(list) = &run.attractors {
        attractors_text(&mut s, list, run.well_defined);
    }
    if !o.converged {
        let _ = writeln!(
            s,
            "note: {}",
            if o.period.is_some() {
                "the periodic orbit did not close to --tolerance within the cycle cap"
            } else {
                "the averages did not reach --average-tolerance within the cycle cap (raise \
                 --max-cycles)"
            }
        );
    }
    s
}

/// A length in pm to three significant digits (below 0.01 pm in scientific form, from
/// 1000 pm on in nm).
fn picometres(m: f64) -> String {
    let pm = m * 1e12;
    if pm.abs() < 0.01 {
        format!("{pm:.1e} pm")
    } else if pm.abs() >= 1000.0 {
        format!("{:.3} nm", pm * 1e-3)
    } else {
        let digits = (2.0 - pm.abs().log10().floor()).max(0.0) as usize;
        format!("{pm:.digits$} pm")
    }
}

/// The attractors reached from several starts, and what their number means.
fn attractors_text(s: &mut String, list: &[Attractor], well_defined: Option<bool>) {
    let starts: usize = list.iter().map(|a| a.count).sum();
    let verdict = match (well_defined, list.len()) {
        (None, _) => "one start",
        (Some(false), 1) => {
            "every start reached one state, but it grazes a switch closer than the \
             thermal motion: the deterministic answer is not defined here (another \
             integrator or tolerance may reach another lock); what an instrument reads \
             is the thermal average, --temperature 300K"
        }
        (Some(false), _) => {
            "the deterministic answer is not defined here: states that graze a switch \
             coexist, their basins finer than the thermal motion (what an instrument \
             reads: --temperature 300K)"
        }
        (Some(true), 1) => "every start reached the same state",
        (Some(true), _) => "coexisting states: which one is reached depends on the history",
    };
    let _ = writeln!(
        s,
        "Attractors from {starts} starts ({} distinct: {verdict})",
        list.len()
    );
    let _ = writeln!(
        s,
        "  {:<12} {:>8} {:>10} {:>10} {:>10}  starts",
        "regime", "touches", "A/A₀", "φ (°)", "E_ts (eV)"
    );
    for a in list {
        let _ = writeln!(
            s,
            "  {:<12} {:>8.4} {:>10.6} {:>10.4} {:>10.4}  {}: {}",
            a.regime,
            a.touch_fraction,
            a.amplitude_ratio,
            a.phase_deg,
            a.e_ts_j / ELECTRONVOLT_J,
            a.count,
            a.starts.join("; ")
        );
    }
}

/// The kind of motion, the periods the values are averaged over, and the stability of a
/// periodic orbit with its largest Floquet multiplier.
fn motion_text(o: &TapObservables) -> String {
    // (A relaxing sample's orbit is marched to: no multipliers are computed.)
    let largest = if o.floquet_multipliers.is_empty() {
        String::new()
    } else {
        let largest = o
            .floquet_multipliers
            .iter()
            .map(|m| m[0].hypot(m[1]))
            .fold(0.0, f64::max);
        format!(", largest |Floquet multiplier| {largest:.4}")
    };
    match (o.stable, o.period) {
        (Some(true), _) if largest.is_empty() => {
            format!("{} (stable: reached by marching)", o.regime)
        }
        (Some(stable), _) => format!(
            "{} ({}{largest})",
            o.regime,
            if stable { "stable" } else { "unstable" }
        ),
        (None, Some(_)) => format!("{} (grazing a switch{largest})", o.regime),
        (None, None) => format!("{}: averages over {} periods", o.regime, o.periods_averaged),
    }
}

/// The trajectory as CSV: t_s, z_m, v_m_s, alpha_m, force_n, branch.
pub fn trajectory_csv(samples: &[TrajectorySample]) -> Result<Vec<u8>> {
    super::records::records_csv(samples)
}

/// Split samples into runs of one branch (so lines do not join across a jump).
fn runs(
    samples: &[TrajectorySample],
    pick: impl Fn(&TrajectorySample) -> (f64, f64),
) -> Vec<(Branch, Vec<(f64, f64)>)> {
    let mut out: Vec<(Branch, Vec<(f64, f64)>)> = Vec::new();
    for s in samples {
        match out.last_mut() {
            Some((b, pts)) if *b == s.branch => pts.push(pick(s)),
            _ => out.push((s.branch, vec![pick(s)])),
        }
    }
    out
}

/// Charts of the recorded trajectory: deflection vs time, force vs time, the
/// force–separation loop with the law's jump-in and jump-out separations marked, and the
/// phase portrait (velocity vs deflection, in and out of contact).
pub fn trajectory_charts(run: &TapRun, title: &str) -> Vec<Chart> {
    let t = &run.trajectory;
    let ns = |s: &TrajectorySample| s.t_s * 1e6;
    let deflection = Chart {
        name: "deflection".into(),
        title: format!("{title}: deflection"),
        x: Axis::linear("time t (µs)", "t_us"),
        y: Axis::linear("deflection z (nm)", "z_nm"),
        series: vec![Series::new(
            "z(t)",
            t.iter().map(|s| (ns(s), s.z_m * 1e9)).collect(),
            Style::Line,
            0,
        )],
        labels: vec![],
        legend: Corner::UpperRight,
    };
    let split = |pick: &dyn Fn(&TrajectorySample) -> (f64, f64)| -> Vec<Series> {
        let mut contact_named = false;
        let mut free_named = false;
        let mut neck_named = false;
        runs(t, pick)
            .into_iter()
            .map(|(branch, pts)| {
                let (name, color, named) = match branch {
                    Branch::Free => ("out of contact", 2, &mut free_named),
                    Branch::Contact => ("in contact", 1, &mut contact_named),
                    Branch::Necked => ("neck attached", 3, &mut neck_named),
                };
                // Only the first run of each branch carries a legend entry.
                let label = if *named {
                    String::new()
                } else {
                    name.to_string()
                };
                *named = true;
                Series::new(&label, pts, Style::Line, color)
            })
            .collect()
    };
    let force = Chart {
        name: "force".into(),
        title: format!("{title}: tip–sample force"),
        x: Axis::linear("time t (µs)", "t_us"),
        y: Axis::linear("force F_ts (nN, repulsive > 0)", "force_nn"),
        series: split(&|s| (ns(s), s.force_n * 1e9)),
        labels: vec![],
        legend: Corner::UpperRight,
    };
    let (jump_in, jump_out) = run.switch_separations_m;
    let mut loop_series = split(&|s| (s.alpha_m * 1e9, s.force_n * 1e9));
    let (f_lo, f_hi) = t
        .iter()
        .map(|s| s.force_n * 1e9)
        .fold((0.0f64, 0.0f64), |(lo, hi), f| (lo.min(f), hi.max(f)));
    for (alpha, name, color) in [(jump_in, "jump-in", 3), (jump_out, "jump-out", 4)] {
        if alpha.is_finite() {
            loop_series.push(Series::new(
                &format!("{name} α = {:.3} nm", alpha * 1e9),
                vec![(alpha * 1e9, f_lo), (alpha * 1e9, f_hi)],
                Style::Dotted,
                color,
            ));
        }
    }
    // Show the interaction region: from the deepest point to a little beyond the jumps.
    let alpha_min = t
        .iter()
        .map(|s| s.alpha_m * 1e9)
        .fold(f64::INFINITY, f64::min);
    let alpha_max = t
        .iter()
        .map(|s| s.alpha_m * 1e9)
        .fold(f64::NEG_INFINITY, f64::max);
    let reach = [jump_in, jump_out]
        .iter()
        .filter(|a| a.is_finite())
        .fold(alpha_min.max(0.0), |m, a| m.max(a * 1e9));
    let span = (reach - alpha_min).max(1.0);
    let x_axis = Axis::linear("tip–sample separation α (nm)", "alpha_nm");
    let x_axis = if alpha_min.is_finite() {
        x_axis.with_range(alpha_min - 0.05 * span, (reach + 0.6 * span).min(alpha_max))
    } else {
        x_axis
    };
    let separation = Chart {
        name: "force_separation".into(),
        title: format!("{title}: force vs separation"),
        x: x_axis,
        y: Axis::linear("force F_ts (nN, repulsive > 0)", "force_nn"),
        series: loop_series,
        // What the orbit gives, beside the loop that gives it (right of the jumps, in
        // the lower half, clear of the legend and the free branch at F = 0).
        labels: {
            let o = &run.observables;
            let x = reach + 0.05 * span;
            let y = |share: f64| f_lo + share * (f_hi - f_lo);
            vec![
                Label {
                    text: format!("{}, A/A₀ = {:.4}", o.regime, o.amplitude_ratio),
                    x,
                    y: y(0.42),
                },
                Label {
                    text: format!("φ = {:.2}°, E_ts = {} eV", o.phase_deg, fixed(o.e_ts_ev, 2)),
                    x,
                    y: y(0.3),
                },
            ]
        },
        legend: Corner::UpperRight,
    };
    let portrait = Chart {
        name: "phase_portrait".into(),
        title: format!("{title}: phase portrait"),
        x: Axis::linear("deflection z (nm)", "z_nm"),
        y: Axis::linear("velocity dz/dt (m/s)", "v_m_s"),
        series: split(&|s| (s.z_m * 1e9, s.v_m_s)),
        labels: vec![],
        legend: Corner::UpperRight,
    };
    vec![deflection, force, separation, portrait]
}

/// A table of the steady states at amplitude setpoint `ratio` (A/A₀): for each, its
/// branch, the rest separation that gives it, A/A₀, φ, E_ts and the motion.
pub fn setpoint_text(
    setup: &TapSetup,
    ratio: f64,
    states: &[crate::analysis::setpoint::SetpointState],
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Steady states at the amplitude setpoint A/A₀ = {ratio} (A = {:.4} nm), {} law",
        ratio * setup.cantilever.free_amplitude_m * 1e9,
        setup.law
    );
    let _ = writeln!(
        s,
        "  {:<11} {:>10} {:>10} {:>10} {:>10} {:>9}  motion",
        "branch", "z_c (nm)", "A/A₀", "φ (°)", "E_ts (eV)", "contact"
    );
    for st in states {
        let o = &st.observables;
        let _ = writeln!(
            s,
            "  {:<11} {:>10.4} {:>10.6} {:>10.4} {:>10.4} {:>9.4}  {}{}",
            st.branch.to_string(),
            st.separation_m * 1e9,
            o.amplitude_ratio,
            o.phase_deg,
            // (+ 0.0: a conservative law's round-off −0 prints as 0.)
            o.e_ts_ev + 0.0,
            o.contact_fraction,
            o.regime,
            if o.grazing { ", grazing a switch" } else { "" }
        );
    }
    if states.len() > 1 {
        let _ = writeln!(
            s,
            "note: {} states hold this setpoint; which one an AFM images on depends on how \
             it got there (approach or retract, the drive's history)",
            states.len()
        );
    }
    s
}

/// Lines naming the other stable period-1 states at the same rest separation (none:
/// nothing).
pub fn coexisting_text(
    states: &[crate::analysis::setpoint::SetpointState],
    search: Search,
) -> String {
    let mut s = String::new();
    if states.is_empty() {
        let _ = writeln!(
            s,
            "{}",
            match search {
                Search::HarmonicBalance =>
                    "note: no other stable period-1 state known at this z_c (looked for where \
                     the first-harmonic balance puts one; --all-states follows every family \
                     of orbits from far)",
                Search::Thorough =>
                    "note: no other stable period-1 state known at this z_c (looked for \
                     where the first-harmonic balance puts one and along every family of \
                     orbits followed in from 1.2 A₀)",
            }
        );
    }
    for st in states {
        let o = &st.observables;
        let _ = writeln!(
            s,
            "note: another stable state exists at this z_c, on the {} branch: A/A₀ {:.6}, \
             φ {:.4}°, E_ts {:.4} eV (an approach or a retract may sit on it; `tapsim tap \
             --setpoint` lists the states at a setpoint)",
            st.branch,
            o.amplitude_ratio,
            o.phase_deg,
            o.e_ts_ev + 0.0
        );
    }
    s
}
