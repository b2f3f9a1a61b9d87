//! `tapsim thermal --psd FILE`: the calibration of a real cantilever from the thermal
//! spectrum an instrument measured — the SHO fit with its errors, and Sader's method
//! beside it when the lever's plan is given.

use crate::app::report::chart::{Axis, Chart, Corner, Series, Style};
use crate::dynamics::setup::significant;
use crate::error::{Error, Result};
use crate::instrument::sader::{AIR, Fluid, Plan, WATER, reynolds, sader_stiffness};
use crate::instrument::spectrum::{Calibration, Psd, SpectralWindow, calibrate, sho_psd};
use std::path::{Path, PathBuf};

/// The largest spectrum file read.
const MAX_PSD_BYTES: u64 = 256 << 20;

/// A measured spectrum's density unit, by its column's name: the factor to m²/Hz (volts
/// need the InvOLS).
fn density_unit(name: &str) -> Option<(f64, bool)> {
    let n = name.trim().to_ascii_lowercase();
    [
        ("_m2_hz", 1.0, false),
        ("_nm2_hz", 1e-18, false),
        ("_pm2_hz", 1e-24, false),
        ("_v2_hz", 1.0, true),
    ]
    .iter()
    .find(|(suffix, _, _)| n.ends_with(suffix) && n.len() > suffix.len())
    .map(|&(_, scale, volts)| (scale, volts))
}

/// A frequency column's factor to Hz, by its name.
fn frequency_unit(name: &str) -> Option<f64> {
    let n = name.trim().to_ascii_lowercase();
    ["freq", "frequency", "f"].iter().find_map(|p| {
        if n == format!("{p}_hz") {
            Some(1.0)
        } else if n == format!("{p}_khz") {
            Some(1e3)
        } else {
            None
        }
    })
}

/// What to read from a spectrum file.
pub struct PsdReading<'a> {
    /// The density column's name (default: the first whose name carries a density
    /// unit).
    pub column: Option<&'a str>,
    /// The deflection sensitivity for a density in V²/Hz, m/V.
    pub invols_m_per_v: Option<f64>,
    /// The window of the estimate's segments.
    pub window: SpectralWindow,
}

/// Read a one-sided deflection PSD from the CSV at `path`: a frequency column (freq_hz,
/// frequency_hz, f_hz or their _khz) and a density column in m²/Hz, nm²/Hz, pm²/Hz or
/// V²/Hz (named …_m2_hz, …_nm2_hz, …_pm2_hz, …_v2_hz), made m²/Hz; rows in rising
/// frequency, evenly spaced, above 0.
pub fn read_psd(path: &Path, how: &PsdReading) -> Result<Psd> {
    let fail = |reason: String| Error::Parse {
        name: "spectrum file",
        text: path.display().to_string(),
        reason,
    };
    let (headers, rows) = crate::app::config::read_csv(path, MAX_PSD_BYTES, fail)?;
    let (fi, f_scale) = headers
        .iter()
        .enumerate()
        .find_map(|(i, h)| frequency_unit(h).map(|s| (i, s)))
        .ok_or_else(|| {
            fail("no frequency column (freq_hz, frequency_hz, f_hz or their _khz)".into())
        })?;
    let density = match how.column {
        Some(name) => headers
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| fail(format!("no column named {name}")))
            .and_then(|i| {
                density_unit(name).map(|u| (i, u)).ok_or_else(|| {
                    fail(format!(
                        "column {name} names no density unit (…_m2_hz, …_nm2_hz, …_pm2_hz, \
                         …_v2_hz)"
                    ))
                })
            })?,
        None => headers
            .iter()
            .enumerate()
            .find_map(|(i, h)| density_unit(h).map(|u| (i, u)))
            .ok_or_else(|| {
                fail("no density column (a name ending _m2_hz, _nm2_hz, _pm2_hz or _v2_hz)".into())
            })?,
    };
    let (di, (mut d_scale, volts)) = density;
    if volts {
        match how.invols_m_per_v {
            Some(s) if s.is_finite() && s > 0.0 => d_scale = s * s,
            Some(s) => {
                return Err(fail(format!(
                    "the deflection sensitivity must be positive, not {s} m/V"
                )));
            }
            None => {
                return Err(fail(format!(
                    "{} is in V²/Hz: give the deflection sensitivity (--invols, m/V, e.g. \
                     50nm)",
                    &headers[di]
                )));
            }
        }
    } else if how.invols_m_per_v.is_some() {
        return Err(Error::NotApplicable(format!(
            "--invols converts volts, and {} is a deflection already",
            &headers[di]
        )));
    }
    let (mut freq_hz, mut values) = (Vec::new(), Vec::new());
    for (row, record) in rows.iter().enumerate() {
        let cell = |i: usize, what: &str| -> Result<f64> {
            let text = record.get(i).unwrap_or("");
            text.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| fail(format!("row {}: {what} {text:?} is not a number", row + 2)))
        };
        let f = cell(fi, "frequency")? * f_scale;
        let p = cell(di, "density")? * d_scale;
        if p < 0.0 {
            return Err(fail(format!("row {}: a negative density, {p:e}", row + 2)));
        }
        if freq_hz.last().is_some_and(|&last| f <= last) || f <= 0.0 {
            return Err(fail(format!(
                "row {}: frequencies must rise from above 0 ({f} Hz)",
                row + 2
            )));
        }
        freq_hz.push(f);
        values.push(p);
    }
    if freq_hz.len() < 16 {
        return Err(fail(format!(
            "{} rows: a spectrum needs at least 16",
            freq_hz.len()
        )));
    }
    let step = (freq_hz[freq_hz.len() - 1] - freq_hz[0]) / (freq_hz.len() - 1) as f64;
    if freq_hz
        .windows(2)
        .any(|w| ((w[1] - w[0]) / step - 1.0).abs() > 1e-2)
    {
        return Err(fail(
            "the frequencies are not evenly spaced (a Welch or FFT estimate's bins are)".into(),
        ));
    }
    Ok(Psd {
        freq_hz,
        density: values,
        segments: 0,
        window: how.window,
    })
}

/// The fluid a lever was calibrated in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum FluidChoice {
    /// Air at 25 °C (1.18 kg/m³, 1.86e-5 Pa·s).
    #[default]
    Air,
    /// Water at 25 °C (997 kg/m³, 8.9e-4 Pa·s).
    Water,
}

impl FluidChoice {
    /// Its density and viscosity.
    pub fn fluid(self) -> Fluid {
        match self {
            FluidChoice::Air => AIR,
            FluidChoice::Water => WATER,
        }
    }
}

/// The calibration's fitted numbers, as the JSON carries them (`fit_` keys).
#[derive(serde::Serialize)]
pub struct FitFields {
    fit_resonance_hz: f64,
    fit_resonance_sd_hz: f64,
    fit_quality: f64,
    fit_quality_sd: f64,
    fit_stiffness_n_m: f64,
    fit_stiffness_sd_n_m: f64,
    fit_low_frequency_m2_hz: f64,
    fit_background_m2_hz: f64,
    fit_background_sd_m2_hz: f64,
    fit_scatter: f64,
    fit_bins: usize,
}

impl From<&Calibration> for FitFields {
    fn from(c: &Calibration) -> Self {
        FitFields {
            fit_resonance_hz: c.resonance_hz,
            fit_resonance_sd_hz: c.resonance_sd_hz,
            fit_quality: c.quality,
            fit_quality_sd: c.quality_sd,
            fit_stiffness_n_m: c.stiffness_n_m,
            fit_stiffness_sd_n_m: c.stiffness_sd_n_m,
            fit_low_frequency_m2_hz: c.low_frequency_m2_hz,
            fit_background_m2_hz: c.background_m2_hz,
            fit_background_sd_m2_hz: c.background_sd_m2_hz,
            fit_scatter: c.scatter,
            fit_bins: c.bins,
        }
    }
}

/// Sader's spring constant beside the thermal one.
#[derive(serde::Serialize)]
struct Sader {
    length_m: f64,
    width_m: f64,
    fluid_density_kg_m3: f64,
    fluid_viscosity_pa_s: f64,
    reynolds: f64,
    stiffness_n_m: f64,
    stiffness_sd_n_m: f64,
}

/// A measured spectrum's calibration, as --json prints it.
#[derive(serde::Serialize)]
struct Report {
    psd_file: String,
    temperature_k: f64,
    invols_m_per_v: Option<f64>,
    window: SpectralWindow,
    bins_read: usize,
    #[serde(flatten)]
    fit: FitFields,
    sader: Option<Sader>,
}

/// Write the calibrated lever (k, f₀, Q) to `path` as a parameter file for --config.
pub fn save_config(path: &Path, c: &Calibration, source: &str, temperature_k: f64) -> Result<()> {
    let source = source.replace(|c: char| c.is_control(), "?");
    let text = format!(
        "# The cantilever tapsim thermal calibrated from {source} at {temperature_k} K\n\
         stiffness = \"{:.6e} N/m\"\nresonance = \"{:.9e} Hz\"\nquality = {:.6e}\n",
        c.stiffness_n_m, c.resonance_hz, c.quality
    );
    crate::app::report::output::write_bytes(path, text.as_bytes())
}

/// One bin (--csv): the spectrum read, in m²/Hz, and the fit.
#[derive(serde::Serialize)]
struct Bin {
    freq_hz: f64,
    psd_m2_hz: f64,
    fit_m2_hz: f64,
}

/// What `thermal --psd` is told.
pub struct PsdRun<'a> {
    pub path: &'a PathBuf,
    pub reading: PsdReading<'a>,
    pub temperature_k: f64,
    pub plan: Option<Plan>,
    pub fluid: Fluid,
    pub save_config: Option<&'a PathBuf>,
}

/// Calibrate from a measured spectrum.
pub fn run(job: PsdRun, out: &super::SweepOutput) -> Result<()> {
    crate::error::positive("temperature", job.temperature_k)?;
    let psd = read_psd(job.path, &job.reading)?;
    let c = calibrate(&psd, job.temperature_k)?;
    let sader = job
        .plan
        .map(|plan| -> Result<Sader> {
            let k = sader_stiffness(plan, job.fluid, c.resonance_hz, c.quality)?;
            let omega = 2.0 * std::f64::consts::PI * c.resonance_hz;
            Ok(Sader {
                length_m: plan.length_m,
                width_m: plan.width_m,
                fluid_density_kg_m3: job.fluid.density_kg_m3,
                fluid_viscosity_pa_s: job.fluid.viscosity_pa_s,
                reynolds: reynolds(job.fluid, plan.width_m, omega),
                stiffness_n_m: k,
                // k ∝ Q·f₀^(2−δ), Γ_i's slope δ small: Q's error dominates.
                stiffness_sd_n_m: k * c.quality_sd / c.quality,
            })
        })
        .transpose()?;
    let report = Report {
        psd_file: job.path.display().to_string(),
        temperature_k: job.temperature_k,
        invols_m_per_v: job.reading.invols_m_per_v,
        window: job.reading.window,
        bins_read: psd.freq_hz.len(),
        fit: FitFields::from(&c),
        sader,
    };
    let model = |f: f64| {
        sho_psd(
            f,
            c.resonance_hz,
            c.quality,
            c.stiffness_n_m,
            job.temperature_k,
        ) + c.background_m2_hz
    };
    let bins: Vec<Bin> = psd
        .freq_hz
        .iter()
        .zip(&psd.density)
        .map(|(&f, &p)| Bin {
            freq_hz: f,
            psd_m2_hz: p,
            fit_m2_hz: model(f),
        })
        .collect();
    if let Some(path) = job.save_config {
        save_config(path, &c, &report.psd_file, job.temperature_k)?;
    }
    out.write_files(&bins, || charts(&report, &c, &bins))?;
    if out.json {
        outln!("{}", crate::app::report::records::document(&report)?);
        return Ok(());
    }
    outln!(
        "thermal calibration of {} at {} K: {} bins read, {} fitted{}",
        report.psd_file,
        job.temperature_k,
        report.bins_read,
        c.bins,
        job.reading
            .invols_m_per_v
            .map(|s| format!(", InvOLS {:.4} nm/V", s * 1e9))
            .unwrap_or_default()
    );
    outln!(
        "  f0 = {:.4} ± {:.4} kHz",
        c.resonance_hz * 1e-3,
        c.resonance_sd_hz * 1e-3
    );
    outln!("  Q  = {:.2} ± {:.2}", c.quality, c.quality_sd);
    outln!(
        "  k  = {:.4} ± {:.4} N/m  (thermal: k_BT over the resonance's area)",
        c.stiffness_n_m,
        c.stiffness_sd_n_m
    );
    outln!(
        "  background {} ± {} pm²/Hz under a resonance of {} pm²/Hz at f = 0; scatter \
         {:.1} % a bin",
        significant(c.background_m2_hz * 1e24),
        significant(c.background_sd_m2_hz * 1e24),
        significant(c.low_frequency_m2_hz * 1e24),
        100.0 * c.scatter
    );
    if let Some(s) = &report.sader {
        outln!(
            "  k  = {:.4} ± {:.4} N/m  (Sader: {:.0} × {:.0} µm in a fluid of {} kg/m³, \
             Re = {:.3})",
            s.stiffness_n_m,
            s.stiffness_sd_n_m,
            s.length_m * 1e6,
            s.width_m * 1e6,
            s.fluid_density_kg_m3,
            s.reynolds
        );
    }
    outln!(
        "(± one standard error of the fit, its bins taken as a {} window correlates them)",
        match job.reading.window {
            SpectralWindow::Hann => "Hann",
            SpectralWindow::Rectangular => "rectangular",
        }
    );
    Ok(())
}

/// The spectrum read and the fit: log-log over the file's range and around the
/// resonance, in pm²/Hz.
fn charts(report: &Report, c: &Calibration, bins: &[Bin]) -> Vec<Chart> {
    const PM2: f64 = 1e24;
    let f0 = c.resonance_hz;
    let near = |b: &&Bin| (b.freq_hz - f0).abs() <= 10.0 * f0 / c.quality;
    let pick = |keep: &dyn Fn(&&Bin) -> bool, value: fn(&Bin) -> f64| -> Vec<(f64, f64)> {
        bins.iter()
            .filter(|b| keep(b))
            .map(|b| (b.freq_hz * 1e-3, PM2 * value(b)))
            .collect()
    };
    let all = |_: &&Bin| true;
    let fit_name = format!(
        "SHO + background fit: f₀ = {:.3} kHz, Q = {:.1}, k = {:.3} N/m",
        f0 * 1e-3,
        c.quality,
        c.stiffness_n_m
    );
    let flat = |keep: &dyn Fn(&&Bin) -> bool| -> Vec<(f64, f64)> {
        pick(keep, |_| 0.0)
            .into_iter()
            .map(|(f, _)| (f, PM2 * c.background_m2_hz))
            .collect()
    };
    let mut overview = vec![
        Series::new(
            "the file's spectrum",
            pick(&all, |b| b.psd_m2_hz),
            Style::Line,
            2,
        ),
        Series::new(&fit_name, pick(&all, |b| b.fit_m2_hz), Style::Dashed, 1),
    ];
    let mut zoom = vec![
        Series::new(
            "the file's spectrum (every bin)",
            pick(&near, |b| b.psd_m2_hz),
            Style::Line,
            2,
        ),
        Series::new("fit", pick(&near, |b| b.fit_m2_hz), Style::Dashed, 1),
    ];
    if c.background_m2_hz > 2.0 * c.background_sd_m2_hz {
        overview.push(Series::new("fitted background", flat(&all), Style::Line, 0));
        zoom.push(Series::new(
            "fitted background",
            flat(&near),
            Style::Line,
            0,
        ));
    }
    spectrum_charts(
        format!("thermal spectrum read from {}", report.psd_file),
        (overview, zoom),
        None,
    )
}

/// A thermal spectrum's two panels: `overview` over the whole range (log-log), `zoom`
/// around the resonance (its density axis over `zoom_range` where given), in pm²/Hz.
pub(super) fn spectrum_charts(
    title: String,
    (overview, zoom): (Vec<Series>, Vec<Series>),
    zoom_range: Option<(f64, f64)>,
) -> Vec<Chart> {
    let density = Axis::log("deflection PSD S_z (pm²/Hz)", "psd_pm2_hz");
    vec![
        Chart {
            name: "thermal_spectrum".into(),
            title,
            x: Axis::log("frequency f (kHz)", "freq_khz"),
            y: density.clone(),
            legend: Corner::LowerLeft,
            series: overview,
            labels: Vec::new(),
        },
        Chart {
            name: "thermal_resonance".into(),
            title: "around the resonance (10 linewidths either side)".into(),
            x: Axis::linear("frequency f (kHz)", "freq_khz"),
            y: match zoom_range {
                Some((lo, hi)) => density.with_range(lo, hi),
                None => density,
            },
            legend: Corner::UpperRight,
            series: zoom,
            labels: Vec::new(),
        },
    ]
}
