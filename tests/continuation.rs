//! The period-1 orbit family followed through the rest separation: folds, period
//! doublings, and what a ramp or a settled orbit shows near them.

use nalgebra::Complex;
use tapsim::dynamics::continuation::{
    Branch, BranchPoint, ContinuationOptions, PointKind, follow_period_one,
};
use tapsim::dynamics::numeric::Ignore;
use tapsim::dynamics::setup::{Numerics, Prepared, TapSetup, default_setup};
use tapsim::dynamics::shooting::Multipliers;
use tapsim::law::LawKind;
use tapsim::sweep::{self, Direction};

/// Follow the period-1 family of `setup` from `from_nm` (settled there from the free
/// steady state) to `to_nm`.
fn follow(setup: &TapSetup, from_nm: f64, to_nm: f64) -> Branch {
    let mut s = setup.clone();
    s.separation_m = from_nm * 1e-9;
    let p = Prepared::new(&s, &Numerics::default()).unwrap();
    let sim = p.simulation();
    let mut phase = sim.free_steady_start();
    let state = sim.steady_state(&mut phase, &p.steady).unwrap();
    assert_eq!(state.motion.period(), Some(1));
    let opts = ContinuationOptions {
        q_end: to_nm * 1e-9 / s.cantilever.free_amplitude_m,
        ..ContinuationOptions::default()
    };
    follow_period_one(&sim, &phase, &opts).unwrap()
}

/// The folds of `branch`, which must be two.
fn two_folds(branch: &Branch) -> Vec<&BranchPoint> {
    let folds: Vec<_> = branch
        .points
        .iter()
        .filter(|p| p.kind == PointKind::Fold)
        .collect();
    assert_eq!(folds.len(), 2, "{:?}", branch.stop);
    folds
}

fn nm(setup: &TapSetup, q: f64) -> f64 {
    q * setup.cantilever.free_amplitude_m * 1e9
}

/// DMT with a strong attraction on a 2 GPa sample: attractive and repulsive orbits
/// coexist over a window of rest separations.
fn bistable_dmt() -> TapSetup {
    let mut setup = default_setup();
    setup.law = LawKind::Dmt.into();
    setup.law.hamaker_j = Some(1.5e-19);
    setup.contact.modulus_pa = tapsim::params::composite_modulus(169e9, 0.28, 2e9, 0.4).unwrap();
    setup
}

fn near(m: &Multipliers, target: f64) -> f64 {
    m.iter()
        .map(|l| (l - Complex::new(target, 0.0)).norm())
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn a_bistable_branch_has_two_folds_where_the_ramps_jump() {
    let setup = bistable_dmt();
    let branch = follow(&setup, 22.0, 14.0);
    let folds = two_folds(&branch);
    for f in &folds {
        let off = near(&f.multipliers, 1.0);
        println!(
            "fold at {:.5} nm, multiplier {off:.1e} from +1",
            nm(&setup, f.q)
        );
        assert!(off < 1e-6);
    }
    // Attractive first (φ > 90°), then back through the unstable middle, then repulsive.
    let (approach_fold, retract_fold) = (nm(&setup, folds[0].q), nm(&setup, folds[1].q));
    assert!(approach_fold < retract_fold);
    assert!(folds[0].integrals.phase().to_degrees() > 90.0);
    let middle = branch
        .points
        .iter()
        .skip_while(|p| p.kind != PointKind::Fold)
        .skip(1)
        .take_while(|p| p.kind != PointKind::Fold);
    assert!(middle.clone().count() > 2 && middle.clone().all(|p| !p.stable()));
    assert!(branch.points.last().unwrap().stable());
    assert!(branch.points.last().unwrap().integrals.phase().to_degrees() < 90.0);

    // A ramp in 0.01 nm steps jumps from the attractive to the repulsive orbit within one
    // step of the approach fold, and back within one step of the other on retract (the
    // jump is the largest phase change between neighbours: the repulsive branch itself
    // rises a little above 90° near its fold).
    let step = 0.01;
    let from = (retract_fold / step).ceil() * step + 0.05;
    let points = ((from - (approach_fold - 0.05)) / step).ceil() as usize + 1;
    let to = from - step * (points - 1) as f64;
    let ramp = sweep::ramp(from * 1e-9, to * 1e-9, points, true).unwrap();
    let numerics = sweep::sweep_numerics(Numerics::default(), (false, false));
    let curve = sweep::approach_curve(&setup, &numerics, &ramp, |_, _| {}).unwrap();
    assert!(curve.iter().all(|p| p.observables.regime == "period-1"));
    let jump = |dir: Direction| {
        let pts: Vec<_> = curve.iter().filter(|p| p.direction == dir).collect();
        let (i, _) = pts
            .windows(2)
            .map(|w| (w[0].observables.phase_deg - w[1].observables.phase_deg).abs())
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        let (z0, z1) = (pts[i].separation_m * 1e9, pts[i + 1].separation_m * 1e9);
        (z0.min(z1), z0.max(z1))
    };
    let (a_lo, a_hi) = jump(Direction::Approach);
    let (r_lo, r_hi) = jump(Direction::Retract);
    println!(
        "approach jumps between {a_hi:.3} and {a_lo:.3} nm, retract between {r_lo:.3} and {r_hi:.3}"
    );
    assert!(a_hi - a_lo < step * 1.001 && r_hi - r_lo < step * 1.001);
    assert!(a_lo <= approach_fold && approach_fold <= a_hi);
    assert!(r_lo <= retract_fold && retract_fold <= r_hi);
}

/// A relaxing sample's surface remembers every tap (as many variables as its elements,
/// beyond the period map's derivative): the continuation refuses it, saying why, rather
/// than follow the orbit in (x, x') alone.
#[test]
fn a_relaxing_sample_is_refused_with_the_reason() {
    let mut setup = bistable_dmt();
    setup.law.unrelaxed_modulus_pa = Some(6e9);
    setup.law.relaxation_time_s = Some(1e-7);
    setup.separation_m = 22e-9;
    let p = Prepared::new(&setup, &Numerics::default()).unwrap();
    let sim = p.simulation();
    let opts = ContinuationOptions {
        q_end: 14e-9 / setup.cantilever.free_amplitude_m,
        ..ContinuationOptions::default()
    };
    let err = follow_period_one(&sim, &sim.free_steady_start(), &opts)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("relaxing sample") && err.contains("marching"),
        "{err}"
    );
}

#[test]
fn pure_hertz_has_no_fold() {
    let setup = TapSetup {
        law: LawKind::Hertz.into(),
        ..default_setup()
    };
    let branch = follow(&setup, 22.0, 6.0);
    println!("{} points, {:?}", branch.points.len(), branch.stop);
    assert!(branch.points.len() > 10);
    assert!(
        branch
            .points
            .iter()
            .all(|p| p.kind == PointKind::Regular && p.stable())
    );
    // Monotonic: the family is a single-valued curve in the rest separation.
    assert!(branch.points.windows(2).all(|w| w[1].q < w[0].q));
    assert!(nm(&setup, branch.points.last().unwrap().q) <= 6.0);
}

#[test]
fn a_period_doubling_gives_way_to_a_period_two_orbit() {
    // A soft cantilever (1 N/m, Q = 100) driven below resonance on a Hertz sample.
    let mut setup = default_setup();
    setup.law = LawKind::Hertz.into();
    setup.cantilever.stiffness_n_m = 1.0;
    setup.cantilever.quality = 100.0;
    setup.cantilever.drive_frequency_hz = 0.9 * setup.cantilever.resonance_hz;
    let branch = follow(&setup, 4.0, 0.5);
    let pd = branch
        .points
        .iter()
        .find(|p| p.kind == PointKind::PeriodDoubling)
        .expect("a period doubling");
    let z_pd = nm(&setup, pd.q);
    let off = near(&pd.multipliers, -1.0);
    println!("period doubling at {z_pd:.5} nm, multiplier {off:.1e} from -1");
    assert!(off < 1e-6);
    // Stable above it, unstable just below.
    let before: Vec<_> = branch.points.iter().filter(|p| p.q > pd.q).collect();
    assert!(before.iter().all(|p| p.stable()));
    assert!(branch.points.iter().any(|p| p.q < pd.q && !p.stable()));

    // Past it the motion settles on a period-2 orbit: the state returns after two periods
    // to 1e-9 and not after one.
    let mut s = setup.clone();
    s.separation_m = (z_pd - 0.25) * 1e-9;
    let p = Prepared::new(&s, &Numerics::default()).unwrap();
    let sim = p.simulation();
    let mut phase = sim.free_steady_start();
    let state = sim.steady_state(&mut phase, &p.steady).unwrap();
    assert_eq!(state.motion.period(), Some(2));
    assert_eq!(state.motion.stable(), Some(true));
    let start = phase.clone();
    sim.cycle(&mut phase, &mut Ignore).unwrap();
    let once = (phase.x - start.x).abs().max((phase.v - start.v).abs());
    sim.cycle(&mut phase, &mut Ignore).unwrap();
    let twice = (phase.x - start.x).abs().max((phase.v - start.v).abs());
    println!("after one period {once:.2e}, after two {twice:.2e}");
    assert!(twice < 1e-9 && once > 1e-3);
    // Above it, period 1.
    s.separation_m = (z_pd + 0.25) * 1e-9;
    let p = Prepared::new(&s, &Numerics::default()).unwrap();
    let sim = p.simulation();
    let mut phase = sim.free_steady_start();
    let state = sim.steady_state(&mut phase, &p.steady).unwrap();
    assert_eq!(state.motion.period(), Some(1));
}
