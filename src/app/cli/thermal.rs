//! `tapsim thermal`: the thermal spectrum of the free cantilever and its calibration.

use super::thermal_psd::{FitFields, FluidChoice, PsdReading, PsdRun};
use crate::app::config::{frequency, length, number, stiffness, temperature, time, viscosity};
use crate::app::report::chart::{Chart, Series, Style};
use crate::dynamics::grazing::{BOLTZMANN_J_K, ROOM_TEMPERATURE_K};
use crate::dynamics::setup::default_setup;
use crate::error::{Error, Result};
use crate::instrument::sader::{Fluid, Plan};
use crate::instrument::spectrum::{Calibration, SpectralWindow, sho_psd};
use crate::instrument::thermal::{STEPS_PER_PERIOD, ThermalSpectrum, thermal_spectrum};
use clap::Args;

/// The thermal noise of a free cantilever and the calibration it gives.
///
/// An AFM cantilever far from the sample and not driven still moves: the thermal force
/// of its damping (fluctuation–dissipation: one-sided density S_F = 4k_BT·k/(ω₀Q))
/// shakes it by √(k_BT/k) rms (10.18 pm at 40 N/m and 300 K). Its deflection spectrum is
/// the simple harmonic oscillator's, S_z(f) = (2k_BT/(πk f₀Q))/((1 − f²/f₀²)² +
/// f²/(f₀²Q²)), and fitting that to a measured spectrum is how a cantilever is
/// calibrated (Hutter & Bechhoefer, RSI 64, 1868, 1993): f₀ and Q from its shape, k from
/// its area, k = k_BT/⟨z²⟩.
///
/// This records that motion (the thermal force held over 64 steps a period, drawn from
/// a seeded stream: the same record on any machine), estimates its spectrum (Welch:
/// half-overlapping Hann segments of 16 bins a linewidth) and fits the oscillator's to
/// it, printing the fitted f₀, Q and k beside the cantilever's own. The record is
/// 8 000 Q resonance periods unless --duration says otherwise (10.7 s of motion at
/// 300 kHz and Q = 400); the fit's scatter from seed to seed falls as 1/√duration.
///
/// The fit is the oscillator's spectrum over a white background (the detector's noise
/// in a measured spectrum), weighted as a spectral estimate's bins scatter (maximum
/// likelihood), each number with its standard error.
///
/// A REAL CANTILEVER: --psd FILE reads the thermal spectrum an instrument measured
/// (CSV: a frequency column freq_hz, frequency_hz or f_hz (or _khz) and a one-sided
/// deflection PSD column named …_m2_hz, …_nm2_hz, …_pm2_hz, or …_v2_hz with --invols)
/// and calibrates k, f₀ and Q from it with their errors; with --lever-length and
/// --lever-width, Sader's method (Sader, Chon & Mulvaney, RSI 70, 3967, 1999: k from
/// the plan, f₀, Q and the fluid's hydrodynamic function) beside it. --save-config
/// FILE.toml writes the calibrated stiffness, resonance and quality for any other
/// command's --config.
///
///   tapsim thermal --csv psd.csv                 # a simulated spectrum, written
///   tapsim thermal --psd psd.csv                 # ... calibrated as a measured one
///   tapsim thermal --psd asylum.csv --invols 52nm --lever-length 125um \
///       --lever-width 35um --save-config lever.toml
///   tapsim tap --config lever.toml               # the calibrated lever tapping
///
/// JSON keys (--json): temperature_k, stiffness_n_m, resonance_hz, quality, periods,
/// duration_s, steps_per_period, segments, rms_m, equipartition_rms_m,
/// fit_resonance_hz, fit_resonance_sd_hz, fit_quality, fit_quality_sd,
/// fit_stiffness_n_m, fit_stiffness_sd_n_m, fit_low_frequency_m2_hz,
/// fit_background_m2_hz, fit_background_sd_m2_hz, fit_scatter, fit_bins; with --psd:
/// psd_file, temperature_k, invols_m_per_v, window, bins_read, the fit_ keys, and
/// sader (length_m, width_m, fluid_density_kg_m3, fluid_viscosity_pa_s, reynolds,
/// stiffness_n_m, stiffness_sd_n_m) or null.
/// --csv FILE: the spectrum (freq_hz, welch_m2_hz, sho_m2_hz, fit_m2_hz; with --psd:
/// freq_hz, psd_m2_hz, fit_m2_hz); --plot FILE.png|svg: the spectrum over 0.05–2 f₀
/// (log-log; with --psd, the file's range) and around the resonance.
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct ThermalArgs {
    /// Temperature [K; default 300K].
    #[arg(long, allow_hyphen_values = true, value_parser = temperature)]
    temperature: Option<f64>,
    /// Cantilever spring constant k [N/m; default 40].
    #[arg(long, allow_hyphen_values = true, value_parser = stiffness)]
    stiffness: Option<f64>,
    /// Resonance frequency f₀ [Hz; default 300kHz].
    #[arg(long, allow_hyphen_values = true, value_parser = frequency)]
    resonance: Option<f64>,
    /// Quality factor Q, 10 to 1e4 [default 400].
    #[arg(long, allow_hyphen_values = true, value_parser = number)]
    quality: Option<f64>,
    /// Length of the record [s; default 8 000 Q resonance periods].
    #[arg(long, allow_hyphen_values = true, value_parser = time)]
    duration: Option<f64>,
    /// Steps a period over which the thermal force is held (a multiple of 8; the
    /// spectrum falls short of white by about (π/steps)²/3 at f₀).
    #[arg(long, default_value_t = STEPS_PER_PERIOD)]
    steps: usize,
    /// Seed of the thermal force's random stream.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// A measured thermal spectrum to calibrate from (CSV; see above) instead of a
    /// simulated record.
    #[arg(long, help_heading = "A measured spectrum", conflicts_with_all = ["stiffness", "resonance", "quality", "duration", "steps", "seed"])]
    psd: Option<std::path::PathBuf>,
    /// The density column to fit [default: the first named with a density unit].
    #[arg(long, requires = "psd", help_heading = "A measured spectrum")]
    column: Option<String>,
    /// Deflection sensitivity (InvOLS) for a density in V²/Hz [m/V, e.g. 50nm].
    #[arg(long, requires = "psd", value_parser = length, help_heading = "A measured spectrum")]
    invols: Option<f64>,
    /// The window of the spectrum's segments, which correlates neighbouring bins and so
    /// sets the errors [hann: most instruments'; rectangular: independent bins].
    #[arg(long, value_enum, requires = "psd", default_value_t = SpectralWindow::Hann, help_heading = "A measured spectrum")]
    window: SpectralWindow,
    /// The cantilever's length, for Sader's method [m, e.g. 125um].
    #[arg(long, requires_all = ["psd", "lever_width"], value_parser = length, help_heading = "A measured spectrum")]
    lever_length: Option<f64>,
    /// The cantilever's width, for Sader's method [m, e.g. 35um].
    #[arg(long, requires = "lever_length", value_parser = length, help_heading = "A measured spectrum")]
    lever_width: Option<f64>,
    /// The fluid the spectrum was measured in, for Sader's method.
    #[arg(long, value_enum, requires = "lever_length", default_value_t = FluidChoice::Air, help_heading = "A measured spectrum")]
    fluid: FluidChoice,
    /// The fluid's density instead of --fluid's [kg/m³].
    #[arg(long, requires = "lever_length", value_parser = number, help_heading = "A measured spectrum")]
    fluid_density: Option<f64>,
    /// The fluid's viscosity instead of --fluid's [Pa·s, e.g. 1.8e-5Pa*s].
    #[arg(long, requires = "lever_length", value_parser = viscosity, help_heading = "A measured spectrum")]
    fluid_viscosity: Option<f64>,
    /// Write the calibrated stiffness, resonance and quality to FILE.toml, for any
    /// command's --config.
    #[arg(long)]
    save_config: Option<std::path::PathBuf>,
    #[command(flatten)]
    pub(super) out: super::SweepOutput,
}

/// The fit beside the truth, as --json prints it.
#[derive(serde::Serialize)]
struct Report {
    temperature_k: f64,
    stiffness_n_m: f64,
    resonance_hz: f64,
    quality: f64,
    periods: usize,
    duration_s: f64,
    steps_per_period: usize,
    segments: usize,
    rms_m: f64,
    equipartition_rms_m: f64,
    #[serde(flatten)]
    fit: FitFields,
}

/// One bin of the spectrum (--csv).
#[derive(serde::Serialize)]
struct Bin {
    freq_hz: f64,
    welch_m2_hz: f64,
    sho_m2_hz: f64,
    fit_m2_hz: f64,
}

impl ThermalArgs {
    /// Refuse, before any work, output files that cannot be written (the parameter
    /// file --save-config among them).
    pub(super) fn check(&self) -> Result<()> {
        self.out.check()?;
        super::check_targets([self.save_config.as_deref()])
    }
}

/// Run the subcommand.
pub fn run(args: ThermalArgs) -> Result<()> {
    let t = args.temperature.unwrap_or(ROOM_TEMPERATURE_K);
    if let Some(path) = &args.psd {
        let fluid = args.fluid.fluid();
        return super::thermal_psd::run(
            PsdRun {
                path,
                reading: PsdReading {
                    column: args.column.as_deref(),
                    invols_m_per_v: args.invols,
                    window: args.window,
                },
                temperature_k: t,
                plan: args.lever_length.zip(args.lever_width).map(|(l, b)| Plan {
                    length_m: l,
                    width_m: b,
                }),
                fluid: Fluid {
                    density_kg_m3: args.fluid_density.unwrap_or(fluid.density_kg_m3),
                    viscosity_pa_s: args.fluid_viscosity.unwrap_or(fluid.viscosity_pa_s),
                },
                save_config: args.save_config.as_ref(),
            },
            &args.out,
        );
    }
    let c = default_setup().cantilever;
    let k = args.stiffness.unwrap_or(c.stiffness_n_m);
    let f0 = args.resonance.unwrap_or(c.resonance_hz);
    let q = args.quality.unwrap_or(c.quality);
    crate::error::positive("resonance frequency", f0)?;
    crate::error::positive("quality factor", q)?;
    let periods_f = match args.duration {
        Some(d) => {
            crate::error::positive("record duration", d)?;
            d * f0
        }
        None => 8000.0 * q,
    };
    if !periods_f.is_finite() || periods_f > 1e12 {
        return Err(Error::OutOfRange(format!(
            "a record of {periods_f:e} resonance periods is beyond reach"
        )));
    }
    let periods = periods_f.round() as usize;
    let bar = args.out.progress("thermal", periods);
    let spectrum = thermal_spectrum((k, f0, q), t, (periods, args.steps), args.seed, |done| {
        bar.set_position(done as u64)
    })?;
    bar.finish_and_clear();
    let fit = spectrum.calibration;
    let report = Report {
        temperature_k: t,
        stiffness_n_m: k,
        resonance_hz: f0,
        quality: q,
        periods,
        duration_s: periods as f64 / f0,
        steps_per_period: args.steps,
        segments: spectrum.psd.segments,
        rms_m: spectrum.rms_m,
        equipartition_rms_m: (BOLTZMANN_J_K * t / k).sqrt(),
        fit: FitFields::from(&fit),
    };
    let bins: Vec<Bin> = spectrum
        .psd
        .freq_hz
        .iter()
        .zip(&spectrum.psd.density)
        .map(|(&f, &p)| Bin {
            freq_hz: f,
            welch_m2_hz: p,
            sho_m2_hz: sho_psd(f, f0, q, k, t),
            fit_m2_hz: sho_psd(f, fit.resonance_hz, fit.quality, fit.stiffness_n_m, t),
        })
        .collect();
    if let Some(path) = &args.save_config {
        super::thermal_psd::save_config(path, &fit, "a simulated thermal record", t)?;
    }
    args.out
        .write_files(&bins, || charts(&report, &fit, &bins, &spectrum))?;
    if args.out.json {
        outln!("{}", crate::app::report::records::document(&report)?);
        return Ok(());
    }
    outln!(
        "thermal spectrum of a free cantilever at {t} K: {periods} resonance periods \
         ({:.3} s), {} force steps a period, {} Welch segments",
        report.duration_s,
        args.steps,
        report.segments
    );
    outln!(
        "{:>10} {:>14} {:>10} {:>14} {:>9}",
        "",
        "fitted",
        "± s.e.",
        "cantilever",
        "off"
    );
    let row = |name: &str, (fitted, error): (f64, f64), true_value: f64, digits: usize| {
        format!(
            "{name:>10} {fitted:>14.digits$} {error:>10.digits$} {true_value:>14.digits$} \
             {:>+8.3}%",
            100.0 * (fitted / true_value - 1.0)
        )
    };
    let khz = (fit.resonance_hz * 1e-3, fit.resonance_sd_hz * 1e-3);
    outln!("{}", row("f0 (kHz)", khz, f0 * 1e-3, 4));
    outln!("{}", row("Q", (fit.quality, fit.quality_sd), q, 2));
    outln!(
        "{}",
        row("k (N/m)", (fit.stiffness_n_m, fit.stiffness_sd_n_m), k, 4)
    );
    outln!(
        "{:>10} {:>14.3} {:>10} {:>14.3} {:>+8.3}%",
        "rms (pm)",
        spectrum.rms_m * 1e12,
        "",
        report.equipartition_rms_m * 1e12,
        100.0 * (spectrum.rms_m / report.equipartition_rms_m - 1.0)
    );
    outln!(
        "(fitted: the oscillator's spectrum over a white background fitted to the \
         record's over {} bins, ± one standard error; rms: the record's, beside \
         equipartition's √(k_BT/k))",
        fit.bins
    );
    Ok(())
}

/// The spectrum over 0.05–2 f₀ (log-log, averaged over logarithmic bins of 1 %; above
/// 2f₀ the record's sampling at 8f₀ folds the tail back) and the resonance within 10
/// linewidths (every bin), in pm²/Hz.
fn charts(
    report: &Report,
    fit: &Calibration,
    bins: &[Bin],
    spectrum: &ThermalSpectrum,
) -> Vec<Chart> {
    let f0 = report.resonance_hz;
    let title = format!(
        "free cantilever, k = {} N/m, f₀ = {} kHz, Q = {}, T = {} K ({} segments)",
        report.stiffness_n_m,
        f0 * 1e-3,
        report.quality,
        report.temperature_k,
        spectrum.psd.segments
    );
    // Logarithmic bins of 1 % for the overview.
    let wide = |b: &Bin| b.freq_hz >= 0.05 * f0 && b.freq_hz <= 2.0 * f0;
    let mut coarse: Vec<(f64, f64)> = Vec::new();
    let (mut lo, mut sum_f, mut sum_p, mut n) = (0.05 * f0, 0.0, 0.0, 0);
    const PM2: f64 = 1e24;
    for b in bins.iter().filter(|b| wide(b)) {
        if b.freq_hz > lo * 1.01 && n > 0 {
            coarse.push((sum_f / n as f64 * 1e-3, PM2 * sum_p / n as f64));
            (lo, sum_f, sum_p, n) = (b.freq_hz, 0.0, 0.0, 0);
        }
        sum_f += b.freq_hz;
        sum_p += b.welch_m2_hz;
        n += 1;
    }
    let model = |pick: fn(&Bin) -> f64, keep: &dyn Fn(&Bin) -> bool| -> Vec<(f64, f64)> {
        bins.iter()
            .filter(|b| keep(b))
            .map(|b| (b.freq_hz * 1e-3, PM2 * pick(b)))
            .collect()
    };
    let half = 10.0 * f0 / report.quality;
    let near = move |b: &Bin| (b.freq_hz - f0).abs() <= half;
    let fit_name = format!(
        "SHO fit: f₀ = {:.3} kHz, Q = {:.1}, k = {:.3} N/m",
        fit.resonance_hz * 1e-3,
        fit.quality,
        fit.stiffness_n_m
    );
    let series = |welch: Vec<(f64, f64)>,
                  keep: &dyn Fn(&Bin) -> bool,
                  (welch_name, own, fitted): (&str, &str, &str)| {
        vec![
            Series::new(welch_name, welch, Style::Line, 2),
            Series::new(own, model(|b| b.sho_m2_hz, keep), Style::Line, 0),
            Series::new(fitted, model(|b| b.fit_m2_hz, keep), Style::Dashed, 1),
        ]
    };
    let overview = series(
        coarse,
        &wide,
        (
            "simulated record, Welch (1 % bins)",
            "S_z(f), the cantilever's own (Hutter & Bechhoefer)",
            &fit_name,
        ),
    );
    let resonance = series(
        model(|b| b.welch_m2_hz, &near),
        &near,
        ("record (every bin)", "cantilever's own", "SHO fit"),
    );
    // Room above the peak for the legend.
    let (lo, hi) = resonance
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .fold((f64::INFINITY, 0.0_f64), |(lo, hi), y| {
            (lo.min(y), hi.max(y))
        });
    super::thermal_psd::spectrum_charts(title, (overview, resonance), Some((0.7 * lo, 8.0 * hi)))
}
