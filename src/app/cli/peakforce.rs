//! `tapsim peakforce`: off-resonance tapping, one settled cycle and its QNM channels.

use super::progress::Busy;
use crate::app::config::{TapInputs, force, frequency, length, number};
use crate::app::report::chart::{Axis, Chart, Corner, Series, Style};
use crate::dynamics::setup::significant;
use crate::error::{Error, Result};
use crate::instrument::peakforce::{
    Analysis, Channels, ForcePoint, Modulation, PeakForceCycle, PeakForceFeedback, at_setpoint,
    check_setpoint, cycle, feedback,
};
use clap::Args;

/// Off-resonance tapping (PeakForce Tapping, Fast Force Mapping, QI): force curves a
/// thousand times a second.
///
/// The base of the cantilever is moved sinusoidally far below its resonance (f_m, 2 kHz
/// by default, by A_m, 150 nm), so that every modulation cycle is a force–distance
/// curve: the tip approaches, snaps in, indents to the peak force, is pulled off against
/// the adhesion and rings freely until the next approach. The cantilever is the
/// compliant support of the paper's §4: its losses are the hysteresis of eq. (26) for
/// slow cycles. A feedback holds the peak force of each cycle at a setpoint by moving
/// the mean separation; tapsim solves for that separation directly (--peak-force,
/// 5 nN by default) or takes it as given (--separation). The motion is marched from
/// rest until it repeats itself; the channels are then computed from the recorded curve
/// as the instrument computes them:
///
///   peak force     the largest force of the cycle;
///   adhesion       minus the least force on retract;
///   dissipation    the area between approach and retract force–separation curves
///                  (printed beside the exact contact loss of the marched path);
///   deformation    from the approach's last zero of force to the separation at the peak;
///   DMT modulus    E* from F − F_adh = (4/3)E*√R (d₀ − d)^{3/2} fitted to the retract
///                  between 30 % and 90 % of the span from adhesion to peak (--fit-from,
///                  --fit-to), as commercial QNM analysis does.
///
/// Sync distance and baseline: an instrument must find where in its sampled deflection
/// each cycle's peak lies (the "sync distance", a delay of its electronics) and subtract
/// a baseline; here every point's time and separation are known exactly and the
/// support's acceleration is not in the model (its baseline, (f_m/f₀)²·A_m, is 7 pm
/// on the defaults), so neither applies.
///
/// On a conservative law (hertz, dmt) the dissipation is nothing and the DMT modulus
/// is the E* given; on the adhesive laws the modulus comes out biased, and JKR loses
/// several times the hybrid law's energy per cycle: the paper's conclusion as a QNM
/// user meets it. Motion that does not repeat every cycle is said so, each cycle of its
/// repeat listed (or the last 8 cycles of irregular motion).
///
/// Examples:
///   tapsim peakforce                               # hybrid law, 5 nN on the built-in lever
///   tapsim peakforce --law jkr --peak-force 2nN
///   tapsim peakforce --feedback                    # the setpoint reached cycle by cycle
///   tapsim peakforce --separation 148nm --csv curve.csv --plot curve.png
///
/// JSON keys (--json): law, modulation_frequency_hz, modulation_amplitude_m,
/// peak_force_setpoint_n (null with --separation), separation_m, regime, settled_after,
/// cycles (each: peak_force_n, adhesion_n, dissipation_j, deformation_m,
/// dmt_modulus_pa, dmt_contact_m, dmt_points), feedback_cycles (with --feedback),
/// contact_loss_j, damping_loss_j, drive_work_j, energy_balance_rel, modulus_given_pa,
/// and with --curve the recorded curve as columns (curve: t_s, piezo_m, deflection_m,
/// separation_m, force_n, approach, contact). --csv FILE: the recorded curve, the same
/// columns; --plot FILE.png|svg: force and deflection against time (the ringing after
/// pull-off shown) and force against separation, approach and retract.
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct PeakForceArgs {
    #[command(flatten)]
    pub(super) inputs: TapInputs,
    /// Peak-force setpoint [N; default 5nN unless --separation is given]: the rest
    /// separation is solved for where each cycle's peak force is this.
    #[arg(long, allow_hyphen_values = true, value_parser = force, conflicts_with = "separation")]
    peak_force: Option<f64>,
    #[command(flatten)]
    modulation: ModulationArgs,
    #[command(flatten)]
    window: FitWindowArgs,
    /// Reach the setpoint as the instrument does: the peak-force feedback, cycle by
    /// cycle from the support's lowest point 2 nm above the sample, instead of solving
    /// for the separation; prints how many cycles it took.
    #[arg(long, conflicts_with = "separation")]
    feedback: bool,
    /// With --json: the recorded force curve too, as columns (`curve`: t_s, piezo_m,
    /// deflection_m, separation_m, force_n, approach, contact).
    #[arg(long, requires = "json")]
    curve: bool,
    /// The feedback's gain per cycle (0 < g ≤ 1) [default 0.5].
    #[arg(long, allow_hyphen_values = true, value_parser = number, requires = "feedback")]
    gain: Option<f64>,
    #[command(flatten)]
    pub(super) out: super::SweepOutput,
}

/// The support's modulation, as flags.
#[derive(Debug, Args)]
pub(super) struct ModulationArgs {
    /// Modulation frequency f_m [Hz; default 2kHz; well below the lever's resonance].
    #[arg(long, allow_hyphen_values = true, value_parser = frequency)]
    pub(super) modulation_frequency: Option<f64>,
    /// Modulation amplitude A_m [m; default 150nm].
    #[arg(long, allow_hyphen_values = true, value_parser = length)]
    pub(super) modulation_amplitude: Option<f64>,
}

impl ModulationArgs {
    /// The modulation these flags ask for (not yet checked against a lever).
    pub(super) fn modulation(&self) -> Modulation {
        let d = Modulation::default();
        Modulation {
            frequency_hz: self.modulation_frequency.unwrap_or(d.frequency_hz),
            amplitude_m: self.modulation_amplitude.unwrap_or(d.amplitude_m),
        }
    }
}

/// The DMT fit's window on the retract (the QNM analysis), as flags.
#[derive(Debug, Args)]
pub(super) struct FitWindowArgs {
    /// Lower end of the DMT fit's window on the retract, as a fraction of the span from
    /// adhesion to peak [default 0.3].
    #[arg(long, allow_hyphen_values = true, value_parser = number)]
    pub(super) fit_from: Option<f64>,
    /// Upper end of the DMT fit's window [default 0.9].
    #[arg(long, allow_hyphen_values = true, value_parser = number)]
    pub(super) fit_to: Option<f64>,
}

impl FitWindowArgs {
    /// The analysis these flags ask for, checked.
    pub(super) fn analysis(&self) -> Result<Analysis> {
        let window = Analysis::default().fit_window;
        let analysis = Analysis {
            fit_window: (
                self.fit_from.unwrap_or(window.0),
                self.fit_to.unwrap_or(window.1),
            ),
        };
        analysis.check()?;
        Ok(analysis)
    }
}

/// The default peak-force setpoint, N.
pub(super) const DEFAULT_PEAK_FORCE_N: f64 = 5e-9;

/// What --json prints.
#[derive(serde::Serialize)]
struct Report {
    law: String,
    modulation_frequency_hz: f64,
    modulation_amplitude_m: f64,
    peak_force_setpoint_n: Option<f64>,
    separation_m: f64,
    regime: String,
    settled_after: usize,
    cycles: Vec<Channels>,
    feedback_cycles: Option<usize>,
    contact_loss_j: f64,
    damping_loss_j: f64,
    drive_work_j: f64,
    energy_balance_rel: f64,
    modulus_given_pa: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    curve: Option<Columns>,
}

/// A recorded force curve as columns (--json --curve).
#[derive(serde::Serialize)]
pub(super) struct Columns {
    t_s: Vec<f64>,
    piezo_m: Vec<f64>,
    deflection_m: Vec<f64>,
    separation_m: Vec<f64>,
    force_n: Vec<f64>,
    approach: Vec<bool>,
    contact: Vec<bool>,
}

impl Columns {
    pub(super) fn of(curve: &[ForcePoint]) -> Self {
        let col = |f: fn(&ForcePoint) -> f64| curve.iter().map(f).collect();
        Self {
            t_s: col(|p| p.t_s),
            piezo_m: col(|p| p.piezo_m),
            deflection_m: col(|p| p.deflection_m),
            separation_m: col(|p| p.separation_m),
            force_n: col(|p| p.force_n),
            approach: curve.iter().map(|p| p.approach).collect(),
            contact: curve.iter().map(|p| p.contact).collect(),
        }
    }
}

/// Run the subcommand.
pub fn run(args: PeakForceArgs) -> Result<()> {
    let inputs = args.inputs.clone().with_config()?;
    inputs.no_setpoint("peakforce")?;
    let (setup, numerics) = inputs.resolve()?;
    let modulation = args.modulation.modulation();
    modulation.check(&setup.cantilever)?;
    let analysis = args.window.analysis()?;
    let setpoint = match inputs.separation {
        Some(_) => None,
        None => Some(args.peak_force.unwrap_or(DEFAULT_PEAK_FORCE_N)),
    };
    let busy = Busy::new(
        match setpoint {
            Some(_) => "peakforce: solving for the separation at the peak-force setpoint",
            None => "peakforce: marching the modulation until it repeats",
        },
        args.out.quiet,
    );
    let mut feedback_cycles = None;
    let result = match setpoint {
        Some(f) if args.feedback => {
            let loop_ = PeakForceFeedback {
                setpoint_n: f,
                gain: args.gain.unwrap_or(0.5),
            };
            let start = modulation.amplitude_m + 2e-9;
            feedback(&setup, &numerics, &modulation, &loop_, start).and_then(|run| {
                match run.cycles.last().copied() {
                    Some(last) if run.settled => {
                        feedback_cycles = Some(run.cycles.len());
                        cycle(&setup, &numerics, &modulation, &analysis, last.separation_m)
                    }
                    _ => Err(Error::NotApplicable(format!(
                        "the peak-force feedback did not settle in {} cycles (gain {}): \
                         lower the gain, or solve for the separation (leave out --feedback)",
                        run.cycles.len(),
                        loop_.gain
                    ))),
                }
            })
        }
        Some(f) => at_setpoint(&setup, &numerics, &modulation, &analysis, f),
        None => cycle(
            &setup,
            &numerics,
            &modulation,
            &analysis,
            setup.separation_m,
        ),
    };
    busy.finish_and_clear();
    let c = result?;
    let report = Report {
        law: setup.law.to_string(),
        modulation_frequency_hz: modulation.frequency_hz,
        modulation_amplitude_m: modulation.amplitude_m,
        peak_force_setpoint_n: setpoint,
        separation_m: c.separation_m,
        regime: c.regime.clone(),
        settled_after: c.settled_after,
        cycles: c.cycles.clone(),
        feedback_cycles,
        contact_loss_j: c.contact_loss_j,
        damping_loss_j: c.damping_loss_j,
        drive_work_j: c.drive_work_j,
        energy_balance_rel: c.energy_balance_rel,
        modulus_given_pa: setup.contact.modulus_pa,
        curve: args.curve.then(|| Columns::of(&c.curve)),
    };
    args.out.write_files(&c.curve, || charts(&report, &c))?;
    if args.out.json {
        outln!("{}", crate::app::report::records::document(&report)?);
        return Ok(());
    }
    let cant = &setup.cantilever;
    outln!(
        "off-resonance tapping, {} law: the support moved by {} nm at {} kHz on a {} N/m \
         lever resonating at {} kHz (Q {})",
        report.law,
        significant(modulation.amplitude_m * 1e9),
        significant(modulation.frequency_hz * 1e-3),
        significant(cant.stiffness_n_m),
        significant(cant.resonance_hz * 1e-3),
        significant(cant.quality)
    );
    let at = match (setpoint, feedback_cycles) {
        (Some(f), Some(n)) => format!(
            " (where the peak-force feedback settled on the setpoint {:.4} nN after {n} cycles)",
            f * 1e9
        ),
        (Some(f), None) => format!(" (where the peak force is the setpoint {:.4} nN)", f * 1e9),
        (None, _) => String::new(),
    };
    outln!(
        "rest separation z_c = {:.4} nm{at}; motion {} after {} cycles marched",
        c.separation_m * 1e9,
        c.regime,
        c.settled_after
    );
    if c.regime != "period-1" {
        outln!(
            "the motion does not repeat every cycle: each cycle of {} is listed",
            if c.regime == "irregular" {
                "the last 8"
            } else {
                "its repeat"
            }
        );
    }
    outln!(
        "{:>6} {:>11} {:>11} {:>13} {:>12} {:>12} {:>6}",
        "cycle",
        "peak (nN)",
        "adh. (nN)",
        "dissip. (eV)",
        "deform. (nm)",
        "DMT E* (GPa)",
        "points"
    );
    for (i, ch) in c.cycles.iter().enumerate() {
        outln!(
            "{:>6} {:>11.4} {:>11.4} {:>13.4} {:>12.4} {:>12} {:>6}",
            i + 1,
            ch.peak_force_n * 1e9,
            ch.adhesion_n * 1e9,
            ch.dissipation_j / crate::physics::params::ELECTRONVOLT_J,
            ch.deformation_m * 1e9,
            ch.dmt_modulus_pa
                .map_or("no fit".into(), |e| format!("{:.4}", e * 1e-9)),
            ch.dmt_points
        );
    }
    let ev = crate::physics::params::ELECTRONVOLT_J;
    outln!(
        "per cycle: drive work {:.4} eV = contact loss {:.4} eV (exact, the dissipation \
         channel reads the recorded curve) + damping {:.4} eV (the ringing after pull-off \
         among it); books close to {:.1e}",
        c.drive_work_j / ev,
        c.contact_loss_j / ev,
        c.damping_loss_j / ev,
        c.energy_balance_rel
    );
    outln!(
        "E* given {:.4} GPa; the DMT fit window {:.0}–{:.0} % of the span from adhesion to peak",
        setup.contact.modulus_pa * 1e-9,
        100.0 * analysis.fit_window.0,
        100.0 * analysis.fit_window.1
    );
    Ok(())
}

/// Force against time over the recorded cycles (the ringing after pull-off in the
/// deflection's force) and against separation, approach and retract apart.
fn charts(report: &Report, c: &PeakForceCycle) -> Vec<Chart> {
    let title = format!(
        "{} law, f_m = {} kHz, A_m = {} nm, z_c = {:.3} nm ({})",
        report.law,
        report.modulation_frequency_hz * 1e-3,
        report.modulation_amplitude_m * 1e9,
        report.separation_m * 1e9,
        report.regime
    );
    let period = 1.0 / report.modulation_frequency_hz;
    let mut cycle_start = 0.0;
    let mut last_t = f64::NEG_INFINITY;
    let mut time = Vec::with_capacity(c.curve.len());
    let mut deflection = Vec::with_capacity(c.curve.len());
    for p in &c.curve {
        if p.t_s < last_t {
            cycle_start += period;
        }
        last_t = p.t_s;
        let t_us = (cycle_start + p.t_s) * 1e6;
        time.push((t_us, p.force_n * 1e9));
        deflection.push((t_us, p.deflection_m * 1e9));
    }
    let near: Vec<&ForcePoint> = c.curve.iter().filter(|p| p.separation_m < 10e-9).collect();
    let half = |approach: bool| -> Vec<(f64, f64)> {
        near.iter()
            .filter(|p| p.approach == approach)
            .map(|p| (p.separation_m * 1e9, p.force_n * 1e9))
            .collect()
    };
    vec![
        Chart {
            name: "peakforce_time".into(),
            title: title.clone(),
            x: Axis::linear("time t (µs)", "t_us"),
            y: Axis::linear("tip–sample force F (nN)", "force_nn"),
            legend: Corner::UpperRight,
            series: vec![Series::new("force (simulated)", time, Style::Line, 0)],
            labels: Vec::new(),
        },
        Chart {
            name: "peakforce_deflection".into(),
            title: title.clone(),
            x: Axis::linear("time t (µs)", "t_us"),
            y: Axis::linear("deflection z (nm)", "deflection_nm"),
            legend: Corner::UpperRight,
            series: vec![Series::new(
                "deflection (simulated): the ringing after pull-off",
                deflection,
                Style::Line,
                0,
            )],
            labels: Vec::new(),
        },
        Chart {
            name: "peakforce_curve".into(),
            title,
            x: Axis::linear("tip–sample separation α (nm)", "separation_nm"),
            y: Axis::linear("tip–sample force F (nN)", "force_nn"),
            legend: Corner::UpperRight,
            series: vec![
                Series::new("approach", half(true), Style::Line, 2),
                Series::new("retract", half(false), Style::Line, 1),
            ],
            labels: Vec::new(),
        },
    ]
}

impl PeakForceArgs {
    /// Refuse before any work what can be known bad from the flags alone.
    pub(super) fn check(&self) -> Result<()> {
        if let Some(f) = self.peak_force {
            check_setpoint(f)?;
        }
        self.out.check()
    }
}
