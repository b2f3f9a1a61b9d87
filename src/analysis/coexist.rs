//! Other stable states at one rest separation: where the attractive and the repulsive
//! regimes coexist (García & San Paulo, Phys. Rev. B 60, 4961, 1999), the free
//! oscillation settles on one of them and an approach or a retract may sit on another.
//!
//! Two searches, each state verified on the exact period map (a stable period-1 orbit,
//! [`crate::dynamics::steady`]):
//! - [`Search::HarmonicBalance`] (what `tapsim tap` runs): the stable roots of the
//!   first-harmonic balance ([`crate::dynamics::harmonic_balance`]) as starts. About a
//!   millisecond; it finds the states the averaged motion has, and would miss an orbit
//!   far from a cosine;
//! - [`Search::Thorough`] (`tapsim tap --all-states`): those starts and, besides, every
//!   family of stable period-1 orbits followed from 1.2 A₀ in past z_c
//!   ([`crate::analysis::setpoint::families`]), the state at z_c started from each family that
//!   brackets it. A hundred times slower. (Continuation alone misses families no seed
//!   lands on: a soft lever's repulsive states deep in the sample, which the harmonic
//!   balance finds.)

use crate::analysis::setpoint::{PhaseBranch, SetpointState, families, free_phase_deg};
use crate::dynamics::march::Phase;
use crate::dynamics::observables::TapObservables;
use crate::dynamics::setup::{Numerics, Prepared, TapSetup};
use crate::error::Result;
use serde::Serialize;

/// How the other states are looked for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Search {
    /// From the roots of the first-harmonic balance (fast).
    #[default]
    HarmonicBalance,
    /// From those and from the period-1 families continued in from far (slow).
    Thorough,
}

/// The stable period-1 states at the setup's rest separation other than `reported` (the
/// one the free oscillation settles on there), found by `search` (see the module): each
/// a stable period-1 orbit of the exact dynamics, on another branch or of another
/// amplitude than `reported`.
pub fn coexisting(
    setup: &TapSetup,
    numerics: &Numerics,
    reported: &TapObservables,
    search: Search,
) -> Result<Vec<SetpointState>> {
    let p = Prepared::new(setup, numerics)?;
    let mut starts: Vec<Phase> = p
        .simulation()
        .harmonic_balance()
        .into_iter()
        .map(|e| e.start)
        .collect();
    if search == Search::Thorough {
        starts.extend(continuation_starts(&p, numerics)?);
    }
    let sim = p.simulation();
    let free = free_phase_deg(setup);
    let mut out: Vec<SetpointState> = Vec::new();
    for mut phase in starts {
        let Ok(state) = sim.steady_state(&mut phase, &p.steady) else {
            continue;
        };
        let o = TapObservables::new(&p, &state)?;
        // The same state: amplitude and phase equal to the orbits' resolution (its
        // branch alone would not do: a free orbit's phase is 90° up to round-off).
        let same = |x: &TapObservables| {
            (x.amplitude_ratio - o.amplitude_ratio).abs() < 1e-6
                && (x.phase_deg - o.phase_deg).abs() < 1e-4
        };
        if o.period == Some(1)
            && o.stable == Some(true)
            && !same(reported)
            && !out.iter().any(|s| same(&s.observables))
        {
            out.push(SetpointState {
                branch: PhaseBranch::of(o.phase_deg, free),
                separation_m: setup.separation_m,
                observables: o,
                phase,
            });
        }
    }
    Ok(out)
}

/// On each family followed from 1.2 A₀ in past z_c whose stable orbits bracket z_c, the
/// orbit nearer to it.
fn continuation_starts(p: &Prepared, numerics: &Numerics) -> Result<Vec<Phase>> {
    let a0 = p.setup.cantilever.free_amplitude_m;
    let z = p.setup.separation_m;
    let (far, deep) = (1.2 * a0, z - 0.05 * a0);
    if z >= far {
        return Ok(Vec::new());
    }
    let family = families(p, numerics, (far, deep))?;
    let stable = |r: &crate::analysis::sweep::BranchRecord| r.observables.stable == Some(true);
    Ok(family
        .windows(2)
        .filter(|w| {
            let (a, b) = (&w[0], &w[1]);
            a.segment == b.segment
                && stable(a)
                && stable(b)
                && (a.separation_m - z) * (b.separation_m - z) <= 0.0
        })
        .map(|w| {
            let (a, b) = (&w[0], &w[1]);
            if (a.separation_m - z).abs() < (b.separation_m - z).abs() {
                a.phase.clone()
            } else {
                b.phase.clone()
            }
        })
        .collect())
}
