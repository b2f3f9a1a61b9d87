//! `tapsim scan`: a line scanned over a sample with the z feedback closed.

use crate::analysis::sweep::Shard;
use crate::app::config::{TapInputs, number};
use crate::app::report::chart::{Axis, Chart, Corner, Series, Style};
use crate::app::report::heatmap::HeatMap;
use crate::app::report::part::{self, Job};
use crate::app::sample::{BLEND, Sample};
use crate::dynamics::setup::{Prepared, significant};
use crate::error::{Error, Result};
use crate::instrument::feedback::{MAX_INTEGRAL, PiController};
use crate::instrument::lockin::LockIn;
use crate::instrument::modal::ModalProbe;
use crate::instrument::repeats::{DEFAULT_TOLERANCE, Repeats};
use crate::instrument::scan::{
    MAX_IMAGE_PIXELS, MAX_PIXELS, Pixel, row, row_probe, settled_material,
};
use crate::instrument::thermal::{
    STEPS_PER_PERIOD, ThermalForce, check_temperature, intensity_hat,
};
use clap::Args;
use serde_json::value::RawValue;

/// Scan one line over a sample as an AFM images it: a lock-in reads the amplitude and
/// phase at the drive frequency, a PI controller moves the z piezo to hold the amplitude
/// at the setpoint, and the tip moves along the line at the line rate, trace then
/// retrace. Per pixel: the topography (the piezo position), the amplitude error and the
/// lock-in phase, each the mean over the pixel's drive periods.
///
/// The built-in sample is a flat blend of two polymers on a 1 µm line (A: E = 0.5 GPa,
/// Δγ = 0.1 J/m², the defaults, on the first half; B: E = 1 GPa, Δγ = 0.08 J/m²): the
/// image shows a step that is not there (the two materials hold the setpoint at
/// different rest separations) and the phase contrast between them. --sample FILE.toml
/// describes another: its materials (any of tap's sample and law parameters), their
/// layout along the line, each region with a surface height, a mask of cells over it
/// (a CSV of material names, or a PNG whose colours the file names) and discs laid over
/// both (see examples/samples/).
///
/// --lines N records an image: N lines across the sample's width, each engaged and
/// scanned on its own (in parallel, --threads; the same result on any number of
/// threads), drawn by --plot as heat maps of topography and phase side by side.
/// --shard I/N (or a Slurm job array) scans every N-th line into a part file; `tapsim
/// merge` joins the parts into the outputs one whole run writes.
/// The loop is engaged over the first region from the free oscillation at 1.2 A₀ (10 000
/// drive periods), so it sits on the branch a falling setpoint stays on (attractive on
/// the defaults). A slow scan (the default: 4 lines/s, 32 pixels, about 2 300 drive
/// periods a pixel at 300 kHz; seconds of computing) lets the loop settle in each
/// pixel; a fast one shows the feedback's artefacts: overshoot after a step up, the
/// amplitude running away after a step down (the tip loses the sample).
///
/// The cantilever is marched at an integrator tolerance of 2e-7 (--rtol to change it):
/// the energy balance of the default orbit stays below 1e-6 there.
///
/// Bimodal imaging (--modes 2 or 3): the higher modes driven at their resonances (as
/// in `tapsim tap --modes`), each read by its own lock-in (the same filter) while the
/// loop holds the first mode's A₁/A₀₁; every pixel adds each higher mode's
/// amplitude ratio and phase (JSON `modes`; CSV modes_1_mode, modes_1_amplitude_ratio,
/// modes_1_phase_deg, …), and the plot φ₂ beside φ₁. About 16 times slower than one
/// mode (a second mode at 6.25 f₀ of Q ≈ 2 500 is integrated with it); no thermal
/// noise. The loop engages from above, as with one mode; where the modes hold the
/// setpoint in several states (`tapsim tap --modes 2 --setpoint 0.8` lists them) the
/// image shows the one the scan's history leads to.
///
/// Off-resonance tapping (--mode peakforce): the support modulated (2 kHz by 150 nm by
/// default), the peak-force feedback moving the z piezo once a cycle to hold --peak-force
/// (5 nN), each line engaged over its first region; per pixel (about f_m/(pixels × line
/// rate) cycles) the topography and the QNM channels of its last cycle: peak force,
/// adhesion, dissipation, deformation and the DMT modulus (JSON/CSV keys peak_force_n,
/// error_n, adhesion_n, dissipation_j, deformation_m, dmt_modulus_pa), drawn as heat
/// maps of topography, adhesion, dissipation and modulus. Once the loop repeats itself
/// over a region the cycles up to the next are taken as repeats (--exact marches every
/// one; the channels agree within 1e-6, tested). Sharded and merged as tapping images
/// are; no thermal noise.
///
/// FM imaging (--mode fm): the cantilever self-excited at its shifted resonance (the
/// phase-locked loop and amplitude controller of `tapsim fm`, running every drive
/// period), the z feedback moving the piezo to hold --frequency-shift (-200 Hz), each
/// line engaged on the settled FM state over its first region; per pixel the
/// topography, the frequency shift and its error, the excitation F/F₀ and the energy
/// per cycle the dissipation channel reads from it (JSON/CSV keys frequency_shift_hz,
/// error_hz, excitation_ratio, dissipation_j, amplitude_ratio), drawn as topography,
/// Δf and dissipation. Every material must hold the setpoint on the attractive side of
/// its Δf(z) (`tapsim fm` shows the curves); a step up that carries the tip past the
/// turning point of Δf(z) is refused (the loop would run the tip in). Repeats are taken
/// as in tapping (--exact marches every period; within 0.3 µHz, tested). Sharded and
/// merged as tapping images are; no thermal noise.
///
/// Output: a table, --json (a record per pixel: direction, line, y_m, x_m,
/// topography_m, amplitude_ratio, error, phase_deg), --csv, --plot (one line: topography
/// and phase profiles, trace and retrace; an image: heat maps of the trace).
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct ScanArgs {
    #[command(flatten)]
    inputs: TapInputs,
    #[command(flatten)]
    pub(super) out: super::SweepOutput,
    /// The sample (TOML; default: the built-in two-polymer blend).
    #[arg(long)]
    sample: Option<std::path::PathBuf>,
    /// Amplitude setpoint A/A₀ the feedback holds.
    #[arg(long, value_name = "A/A0", allow_hyphen_values = true, value_parser = number,
          default_value_t = 0.8)]
    setpoint: f64,
    /// Pixels along the line.
    #[arg(long, allow_hyphen_values = true, default_value_t = 32)]
    pixels: usize,
    /// Lines across the sample (an image when more than one).
    #[arg(long, allow_hyphen_values = true, default_value_t = 1)]
    lines: usize,
    /// Worker threads for the lines of an image (0: all cores).
    #[arg(long, allow_hyphen_values = true, default_value_t = 0)]
    threads: usize,
    /// Lines per second (each direction).
    #[arg(long, allow_hyphen_values = true, value_parser = number, default_value_t = 4.0)]
    line_rate: f64,
    /// Integral gain of the z feedback: K_i, the move of z_c in A₀ per unit of A/A₀
    /// error and drive period; or, ending in /s, the I gain an instrument panel in SI
    /// shows (metres of z per metre of amplitude error and second, K_i·f_drive: 0.002 at
    /// 300 kHz is 600/s).
    #[arg(long, allow_hyphen_values = true, value_parser = integral_gain,
          default_value_t = IntegralGain::PerPeriod(0.002))]
    integral_gain: IntegralGain,
    /// Proportional gain K_p: the move of z_c per step of the amplitude error, both in
    /// one length unit (an instrument panel's P gain in m/m).
    #[arg(long, allow_hyphen_values = true, value_parser = number, default_value_t = 0.0)]
    proportional_gain: f64,
    /// Lock-in filter order (1–4).
    #[arg(
        hide_short_help = true,
        long,
        allow_hyphen_values = true,
        default_value_t = 4
    )]
    lockin_order: usize,
    /// Lock-in time constant, in drive periods (at most 1000).
    #[arg(long, allow_hyphen_values = true, value_parser = number, default_value_t = 2.0)]
    lockin_periods: f64,
    /// Trace only.
    #[arg(long)]
    no_retrace: bool,
    /// March every drive period. By default, over a stretch of sample that does not
    /// change, once the whole loop (oscillator, lock-in, piezo, controller) repeats
    /// itself to 1e-7 A₀ (its distance from the loop's fixed point, bounded from how fast
    /// it approached it), the periods up to the next change are taken as repeats of the
    /// last: images agree with --exact to far below 1 pm and 1e-3° (tested), many times
    /// faster. Motion that does not repeat each period (near the onset of contact, a
    /// second mode) and a thermal force are always marched; under a thermal force
    /// --exact also locates every force step of free flight against the contact
    /// instead of taking the steps that cannot meet it from one precomputed transition
    /// (the same motion to round-off, tested).
    #[arg(long)]
    exact: bool,
    /// Temperature [K; default none]: the cantilever shaken by the thermal force of its
    /// damping (S_F = 4k_BT·k/(ω₀Q), held over 64 steps a period), each line drawing
    /// from its own stream of --seed; the table then ends with each material's
    /// pixel-to-pixel phase noise and the contrast over it.
    #[arg(long, allow_hyphen_values = true, value_parser = crate::app::config::temperature,
          help_heading = "Thermal noise")]
    temperature: Option<f64>,
    /// Seed of the thermal force's streams (one a line).
    #[arg(long, default_value_t = 1, help_heading = "Thermal noise")]
    seed: u64,
    #[command(flatten)]
    modes: crate::app::config::ModeInputs,
    #[command(flatten)]
    split: super::shard::ShardArgs,
    #[command(flatten)]
    qnm: super::qnm::QnmArgs,
    #[command(flatten)]
    fm: super::fm_scan::FmScanArgs,
    #[command(flatten)]
    pub(super) images: super::image::ImageFiles,
}

/// A pixel with its direction and line.
#[derive(serde::Serialize, serde::Deserialize)]
struct Row {
    direction: String,
    /// The line's index (0 first) and its position across the sample, in m.
    line: usize,
    y_m: f64,
    #[serde(flatten)]
    pixel: Pixel,
}

/// The most drive periods one scan marches (every line, both directions).
const MAX_PERIODS: f64 = 2e8;

/// The most drive periods a scan marches under the thermal force (none skipped): some 20
/// minutes on one core, ten on two.
const MAX_NOISY_PERIODS: f64 = 3e7;

/// The loop's engagement over the first region, in drive periods.
const ENGAGE_PERIODS: usize = 10_000;

/// What of the sample determines a scan's results, for a part file's configuration.
fn sample_config(sample: &Sample) -> serde_json::Value {
    serde_json::to_value((
        &sample.materials,
        &sample.layout,
        (sample.length_m, sample.width_m),
    ))
    .expect("a sample serialises")
}

/// Run the subcommand.
pub fn run(args: ScanArgs) -> Result<()> {
    let mut base = args.inputs.clone().with_config()?;
    base.takes_modes = true;
    base.no_setpoint("scan")?;
    if base.separation.is_some() {
        return Err(Error::NotApplicable(
            "a scan holds the setpoint (--setpoint); the feedback sets the separation".into(),
        ));
    }
    let sample = match &args.sample {
        Some(path) => Sample::from_file(path, &base)?,
        None => Sample::from_toml(BLEND, &base)?,
    };
    if !(1..=MAX_PIXELS).contains(&args.pixels) || !(1..=MAX_PIXELS).contains(&args.lines) {
        return Err(Error::OutOfRange(format!(
            "--pixels and --lines are from 1 to {MAX_PIXELS}, not {} and {}",
            args.pixels, args.lines
        )));
    }
    if args.pixels * args.lines > MAX_IMAGE_PIXELS {
        return Err(Error::OutOfRange(format!(
            "an image holds at most {MAX_IMAGE_PIXELS} pixels, not {} × {}",
            args.lines, args.pixels
        )));
    }
    crate::error::positive("line rate", args.line_rate)?;
    if !(args.lockin_periods > 0.0 && args.lockin_periods <= 1000.0) {
        return Err(Error::OutOfRange(format!(
            "--lockin-periods is from above 0 to 1000 drive periods, not {}",
            args.lockin_periods
        )));
    }
    let (_, mut numerics) = base.resolve()?;
    if base.rtol.is_none() {
        numerics.rtol = crate::instrument::MARCH_RTOL;
        numerics.atol = 1e-2 * crate::instrument::MARCH_RTOL;
    }
    let first_setup = &sample.materials[0].1;
    let set = args
        .modes
        .mode_set(&base.mode_file, &first_setup.cantilever)?;
    if set.is_some() {
        super::modal::refuse(args.temperature.is_some(), "--temperature")?;
    }
    let prepared = sample
        .materials
        .iter()
        .map(|(_, s)| Prepared::new(s, &numerics))
        .collect::<Result<Vec<_>>>()?;
    let modal = match &set {
        Some(set) => Some(
            prepared
                .iter()
                .map(|p| crate::dynamics::modes::with_modes(p.clone(), set))
                .collect::<Result<Vec<_>>>()?,
        ),
        None => None,
    };
    let whole_outputs =
        args.out.csv.is_some() || args.out.plot.is_some() || args.out.json || args.images.any();
    let shard = args.split.resolve("scan", whole_outputs)?;
    let mine = shard.unwrap_or(Shard::WHOLE).items(args.lines);
    let lines: Vec<(f64, Vec<crate::instrument::scan::Region>)> = (0..args.lines)
        .map(|j| {
            let y = sample.width_m * (j as f64 + 0.5) / args.lines as f64;
            (y, sample.layout.line_at(y, sample.length_m))
        })
        .collect();
    if let Some(fm) = args.fm.resolve(args.qnm.mode)? {
        super::qnm::refuse_in_mode(
            "fm",
            &[
                ("--temperature", args.temperature.is_some()),
                ("--modes", set.is_some()),
            ],
        )?;
        return super::fm_scan::scan(
            &fm,
            (&sample.materials, &prepared),
            &numerics,
            &lines,
            (sample.length_m, args.pixels, args.line_rate),
            (args.threads, !args.no_retrace, args.exact),
            (&args.out, &args.split, sample_config(&sample)),
            (
                &args.images,
                super::image::meta(
                    "frequency modulation (FM)",
                    first_setup,
                    &args.sample,
                    (args.lines, args.pixels, args.line_rate),
                    format!("frequency shift {} Hz", fm.setpoint_hz()),
                    "z feedback on the frequency shift (integral)",
                ),
                (sample.length_m, sample.width_m),
            ),
        );
    }
    if let Some(q) = args.qnm.resolve()? {
        super::qnm::refuse_in_mode(
            "peakforce",
            &[
                ("--temperature", args.temperature.is_some()),
                ("--modes", set.is_some()),
            ],
        )?;
        return super::qnm::scan(
            &q,
            &prepared,
            &numerics,
            &lines,
            (sample.length_m, args.pixels, args.line_rate),
            (args.threads, !args.no_retrace, args.exact),
            (&args.out, &args.split, sample_config(&sample)),
            (
                &args.images,
                super::image::meta(
                    "off-resonance tapping (peak-force)",
                    first_setup,
                    &args.sample,
                    (args.lines, args.pixels, args.line_rate),
                    format!("peak force {} nN", q.setpoint_n * 1e9),
                    &format!("peak-force feedback, gain {} a cycle", q.gain),
                ),
                (sample.length_m, sample.width_m),
            ),
        );
    }
    let first = &prepared[lines[0].1[0].material];
    let sim = first.simulation();
    let omega = sim.osc.omega;
    let period_hat = sim.osc.period();
    let drive_hz = first.setup.cantilever.drive_frequency_hz;
    let per_pixel = (drive_hz / (args.pixels as f64 * args.line_rate)).round();
    let directions = if args.no_retrace { 1 } else { 2 };
    let total = per_pixel * (args.pixels * args.lines * directions) as f64;
    if !(per_pixel >= 1.0 && total <= MAX_PERIODS) {
        return Err(Error::OutOfRange(format!(
            "{} lines of {} pixels at {} lines/s is {per_pixel:e} drive periods a pixel, \
             {total:.3e} in all: from 1 a pixel to {MAX_PERIODS:e} in all",
            args.lines,
            args.pixels,
            if (1e-3..1e6).contains(&args.line_rate) {
                args.line_rate.to_string()
            } else {
                format!("{:e}", args.line_rate)
            }
        )));
    }
    // Under the thermal force no period repeats another: every one is marched, at some
    // 42 µs each (`cargo bench -p tapsim-benches --bench dynamics -- noise/`).
    if args.temperature.is_some_and(|t| t > 0.0) && total > MAX_NOISY_PERIODS {
        return Err(Error::OutOfRange(format!(
            "under the thermal force every drive period is marched: {total:.3e} in all, \
             about {:.0} min on one core at 42 µs a period; at most {MAX_NOISY_PERIODS:e} \
             (fewer lines or pixels, or a faster line rate)",
            total * 42e-6 / 60.0
        )));
    }
    let per_pixel = per_pixel as usize;
    let cantilever = first.setup.cantilever;
    let intensity = match args.temperature {
        Some(t) => {
            check_temperature(t)?;
            intensity_hat(
                t,
                cantilever.stiffness_n_m,
                cantilever.quality,
                cantilever.free_amplitude_m,
            )
        }
        None => 0.0,
    };
    let lockin = LockIn::new(args.lockin_order, args.lockin_periods * period_hat, omega)?;
    let k_i = args.integral_gain.per_period(drive_hz);
    // The controller's own bound on K_i, said in the units the gain was given in.
    let controller =
        PiController::new(args.setpoint, args.proportional_gain, k_i).map_err(|e| {
            match (args.integral_gain, &e) {
                (
                    IntegralGain::PerSecond(g),
                    Error::InvalidParameter {
                        name: "integral gain",
                        ..
                    },
                ) => Error::OutOfRange(format!(
                    "an integral gain of {g}/s is K_i = {} a drive period at {} kHz: \
                 from 0 to {}/s (K_i = {MAX_INTEGRAL}; a loop that moves the sample by A₀ \
                 and more per period on a small error only throws the tip about)",
                    significant(k_i),
                    drive_hz * 1e-3,
                    MAX_INTEGRAL * drive_hz
                )),
                _ => e,
            }
        })?;
    let feedback = feedback_panel(&controller, drive_hz);
    let bar = args
        .out
        .progress("scan", mine.len() * (args.pixels * directions + 1));
    let shape = (sample.length_m, args.pixels, per_pixel);
    let scanned = {
        use rayon::prelude::*;
        crate::analysis::sweep::thread_pool(args.threads)?.install(|| {
            mine.par_iter()
                .map(|&j| {
                    bar.inc(1);
                    let mut repeats = if args.exact {
                        Repeats::exact()
                    } else {
                        Repeats::within(DEFAULT_TOLERANCE)
                    };
                    let engage = (ENGAGE_PERIODS, &mut repeats);
                    if let Some(modal) = &modal {
                        let mut probe =
                            ModalProbe::new(modal, lockin.order(), lockin.time_constant_hat())?;
                        return row_probe(
                            &mut probe,
                            &lines[j].1,
                            shape,
                            controller,
                            engage,
                            !args.no_retrace,
                            |_| bar.inc(1),
                        );
                    }
                    let force =
                        ThermalForce::new(intensity, STEPS_PER_PERIOD, args.seed, j as u64)?;
                    let force = if args.exact { force.exact() } else { force };
                    row(
                        &prepared,
                        &lines[j].1,
                        shape,
                        (lockin, controller, force),
                        engage,
                        !args.no_retrace,
                        |_| bar.inc(1),
                    )
                })
                .collect::<Result<Vec<_>>>()
        })?
    };
    // Each line's rows, trace then retrace.
    let per_line: Vec<Vec<Row>> = mine
        .iter()
        .zip(scanned)
        .map(|(&line, (trace, retrace))| {
            let y_m = lines[line].0;
            let tagged = move |direction: &str, pixels: Vec<Pixel>| {
                let direction = direction.to_string();
                pixels.into_iter().map(move |pixel| Row {
                    direction: direction.clone(),
                    line,
                    y_m,
                    pixel,
                })
            };
            tagged("trace", trace)
                .chain(retrace.into_iter().flat_map(|r| tagged("retrace", r)))
                .collect()
        })
        .collect();
    bar.finish_and_clear();
    let image = part::ImageInfo {
        size_m: (sample.length_m, sample.width_m),
        meta: super::image::meta(
            "tapping (amplitude modulation)",
            first_setup,
            &args.sample,
            (args.lines, args.pixels, args.line_rate),
            format!("A/A0 = {}", args.setpoint),
            &feedback,
        ),
    };
    let job = Job::Scan {
        lines: args.lines,
        pixels: args.pixels,
        retrace: !args.no_retrace,
        setpoint: args.setpoint,
        image: Some(image.clone()),
    };
    if let Some(shard) = shard {
        let config = serde_json::to_value((
            &sample.materials,
            &sample.layout,
            (sample.length_m, sample.width_m),
            &numerics,
            (per_pixel, args.lockin_order, args.lockin_periods),
            (args.proportional_gain, controller.integral),
            (args.temperature, args.seed, args.exact),
            &set,
        ))
        .expect("a configuration serialises");
        return args.split.write(
            ("scan", shard, args.out.quiet),
            job,
            &part::Config::Whole(config),
            mine,
            per_line
                .iter()
                .map(|rows| part::raw_records(rows))
                .collect::<Result<_>>()?,
        );
    }
    let rows: Vec<Row> = per_line.into_iter().flatten().collect();
    args.out
        .write_files_drawn(&rows, |path| draw(&job, &rows, path))?;
    if args.images.any() {
        args.images.write(
            &image_channels(&rows, (args.lines, args.pixels), image.size_m),
            &image.meta,
        )?;
    }
    if args.out.json {
        return args.out.print_json(&rows);
    }
    outln!(
        "{} at A/A₀ = {}: {} pixels a line, {per_pixel} drive periods each",
        if args.lines > 1 {
            format!("image of {} lines", args.lines)
        } else {
            "line scan".into()
        },
        args.setpoint,
        args.pixels
    );
    outln!("z feedback: {feedback}");
    let higher = rows.first().map_or(0, |r| r.pixel.modes.len());
    let mut head = format!(
        "{:>10} {:>10} {:>8} {:>12} {:>10} {:>10} {:>10}",
        "y (nm)",
        "x (nm)",
        "dir",
        "height (nm)",
        if higher > 0 { "A1/A01" } else { "A/A0" },
        "error",
        if higher > 0 {
            "phi1 (deg)"
        } else {
            "phi (deg)"
        }
    );
    for k in 2..2 + higher {
        head += &format!(
            " {:>10} {:>10}",
            format!("A{k}/A0{k}"),
            format!("phi{k} (deg)")
        );
    }
    if args.lines > 1 {
        let values: Vec<Vec<f64>> = rows
            .iter()
            .filter(|r| r.direction == "trace")
            .map(|r| {
                let p = &r.pixel;
                vec![
                    p.topography_m * 1e9,
                    p.amplitude_ratio,
                    p.error,
                    p.phase_deg,
                ]
            })
            .collect();
        super::image::summary(
            &["height (nm)", "A/A0", "amplitude error", "phase (deg)"],
            &values,
            rows.len(),
        )?;
    }
    if args.lines == 1 {
        outln!("{head}");
    }
    for r in rows.iter().filter(|_| args.lines == 1) {
        let p = &r.pixel;
        let mut line = format!(
            "{:>10.2} {:>10.2} {:>8} {:>12.4} {:>10.6} {:>10.2e} {:>10.4}",
            r.y_m * 1e9,
            p.x_m * 1e9,
            r.direction.as_str(),
            p.topography_m * 1e9,
            p.amplitude_ratio,
            p.error,
            p.phase_deg
        );
        for m in &p.modes {
            line += &format!(" {:>10.6} {:>10.4}", m.amplitude_ratio, m.phase_deg);
        }
        outln!("{line}");
    }
    if let Some(t) = args.temperature {
        // Each material's settled trace pixels: their mean phase and scatter.
        let mut phases: Vec<Vec<f64>> = vec![Vec::new(); sample.materials.len()];
        for r in rows.iter().filter(|r| r.direction == "trace") {
            let i = (r.pixel.x_m / sample.length_m * args.pixels as f64).floor() as usize;
            let regions = &lines[r.line].1;
            if let Some(m) = settled_material(regions, sample.length_m, args.pixels, i) {
                phases[m].push(r.pixel.phase_deg);
            }
        }
        let stats: Vec<Option<(f64, f64, usize)>> = phases
            .iter()
            .map(|v| {
                let n = v.len();
                (n >= 3).then(|| {
                    let (m, var) = crate::numeric::mean_and_variance(v.iter().copied());
                    (m, var.sqrt(), n)
                })
            })
            .collect();
        outln!(
            "thermal noise at {t} K (seed {}): the phase over each material's settled trace \
             pixels (those whose pixel before lies on it too), mean ± pixel-to-pixel \
             standard deviation:",
            args.seed
        );
        for ((name, _), stat) in sample.materials.iter().zip(&stats) {
            match stat {
                Some((m, sd, n)) => outln!("  {name}: φ = {m:.4} ± {sd:.4}° ({n} pixels)"),
                None => outln!("  {name}: fewer than 3 settled pixels"),
            }
        }
        let present: Vec<(&str, (f64, f64, usize))> = sample
            .materials
            .iter()
            .zip(&stats)
            .filter_map(|((name, _), s)| s.map(|s| (name.as_str(), s)))
            .collect();
        if let [(a, (ma, sa, _)), .., (b, (mb, sb, _))] = present.as_slice() {
            outln!(
                "  Δφ({b} − {a}) = {:.4}°, |Δφ|/√(σ_{a}² + σ_{b}²) = {:.1}",
                mb - ma,
                (mb - ma).abs() / sa.hypot(*sb)
            );
        }
    }
    Ok(())
}

/// What a plot shows of a pixel's record: its direction (trace?), position (y, x in m),
/// topography (m), phase (deg) and the second mode's phase (deg), if read.
type Point = (bool, f64, f64, f64, f64, Option<f64>);

/// A pixel's record, as computed or as read back from a part file.
pub(super) trait ScanRecord: serde::Serialize {
    /// What a plot shows of it.
    fn point(&self) -> Option<Point>;
}

impl Row {
    /// What a plot shows of this pixel.
    fn point_of(&self) -> Point {
        let p = &self.pixel;
        (
            self.direction == "trace",
            self.y_m,
            p.x_m,
            p.topography_m,
            p.phase_deg,
            p.modes.first().map(|m| m.phase_deg),
        )
    }
}

impl ScanRecord for Row {
    fn point(&self) -> Option<Point> {
        Some(self.point_of())
    }
}

impl ScanRecord for Box<RawValue> {
    fn point(&self) -> Option<Point> {
        Some(serde_json::from_str::<Row>(self.get()).ok()?.point_of())
    }
}

/// The Gwyddion channels of a scanned image's `rows` ([`super::image::channels`]):
/// topography, amplitude, amplitude error and phase, and each higher mode's phase.
fn image_channels(
    rows: &[Row],
    shape: (usize, usize),
    size_m: (f64, f64),
) -> Vec<crate::app::report::gwyddion::Channel> {
    let mut names = vec![
        ("Topography", "m"),
        ("Amplitude A/A0", ""),
        ("Amplitude error", ""),
        ("Phase", "deg"),
    ];
    let higher = rows.first().map_or(0, |r| r.pixel.modes.len());
    let mode_names: Vec<String> = (2..2 + higher).map(|k| format!("Phase {k}")).collect();
    names.extend(mode_names.iter().map(|n| (n.as_str(), "deg")));
    let values: Vec<(bool, usize, f64, Vec<f64>)> = rows
        .iter()
        .map(|r| {
            let p = &r.pixel;
            let mut v = vec![p.topography_m, p.amplitude_ratio, p.error, p.phase_deg];
            v.extend(p.modes.iter().map(|m| m.phase_deg));
            (r.direction == "trace", r.line, p.x_m, v)
        })
        .collect();
    super::image::channels(&values, shape, size_m, &names)
}

/// Write a whole scan's outputs from its records: `tapsim merge` writes a sharded
/// image's through this ([`super::SweepOutput::emit`]), its Gwyddion files
/// ([`super::image::ImageFiles`]) among them.
pub(super) fn emit<T: ScanRecord>(
    out: &super::SweepOutput,
    extra: &[std::path::PathBuf],
    job: &Job,
    records: &[T],
) -> Result<()> {
    let (files, extra) = super::image::ImageFiles::among(extra)?;
    let image = match job {
        _ if !files.any() => None,
        Job::Scan {
            lines,
            pixels,
            image: Some(image),
            ..
        } => Some(((*lines, *pixels), image)),
        _ => return Err(files.no_image()),
    };
    out.emit(
        ("scan", &extra),
        records,
        || crate::app::report::records::columns_json(records),
        Some(&|path| draw(job, records, path)),
    )?;
    let Some((shape, image)) = image else {
        return Ok(());
    };
    let rows: Vec<Row> = crate::app::report::records::typed(records, "scan")?;
    files.write(&image_channels(&rows, shape, image.size_m), &image.meta)
}

/// The plot of a scan: profiles of one line, heat maps of an image.
fn draw<T: ScanRecord>(job: &Job, records: &[T], path: &std::path::Path) -> Result<()> {
    let points: Vec<Point> = records.iter().filter_map(ScanRecord::point).collect();
    match *job {
        Job::Scan {
            lines,
            pixels,
            setpoint,
            ..
        } if lines > 1 => crate::app::report::plot::render_side_by_side(
            &images(&points, lines, pixels, setpoint),
            path,
        ),
        _ => crate::app::report::plot::render_stack(&charts(&points), path),
    }
}

/// Topography and phase profiles, trace and retrace.
fn charts(rows: &[Point]) -> Vec<Chart> {
    let profile = |name: &str, title: &str, label: &str, pick: fn(&Point) -> Option<f64>| {
        let series: Vec<Series> = [("trace", Style::Line, 1), ("retrace", Style::Dashed, 2)]
            .into_iter()
            .filter_map(|(dir, style, color)| {
                let points: Vec<(f64, f64)> = rows
                    .iter()
                    .filter(|r| r.0 == (dir == "trace"))
                    .filter_map(|r| Some((r.2 * 1e9, pick(r)?)))
                    .collect();
                (!points.is_empty()).then(|| Series::new(dir, points, style, color))
            })
            .collect();
        Chart {
            name: name.into(),
            title: title.into(),
            x: Axis::linear("position along the line x (nm)", "x_nm"),
            y: Axis::linear(label, name),
            legend: Corner::quietest(&series),
            series,
            labels: vec![],
        }
    };
    let bimodal = rows.iter().any(|r| r.5.is_some());
    let mut charts = vec![
        profile(
            "topography_nm",
            "topography (z piezo)",
            "height (nm)",
            |p| Some(p.3 * 1e9),
        ),
        profile(
            "phase_deg",
            if bimodal {
                "first mode's lock-in phase"
            } else {
                "lock-in phase"
            },
            if bimodal {
                "phase lag φ₁ (deg)"
            } else {
                "phase lag φ (deg)"
            },
            |p| Some(p.4),
        ),
    ];
    if bimodal {
        charts.push(profile(
            "phase2_deg",
            "second mode's lock-in phase",
            "phase lag φ₂ (deg)",
            |p| p.5,
        ));
    }
    charts
}

/// Heat maps of the trace's topography and phase over the image, side by side.
fn images(rows: &[Point], lines: usize, pixels: usize, setpoint: f64) -> Vec<HeatMap> {
    let bimodal = rows.iter().any(|r| r.5.is_some());
    let trace: Vec<&Point> = rows.iter().filter(|r| r.0).collect();
    let x: Vec<f64> = trace.iter().take(pixels).map(|r| r.2 * 1e9).collect();
    let y: Vec<f64> = trace.iter().step_by(pixels).map(|r| r.1 * 1e9).collect();
    let map = |title: &str, label: &str, pick: fn(&Point) -> f64| {
        HeatMap::image(
            (
                format!(
                    "{title} at {} = {setpoint} (trace)",
                    if bimodal { "A₁/A₀₁" } else { "A/A₀" }
                ),
                label,
                "",
            ),
            (x.clone(), y.clone()),
            trace
                .chunks(pixels)
                .take(lines)
                .map(|line| line.iter().map(|r| Some(pick(r))).collect())
                .collect(),
        )
    };
    let mut maps = vec![map("topography", "z piezo height (nm)", |p| p.3 * 1e9)];
    if bimodal {
        maps.push(map("first mode's phase", "lock-in phase φ₁ (deg)", |p| p.4));
        maps.push(map(
            "second mode's phase",
            "lock-in phase φ₂ (deg)",
            |p| p.5.unwrap_or(f64::NAN),
        ));
    } else {
        maps.push(map("phase", "lock-in phase φ (deg)", |p| p.4));
    }
    maps
}

/// The z feedback's integral gain as the user gives it: per drive period (K_i) or per
/// second (an instrument panel's I gain).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum IntegralGain {
    /// K_i: A₀ of z_c per unit of A/A₀ error and drive period.
    PerPeriod(f64),
    /// The I gain, s⁻¹ (m of z per m of amplitude error and second).
    PerSecond(f64),
}

impl IntegralGain {
    /// K_i at the drive frequency `drive_hz`.
    fn per_period(self, drive_hz: f64) -> f64 {
        match self {
            IntegralGain::PerPeriod(k) => k,
            IntegralGain::PerSecond(g) => g / drive_hz,
        }
    }
}

impl std::fmt::Display for IntegralGain {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            IntegralGain::PerPeriod(k) => write!(f, "{k}"),
            IntegralGain::PerSecond(g) => write!(f, "{g}/s"),
        }
    }
}

/// `0.002` (K_i, per drive period) or `600/s` (the I gain, per second).
fn integral_gain(s: &str) -> std::result::Result<IntegralGain, String> {
    let t = s.trim();
    match t.strip_suffix("/s").or_else(|| t.strip_suffix("s^-1")) {
        Some(g) => number(g.trim()).map(IntegralGain::PerSecond),
        None => number(t).map(IntegralGain::PerPeriod),
    }
}

/// The gains as tapsim takes them and as an instrument panel in SI shows them.
fn feedback_panel(c: &PiController, drive_hz: f64) -> String {
    let mut text = format!(
        "I gain {} s⁻¹ (K_i = {} a drive period), P gain {} m/m",
        significant(c.integral_gain_per_s(drive_hz)),
        significant(c.integral),
        c.proportional
    );
    if let Some(t) = c.integral_time_s(drive_hz) {
        text += &format!(", integral time {} ms", significant(t * 1e3));
    }
    text
}
