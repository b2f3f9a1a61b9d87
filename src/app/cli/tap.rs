//! `tapsim tap`: one tapping-mode simulation to its steady state.

use super::progress::Busy;
use crate::analysis::coexist::{Search, coexisting};
use crate::analysis::setpoint::states_at_setpoint;
use crate::app::config::{BranchChoice, TapInputs, length, number};
use crate::app::report::{output, plot, tap as report};
use crate::dynamics::observables::{Observe, Starts, tap};
use crate::error::{Error, Result};
use crate::instrument::average::{AverageRequest, reads_as_average, thermal_average};
use crate::instrument::noise::thermal_noise_at;
use clap::Args;
use std::path::PathBuf;

/// Simulate a tapping-mode cantilever against a tip–sample force law to its steady state:
/// amplitude, phase, energy dissipated per cycle and the phase that follows from it.
///
/// An AFM holds the amplitude at a setpoint while its z feedback moves the sample:
/// `tapsim tap --setpoint 0.8` lists every stable steady state whose A/A₀ is 0.8, each
/// with the rest separation z_c that gives it and its branch (attractive: φ above the
/// free phase, 90° at resonance; repulsive: below). Without a setpoint the tip is held
/// at a rest separation (--separation) and the state it settles on is reported.
///
/// Built-in defaults: a silicon cantilever (k = 40 N/m, f₀ = 300 kHz, Q = 400,
/// A₀ = 20 nm, driven at f₀) with a 20 nm silicon tip on a soft polymer
/// (E = 0.5 GPa, ν = 0.4; E* = 0.59 GPa), Δγ = 0.1 J/m², ε = 0.3 nm (μ ≈ 2.8),
/// rest separation z_c = 16 nm, the paper's hybrid law. Every value can be changed
/// by a flag or a TOML file (--config; keys are the flags' names, flags win; a file
/// may hold `setpoint` and `branch` in place of `separation`).
///
/// Laws: the paper's hybrid (the default) and the others --law lists, each explained
/// under it below. On top of any of them but none: a viscous sample
/// (--viscosity, Kelvin–Voigt) and a capillary neck (--rupture-distance, which on jkr,
/// hybrid and lj outlives the contact); on hertz and dmt, a relaxing sample instead
/// (--unrelaxed-modulus and --relaxation-time: a standard linear solid, whose memory
/// the motion carries: its orbits have three Floquet multipliers).
///
/// The motion starts from the free oscillation and settles on a steady state, which is
/// named: a period-n orbit (n ≤ 1000; its Floquet multipliers say whether it is stable) or
/// irregular motion. What is reported is what a lock-in and a dissipation measurement
/// read: averages over the n periods of the orbit, or over a window of irregular motion
/// (with standard errors), never one period of motion that is not period-1.
///
/// Where another stable period-1 state exists at the same rest separation (a bistable
/// setpoint: the attractive and the repulsive branch), tap names it (JSON `coexisting`),
/// or says in one line that none is known. It looks where the first-harmonic balance
/// of the cantilever puts a steady state (about a millisecond; each state verified on
/// the exact dynamics); --all-states also follows every family of period-1 orbits in
/// from far past z_c (some 0.1–3 s).
///
/// Near the onset of contact a turning point of the tip can pass a switch of the force
/// law (the jump-in, the pull-off) by less than the thermal motion of the cantilever
/// (√(k_BT/k) at 300 K, 10 pm on the defaults). Whether the tip touches in a period is
/// then decided by perturbations nothing controls, several long mode locks can coexist,
/// and the deterministic answer is not defined. Such a state is flagged "grazing a
/// switch" (its grazing margin is printed beside the thermal rms) and not well defined,
/// even where every start reaches one lock (another integrator or tolerance may reach
/// another); tapsim marches from six documented starts and lists every attractor
/// reached, with how many starts reached each (--starts N for any state). What an
/// instrument reads there is the average over the thermal motion: --temperature 300K.
///
/// Several eigenmodes (--modes 2 or 3; bimodal AFM): the higher modes, driven at their
/// own resonances with small amplitudes (a rectangular beam's by default: f₂ = 6.267 f₀,
/// A₀₂ = A₀/40), share the tip force; each mode's lock-in amplitude and phase, the
/// energy its drive puts in, its damping takes and the tip force exchanges with it,
/// over the common period (a higher mode's frequency is moved within --ratio-tolerance
/// to p/q times the drive's, and the table says by how much; with --ratio-tolerance 0
/// the frequencies stay as given and, with no common period, the motion is averaged
/// over windows of thousands of periods, each number with its error). `--setpoint` then holds
/// the first mode's A₁/A₀₁: every state that holds it, on each branch (--branch), each
/// followed from the one-mode state on its branch. JSON: the keys of the
/// orbit (e_ts_j, contact_fraction, floquet_multipliers, stable, …) and `modes`, one
/// object per mode (amplitude_ratio, phase_deg, e_drive_j, e_damp_j, e_exchange_j,
/// virial_j, energy_balance_rel, …).
///
/// JSON keys (--json): amplitude_m, amplitude_ratio, phase_deg, phase_from_energy_deg,
/// e_ts_j, e_ts_ev, e_ts_adhesion_j, e_ts_viscous_j and e_ts_capillary_j (E_ts by
/// mechanism), e_damp_j, e_drive_j, energy_balance_rel, virial_j, mean_force_n,
/// peak_force_n,
/// min_separation_m, contact_fraction, jumps_in, loop_area_j, tabor_mu, regime, period,
/// periods_averaged, stable, floquet_multipliers, amplitude_std_err_m,
/// phase_std_err_deg, e_ts_std_err_j, cycles, converged, grazing, grazing_margin_m,
/// thermal_rms_m, integration_error_m, attractors, well_defined, harmonics (harmonics 2…10 of
/// the deflection and the force over a periodic orbit: order, deflection_amplitude_m,
/// deflection_phase_deg, force_amplitude_n, force_phase_deg; null for irregular
/// motion), and more (see the guide, docs/src/how-to/tap.md).
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct TapArgs {
    #[command(flatten)]
    inputs: TapInputs,
    /// Write the trajectory of the last cycles as CSV (t_s, z_m, v_m_s, alpha_m,
    /// force_n, branch).
    #[arg(long, help_heading = "Output")]
    pub(super) trajectory: Option<PathBuf>,
    /// Plot the motion, the force loop and the phase portrait.
    ///
    /// Deflection and force against time, the force–separation loop and the phase
    /// portrait, as .png or .svg.
    #[arg(long, help_heading = "Output")]
    pub(super) plot: Option<PathBuf>,
    /// Cycles recorded for --trajectory and --plot.
    #[arg(
        hide_short_help = true,
        long,
        allow_hyphen_values = true,
        default_value_t = 3,
        help_heading = "Output"
    )]
    record_cycles: usize,
    /// March from N documented starts and list every distinct attractor reached, with
    /// how many starts reached it: 1 the free oscillation (what is reported), 2 the
    /// same at tolerances / 100, 3 rest, 4 and 5 ramps from z_c ± 0.1 A₀, then phases
    /// of the free oscillation. A state that grazes a switch lists its attractors from
    /// 6 starts without it. At most 64.
    #[arg(hide_short_help = true, long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=64), help_heading = "Numerics")]
    starts: Option<u64>,
    /// Look for other stable period-1 states at z_c also by following every family of
    /// period-1 orbits in from 1.2 A₀ (besides the default search from the roots of the
    /// first-harmonic balance; about a hundred times slower).
    #[arg(hide_short_help = true, long, help_heading = "Numerics")]
    all_states: bool,
    /// Amplitude setpoint A/A₀ in place of a rest separation (between 0 and 1; as an
    /// AFM's z feedback holds it): every stable period-1 steady state whose amplitude
    /// is the setpoint, on each branch (--branch), with the rest separation z_c that
    /// gives it. Not with --separation, --trajectory or --plot.
    #[arg(long, value_name = "A/A0", allow_hyphen_values = true, value_parser = number,
          conflicts_with = "amplitude_setpoint")]
    setpoint: Option<f64>,
    /// The amplitude setpoint as an amplitude (e.g. 16nm): --setpoint A_sp/A₀.
    #[arg(hide_short_help = true, long, allow_hyphen_values = true, value_parser = length)]
    amplitude_setpoint: Option<f64>,
    /// The branch whose states a setpoint lists [default: all]. Attractive:
    /// the phase lag above the free oscillator's (90° at resonance), net attractive
    /// force; repulsive: below it.
    #[arg(long, value_enum, ignore_case = true)]
    branch: Option<BranchChoice>,
    #[command(flatten)]
    pub(super) noise: super::NoiseArgs,
    #[command(flatten)]
    modes: crate::app::config::ModeInputs,
    /// Drive periods a --temperature run averages over where the deterministic state
    /// grazes a switch or is not a stable period-1 orbit: eight independent records of
    /// an eighth each (after ten decay times of settling), whose spread gives the
    /// standard errors.
    #[arg(hide_short_help = true, long, default_value_t = super::DEFAULT_THERMAL_PERIODS, help_heading = "Thermal noise")]
    thermal_periods: usize,
    /// Print one JSON object on stdout instead of the table.
    #[arg(long, help_heading = "Output")]
    json: bool,
    /// No progress or notes of files written on stderr.
    #[arg(long, short = 'q', help_heading = "Output")]
    pub(super) quiet: bool,
}

/// Run the subcommand.
pub fn run(args: TapArgs) -> Result<()> {
    let mut inputs =
        args.inputs
            .clone()
            .holding(args.setpoint, args.amplitude_setpoint, args.branch)?;
    inputs.takes_modes = true;
    if inputs.holds_setpoint() && inputs.separation.is_some() {
        return Err(super::separation_and_setpoint());
    }
    let (setup, numerics) = inputs.resolve()?;
    if let Some(set) = args.modes.mode_set(&inputs.mode_file, &setup.cantilever)? {
        use super::modal::refuse;
        refuse(args.trajectory.is_some(), "--trajectory")?;
        refuse(args.plot.is_some(), "--plot")?;
        refuse(args.starts.is_some(), "--starts")?;
        refuse(args.noise.temperature.is_some(), "--temperature")?;
        let ratio = inputs.setpoint_ratio(setup.cantilever.free_amplitude_m);
        let branch = inputs.branch.unwrap_or(BranchChoice::All).only();
        return super::modal::tap(
            &setup,
            &numerics,
            &set,
            ratio.map(|r| (r, branch)),
            (args.json, args.quiet),
        );
    }
    if inputs.holds_setpoint() {
        return at_setpoint(&args, &inputs, (setup, numerics));
    }
    let wants_trajectory = args.trajectory.is_some() || args.plot.is_some();
    let record = if wants_trajectory {
        args.record_cycles.max(1)
    } else {
        0
    };
    let observe = Observe {
        record_cycles: record,
        harmonics: true,
        starts: args
            .starts
            .map_or(Starts::WhereGrazing, |n| Starts::First(n as usize)),
    };
    // (Seconds on most samples; a relaxing sample's orbit is marched to, which can take
    // a minute or more.)
    let settling = Busy::new("tap: finding the steady state", args.quiet);
    let run = tap(&setup, &numerics, observe);
    settling.finish_and_clear();
    let run = run?;
    if let Some(path) = &args.trajectory {
        output::write_bytes(path, &report::trajectory_csv(&run.trajectory)?)?;
    }
    if let Some(path) = &args.plot {
        let title = format!(
            "{} law, z_c = {:.4} nm, A₀ = {:.4} nm",
            setup.law,
            setup.separation_m * 1e9,
            setup.cantilever.free_amplitude_m * 1e9
        );
        plot::render_stack(&report::trajectory_charts(&run, &title), path)?;
    }
    // Another stable period-1 state at this z_c (a bistable setpoint: the free
    // oscillation settles on one, an approach or a retract may sit on the other).
    let searching = Busy::new(
        "tap: looking for other stable states at this z_c",
        args.quiet,
    );
    let search = if args.all_states {
        Search::Thorough
    } else {
        Search::HarmonicBalance
    };
    let coexisting = coexisting(&setup, &numerics, &run.observables, search);
    searching.finish_and_clear();
    let coexisting = coexisting?;
    let noise = match args.noise.request() {
        Some(request) => Some(thermal_noise_at(&setup, &numerics, &request)?),
        None => None,
    };
    // Where the deterministic answer is not a stable period-1 orbit away from every
    // switch, what an instrument reads is the average over the thermal motion.
    let average = match args.noise.temperature {
        Some(temperature_k) if reads_as_average(&run.observables) => {
            let busy = Busy::new("tap: averaging the state over a thermal record", args.quiet);
            let request = AverageRequest {
                temperature_k,
                periods: args.thermal_periods,
                seed: 1,
            };
            let average = thermal_average(&setup, &numerics, &request.for_state(&setup));
            busy.finish_and_clear();
            Some(average?)
        }
        _ => None,
    };
    if args.json {
        let mut v = serde_json::to_value(&run).expect("observables serialise");
        if let serde_json::Value::Object(m) = &mut v {
            m.insert(
                "coexisting".into(),
                serde_json::to_value(&coexisting).expect("states serialise"),
            );
            m.insert(
                "coexisting_search".into(),
                serde_json::to_value(search).expect("a name serialises"),
            );
            if let Some(noise) = &noise {
                m.insert(
                    "thermal_noise".into(),
                    serde_json::to_value(noise).expect("noise serialises"),
                );
            }
            if let Some(average) = &average {
                m.insert(
                    "thermal_average".into(),
                    serde_json::to_value(average).expect("average serialises"),
                );
            }
        }
        outln!("{}", crate::app::report::records::document(&v)?);
    } else {
        out!("{}", report::to_text(&setup, &run));
        out!("{}", report::coexisting_text(&coexisting, search));
        match noise {
            Some(Some(n)) => outln!(
                "thermal noise at {} K through a lock-in of order {}, ENBW {} Hz (T_f = \
                 {:.4} µs), linear theory about the orbit: σ_A = {:.4} pm, σ_φ = {:.5}°",
                n.temperature_k,
                n.lockin_order,
                n.enbw_hz,
                n.time_constant_s * 1e6,
                n.sigma_amplitude_m * 1e12,
                n.sigma_phase_deg
            ),
            Some(None) => outln!(
                "thermal noise: not computed — the linear theory needs a stable period-1 \
                 orbit, and this state is not one"
            ),
            None => {}
        }
        if let Some(a) = average {
            let ev = crate::physics::params::ELECTRONVOLT_J;
            outln!(
                "thermal average at {} K over {} periods (what an instrument reads here: \
                 the deterministic state {}): E_ts = {:.3} ± {:.3} eV, φ = {:.3} ± {:.3}°, \
                 A/A₀ = {:.6} ± {:.1e}, touches in {:.2} ± {:.2} % of periods (standard \
                 errors from {} independent records)",
                a.temperature_k,
                a.periods,
                if run.observables.grazing {
                    "grazes a switch"
                } else {
                    "is not a stable period-1 orbit"
                },
                a.e_ts_j / ev,
                a.e_ts_std_err_j / ev,
                a.phase_deg,
                a.phase_std_err_deg,
                a.amplitude_ratio,
                a.amplitude_ratio_std_err,
                100.0 * a.touch_fraction,
                100.0 * a.touch_fraction_std_err,
                a.records
            );
        }
    }
    Ok(())
}

/// `tap --setpoint`: the states at the setpoint, listed.
fn at_setpoint(
    args: &TapArgs,
    inputs: &TapInputs,
    (setup, numerics): (
        crate::dynamics::setup::TapSetup,
        crate::dynamics::setup::Numerics,
    ),
) -> Result<()> {
    if args.trajectory.is_some() || args.plot.is_some() {
        return Err(Error::NotApplicable(
            "--trajectory and --plot draw one state: run `tapsim tap --separation <z_c>` \
             with the separation_m of the state at the setpoint you want"
                .into(),
        ));
    }
    let ratio = inputs
        .setpoint_ratio(setup.cantilever.free_amplitude_m)
        .expect("called with a setpoint");
    let branch = inputs.branch.unwrap_or(BranchChoice::All).only();
    let spinner = Busy::new(
        "tap: following the period-1 families to the setpoint",
        args.quiet,
    );
    let states = states_at_setpoint(&setup, &numerics, ratio, branch);
    spinner.finish_and_clear();
    let states = states.map_err(|e| match e {
        Error::OutOfRange(why) if inputs.amplitude_setpoint.is_some() => {
            Error::OutOfRange(format!(
                "{why} (--amplitude-setpoint is an amplitude, bare numbers in m: e.g. 16nm; \
             --setpoint takes A/A₀)"
            ))
        }
        e => e,
    })?;
    // Each state is a stable period-1 orbit: the linear theory reads its noise.
    let noise = match args.noise.request() {
        Some(request) => {
            let prepared = crate::dynamics::setup::Prepared::new(&setup, &numerics)?;
            states
                .iter()
                .map(|s| s.thermal_noise(&prepared, &request).map(Some))
                .collect::<Result<Vec<_>>>()?
        }
        None => vec![None; states.len()],
    };
    if args.json {
        let mut listed = serde_json::to_value(&states).expect("states serialise");
        if let serde_json::Value::Array(list) = &mut listed {
            for (state, noise) in list.iter_mut().zip(&noise) {
                if let (serde_json::Value::Object(m), Some(noise)) = (state, noise) {
                    m.insert(
                        "thermal_noise".into(),
                        serde_json::to_value(noise).expect("noise serialises"),
                    );
                }
            }
        }
        let mut top = listed[0].clone();
        if let serde_json::Value::Object(m) = &mut top {
            m.insert("setpoint".into(), ratio.into());
            m.insert("states".into(), listed);
        }
        outln!("{}", crate::app::report::records::document(&top)?);
    } else {
        out!("{}", report::setpoint_text(&setup, ratio, &states));
        for (state, noise) in states.iter().zip(&noise) {
            if let Some(n) = noise {
                outln!(
                    "thermal noise on the {} state (z_c = {:.4} nm) at {} K, lock-in order \
                     {}, ENBW {} Hz: σ_A = {:.4} pm, σ_φ = {:.5}°",
                    format!("{:?}", state.branch).to_lowercase(),
                    state.separation_m * 1e9,
                    n.temperature_k,
                    n.lockin_order,
                    n.enbw_hz,
                    n.sigma_amplitude_m * 1e12,
                    n.sigma_phase_deg
                );
            }
        }
    }
    Ok(())
}
