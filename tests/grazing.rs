//! Grazing near the onset of contact: the margin, the flag, the attractors that coexist,
//! and an independent brute-force marcher to hold them against.

use crate::common;

use std::cell::RefCell;
use tapsim::dynamics::model::Drive;
use tapsim::dynamics::observables::{Observe, Starts, TapRun, tap};
use tapsim::dynamics::setup::{Numerics, Prepared, TapSetup, default_setup};
use tapsim::law::{AnyLaw, Branch, ForceLaw, LawKind};

fn hybrid_at(separation_nm: f64) -> TapSetup {
    TapSetup {
        separation_m: separation_nm * 1e-9,
        ..default_setup()
    }
}

fn run(setup: &TapSetup, starts: Starts) -> TapRun {
    let observe = Observe {
        starts,
        ..Observe::default()
    };
    tap(setup, &Numerics::default(), observe).unwrap()
}

#[test]
fn the_defaults_do_not_graze_and_their_margin_is_the_depth_past_the_jump_in() {
    let setup = default_setup();
    let r = run(&setup, Starts::WhereGrazing);
    let o = &r.observables;
    assert_eq!(o.regime, "period-1");
    assert_eq!(o.stable, Some(true));
    assert!(!o.grazing && r.attractors.is_none() && r.well_defined.is_none());
    // The turning point nearest a switch is the deepest point of the contact, past the
    // jump-in separation α_A where the contact branch was entered: the margin is that
    // depth, from the law's α_A and the orbit's smallest separation.
    let p = Prepared::new(&setup, &Numerics::default()).unwrap();
    let alpha_a_m = p.law.jump_in_alpha_hat() * setup.contact.separation_scale_m();
    let depth = alpha_a_m - o.min_separation_m;
    let margin = o.grazing_margin_m.unwrap();
    assert!((margin - depth).abs() < 1e-6 * depth, "{margin} vs {depth}");
    assert!(margin > 100.0 * r.thermal_rms_m);
    // The thermal rms deflection of the 40 N/m cantilever at 300 K: √(k_B T/k).
    assert!((r.thermal_rms_m - (1.380649e-23 * 300.0 / 40.0f64).sqrt()).abs() < 1e-20);
}

#[test]
fn a_touch_that_barely_passes_the_jump_in_is_flagged_and_its_attractors_listed() {
    // 19.5 nm: the period-1 orbit Newton's method finds turns 0.3 pm past α_A, thirty
    // times less than the thermal motion; the marched motion locks onto a long period
    // that grazes too, and every documented start is listed.
    let r = run(&hybrid_at(19.5), Starts::WhereGrazing);
    let o = &r.observables;
    println!(
        "{} ({} touches/period), margin {:?}",
        o.regime, o.jumps_in, o.grazing_margin_m
    );
    assert!(o.grazing);
    assert!(o.grazing_margin_m.unwrap() < r.thermal_rms_m);
    assert_eq!(o.stable, None, "its stability rests on the grazing contact");
    let list = r.attractors.as_ref().unwrap();
    assert_eq!(list.iter().map(|a| a.count).sum::<usize>(), 6);
    assert_eq!(list[0].regime, o.regime);
    assert_eq!(list[0].phase_deg, o.phase_deg, "the free start's first");
    let loop_j = o.loop_area_j;
    for a in list {
        assert!(a.grazing);
        // Each touch of the hybrid loses its whole loop: on a periodic attractor E_ts is
        // exactly the touches per period times the loop.
        if a.period.is_some() {
            assert!((a.e_ts_j / (a.touch_fraction * loop_j) - 1.0).abs() < 1e-6);
        }
    }
}

#[test]
fn at_20_5_nm_coexisting_locks_make_the_answer_ill_defined() {
    let r = run(&hybrid_at(20.5), Starts::WhereGrazing);
    let list = r.attractors.as_ref().unwrap();
    for a in list {
        println!("{} {} {:?}", a.regime, a.touch_fraction, a.starts);
    }
    assert_eq!(r.well_defined, Some(false));
    assert!(list.len() >= 2);
    // Distinct attractors, each named by its least period, none of them irregular.
    assert!(list.iter().all(|a| a.period.is_some_and(|n| n > 8)));
}

#[test]
fn a_state_that_grazes_is_not_well_defined_even_where_every_start_agrees() {
    // Issue 45: at 19.5, 20 and 20.2 nm the six starts all reach one long lock (periods
    // 27, 41, 23), yet the margins (0.04–0.09 pm) lie far below the thermal motion, and
    // an independent integrator reaches other locks from the same start at other
    // tolerances (19.5 nm: 9.87 eV a period at rtol 1e-10, 15.59 eV at 1e-12, against
    // 19.70 eV here). Agreement among one integrator's starts does not define it.
    for z in [19.5, 20.0, 20.2] {
        let r = run(&hybrid_at(z), Starts::WhereGrazing);
        let o = &r.observables;
        assert!(o.grazing, "{z} nm");
        assert!(
            o.grazing_margin_m.unwrap() < 0.01 * r.thermal_rms_m,
            "{z} nm"
        );
        assert_eq!(r.attractors.as_ref().unwrap().len(), 1, "{z} nm");
        assert_eq!(r.well_defined, Some(false), "{z} nm");
    }
    // The table says so, and where to look for what an instrument reads.
    let out = common::tapsim(&["tap", "--separation", "19.5nm"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("not defined here") && text.contains("--temperature"),
        "{text}"
    );
}

#[test]
fn starts_are_listed_on_request_and_bounded() {
    // Away from grazing the tighter tolerance reaches the same orbit.
    let r = run(&default_setup(), Starts::First(2));
    let list = r.attractors.unwrap();
    assert_eq!(list.len(), 1);
    assert_eq!(list[0].count, 2);
    assert_eq!(r.well_defined, Some(true));
    // The defaults are bistable: from rest the tip settles on the attractive branch
    // (φ > 90°), from the free oscillation on the repulsive one; neither grazes, so
    // each is well defined, and which one is reached depends on the history.
    let r = run(&default_setup(), Starts::First(6));
    let list = r.attractors.unwrap();
    assert_eq!(list.len(), 2, "{list:?}");
    assert!(list[0].phase_deg < 90.0 && list[1].phase_deg > 90.0);
    assert!(list.iter().all(|a| !a.grazing && a.period == Some(1)));
    assert!(list[1].starts.contains(&"rest".to_string()));
    assert_eq!(r.well_defined, Some(true));
    let bad = tap(
        &default_setup(),
        &Numerics::default(),
        Observe {
            starts: Starts::First(65),
            ..Observe::default()
        },
    );
    assert!(bad.is_err());
}

#[test]
fn the_standard_error_of_irregular_motion_covers_the_spread_of_five_windows() {
    // The quasi-periodic JKR state (1 touch in 29 periods, the state never repeating):
    // five more windows as long as the reported one, marched on from where it ended.
    let mut setup = TapSetup {
        law: LawKind::Jkr.into(),
        separation_m: 20e-9,
        ..default_setup()
    };
    setup.cantilever.drive_frequency_hz = 305e3;
    let p = Prepared::new(&setup, &Numerics::default()).unwrap();
    let sim = p.simulation();
    let mut phase = sim.free_steady_start();
    let state = sim.steady_state(&mut phase, &p.steady).unwrap();
    assert!(state.motion.period().is_none() && state.converged);
    let n = state.window.periods;
    let means: Vec<(f64, f64, f64)> = (0..5)
        .map(|_| {
            let mut w = sim
                .cycle(&mut phase, &mut tapsim::dynamics::numeric::Ignore)
                .unwrap();
            for _ in 1..n {
                let c = sim
                    .cycle(&mut phase, &mut tapsim::dynamics::numeric::Ignore)
                    .unwrap();
                w = w.then(&c);
            }
            (w.amplitude(), w.phase(), w.e_ts_per_period())
        })
        .collect();
    let spread = |pick: fn(&(f64, f64, f64)) -> f64| {
        let m = means.iter().map(pick).sum::<f64>() / 5.0;
        (means.iter().map(|x| (pick(x) - m).powi(2)).sum::<f64>() / 4.0).sqrt()
    };
    let se = state.std_err;
    let w = state.window;
    for (what, s, e, mean, reported) in [
        (
            "A",
            spread(|x| x.0),
            se.amplitude,
            w.amplitude(),
            means[0].0,
        ),
        ("phi", spread(|x| x.1), se.phase, w.phase(), means[0].1),
        (
            "E_ts",
            spread(|x| x.2),
            se.e_ts,
            w.e_ts_per_period(),
            means[0].2,
        ),
    ] {
        println!("{what}: spread of 5 windows {s:e}, reported standard error {e:e}");
        // With 4 degrees of freedom the sample spread exceeds 1.54 σ with 5 % chance.
        assert!(s <= 2.0 * e, "{what}: spread {s:e} vs standard error {e:e}");
        assert!((reported - mean).abs() <= 4.0 * e.max(1e-300) + 4.0 * s);
    }
}

// ---------------------------------------------------------------------------------------
// An independent marcher: the same point-mass model and the same hybrid law (its branches
// and switch levels), integrated by ode_solvers' Dop853 (8th order; tapsim uses Dopri5 and
// closed-form free flight), every switch located by the Illinois method on re-integrated
// states, from the start marched for 3000 periods and measured over 2000. It shares no
// integrator, event finder, classification or averaging with tapsim.
//
// The time is carried as a sixth state (τ' = 1) and the drive read from it: ode_solvers
// 0.6.2's Dop853 evaluates its last stage at c₁₂ = 0 instead of 1 (its tableau's C[11]),
// which is harmless for an autonomous system and reduces a time-dependent one to low
// order (measured: 168 steps per unit time for a driven oscillator at rtol 1e-9, 5 for
// the same oscillator undriven; its Dopri5, which tapsim uses, has no such slip).

use ode_solvers::dop853::Dop853;
use ode_solvers::{OutputType, SVector, System};

type Y = SVector<f64, 6>;

/// What the marcher needs of the model: x'' + 2γx' + x = f₀ cos Ωτ − f_s T̂(α̂, branch),
/// α̂ = a₀ + a₁x.
struct Model<'a> {
    law: &'a AnyLaw,
    gamma: f64,
    omega: f64,
    f0: f64,
    a0: f64,
    a1: f64,
    f_scale: f64,
}

impl Model<'_> {
    fn alpha(&self, x: f64) -> f64 {
        self.a0 + self.a1 * x
    }
    /// y = (x, x', ∫ f x' dτ, ∫ x cos Ωτ dτ, ∫ x sin Ωτ dτ, τ). Past the branch's own
    /// levels (where a stage of a step that crosses one lands) the force is held at its
    /// value on the level: a branch may end at a fold, beyond which it has no force, and
    /// a force undefined there would make every step that crosses it fail, the steps
    /// shrinking towards the level without end.
    fn rhs(&self, branch: Branch, y: &Y) -> Y {
        let e = self.law.exits(branch);
        let alpha = self
            .alpha(y[0])
            .max(e.below.map_or(f64::NEG_INFINITY, |b| b.0))
            .min(e.above.map_or(f64::INFINITY, |a| a.0));
        let f = -self.f_scale * self.law.t_hat(alpha, branch);
        let (s, c) = (self.omega * y[5]).sin_cos();
        Y::from([
            y[1],
            self.f0 * c - 2.0 * self.gamma * y[1] - y[0] + f,
            f * y[1],
            y[0] * c,
            y[0] * s,
            1.0,
        ])
    }
}

/// A segment on one branch; stops at the first step over whose span α̂ crosses one of
/// the branch's levels (at a step end, or inside it at a turning point of the cubic
/// through the step's ends).
struct Segment<'a> {
    model: &'a Model<'a>,
    branch: Branch,
    below: f64,
    above: f64,
    log: &'a RefCell<Log>,
}

struct Log {
    /// The last accepted step's end (the segment's start before any).
    prev: (f64, Y),
    /// The step that crossed: its start, the time by which α̂ is past a level (the
    /// step's end or the turning point inside it), and whether that level is below.
    crossed: Option<((f64, Y), f64, bool)>,
}

impl Log {
    fn from(t: f64, y: Y) -> RefCell<Self> {
        RefCell::new(Self {
            prev: (t, y),
            crossed: None,
        })
    }
}

impl System<f64, Y> for Segment<'_> {
    fn system(&self, _t: f64, y: &Y, dy: &mut Y) {
        *dy = self.model.rhs(self.branch, y);
    }
    fn solout(&mut self, t: f64, y: &Y, _dy: &Y) -> bool {
        let mut log = self.log.borrow_mut();
        let (t0, y0) = log.prev;
        let m = self.model;
        let past = |x: f64| m.alpha(x) <= self.below || m.alpha(x) >= self.above;
        let mut at = past(y[0]).then_some((t, y[0]));
        if at.is_none() && (y0[1] < 0.0) != (y[1] < 0.0) {
            // A turning point inside: the cubic Hermite through both ends.
            let h = t - t0;
            let (p0, p1, m0, m1) = (y0[0], y[0], h * y0[1], h * y[1]);
            let c3 = 2.0 * p0 + m0 - 2.0 * p1 + m1;
            let c2 = -3.0 * p0 - 2.0 * m0 + 3.0 * p1 - m1;
            let (qa, qb, qc) = (3.0 * c3, 2.0 * c2, m0);
            let disc = (qb * qb - 4.0 * qa * qc).max(0.0).sqrt();
            for s in [
                (-qb - disc) / (2.0 * qa),
                (-qb + disc) / (2.0 * qa),
                -qc / qb,
            ] {
                if s.is_finite() && (0.0..=1.0).contains(&s) {
                    let x = p0 + s * (m0 + s * (c2 + s * c3));
                    if past(x) {
                        at = Some((t0 + s * h, x));
                        break;
                    }
                }
            }
        }
        match at {
            Some((when, x)) => {
                log.crossed = Some(((t0, y0), when, m.alpha(x) <= self.below));
                true
            }
            None => {
                log.prev = (t, *y);
                false
            }
        }
    }
}

struct Marcher<'a> {
    model: Model<'a>,
    rtol: f64,
    /// Steps no longer than this (a period / 200: a dip across a level inside one step is
    /// caught by the cubic through its ends).
    h_max: f64,
}

impl Marcher<'_> {
    fn levels(&self, branch: Branch) -> (f64, f64) {
        let e = self.model.law.exits(branch);
        (
            e.below.map_or(f64::NEG_INFINITY, |b| b.0),
            e.above.map_or(f64::INFINITY, |a| a.0),
        )
    }

    /// Dop853 over `seg` from (t, y) to `t_end`: this marcher's tolerances (atol 1 % of
    /// rtol), Hairer's step controls, steps of at most `h_max`, no stiffness test.
    fn stepper<'s>(
        &self,
        seg: Segment<'s>,
        (t, y): (f64, Y),
        t_end: f64,
    ) -> Dop853<f64, Y, Segment<'s>> {
        Dop853::from_param(
            seg,
            t,
            t_end,
            0.0,
            y,
            self.rtol,
            self.rtol * 1e-2,
            0.9,
            0.0,
            0.333,
            6.0,
            self.h_max,
            0.0,
            1_000_000,
            u32::MAX,
            OutputType::Sparse,
        )
    }

    /// Integrate on `branch` from (t, y) to `t_end` with no event.
    fn plain(&self, branch: Branch, (t, y): (f64, Y), t_end: f64) -> Y {
        if t_end <= t {
            return y;
        }
        let log = Log::from(t, y);
        let seg = Segment {
            model: &self.model,
            branch,
            below: f64::NEG_INFINITY,
            above: f64::INFINITY,
            log: &log,
        };
        let mut s = self.stepper(seg, (t, y), t_end);
        s.integrate().unwrap();
        *s.y_out().last().unwrap()
    }

    /// One drive period from (t, y) on `branch`: the end state and branch, and the jumps
    /// into contact.
    fn period(&self, mut branch: Branch, mut t: f64, mut y: Y, t_end: f64) -> (Y, Branch, u32) {
        let mut jumps_in = 0;
        while t_end - t > 1e-12 {
            let (below, above) = self.levels(branch);
            let log = Log::from(t, y);
            let seg = Segment {
                model: &self.model,
                branch,
                below,
                above,
                log: &log,
            };
            let mut s = self.stepper(seg, (t, y), t_end);
            s.integrate().unwrap();
            let end = (*s.x_out().last().unwrap(), *s.y_out().last().unwrap());
            let Some((start, when, falling)) = log.borrow().crossed else {
                (t, y) = end;
                continue;
            };
            // Illinois on g(τ), how far α̂ is short of the level, from the step's start.
            let short_of = |yy: &Y| {
                let a = self.model.alpha(yy[0]);
                if falling { a - below } else { above - a }
            };
            let g = |tt: f64| short_of(&self.plain(branch, start, tt));
            let (mut lo, mut hi) = (start.0, when);
            let (mut g_lo, mut g_hi) = (g(lo), g(hi));
            if g_hi > 0.0 {
                // The cubic's dip was not real: go on from the step's end.
                (t, y) = end;
                continue;
            }
            let mut side = 0;
            for _ in 0..200 {
                if hi - lo < 1e-14 * t_end.abs().max(1.0) {
                    break;
                }
                let mid = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
                let mid = if mid > lo && mid < hi {
                    mid
                } else {
                    0.5 * (lo + hi)
                };
                let gm = g(mid);
                if gm > 0.0 {
                    (lo, g_lo) = (mid, gm);
                    if side == -1 {
                        g_hi *= 0.5;
                    }
                    side = -1;
                } else {
                    (hi, g_hi) = (mid, gm);
                    if side == 1 {
                        g_lo *= 0.5;
                    }
                    side = 1;
                }
            }
            y = self.plain(branch, start, hi);
            t = hi;
            let exits = self.model.law.exits(branch);
            let next = if falling { exits.below } else { exits.above };
            let next = next.expect("a level crossed is an exit").1;
            jumps_in += u32::from(next == Branch::Contact);
            branch = next;
        }
        (y, branch, jumps_in)
    }
}

/// What the marcher saw over its measured periods.
#[derive(Debug, Clone, Copy)]
struct Seen {
    touch_fraction: f64,
    amplitude_ratio: f64,
    phase_deg: f64,
    e_ts_j: f64,
    /// The least n ≤ 1000 after which the state returned within 1e-7 three periods
    /// running at the end, if any.
    period: Option<usize>,
}

fn march(setup: &TapSetup, rtol: f64, from_rest: bool) -> Seen {
    let p = Prepared::new(setup, &Numerics::default()).unwrap();
    let Drive::Force { amplitude: f0 } = p.osc.drive else {
        unreachable!("a force drive")
    };
    let (gamma, omega) = (p.osc.gamma, p.osc.omega);
    let model = Model {
        law: &p.law,
        gamma,
        omega,
        f0,
        a0: p.cpl.a0,
        a1: p.cpl.a1,
        f_scale: p.cpl.f_scale,
    };
    let period = 2.0 * std::f64::consts::PI / omega;
    let m = Marcher {
        model,
        rtol,
        h_max: period / 200.0,
    };
    // The free steady state a cos Ωτ + b sin Ωτ at τ = 0, or rest.
    let det = (1.0 - omega * omega).powi(2) + (2.0 * gamma * omega).powi(2);
    let (a, b) = (
        f0 * (1.0 - omega * omega) / det,
        f0 * 2.0 * gamma * omega / det,
    );
    let mut y = if from_rest {
        Y::zeros()
    } else {
        Y::from([a, b * omega, 0.0, 0.0, 0.0, 0.0])
    };
    let mut branch = Branch::Free;
    let (transient, measured) = (3000, 2000);
    let mut sections: Vec<(f64, f64)> = Vec::with_capacity(measured);
    let mut per_period = Vec::with_capacity(measured);
    for k in 0..transient + measured {
        // Each period from τ = 0 (the drive is periodic), the integrals reset.
        y[2] = 0.0;
        y[3] = 0.0;
        y[4] = 0.0;
        y[5] = 0.0;
        let (end, next, jumps) = m.period(branch, 0.0, y, period);
        (y, branch) = (end, next);
        if k >= transient {
            sections.push((y[0], y[1]));
            per_period.push((jumps, y[2], y[3], y[4]));
        }
    }
    let n = sections.len();
    let period_found = (1..=1000).find(|&q| {
        (0..3).all(|back| {
            let (x1, v1) = sections[n - 1 - back];
            let (x0, v0) = sections[n - 1 - back - q];
            (x1 - x0).abs().max((v1 - v0).abs()) < 1e-7
        })
    });
    // Average over whole passes of an orbit found, else over every measured period.
    let count = period_found.map_or(n, |q| n / q * q);
    let window = &per_period[n - count..];
    let jumps: u32 = window.iter().map(|w| w.0).sum();
    let work: f64 = window.iter().map(|w| w.1).sum();
    let (sc, ss) = window
        .iter()
        .fold((0.0, 0.0), |(c, s), w| (c + w.2, s + w.3));
    let span = count as f64 * period;
    let cant = &setup.cantilever;
    Seen {
        touch_fraction: f64::from(jumps) / count as f64,
        amplitude_ratio: 2.0 / span * sc.hypot(ss),
        phase_deg: ss.atan2(sc).to_degrees(),
        e_ts_j: -work / count as f64 * cant.stiffness_n_m * cant.free_amplitude_m.powi(2),
        period: period_found,
    }
}

#[test]
#[ignore = "slow: run with cargo test --release -- --ignored grazing::"]
fn near_onset_every_point_the_independent_marcher_finds_ill_posed_is_flagged() {
    let mut flagged_and_changed = 0;
    for k in 0..10 {
        let z = 19.0 + 2.5 * k as f64 / 9.0;
        let setup = hybrid_at(z);
        let r = run(&setup, Starts::WhereGrazing);
        let o = &r.observables;
        let seen = [
            march(&setup, 1e-11, false),
            march(&setup, 1e-12, false),
            march(&setup, 1e-11, true),
        ];
        println!("z_c {z:.3} nm: tapsim {} grazing {} ", o.regime, o.grazing);
        for a in r.attractors.iter().flatten() {
            println!(
                "   tapsim attractor: {} touches {:.6} A/A0 {:.10} E_ts {:e} J, starts {:?}",
                a.regime, a.touch_fraction, a.amplitude_ratio, a.e_ts_j, a.starts
            );
        }
        for s in &seen {
            println!("   marcher {s:?}");
        }
        // The same attractor: the same period and touches, A/A₀ equal to the marcher's
        // own tolerance.
        let same = |a: &Seen, b: &Seen| {
            a.period == b.period
                && a.touch_fraction == b.touch_fraction
                && (a.amplitude_ratio - b.amplitude_ratio).abs() < 1e-8
        };
        let changes = !(same(&seen[0], &seen[1]) && same(&seen[0], &seen[2]));
        if changes {
            assert!(
                o.grazing,
                "{z} nm: the marcher's attractor changes; not flagged"
            );
            flagged_and_changed += 1;
        }
        if o.grazing {
            // Every state the marcher reached, from either start at either tolerance, is
            // among the attractors tapsim lists: the same period and touches, E_ts within
            // 1e-6 (the issue asks 2 %; measured: 7e-10).
            let list = r
                .attractors
                .as_ref()
                .expect("a flagged state lists attractors");
            for s in &seen {
                assert!(
                    list.iter().any(|a| a.period == s.period
                        && (a.touch_fraction - s.touch_fraction).abs() < 1e-12
                        && (a.e_ts_j / s.e_ts_j - 1.0).abs() < 1e-6),
                    "{z} nm: the marcher's {s:?} is not among {list:?}"
                );
            }
        }
        if !o.grazing {
            // Away from grazing the answer is the marcher's.
            let s = &seen[0];
            assert_eq!(o.period, s.period, "{z} nm");
            // (The issue asks 1e-4; measured: 4e-10.)
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-8 * b.abs().max(1e-30);
            assert!(close(o.amplitude_ratio, s.amplitude_ratio), "{z} nm");
            assert!(close(o.phase_deg, s.phase_deg), "{z} nm");
            assert!(
                close(o.e_ts_j, s.e_ts_j) || (o.e_ts_j == 0.0 && s.e_ts_j.abs() < 1e-30),
                "{z} nm: {} vs {}",
                o.e_ts_j,
                s.e_ts_j
            );
        }
    }
    println!("{flagged_and_changed} of 10 points ill-posed for the marcher, all flagged");
    // The coexisting locks at 20.39 nm (period 89 from the free oscillation, 76 from rest)
    // are found by both: the check above is not vacuous.
    assert!(flagged_and_changed >= 1);
}
