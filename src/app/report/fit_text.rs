//! What `tapsim fit` prints: the estimates, the verdict on the fit, the minima the
//! search found, the profiles, and (with several laws) their ranking.

use crate::analysis::fit::{FitReport, LawComparison, Measured, Parameter, Profile};
use std::fmt::Write as _;

/// A number as a table shows a parameter of `name` (an offset in its unit).
fn value_text(name: &str, v: f64) -> String {
    if name == Parameter::ZOffset.key() {
        format!("{:.4} nm", v * 1e9)
    } else if name == Parameter::PhaseOffset.key() {
        format!("{v:.4}°")
    } else {
        format!("{v:.5e}")
    }
}

/// The profiles' intervals beside the linearised ones.
pub fn profiles(r: &FitReport, profiles: &[Profile]) -> String {
    let mut s = String::new();
    let g = |v: Option<f64>| v.map_or("open".to_string(), |v| format!("{v:.5e}"));
    for p in profiles {
        let lin = r.parameters.iter().find(|e| e.name == p.name);
        let _ = writeln!(
            s,
            "profile of {} ({} points): 68 % [{}, {}] (linearised {}), 95 % [{}, {}] \
             (linearised {})",
            p.name,
            p.values.len(),
            g(p.interval_68[0]),
            g(p.interval_68[1]),
            lin.and_then(|e| e.interval_68)
                .map_or("-".into(), |[a, b]| format!("[{a:.5e}, {b:.5e}]")),
            g(p.interval_95[0]),
            g(p.interval_95[1]),
            lin.and_then(|e| e.interval_95)
                .map_or("-".into(), |[a, b]| format!("[{a:.5e}, {b:.5e}]")),
        );
        if !p.unavailable.is_empty() {
            let _ = writeln!(
                s,
                "  (no value at {}: the law or the simulation cannot take it there; that side \
                 of the profile stops)",
                p.unavailable
                    .iter()
                    .map(|v| format!("{v:.5e}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
    }
    if profiles.iter().any(|p| {
        p.interval_95.iter().any(Option::is_none) || p.interval_68.iter().any(Option::is_none)
    }) {
        let _ = writeln!(
            s,
            "(open: χ² does not rise that far within 4.5 standard errors on that side, or the \
             profile stopped there — the data do not bound the parameter there)"
        );
    }
    s
}

/// What the channels fitted are, in words.
fn channels(data: &Measured) -> String {
    let first = match (data.amplitude_m.is_some(), data.phase_deg.is_some()) {
        (true, true) => "amplitude and phase",
        (true, false) => "amplitude",
        _ => "phase",
    };
    let second = data.second_mode.as_ref().map_or("", |m| {
        match (m.amplitude_m.is_some(), m.phase_deg.is_some()) {
            (true, true) => "; the second mode's amplitude and phase",
            (true, false) => "; the second mode's amplitude",
            (false, true) => "; the second mode's phase",
            (false, false) => "; two modes simulated",
        }
    });
    let at = if data.setpoint_ratio.is_some() {
        " at amplitude setpoints"
    } else {
        ""
    };
    format!("{first}{at}{second}")
}

/// The whole report of one fit with the `law` named.
pub fn report(r: &FitReport, law: &str, data: &Measured) -> String {
    let mut s = String::new();
    let search = match r.search {
        crate::analysis::fit::Search::Local => "from the start alone".to_string(),
        crate::analysis::fit::Search::Global { factor, starts, .. } => format!(
            "global search (a design over ×/÷{factor} about the start, then up to {starts} \
             local runs)"
        ),
    };
    let _ = writeln!(
        s,
        "fit of {} points ({}), {law} law, {search}: {} simulated curves",
        data.len(),
        channels(data),
        r.curves,
    );
    let _ = writeln!(
        s,
        "{}: {}",
        if r.converged {
            "converged"
        } else {
            "NOT converged"
        },
        r.termination
    );
    let _ = writeln!(
        s,
        "{:<24} {:>13} {:>13} {:>11} {:>29} {:>29}",
        "parameter", "start", "fitted", "±1σ", "68 % interval", "95 % interval"
    );
    for p in &r.parameters {
        let offset = [Parameter::ZOffset.key(), Parameter::PhaseOffset.key()].contains(&p.name);
        let g = |v: f64| value_text(p.name, v);
        let iv =
            |i: Option<[f64; 2]>| i.map_or("-".into(), |[a, b]| format!("[{}, {}]", g(a), g(b)));
        let _ = writeln!(
            s,
            "{:<24} {:>13} {:>13} {:>11} {:>29} {:>29}",
            p.name,
            g(p.start),
            p.value.map_or("not identifiable".into(), g),
            p.std_err.map_or("-".into(), |e| if offset {
                g(e)
            } else {
                format!("{e:.2e}")
            }),
            iv(p.interval_68),
            iv(p.interval_95)
        );
    }
    let _ = writeln!(
        s,
        "χ²/dof = {} ({} degrees of freedom; σ {})",
        if r.reduced_chi_square >= 1e-3 {
            format!("{:.3}", r.reduced_chi_square)
        } else {
            format!("{:.1e}", r.reduced_chi_square)
        },
        r.degrees_of_freedom,
        match (r.sigma_estimated, r.diagnosis.describes_data) {
            (true, true) => "estimated from the residuals: the intervals are scaled by √(χ²/dof)",
            (true, false) => "not given: relative to the default weights 0.02 nm and 0.05°",
            (false, _) => "as given",
        }
    );
    if !r.sigma_estimates.is_empty() && r.diagnosis.describes_data {
        let unit = |c: &str| match c {
            "amplitude_m" | "amplitude2_m" => (1e9, "nm"),
            _ => (1.0, "°"),
        };
        let est: Vec<String> = r
            .sigma_estimates
            .iter()
            .map(|e| {
                let (k, u) = unit(e.channel);
                format!(
                    "{} {:.3} {u} (weight {:.3} {u})",
                    e.channel,
                    e.sigma * k,
                    e.weight_sigma * k
                )
            })
            .collect();
        let _ = writeln!(s, "noise the residuals imply: {}", est.join(", "));
    }
    let d = &r.diagnosis;
    if !d.describes_data {
        let _ = writeln!(
            s,
            "THE FIT DOES NOT DESCRIBE THE DATA — no intervals are given:"
        );
        for reason in &d.reasons {
            let _ = writeln!(s, "  - {reason}");
        }
        let _ = writeln!(s, "  worst points:");
        for w in &d.worst_points {
            let (k, u) = match w.channel {
                "amplitude_m" | "amplitude2_m" => (1e9, "nm"),
                _ => (1.0, "°"),
            };
            let at = if data.setpoint_ratio.is_some() {
                format!("setpoint {:.4}", w.at)
            } else {
                format!("position {:.3} nm", w.at * 1e9)
            };
            let _ = writeln!(
                s,
                "    point {} ({at}): {} measured {:.4} {u}, fitted {:.4} {u} ({:+.1} σ)",
                w.index + 1,
                w.channel,
                w.measured * k,
                w.fitted * k,
                w.weighted_residual
            );
        }
    }
    if r.minima.len() > 1 {
        let _ = writeln!(
            s,
            "local minima found ({} local runs; the first is reported above):",
            r.minima.iter().map(|m| m.runs).sum::<usize>()
        );
        for m in &r.minima {
            let values: Vec<String> = r
                .parameters
                .iter()
                .zip(&m.values)
                .map(|(p, &v)| format!("{} {}", p.name, value_text(p.name, v)))
                .collect();
            let _ = writeln!(
                s,
                "  χ²/dof {:>12.4}: {} ({} run{}{})",
                m.reduced_chi_square,
                values.join(", "),
                m.runs,
                if m.runs == 1 { "" } else { "s" },
                if m.cut_short {
                    ", cut short: its run stopped before it converged"
                } else {
                    ""
                }
            );
        }
    }
    let id = &r.identifiability;
    let _ = writeln!(
        s,
        "singular values of the weighted Jacobian [{}]; condition number {}",
        id.singular_values
            .iter()
            .map(|v| format!("{v:.3e}"))
            .collect::<Vec<_>>()
            .join(", "),
        id.condition_number
            .map_or("— (a parameter the data do not see)".into(), |c| format!(
                "{c:.3e}"
            ))
    );
    let names: Vec<&str> = r.parameters.iter().map(|p| p.name).collect();
    let _ = writeln!(s, "correlations:");
    for (name, row) in names.iter().zip(&id.correlations) {
        let cells: Vec<String> = row
            .iter()
            .map(|c| c.map_or("     -".into(), |c| format!("{c:+.3}")))
            .collect();
        let _ = writeln!(s, "  {name:<24} {}", cells.join(" "));
    }
    for note in &id.notes {
        let _ = writeln!(s, "note: {note}");
    }
    let averaged = r.fitted.averaged.iter().filter(|a| **a).count();
    if averaged > 0 {
        let _ = writeln!(
            s,
            "note: {averaged} of the fitted curve's points graze a switch or are not \
             period-1 there, and are read as the average over the thermal motion (as an \
             instrument reads them), their standard errors added to the data's"
        );
    }
    let unsettled = r.fitted.unsettled();
    if unsettled > 0 {
        let _ = writeln!(
            s,
            "note: {unsettled} of the fitted curve's points are not stable period-1 orbits clear of \
             the law's switches: their values are averages perturbations can change, and \
             the fit there is less sure than its intervals say"
        );
    }
    s
}

/// The laws ranked, and the verdict.
pub fn comparison(c: &LawComparison) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "which law the data support (best first):");
    let _ = writeln!(
        s,
        "  {:<18} {:>3} {:>14} {:>12} {:>12} {:>9} {:>8}  describes the data",
        "law", "k", "chi^2", "AIC", "BIC", "ΔAIC", "weight"
    );
    for l in &c.ranking {
        let _ = writeln!(
            s,
            "  {:<18} {:>3} {:>14.4e} {:>12.2} {:>12.2} {:>9.2} {:>8.4}  {}",
            l.law,
            l.parameters,
            l.chi_square,
            l.aic,
            l.bic,
            l.delta_aic,
            l.akaike_weight,
            if l.describes_data { "yes" } else { "no" }
        );
    }
    let _ = writeln!(s, "verdict: {}", c.verdict);
    s
}
