//! A second eigenmode on top of the tapping orbit, by brute force: both modes marched
//! together by a fixed-step fourth-order Runge–Kutta method written here (the law's
//! branch switches located by bisection of the step). Two checks:
//! - tapsim's ⟨∂F_ts/∂z⟩ (`mean_force_gradient_n_m`: the slope averaged over the orbit,
//!   each switch's force step counted as Δf/ẋ) against the same average taken here over
//!   a one-mode march (the law's slope at every step, the steps at located switches);
//! - the small-amplitude limit, cot φ₂ = −(Q₂/k₂)⟨∂F_ts/∂z⟩ (Lozano & García, PRL 100,
//!   076102, 2008), against the phase of a second mode marched with the first, the
//!   average taken over that march's own orbit (a second mode also yields to the tip's
//!   force, and so changes the orbit a little).
//!
//! The second mode is a rectangular beam's: f₂/f₁ = (4.6941/1.8751)², k₂ = k₁ (f₂/f₁)²
//! (equal modal masses), driven at its free resonance with A₀₂ = 0.1 nm.

use tapsim::dynamics::gradient::second_mode_phase_deg;
use tapsim::dynamics::model::Drive;
use tapsim::dynamics::observables::{Observe, tap};
use tapsim::dynamics::setup::{Numerics, Prepared, TapSetup, default_setup};
use tapsim::law::{Branch, ForceLaw};

/// The first two roots of cos β cosh β = −1 (a clamped–free beam).
const BETA: (f64, f64) = (1.875_104_068_711_961, 4.694_091_132_974_175);

/// f₂/f₁ of a rectangular beam.
const BEAM: f64 = (BETA.1 / BETA.0) * (BETA.1 / BETA.0);

/// Steps per drive period.
const PER_PERIOD: usize = 1280;

struct Bimodal {
    p: Prepared,
    /// Mode 2 over mode 1: frequency ratio (its stiffness is r², equal masses).
    r: f64,
    q2: f64,
    /// Drive amplitudes of the modes (units of k₁A₀); mode 2 absent if `second` is false.
    f1: f64,
    f2: f64,
    second: bool,
}

/// What a march saw over its window: ∫ x cos, ∫ x sin of the deflection x = q₁ + q₂ at
/// both modes' drive frequencies, ∫ ∂f/∂x dτ with the switches' steps, and the time.
#[derive(Default)]
struct Window {
    mode1: (f64, f64),
    mode2: (f64, f64),
    gradient: f64,
    span: f64,
    /// A Hann taper over (start, length) on the projections: 2 sin²(π(τ − start)/length)
    /// (mean 1), whose leak of a line δ away falls as 1/(δ·length)³ instead of 1/(δ·length).
    taper: Option<(f64, f64)>,
}

impl Bimodal {
    fn alpha(&self, x: f64) -> f64 {
        self.p.cpl.alpha_hat(x, 0.0)
    }

    fn force(&self, x: f64, branch: Branch) -> f64 {
        -self.p.cpl.f_scale * self.p.law.t_hat(self.alpha(x), branch)
    }

    fn slope(&self, x: f64, branch: Branch) -> f64 {
        -self.p.cpl.f_scale * self.p.law.slope_hat(self.alpha(x), branch) * self.p.cpl.a1
    }

    /// The tip's deflection and velocity.
    fn tip(&self, y: &[f64; 4]) -> (f64, f64) {
        if self.second {
            (y[0] + y[2], y[1] + y[3])
        } else {
            (y[0], y[1])
        }
    }

    /// d/dτ of (x₁, v₁, x₂, v₂) at τ on `branch` (mode-1 units: τ = ω₁t, lengths A₀,
    /// forces k₁A₀).
    fn rate(&self, tau: f64, y: [f64; 4], branch: Branch) -> [f64; 4] {
        let f = self.force(self.tip(&y).0, branch);
        let (q1, r) = (1.0 / (2.0 * self.p.osc.gamma), self.r);
        let second = if self.second {
            -r * r * y[2] - r * y[3] / self.q2 + f + self.f2 * (r * tau).cos()
        } else {
            0.0
        };
        [
            y[1],
            -y[0] - y[1] / q1 + f + self.f1 * (self.p.osc.omega * tau).cos(),
            y[3],
            second,
        ]
    }

    fn rk4(&self, tau: f64, y: [f64; 4], h: f64, branch: Branch) -> [f64; 4] {
        let add = |a: [f64; 4], k: [f64; 4], s: f64| std::array::from_fn(|i| a[i] + s * k[i]);
        let k1 = self.rate(tau, y, branch);
        let k2 = self.rate(tau + h / 2.0, add(y, k1, h / 2.0), branch);
        let k3 = self.rate(tau + h / 2.0, add(y, k2, h / 2.0), branch);
        let k4 = self.rate(tau + h, add(y, k3, h), branch);
        std::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
    }

    /// The branch entered where `branch` ends at tip deflection `x`, if it does.
    fn exit(&self, branch: Branch, x: f64) -> Option<Branch> {
        let alpha = self.alpha(x);
        let exits = self.p.law.exits(branch);
        match (exits.below, exits.above) {
            (Some((level, next)), _) if alpha < level => Some(next),
            (_, Some((level, next))) if alpha > level => Some(next),
            _ => None,
        }
    }

    /// March `steps` steps of `h` from (τ, y) on `branch`; a step that leaves the branch
    /// is cut where it does (bisection to 1e-13 of the step) and goes on on the next.
    /// With `window`, its integrals over the march (per piece; each switch's step of the
    /// force over the tip's velocity there).
    fn march(
        &self,
        (mut tau, mut y, mut branch): (f64, [f64; 4], Branch),
        h: f64,
        steps: usize,
        mut window: Option<&mut Window>,
    ) -> (f64, [f64; 4], Branch) {
        for _ in 0..steps {
            let mut left = h;
            while left > 0.0 {
                let mut piece = left;
                let mut next = self.rk4(tau, y, piece, branch);
                let mut entered = None;
                if let Some(b) = self.exit(branch, self.tip(&next).0) {
                    let (mut lo, mut hi) = (0.0, left);
                    while hi - lo > 1e-13 * h {
                        let mid = 0.5 * (lo + hi);
                        if self
                            .exit(branch, self.tip(&self.rk4(tau, y, mid, branch)).0)
                            .is_some()
                        {
                            hi = mid;
                        } else {
                            lo = mid;
                        }
                    }
                    piece = hi;
                    next = self.rk4(tau, y, piece, branch);
                    entered = Some(b);
                }
                if let Some(w) = window.as_deref_mut() {
                    let mid = self.rk4(tau, y, piece / 2.0, branch);
                    let t = tau + piece / 2.0;
                    let weight = w.taper.map_or(1.0, |(start, length)| {
                        2.0 * (std::f64::consts::PI * (t - start) / length).sin().powi(2)
                    }) * piece;
                    // What a lock-in at each mode's drive reads: the deflection, the
                    // sum of the modes (issue 45: not each mode's own coordinate).
                    let x = self.tip(&mid).0;
                    w.mode1.0 += x * (self.p.osc.omega * t).cos() * weight;
                    w.mode1.1 += x * (self.p.osc.omega * t).sin() * weight;
                    w.mode2.0 += x * (self.r * t).cos() * weight;
                    w.mode2.1 += x * (self.r * t).sin() * weight;
                    // ∫ f'(x(τ)) dτ over the piece: where the tip moves, Δf/ẋ (the
                    // slope's square-root singularity at a fold integrated exactly,
                    // with ẋ of the midpoint); near a turning point the midpoint rule.
                    let (x0, (x1, v)) = (self.tip(&y).0, self.tip(&mid));
                    w.gradient += if v.abs() > 0.05 {
                        (self.force(self.tip(&next).0, branch) - self.force(x0, branch)) / v
                    } else {
                        self.slope(x1, branch) * piece
                    };
                    w.span += piece;
                    if let Some(b) = entered {
                        let (x, v) = self.tip(&next);
                        w.gradient += (self.force(x, b) - self.force(x, branch)) / v;
                    }
                }
                (tau, y) = (tau + piece, next);
                if let Some(b) = entered {
                    branch = b;
                }
                left -= piece;
            }
        }
        (tau, y, branch)
    }
}

/// The system for `setup` with a second mode of quality `q2` (or none), settled from
/// the free oscillation (x₁ = sin τ, as tapsim starts) over 1500 periods (Q₁ = 400:
/// e^{−1500π/400} ≈ 1e-5 of the start, sooner with the contact's loss), then watched
/// over 400: its window.
fn settle_and_watch(
    setup: &TapSetup,
    q2: Option<f64>,
    drive2: bool,
    r: f64,
    per_period: usize,
) -> (Bimodal, Window) {
    watch(setup, (q2, drive2, r), per_period, false)
}

/// [`settle_and_watch`], the window tapered (Hann) if `tapered`.
fn watch(
    setup: &TapSetup,
    (q2, drive2, r): (Option<f64>, bool, f64),
    per_period: usize,
    tapered: bool,
) -> (Bimodal, Window) {
    let numerics = Numerics::default();
    let p = Prepared::new(setup, &numerics).unwrap();
    let Drive::Force { amplitude: f1 } = p.osc.drive else {
        panic!("a force drive")
    };
    let q2v = q2.unwrap_or(1.0);
    let system = Bimodal {
        r,
        q2: q2v,
        // A₀₂ = 0.1 nm at resonance: F₂ = k₂A₀₂/Q₂.
        f2: if drive2 {
            r * r * (0.1e-9 / setup.cantilever.free_amplitude_m) / q2v
        } else {
            0.0
        },
        f1,
        second: q2.is_some(),
        p,
    };
    let h = 2.0 * std::f64::consts::PI / system.p.osc.omega / per_period as f64;
    let start = (0.0, [0.0, 1.0, 0.0, 0.0], Branch::Free);
    let settled = system.march(start, h, per_period * 1500, None);
    let mut window = Window {
        taper: tapered.then(|| (settled.0, h * (per_period * 400) as f64)),
        ..Window::default()
    };
    system.march(settled, h, per_period * 400, Some(&mut window));
    (system, window)
}

fn lag_deg((c, s): (f64, f64)) -> f64 {
    s.atan2(c).to_degrees()
}

/// tapsim's averaged gradient and φ₁ against a one-mode march's; then φ₂ of a marched
/// second mode against the limit from the average over that march, to `within` of
/// φ₂ − 90°.
fn check(setup: &TapSetup, q2s: &[f64], within: f64) {
    let run = tap(
        setup,
        &Numerics::default(),
        Observe {
            harmonics: true,
            ..Observe::default()
        },
    )
    .unwrap();
    assert_eq!(run.observables.regime, "period-1");
    let k1 = setup.cantilever.stiffness_n_m;
    let tapsim_gradient = run.mean_force_gradient_n_m.expect("a periodic orbit's") / k1;
    let (_, one) = settle_and_watch(setup, None, false, BEAM, PER_PERIOD);
    let (phi1, gradient) = (lag_deg(one.mode1), one.gradient / one.span);
    eprintln!(
        "{}: phi1 {phi1:.5} march, {:.5} tapsim; <df/dx> {gradient:.6} march, \
         {tapsim_gradient:.6} tapsim",
        setup.law, run.observables.phase_deg
    );
    assert!((phi1 - run.observables.phase_deg).abs() < 2e-3);
    assert!((gradient - tapsim_gradient).abs() < 1e-3 * tapsim_gradient.abs());
    for &q2 in q2s {
        // The second mode's response to its drive: the driven march's projection less
        // the undriven one's (what the tip force's harmonics near f₂ leak into a finite
        // window, the same in both).
        let (system, w) = settle_and_watch(setup, Some(q2), true, BEAM, PER_PERIOD);
        let (_, still) = settle_and_watch(setup, Some(q2), false, BEAM, PER_PERIOD);
        let measured = lag_deg((w.mode2.0 - still.mode2.0, w.mode2.1 - still.mode2.1));
        let limit = second_mode_phase_deg(w.gradient / w.span, system.r * system.r, q2);
        eprintln!("  Q2 = {q2}: phi2 {measured:.4} marched, {limit:.4} limit");
        assert!((limit - 90.0).abs() > 1.0, "a shift to compare: {limit}");
        assert!(
            ((measured - 90.0) - (limit - 90.0)).abs() <= within * (limit - 90.0).abs(),
            "phi2 {measured} against the limit {limit}"
        );
    }
}

/// Hertz contact (no switch): the gradient is the slope averaged over the contact.
#[test]
fn a_small_second_mode_sees_the_averaged_hertz_stiffness() {
    let setup = TapSetup {
        law: tapsim::law::LawKind::Hertz.into(),
        separation_m: 12e-9,
        ..default_setup()
    };
    check(&setup, &[100.0, 400.0], 0.02);
}

/// The hybrid law on the defaults: the jump-in and the pull-off step the force, and the
/// steps count as the gradient they are to the second mode (here they give back a fifth
/// of the contact's stiffening). The limit holds to 2.2 % of φ₂ − 90° (Hertz: 0.8–0.95 %):
/// it is first order in the gradient's modulation over the orbit, and what it leaves
/// out does not shrink with a stiffer second mode (measured with k₂ ×4 and ×16), so it is
/// the first mode's response at the sidebands f₂ ± n f₁ (f₂ − 6 f₁ ≈ 0.27 f₁ lies near
/// it) fed back through that modulation. 2.2 % at Q₂ = 100 and at 400 alike.
#[test]
fn a_small_second_mode_sees_the_hybrid_loops_steps() {
    check(&default_setup(), &[100.0, 400.0], 0.025);
}

/// The several-mode solver (Newton's method on the common period of four first-mode
/// periods, Dopri5, switches located and corrected to the level) against this march of
/// the same system (f₂ = 6.25 f₁ exactly, Q₂ = 400, A₀₂ = 0.1 nm): both modes'
/// amplitudes and phases. The march takes 2560 steps a period here: its own error is
/// what is left (at 1280 steps φ₁ differs by 2.3e-3°, at 2560 by 6.5e-4°, A₁ by 1.2e-6
/// and 3e-7: the march converges onto the solver's values).
#[test]
fn the_several_mode_solver_agrees_with_the_brute_force_march() {
    use tapsim::dynamics::modes::{Eigenmode, ModeSet, tap_modes};
    for setup in [
        default_setup(),
        TapSetup {
            law: tapsim::law::LawKind::Hertz.into(),
            separation_m: 12e-9,
            ..default_setup()
        },
    ] {
        let c = &setup.cantilever;
        let r = 6.25;
        let set = ModeSet {
            higher: vec![Eigenmode {
                stiffness_n_m: c.stiffness_n_m * r * r,
                resonance_hz: c.resonance_hz * r,
                quality: 400.0,
                free_amplitude_m: 0.1e-9,
            }],
            ratio_tolerance: 1e-9,
        };
        let m = tap_modes(&setup, &set, &Numerics::default()).unwrap();
        let (_, w) = settle_and_watch(&setup, Some(400.0), true, r, 2 * PER_PERIOD);
        let amp = |(c, s): (f64, f64)| 2.0 / w.span * c.hypot(s);
        let a0 = c.free_amplitude_m;
        let (a1, a2) = (amp(w.mode1), amp(w.mode2) * a0 / 0.1e-9);
        let (phi1, phi2) = (lag_deg(w.mode1), lag_deg(w.mode2));
        eprintln!(
            "{}: A1 {a1:.7} / {:.7}, phi1 {phi1:.5} / {:.5}, A2 {a2:.6} / {:.6}, phi2 {phi2:.4} / {:.4}",
            setup.law,
            m.modes[0].amplitude_ratio.unwrap(),
            m.modes[0].phase_deg,
            m.modes[1].amplitude_ratio.unwrap(),
            m.modes[1].phase_deg
        );
        assert!((a1 - m.modes[0].amplitude_ratio.unwrap()).abs() < 1e-6);
        assert!((phi1 - m.modes[0].phase_deg).abs() < 1e-3);
        assert!((a2 - m.modes[1].amplitude_ratio.unwrap()).abs() < 1e-5);
        assert!((phi2 - m.modes[1].phase_deg).abs() < 1e-3);
    }
}

/// The small-amplitude limit against the several-mode solver: φ₂ − 90° of a beam's
/// second mode (Euler–Bernoulli defaults, A₀₂ = 0.1 nm) against cot φ₂ =
/// −(Q₂/k₂)⟨∂F_ts/∂z⟩ over the one-mode orbit (tapsim's `mean_force_gradient_n_m`):
/// within 2 % as the issue asks, and within what the guide states (0.7 % for Hertz,
/// 1.3 % for the hybrid law).
#[test]
fn the_several_mode_phase_meets_the_small_amplitude_limit() {
    use tapsim::dynamics::modes::{ModeSet, tap_modes};
    for (setup, within) in [
        (
            TapSetup {
                law: tapsim::law::LawKind::Hertz.into(),
                separation_m: 12e-9,
                ..default_setup()
            },
            0.007,
        ),
        (default_setup(), 0.013),
    ] {
        let run = tap(
            &setup,
            &Numerics::default(),
            Observe {
                harmonics: true,
                ..Observe::default()
            },
        )
        .unwrap();
        let gradient = run.mean_force_gradient_n_m.unwrap();
        let mut set = ModeSet::euler_bernoulli(&setup.cantilever, 2).unwrap();
        set.higher[0].free_amplitude_m = 0.1e-9;
        let mode2 = set.higher[0];
        let m = tap_modes(&setup, &set, &Numerics::default()).unwrap();
        let limit = second_mode_phase_deg(
            gradient / setup.cantilever.stiffness_n_m,
            mode2.stiffness_n_m / setup.cantilever.stiffness_n_m,
            mode2.quality,
        );
        let phi2 = m.modes[1].phase_deg;
        eprintln!("{}: phi2 {phi2:.4}, limit {limit:.4}", setup.law);
        assert!(((phi2 - 90.0) - (limit - 90.0)).abs() <= within * (limit - 90.0).abs());
    }
}

/// Drives with no common period (the beam's exact f₂/f₁ = 6.26689…, a ratio tolerance
/// of 0): tapsim's window averages (whole periods of each mode, bump-weighted windows)
/// against this march of the same system, projected over its 400 periods with a Hann
/// taper, both modes' amplitudes and phases on the hybrid defaults. The march at 5120
/// steps a period leaves its own error (φ₁: 2.6e-4° here, 9.4e-4° at 2560 steps, as
/// against the commensurate solver above); the second mode's agree to 8e-5° and 7e-7,
/// and tapsim's standard errors (about 1e-6°) are below what the march resolves. (With
/// a plain, untapered 400-period projection the march is off by 0.02° in φ₂: the line
/// 6f₁, 0.27f₁ from f₂, leaks into it.)
#[test]
fn window_averages_without_a_common_period_agree_with_the_brute_force_march() {
    use tapsim::dynamics::modes::{Eigenmode, ModeSet, modal_windowed, prepare};
    let setup = default_setup();
    let c = &setup.cantilever;
    let set = ModeSet {
        higher: vec![Eigenmode {
            stiffness_n_m: c.stiffness_n_m * BEAM * BEAM,
            resonance_hz: c.resonance_hz * BEAM,
            quality: 400.0,
            free_amplitude_m: 0.1e-9,
        }],
        ratio_tolerance: 0.0,
    };
    let numerics = Numerics::default();
    let (p, modal) = prepare(&setup, &set, &numerics).unwrap();
    assert_eq!(modal.periods, None, "no common period");
    let m = modal_windowed(&p, &modal, &numerics).unwrap();
    assert!(m.converged);
    let (_, w) = watch(&setup, (Some(400.0), true, BEAM), 4 * PER_PERIOD, true);
    let amp = |(c, s): (f64, f64)| 2.0 / w.span * c.hypot(s);
    let (a1, a2) = (amp(w.mode1), amp(w.mode2) * c.free_amplitude_m / 0.1e-9);
    let (phi1, phi2) = (lag_deg(w.mode1), lag_deg(w.mode2));
    let (t1, t2) = (&m.modes[0], &m.modes[1]);
    eprintln!(
        "A1 {a1:.8} / {:.8} ± {:.1e}, phi1 {phi1:.5} / {:.5} ± {:.1e}, A2 {a2:.7} / {:.7} ± \
         {:.1e}, phi2 {phi2:.5} / {:.5} ± {:.1e}",
        t1.amplitude_ratio.unwrap(),
        t1.amplitude_ratio_std_err.unwrap(),
        t1.phase_deg,
        t1.phase_std_err_deg,
        t2.amplitude_ratio.unwrap(),
        t2.amplitude_ratio_std_err.unwrap(),
        t2.phase_deg,
        t2.phase_std_err_deg
    );
    // the guide and docs/src/explanation/design.md: φ₂ within 8e-5°, A₂ 7e-7, φ₁ 2.6e-4°, A₁ 1.4e-7.
    assert!((a1 - t1.amplitude_ratio.unwrap()).abs() < 2e-7);
    assert!((phi1 - t1.phase_deg).abs() < 3e-4);
    assert!((a2 - t2.amplitude_ratio.unwrap()).abs() < 1e-6);
    assert!((phi2 - t2.phase_deg).abs() < 1e-4);
    for e in [t1.phase_std_err_deg, t2.phase_std_err_deg] {
        assert!(e < 1e-3, "a stated error the march could not check: {e}");
    }
    assert!(t1.amplitude_ratio_std_err.unwrap() < 1e-6);
    assert!(t2.amplitude_ratio_std_err.unwrap() < 1e-5);
}
