//! What an instrument reads where the deterministic answer is not a stable period-1
//! orbit away from every switch (a state that grazes a switch, a long lock, irregular
//! motion): the state averaged over the thermal motion, from independent records under
//! the thermal force ([`super::thermal`]), each with its own stream, so that the
//! standard errors are the spread of independent records. Near grazing the touch
//! pattern is set by perturbations far below the thermal motion; the average over that
//! motion does not depend on the integrator's tolerance, as the deterministic lock
//! does.

use super::thermal::{
    MAX_THERMAL_PERIODS, STEPS_PER_PERIOD, ThermalForce, check_temperature, intensity_hat,
};
use crate::dynamics::march::{CycleIntegrals, Phase, Simulation};
use crate::dynamics::observables::TapObservables;
use crate::dynamics::setup::{Numerics, Prepared, TapSetup};
use crate::error::{Error, Result};
use crate::physics::law::AnyLaw;

/// What an instrument reads of a state under the thermal force, averaged over thermal
/// records: the means and their standard errors, from the spread of independent
/// records (streams of the seed). The spread of batches of one record would not do:
/// near grazing the touches follow a long lock pattern whose part in each batch swings
/// the batch means, which cancels over the record — such errors came out up to 2.7
/// times the spread of independent records.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ThermalAverage {
    /// Temperature, K.
    pub temperature_k: f64,
    /// Drive periods averaged (after settling), over all records.
    pub periods: usize,
    /// Independent records (each its own settling and stream).
    pub records: usize,
    /// Mean energy dissipated in the contact per period, J.
    pub e_ts_j: f64,
    /// Its standard error, J.
    pub e_ts_std_err_j: f64,
    /// The phase of the averaged fundamental (what a slow lock-in reads), degrees.
    pub phase_deg: f64,
    /// Its standard error, degrees.
    pub phase_std_err_deg: f64,
    /// The amplitude of the averaged fundamental over A₀.
    pub amplitude_ratio: f64,
    /// Its standard error.
    pub amplitude_ratio_std_err: f64,
    /// The fraction of periods in which the tip touches (jumps into contact).
    pub touch_fraction: f64,
    /// Its standard error.
    pub touch_fraction_std_err: f64,
    /// The seed whose streams its records drew: in a sweep, derived from the request's
    /// seed and the point's place ([`AverageRequest::at`]), so that no two points share
    /// their noise and their errors are independent.
    pub seed: u64,
}

/// Independent records a thermal average is made of.
pub const AVERAGE_RECORDS: usize = 8;

/// A thermal average asked for: the temperature, the drive periods averaged over all
/// records (after settling) and the seed whose streams 0, 1, … the records draw.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct AverageRequest {
    /// Temperature, K.
    pub temperature_k: f64,
    /// Drive periods averaged, over all records.
    pub periods: usize,
    /// Seed of the records' streams.
    pub seed: u64,
}

impl AverageRequest {
    /// The request for a state of `setup` alone: at the place its work of adhesion,
    /// modulus and rest separation give it ([`AverageRequest::at`]), so that `tap` at a
    /// map cell's parameters draws the cell's noise.
    pub fn for_state(&self, setup: &TapSetup) -> Self {
        let c = &setup.contact;
        self.at(&[
            c.work_of_adhesion_j_m2.to_bits(),
            c.modulus_pa.to_bits(),
            setup.separation_m.to_bits(),
        ])
    }

    /// The request for the point at `place` of a sweep (its index along a curve, its
    /// parameters in a map): the same temperature and length, a seed of its own derived
    /// from this one and the place (SplitMix64, Steele, Lea & Flood, OOPSLA 2014, over
    /// the words), so that the points' records draw unrelated streams and the errors of
    /// neighbouring points do not move together. The same place gives the same seed on
    /// any machine, shard or thread count.
    pub fn at(&self, place: &[u64]) -> Self {
        let mix = |z: u64| {
            let z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            let z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        };
        let seed = place.iter().fold(mix(self.seed), |h, &w| {
            mix(h.wrapping_add(0x9e37_79b9_7f4a_7c15).wrapping_add(mix(w)))
        });
        Self { seed, ..*self }
    }

    /// Refuse a temperature that is negative or not finite, a length with fewer than
    /// 100 periods a record or more than [`MAX_THERMAL_PERIODS`] in all, and an average
    /// that would march more than [`MAX_AVERAGE_MARCHED`] drive periods with its
    /// settling ([`settling_periods`]) on a cantilever of quality `quality` (the work
    /// grows with Q: refused at once, not after an hour).
    pub fn check(&self, quality: f64) -> Result<()> {
        check_temperature(self.temperature_k)?;
        let per_record = self.periods / AVERAGE_RECORDS;
        if !(100..=MAX_THERMAL_PERIODS / AVERAGE_RECORDS).contains(&per_record) {
            return Err(Error::OutOfRange(format!(
                "a thermal average spans {} to {MAX_THERMAL_PERIODS} drive periods, not {}",
                100 * AVERAGE_RECORDS,
                self.periods
            )));
        }
        let settle = settling_periods(quality);
        let marched = (settle as f64 + per_record as f64) * AVERAGE_RECORDS as f64;
        if marched > MAX_AVERAGE_MARCHED as f64 {
            return Err(Error::OutOfRange(format!(
                "a thermal average at Q = {quality} marches {marched:.3e} drive periods \
                 ({AVERAGE_RECORDS} records, each {settle} periods of settling, ten decay \
                 times, before its {per_record}): more than the {MAX_AVERAGE_MARCHED:.0e} \
                 tapsim marches for one; average fewer periods, or a lower Q"
            )));
        }
        Ok(())
    }
}

/// The most drive periods one thermal average marches, settling included: about two
/// minutes on two cores at 40 µs a noisy period.
pub const MAX_AVERAGE_MARCHED: usize = 6_000_000;

/// Periods a record settles for before it is averaged: ten decay times of the free
/// amplitude, 10 Q/π.
pub fn settling_periods(quality: f64) -> usize {
    (10.0 * quality / std::f64::consts::PI).ceil() as usize
}

/// Whether an instrument reads state `o` only as a thermal average: it grazes a switch,
/// or it is not a stable period-1 orbit (where it is one, away from every switch, the
/// linear noise theory about it speaks: [`super::noise`]).
pub fn reads_as_average(o: &TapObservables) -> bool {
    o.grazing || o.period != Some(1) || o.stable != Some(true)
}

/// The state `setup` settles on from the free oscillation, under the thermal force
/// ([`thermal_average_from`] from the free steady motion at the setup's separation).
pub fn thermal_average(
    setup: &TapSetup,
    numerics: &Numerics,
    request: &AverageRequest,
) -> Result<ThermalAverage> {
    let p = Prepared::new(setup, numerics)?;
    let sim = p.simulation();
    thermal_average_from(&p, &sim, &sim.free_steady_start(), request)
}

/// The state `sim` (of `p`, at any separation) settles on from `start` under the
/// thermal force at the request's temperature ([`STEPS_PER_PERIOD`] steps a period):
/// [`AVERAGE_RECORDS`] independent records (streams 0, 1, … of the seed, marched in
/// parallel: the same result on any thread count), each 10 Q/π periods of settling (ten
/// decay times of the free amplitude) and then its share of the periods; each record's
/// E_ts, fundamental (A, φ from its summed Fourier projections) and touch fraction;
/// their means and standard errors. At 0 K every record is the deterministic march's.
pub fn thermal_average_from(
    p: &Prepared,
    sim: &Simulation<'_, AnyLaw>,
    start: &Phase,
    request: &AverageRequest,
) -> Result<ThermalAverage> {
    use rayon::prelude::*;
    let c = p.setup.cantilever;
    request.check(c.quality)?;
    let per_record = request.periods / AVERAGE_RECORDS;
    let a0 = c.free_amplitude_m;
    let intensity = intensity_hat(request.temperature_k, c.stiffness_n_m, c.quality, a0);
    let settle = settling_periods(c.quality);
    let energy_j = c.stiffness_n_m * a0 * a0;
    let records: Vec<[f64; 4]> = (0..AVERAGE_RECORDS)
        .into_par_iter()
        .map(|stream| -> Result<[f64; 4]> {
            let mut force =
                ThermalForce::new(intensity, STEPS_PER_PERIOD, request.seed, stream as u64)?;
            let mut phase = start.clone();
            let ignore = &mut crate::dynamics::numeric::Ignore;
            force.march(sim, &mut phase, settle, ignore)?;
            let (mut sum, mut touched) = (None::<CycleIntegrals>, 0usize);
            for _ in 0..per_record {
                let (one, _) = force.march(sim, &mut phase, 1, ignore)?;
                let one = one.expect("one period marched");
                touched += usize::from(one.jumps_in > 0);
                sum = Some(sum.map_or(one, |s| s.then(&one)));
            }
            let sum = sum.expect("a record has periods");
            Ok([
                sum.e_ts_per_period() * energy_j,
                sum.phase().to_degrees(),
                sum.amplitude(),
                touched as f64 / per_record as f64,
            ])
        })
        .collect::<Result<_>>()?;
    let n = records.len() as f64;
    let stat = |i: usize| {
        let (m, var) = crate::numeric::mean_and_variance(records.iter().map(|b| b[i]));
        (m, (var / n).sqrt())
    };
    let ((e, e_se), (ph, ph_se), (a, a_se), (t, t_se)) = (stat(0), stat(1), stat(2), stat(3));
    Ok(ThermalAverage {
        temperature_k: request.temperature_k,
        periods: per_record * AVERAGE_RECORDS,
        records: AVERAGE_RECORDS,
        e_ts_j: e,
        e_ts_std_err_j: e_se,
        phase_deg: ph,
        phase_std_err_deg: ph_se,
        amplitude_ratio: a,
        amplitude_ratio_std_err: a_se,
        touch_fraction: t,
        touch_fraction_std_err: t_se,
        seed: request.seed,
    })
}
