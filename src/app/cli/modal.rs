//! The several-mode forms of `tap`, `approach` and `contrast` (`--modes 2` or 3).

use crate::analysis::bimodal;
use crate::analysis::contrast::Material;
use crate::analysis::setpoint::PhaseBranch;
use crate::analysis::sweep::Direction;
use crate::app::report::modes as report;
use crate::dynamics::modes::{ModeSet, modal_steady, modal_windowed, prepare};
use crate::dynamics::setup::{Numerics, TapSetup};
use crate::error::{Error, Result};
use crate::physics::law::LawKind;

/// Refuse `flag` (given when `given`) with several modes.
pub(super) fn refuse(given: bool, flag: &str) -> Result<()> {
    if given {
        return Err(Error::NotApplicable(format!(
            "{flag} is for one mode; with --modes 2 or 3 tapsim reports the several-mode \
             orbit's lock-in amplitudes, phases and energies per mode"
        )));
    }
    Ok(())
}

/// `tap --modes N`: the steady state at the rest separation, or every state at the
/// first mode's amplitude setpoint (A₁/A₀₁, on the branch given or on both).
pub(super) fn tap(
    setup: &TapSetup,
    numerics: &Numerics,
    set: &ModeSet,
    setpoint: Option<(f64, Option<PhaseBranch>)>,
    (json, quiet): (bool, bool),
) -> Result<()> {
    let Some((ratio, branch)) = setpoint else {
        let (p, modal) = prepare(setup, set, numerics)?;
        if modal.periods.is_none() {
            let busy = super::progress::Busy::new(
                "tap: averaging the modes over windows of thousands of drive periods",
                quiet,
            );
            let state = modal_windowed(&p, &modal, numerics);
            busy.finish_and_clear();
            let state = state?;
            if json {
                outln!("{}", crate::app::report::records::document(&state)?);
            } else {
                out!("{}", report::windowed_text(set, &state));
            }
            return Ok(());
        }
        let state = modal_steady(&p, &modal, numerics, None)?.0;
        if json {
            outln!("{}", crate::app::report::records::document(&state)?);
        } else {
            out!("{}", report::tap_text(set, &state));
        }
        return Ok(());
    };
    crate::analysis::setpoint::check_ratio(ratio)?;
    let found = bimodal::states_at_setpoint(setup, set, numerics, ratio, branch)?;
    let (states, notes): (Vec<_>, Vec<_>) = found.into_iter().partition(|(_, s)| s.is_ok());
    let states: Vec<bimodal::ModalSetpointState> =
        states.into_iter().filter_map(|(_, s)| s.ok()).collect();
    let notes: Vec<String> = notes
        .into_iter()
        .filter_map(|(_, s)| s.err().map(|e| e.to_string()))
        .collect();
    if states.is_empty() {
        return Err(Error::NotApplicable(notes.join("; ")));
    }
    if json {
        let listed = serde_json::to_value(&states).expect("states serialise");
        let mut top = listed[0].clone();
        if let serde_json::Value::Object(m) = &mut top {
            m.insert("setpoint".into(), ratio.into());
            m.insert("states".into(), listed);
            m.insert("notes".into(), notes.into());
        }
        outln!("{}", crate::app::report::records::document(&top)?);
        return Ok(());
    }
    outln!(
        "first-mode setpoint A₁/A₀₁ = {ratio}: {} hold it{}",
        match states.len() {
            1 => "1 state of the modes".to_string(),
            n => format!("{n} states of the modes"),
        },
        if states.len() > 1 {
            " (coexisting attractors: which one an AFM images on depends on how it got \
             there, approach or retract)"
        } else {
            ""
        }
    );
    for s in &states {
        let on: Vec<_> = states.iter().filter(|t| t.branch == s.branch).collect();
        let which = match on.iter().position(|t| std::ptr::eq(*t, s)) {
            Some(i) if on.len() > 1 => {
                format!(", state {} of {}: the higher modes differ", i + 1, on.len())
            }
            _ => String::new(),
        };
        outln!(
            "\n{} branch (φ₁ on the {0} side of the free phase){which}:",
            s.branch
        );
        out!("{}", report::tap_text(set, &s.observables));
    }
    for note in &notes {
        outln!("note: {note}");
    }
    Ok(())
}

/// `approach --modes N`: the approach (and retract) curve, each point continued from the
/// last.
pub(super) fn approach(
    start: &super::SweepStart,
    set: &ModeSet,
    ramp: &[(f64, Direction)],
    out: &super::SweepOutput,
) -> Result<()> {
    let (p, modal) = prepare(&start.setup, set, &start.sweep_numerics)?;
    let bar = out.progress("approach", ramp.len());
    let separations: Vec<f64> = ramp.iter().map(|r| r.0).collect();
    let points = bimodal::approach(&p, &modal, &start.sweep_numerics, &separations, || {
        bar.inc(1)
    })?;
    bar.finish_and_clear();
    let points: Vec<_> = points.into_iter().zip(ramp.iter().map(|r| r.1)).collect();
    let rows = report::rows(&points);
    let title = format!("{} law, {} modes", start.setup.law, set.count());
    out.write_files(&rows, || report::approach_charts(&rows, &title))?;
    if out.json {
        return out.print_json(&rows);
    }
    outln!(
        "{:>9} {:>9} {:>10} {:>10} {:>10} {:>10} {:>11} {:>8} {:>7}",
        "z_c (nm)",
        "dir",
        "A1/A01",
        "phi1 (deg)",
        "A2/A02",
        "phi2 (deg)",
        "E_ts (eV)",
        "contact",
        "stable"
    );
    let f = |v: Option<f64>, p: usize| v.map_or("-".into(), |v| format!("{v:.p$}"));
    for r in &rows {
        outln!(
            "{:>9.3} {:>9} {:>10} {:>10} {:>10} {:>10} {:>11} {:>8} {:>7}",
            r.separation_m * 1e9,
            r.direction,
            f(r.amplitude1_ratio, 6),
            f(r.phase1_deg, 4),
            f(r.amplitude2_ratio, 6),
            f(r.phase2_deg, 4),
            f(
                r.e_ts_j.map(|e| e / crate::physics::params::ELECTRONVOLT_J),
                4
            ),
            f(r.contact_fraction, 3),
            r.stable.map_or("-", |s| if s { "yes" } else { "NO" })
        );
    }
    for r in rows.iter().filter(|r| r.note.is_some()) {
        outln!(
            "note: z_c = {:.3} nm ({}): {}",
            r.separation_m * 1e9,
            r.direction,
            r.note.as_deref().unwrap_or_default()
        );
    }
    Ok(())
}

/// `contrast --modes N`: φ₁ and φ₂ of each material at each first-mode setpoint.
pub(super) fn contrast(
    materials: &[Material],
    set: &ModeSet,
    laws: &[LawKind],
    setpoints: &[f64],
    out: &super::SweepOutput,
) -> Result<()> {
    let bar = out.progress("contrast", laws.len() * materials.len());
    let rows = bimodal::contrast(materials, set, laws, setpoints, || bar.inc(1));
    bar.finish_and_clear();
    let rows = rows?;
    let names: Vec<String> = laws.iter().map(ToString::to_string).collect();
    out.write_files(&rows, || report::contrast_charts(&rows, &names))?;
    if out.json {
        outln!(
            "{}",
            crate::app::report::records::document(&crate::app::report::records::columns_json(
                &rows
            )?)?
        );
    } else {
        out!("{}", report::contrast_text(&rows));
    }
    Ok(())
}

/// `map --modes N`: the several-mode state of every cell of the (Δγ, E*) grid.
pub(super) fn map(
    (setup, numerics, set): (&TapSetup, &Numerics, &ModeSet),
    (works, moduli): (&[f64], &[f64]),
    threads: usize,
    setpoint: Option<(f64, PhaseBranch)>,
    out: &super::SweepOutput,
) -> Result<()> {
    let bar = out.progress("map", works.len() * moduli.len());
    let cells = bimodal::map_cells(
        setup,
        set,
        numerics,
        (works, moduli),
        threads,
        || bar.inc(1),
        setpoint,
    );
    bar.finish_and_clear();
    let cells = cells?;
    let title = match setpoint {
        Some((s, branch)) => format!(
            "{} law, {} modes, A₁/A₀₁ = {s}, {branch}",
            setup.law,
            set.count()
        ),
        None => format!(
            "{} law, {} modes, z_c = {:.4} nm",
            setup.law,
            set.count(),
            setup.separation_m * 1e9
        ),
    };
    out.emit(
        ("map", &[]),
        &cells,
        || crate::app::report::records::columns_json(&cells),
        Some(&|path| {
            crate::app::report::plot::render_heatmaps(
                &report::map_heat_maps(&title, works, moduli, &cells),
                path,
            )
        }),
    )?;
    let empty = cells.iter().filter(|c| c.note.is_some()).count();
    if empty > 0 && !out.quiet {
        eprintln!(
            "note: {empty} of {} cells have no periodic state of the modes (column note; \
             grey on the heat maps)",
            cells.len()
        );
    }
    Ok(())
}
