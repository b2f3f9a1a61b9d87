//! Closed-form motion of the force-driven, underdamped oscillator while the tip feels no
//! force: x'' + 2γx' + x = f₀ cos Ωτ + b, b a constant force (the thermal force over
//! one of its steps; usually 0). Exact, so free flight costs no integration steps, and
//! so are the carried integrals. Under a base drive (the support moving as B cos Ωτ, no
//! drive force: f₀ = 0) the deflection rings freely and the separation follows
//! x + B cos Ωτ, whose fall to the jump-in ends the flight (`FreeFlight::separation`);
//! on a ramp's leg (the support moving at a constant speed u) it is x + p + uτ.

use super::model::{Carried, Drive, Oscillator, SECTION_DIM, State, V, X, has_tangent, phi_column};
use crate::numeric::newton_bracketed;
use nalgebra::{Complex, Matrix2};

/// What [`FreeFlight::first_fall_to`] found.
#[derive(Debug, Clone, Copy, PartialEq)]
#[doc(hidden)]
pub struct Fall {
    /// When x falls to the level, if it does.
    pub hit: Option<f64>,
    /// The lowest x met (the level, if it is hit).
    pub min_x: f64,
    /// The lowest turning point (x' rising through 0) before the hit (∞: none).
    pub lowest_turn: f64,
    /// The highest turning point (x' falling through 0) before the hit (−∞: none).
    pub highest_turn: f64,
}

/// The free motion from a given state.
#[derive(Debug, Clone, Copy)]
pub struct FreeFlight {
    tau0: f64,
    /// Particular solution a cos Ωτ + b sin Ωτ + bias.
    a: f64,
    b: f64,
    bias: f64,
    /// Transient e^{−γs}(c1 cos ω_d s + c2 sin ω_d s), s = τ − τ₀.
    c1: f64,
    c2: f64,
    gamma: f64,
    omega_d: f64,
    omega: f64,
    f0: f64,
    /// The support's amplitude B under a base drive (0 under a force drive).
    base: f64,
    /// The support's (p, u) on a ramp's leg, x_b = p + uτ ((0, 0) otherwise); part of
    /// the particular solution only in the separation ([`FreeFlight::separation`]).
    line: (f64, f64),
    /// Whether this is the separation x + B cos Ωτ of a base-driven flight, not the
    /// deflection.
    shifted: bool,
}

/// (e^z − 1)/z, accurate also for small |z|.
fn exprel(z: Complex<f64>) -> Complex<f64> {
    if z.norm() < 1e-3 {
        // 1 + z/2 + z²/6 + z³/24 + z⁴/120: error below 1e-18.
        Complex::new(1.0, 0.0) + z * (0.5 + z * (1.0 / 6.0 + z * (1.0 / 24.0 + z / 120.0)))
    } else {
        (z.exp() - 1.0) / z
    }
}

impl FreeFlight {
    /// The free motion through (`tau0`, `x0`, `v0`); `None` unless the oscillator is
    /// underdamped.
    pub fn new(osc: &Oscillator, tau0: f64, x0: f64, v0: f64) -> Option<Self> {
        let (f0, base, ramp) = match osc.drive {
            Drive::Force { amplitude } => (amplitude, 0.0, (0.0, 0.0)),
            Drive::Base { amplitude } => (0.0, amplitude, (0.0, 0.0)),
            Drive::Ramp { position, speed } => (0.0, 0.0, (position, speed)),
        };
        if !osc.underdamped() {
            return None;
        }
        let w = osc.omega;
        let det = (1.0 - w * w).powi(2) + (2.0 * osc.gamma * w).powi(2);
        let a = f0 * (1.0 - w * w) / det;
        let b = f0 * 2.0 * osc.gamma * w / det;
        let (s, c) = (w * tau0).sin_cos();
        let xp = a * c + b * s;
        let vp = w * (-a * s + b * c);
        let omega_d = (1.0 - osc.gamma * osc.gamma).sqrt();
        let c1 = x0 - xp - osc.bias;
        let c2 = (v0 - vp + osc.gamma * c1) / omega_d;
        Some(Self {
            tau0,
            a,
            b,
            bias: osc.bias,
            c1,
            c2,
            gamma: osc.gamma,
            omega_d,
            omega: w,
            f0,
            base,
            line: ramp,
            shifted: false,
        })
    }

    /// The separation coordinate x + x_b of this flight (x itself under a force drive):
    /// the same form with the support's B cos Ωτ (or a ramp's p + uτ) added to the
    /// particular part, for the fall to a switch level and the turning points the
    /// grazing margins measure.
    #[doc(hidden)]
    pub fn separation(&self) -> Self {
        if self.base == 0.0 && self.line == (0.0, 0.0) {
            return *self;
        }
        Self {
            a: self.a + self.base,
            base: 0.0,
            shifted: true,
            ..*self
        }
    }

    /// The ramp's share of the particular part at τ, (p + uτ, u), in the separation.
    #[inline]
    fn line_at(&self, tau: f64) -> (f64, f64) {
        if self.shifted {
            (self.line.0 + self.line.1 * tau, self.line.1)
        } else {
            (0.0, 0.0)
        }
    }

    /// The steady free response (a, b) for a force drive: x = a cos Ωτ + b sin Ωτ.
    pub fn steady(osc: &Oscillator) -> Option<(f64, f64)> {
        Self::new(osc, 0.0, 0.0, 0.0).map(|f| (f.a, f.b))
    }

    /// Deflection and velocity at τ.
    #[inline]
    pub fn at(&self, tau: f64) -> (f64, f64) {
        let t = tau - self.tau0;
        self.combine(
            tau,
            (self.omega * tau).sin_cos(),
            (self.omega_d * t).sin_cos(),
            (-self.gamma * t).exp(),
        )
    }

    /// (x, x') at τ from the drive phasor (sin Ωτ, cos Ωτ), the transient's phasor
    /// (sin ω_d s, cos ω_d s) and its decay e^{−γs}.
    #[inline]
    fn combine(&self, tau: f64, (s, c): (f64, f64), (sd, cd): (f64, f64), e: f64) -> (f64, f64) {
        let (p, u) = self.line_at(tau);
        let (x_p, v_p) = (
            self.a * c + self.b * s + self.bias + p,
            self.omega * (-self.a * s + self.b * c) + u,
        );
        let x_h = e * (self.c1 * cd + self.c2 * sd);
        let v_h = e
            * ((-self.gamma * self.c1 + self.omega_d * self.c2) * cd
                + (-self.gamma * self.c2 - self.omega_d * self.c1) * sd);
        (x_p + x_h, v_p + v_h)
    }

    /// (x, x') at τ_a + k·h for k = 0, 1, 2, …, by rotating the phasors of both parts
    /// instead of calling sin, cos and exp at every sample.
    #[doc(hidden)]
    pub fn samples(&self, tau_a: f64, h: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        let t = tau_a - self.tau0;
        let (mut s, mut c) = (self.omega * tau_a).sin_cos();
        let (mut sd, mut cd) = (self.omega_d * t).sin_cos();
        let mut e = (-self.gamma * t).exp();
        let (rs, rc) = (self.omega * h).sin_cos();
        let (rsd, rcd) = (self.omega_d * h).sin_cos();
        let decay = (-self.gamma * h).exp();
        let mut k = 0.0;
        std::iter::from_fn(move || {
            let sample = self.combine(tau_a + k * h, (s, c), (sd, cd), e);
            k += 1.0;
            (s, c) = (s * rc + c * rs, c * rc - s * rs);
            (sd, cd) = (sd * rcd + cd * rsd, cd * rcd - sd * rsd);
            e *= decay;
            Some(sample)
        })
    }

    /// Velocity and acceleration at τ: from the equation of motion for the deflection;
    /// for a separation under a base drive or a ramp ([`FreeFlight::separation`]), the particular
    /// part's −Ω²(a cos Ωτ + b sin Ωτ) and the transient's, which obeys the free
    /// equation (h'' = −2γh' − h).
    #[inline]
    #[doc(hidden)]
    pub fn velocity_and_acceleration(&self, tau: f64) -> (f64, f64) {
        let (x, v) = self.at(tau);
        if !self.shifted {
            return (
                v,
                self.f0 * (self.omega * tau).cos() + self.bias - 2.0 * self.gamma * v - x,
            );
        }
        let (s, c) = (self.omega * tau).sin_cos();
        let particular = self.a * c + self.b * s;
        let (p, u) = self.line_at(tau);
        let (x_h, v_h) = (
            x - particular - self.bias - p,
            v - self.omega * (-self.a * s + self.b * c) - u,
        );
        (
            v,
            -self.omega * self.omega * particular - 2.0 * self.gamma * v_h - x_h,
        )
    }

    /// Advance `y` (deflection, velocity and the carried integrals) from `tau_a` to
    /// `tau_b`, all in closed form: the Fourier projections are integrals of exponentials,
    /// the drive's work follows from them by parts, ∫ f₀ cos Ωτ x' dτ =
    /// f₀([x cos Ωτ] + Ω ∫ x sin Ωτ dτ), a constant force's is b[x], and damping takes the
    /// rest of the energy balance (the tip feels no force). The tip–sample integrals do not change. The variational
    /// matrix of a state with a tangent ([`super::model::has_tangent`]) is carried by
    /// [`FreeFlight::transition`].
    #[doc(hidden)]
    pub fn advance<const N: usize>(&self, y: &mut State<N>, tau_a: f64, tau_b: f64) {
        let (sc, ss) = self.fourier(tau_a, tau_b);
        let (x_a, v_a) = self.at(tau_a);
        let (x_b, v_b) = self.at(tau_b);
        let drive = self.f0
            * (x_b * (self.omega * tau_b).cos() - x_a * (self.omega * tau_a).cos()
                + self.omega * ss);
        let mechanical = 0.5 * (x_b * x_b + v_b * v_b) - 0.5 * (x_a * x_a + v_a * v_a);
        y[X] = x_b;
        y[V] = v_b;
        y[Carried::Damping] += drive + self.bias * (x_b - x_a) - mechanical;
        y[Carried::CosProjection] += sc;
        y[Carried::SinProjection] += ss;
        if has_tangent(N) {
            // The rows of x and x', column by column.
            let t = self.transition(tau_b - tau_a);
            for col in 0..=SECTION_DIM {
                let at = phi_column(col);
                let (dx, dv) = (y[at], y[at + 1]);
                y[at] = t[(0, 0)] * dx + t[(0, 1)] * dv;
                y[at + 1] = t[(1, 0)] * dx + t[(1, 1)] * dv;
            }
        }
    }

    /// ∂(x, x')(τ₀ + s)/∂(x, x')(τ₀): the free oscillation's transition matrix over a
    /// time s (the drive only shifts the particular solution),
    /// e^{−γs}[[cos ω_d s + (γ/ω_d) sin ω_d s, sin ω_d s/ω_d],
    ///         [−sin ω_d s/ω_d, cos ω_d s − (γ/ω_d) sin ω_d s]].
    pub fn transition(&self, s: f64) -> Matrix2<f64> {
        let e = (-self.gamma * s).exp();
        let (sd, cd) = (self.omega_d * s).sin_cos();
        let g = self.gamma / self.omega_d;
        Matrix2::new(
            e * (cd + g * sd),
            e * sd / self.omega_d,
            -e * sd / self.omega_d,
            e * (cd - g * sd),
        )
    }

    /// (∫ x cos Ωτ dτ, ∫ x sin Ωτ dτ) over [a, b], exactly: with x = Re[P e^{iΩτ}] +
    /// Re[C e^{λ(τ−τ₀)}] + bias, P = a − ib, C = c₁ − ic₂, λ = −γ + iω_d, the integral of
    /// x e^{iΩτ} is a sum of integrals of complex exponentials.
    pub(crate) fn fourier(&self, tau_a: f64, tau_b: f64) -> (f64, f64) {
        let w = self.omega;
        let p = Complex::new(self.a, -self.b);
        let e2 = |t: f64| Complex::from_polar(1.0, 2.0 * w * t);
        let particular = p * (e2(tau_b) - e2(tau_a)) / Complex::new(0.0, 4.0 * w)
            + p.conj() * (0.5 * (tau_b - tau_a));
        let c = Complex::new(self.c1, -self.c2);
        let (sa, sb) = (tau_a - self.tau0, tau_b - self.tau0);
        let lam = Complex::new(-self.gamma, self.omega_d);
        let span = |mu: Complex<f64>| (mu * sa).exp() * exprel(mu * (sb - sa)) * (sb - sa);
        let homogeneous = Complex::from_polar(0.5, w * self.tau0)
            * (c * span(lam + Complex::new(0.0, w))
                + c.conj() * span(lam.conj() + Complex::new(0.0, w)));
        let constant = if self.bias == 0.0 {
            Complex::new(0.0, 0.0)
        } else {
            self.bias * (Complex::from_polar(1.0, w * tau_b) - Complex::from_polar(1.0, w * tau_a))
                / Complex::new(0.0, w)
        };
        let total = particular + homogeneous + constant;
        (total.re, total.im)
    }

    /// The first τ in [`tau_a`, `tau_b`] where x falls to `level` (`None` if it stays
    /// above), the lowest x met up to there, and the turning points of x met before
    /// it (what [`super::grazing`] measures against the law's switch levels). Sampled
    /// at most `max_dt` apart; a turning point between samples is found by Newton on
    /// x' = 0, so a minimum that just touches the level is not missed.
    #[doc(hidden)]
    pub fn first_fall_to(&self, level: f64, tau_a: f64, tau_b: f64, max_dt: f64) -> Fall {
        let n = ((tau_b - tau_a) / max_dt).ceil().max(1.0) as usize;
        let h = (tau_b - tau_a) / n as f64;
        let mut fall = Fall {
            hit: None,
            min_x: f64::INFINITY,
            lowest_turn: f64::INFINITY,
            highest_turn: f64::NEG_INFINITY,
        };
        let mut samples = self.samples(tau_a, h);
        let (mut t0, (mut x0, mut v0)) = (tau_a, samples.next().expect("endless"));
        let zero_velocity =
            |a, b| newton_bracketed(|t| self.velocity_and_acceleration(t), a, b, 1e-14);
        for i in 1..=n {
            let t1 = if i == n { tau_b } else { tau_a + h * i as f64 };
            let (x1, v1) = samples.next().expect("endless");
            // The lowest point inside, where x' changes from negative to positive.
            let turning = v0 < 0.0 && v1 > 0.0;
            let (t_low, x_low) = if turning {
                let t = zero_velocity(t0, t1);
                (t, self.at(t).0)
            } else if x1 < x0 {
                (t1, x1)
            } else {
                (t0, x0)
            };
            fall.min_x = fall.min_x.min(x_low);
            if x_low <= level && x0 > level {
                let hit = newton_bracketed(
                    |t| {
                        let (x, v) = self.at(t);
                        (x - level, v)
                    },
                    t0,
                    t_low,
                    1e-14,
                );
                // (A turning point here lies past the hit, where the flight ends.)
                fall.hit = Some(hit);
                fall.min_x = fall.min_x.min(level);
                return fall;
            }
            if turning {
                fall.lowest_turn = fall.lowest_turn.min(x_low);
            }
            if v0 > 0.0 && v1 < 0.0 {
                fall.highest_turn = fall.highest_turn.max(self.at(zero_velocity(t0, t1)).0);
            }
            (t0, x0, v0) = (t1, x1, v1);
        }
        fall
    }
}
