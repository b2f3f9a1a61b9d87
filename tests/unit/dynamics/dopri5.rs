//! Tests of `tapsim::dynamics::dopri5` (src/dynamics/dopri5.rs).

use tapsim::dynamics::dopri5::*;
use tapsim::dynamics::model::BASE;
use tapsim::dynamics::model::State;

/// A damped, driven Duffing oscillator in the first two components and quadratures of
/// it in the next five (which the stages skip, [`System::QUADRATURES`]), every accepted
/// step recorded.
struct Duffing(Vec<(f64, State<BASE>)>);

impl System<BASE> for Duffing {
    const QUADRATURES: std::ops::Range<usize> = 2..7;
    fn system(&self, t: f64, y: &State<BASE>, dy: &mut State<BASE>) {
        *dy = State::zeros();
        dy[0] = y[1];
        dy[1] = -0.1 * y[1] - y[0] - 0.5 * y[0] * y[0] * y[0] + 0.3 * (1.2 * t).cos();
        dy[2] = y[1] * y[1];
        dy[3] = y[0] * (1.2 * t).cos();
        dy[4] = y[0] * (1.2 * t).sin();
        dy[5] = y[0] * y[0] * y[0];
        dy[6] = y[0] * y[1];
    }
    fn solout(&mut self, t: f64, y: &State<BASE>, _: &State<BASE>) -> bool {
        self.0.push((t, *y));
        false
    }
}

impl ode_solvers::dop_shared::System<f64, State<BASE>> for Duffing {
    fn system(&self, t: f64, y: &State<BASE>, dy: &mut State<BASE>) {
        System::system(self, t, y, dy);
    }
}

#[test]
fn steps_as_ode_solvers_dopri5_does_to_the_last_bit() {
    let mut y0 = State::<BASE>::zeros();
    y0[0] = 1.0;
    for (rtol, h0) in [(1e-9, 0.0), (1e-6, 0.0), (1e-8, 0.05)] {
        let settings = Settings {
            rtol,
            atol: 1e-2 * rtol,
            h_max: 0.3,
            h0,
            max_steps: 100_000,
        };
        let mut ours = Duffing(Vec::new());
        let stats = integrate(&mut ours, 0.0, 30.0, y0, &settings).unwrap();
        let mut theirs = ode_solvers::dopri5::Dopri5::from_param(
            Duffing(Vec::new()),
            0.0,
            30.0,
            0.0,
            y0,
            rtol,
            1e-2 * rtol,
            SAFETY,
            BETA,
            FAC_MIN,
            FAC_MAX,
            0.3,
            h0,
            100_000,
            u32::MAX,
            ode_solvers::dop_shared::OutputType::Sparse,
        );
        let their_stats = theirs.integrate().unwrap();
        assert_eq!(stats.accepted_steps, their_stats.accepted_steps);
        assert_eq!(stats.rejected_steps, their_stats.rejected_steps);
        // Theirs records the start too.
        let (t, y) = (theirs.x_out(), theirs.y_out());
        assert_eq!(ours.0.len() + 1, t.len());
        for (k, (tk, yk)) in ours.0.iter().enumerate() {
            assert_eq!(tk.to_bits(), t[k + 1].to_bits(), "rtol {rtol}, step {k}");
            assert_eq!(yk, &y[k + 1], "rtol {rtol}, step {k}");
        }
    }
}

#[test]
fn a_harmonic_oscillator_keeps_to_its_closed_form() {
    struct Harmonic;
    impl System<BASE> for Harmonic {
        fn system(&self, _: f64, y: &State<BASE>, dy: &mut State<BASE>) {
            *dy = State::zeros();
            dy[0] = y[1];
            dy[1] = -y[0];
        }
    }
    let mut y0 = State::<BASE>::zeros();
    y0[0] = 1.0;
    let settings = Settings {
        rtol: 1e-10,
        atol: 1e-12,
        h_max: 1.0,
        h0: 0.0,
        max_steps: 100_000,
    };
    let mut end = y0;
    struct Last<'a>(&'a mut State<BASE>);
    impl System<BASE> for Last<'_> {
        fn system(&self, t: f64, y: &State<BASE>, dy: &mut State<BASE>) {
            Harmonic.system(t, y, dy);
        }
        fn solout(&mut self, _: f64, y: &State<BASE>, _: &State<BASE>) -> bool {
            *self.0 = *y;
            false
        }
    }
    integrate(&mut Last(&mut end), 0.0, 10.0, y0, &settings).unwrap();
    assert!((end[0] - 10f64.cos()).abs() < 1e-8, "{}", end[0]);
    assert!((end[1] + 10f64.sin()).abs() < 1e-8, "{}", end[1]);
}
