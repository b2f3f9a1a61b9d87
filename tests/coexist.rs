//! Other stable states at one rest separation (issue 44): the default search starts
//! from the roots of the first-harmonic balance; it must find every state the thorough
//! search (which also follows every period-1 family in from far, what `tap` ran before)
//! finds, and its estimates must be those of a linear oscillator where there is no force.

use tapsim::coexist::{Search, coexisting};
use tapsim::config::TapInputs;
use tapsim::dynamics::observables::{Observe, tap};
use tapsim::dynamics::setup::{Numerics, Prepared, TapSetup};
use tapsim::setpoint::SetpointState;

fn resolved(toml: &str) -> (TapSetup, Numerics) {
    TapInputs::from_toml(toml).unwrap().resolve().unwrap()
}

#[test]
fn a_lever_with_no_tip_force_balances_at_its_linear_response() {
    // Closed form: A/A₀·|L(Ω)| = f₀, θ = atan2(2γΩ, 1 − Ω²). A₀ is the free amplitude at
    // the drive frequency, so the root is A/A₀ = 1 at any drive.
    for drive in ["300kHz", "299.5kHz", "301kHz"] {
        let (setup, numerics) = resolved(&format!(
            "law = \"none\"\ndrive-frequency = \"{drive}\"\nseparation = \"10nm\""
        ));
        let p = Prepared::new(&setup, &numerics).unwrap();
        let roots = p.simulation().harmonic_balance();
        assert_eq!(roots.len(), 1, "{drive}: {roots:?}");
        let (w, q) = (setup.cantilever.omega_ratio(), setup.cantilever.quality);
        let theta = (w / q).atan2(1.0 - w * w).to_degrees();
        assert!(
            (roots[0].amplitude - 1.0).abs() < 1e-6,
            "{drive}: {roots:?}"
        );
        assert!(
            (roots[0].phase_deg - theta).abs() < 1e-6,
            "{drive}: {roots:?}"
        );
        // The start is the free steady state itself.
        let free = p.simulation().free_steady_start();
        assert!((roots[0].start.x - free.x).abs() < 1e-6, "{drive}");
        assert!((roots[0].start.v - free.v).abs() < 1e-6, "{drive}");
    }
}

#[test]
fn on_the_defaults_the_estimates_lie_near_both_exact_states() {
    // The two stable roots of the defaults (z_c = 16 nm): the attractive and the
    // repulsive state, against the exact orbits (A/A₀ 0.762208, φ 127.2089° and
    // 0.941472, 75.7390°). A cosine misses the harmonics and the mean deflection's
    // effect on them: within 0.01 in A/A₀ and 3° in phase.
    let (setup, numerics) = resolved("");
    let p = Prepared::new(&setup, &numerics).unwrap();
    let roots = p.simulation().harmonic_balance();
    assert_eq!(roots.len(), 2, "{roots:?}");
    for (root, (ratio, phase)) in roots
        .iter()
        .zip([(0.762208, 127.2089), (0.941472, 75.7390)])
    {
        assert!((root.amplitude - ratio).abs() < 0.01, "{root:?}");
        assert!((root.phase_deg - phase).abs() < 3.0, "{root:?}");
    }
    // And the search started from them reaches the attractive state the guide names.
    let run = tap(&setup, &numerics, Observe::default()).unwrap();
    let others = coexisting(&setup, &numerics, &run.observables, Search::HarmonicBalance).unwrap();
    assert_eq!(others.len(), 1);
    assert!((others[0].observables.amplitude_ratio - 0.7622).abs() < 5e-5);
    assert!((others[0].observables.phase_deg - 127.21).abs() < 5e-3);
}

/// Whether two lists hold the same states (amplitude to 1e-6, phase to 1e-4°).
fn same_states(a: &[SetpointState], b: &[SetpointState]) -> bool {
    let has = |list: &[SetpointState], s: &SetpointState| {
        list.iter().any(|x| {
            (x.observables.amplitude_ratio - s.observables.amplitude_ratio).abs() < 1e-6
                && (x.observables.phase_deg - s.observables.phase_deg).abs() < 1e-4
        })
    };
    a.len() == b.len() && a.iter().all(|s| has(b, s)) && b.iter().all(|s| has(a, s))
}

#[test]
#[ignore = "release: about 30 s (cargo test --release -- --ignored coexist::)"]
fn the_default_search_finds_every_state_the_thorough_one_finds() {
    // Approach curves across the bistable zones of five setups: the hybrid defaults, the
    // issue's soft sample, JKR, hybrid with semi-rigid attraction, and a soft lever on
    // DMT with van der Waals attraction (where continuation alone misses the repulsive
    // states deep in the sample, and the thorough search has them from the harmonic
    // balance).
    let cases: [(&str, (f64, f64, f64)); 5] = [
        ("", (8.0, 24.0, 1.0)),
        (
            "radius = \"10nm\"\nmodulus = \"50MPa\"\nwork-of-adhesion = 0.05",
            (4.0, 22.0, 2.0),
        ),
        ("law = \"jkr\"", (6.0, 22.0, 1.0)),
        ("law = \"hybrid-attractive\"", (13.0, 19.0, 2.0)),
        (
            "law = \"dmt\"\nhamaker = 1e-19\nstiffness = \"2N/m\"\nresonance = \"70kHz\"\n\
             free-amplitude = \"10nm\"",
            (3.0, 11.0, 0.5),
        ),
    ];
    let mut bistable = 0;
    for (toml, (from, to, step)) in cases {
        let mut z = from;
        while z <= to + 1e-9 {
            let (setup, numerics) = resolved(&format!("{toml}\nseparation = \"{z}nm\""));
            let run = tap(&setup, &numerics, Observe::default()).unwrap();
            let o = &run.observables;
            let fast = coexisting(&setup, &numerics, o, Search::HarmonicBalance).unwrap();
            let thorough = coexisting(&setup, &numerics, o, Search::Thorough).unwrap();
            assert!(
                same_states(&fast, &thorough),
                "{toml} at {z} nm: {} vs {}",
                fast.len(),
                thorough.len()
            );
            bistable += usize::from(!fast.is_empty());
            z += step;
        }
    }
    // The zones are there to be found (a search that finds nothing anywhere would pass).
    assert!(bistable >= 20, "{bistable} bistable points");
}
