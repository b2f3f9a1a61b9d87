//! A function tabulated on a uniform grid, interpolated by cubic Hermite polynomials:
//! O(1) look-up, no allocation, continuous value and slope.

/// Values y(x) on a uniform grid with Hermite slopes.
#[derive(Debug, Clone)]
pub struct UniformTable {
    x0: f64,
    dx: f64,
    inv_dx: f64,
    /// Per node: value and slope·dx, side by side for one cache line per look-up.
    nodes: Vec<[f64; 2]>,
}

impl UniformTable {
    /// Tabulate `f` at `n ≥ 5` points from `x0` to `x1`; slopes by fourth-order finite
    /// differences inside, third-order one-sided ones at the two ends of the grid, so the
    /// interpolation error falls as the fourth power of the spacing.
    pub fn sample(x0: f64, x1: f64, n: usize, f: impl Fn(f64) -> f64) -> Self {
        let n = n.max(5);
        let dx = (x1 - x0) / (n - 1) as f64;
        let y: Vec<f64> = (0..n).map(|i| f(x0 + dx * i as f64)).collect();
        let slope: Vec<f64> = (0..n)
            .map(|i| match i {
                0 => (-11.0 * y[0] + 18.0 * y[1] - 9.0 * y[2] + 2.0 * y[3]) / (6.0 * dx),
                1 => (-2.0 * y[0] - 3.0 * y[1] + 6.0 * y[2] - y[3]) / (6.0 * dx),
                _ if i == n - 1 => {
                    (11.0 * y[n - 1] - 18.0 * y[n - 2] + 9.0 * y[n - 3] - 2.0 * y[n - 4])
                        / (6.0 * dx)
                }
                _ if i == n - 2 => {
                    (2.0 * y[n - 1] + 3.0 * y[n - 2] - 6.0 * y[n - 3] + y[n - 4]) / (6.0 * dx)
                }
                _ => (-y[i + 2] + 8.0 * (y[i + 1] - y[i - 1]) + y[i - 2]) / (12.0 * dx),
            })
            .collect();
        let nodes = y.iter().zip(&slope).map(|(&v, &m)| [v, m * dx]).collect();
        Self {
            x0,
            dx,
            inv_dx: 1.0 / dx,
            nodes,
        }
    }

    /// First abscissa.
    pub fn start(&self) -> f64 {
        self.x0
    }

    /// Last abscissa.
    pub fn end(&self) -> f64 {
        self.x0 + self.dx * (self.nodes.len() - 1) as f64
    }

    /// Grid spacing.
    pub fn step(&self) -> f64 {
        self.dx
    }

    /// Number of grid points.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the table is empty (never, once sampled).
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The interval holding `x` (the end ones outside the grid): its fraction t, the
    /// value y₀ and scaled slope m₀ at its start, those at its end, and y₁ − y₀.
    #[inline]
    fn interval(&self, x: f64) -> (f64, f64, f64, f64, f64) {
        let u = (x - self.x0) * self.inv_dx;
        let last = self.nodes.len() - 2;
        // `as usize` saturates: negative u and NaN give 0.
        let i = (u as usize).min(last);
        let [y0, m0] = self.nodes[i];
        let [y1, m1] = self.nodes[i + 1];
        (u - i as f64, y0, m0, m1, y1 - y0)
    }

    /// Interpolated value; outside the grid the end cubic is extrapolated.
    #[inline]
    pub fn eval(&self, x: f64) -> f64 {
        self.eval_and_slope(x).0
    }

    /// [`UniformTable::eval`] and [`UniformTable::slope`] from one look-up: the Hermite
    /// cubic in Horner form and its derivative.
    #[inline]
    pub fn eval_and_slope(&self, x: f64) -> (f64, f64) {
        let (t, y0, m0, m1, d) = self.interval(x);
        let (c2, c3) = (3.0 * d - 2.0 * m0 - m1, m0 + m1 - 2.0 * d);
        (
            y0 + t * (m0 + t * (c2 + t * c3)),
            (m0 + t * (2.0 * c2 + 3.0 * t * c3)) * self.inv_dx,
        )
    }

    /// ∫ p(x)·2x dx from node `i` to the fraction `t` of its interval, p the Hermite
    /// cubic there: the cubic times a line integrated term by term (exact; what a
    /// work function ∫ T̂ dα̂ = ∫ T̂(u)·2u du over a table in u = √α̂ needs).
    #[inline]
    pub fn weighted_integral(&self, i: usize, t: f64) -> f64 {
        let [y0, m0] = self.nodes[i];
        let [y1, m1] = self.nodes[i + 1];
        let d = y1 - y0;
        let (c2, c3) = (3.0 * d - 2.0 * m0 - m1, m0 + m1 - 2.0 * d);
        // ∫₀ᵗ p and ∫₀ᵗ s·p, p(s) = y₀ + m₀s + c₂s² + c₃s³.
        let i0 = t * (y0 + t * (m0 / 2.0 + t * (c2 / 3.0 + t * c3 / 4.0)));
        let i1 = t * t * (y0 / 2.0 + t * (m0 / 3.0 + t * (c2 / 4.0 + t * c3 / 5.0)));
        let x_i = self.x0 + self.dx * i as f64;
        2.0 * self.dx * (x_i * i0 + self.dx * i1)
    }

    /// Slope of the interpolant at `x` (the derivative of [`UniformTable::eval`]).
    #[inline]
    pub fn slope(&self, x: f64) -> f64 {
        self.eval_and_slope(x).1
    }
}
