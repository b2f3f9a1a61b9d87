//! `tapsim force-curve`: one force–distance curve, its jumps and its QNM channels.

use super::peakforce::{Columns, DEFAULT_PEAK_FORCE_N, FitWindowArgs};
use super::progress::Busy;
use crate::app::config::{TapInputs, force, length, time, velocity};
use crate::app::report::chart::{Axis, Chart, Corner, Series, Style};
use crate::dynamics::setup::significant;
use crate::error::{Error, Result};
use crate::instrument::force_curve::{Jump, Ramp, force_curve, force_curve_modes};
use crate::instrument::peakforce::check_setpoint;
use crate::instrument::qnm::{Analysis, Channels, ForcePoint};
use crate::physics::params::ELECTRONVOLT_J;
use clap::Args;

/// A force–distance curve: the cantilever's support ramped to the sample and back.
///
/// The support starts out of contact (--from, 20 nm by default: the separation of the
/// undeflected tip from the sample), moves toward the sample at a constant speed
/// (--velocity, 1 µm/s), turns back where the force first reaches the trigger
/// (--trigger, 5 nN) or at a piezo position (--to; with both, whichever comes first),
/// rests there for --dwell, and returns at the same speed. The point-mass cantilever
/// is integrated against the law all the way, with its inertia and damping: the tip
/// snaps in where the law jumps into contact, the lever rings, is pressed in, sticks on
/// the way out and snaps off at the pull-off, ringing again. The cantilever is the
/// compliant support of the paper's §4: as the ramp slows, the area of the force–piezo
/// loop (the support's work) tends to the finite-stiffness loss of eq. (26), the snap-in
/// to where the support reaches the jump-in separation (eq. (17)) and the pull-off to
/// the support separation at the JKR jump-out with the spring, eq. (24).
///
/// Printed: where the tip snapped in and pulled off (piezo position, tip separation,
/// force), the QNM channels read from the curve as an instrument's analysis reads them
/// (peak force, adhesion, dissipation as the area between approach and retract
/// force–separation curves, deformation, a DMT modulus fitted to the retract between
/// --fit-from and --fit-to of the span from adhesion to peak), the deepest indentation,
/// and the energy books: the support's work = the contact's loss + damping + what rings
/// at the end. On a conservative law (hertz, dmt) nothing is lost in the contact and
/// the DMT fit returns the E* given; JKR loses several times the hybrid law's energy.
///
/// Examples:
///   tapsim force-curve                              # hybrid law, 5 nN trigger, 1 µm/s
///   tapsim force-curve --law jkr --plot jkr.png
///   tapsim force-curve --to -2nm --no-trigger --dwell 1ms --csv curve.csv
///   tapsim force-curve --stiffness 0.4N/m --resonance 70kHz --velocity 500nm/s
///   tapsim force-curve --modes 2 --velocity 10um/s   # the second mode rings too
///
/// With --modes 2 (or 3) the cantilever's higher eigenmodes are marched with the first
/// (bimodal AFM's model, their drives off): the tip is their sum, and every mode rings
/// after a jump. Each of their periods is stepped through (seconds of work on the
/// defaults); a ramp whose leg lasts more than 200 000 periods of the highest mode is
/// refused.
///
/// JSON keys (--json): law, start_m, turn_m, triggered, trigger_n, velocity_m_s,
/// dwell_s, snap_in and pull_off (each null or t_s, piezo_m, separation_m, force_n),
/// channels (peak_force_n, adhesion_n, dissipation_j, deformation_m, dmt_modulus_pa,
/// dmt_contact_m, dmt_points), max_indentation_m, contact_loss_j, damping_loss_j,
/// drive_work_j, final_energy_j, energy_balance_rel, modulus_given_pa, points_recorded,
/// and with --curve the curve as columns (curve: t_s, piezo_m, deflection_m,
/// separation_m, force_n, approach, contact). --csv FILE: the curve, the same columns;
/// --plot FILE.png|svg: force against piezo position and against separation, approach
/// and retract, and the deflection against time. The curve in files has at most
/// --points points (evenly in time, both sides of every jump kept); the channels are
/// read from the full record.
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct ForceCurveArgs {
    #[command(flatten)]
    pub(super) inputs: TapInputs,
    /// Where the ramp starts and ends: the undeflected tip's separation from the sample
    /// [m; default 20nm].
    #[arg(long, allow_hyphen_values = true, value_parser = length)]
    from: Option<f64>,
    /// The nearest the support comes (the undeflected tip's separation; negative:
    /// pressed in) [m; default: as far as the trigger needs].
    #[arg(long, allow_hyphen_values = true, value_parser = length)]
    to: Option<f64>,
    /// Turn back where the force first reaches this [N; default 5nN].
    #[arg(long, allow_hyphen_values = true, value_parser = force, conflicts_with = "no_trigger")]
    trigger: Option<f64>,
    /// No trigger: turn at --to only.
    #[arg(long, requires = "to")]
    no_trigger: bool,
    /// The support's speed on both legs [m/s; default 1um/s].
    #[arg(long, allow_hyphen_values = true, value_parser = velocity)]
    velocity: Option<f64>,
    /// How long the support rests at the turn [s; default 0].
    #[arg(long, allow_hyphen_values = true, value_parser = time)]
    dwell: Option<f64>,
    #[command(flatten)]
    window: FitWindowArgs,
    /// The most points of the curve written to --csv, --json --curve and the plot
    /// [default 2048].
    #[arg(long, value_parser = clap::value_parser!(u32).range(2..=1_000_000))]
    points: Option<u32>,
    /// With --json: the curve too, as columns (`curve`: t_s, piezo_m, deflection_m,
    /// separation_m, force_n, approach, contact).
    #[arg(long, requires = "json")]
    curve: bool,
    #[command(flatten)]
    modes: crate::app::config::ModeInputs,
    #[command(flatten)]
    pub(super) out: super::SweepOutput,
}

/// What --json prints.
#[derive(serde::Serialize)]
struct Report {
    law: String,
    start_m: f64,
    turn_m: f64,
    triggered: bool,
    trigger_n: Option<f64>,
    velocity_m_s: f64,
    dwell_s: f64,
    snap_in: Option<Jump>,
    pull_off: Option<Jump>,
    channels: Channels,
    max_indentation_m: f64,
    contact_loss_j: f64,
    damping_loss_j: f64,
    drive_work_j: f64,
    final_energy_j: f64,
    energy_balance_rel: f64,
    modulus_given_pa: f64,
    points_recorded: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    curve: Option<Columns>,
}

impl ForceCurveArgs {
    /// The ramp the flags ask for.
    fn ramp(&self) -> Ramp {
        let d = Ramp::default();
        Ramp {
            start_m: self.from.unwrap_or(d.start_m),
            turn_m: self.to,
            trigger_n: if self.no_trigger {
                None
            } else {
                Some(self.trigger.unwrap_or(DEFAULT_PEAK_FORCE_N))
            },
            velocity_m_s: self.velocity.unwrap_or(d.velocity_m_s),
            dwell_s: self.dwell.unwrap_or(d.dwell_s),
        }
    }

    /// Refuse before any work what can be known bad from the flags alone.
    pub(super) fn check(&self) -> Result<()> {
        if self.inputs.separation.is_some() {
            return Err(Error::NotApplicable(
                "a force curve ramps the separation itself: give where it starts (--from) \
                 and where it turns (--to, --trigger), not --separation"
                    .into(),
            ));
        }
        if let Some(f) = self.trigger {
            check_setpoint(f)?;
        }
        self.out.check()
    }
}

/// Run the subcommand.
pub fn run(args: ForceCurveArgs) -> Result<()> {
    let mut inputs = args.inputs.clone().with_config()?;
    inputs.takes_modes = true;
    inputs.no_setpoint("force-curve")?;
    let (setup, numerics) = inputs.resolve()?;
    let set = args.modes.mode_set(&inputs.mode_file, &setup.cantilever)?;
    let ramp = args.ramp();
    ramp.check(&setup.cantilever)?;
    let analysis = args.window.analysis()?;
    let busy = Busy::new("force-curve: ramping the support", args.out.quiet);
    let result = match &set {
        Some(set) => force_curve_modes(&setup, &numerics, set, &ramp, &analysis),
        None => force_curve(&setup, &numerics, &ramp, &analysis),
    };
    busy.finish_and_clear();
    let c = result?;
    let shown = c.thinned(args.points.map_or(2048, |n| n as usize));
    let report = Report {
        law: setup.law.to_string(),
        start_m: ramp.start_m,
        turn_m: c.turn_m,
        triggered: c.triggered,
        trigger_n: ramp.trigger_n,
        velocity_m_s: ramp.velocity_m_s,
        dwell_s: ramp.dwell_s,
        snap_in: c.snap_in,
        pull_off: c.pull_off,
        channels: c.channels,
        max_indentation_m: c.max_indentation_m,
        contact_loss_j: c.contact_loss_j,
        damping_loss_j: c.damping_loss_j,
        drive_work_j: c.drive_work_j,
        final_energy_j: c.final_energy_j,
        energy_balance_rel: c.energy_balance_rel,
        modulus_given_pa: setup.contact.modulus_pa,
        points_recorded: c.curve.len(),
        curve: args.curve.then(|| Columns::of(&shown)),
    };
    args.out.write_files(&shown, || charts(&report, &shown))?;
    if args.out.json {
        outln!("{}", crate::app::report::records::document(&report)?);
        return Ok(());
    }
    print_table(&report, &analysis, &setup)
}

/// The table: the ramp, the jumps, the channels and the books.
fn print_table(
    r: &Report,
    analysis: &Analysis,
    setup: &crate::dynamics::setup::TapSetup,
) -> Result<()> {
    let cant = &setup.cantilever;
    let turned = if r.triggered {
        format!(
            "turned by the {} nN trigger",
            significant(r.trigger_n.unwrap_or(0.0) * 1e9)
        )
    } else {
        "turned".to_string()
    };
    outln!(
        "force curve, {} law: the support ramped from {} nm at {} µm/s, {turned} at {:.4} nm \
         (dwell {} s), on a {} N/m lever resonating at {} kHz (Q {})",
        r.law,
        significant(r.start_m * 1e9),
        significant(r.velocity_m_s * 1e6),
        r.turn_m * 1e9,
        significant(r.dwell_s),
        significant(cant.stiffness_n_m),
        significant(cant.resonance_hz * 1e-3),
        significant(cant.quality)
    );
    let jump = |name: &str, j: Option<Jump>, none: &str| -> Result<()> {
        match j {
            Some(j) => outln!(
                "{name:<9} at piezo {:.4} nm (tip at {:.4} nm, {:.4} ms into the ramp): force {:.4} nN",
                j.piezo_m * 1e9 + 0.0,
                j.separation_m * 1e9 + 0.0,
                j.t_s * 1e3,
                j.force_n * 1e9 + 0.0
            ),
            None => outln!("{name:<9} {none}"),
        }
        Ok(())
    };
    jump("snap-in", r.snap_in, "none: the tip never touched")?;
    jump(
        "pull-off",
        r.pull_off,
        "none: the tip left no contact on the way back",
    )?;
    let ch = &r.channels;
    outln!(
        "peak force {:.4} nN, adhesion {:.4} nN, deformation {:.4} nm, deepest indentation \
         {:.4} nm",
        ch.peak_force_n * 1e9,
        ch.adhesion_n * 1e9,
        ch.deformation_m * 1e9,
        r.max_indentation_m * 1e9
    );
    outln!(
        "DMT fit of the retract ({:.0}–{:.0} % of the span from adhesion to peak): {}; E* \
         given {:.4} GPa",
        100.0 * analysis.fit_window.0,
        100.0 * analysis.fit_window.1,
        ch.dmt_modulus_pa
            .map_or("no fit (fewer than 3 points in the window)".into(), |e| {
                format!("E* = {:.4} GPa from {} points", e * 1e-9, ch.dmt_points)
            }),
        r.modulus_given_pa * 1e-9
    );
    outln!(
        "dissipation (area between approach and retract, force against separation) {:.4} eV; \
         the contact's exact loss {:.4} eV",
        ch.dissipation_j / ELECTRONVOLT_J,
        r.contact_loss_j / ELECTRONVOLT_J
    );
    outln!(
        "the support's work (area of the force–piezo loop) {:.4} eV = contact {:.4} eV + \
         damping {:.4} eV + left ringing {:.4} eV; books close to {:.1e}",
        r.drive_work_j / ELECTRONVOLT_J,
        r.contact_loss_j / ELECTRONVOLT_J,
        r.damping_loss_j / ELECTRONVOLT_J,
        r.final_energy_j / ELECTRONVOLT_J,
        r.energy_balance_rel
    );
    Ok(())
}

/// Force against piezo position and against separation, approach and retract apart,
/// and the deflection against time (the ringing after the jumps).
fn charts(r: &Report, curve: &[ForcePoint]) -> Vec<Chart> {
    let title = format!(
        "{} law, force curve at {} µm/s from {} nm to {:.3} nm",
        r.law,
        significant(r.velocity_m_s * 1e6),
        significant(r.start_m * 1e9),
        r.turn_m * 1e9
    );
    // The force charts show the contact and as much again beyond its farthest jump
    // (the rest is the free lever's flat zero).
    let reach = [r.snap_in, r.pull_off]
        .iter()
        .flatten()
        .map(|j| j.piezo_m)
        .fold(r.turn_m, f64::max);
    let near = reach + (reach - r.turn_m).max(1e-9);
    let part = |approach: bool, x: fn(&ForcePoint) -> f64| -> Vec<(f64, f64)> {
        curve
            .iter()
            .filter(|p| p.approach == approach && p.piezo_m <= near)
            .map(|p| (x(p) * 1e9, p.force_n * 1e9))
            .collect()
    };
    let deflection = curve
        .iter()
        .map(|p| (p.t_s * 1e3, p.deflection_m * 1e9))
        .collect();
    let pair = |x: fn(&ForcePoint) -> f64| {
        vec![
            Series::new("approach (simulated)", part(true, x), Style::Line, 2),
            Series::new("retract (simulated)", part(false, x), Style::Line, 1),
        ]
    };
    vec![
        Chart {
            name: "force_piezo".into(),
            title: title.clone(),
            x: Axis::linear(
                "piezo position: undeflected tip's separation (nm)",
                "piezo_nm",
            ),
            y: Axis::linear("tip–sample force F (nN)", "force_nn"),
            legend: Corner::UpperRight,
            series: pair(|p| p.piezo_m),
            labels: Vec::new(),
        },
        Chart {
            name: "force_separation".into(),
            title: title.clone(),
            x: Axis::linear("tip–sample separation α (nm)", "separation_nm"),
            y: Axis::linear("tip–sample force F (nN)", "force_nn"),
            legend: Corner::UpperRight,
            series: pair(|p| p.separation_m),
            labels: Vec::new(),
        },
        Chart {
            name: "force_curve_deflection".into(),
            title,
            x: Axis::linear("time t (ms)", "t_ms"),
            y: Axis::linear("deflection z (nm)", "deflection_nm"),
            legend: Corner::UpperRight,
            series: vec![Series::new(
                "deflection (simulated)",
                deflection,
                Style::Line,
                0,
            )],
            labels: Vec::new(),
        },
    ]
}
