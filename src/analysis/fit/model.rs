//! The forward model of a fit: the parameters it may adjust, the measured curve, and the
//! approach curve a parameter set gives at the measured piezo positions.

use crate::analysis::sweep::{Direction, MAX_SWEEP_POINTS, SweepPoint, approach_curve_while};
use crate::dynamics::modes::ModeSet;
use crate::dynamics::setup::{Numerics, TapSetup};
use crate::error::{Error, Result};
use crate::instrument::average::AverageRequest;
use serde::Serialize;

/// A parameter a fit may adjust (the others stay as the setup gives them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Parameter {
    /// Composite modulus E*, Pa.
    Modulus,
    /// Work of adhesion Δγ, J/m².
    WorkOfAdhesion,
    /// Range ε of the Lennard-Jones law (the equilibrium gap), m.
    Range,
    /// The DMT law's Hamaker constant H, J.
    Hamaker,
    /// A Kelvin–Voigt sample's viscosity η, Pa·s.
    Viscosity,
    /// A standard-linear-solid sample's relaxation time τ_r, s.
    RelaxationTime,
    /// The cantilever's spring constant k, N/m (a nuisance parameter).
    Stiffness,
    /// The cantilever's quality factor Q (a nuisance parameter).
    Quality,
    /// The detector's sensitivity relative to its calibration: amplitudes read are this
    /// times the true ones, the free amplitude A₀ the setup gives included (a nuisance
    /// parameter; 1 where the calibration holds).
    Sensitivity,
    /// An offset added to every phase the instrument reads, degrees (a nuisance
    /// parameter: a phase channel's zero is set by the electronics, not the physics).
    PhaseOffset,
    /// The offset of the piezo position: z_c = z_piezo + offset, m.
    ZOffset,
}

/// What a fit adjusts besides the setup: the piezo offset, the detector's sensitivity
/// and the phase channel's offset.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nuisance {
    /// z_c = position + offset, m.
    pub offset_m: f64,
    /// Amplitudes read over true amplitudes (1: the calibration holds).
    pub sensitivity: f64,
    /// Phases read minus true phases, degrees (0: the phase channel is zeroed as
    /// tapsim's is, 90° free at resonance).
    pub phase_offset_deg: f64,
}

impl Nuisance {
    /// An offset, the calibration holding and the phase channel zeroed.
    pub fn offset(offset_m: f64) -> Self {
        Self {
            offset_m,
            sensitivity: 1.0,
            phase_offset_deg: 0.0,
        }
    }
}

impl Parameter {
    /// Every parameter.
    pub const ALL: [Parameter; 11] = [
        Parameter::Modulus,
        Parameter::WorkOfAdhesion,
        Parameter::Range,
        Parameter::Hamaker,
        Parameter::Viscosity,
        Parameter::RelaxationTime,
        Parameter::Stiffness,
        Parameter::Quality,
        Parameter::Sensitivity,
        Parameter::PhaseOffset,
        Parameter::ZOffset,
    ];

    /// What it is, with its unit, as an axis names it.
    pub fn label(self) -> &'static str {
        match self {
            Parameter::Modulus => "composite modulus E* (Pa)",
            Parameter::WorkOfAdhesion => "work of adhesion Δγ (J/m²)",
            Parameter::Range => "range ε (m)",
            Parameter::Hamaker => "Hamaker constant H (J)",
            Parameter::Viscosity => "sample viscosity η (Pa·s)",
            Parameter::RelaxationTime => "relaxation time τ_r (s)",
            Parameter::Stiffness => "spring constant k (N/m)",
            Parameter::Quality => "quality factor Q",
            Parameter::Sensitivity => "detector sensitivity (read / true amplitude)",
            Parameter::PhaseOffset => "phase offset (deg)",
            Parameter::ZOffset => "piezo offset (m)",
        }
    }

    /// Its key in tables and JSON, unit included.
    pub fn key(self) -> &'static str {
        match self {
            Parameter::Modulus => "modulus_pa",
            Parameter::WorkOfAdhesion => "work_of_adhesion_j_m2",
            Parameter::Range => "range_m",
            Parameter::Hamaker => "hamaker_j",
            Parameter::Viscosity => "viscosity_pa_s",
            Parameter::RelaxationTime => "relaxation_time_s",
            Parameter::Stiffness => "stiffness_n_m",
            Parameter::Quality => "quality",
            Parameter::Sensitivity => "sensitivity",
            Parameter::PhaseOffset => "phase_offset_deg",
            Parameter::ZOffset => "z_offset_m",
        }
    }

    /// Whether it is a positive scale, fitted as its logarithm (a relative step means
    /// the same anywhere), or an offset, fitted as it is (in [`Parameter::unit`]s).
    pub fn is_scale(self) -> bool {
        !matches!(self, Parameter::ZOffset | Parameter::PhaseOffset)
    }

    /// An offset's coordinate unit in SI (the piezo offset in nm, the phase offset in
    /// degrees); 1 for a scale, whose coordinate is its logarithm.
    pub fn unit(self) -> f64 {
        match self {
            Parameter::ZOffset => 1e-9,
            _ => 1.0,
        }
    }

    /// Its value `coordinate` away from `start` in the fitted coordinates (a scale's
    /// logarithm, an offset in its unit).
    pub fn shifted(self, start: f64, coordinate: f64) -> f64 {
        if self.is_scale() {
            start * coordinate.exp()
        } else {
            start + coordinate * self.unit()
        }
    }

    /// How far apart two of its values lie in the fitted coordinates.
    pub fn coordinate_gap(self, a: f64, b: f64) -> f64 {
        if self.is_scale() {
            (a / b).ln().abs()
        } else {
            (a - b).abs() / self.unit()
        }
    }

    /// Whether it belongs to the material or its law (what the global search spreads
    /// its design over), not the instrument's calibration.
    pub fn is_material(self) -> bool {
        matches!(
            self,
            Parameter::Modulus
                | Parameter::WorkOfAdhesion
                | Parameter::Range
                | Parameter::Hamaker
                | Parameter::Viscosity
                | Parameter::RelaxationTime
        )
    }

    /// What data would show it, for a report that finds the data blind to it.
    pub fn seen_in(self) -> &'static str {
        match self {
            Parameter::Modulus => {
                "data where the tip presses into the sample (the repulsive branch)"
            }
            Parameter::WorkOfAdhesion | Parameter::Range => {
                "data where the tip touches: the jump-in position, the attractive branch's \
                 contact, the repulsive branch"
            }
            Parameter::Hamaker => "data where the tip feels the long-range attraction",
            Parameter::Viscosity | Parameter::RelaxationTime => {
                "data where the tip indents the sample (the repulsive branch), best at more \
                 than one indentation rate (another drive frequency or amplitude)"
            }
            Parameter::Stiffness | Parameter::Quality => {
                "data where the tip feels the sample, on both branches"
            }
            Parameter::Sensitivity => {
                "amplitudes in length units (a ratio A/A₀ cancels the sensitivity)"
            }
            Parameter::PhaseOffset => "a phase channel",
            Parameter::ZOffset => "data where the tip feels the sample at all",
        }
    }

    /// Its value in `setup` or `nuisance`; NaN for a law parameter the setup does not
    /// have ([`Parameter::start`] refuses those).
    pub fn value(self, setup: &TapSetup, nuisance: &Nuisance) -> f64 {
        let law = &setup.law;
        match self {
            Parameter::Modulus => setup.contact.modulus_pa,
            Parameter::WorkOfAdhesion => setup.contact.work_of_adhesion_j_m2,
            Parameter::Range => setup.contact.range_m,
            Parameter::Hamaker => law.hamaker_j.unwrap_or_else(|| {
                12.0 * std::f64::consts::PI
                    * setup.contact.range_m.powi(2)
                    * setup.contact.work_of_adhesion_j_m2
            }),
            Parameter::Viscosity => law.viscosity_pa_s.unwrap_or(f64::NAN),
            Parameter::RelaxationTime => law.relaxation_time_s.unwrap_or(f64::NAN),
            Parameter::Stiffness => setup.cantilever.stiffness_n_m,
            Parameter::Quality => setup.cantilever.quality,
            Parameter::Sensitivity => nuisance.sensitivity,
            Parameter::PhaseOffset => nuisance.phase_offset_deg,
            Parameter::ZOffset => nuisance.offset_m,
        }
    }

    /// Its starting value in `setup`, or why it has none: a law parameter the setup's law
    /// does not take or the setup does not set.
    pub fn start(self, setup: &TapSetup, nuisance: &Nuisance) -> Result<f64> {
        let law = &setup.law;
        let missing = |what: &str| {
            Err(Error::NotApplicable(format!(
                "fitting {} needs {what}",
                self.key()
            )))
        };
        match self {
            Parameter::Hamaker if law.kind != crate::physics::law::LawKind::Dmt => {
                missing("the dmt law, the one with a Hamaker constant")
            }
            Parameter::Viscosity if law.viscosity_pa_s.is_none() => {
                missing("a viscous sample to start from: give the setup a viscosity")
            }
            Parameter::RelaxationTime if law.relaxing().is_none() => missing(
                "a relaxing sample to start from: give the setup an unrelaxed modulus and a \
                 relaxation time",
            ),
            _ => Ok(self.value(setup, nuisance)),
        }
    }

    /// Set it to `value` in `setup` or `nuisance`.
    pub fn set(self, setup: &mut TapSetup, nuisance: &mut Nuisance, value: f64) {
        match self {
            Parameter::Modulus => setup.contact.modulus_pa = value,
            Parameter::WorkOfAdhesion => setup.contact.work_of_adhesion_j_m2 = value,
            Parameter::Range => setup.contact.range_m = value,
            Parameter::Hamaker => setup.law.hamaker_j = Some(value),
            Parameter::Viscosity => setup.law.viscosity_pa_s = Some(value),
            Parameter::RelaxationTime => setup.law.relaxation_time_s = Some(value),
            Parameter::Stiffness => setup.cantilever.stiffness_n_m = value,
            Parameter::Quality => setup.cantilever.quality = value,
            Parameter::Sensitivity => nuisance.sensitivity = value,
            Parameter::PhaseOffset => nuisance.phase_offset_deg = value,
            Parameter::ZOffset => nuisance.offset_m = value,
        }
    }
}

/// A measured approach curve — or several, one after another — : piezo positions (any
/// zero; far to near in each) with the amplitude and/or the phase read there, and each
/// channel's standard deviation (the weights of the least squares). Or phases read at
/// amplitude setpoints, as a z feedback holds them (`setpoint_ratio`): no positions
/// then, each point the state at its setpoint on the branch its phase shows.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// Piezo positions, m, decreasing within each approach (empty for setpoint data).
    pub position_m: Vec<f64>,
    /// Amplitude setpoints A/A₀ the phases were read at, in place of positions (None
    /// for an approach curve). The amplitude is then the setpoint, not a measurement.
    pub setpoint_ratio: Option<Vec<f64>>,
    /// Where each approach begins (indices into the positions, the first 0): each is
    /// simulated from the free oscillation at its first position, as `approach` starts
    /// — a second approach begun close to the sample reaches the repulsive branch where
    /// one from far stays on the attractive one.
    pub segments: Vec<usize>,
    /// Amplitudes, m.
    pub amplitude_m: Option<Vec<f64>>,
    /// Phases, degrees (90° free at resonance).
    pub phase_deg: Option<Vec<f64>>,
    /// The amplitude's standard deviation, m.
    pub sigma_amplitude_m: f64,
    /// The phase's, degrees.
    pub sigma_phase_deg: f64,
    /// The second eigenmode's channels, read with the first (bimodal AFM).
    pub second_mode: Option<SecondMode>,
    /// The temperature the data were read at (and the periods a simulated average
    /// spans, and the seed of its noise): each point an instrument reads only as a
    /// thermal average — its state grazes a switch or is not a stable period-1 orbit
    /// ([`crate::instrument::average::reads_as_average`]), typically the onset of
    /// contact — is simulated as that average, its standard errors added to the data's
    /// standard deviations in quadrature. None: every point is its deterministic state
    /// (and a grazing one is left out of the fit unless kept).
    pub thermal: Option<AverageRequest>,
}

/// What a second eigenmode read at each point (bimodal AFM: the first mode's amplitude
/// and phase above, the second's here), with the modes simulated; with neither channel
/// the modes are simulated and only the first mode read.
#[derive(Debug, Clone, PartialEq)]
pub struct SecondMode {
    /// The higher modes (their stiffness, resonance, Q and drive), as given.
    pub modes: ModeSet,
    /// The second mode's amplitudes, m.
    pub amplitude_m: Option<Vec<f64>>,
    /// Its phases, degrees.
    pub phase_deg: Option<Vec<f64>>,
    /// The standard deviation of its amplitude, m.
    pub sigma_amplitude_m: f64,
    /// Of its phase, degrees.
    pub sigma_phase_deg: f64,
}

impl Measured {
    /// Validate: at least three points, as many values in each channel as positions,
    /// one channel at least, all finite, positions strictly decreasing, standard
    /// deviations positive.
    pub fn validated(self) -> Result<Self> {
        if let Some(n) = self.setpoint_ratio.as_ref().map(Vec::len) {
            return self.validated_setpoints(n);
        }
        let n = self.position_m.len();
        if !(3..=MAX_SWEEP_POINTS).contains(&n) {
            return Err(Error::OutOfRange(format!(
                "a fit takes 3 to {MAX_SWEEP_POINTS} measured points, not {n}"
            )));
        }
        if self.amplitude_m.is_none() && self.phase_deg.is_none() {
            return Err(Error::NotApplicable(
                "the data hold neither an amplitude nor a phase to fit".into(),
            ));
        }
        for (name, column) in [
            ("position", Some(&self.position_m)),
            ("amplitude", self.amplitude_m.as_ref()),
            ("phase", self.phase_deg.as_ref()),
        ] {
            let Some(column) = column else { continue };
            check_column(name, column, n, "positions")?;
        }
        if self.segments.first() != Some(&0)
            || self.segments.windows(2).any(|w| w[1] <= w[0])
            || self.segments.last().is_some_and(|&l| l >= n)
        {
            return Err(Error::NotApplicable(format!(
                "the approaches must begin at increasing points from the first, each with a \
                 point of its own: {:?} for {n} points",
                self.segments
            )));
        }
        if let Some(i) = self
            .position_m
            .windows(2)
            .enumerate()
            .position(|(i, w)| w[1] >= w[0] && !self.segments.contains(&(i + 1)))
        {
            return Err(Error::NotApplicable(format!(
                "a fit takes approach curves, positions from far to near: point {} \
                 ({:e} m) does not lie nearer than point {} ({:e} m)",
                i + 2,
                self.position_m[i + 1],
                i + 1,
                self.position_m[i]
            )));
        }
        if self.amplitude_m.is_some() {
            crate::error::positive("amplitude standard deviation", self.sigma_amplitude_m)?;
        }
        if self.phase_deg.is_some() {
            crate::error::positive("phase standard deviation", self.sigma_phase_deg)?;
        }
        if let Some(m) = &self.second_mode {
            m.check(n)?;
            if self.thermal.is_some() {
                return Err(Error::NotApplicable(
                    "thermal averages are simulated for one mode: fit several-mode data \
                     without a temperature"
                        .into(),
                ));
            }
        }
        Ok(self)
    }

    /// Validate setpoint data of `n` points: 3 to the sweep's most, setpoints in (0, 1),
    /// a phase for each and no amplitude (it is the setpoint), the phase's standard
    /// deviation positive.
    fn validated_setpoints(self, n: usize) -> Result<Self> {
        if !(3..=MAX_SWEEP_POINTS).contains(&n) {
            return Err(Error::OutOfRange(format!(
                "a fit takes 3 to {MAX_SWEEP_POINTS} measured points, not {n}"
            )));
        }
        if !self.position_m.is_empty() {
            return Err(Error::NotApplicable(
                "give positions or setpoints, not both".into(),
            ));
        }
        if self.thermal.is_some() {
            return Err(Error::NotApplicable(
                "at a setpoint the feedback holds a stable period-1 state, which is read as \
                 it is: a temperature averages the points of an approach curve that graze \
                 a switch or are not period-1"
                    .into(),
            ));
        }
        if self.second_mode.is_some() {
            return Err(Error::NotApplicable(
                "second-mode channels are fitted along an approach curve (positions), not \
                 at setpoints"
                    .into(),
            ));
        }
        if self.amplitude_m.is_some() {
            return Err(Error::NotApplicable(
                "at a setpoint the amplitude is the setpoint the feedback holds, not a \
                 measurement: fit the phase"
                    .into(),
            ));
        }
        let Some(phase) = &self.phase_deg else {
            return Err(Error::NotApplicable(
                "setpoint data need the phase read at each setpoint".into(),
            ));
        };
        check_column("phase", phase, n, "setpoints")?;
        for &r in self.setpoint_ratio.iter().flatten() {
            crate::analysis::setpoint::check_ratio(r)?;
        }
        crate::error::positive("phase standard deviation", self.sigma_phase_deg)?;
        Ok(self)
    }

    /// How many points the data hold.
    pub fn len(&self) -> usize {
        self.setpoint_ratio
            .as_ref()
            .map_or(self.position_m.len(), Vec::len)
    }

    /// Whether the data hold no point.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The curves of `setup` at the measured positions shifted by the offset, each
    /// approach from the free oscillation at its first position, joined; for setpoint
    /// data the state at each setpoint on the branch the measured phase shows (the
    /// offset plays no part). Amplitudes as the detector reads them: the motion is
    /// simulated with the true free amplitude A₀/s and its amplitudes read times s;
    /// phases with the phase channel's offset added (the first mode's).
    pub fn simulate(
        &self,
        setup: &TapSetup,
        numerics: &Numerics,
        nuisance: &Nuisance,
    ) -> Result<Curve> {
        let mut c = self.simulate_calibrated(setup, numerics, nuisance)?;
        if nuisance.phase_offset_deg != 0.0 {
            for p in c.phase_deg.iter_mut() {
                *p += nuisance.phase_offset_deg;
            }
        }
        Ok(c)
    }

    /// [`Measured::simulate`] with the phase channel zeroed.
    fn simulate_calibrated(
        &self,
        setup: &TapSetup,
        numerics: &Numerics,
        nuisance: &Nuisance,
    ) -> Result<Curve> {
        let s = nuisance.sensitivity;
        if s == 1.0 {
            return self.simulate_true(setup, numerics, nuisance);
        }
        let mut true_setup = setup.clone();
        true_setup.cantilever.free_amplitude_m /= s;
        let mut data = self.clone();
        if let Some(m) = &mut data.second_mode {
            for mode in &mut m.modes.higher {
                mode.free_amplitude_m /= s;
            }
        }
        let mut c = data.simulate_true(&true_setup, numerics, nuisance)?;
        for a in c
            .amplitude_m
            .iter_mut()
            .chain(&mut c.amplitude2_m)
            .chain(&mut c.amplitude_std_err_m)
        {
            *a *= s;
        }
        Ok(c)
    }

    /// [`Measured::simulate`] with the calibration holding and the phase channel zeroed
    /// (its offset only tells setpoint data's branches).
    fn simulate_true(
        &self,
        setup: &TapSetup,
        numerics: &Numerics,
        nuisance: &Nuisance,
    ) -> Result<Curve> {
        let offset_m = nuisance.offset_m;
        if let (Some(ratios), Some(phases)) = (&self.setpoint_ratio, &self.phase_deg) {
            let zeroed: Vec<f64> = phases
                .iter()
                .map(|p| p - nuisance.phase_offset_deg)
                .collect();
            return at_setpoints(setup, numerics, ratios, &zeroed);
        }
        let n = self.position_m.len();
        let mut joined: Option<Curve> = None;
        for (k, &start) in self.segments.iter().enumerate() {
            let end = self.segments.get(k + 1).copied().unwrap_or(n);
            let positions = &self.position_m[start..end];
            let c = match &self.second_mode {
                Some(m) => modal_curve(setup, numerics, &m.modes, positions, offset_m)?,
                None => curve_while(
                    setup,
                    numerics,
                    positions,
                    offset_m,
                    self.segment_thermal(k).as_ref(),
                    |_, _| true,
                )?,
            };
            match joined.as_mut() {
                None => joined = Some(c),
                Some(j) => {
                    j.separation_m.extend(c.separation_m);
                    j.amplitude_m.extend(c.amplitude_m);
                    j.phase_deg.extend(c.phase_deg);
                    j.well_defined.extend(c.well_defined);
                    j.grazing.extend(c.grazing);
                    j.averaged.extend(c.averaged);
                    j.amplitude_std_err_m.extend(c.amplitude_std_err_m);
                    j.phase_std_err_deg.extend(c.phase_std_err_deg);
                    j.amplitude2_m.extend(c.amplitude2_m);
                    j.phase2_deg.extend(c.phase2_deg);
                }
            }
        }
        joined.ok_or_else(|| Error::NotApplicable("no approach to simulate".into()))
    }

    /// The data without the points `left_out` (indices, increasing): an approach that
    /// began at a point left out begins at its next point; one left empty is gone.
    pub fn without(&self, left_out: &[usize]) -> Measured {
        let n = self.len();
        let kept: Vec<usize> = (0..n)
            .filter(|i| left_out.binary_search(i).is_err())
            .collect();
        let pick = |v: &Vec<f64>| kept.iter().map(|&i| v[i]).collect::<Vec<f64>>();
        let pick_opt = |v: &Option<Vec<f64>>| v.as_ref().map(pick);
        let mut segments: Vec<usize> = self
            .segments
            .iter()
            .enumerate()
            .filter_map(|(k, &start)| {
                let end = self.segments.get(k + 1).copied().unwrap_or(n);
                let first = kept.iter().position(|&i| i >= start)?;
                (kept[first] < end).then_some(first)
            })
            .collect();
        segments.dedup();
        Measured {
            position_m: if self.position_m.is_empty() {
                Vec::new()
            } else {
                pick(&self.position_m)
            },
            setpoint_ratio: pick_opt(&self.setpoint_ratio),
            segments,
            amplitude_m: pick_opt(&self.amplitude_m),
            phase_deg: pick_opt(&self.phase_deg),
            sigma_amplitude_m: self.sigma_amplitude_m,
            sigma_phase_deg: self.sigma_phase_deg,
            second_mode: self.second_mode.as_ref().map(|m| SecondMode {
                amplitude_m: pick_opt(&m.amplitude_m),
                phase_deg: pick_opt(&m.phase_deg),
                ..m.clone()
            }),
            thermal: self.thermal,
        }
    }

    /// The names of the channels measured, in the residuals' order.
    pub fn channel_names(&self) -> Vec<&'static str> {
        let second = self.second_mode.as_ref();
        [
            ("amplitude_m", self.amplitude_m.is_some()),
            ("phase_deg", self.phase_deg.is_some()),
            (
                "amplitude2_m",
                second.is_some_and(|m| m.amplitude_m.is_some()),
            ),
            ("phase2_deg", second.is_some_and(|m| m.phase_deg.is_some())),
        ]
        .into_iter()
        .filter_map(|(name, held)| held.then_some(name))
        .collect()
    }

    /// Each channel measured, the simulated values it is compared with in `curve`, its
    /// standard deviation, and the simulated values' standard errors (empty where every
    /// value is deterministic): amplitude, phase, then the second mode's.
    pub fn channel_values<'a>(&'a self, curve: &'a Curve) -> Vec<Channel<'a>> {
        let second = self.second_mode.as_ref();
        [
            (
                self.amplitude_m.as_deref(),
                curve.amplitude_m.as_slice(),
                self.sigma_amplitude_m,
                curve.amplitude_std_err_m.as_slice(),
            ),
            (
                self.phase_deg.as_deref(),
                curve.phase_deg.as_slice(),
                self.sigma_phase_deg,
                curve.phase_std_err_deg.as_slice(),
            ),
            (
                second.and_then(|m| m.amplitude_m.as_deref()),
                curve.amplitude2_m.as_slice(),
                second.map_or(0.0, |m| m.sigma_amplitude_m),
                &[],
            ),
            (
                second.and_then(|m| m.phase_deg.as_deref()),
                curve.phase2_deg.as_slice(),
                second.map_or(0.0, |m| m.sigma_phase_deg),
                &[],
            ),
        ]
        .into_iter()
        .filter_map(|(measured, simulated, sigma, std_err)| {
            measured.map(|measured| Channel {
                measured,
                simulated,
                sigma,
                std_err,
            })
        })
        .collect()
    }

    /// Residuals per point: one per channel measured.
    pub fn channels(&self) -> usize {
        let second = self.second_mode.as_ref().map_or(0, |m| {
            usize::from(m.amplitude_m.is_some()) + usize::from(m.phase_deg.is_some())
        });
        usize::from(self.amplitude_m.is_some()) + usize::from(self.phase_deg.is_some()) + second
    }

    /// The thermal averaging of approach `k` (its segment): each approach's points
    /// draw noise of their own, the first's as a lone curve's.
    pub fn segment_thermal(&self, k: usize) -> Option<AverageRequest> {
        self.thermal.map(|t| match k {
            0 => t,
            _ => t.at(&[k as u64]),
        })
    }

    /// χ² of `curve`: the sum of its weighted residuals' squares.
    pub fn chi_square(&self, curve: &Curve) -> f64 {
        self.residuals(curve).iter().map(|r| r * r).sum()
    }

    /// The weighted residuals (model − measured)/σ of `curve`: the amplitudes, the
    /// phases, then the second mode's.
    pub fn residuals(&self, curve: &Curve) -> Vec<f64> {
        self.channel_values(curve)
            .into_iter()
            .flat_map(|c| (0..c.measured.len()).map(move |i| c.residual(i)))
            .collect()
    }
}

/// One channel of measured data beside its simulation ([`Measured::channel_values`]).
pub struct Channel<'a> {
    /// The values measured.
    pub measured: &'a [f64],
    /// The values simulated.
    pub simulated: &'a [f64],
    /// The standard deviation of a measured value.
    pub sigma: f64,
    /// The standard error of each simulated value (a thermal average's; empty where
    /// every value is deterministic).
    pub std_err: &'a [f64],
}

impl Channel<'_> {
    /// The weighted residual of point `i`: (simulated − measured) over the measured
    /// value's standard deviation and the simulated one's standard error in quadrature.
    pub fn residual(&self, i: usize) -> f64 {
        let e = self.std_err.get(i).copied().unwrap_or(0.0);
        weighted_residual(self.simulated[i], self.measured[i], self.sigma, e)
    }
}

/// A simulated approach curve at the measured positions (or the states at the measured
/// setpoints).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Curve {
    /// Rest separations z_c = position + offset, m (at a setpoint: where its state is).
    pub separation_m: Vec<f64>,
    /// Amplitudes, m.
    pub amplitude_m: Vec<f64>,
    /// Phases, degrees.
    pub phase_deg: Vec<f64>,
    /// Whether each point is a stable period-1 orbit that does not graze a switch (else
    /// its values are averages over motion that perturbations can change).
    pub well_defined: Vec<bool>,
    /// Whether each point grazes a switch of the law: a turning point closer to it than
    /// the thermal motion, so which of the coexisting states an instrument reads there
    /// is set by perturbations (empty where not known: the several-mode curve).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub grazing: Vec<bool>,
    /// Whether each point is a thermal average ([`Measured::thermal`]; empty without a
    /// temperature).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub averaged: Vec<bool>,
    /// The standard errors of the amplitudes, m: those of the thermal averages, 0 at
    /// the deterministic points (empty without a temperature).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub amplitude_std_err_m: Vec<f64>,
    /// The standard errors of the phases, degrees, likewise.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub phase_std_err_deg: Vec<f64>,
    /// The second mode's amplitudes, m (empty without one).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub amplitude2_m: Vec<f64>,
    /// Its phases, degrees (empty without one).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub phase2_deg: Vec<f64>,
}

impl Curve {
    /// The points that are not [`Curve::well_defined`]: mode locks and grazing touches.
    pub fn unsettled(&self) -> usize {
        self.well_defined.iter().filter(|w| !**w).count()
    }

    /// Whether more than a quarter of the points are unsettled: their values step as the
    /// parameters move, so a fit differences such a curve over wide steps and gives no
    /// linearised intervals at it.
    pub fn mostly_unsettled(&self) -> bool {
        4 * self.unsettled() > self.well_defined.len()
    }
}

/// The approach curve of `setup` at the piezo positions `position_m` shifted by
/// `offset_m` (each point's steady state started from the last one's, as an approach
/// goes).
pub fn curve(
    setup: &TapSetup,
    numerics: &Numerics,
    position_m: &[f64],
    offset_m: f64,
) -> Result<Curve> {
    curve_while(setup, numerics, position_m, offset_m, None, |_, _| true)
}

/// What an instrument reads at one point of a simulated curve: the state's amplitude
/// and phase, or the thermal average's with its standard errors (zero for a
/// deterministic state).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reading {
    /// Amplitude, m.
    pub amplitude_m: f64,
    /// Phase, degrees.
    pub phase_deg: f64,
    /// The amplitude's standard error, m.
    pub amplitude_std_err_m: f64,
    /// The phase's standard error, degrees.
    pub phase_std_err_deg: f64,
}

/// The weighted residual (simulated − measured)/√(σ² + se²) of a measured value of
/// standard deviation `sigma` against a simulated one of standard error `std_err`
/// (independent errors add in quadrature).
pub fn weighted_residual(simulated: f64, measured: f64, sigma: f64, std_err: f64) -> f64 {
    (simulated - measured) / sigma.hypot(std_err)
}

/// [`curve`] read at a temperature where `thermal` is given: each point an instrument
/// reads only as a thermal average ([`crate::instrument::average::reads_as_average`])
/// is that average ([`crate::analysis::sweep::approach_curve_at`]: the approach itself
/// goes on from the deterministic state), with its standard errors, and neither grazes
/// nor is ill-defined any more — an average is what the instrument reads there; the
/// `keep` of [`curve_while`] that stops after the first point it refuses (given its
/// index and what is read there): the points up to and including it.
pub fn curve_while(
    setup: &TapSetup,
    numerics: &Numerics,
    position_m: &[f64],
    offset_m: f64,
    thermal: Option<&AverageRequest>,
    mut keep: impl FnMut(usize, &Reading) -> bool,
) -> Result<Curve> {
    let ramp: Vec<(f64, Direction)> = position_m
        .iter()
        .map(|z| (z + offset_m, Direction::Approach))
        .collect();
    let a0 = setup.cantilever.free_amplitude_m;
    // What the instrument reads at a point: the average where there is one.
    let read = |p: &SweepPoint| match p.thermal_average {
        Some(t) => Reading {
            amplitude_m: t.amplitude_ratio * a0,
            phase_deg: t.phase_deg,
            amplitude_std_err_m: t.amplitude_ratio_std_err * a0,
            phase_std_err_deg: t.phase_std_err_deg,
        },
        None => Reading {
            amplitude_m: p.observables.amplitude_m,
            phase_deg: p.observables.phase_deg,
            amplitude_std_err_m: 0.0,
            phase_std_err_deg: 0.0,
        },
    };
    let points = approach_curve_while(setup, numerics, &ramp, thermal, |i, p| keep(i, &read(p)))?;
    let averaged: Vec<bool> = points.iter().map(|p| p.thermal_average.is_some()).collect();
    let readings: Vec<Reading> = points.iter().map(read).collect();
    let pick = |f: fn(&Reading) -> f64| readings.iter().map(f).collect::<Vec<f64>>();
    // Standard errors only where a temperature is given.
    let std_err = |f: fn(&Reading) -> f64| match thermal {
        Some(_) => pick(f),
        None => Vec::new(),
    };
    Ok(Curve {
        separation_m: ramp.iter().take(points.len()).map(|r| r.0).collect(),
        amplitude_m: pick(|r| r.amplitude_m),
        phase_deg: pick(|r| r.phase_deg),
        well_defined: points
            .iter()
            .zip(&averaged)
            .map(|(p, &avg)| avg || (p.observables.regime == "period-1" && !p.observables.grazing))
            .collect(),
        grazing: points
            .iter()
            .zip(&averaged)
            .map(|(p, &avg)| p.observables.grazing && !avg)
            .collect(),
        amplitude_std_err_m: std_err(|r| r.amplitude_std_err_m),
        phase_std_err_deg: std_err(|r| r.phase_std_err_deg),
        averaged: if thermal.is_some() {
            averaged
        } else {
            Vec::new()
        },
        amplitude2_m: Vec::new(),
        phase2_deg: Vec::new(),
    })
}

/// The states of `setup` at the amplitude setpoints `ratios`, each on the branch its
/// measured phase in `phases` shows (above the free phase attractive, below
/// repulsive); where that branch has no stable period-1 state at the setpoint, an
/// error saying so.
pub fn at_setpoints(
    setup: &TapSetup,
    numerics: &Numerics,
    ratios: &[f64],
    phases: &[f64],
) -> Result<Curve> {
    let free = crate::analysis::setpoint::free_phase_deg(setup);
    let mut c = Curve {
        separation_m: Vec::with_capacity(ratios.len()),
        amplitude_m: Vec::with_capacity(ratios.len()),
        phase_deg: Vec::with_capacity(ratios.len()),
        well_defined: Vec::with_capacity(ratios.len()),
        grazing: Vec::with_capacity(ratios.len()),
        averaged: Vec::new(),
        amplitude_std_err_m: Vec::new(),
        phase_std_err_deg: Vec::new(),
        amplitude2_m: Vec::new(),
        phase2_deg: Vec::new(),
    };
    for (&r, &phi) in ratios.iter().zip(phases) {
        crate::interrupt::check()?;
        let branch = crate::analysis::setpoint::PhaseBranch::of(phi, free);
        let states =
            crate::analysis::setpoint::states_at_setpoint(setup, numerics, r, Some(branch))?;
        let s = states.first().ok_or_else(|| {
            Error::NotApplicable(format!("no {branch} state at the setpoint {r}"))
        })?;
        c.separation_m.push(s.separation_m);
        c.amplitude_m.push(s.observables.amplitude_m);
        c.phase_deg.push(s.observables.phase_deg);
        c.well_defined.push(!s.observables.grazing);
        c.grazing.push(s.observables.grazing);
    }
    Ok(c)
}

/// Refuse a measured channel `name` that does not hold one finite value for each of the
/// `n` points (`per`: what the points are, positions or setpoints).
fn check_column(name: &str, column: &[f64], n: usize, per: &str) -> Result<()> {
    if column.len() != n {
        return Err(Error::NotApplicable(format!(
            "{} {name} values for {n} {per}",
            column.len()
        )));
    }
    if let Some((i, v)) = column.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(Error::NotApplicable(format!(
            "{name} of point {} is {v}: every value must be finite",
            i + 1
        )));
    }
    Ok(())
}

impl SecondMode {
    /// Validate for `n` points: each channel given of `n` finite values, its standard
    /// deviation positive (none given: the modes are simulated, only the first read).
    fn check(&self, n: usize) -> Result<()> {
        if self.modes.higher.is_empty() {
            return Err(Error::NotApplicable(
                "second-mode channels need a second mode to simulate".into(),
            ));
        }
        for (name, column, sigma) in [
            (
                "second mode's amplitude",
                self.amplitude_m.as_ref(),
                self.sigma_amplitude_m,
            ),
            (
                "second mode's phase",
                self.phase_deg.as_ref(),
                self.sigma_phase_deg,
            ),
        ] {
            let Some(column) = column else { continue };
            check_column(name, column, n, "positions")?;
            if !(sigma.is_finite() && sigma > 0.0) {
                return Err(Error::NotApplicable(format!(
                    "the {name}'s standard deviation must be positive, not {sigma}"
                )));
            }
        }
        Ok(())
    }
}

/// The several-mode approach curve of `setup` with the higher modes `modes` at the
/// positions `position_m` shifted by `offset_m`, each point's orbit continued from the
/// last ([`crate::analysis::bimodal::approach`]); the first two modes' amplitudes and phases. A
/// point where the modes settle on no orbit of their common period is an error naming
/// it (such points are left out of the data).
pub fn modal_curve(
    setup: &TapSetup,
    numerics: &Numerics,
    modes: &ModeSet,
    position_m: &[f64],
    offset_m: f64,
) -> Result<Curve> {
    let (p, modal) = crate::dynamics::modes::prepare(setup, modes, numerics)?;
    let separations: Vec<f64> = position_m.iter().map(|z| z + offset_m).collect();
    let points = crate::analysis::bimodal::approach(&p, &modal, numerics, &separations, || {})?;
    let mut c = Curve {
        separation_m: separations,
        amplitude_m: Vec::with_capacity(points.len()),
        phase_deg: Vec::with_capacity(points.len()),
        well_defined: Vec::with_capacity(points.len()),
        grazing: Vec::new(),
        averaged: Vec::new(),
        amplitude_std_err_m: Vec::new(),
        phase_std_err_deg: Vec::new(),
        amplitude2_m: Vec::with_capacity(points.len()),
        phase2_deg: Vec::with_capacity(points.len()),
    };
    for point in points {
        let Some(state) = point.state else {
            return Err(Error::NotApplicable(format!(
                "at z_c = {:.4} nm the modes settle on no orbit of their common period ({}): \
                 leave such points out of the data",
                point.separation_m * 1e9,
                point.note.unwrap_or_default()
            )));
        };
        let (first, second) = (&state.modes[0], &state.modes[1]);
        c.amplitude_m.push(first.amplitude_m);
        c.phase_deg.push(first.phase_deg);
        c.amplitude2_m.push(second.amplitude_m);
        c.phase2_deg.push(second.phase_deg);
        c.well_defined.push(state.stable);
    }
    Ok(c)
}
