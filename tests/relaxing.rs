//! The relaxing (standard-linear-solid) sample against a lever integrated on its own: a
//! velocity-Verlet march, fixed steps, the sample's state advanced exactly along each
//! step's straight-line indentation. Once with Lee & Radok's hereditary integral, as the
//! dynamics run it; once with Ting's receding contact (the contact layer's
//! `RelaxingHalfSpace`), which the dynamics do not run yet.

use std::f64::consts::PI;
use tapsim::contact::viscoelastic::RelaxingHalfSpace;
use tapsim::{LawKind, LawSpec, Numerics, Observe, TapObservables, TapSetup, default_setup, tap};

const EV: f64 = 1.602_176_634e-19;

/// The case: Hertz at E* = 1 GPa, z_c = 12 nm on the default lever.
fn setup(law: LawSpec) -> TapSetup {
    let mut s = TapSetup {
        law,
        separation_m: 12e-9,
        ..default_setup()
    };
    s.contact.modulus_pa = 1e9;
    s
}

fn elastic(modulus_pa: f64) -> TapObservables {
    let mut s = setup(LawKind::Hertz.into());
    s.contact.modulus_pa = modulus_pa;
    tap(&s, &Numerics::default(), Observe::default())
        .unwrap()
        .observables
}

#[derive(Debug, Clone, Copy)]
enum Sample {
    LeeRadok,
    Ting { cells: usize },
}

#[derive(Debug)]
struct Orbit {
    amplitude_ratio: f64,
    phase_deg: f64,
    e_ts_ev: f64,
    most_tensile_n: f64,
}

/// The steady orbit on a sample with unrelaxed modulus 3E* and relaxation time `tau_s`,
/// by velocity Verlet at `steps` a period for `periods` periods (the last one observed,
/// after the amplitude has settled to 1e-7 from one period to the next).
fn reference(tau_s: f64, sample: Sample, steps: usize, periods: usize) -> Orbit {
    let s = setup(LawKind::Hertz.into());
    let (k, q) = (s.cantilever.stiffness_n_m, s.cantilever.quality);
    let (a0, zc) = (s.cantilever.free_amplitude_m, s.separation_m);
    let (radius, e_inf) = (s.contact.radius_m, s.contact.modulus_pa);
    let e0 = 3.0 * e_inf;
    assert_eq!(s.cantilever.drive_frequency_hz, s.cantilever.resonance_hz);
    // Time in τ = ω₀t; the drive F₀ cos τ with F₀ = kA₀/Q.
    let tau_hat = 2.0 * PI * s.cantilever.resonance_hz * tau_s;
    let dt = 2.0 * PI / steps as f64;
    let unit: f64 = 1e-9; // the indentation unit of the half-space
    let force_unit = e_inf * radius.sqrt() * unit.powf(1.5);
    let hertz = |d: f64| 4.0 / 3.0 * radius.sqrt() * d.max(0.0).powf(1.5);
    let mut surface = RelaxingHalfSpace::new(
        2.0,
        tau_hat,
        4.0,
        match sample {
            Sample::Ting { cells } => cells,
            Sample::LeeRadok => 2,
        },
    )
    .unwrap();
    // Lee & Radok's Maxwell arm m (N per unit modulus): dm/dτ = dH/dτ − m/τ̂_r.
    let mut arm = 0.0;
    let force = |surface: &RelaxingHalfSpace, arm: f64, z: f64| {
        let d = -(zc + z);
        match sample {
            Sample::Ting { .. } => force_unit * surface.force_hat(d / unit),
            Sample::LeeRadok if d > 0.0 => e_inf * hertz(d) + (e0 - e_inf) * arm,
            Sample::LeeRadok => 0.0,
        }
    };
    // Start near the tapping orbit (z = 0, going up at 13 nm a radian).
    let (mut z, mut v, mut t): (f64, f64, f64) = (0.0, 13e-9, 0.0);
    let mut f = force(&surface, arm, z);
    let mut previous = f64::NAN;
    let mut orbit = None;
    for period in 0..periods {
        let (mut x_c, mut x_s, mut work, mut most_tensile) = (0.0, 0.0, 0.0, 0.0f64);
        for _ in 0..steps {
            let half = v + 0.5 * dt * ((a0 / q * t.cos() * k + f) / k - z - v / q);
            let z1 = z + dt * half;
            let (d0, d1) = (-(zc + z), -(zc + z1));
            match sample {
                Sample::Ting { .. } => surface
                    .advance(d0.max(-2e-9) / unit, d1.max(-2e-9) / unit, dt)
                    .unwrap(),
                Sample::LeeRadok => {
                    let decay = (-dt / tau_hat).exp();
                    arm = arm * decay + (hertz(d1) - hertz(d0)) / dt * tau_hat * (1.0 - decay);
                }
            }
            let f1 = force(&surface, arm, z1);
            let t1 = t + dt;
            let v1 =
                (half + 0.5 * dt * ((a0 / q * t1.cos() * k + f1) / k - z1)) / (1.0 + 0.5 * dt / q);
            work -= 0.5 * (f + f1) * (z1 - z);
            x_c += 0.5 * (z * t.cos() + z1 * t1.cos()) * dt / PI;
            x_s += 0.5 * (z * t.sin() + z1 * t1.sin()) * dt / PI;
            most_tensile = most_tensile.min(f1);
            (z, v, f, t) = (z1, v1, f1, t1);
        }
        let amplitude = x_c.hypot(x_s);
        if period + 1 == periods {
            assert!(
                ((amplitude - previous) / amplitude).abs() < 1e-7,
                "{sample:?} at τ_r = {tau_s:e} s has not settled: {amplitude:e} after {previous:e}"
            );
            orbit = Some(Orbit {
                amplitude_ratio: amplitude / a0,
                phase_deg: x_s.atan2(x_c).to_degrees(),
                e_ts_ev: work / EV,
                most_tensile_n: most_tensile,
            });
        }
        previous = amplitude;
    }
    let orbit = orbit.unwrap();
    eprintln!("{sample:?}, τ_r = {tau_s:e} s: {orbit:?}");
    orbit
}

/// The dynamics' Lee–Radok orbit is what an independent lever integration of the same
/// model finds, within the reference's own fixed-step resolution (measured: A/A₀ 1.1e-5,
/// φ 0.023°, E_ts 0.3 %, the most tensile force 1e-4 apart; at 2000 steps a period the
/// reference lands 0.008° from φ on the other side: a fixed step meets the contact's
/// onset at a grid point, which shifts the orbit by that much).
#[test]
#[ignore = "release: an independent integration of 1500 periods"]
fn an_independent_lever_finds_the_dynamics_lee_radok_orbit() {
    let law = LawSpec {
        unrelaxed_modulus_pa: Some(3e9),
        relaxation_time_s: Some(1e-7),
        ..LawKind::Hertz.into()
    };
    let o = tap(&setup(law), &Numerics::default(), Observe::default())
        .unwrap()
        .observables;
    let r = reference(1e-7, Sample::LeeRadok, 4000, 1500);
    assert!(
        (r.amplitude_ratio - o.amplitude_ratio).abs() < 3e-5,
        "{r:?}"
    );
    assert!((r.phase_deg - o.phase_deg).abs() < 0.05, "{r:?}");
    assert!((r.e_ts_ev / o.e_ts_ev - 1.0).abs() < 5e-3, "{r:?}");
    assert!(
        (r.most_tensile_n / o.peak_attractive_force_n - 1.0).abs() < 1e-2,
        "{r:?}"
    );
}

/// Ting's receding contact on the same lever: it never pulls, it loses much less than
/// Lee & Radok's integral where τ_r is near the contact time (measured at 100 ns:
/// 26.2 eV against 45.8 eV, φ 44.66° against 47.99°, A/A₀ 0.6516 against 0.6536), and as
/// τ_r → 0 it is the relaxed elastic contact the dynamics find (1e-5 in A/A₀, 0.002° at
/// 10 ps).
#[test]
#[ignore = "release: independent integrations of 1500 periods"]
fn tings_contact_never_pulls_and_loses_less_than_lee_radoks() {
    let lee_radok = reference(1e-7, Sample::LeeRadok, 2000, 1500);
    let ting = reference(1e-7, Sample::Ting { cells: 48 }, 2000, 1500);
    assert!(
        ting.most_tensile_n >= 0.0 && lee_radok.most_tensile_n < -5e-9,
        "{ting:?}"
    );
    assert!(
        ting.e_ts_ev < 0.7 * lee_radok.e_ts_ev,
        "{ting:?} {lee_radok:?}"
    );
    let fast = reference(1e-11, Sample::Ting { cells: 48 }, 2000, 1500);
    let relaxed = elastic(1e9);
    assert!(
        (fast.amplitude_ratio - relaxed.amplitude_ratio).abs() < 3e-5,
        "{fast:?}"
    );
    assert!(
        (fast.phase_deg - relaxed.phase_deg).abs() < 0.05,
        "{fast:?}"
    );
}

/// As τ_r grows the steady orbit does not become the unrelaxed elastic contact: over
/// times long against the retardation time the surface sinks under the mean tapping
/// force, by an amount that does not shrink with τ_r, while the loss falls as 1/τ_r
/// (measured: A/A₀ 0.641870 and 0.641872 at 50 and 100 µs against the unrelaxed
/// contact's 0.638242; the loss 0.0968 and 0.0485 eV).
#[test]
#[ignore = "release: independent integrations of 1500 periods"]
fn a_slowly_relaxing_surface_sinks_under_the_mean_tapping_force() {
    let slow = reference(5e-5, Sample::Ting { cells: 48 }, 2000, 1500);
    let slower = reference(1e-4, Sample::Ting { cells: 48 }, 2000, 1500);
    let unrelaxed = elastic(3e9);
    assert!(
        (slow.amplitude_ratio - slower.amplitude_ratio).abs() < 1e-4,
        "{slow:?} {slower:?}"
    );
    assert!(
        slower.amplitude_ratio > 1.003 * unrelaxed.amplitude_ratio,
        "{slower:?}"
    );
    assert!(
        (slow.e_ts_ev / slower.e_ts_ev - 2.0).abs() < 0.2,
        "{slow:?} {slower:?}"
    );
}

/// The same orbit on Ting's contact by classical Runge–Kutta at `steps` a period, the
/// surface driven through each step as an adaptive integrator would drive it: the
/// stages see [`RelaxingHalfSpace::force_in_step_hat`], the Maxwell mean ŷ integrated
/// with the motion (dŷ/dτ = (δ̂ − ŷ)/τ̂_r), the step closed by `end_step`.
fn runge_kutta_ting(tau_s: f64, cells: usize, steps: usize, periods: usize) -> Orbit {
    let s = setup(LawKind::Hertz.into());
    let (k, q) = (s.cantilever.stiffness_n_m, s.cantilever.quality);
    let (a0, zc) = (s.cantilever.free_amplitude_m, s.separation_m);
    let (radius, e_inf) = (s.contact.radius_m, s.contact.modulus_pa);
    let tau_hat = 2.0 * PI * s.cantilever.resonance_hz * tau_s;
    let dt = 2.0 * PI / steps as f64;
    let unit: f64 = 1e-9;
    let force_unit = e_inf * radius.sqrt() * unit.powf(1.5);
    let mut surface = RelaxingHalfSpace::new(2.0, tau_hat, 4.0, cells).unwrap();
    // (z, z', ŷ) and their rates `elapsed` into the step.
    let rates = |surface: &RelaxingHalfSpace, t: f64, y: [f64; 3], elapsed: f64| {
        let (d, d_rate) = (-(zc + y[0]) / unit, -y[1] / unit);
        let f = force_unit * surface.force_in_step_hat(d, d_rate, y[2], elapsed);
        [
            y[1],
            a0 / q * t.cos() + f / k - y[0] - y[1] / q,
            (d - y[2]) / tau_hat,
        ]
    };
    let plus =
        |y: [f64; 3], r: [f64; 3], h: f64| [y[0] + h * r[0], y[1] + h * r[1], y[2] + h * r[2]];
    let (mut y, mut t): ([f64; 3], f64) = ([0.0, 13e-9, 0.0], 0.0);
    let force_now = |surface: &RelaxingHalfSpace, y: [f64; 3]| {
        force_unit * surface.force_hat(-(zc + y[0]) / unit)
    };
    let mut f = force_now(&surface, y);
    let mut previous = f64::NAN;
    let mut orbit = None;
    for period in 0..periods {
        let (mut x_c, mut x_s, mut work, mut most_tensile) = (0.0, 0.0, 0.0, 0.0f64);
        for _ in 0..steps {
            surface
                .begin_step(-(zc + y[0]) / unit, -y[1] / unit, y[2])
                .unwrap();
            let k1 = rates(&surface, t, y, 0.0);
            let k2 = rates(&surface, t + 0.5 * dt, plus(y, k1, 0.5 * dt), 0.5 * dt);
            let k3 = rates(&surface, t + 0.5 * dt, plus(y, k2, 0.5 * dt), 0.5 * dt);
            let k4 = rates(&surface, t + dt, plus(y, k3, dt), dt);
            let y1: [f64; 3] = std::array::from_fn(|i| {
                y[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
            surface.end_step(-(zc + y1[0]) / unit, -y1[1] / unit, y1[2], dt);
            let f1 = force_now(&surface, y1);
            let t1 = t + dt;
            work -= 0.5 * (f + f1) * (y1[0] - y[0]);
            x_c += 0.5 * (y[0] * t.cos() + y1[0] * t1.cos()) * dt / PI;
            x_s += 0.5 * (y[0] * t.sin() + y1[0] * t1.sin()) * dt / PI;
            most_tensile = most_tensile.min(f1);
            (y, f, t) = (y1, f1, t1);
        }
        let amplitude = x_c.hypot(x_s);
        if period + 1 == periods {
            assert!(
                ((amplitude - previous) / amplitude).abs() < 1e-7,
                "not settled"
            );
            orbit = Some(Orbit {
                amplitude_ratio: amplitude / a0,
                phase_deg: x_s.atan2(x_c).to_degrees(),
                e_ts_ev: work / EV,
                most_tensile_n: most_tensile,
            });
        }
        previous = amplitude;
    }
    let orbit = orbit.unwrap();
    eprintln!("Runge–Kutta on Ting, τ_r = {tau_s:e} s, {steps} steps: {orbit:?}");
    orbit
}

/// Ting's contact driven step by step as the dynamics will drive it (the stages seeing
/// the surface within the step, the step closed after) settles, already at 1000 steps a
/// period, on the orbit of a finer integration and of the fixed-step reference
/// (measured: A/A₀ 0.6516410 at 1000 and 2000 steps a period, 4e-8 apart; φ 44.66573°,
/// 5e-5° apart; the Verlet reference 8e-6 and 0.0023° away).
#[test]
#[ignore = "release: integrations of 1000 and 1500 periods"]
fn tings_contact_driven_step_by_step_settles_on_the_reference_orbit() {
    let coarse = runge_kutta_ting(1e-7, 48, 1000, 1000);
    let fine = runge_kutta_ting(1e-7, 48, 2000, 1000);
    assert!(
        (coarse.amplitude_ratio - fine.amplitude_ratio).abs() < 3e-7,
        "{coarse:?} {fine:?}"
    );
    assert!(
        (coarse.phase_deg - fine.phase_deg).abs() < 3e-4,
        "{coarse:?} {fine:?}"
    );
    assert!(fine.most_tensile_n >= 0.0);
    let verlet = reference(1e-7, Sample::Ting { cells: 48 }, 2000, 1500);
    assert!(
        (verlet.amplitude_ratio - fine.amplitude_ratio).abs() < 3e-5,
        "{verlet:?}"
    );
    assert!(
        (verlet.phase_deg - fine.phase_deg).abs() < 0.05,
        "{verlet:?}"
    );
}
