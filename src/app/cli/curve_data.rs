//! A measured (or simulated) AM curve read from CSV, as `tapsim fit` and
//! `tapsim reconstruct` take it: columns named with their units in the header.

use crate::dynamics::setup::Cantilever;
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::path::Path;

/// The largest data file read.
const MAX_DATA_BYTES: u64 = 64 << 20;

/// How a data file's phase is defined (it is read into tapsim's: the lag).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum PhaseConvention {
    /// The tip's lag behind the drive: 90° free at resonance, above 90° where the tip
    /// feels attraction (tapsim's).
    #[default]
    Lag,
    /// The negative of the lag: −90° free.
    Lead,
    /// 90° − lag: 0 free, negative where the tip feels attraction.
    Shift,
}

impl PhaseConvention {
    /// The lag of a phase read in this convention, degrees.
    pub fn lag_deg(self, read: f64) -> f64 {
        match self {
            PhaseConvention::Lag => read,
            PhaseConvention::Lead => -read,
            PhaseConvention::Shift => 90.0 - read,
        }
    }
}

/// How to read a file's channels.
#[derive(Debug, Clone, Copy, Default)]
pub struct Reading {
    /// The phase columns' convention.
    pub phase: PhaseConvention,
    /// The deflection sensitivity for amplitudes in volts, m/V.
    pub invols_m_per_v: Option<f64>,
    /// Leave out the rows a `grazing` column flags (a simulated curve's points whose
    /// turning point passes a switch of the law closer than the thermal motion: one
    /// draw among coexisting mode locks, which no fit can match point for point).
    pub skip_grazing: bool,
    /// Read a row's amplitude and phase from its `thermal_average_amplitude_ratio` and
    /// `thermal_average_phase_deg` where those are filled (`tapsim approach
    /// --temperature` averages there: what an instrument reads), its deterministic
    /// columns elsewhere.
    pub thermal_averages: bool,
}

/// What a column holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Kind {
    Position,
    Amplitude,
    AmplitudeVolts,
    AmplitudeRatio,
    Phase,
    Amplitude2,
    Amplitude2Ratio,
    Phase2,
    Setpoint,
    Deflection,
    MeanForce,
    Direction,
    Segment,
    Grazing,
    FrequencyShift,
    Excitation,
    ThermalAmplitudeRatio,
    ThermalPhase,
}

/// A column's kind and the factor that makes its values SI, by the header's name.
fn column_kind(name: &str) -> Option<(Kind, f64)> {
    let n = name.trim().to_ascii_lowercase();
    for p in ["z", "z_c", "separation", "position"] {
        if n == format!("{p}_m") {
            return Some((Kind::Position, 1.0));
        }
        if n == format!("{p}_nm") {
            return Some((Kind::Position, 1e-9));
        }
    }
    match n.as_str() {
        // The first mode's (a several-mode approach names it amplitude1_…, phase1_…).
        "amplitude_m" | "amplitude1_m" => Some((Kind::Amplitude, 1.0)),
        "amplitude_nm" | "amplitude1_nm" => Some((Kind::Amplitude, 1e-9)),
        "amplitude_ratio" | "amplitude1_ratio" => Some((Kind::AmplitudeRatio, 1.0)),
        "amplitude_v" | "amplitude1_v" => Some((Kind::AmplitudeVolts, 1.0)),
        "phase_deg" | "phase1_deg" => Some((Kind::Phase, 1.0)),
        "amplitude2_m" => Some((Kind::Amplitude2, 1.0)),
        "amplitude2_nm" => Some((Kind::Amplitude2, 1e-9)),
        "amplitude2_ratio" => Some((Kind::Amplitude2Ratio, 1.0)),
        "phase2_deg" => Some((Kind::Phase2, 1.0)),
        "setpoint" | "setpoint_ratio" => Some((Kind::Setpoint, 1.0)),
        "deflection_m" => Some((Kind::Deflection, 1.0)),
        "deflection_nm" => Some((Kind::Deflection, 1e-9)),
        "mean_force_n" => Some((Kind::MeanForce, 1.0)),
        "direction" => Some((Kind::Direction, 1.0)),
        "segment" => Some((Kind::Segment, 1.0)),
        "grazing" => Some((Kind::Grazing, 1.0)),
        "frequency_shift_hz" | "df_hz" => Some((Kind::FrequencyShift, 1.0)),
        "excitation_ratio" => Some((Kind::Excitation, 1.0)),
        "thermal_average_amplitude_ratio" => Some((Kind::ThermalAmplitudeRatio, 1.0)),
        "thermal_average_phase_deg" => Some((Kind::ThermalPhase, 1.0)),
        _ => None,
    }
}

/// The columns of a data file, in SI.
pub struct Columns {
    /// Positions, m, in the file's order (empty where the file gives setpoints
    /// instead).
    pub position_m: Vec<f64>,
    /// Amplitude setpoints A/A₀, where the file gives them and no position.
    pub setpoint_ratio: Option<Vec<f64>>,
    /// Where each segment (a run of one `segment` label) begins.
    pub segments: Vec<usize>,
    /// Amplitudes, m.
    pub amplitude_m: Option<Vec<f64>>,
    /// Phases, degrees.
    pub phase_deg: Option<Vec<f64>>,
    /// Mean deflections, m (a deflection column, or the mean force over k).
    pub mean_deflection_m: Option<Vec<f64>>,
    /// The second eigenmode's amplitudes, m.
    pub amplitude2_m: Option<Vec<f64>>,
    /// Its phases, degrees.
    pub phase2_deg: Option<Vec<f64>>,
    /// Frequency shifts Δf (FM), Hz.
    pub frequency_shift_hz: Option<Vec<f64>>,
    /// Excitations over their free value, F/F₀ (FM).
    pub excitation_ratio: Option<Vec<f64>>,
    /// How many rows of the direction read were left out as grazing
    /// ([`Reading::skip_grazing`]).
    pub grazing_left_out: usize,
}

/// The farthest position a curve may give, in m: a scanner's range (100 µm).
const MAX_POSITION_M: f64 = 1e-4;
/// The largest phase (in degrees, either sign) a curve may give: two turns.
const MAX_PHASE_DEG: f64 = 720.0;

/// Read the curve of `path`: the rows whose `direction` column (if any) is `direction`;
/// amplitudes given as ratios are made m with the cantilever's A₀ (the second mode's
/// with `second_free_amplitude_m`, A₀₂), in volts with the InvOLS of `reading`; phases
/// made lags from its convention; a mean force is made a deflection with its k.
pub fn read_curve(
    path: &Path,
    cantilever: &Cantilever,
    second_free_amplitude_m: Option<f64>,
    direction: &str,
    reading: &Reading,
) -> Result<Columns> {
    let fail = |reason: String| Error::Parse {
        name: "data file",
        text: path.display().to_string(),
        reason,
    };
    let (headers, rows) = crate::app::config::read_csv(path, MAX_DATA_BYTES, fail)?;
    let mut at: HashMap<Kind, (usize, f64)> = HashMap::new();
    for (i, h) in headers.iter().enumerate() {
        if let Some((kind, scale)) = column_kind(h) {
            if kind == Kind::Position && at.contains_key(&Kind::Position) {
                continue;
            }
            if at.insert(kind, (i, scale)).is_some() {
                let what = format!("{kind:?}").to_lowercase();
                return Err(fail(format!("two columns give the {what}")));
            }
        }
    }
    // Positions, or (without them) the setpoints the phases were read at.
    let position = at.get(&Kind::Position).copied();
    let setpoint = if position.is_none() {
        at.get(&Kind::Setpoint).copied()
    } else {
        None
    };
    let Some(abscissa) = position.or(setpoint) else {
        return Err(fail(
            "no position column (z_nm, z_m, z_c_nm, z_c_m, separation_nm, separation_m, \
             position_nm or position_m) nor a setpoint column (setpoint, A/A₀)"
                .into(),
        ));
    };
    let volts = match (at.get(&Kind::AmplitudeVolts), reading.invols_m_per_v) {
        (None, _) => None,
        (Some(&(i, _)), Some(invols)) if invols.is_finite() && invols > 0.0 => Some((i, invols)),
        (Some(_), Some(invols)) => {
            return Err(fail(format!(
                "the deflection sensitivity must be positive, not {invols} m/V"
            )));
        }
        (Some(_), None) => {
            return Err(fail(
                "amplitude_v is in volts: give the deflection sensitivity (--invols, m/V, \
                 e.g. 50nm)"
                    .into(),
            ));
        }
    };
    if volts.is_some()
        && (at.contains_key(&Kind::Amplitude) || at.contains_key(&Kind::AmplitudeRatio))
    {
        return Err(fail("two columns give the amplitude".into()));
    }
    let amp = at
        .get(&Kind::Amplitude)
        .copied()
        .or_else(|| {
            at.get(&Kind::AmplitudeRatio)
                .map(|&(i, _)| (i, cantilever.free_amplitude_m))
        })
        .or(volts);
    let phase = at.get(&Kind::Phase).copied();
    let shift = at.get(&Kind::FrequencyShift).copied();
    let excitation = at.get(&Kind::Excitation).copied();
    if amp.is_none() && phase.is_none() && shift.is_none() {
        return Err(fail(
            "no amplitude (amplitude_nm, amplitude_m, amplitude_ratio, amplitude_v), phase \
             (phase_deg) or frequency shift (frequency_shift_hz, df_hz) column"
                .into(),
        ));
    }
    let deflection = at.get(&Kind::Deflection).copied().or_else(|| {
        at.get(&Kind::MeanForce)
            .map(|&(i, _)| (i, 1.0 / cantilever.stiffness_n_m))
    });
    if at.contains_key(&Kind::Amplitude2) {
        at.remove(&Kind::Amplitude2Ratio);
    }
    let amp2 = match (
        at.get(&Kind::Amplitude2).copied(),
        at.get(&Kind::Amplitude2Ratio),
    ) {
        (Some(c), _) => Some(c),
        (None, Some(&(i, _))) => match second_free_amplitude_m {
            Some(a02) => Some((i, a02)),
            None => {
                return Err(fail(
                    "amplitude2_ratio is A₂/A₀₂: the second mode's free amplitude is needed \
                     (simulate two modes)"
                        .into(),
                ));
            }
        },
        (None, None) => None,
    };
    let phase2 = at.get(&Kind::Phase2).copied();
    // Where a row holds a thermal average, that (the amplitude's as a ratio of A₀).
    let averaged = |kind: Kind, scale: f64| {
        at.get(&kind)
            .filter(|_| reading.thermal_averages)
            .map(|&(i, _)| (i, scale))
    };
    let averaged_amp = averaged(Kind::ThermalAmplitudeRatio, cantilever.free_amplitude_m);
    let averaged_phase = averaged(Kind::ThermalPhase, 1.0);
    let direction_col = at.get(&Kind::Direction).map(|&(i, _)| i);
    let segment = at.get(&Kind::Segment).map(|&(i, _)| i);
    let grazing = at
        .get(&Kind::Grazing)
        .map(|&(i, _)| i)
        .filter(|_| reading.skip_grazing);
    let mut grazing_left_out = 0;
    let (mut z, mut a, mut p, mut d) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut a2, mut p2) = (Vec::new(), Vec::new());
    let (mut df, mut ex) = (Vec::new(), Vec::new());
    let mut segments = Vec::new();
    let mut label: Option<String> = None;
    for (row, record) in rows.iter().enumerate() {
        if direction_col.is_some_and(|c| record.get(c).is_some_and(|v| v != direction)) {
            continue;
        }
        if grazing.is_some_and(|c| {
            record
                .get(c)
                .is_some_and(|v| v.trim().eq_ignore_ascii_case("true"))
        }) {
            grazing_left_out += 1;
            continue;
        }
        let value = |(col, scale): (usize, f64), what: &str| -> Result<f64> {
            let text = record.get(col).unwrap_or("");
            text.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .map(|v| v * scale)
                .ok_or_else(|| {
                    fail(format!(
                        "row {}: the {what} {text:?} is not a number",
                        row + 2
                    ))
                })
        };
        // Values no cantilever of this free amplitude measures are refused at once (a
        // cell of 1e308 would otherwise reach the fit as an overflow).
        let a0 = cantilever.free_amplitude_m;
        let within = |v: f64, (lo, hi): (f64, f64), what: &str, unit: &str| -> Result<f64> {
            let shown = |v: f64| {
                if v == 0.0 || (1e-3..1e4).contains(&v.abs()) {
                    format!("{v}")
                } else {
                    format!("{v:e}")
                }
            };
            if (lo..=hi).contains(&v) {
                Ok(v)
            } else {
                Err(fail(format!(
                    "row {}: the {what} {}{unit} lies outside what this cantilever (A₀ = \
                     {} m) measures, {} to {}{unit}",
                    row + 2,
                    shown(v),
                    shown(a0),
                    shown(lo),
                    shown(hi)
                )))
            }
        };
        let this = segment.map(|c| record.get(c).unwrap_or("").to_string());
        if z.is_empty() || this != label {
            segments.push(z.len());
            label = this;
        }
        z.push(if setpoint.is_some() {
            within(value(abscissa, "setpoint")?, (0.0, 10.0), "setpoint", "")?
        } else {
            within(
                value(abscissa, "position")?,
                (-MAX_POSITION_M, MAX_POSITION_M),
                "position",
                " m",
            )?
        });
        // A thermal average's column where the row fills it, else `plain`.
        let or_averaged = |plain: (usize, f64), averaged: Option<(usize, f64)>| {
            averaged
                .filter(|&(i, _)| record.get(i).is_some_and(|v| !v.trim().is_empty()))
                .unwrap_or(plain)
        };
        let amplitude = (0.0, 10.0 * a0);
        if let Some(c) = amp {
            a.push(within(
                value(or_averaged(c, averaged_amp), "amplitude")?,
                amplitude,
                "amplitude",
                " m",
            )?);
        }
        let degrees = (-MAX_PHASE_DEG, MAX_PHASE_DEG);
        if let Some(c) = phase {
            let c = or_averaged(c, averaged_phase);
            let lag = reading.phase.lag_deg(value(c, "phase")?);
            p.push(within(lag, degrees, "phase", "°")?);
        }
        if let Some(c) = deflection {
            let deflection = (-10.0 * a0, 10.0 * a0);
            d.push(within(
                value(c, "deflection")?,
                deflection,
                "mean deflection",
                " m",
            )?);
        }
        if let Some(c) = amp2 {
            let second = (0.0, 10.0 * second_free_amplitude_m.unwrap_or(a0));
            a2.push(within(
                value(c, "second mode's amplitude")?,
                second,
                "second mode's amplitude",
                " m",
            )?);
        }
        if let Some(c) = phase2 {
            let lag = reading.phase.lag_deg(value(c, "second mode's phase")?);
            p2.push(within(lag, degrees, "second mode's phase", "°")?);
        }
        // A shift past half the resonance, an excitation a million times its free value:
        // no PLL or amplitude controller reads these.
        if let Some(c) = shift {
            let f0 = cantilever.resonance_hz;
            let v = value(c, "frequency shift")?;
            df.push(within(v, (-0.5 * f0, 0.5 * f0), "frequency shift", " Hz")?);
        }
        if let Some(c) = excitation {
            let v = value(c, "excitation ratio")?;
            ex.push(within(v, (0.0, 1e6), "excitation ratio", "")?);
        }
    }
    if z.is_empty() {
        return Err(fail(match direction_col {
            Some(_) => format!("no rows with direction \"{direction}\""),
            None => "no data rows".into(),
        }));
    }
    let (position_m, setpoint_ratio) = match setpoint {
        Some(_) => (Vec::new(), Some(z)),
        None => (z, None),
    };
    Ok(Columns {
        position_m,
        setpoint_ratio,
        segments,
        amplitude_m: amp.map(|_| a),
        phase_deg: phase.map(|_| p),
        mean_deflection_m: deflection.map(|_| d),
        amplitude2_m: amp2.map(|_| a2),
        phase2_deg: phase2.map(|_| p2),
        frequency_shift_hz: shift.map(|_| df),
        excitation_ratio: excitation.map(|_| ex),
        grazing_left_out,
    })
}
