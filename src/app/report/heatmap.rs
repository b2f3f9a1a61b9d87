//! A quantity over a two-dimensional grid of parameters, drawn as a heat map: one
//! coloured cell per grid point on a perceptually uniform scale (viridis) with its colour
//! bar, cells where the law does not apply left grey, cells whose motion is not
//! period-1 marked, and cells whose motion grazes a switch marked too.

/// One cell of a heat map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cell {
    /// A value, and whether it comes from a period-1 orbit (else from an orbit of
    /// higher period or a window of irregular motion: marked).
    Value {
        /// The value.
        value: f64,
        /// Whether the motion is period-1.
        period_one: bool,
        /// Whether the motion grazes a switch (marked by a black dot).
        grazing: bool,
    },
    /// The law does not apply here.
    NotApplicable,
}

/// A heat map over log-spaced (a parameter grid) or evenly spaced (an image) axes.
#[derive(Debug, Clone, PartialEq)]
pub struct HeatMap {
    /// Title above the panel.
    pub title: String,
    /// x axis label (with units).
    pub x_label: String,
    /// y axis label (with units).
    pub y_label: String,
    /// Label of the colour bar (the quantity, with units).
    pub value_label: String,
    /// Grid values along x, increasing.
    pub x: Vec<f64>,
    /// Grid values along y, increasing.
    pub y: Vec<f64>,
    /// Cells, `cells[j][i]` at `(x[i], y[j])`.
    pub cells: Vec<Vec<Cell>>,
    /// What a grey (empty) cell means, as the key says it ("law n/a"); nothing: no
    /// key (no cell is empty or marked).
    pub empty_label: String,
    /// Log axes (a parameter grid); else linear (an image in nm).
    pub log_axes: bool,
}

impl HeatMap {
    /// A scanned image's panel: `values[j][i]` at pixel i of line j (None: no value,
    /// grey with `empty_label`), x along the line and y across the lines in nm.
    pub fn image(
        (title, value_label, empty_label): (String, &str, &str),
        (x_nm, y_nm): (Vec<f64>, Vec<f64>),
        values: Vec<Vec<Option<f64>>>,
    ) -> Self {
        Self {
            title,
            x_label: "x along the line (nm)".into(),
            y_label: "y across the lines (nm)".into(),
            value_label: value_label.into(),
            x: x_nm,
            y: y_nm,
            cells: values
                .into_iter()
                .map(|line| {
                    line.into_iter()
                        .map(|v| match v {
                            Some(value) => Cell::Value {
                                value,
                                period_one: true,
                                grazing: false,
                            },
                            None => Cell::NotApplicable,
                        })
                        .collect()
                })
                .collect(),
            empty_label: empty_label.into(),
            log_axes: false,
        }
    }

    /// A panel over the (Δγ, E*) grid of a map: `values[j][i]` at work of adhesion i
    /// and modulus j, each its value and whether its motion is period-1 (None: grey,
    /// `empty_label`), log axes, E* in GPa.
    pub fn parameter_grid(
        (title, value_label, empty_label): (String, &str, &str),
        (works_j_m2, moduli_pa): (&[f64], &[f64]),
        values: Vec<Vec<Option<(f64, bool)>>>,
    ) -> Self {
        Self {
            title,
            x_label: "work of adhesion Δγ (J/m²)".into(),
            y_label: "composite modulus E* (GPa)".into(),
            value_label: value_label.into(),
            x: works_j_m2.to_vec(),
            y: moduli_pa.iter().map(|e| e * 1e-9).collect(),
            cells: values
                .into_iter()
                .map(|row| {
                    row.into_iter()
                        .map(|v| match v {
                            Some((value, period_one)) => Cell::Value {
                                value,
                                period_one,
                                grazing: false,
                            },
                            None => Cell::NotApplicable,
                        })
                        .collect()
                })
                .collect(),
            empty_label: empty_label.into(),
            log_axes: true,
        }
    }

    /// The range of the values (both ends equal if there is one value; `None` if none).
    pub fn value_range(&self) -> Option<(f64, f64)> {
        let values = self.cells.iter().flatten().filter_map(|c| match c {
            Cell::Value { value, .. } if value.is_finite() => Some(*value),
            _ => None,
        });
        values.fold(None, |r, v| match r {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
    }

    /// Cell edges along x and y ([`HeatMap::edges`], [`HeatMap::linear_edges`]).
    pub fn cell_edges(&self) -> (Vec<f64>, Vec<f64>) {
        let edges = if self.log_axes {
            Self::edges
        } else {
            Self::linear_edges
        };
        (edges(&self.x), edges(&self.y))
    }

    /// Cell edges along an evenly spaced axis: midpoints between the values, and half a
    /// step beyond the first and the last (a single value: ±1 around it).
    pub fn linear_edges(values: &[f64]) -> Vec<f64> {
        match values {
            [] => Vec::new(),
            [v] => vec![v - 1.0, v + 1.0],
            _ => {
                let n = values.len();
                let mut e = Vec::with_capacity(n + 1);
                e.push(values[0] - 0.5 * (values[1] - values[0]));
                e.extend(values.windows(2).map(|w| 0.5 * (w[0] + w[1])));
                e.push(values[n - 1] + 0.5 * (values[n - 1] - values[n - 2]));
                // An edge at zero computed from the values (pixels from 0) is zero, not
                // the round-off an axis would label.
                let span = (e[n] - e[0]).abs();
                for v in &mut e {
                    if v.abs() < 1e-9 * span {
                        *v = 0.0;
                    }
                }
                e
            }
        }
    }

    /// Cell edges along a log-spaced axis: geometric midpoints between the values, and
    /// half a step beyond the first and the last.
    pub fn edges(values: &[f64]) -> Vec<f64> {
        match values {
            [] => Vec::new(),
            [v] => vec![v / 1.1, v * 1.1],
            _ => {
                let n = values.len();
                let mut e = Vec::with_capacity(n + 1);
                e.push(values[0] * (values[0] / values[1]).sqrt());
                e.extend(values.windows(2).map(|w| (w[0] * w[1]).sqrt()));
                e.push(values[n - 1] * (values[n - 1] / values[n - 2]).sqrt());
                e
            }
        }
    }
}

/// The viridis colour map (van der Walt & Smith, matplotlib) at nine stops, linearly
/// interpolated: perceptually uniform and readable in grey scale.
#[doc(hidden)]
pub const VIRIDIS: [(u8, u8, u8); 9] = [
    (68, 1, 84),
    (71, 44, 122),
    (59, 81, 139),
    (44, 113, 142),
    (33, 144, 141),
    (39, 173, 129),
    (92, 200, 99),
    (170, 220, 50),
    (253, 231, 37),
];

/// The colour of fraction `t` ∈ [0, 1] of the scale (clamped).
pub fn viridis(t: f64) -> (u8, u8, u8) {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (VIRIDIS.len() - 1) as f64;
    let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |p: u8, q: u8| (p as f64 + f * (q as f64 - p as f64)).round() as u8;
    (mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}
