//! FM-AFM with settled loops (issue 48, the library's first piece): the orbit the
//! phase-locked loop and the amplitude controller hold, checked against the first
//! harmonic of the equation of motion evaluated on the recorded orbit with force laws
//! written here, and the dissipation channel against the law's own loss.

use crate::common;

use std::f64::consts::PI;
use tapsim::analysis::fm::{self, FmState};
use tapsim::analysis::reconstruct::Inversion;
use tapsim::dynamics::observed::TrajectorySample;
use tapsim::dynamics::setup::{Numerics, TapSetup, default_setup};
use tapsim::instrument::thermal::ThermalForce;
use tapsim::law::{Branch, LawKind, LawSpec};

fn setup(law: LawSpec, amplitude_nm: f64) -> TapSetup {
    let mut s = default_setup();
    s.law = law;
    s.cantilever.free_amplitude_m = amplitude_nm * 1e-9;
    s
}

/// The settled states of an approach from `from_nm` to `to_nm` in `n` points, all of
/// which must settle.
fn approach(s: &TapSetup, from_nm: f64, to_nm: f64, n: usize) -> Vec<FmState> {
    let z: Vec<f64> = (0..n)
        .map(|i| (from_nm + (to_nm - from_nm) * i as f64 / (n - 1) as f64) * 1e-9)
        .collect();
    fm::approach(s, &Numerics::default(), &z, || {})
        .unwrap()
        .into_iter()
        .map(|p| {
            p.state
                .unwrap_or_else(|| panic!("{}: {:?}", p.separation_m, p.note))
        })
        .collect()
}

/// Time averages over one recorded period by the trapezoid rule: ⟨F q₁⟩ and the
/// amplitude A of q₁, the deflection's first harmonic at the drive frequency, with
/// `force` the tip–sample force (repulsive positive) at separation α.
fn first_harmonic_virial(
    samples: &[TrajectorySample],
    frequency_hz: f64,
    force: impl Fn(&TrajectorySample) -> f64,
) -> (f64, f64) {
    let w = 2.0 * PI * frequency_hz;
    let period = 1.0 / frequency_hz;
    let integral = |g: &dyn Fn(&TrajectorySample) -> f64| {
        samples
            .windows(2)
            .map(|p| 0.5 * (g(&p[0]) + g(&p[1])) * (p[1].t_s - p[0].t_s))
            .sum::<f64>()
    };
    let end = samples.last().unwrap().t_s;
    assert!((end / period - 1.0).abs() < 1e-9, "{end} vs {period}");
    let a = 2.0 / period * integral(&|s| s.z_m * (w * s.t_s).cos());
    let b = 2.0 / period * integral(&|s| s.z_m * (w * s.t_s).sin());
    let virial = integral(&|s| force(s) * (a * (w * s.t_s).cos() + b * (w * s.t_s).sin())) / period;
    (virial, a.hypot(b))
}

/// Conservative laws from 0.5 to 20 nm of amplitude, in the attractive and the
/// repulsive regime: the settled frequency ratio meets the first harmonic's balance with
/// the drive in quadrature, 1 − Ω² = 2⟨F_ts q₁⟩/(kA²), ⟨F_ts q₁⟩ computed on the recorded
/// orbit with the Hertz and DMT forces written here, within 2e-4 of the shift; where
/// |Δf/f₀| < 1e-3, Giessibl's first-order Δf = −f₀⟨F_ts q₁⟩/(kA²) meets it within 0.1 %.
/// The amplitude held is A.
#[test]
fn conservative_frequency_shifts_meet_the_first_harmonic_balance() {
    let base = default_setup();
    let (r, e, eps) = (
        base.contact.radius_m,
        base.contact.modulus_pa,
        base.contact.range_m,
    );
    let hertz = move |alpha: f64| {
        if alpha < 0.0 {
            4.0 / 3.0 * e * r.sqrt() * (-alpha).powf(1.5)
        } else {
            0.0
        }
    };
    // DMT with its default Hamaker constant 12πε²Δγ: −HR/(6d²), d = α + ε, outside;
    // Hertz minus the pull-off HR/(6ε²) inside.
    let h = 12.0 * PI * eps * eps * base.contact.work_of_adhesion_j_m2;
    let dmt = move |alpha: f64| {
        if alpha > 0.0 {
            -h * r / (6.0 * (alpha + eps).powi(2))
        } else {
            -h * r / (6.0 * eps * eps) + hertz(alpha)
        }
    };
    let k = base.cantilever.stiffness_n_m;
    let f0 = base.cantilever.resonance_hz;
    let mut checked_first_order = 0;
    let (mut worst_balance, mut worst_first_order) = (0f64, 0f64);
    for (kind, amplitude_nm, from, to, force) in [
        (LawKind::Hertz, 0.5, 0.5, 0.2, &hertz as &dyn Fn(f64) -> f64),
        (LawKind::Hertz, 2.0, 2.0, 1.0, &hertz),
        (LawKind::Hertz, 20.0, 20.0, 17.0, &hertz),
        (LawKind::Dmt, 1.0, 2.0, 0.6, &dmt),
        (LawKind::Dmt, 20.0, 21.0, 17.0, &dmt),
    ] {
        let s = setup(kind.into(), amplitude_nm);
        for state in approach(&s, from, to, 8) {
            let at = TapSetup {
                separation_m: state.separation_m,
                ..s.clone()
            };
            let samples = fm::trajectory(&at, &Numerics::default(), &state).unwrap();
            let f = state.frequency_ratio * f0;
            let (virial, a) = first_harmonic_virial(&samples, f, |s| force(s.alpha_m));
            let what = format!(
                "{kind} A = {amplitude_nm} nm at {:.3e} m",
                state.separation_m
            );
            // (The trapezoid rule on the recorded samples resolves A to some 1e-5.)
            assert!(
                (a / s.cantilever.free_amplitude_m - 1.0).abs() < 1e-4,
                "{what}: A {a}"
            );
            let omega_balance = (1.0 - 2.0 * virial / (k * a * a)).sqrt();
            let shift = state.frequency_shift_hz;
            if shift.abs() > 1.0 {
                worst_balance = worst_balance.max(((omega_balance - 1.0) * f0 / shift - 1.0).abs());
            }
            assert!(
                ((omega_balance - 1.0) * f0 - shift).abs() <= 2e-4 * shift.abs() + 1e-6,
                "{what}: Δf {shift} Hz, balance {} Hz",
                (omega_balance - 1.0) * f0
            );
            if shift.abs() < 1e-3 * f0 && shift.abs() > 1.0 {
                let giessibl = -f0 * virial / (k * a * a);
                worst_first_order = worst_first_order.max((giessibl / shift - 1.0).abs());
                assert!(
                    (giessibl / shift - 1.0).abs() < 1e-3,
                    "{what}: Δf {shift} Hz, Giessibl {giessibl} Hz"
                );
                checked_first_order += 1;
            }
        }
    }
    eprintln!(
        "worst: balance {worst_balance:.2e} of Δf, Giessibl {worst_first_order:.2e} over \
         {checked_first_order} points"
    );
    assert!(checked_first_order >= 10, "{checked_first_order}");
}

/// JKR's contact branch, eq. (5), written here: the tensile force T̂ (in units of RΔγ)
/// at separation α̂ on the displacement-stable side, â = s² with s the larger root of
/// s⁴ − √(2π)s + α̂ = 0, found by bisection.
fn jkr_contact_t_hat(alpha_hat: f64) -> f64 {
    let p = (2.0 * PI).sqrt();
    let f = |s: f64| s.powi(4) - p * s + alpha_hat;
    // f is least at s_C = (p/4)^(1/3), the fold; the stable root lies above it.
    let (mut lo, mut hi) = ((p / 4.0).cbrt(), 1.0);
    // (The orbit's sample at the jump-out lies on the fold, to rounding.)
    assert!(f(lo) <= 1e-12, "α̂ = {alpha_hat} is past the fold");
    while f(hi) < 0.0 {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let a = (0.5 * (lo + hi)).powi(2);
    (8.0 * PI * a.powi(3)).sqrt() - 4.0 * a.powi(3) / 3.0
}

/// Hysteresis moves the frequency shift, not only the excitation (Gotsmann & Fuchs,
/// Appl. Phys. A 72, 2001): on the defaults at A = 20 nm, the hybrid law against its
/// reversible twin (`hybrid-reversible`: the same approach branch both ways, letting go
/// of contact at α̂_A instead of holding on to α̂_C). Each law's Δf meets the first
/// harmonic's balance on its own orbit, the force recomputed here from JKR's eq. (5) on
/// the orbit's contact samples (none out of contact), within 2e-4 of the shift; the
/// hybrid's is the lower, by more than 10 Hz and a hundred times that tolerance: the
/// neck it keeps between α̂_A and α̂_C pulls on the way out. The reversible law loses
/// nothing but what the orbit's higher harmonics damp (under 1 % of the hybrid's loop).
#[test]
fn hysteresis_moves_the_frequency_shift() {
    let reversible = LawKind::from_name("hybrid-reversible").unwrap();
    let base = default_setup();
    let (k, f0) = (base.cantilever.stiffness_n_m, base.cantilever.resonance_hz);
    let (alpha_scale, force_scale) = (
        base.contact.separation_scale_m(),
        base.contact.force_scale_n(),
    );
    let force = |s: &TrajectorySample| match s.branch {
        Branch::Contact => -force_scale * jkr_contact_t_hat(s.alpha_m / alpha_scale),
        _ => 0.0,
    };
    let shifts = |kind: LawKind| -> Vec<(f64, f64, FmState)> {
        let s = setup(kind.into(), 20.0);
        approach(&s, 19.5, 17.0, 6)
            .into_iter()
            .map(|state| {
                let at = TapSetup {
                    separation_m: state.separation_m,
                    ..s.clone()
                };
                let samples = fm::trajectory(&at, &Numerics::default(), &state).unwrap();
                let (virial, a) =
                    first_harmonic_virial(&samples, state.frequency_ratio * f0, force);
                let balance = ((1.0 - 2.0 * virial / (k * a * a)).sqrt() - 1.0) * f0;
                let shift = state.frequency_shift_hz;
                eprintln!(
                    "{kind}: balance {:.2e} of Δf",
                    (balance / shift - 1.0).abs()
                );
                assert!(
                    (balance - shift).abs() < 2e-4 * shift.abs(),
                    "{kind} at {:.4e} m: Δf {shift} Hz, balance {balance} Hz",
                    state.separation_m
                );
                (shift, balance, state)
            })
            .collect()
    };
    let hybrid = shifts(LawKind::Hybrid);
    let twin = shifts(reversible);
    for ((h, _, hs), (r, _, rs)) in hybrid.iter().zip(&twin) {
        eprintln!(
            "z_c {:.3} nm: Δf hybrid {h:.3} Hz, reversible {r:.3} Hz, hysteresis {:.3} Hz",
            hs.separation_m * 1e9,
            h - r
        );
        assert!(
            h < r && r - h > 10.0 && r - h > 100.0 * 2e-4 * h.abs(),
            "{h} vs {r}"
        );
        let loss = hs.observables.loop_area_j * hs.observables.jumps_in;
        assert!(rs.e_ts_from_excitation_j.abs() < 1e-2 * loss, "{rs:?}");
    }
}

/// The dissipation channel: on the hybrid law the energy read from the excitation,
/// (πkA²/Q)(F/F₀ − Ω) (Anczykowski et al. 1999), is the law's loop lost per touch
/// within 1e-3 all along an approach; JKR's reads more, by the ratio of the two loops
/// (the paper's point, in an FM instrument's channel). On a conservative law the
/// excitation's rise above Ω is only the damping of the orbit's higher harmonics, which
/// the first-harmonic formula leaves out: E_damp − πkΩA²/Q from the orbit's integrals.
#[test]
fn the_excitation_reads_the_laws_loss_and_jkr_reads_more() {
    // (From 19.5 nm, where JKR, jumping in at contact, touches too.)
    let hybrid = approach(&setup(LawKind::Hybrid.into(), 20.0), 19.5, 17.0, 6);
    let jkr = approach(&setup(LawKind::Jkr.into(), 20.0), 19.5, 17.0, 6);
    for (h, j) in hybrid.iter().zip(&jkr) {
        for s in [h, j] {
            let o = &s.observables;
            let loss = o.loop_area_j * o.jumps_in;
            assert!(loss > 0.0, "{o:?}");
            assert!(
                (s.e_ts_from_excitation_j / loss - 1.0).abs() < 1e-3,
                "{} at {}: {} vs {loss}",
                o.law,
                s.separation_m,
                s.e_ts_from_excitation_j
            );
        }
        let ratio = j.e_ts_from_excitation_j / h.e_ts_from_excitation_j;
        let loops = j.observables.loop_area_j / h.observables.loop_area_j;
        assert!(
            ratio > 1.0 && (ratio / loops - 1.0).abs() < 2e-3,
            "{ratio} vs {loops}"
        );
    }
    let base = default_setup();
    let c = &base.cantilever;
    // At 0.5 nm of amplitude and up to 0.3 nm of indentation the harmonics take up to
    // some 3e-5 of the damping, well above the integration's 1e-8.
    for s in approach(&setup(LawKind::Hertz.into(), 0.5), 0.45, 0.2, 6) {
        let a = 0.5e-9;
        let first = PI * c.stiffness_n_m * s.frequency_ratio * a * a / c.quality;
        let harmonics = s.observables.e_damp_j - first;
        let read = s.e_ts_from_excitation_j;
        assert!(
            (read - harmonics).abs() < 1e-2 * harmonics.abs() + 2e-8 * first,
            "{}: read {read:e}, harmonics' damping {harmonics:e}",
            s.separation_m
        );
    }
}

/// The loops as they run in time (a PLL and an amplitude controller with the default
/// gains for the lever's Q, updated once a period) lock from the free oscillation onto
/// the state `fm::settle` finds directly: on the hybrid defaults at 19 nm and on Hertz
/// at A = 2 nm, 1.5 nm, after 3 000 periods the frequency within 1e-10 of f₀, the
/// excitation within 1e-9, the amplitude and the lag held within 1e-9 and 1e-7° (two
/// methods, one orbit: marching closed loops against Newton's method on the orbit).
#[test]
fn the_loops_in_time_lock_onto_the_settled_state() {
    use tapsim::dynamics::setup::Prepared;
    use tapsim::instrument::fm::{AmplitudeController, PhaseLockedLoop, run};
    for (law, amplitude_nm, z_nm) in [(LawKind::Hybrid, 20.0, 19.0), (LawKind::Hertz, 2.0, 1.5)] {
        let s = TapSetup {
            separation_m: z_nm * 1e-9,
            ..setup(law.into(), amplitude_nm)
        };
        let numerics = Numerics::default();
        let settled = approach(&s, z_nm, z_nm, 2).pop().unwrap();
        let p = Prepared::new(&s, &numerics).unwrap();
        let mut phase = p.simulation().free_steady_start();
        let q = s.cantilever.quality;
        let (mut pll, mut agc) = (
            PhaseLockedLoop::for_quality(q).unwrap(),
            AmplitudeController::for_quality(q).unwrap(),
        );
        let samples = run(
            &p,
            &mut phase,
            (&mut pll, &mut agc, &mut ThermalForce::none()),
            3000,
        )
        .unwrap();
        let last = samples.last().unwrap();
        let what = format!("{law} at {z_nm} nm: {last:?} vs {settled:?}");
        assert!(
            (last.frequency_ratio - settled.frequency_ratio).abs() < 1e-10,
            "{what}"
        );
        assert!(
            (last.excitation_ratio / settled.excitation_ratio - 1.0).abs() < 1e-9,
            "{what}"
        );
        assert!((last.amplitude - 1.0).abs() < 1e-9, "{what}");
        assert!((last.phase_deg - 90.0).abs() < 1e-7, "{what}");
    }
}

/// Gains that make the loops unstable are said to, not turned into numbers; gains that
/// are no gains are refused.
#[test]
fn unstable_or_meaningless_gains_are_refused() {
    use tapsim::dynamics::setup::Prepared;
    use tapsim::instrument::fm::{AmplitudeController, PhaseLockedLoop, run};
    assert!(PhaseLockedLoop::new(-1e-3, 1e-5).is_err());
    assert!(PhaseLockedLoop::new(1e-3, 0.0).is_err());
    assert!(AmplitudeController::new(f64::NAN, 1e-2).is_err());
    let s = TapSetup {
        separation_m: 19e-9,
        ..default_setup()
    };
    let p = Prepared::new(&s, &Numerics::default()).unwrap();
    let mut phase = p.simulation().free_steady_start();
    let (mut pll, mut agc) = (
        PhaseLockedLoop::new(0.5, 0.1).unwrap(),
        AmplitudeController::for_quality(400.0).unwrap(),
    );
    let err = run(
        &p,
        &mut phase,
        (&mut pll, &mut agc, &mut ThermalForce::none()),
        3000,
    )
    .unwrap_err();
    assert!(err.to_string().contains("unstable"), "{err}");
}

/// `tapsim fm` prints what the library settles on: per point Δf, F/F₀ and E_ts from
/// the excitation, which on JKR is the law's loop per touch within 1e-3; a grazing
/// point says so; bad input is refused before any file is written.
#[test]
fn the_fm_command_reports_the_settled_states() {
    let doc = common::json(&[
        "fm", "--law", "jkr", "--from", "20nm", "--to", "17nm", "--points", "7", "--json",
    ]);
    assert_eq!(doc["law"], "jkr");
    let column = |key: &str| -> Vec<serde_json::Value> { doc[key].as_array().unwrap().clone() };
    let (shifts, read, lost) = (
        column("frequency_shift_hz"),
        column("e_ts_from_excitation_j"),
        column("loop_loss_j"),
    );
    assert_eq!(shifts.len(), 7);
    let s = setup(LawKind::Jkr.into(), 20.0);
    let library = approach(&s, 20.0, 17.0, 7);
    for (i, l) in library.iter().enumerate() {
        let df = shifts[i].as_f64().unwrap();
        assert!(
            (df - l.frequency_shift_hz).abs() < 1e-9 * f64::max(1.0, df.abs()),
            "{i}"
        );
        let (read, lost) = (read[i].as_f64().unwrap(), lost[i].as_f64().unwrap());
        assert!((read / lost - 1.0).abs() < 1e-3, "{i}: {read} vs {lost}");
    }
    // The orbit at 20 nm touches 0.4 pm past JKR's jump-in: grazing.
    let grazing = column("grazing");
    assert_eq!(grazing[0], true);
    assert!(grazing[1..].iter().all(|g| *g == false), "{grazing:?}");
    // At a frequency-shift setpoint: the library's state; where the shift jumps across
    // the setpoint (the hybrid law's jump into contact), no number.
    let held = common::json(&["fm", "--setpoint", "-300Hz", "--json"]);
    let z = held["separation_m"].as_f64().unwrap();
    assert!(
        (held["frequency_shift_hz"].as_f64().unwrap() + 300.0).abs() < 3e-7,
        "{held}"
    );
    assert!(z > 20.0e-9 && z < 20.5e-9, "{held}");
    let jump = common::tapsim(&["fm", "--setpoint", "-20Hz"]);
    assert!(!jump.status.success() && jump.stdout.is_empty());
    let said = String::from_utf8_lossy(&jump.stderr);
    assert!(said.contains("jumps across the setpoint"), "{said}");
    let dir = std::env::temp_dir().join(format!("tapsim-fm-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("fm.csv");
    for bad in [
        vec!["fm", "--points", "1"],
        vec!["fm", "--plot", "x.jpg"],
        vec!["fm", "--free-amplitude", "-1nm"],
        vec!["fm", "--law", "nonsense"],
        vec!["fm", "--setpoint", "0.8"],
        // (A relaxing sample's memory is not in the orbit search yet: refused, not
        // reported point by point.)
        vec![
            "fm",
            "--law",
            "hertz",
            "--unrelaxed-modulus",
            "3GPa",
            "--relaxation-time",
            "100ns",
        ],
    ] {
        let mut args = bad.clone();
        args.extend(["--csv", csv.to_str().unwrap()]);
        let out = common::tapsim(&args);
        assert!(!out.status.success(), "{bad:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{bad:?}: {err}");
        assert!(!csv.exists(), "{bad:?} wrote a file");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The DMT force at distance d (m) on the setup's contact with its default Hamaker
/// constant 12πε²Δγ: −HR/(6(d + ε)²) outside, Hertz minus the pull-off HR/(6ε²) inside
/// (N, repulsive positive).
fn dmt_force(s: &TapSetup) -> impl Fn(f64) -> f64 + use<> {
    let (r, e, eps) = (s.contact.radius_m, s.contact.modulus_pa, s.contact.range_m);
    let h = 12.0 * PI * eps * eps * s.contact.work_of_adhesion_j_m2;
    move |d: f64| {
        if d > 0.0 {
            -h * r / (6.0 * (d + eps).powi(2))
        } else {
            -h * r / (6.0 * eps * eps) + 4.0 / 3.0 * e * r.sqrt() * (-d).powf(1.5)
        }
    }
}

/// `tapsim reconstruct --mode fm` on the file `tapsim fm --csv` writes. DMT at A = 20 nm,
/// 650 points from z_c = 30 to 17 nm, the distance taken as an instrument knows it,
/// D = z_c + z̄ − A: the force within 1.5 % of the largest DMT force (written here) at
/// every D farther than 0.2 nm from contact (measured 1.27 %), and within 11 % next to
/// contact (measured 10.3 %, at D = 0.013 nm). There the DMT force changes by 8 nN a
/// nm, and the orbit's higher harmonics move its turning point off z_c + z̄ − A by up to
/// 0.03 nm — the library's inversion with each orbit's own least separation, on a stiff
/// sensor and finer points, is within 1 % there (below); the file has only z_c. With
/// `--inversion first-order` the same: 9.4 % next to contact, 1.24 % beyond. The
/// hybrid law from 19.5 to 17 nm: the loss read from the excitation is the law's loop
/// per touch, as the orbit counts it, within 1e-3. An FM file read as AM, an AM file
/// read as FM, and an FM file without its excitation are refused, naming what is missing.
#[test]
fn reconstruct_inverts_an_fm_curve_from_the_command_line() {
    let dir = common::scratch("fm-reconstruct");
    let csv = dir.join("dmt.csv");
    let path = csv.to_str().unwrap();
    let fm_args = ["fm", "--law", "dmt", "--from", "30nm", "--to", "17nm"];
    let out = common::tapsim(&[&fm_args[..], &["--points", "650", "--csv", path, "-q"]].concat());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let dmt = dmt_force(&setup(LawKind::Dmt.into(), 20.0));
    let column = common::column;
    // The worst error over all D and over those beyond 0.2 nm of contact (where the
    // force is no steeper than 2 N/m), in units of the largest force.
    let errors = |inversion: &str| {
        let v = common::json(&[
            "reconstruct",
            path,
            "--mode",
            "fm",
            "--law",
            "dmt",
            "--inversion",
            inversion,
            "--json",
        ]);
        assert_eq!(v["inversion"], inversion);
        let (d, f) = (column(&v, "closest_m"), column(&v, "force_n"));
        assert_eq!(d.len(), 650);
        assert!(
            d[0] < -2.5e-9 && d[d.len() - 1] > 9e-9,
            "{} {}",
            d[0],
            d[d.len() - 1]
        );
        let largest = d.iter().fold(0.0f64, |m, &d| m.max(dmt(d).abs()));
        let worst_beyond = |from: f64| {
            d.iter()
                .zip(&f)
                .filter(|(d, _)| d.abs() >= from)
                .map(|(&d, &f)| (f - dmt(d)).abs() / largest)
                .fold(0.0f64, f64::max)
        };
        let (worst, away) = (worst_beyond(0.0), worst_beyond(0.2e-9));
        eprintln!(
            "DMT through the files, {inversion}: worst {worst:.2e} of {:.3} nN, {away:.2e} \
             beyond 0.2 nm of contact",
            largest * 1e9
        );
        (worst, away)
    };
    let (worst, away) = errors("sader-jarvis");
    let (worst_exact, away_exact) = errors("first-order");
    assert!(worst < 0.11, "{worst}");
    assert!(away < 0.015, "{away}");
    assert!(worst_exact < 0.1, "{worst_exact}");
    assert!(away_exact < 0.015, "{away_exact}");
    // The hybrid law's loss.
    let hybrid = dir.join("hybrid.csv");
    let out = common::tapsim(&[
        "fm",
        "--from",
        "19.5nm",
        "--to",
        "17nm",
        "--points",
        "6",
        "--csv",
        hybrid.to_str().unwrap(),
        "-q",
    ]);
    assert!(out.status.success());
    let mut reader = csv::Reader::from_path(&hybrid).unwrap();
    let headers = reader.headers().unwrap().clone();
    let at = |name: &str| headers.iter().position(|h| h == name).unwrap();
    let (z_col, loss_col) = (at("separation_m"), at("loop_loss_j"));
    let loops: Vec<(f64, f64)> = reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            (r[z_col].parse().unwrap(), r[loss_col].parse().unwrap())
        })
        .collect();
    let v = common::json(&[
        "reconstruct",
        hybrid.to_str().unwrap(),
        "--mode",
        "fm",
        "--json",
    ]);
    let (z, e) = (column(&v, "separation_m"), column(&v, "e_ts_j"));
    assert_eq!(z.len(), loops.len());
    for (z, e) in z.iter().zip(&e) {
        let (_, loss) = loops
            .iter()
            .find(|(at, _)| (at - z).abs() < 1e-15)
            .unwrap_or_else(|| panic!("{z}"));
        assert!(
            *loss > 0.0 && (e / loss - 1.0).abs() < 1e-3,
            "{z}: {e} vs {loss}"
        );
    }
    // Refusals.
    let am = dir.join("am.csv");
    let out = common::tapsim(&[
        "approach",
        "--points",
        "5",
        "--no-retract",
        "--csv",
        am.to_str().unwrap(),
        "-q",
    ]);
    assert!(out.status.success());
    common::refused(
        &["reconstruct", am.to_str().unwrap(), "--mode", "fm"],
        "needs the frequency shift",
    );
    common::refused(&["reconstruct", path], "this is an FM curve: --mode fm");
    common::refused(&["fit", path], "fit reads AM curves");
    let bare = dir.join("bare.csv");
    std::fs::write(&bare, "z_nm,df_hz\n30,-1\n25,-2\n20,-5\n").unwrap();
    common::refused(
        &["reconstruct", bare.to_str().unwrap(), "--mode", "fm"],
        "excitation over its free value",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Sader–Jarvis on a simulated FM approach of the DMT law (A = 20 nm, 2 601 points
/// 0.005 nm apart from z_c = 30 to 17 nm: least separations from 10 nm out of contact to
/// 3 nm into it) recovers the law's force, written here, within 1 % of the largest force
/// (the adhesion, 12.56 nN) at every distance the orbits reach: measured 0.73 %, the
/// worst at the kink of the DMT force at contact; the first-order relation inverted
/// exactly does better, 0.06 %. Checked independently of the dynamics: the shift a pure
/// cosine reads (the law's quadrature) inverted by the formula errs by 0.73 %, by the
/// exact inverse by 0.04 %. The sensor is a stiff one (k = 1 800 N/m, qPlus-like, as FM
/// force spectroscopy uses): both inversions rest on the first-order relation, which
/// needs the force's gradient (83 N/m just outside contact) well below k. On the
/// built-in 40 N/m lever the orbit's own distortion breaks it: the exact inverse then
/// errs by 1.35 % at the kink, the formula by 1.1 %; and at 0.02 nm spacing the
/// formula's own error is 1.3 %.
#[test]
fn sader_jarvis_recovers_the_dmt_force_from_an_fm_approach() {
    let mut s = setup(LawKind::Dmt.into(), 20.0);
    s.cantilever.stiffness_n_m = 1800.0;
    let states = approach(&s, 30.0, 17.0, 2601);
    let by = |inversion| fm::force_from_shift(&s, &states, inversion).unwrap();
    let (formula, exact) = (by(Inversion::SaderJarvis), by(Inversion::FirstOrder));
    let dmt = dmt_force(&s);
    let ds: Vec<f64> = formula.iter().map(|p| p.0).collect();
    let largest = ds.iter().fold(0.0f64, |m, &d| m.max(dmt(d).abs()));
    let worst = |f: &mut dyn Iterator<Item = f64>| {
        ds.iter()
            .zip(f)
            .map(|(&d, f)| (f - dmt(d)).abs() / largest)
            .fold(0.0f64, f64::max)
    };
    let simulated = worst(&mut formula.iter().map(|p| p.1));
    let inverted = worst(&mut exact.iter().map(|p| p.1));
    // The shift a pure cosine z = D + A(1 + cos θ) reads: −⟨F A cos θ⟩/(kA²), by the
    // midpoint rule over θ (fine enough to cross the kink).
    let (a, k) = (20e-9, s.cantilever.stiffness_n_m);
    let shift: Vec<f64> = ds
        .iter()
        .map(|&d| {
            let n = 20_000;
            let sum = (0..n)
                .map(|i| {
                    let t = 2.0 * PI * (f64::from(i) + 0.5) / f64::from(n);
                    dmt(d + a * (1.0 + t.cos())) * a * t.cos()
                })
                .sum::<f64>()
                / f64::from(n);
            -sum / (k * a * a)
        })
        .collect();
    let amplitude = vec![a; ds.len()];
    let cosine =
        |inversion: Inversion| worst(&mut inversion.force(k, &ds, &amplitude, &shift).into_iter());
    let (formula_cosine, exact_cosine) = (
        cosine(Inversion::SaderJarvis),
        cosine(Inversion::FirstOrder),
    );
    eprintln!(
        "{} distances from {:.3} to {:.3} nm: worst error of {:.3} nN by Sader–Jarvis \
         {simulated:.2e} (on a pure cosine {formula_cosine:.2e}), by the first-order \
         inverse {inverted:.2e} (on a pure cosine {exact_cosine:.2e})",
        ds.len(),
        ds[0] * 1e9,
        ds[ds.len() - 1] * 1e9,
        largest * 1e9
    );
    assert!(ds[0] < -2.5e-9 && ds[ds.len() - 1] > 9e-9);
    assert!(simulated < 0.01, "{simulated}");
    assert!(inverted < 0.002, "{inverted}");
    assert!(formula_cosine < 0.01, "{formula_cosine}");
    assert!(exact_cosine < 0.002, "{exact_cosine}");
}

/// Apparent dissipation (Nony et al., Phys. Rev. B 74, 235439, 2006): approaching a
/// conservative sample (Hertz, A = 20 nm, z_c from 21 to 17 nm in 2 000 periods, 6.7 ms
/// at 300 kHz) under loops, the dissipation channel (F/F₀ − Ω, in units of the free
/// damping per cycle) reads a loss that is not there where the loops lag: a PLL that
/// lags leaves the drive off resonance, and the amplitude controller makes up the
/// amplitude with excitation. With the default gains it stays below 1 % of the free
/// damping all along (measured 0.17 %, the harmonics' real share included); with a PLL a
/// hundred times slower it reads some 45 %. An amplitude controller a hundred times
/// slower does not (0.15 %): on a conservative sample the drive stays at resonance, so
/// the amplitude holds at the free excitation and there is nothing for its lag to add —
/// the lag that reads as loss is the PLL's (issue 48 names the amplitude controller; on
/// this approach it is not the culprit).
#[test]
fn slow_loops_read_a_dissipation_that_is_not_there() {
    use tapsim::dynamics::setup::Prepared;
    use tapsim::instrument::fm::{AmplitudeController, PhaseLockedLoop, run_along};
    let s = TapSetup {
        separation_m: 21e-9,
        ..setup(LawKind::Hertz.into(), 20.0)
    };
    let q = s.cantilever.quality;
    let p = Prepared::new(&s, &Numerics::default()).unwrap();
    let n = 2_000;
    let z: Vec<f64> = (0..n)
        .map(|i| 21e-9 - 4e-9 * i as f64 / (n - 1) as f64)
        .collect();
    let apparent = |mut pll: PhaseLockedLoop, mut agc: AmplitudeController| {
        let mut phase = p.simulation().free_steady_start();
        let samples = run_along(
            &p,
            &mut phase,
            (&mut pll, &mut agc, &mut ThermalForce::none()),
            &z,
        )
        .unwrap();
        // The harmonics' damping is a real rise of the excitation on Hertz (3e-5 at
        // most here, see above): what exceeds it is the loops' lag.
        samples
            .iter()
            .map(|x| x.dissipation_read().abs())
            .fold(0.0f64, f64::max)
    };
    let (pll, agc) = (
        || PhaseLockedLoop::for_quality(q).unwrap(),
        || AmplitudeController::for_quality(q).unwrap(),
    );
    let default = apparent(pll(), agc());
    let slow = apparent(
        PhaseLockedLoop::new(0.01 / q, 0.08 / (q * q)).unwrap(),
        agc(),
    );
    let slow_agc = apparent(pll(), AmplitudeController::new(0.02, 0.16 / q).unwrap());
    eprintln!(
        "apparent dissipation: default gains {default:.2e}, slow PLL {slow:.2e}, slow \
         amplitude controller {slow_agc:.2e} of the free"
    );
    assert!(default < 0.01, "{default}");
    assert!(slow > 0.01, "{slow}");
    assert!(slow_agc < 0.01, "{slow_agc}");
}

/// The state at a frequency-shift setpoint: on the hybrid defaults −300 Hz is first met on
/// the way in between the approach's points at 20.5 and 20 nm (Δf −270 and −350 Hz);
/// the state found there holds it to 1e-9 and lies where the approach's own settled
/// states put it (a fine approach brackets its z_c); a setpoint never reached is refused
/// with the shift that was.
#[test]
fn the_state_at_a_frequency_shift_setpoint_is_on_the_approach() {
    let s = default_setup();
    let n = Numerics::default();
    let state = fm::at_shift(&s, &n, -300.0, (24e-9, 8e-9), 32).unwrap();
    assert!((state.frequency_shift_hz + 300.0).abs() < 3e-7, "{state:?}");
    let z = state.separation_m;
    assert!(z < 20.5e-9 && z > 20.0e-9, "{z}");
    // A fine approach across it: the shift passes −300 Hz between the neighbours of z.
    let around = approach(&s, z * 1e9 + 0.01, z * 1e9 - 0.01, 3);
    let (above, below) = (around[0].frequency_shift_hz, around[2].frequency_shift_hz);
    assert!((above + 300.0) * (below + 300.0) < 0.0, "{above} {below}");
    let err = fm::at_shift(&s, &n, -5000.0, (24e-9, 8e-9), 32).unwrap_err();
    assert!(err.to_string().contains("not reached"), "{err}");
    assert!(fm::at_shift(&s, &n, f64::NAN, (24e-9, 8e-9), 32).is_err());
}

/// The thermal force through the loops: the frequency noise Albrecht et al. (J. Appl.
/// Phys. 69, 668, 1991) give for a self-excited cantilever, δf = √(f₀k_BT·B/(πkA²Q)) in
/// a bandwidth B. The free cantilever at 300 K under the default loops for 10⁶ periods,
/// its frequency averaged over blocks of N periods (B = 1/(2T), T a block's duration)
/// as the cantilever's own phase advanced (the PLL's drive phase less the lag it reads
/// at the block's two ends). Over N = 2000 periods (B = 75 Hz, far below the loops'
/// bandwidth) the spread of 500 blocks is the formula's within 10 % (the spread of 500
/// draws is itself uncertain by 3.2 %). Over N = 125 (B = 1.2 kHz, the resonator's own
/// time, Q/π periods) it is well below, under 0.92 of it: there the drive, moved by the
/// PLL, still pulls the cantilever's phase back, which the free self-oscillator of the
/// formula does not.
#[test]
#[ignore = "slow (10⁶ periods under the thermal force, about 30 s in release): cargo test --release -- --ignored fm::"]
fn the_plls_thermal_frequency_noise_is_albrechts() {
    use tapsim::dynamics::setup::Prepared;
    use tapsim::instrument::fm::{AmplitudeController, PhaseLockedLoop, run};
    use tapsim::instrument::thermal::{STEPS_PER_PERIOD, intensity_hat};
    let s = setup(LawKind::None.into(), 20.0);
    let c = &s.cantilever;
    let (k, q, f0, a) = (
        c.stiffness_n_m,
        c.quality,
        c.resonance_hz,
        c.free_amplitude_m,
    );
    let temperature = 300.0;
    let p = Prepared::new(&s, &Numerics::default()).unwrap();
    let mut phase = p.simulation().free_steady_start();
    let (mut pll, mut agc) = (
        PhaseLockedLoop::for_quality(q).unwrap(),
        AmplitudeController::for_quality(q).unwrap(),
    );
    let mut force = ThermalForce::new(
        intensity_hat(temperature, k, q, a),
        STEPS_PER_PERIOD,
        20_261_129,
        0,
    )
    .unwrap();
    let (periods, warm) = (1_000_000, 2000);
    let samples = run(
        &p,
        &mut phase,
        (&mut pll, &mut agc, &mut force),
        warm + periods + 1,
    )
    .unwrap();
    let samples = &samples[warm..];
    // The spread of the block means over Albrecht's δf in their bandwidth.
    let ratio = |n: usize| -> f64 {
        let blocks = periods / n;
        let means: Vec<f64> = (0..blocks)
            .map(|b| {
                let block = &samples[b * n..=(b + 1) * n];
                let duration: f64 = block[..n]
                    .iter()
                    .map(|s| 1.0 / (s.frequency_ratio * f0))
                    .sum();
                let slip = (block[n].phase_deg - block[0].phase_deg) / 360.0;
                (n as f64 - slip) / duration
            })
            .collect();
        let mean = means.iter().sum::<f64>() / blocks as f64;
        let spread =
            (means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (blocks - 1) as f64).sqrt();
        let bandwidth = mean / (2.0 * n as f64);
        let kt = 1.380_649e-23 * temperature;
        let albrecht = (f0 * kt * bandwidth / (PI * k * a * a * q)).sqrt();
        eprintln!(
            "N = {n}: δf in B = {bandwidth:.1} Hz {spread:.4e} Hz, Albrecht {albrecht:.4e} Hz \
             ({:.4}), over {blocks} blocks",
            spread / albrecht
        );
        spread / albrecht
    };
    let slow = ratio(2000);
    assert!((slow - 1.0).abs() < 0.1, "{slow}");
    let fast = ratio(125);
    assert!(fast < 0.92, "{fast}");
}

/// A PLL whose centre frequency is not the cantilever's resonance (f₀ mismatch): within
/// its capture range (here 600 Hz, about a linewidth f₀/(2Q)) it locks onto the same
/// orbit all the same — the frequency within 1e-10 of the settled one, the integral
/// term taking up the offset, so Δf counted from the wrong centre is off by exactly the
/// mismatch; 3 kHz off it cannot capture, and the run says so (the lag leaves
/// (0°, 180°)) instead of returning what a drifting loop read.
#[test]
fn a_pll_off_the_resonance_locks_or_says_it_lost_lock() {
    use tapsim::dynamics::setup::Prepared;
    use tapsim::instrument::fm::{AmplitudeController, PhaseLockedLoop, run};
    let s = TapSetup {
        separation_m: 19e-9,
        ..setup(LawKind::Hybrid.into(), 20.0)
    };
    let settled = approach(&s, 19.0, 19.0, 2).pop().unwrap();
    let p = Prepared::new(&s, &Numerics::default()).unwrap();
    let q = s.cantilever.quality;
    let march = |mismatch: f64| {
        let mut phase = p.simulation().free_steady_start();
        let (mut pll, mut agc) = (
            PhaseLockedLoop::for_quality(q).unwrap(),
            AmplitudeController::for_quality(q).unwrap(),
        );
        pll.centre = 1.0 + mismatch;
        run(
            &p,
            &mut phase,
            (&mut pll, &mut agc, &mut ThermalForce::none()),
            4000,
        )
    };
    let near = march(2e-3).unwrap();
    let last = near.last().unwrap();
    assert!(
        (last.frequency_ratio - settled.frequency_ratio).abs() < 1e-10,
        "{last:?} vs {settled:?}"
    );
    let far = march(1e-2).unwrap_err().to_string();
    assert!(far.contains("lost lock") && far.contains("centre"), "{far}");
}

#[test]
fn fm_under_the_thermal_force_reads_the_settled_state_in_the_cold_and_albrechts_noise_when_free() {
    use common::column;
    // Far from the sample (22 nm) and on the hybrid contact (19 nm).
    let head = [
        "fm", "--from", "22nm", "--to", "19nm", "--points", "2", "--json", "-q",
    ];
    let cold = common::json_of(&head, &["--temperature", "0.001K"]);
    let (df, df_cold, se_cold) = (
        column(&cold, "frequency_shift_hz"),
        column(&cold, "thermal_frequency_shift_hz"),
        column(&cold, "thermal_frequency_shift_std_err_hz"),
    );
    let (e, e_cold) = (
        column(&cold, "e_ts_from_excitation_j"),
        column(&cold, "thermal_e_ts_j"),
    );
    // The limit: the loops marched in time hold what Newton's method settles.
    for i in 0..2 {
        eprintln!(
            "0.001 K: Δf {} vs {} (± {}), E_ts {:e} vs {:e}",
            df_cold[i], df[i], se_cold[i], e_cold[i], e[i]
        );
        assert!((df_cold[i] - df[i]).abs() < 1e-3 && se_cold[i] < 1e-3);
        assert!((e_cold[i] - e[i]).abs() < 1e-5 * e[1]);
    }
    // Free at 300 K: the mean shift is none within its error, and the error is the
    // frequency noise Albrecht et al. (1991) give for one record's averaging time
    // (B = f₀/(2N), N = 2 500 periods), over √8 records: 8 records spread their
    // standard error by ±25 % (χ² of 7), hence the band.
    let warm = common::json_of(&head, &["--temperature", "300K"]);
    let (m, se) = (
        column(&warm, "thermal_frequency_shift_hz")[0],
        column(&warm, "thermal_frequency_shift_std_err_hz")[0],
    );
    let (f0, k, a, q, kt) = (300e3, 40.0, 20e-9, 400.0, 1.380649e-23 * 300.0);
    let b = f0 / (2.0 * 2500.0);
    let albrecht = (f0 * kt * b / (PI * k * a * a * q)).sqrt() / 8f64.sqrt();
    eprintln!("300 K, free: Δf {m} ± {se} Hz; Albrecht's over 8 records {albrecht}");
    assert!(m.abs() < 4.0 * se);
    assert!(
        se > 0.45 * albrecht && se < 1.6 * albrecht,
        "{se} vs {albrecht}"
    );
    // Each point draws its own noise.
    let seeds = warm["thermal_seed"].as_array().unwrap();
    assert_ne!(seeds[0], seeds[1]);
}
