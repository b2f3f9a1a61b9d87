//! The whole tapping run: the steady state from the free start, the coexisting
//! attractors where it grazes a switch, its observables ([`super::observed`]), the
//! trajectory and the higher harmonics.

use super::attractors::{Attractor, DEFAULT_STARTS, MAX_STARTS, Start, attractors};
use super::budget;
use super::gradient::GradientObserver;
use super::harmonics::{Harmonic, HarmonicsObserver};
use super::observed::Recorder;
pub use super::observed::{
    MAX_RECORD_CYCLES, MAX_TRAJECTORY_SAMPLES, TapObservables, TrajectorySample,
};
use super::setup::{Numerics, Prepared, TapSetup};
use crate::error::{Error, Result};
use crate::physics::law::ForceLaw;
use serde::Serialize;

/// What a tapping run observes beyond the steady state's observables.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Observe {
    /// Drive periods of trajectory to record after the steady state (at most
    /// [`MAX_RECORD_CYCLES`]; 0: none).
    pub record_cycles: usize,
    /// Whether to compute the higher harmonics of a periodic orbit (one more orbit
    /// integrated; nothing for irregular motion).
    pub harmonics: bool,
    /// The starts whose attractors the run lists ([`super::attractors`]).
    pub starts: Starts,
}

/// Which starts a run lists the attractors of ([`super::attractors`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Starts {
    /// None: the free oscillation's steady state alone (sweeps, maps and batches, which
    /// carry the grazing flag per point instead).
    #[default]
    None,
    /// [`DEFAULT_STARTS`] where the state grazes a switch, none otherwise (what
    /// `tapsim tap` does).
    WhereGrazing,
    /// The first n of [`Start::list`] (1 to [`MAX_STARTS`]).
    First(usize),
}

impl Observe {
    /// Record `cycles` drive periods of trajectory, nothing else.
    pub fn recording(cycles: usize) -> Self {
        Self {
            record_cycles: cycles,
            ..Self::default()
        }
    }
}

/// A complete tapping run: observables and, if asked for, the trajectory of the last
/// recorded cycles and the higher harmonics.
#[derive(Debug, Clone, Serialize)]
pub struct TapRun {
    /// Observables of the reported cycle.
    #[serde(flatten)]
    pub observables: TapObservables,
    /// Harmonics 2…10 of the deflection and the force over the periodic orbit, if asked
    /// for and the motion is periodic (null otherwise).
    pub harmonics: Option<Vec<Harmonic>>,
    /// The tip–sample force gradient averaged over the periodic orbit, ⟨∂F_ts/∂z⟩ in
    /// N/m (repulsive force positive; a branch switch's step counted as the gradient it
    /// is to a small oscillation on top: [`super::gradient`]): what a second eigenmode
    /// with a small amplitude feels, cot φ₂ = −(Q₂/k₂)⟨∂F_ts/∂z⟩. Null where the harmonics
    /// are (motion that is not periodic, or not asked for).
    pub mean_force_gradient_n_m: Option<f64>,
    /// What the grazing margin is compared with ([`TapObservables::grazing`]): the
    /// cantilever's rms thermal deflection at 300 K, √(k_B T/k), in m …
    pub thermal_rms_m: f64,
    /// … and how finely the integration resolves the state, in m: A₀ times the larger
    /// of the orbit's closure tolerance and rtol (periodic), or the marching rtol
    /// (irregular).
    pub integration_error_m: f64,
    /// The attractors reached from several starts ([`super::attractors`]), the free
    /// oscillation's first; null where none were looked for (a state that does not
    /// graze a switch, without `starts`).
    pub attractors: Option<Vec<Attractor>>,
    /// Whether the deterministic answer is defined: the state does not graze a switch,
    /// and every start reached the same attractor or those reached coexist without
    /// grazing (a bistability: which one is reached depends on the history, each is well
    /// defined). False for a state that grazes a switch (its margin below the thermal
    /// motion: which touches a period makes is then set by perturbations, even where
    /// every start of one integrator reaches one lock; what an instrument reads is the
    /// thermal average, `--temperature`) and where attractors that graze coexist; null
    /// where only one start was tried for a state that does not graze.
    pub well_defined: Option<bool>,
    /// Trajectory samples (empty unless recorded).
    #[serde(skip)]
    pub trajectory: Vec<TrajectorySample>,
    /// The law's jump-in and jump-out separations in m (for marking plots).
    #[serde(skip)]
    pub switch_separations_m: (f64, f64),
}

/// Simulate `setup` from the free steady state (the cantilever oscillating freely, far
/// from the sample, when the rest separation is set) to the steady state it settles on,
/// then observe what `observe` asks for: the n periods of a period-n orbit once more for
/// its harmonics, and `observe.record_cycles` more cycles recording the trajectory
/// (neither counted in the observables, which are the steady state's).
///
/// ```
/// use tapsim::{LawKind, Numerics, Observe, TapSetup, default_setup, tap};
///
/// // The built-in silicon cantilever on a polymer, with the paper's hybrid law.
/// let setup = TapSetup { law: LawKind::Hybrid.into(), ..default_setup() };
/// let o = tap(&setup, &Numerics::default(), Observe::default())?.observables;
/// assert_eq!(o.regime, "period-1");
/// assert!(o.energy_balance_rel < 1e-6);
/// // Each period dissipates the hybrid loop: Ŵ_hybrid(μ)·μεRΔγ.
/// assert!((o.e_ts_j / o.loop_area_j - 1.0).abs() < 1e-6);
/// # Ok::<(), tapsim::Error>(())
/// ```
pub fn tap(setup: &TapSetup, numerics: &Numerics, observe: Observe) -> Result<TapRun> {
    let record_cycles = observe.record_cycles;
    if record_cycles > MAX_RECORD_CYCLES {
        return Err(Error::InvalidParameter {
            name: "record cycles",
            value: record_cycles as f64,
            reason: "must be at most 1000 (the trajectory is kept in memory)",
        });
    }
    if let Starts::First(n) = observe.starts {
        if !(1..=MAX_STARTS).contains(&n) {
            return Err(Error::InvalidParameter {
                name: "starts",
                value: n as f64,
                reason: "must be 1 to 64",
            });
        }
    }
    let p = Prepared::new(setup, numerics)?;
    let sim = p.simulation();
    let mut phase = sim.free_steady_start();
    let state = sim.steady_state(&mut phase, &p.steady)?;
    let observables = TapObservables::new(&p, &state)?;
    let starts = match observe.starts {
        Starts::None => 0,
        Starts::WhereGrazing if observables.grazing => DEFAULT_STARTS,
        Starts::WhereGrazing => 0,
        Starts::First(n) => n,
    };
    let attractors = (starts > 0)
        .then(|| attractors(setup, numerics, &Start::list(starts)))
        .transpose()?;
    let (harmonics, mean_force_gradient_n_m) = match state.motion.period() {
        // (Not on a relaxing sample: its force between the integrator's steps lives in
        // a surface only the open step knows.)
        Some(n) if observe.harmonics && !sim.has_surface() => {
            // Both watch the same n periods of the orbit.
            let mut observer = (
                HarmonicsObserver::new(&p.law, p.cpl, p.osc),
                GradientObserver::new(&p.law, p.cpl, p.osc),
            );
            for _ in 0..n {
                budget::budgeted(p.steady.max_steps, || sim.cycle(&mut phase, &mut observer))?;
            }
            let cant = &setup.cantilever;
            let a0 = cant.free_amplitude_m;
            (
                Some(Harmonic::list(
                    &observer.0.finish(),
                    a0,
                    cant.stiffness_n_m * a0,
                )),
                Some(observer.1.finish() * cant.stiffness_n_m + 0.0),
            )
        }
        _ => (None, None),
    };
    let mut recorder = Recorder::new(&p.law, p.cpl, p.osc);
    for done in 0..record_cycles {
        budget::budgeted(p.steady.max_steps, || sim.cycle(&mut phase, &mut recorder))?;
        if recorder.overflowed {
            let fit = if done == 0 {
                "not even one cycle fits".to_string()
            } else {
                format!("record at most {done} cycles")
            };
            return Err(Error::NotApplicable(format!(
                "the trajectory of {record_cycles} cycles needs more than \
                 {MAX_TRAJECTORY_SAMPLES} samples, the most tapsim records: {fit}"
            )));
        }
    }
    let scale = setup.contact.separation_scale_m();
    let a0 = setup.cantilever.free_amplitude_m;
    let grazing = observables.grazing;
    Ok(TapRun {
        thermal_rms_m: p.steady.grazing_threshold * a0,
        integration_error_m: sim.resolution(&p.steady, &state.motion) * a0,
        observables,
        // A state that grazes a switch closer than the thermal motion is not defined by
        // the deterministic equation, whatever the starts of one integrator reach (issue
        // 45: independent integrators reach other locks from the same start).
        well_defined: if grazing {
            Some(false)
        } else {
            attractors
                .as_ref()
                .filter(|_| starts > 1)
                .map(|list| list.len() == 1 || list.iter().all(|a| !a.grazing))
        },
        attractors,
        harmonics,
        mean_force_gradient_n_m,
        trajectory: recorder.to_si(&p),
        switch_separations_m: (
            p.law.jump_in_alpha_hat() * scale,
            p.law.jump_out_alpha_hat() * scale,
        ),
    })
}
