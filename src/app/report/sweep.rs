//! Reports of sweeps: the approach-curve and phase-contrast charts. (Records go out
//! through [`super::records`].)

use super::chart::{Axis, Chart, Corner, Series, Style};
use crate::analysis::identification::{Mechanism, Normalized};
use crate::analysis::sweep::{Direction, SweepPoint};
use crate::instrument::average::ThermalAverage;

/// The x axis of every chart against the rest separation: z_c in nm.
pub fn separation_axis() -> Axis {
    Axis::linear("rest separation z_c (nm)", "separation_nm")
}

/// Approach-curve charts: A/A₀, φ, E_ts, virial and peak force against z_c, and the
/// last four against A/A₀; approach and retract as separate series. The peak force
/// is left out where it is zero at every setpoint (no repulsive contact).
pub fn approach_charts(points: &[SweepPoint], title: &str) -> Vec<Chart> {
    type Pick = fn(&SweepPoint) -> f64;
    type Thermal = Option<fn(&ThermalAverage) -> f64>;
    type ThermalX = fn(&SweepPoint, &ThermalAverage) -> f64;
    // An x axis: the axis, a point's x and a thermal average's x.
    type XAxis<'a> = (Axis, &'a dyn Fn(&SweepPoint) -> f64, ThermalX);
    let nm = |p: &SweepPoint| p.separation_m * 1e9;
    let series = |x: &dyn Fn(&SweepPoint) -> f64, y: Pick| -> Vec<Series> {
        let mut all: Vec<Located> = Vec::new();
        let mut out: Vec<Series> = [
            (Direction::Approach, "approach", 1),
            (Direction::Retract, "retract", 2),
        ]
        .into_iter()
        .flat_map(|(dir, name, color)| {
            let style = if dir == Direction::Approach {
                Style::Line
            } else {
                Style::Dashed
            };
            let on: Vec<Located> = points
                .iter()
                .filter(|p| p.direction == dir)
                .map(|p| locate(p, &|p| (x(p), y(p)), color))
                .collect();
            let lines = period_one_lines(&on, name, style, color);
            all.extend(on);
            lines
        })
        .collect();
        out.extend(not_period_one(&all));
        out
    };
    // The thermal averages (`approach --temperature`) where the sweep has them, in black
    // over the coloured markers of the states they average (approach and retract alike:
    // the thermal motion forgets the direction of the ramp): what an instrument reads
    // at the points marked as grazing or not period-1.
    let thermal = |xs: ThermalX, ys: Thermal| -> Vec<Series> {
        let Some(ys) = ys else { return vec![] };
        let Some(t) = points.iter().find_map(|p| p.thermal_average) else {
            return vec![];
        };
        let pts: Vec<(f64, f64)> = points
            .iter()
            .filter_map(|p| p.thermal_average.map(|a| (xs(p, &a), ys(&a))))
            .collect();
        vec![Series::new(
            &format!("thermal average at {} K", t.temperature_k),
            pts,
            Style::Triangles,
            0,
        )]
    };
    let chart =
        |name: &str, what: &str, (x, xs, txs): XAxis<'_>, (y, ys, tys): (Axis, Pick, Thermal)| {
            let mut series = series(xs, ys);
            series.extend(thermal(txs, tys));
            Chart {
                name: name.into(),
                title: format!("{title}: {what}"),
                x,
                y,
                legend: Corner::quietest(&series),
                series,
                labels: vec![],
            }
        };
    let ratio = |p: &SweepPoint| p.observables.amplitude_ratio;
    // (file stem, caption, axis label, column, value, a thermal average's value); the
    // first is A/A₀ itself.
    let quantities: [(&str, &str, &str, &str, Pick, Thermal); 7] = [
        (
            "amplitude",
            "amplitude",
            "A/A₀",
            "amplitude_ratio",
            |p| p.observables.amplitude_ratio,
            Some(|a| a.amplitude_ratio),
        ),
        (
            "phase",
            "phase",
            "phase lag φ (deg)",
            "phase_deg",
            |p| p.observables.phase_deg,
            Some(|a| a.phase_deg),
        ),
        (
            "e_ts",
            "dissipation",
            "E_ts per cycle (eV)",
            "e_ts_ev",
            |p| p.observables.e_ts_ev,
            Some(|a| a.e_ts_j / crate::physics::params::ELECTRONVOLT_J),
        ),
        (
            "e_ts_viscous",
            "viscous dissipation",
            "E_ts in the viscous sample per cycle (eV)",
            "e_ts_viscous_ev",
            |p| p.observables.e_ts_viscous_j / crate::physics::params::ELECTRONVOLT_J,
            None,
        ),
        (
            "e_ts_capillary",
            "capillary dissipation",
            "E_ts in the capillary neck per cycle (eV)",
            "e_ts_capillary_ev",
            |p| p.observables.e_ts_capillary_j / crate::physics::params::ELECTRONVOLT_J,
            None,
        ),
        (
            "virial",
            "virial",
            "virial ⟨F_ts z⟩ (eV)",
            "virial_ev",
            |p| p.observables.virial_j / crate::physics::params::ELECTRONVOLT_J,
            None,
        ),
        (
            "peak_force",
            "peak force",
            "peak repulsive force (nN)",
            "peak_force_nn",
            |p| p.observables.peak_force_n * 1e9,
            None,
        ),
    ];
    // A quantity that is zero throughout (a peak repulsive force where the tip never
    // presses into the sample: the attractive regime; the viscous part of E_ts on an
    // elastic sample) gets no panels.
    let shown =
        |q: &&(&str, &str, &str, &str, Pick, Thermal)| !points.iter().all(|p| q.4(p) == 0.0);
    let against_separation =
        quantities
            .iter()
            .filter(shown)
            .map(|&(name, what, label, column, pick, thermal)| {
                chart(
                    name,
                    what,
                    (separation_axis(), &nm, |p, _| p.separation_m * 1e9),
                    (Axis::linear(label, column), pick, thermal),
                )
            });
    let against_amplitude = quantities.iter().skip(1).filter(shown).map(
        |&(name, what, label, column, pick, thermal)| {
            chart(
                &format!("{name}_vs_amplitude"),
                &format!("{what} vs amplitude"),
                (Axis::linear("A/A₀", "amplitude_ratio"), &ratio, |_, a| {
                    a.amplitude_ratio
                }),
                (Axis::linear(label, column), pick, thermal),
            )
        },
    );
    let mut charts: Vec<Chart> = against_separation.chain(against_amplitude).collect();
    super::chart::share_legends(&mut charts);
    charts
}

/// The identification curves of a sweep ([`crate::analysis::identification`]): each mechanism's
/// E/E_max against A/A₀ on the approach (`normalized` holds the points' values), one
/// curve per mechanism that dissipates anything (the total only where it is a single
/// mechanism's); the free points (A/A₀ ≥ 0.999) left out.
pub fn identification_chart(
    name: &str,
    title: &str,
    curves: &[(&str, &[SweepPoint], &[Normalized])],
) -> Chart {
    let mut series = Vec::new();
    let mut all = Vec::new();
    let mut color = 0;
    for (label, points, normalized) in curves {
        let present: Vec<Mechanism> = Mechanism::ALL
            .into_iter()
            .filter(|&m| normalized.iter().any(|n| n.of(m).is_some()))
            .collect();
        // With one mechanism the total is that mechanism's curve: drawn once, as the
        // mechanism's.
        let shown = present
            .iter()
            .copied()
            .filter(|&m| m != Mechanism::All || present.len() > 2);
        for mechanism in shown {
            color += 1;
            let on: Vec<Located> = points
                .iter()
                .zip(normalized.iter())
                .filter(|(p, _)| touching_on_approach(p))
                .filter_map(|(p, n)| {
                    let e = n.of(mechanism)?;
                    Some(locate(p, &|p| (p.observables.amplitude_ratio, e), color))
                })
                .collect();
            let name = match (curves.len(), present.len()) {
                (1, _) => mechanism.label().to_string(),
                (_, 2) => label.to_string(),
                _ => format!("{label}: {}", mechanism.label()),
            };
            // Plateaus of different mechanisms coincide at 1: solid, dashed and dotted
            // by turns, so none hides another.
            let style = [Style::Line, Style::Dashed, Style::Dotted][(color - 1) % 3];
            series.extend(period_one_lines(&on, &name, style, color));
            all.extend(on);
        }
    }
    series.extend(not_period_one(&all));
    Chart {
        name: name.into(),
        title: title.into(),
        x: Axis::linear("A/A₀", "amplitude_ratio"),
        y: Axis::linear("E/E_max per mechanism", "e_ts_norm"),
        legend: Corner::quietest(&series),
        series,
        labels: vec![],
    }
}

/// φ against A/A₀ on the approach branch (free points A/A₀ ≥ 0.999 left out), one series
/// per labelled curve: the phase-contrast view.
/// The free oscillation's phase (where the curves start, A/A₀ ≥ 0.999) is drawn across
/// as the line that parts the branches: attractive above it, repulsive below.
pub fn phase_vs_amplitude(name: &str, title: &str, curves: &[(&str, &[SweepPoint])]) -> Chart {
    let mut chart = vs_amplitude(
        (name, title),
        Axis::linear("phase lag φ (deg)", "phase_deg"),
        |o| o.phase_deg,
        curves,
    );
    let free = curves.iter().find_map(|(_, points)| {
        points
            .iter()
            .find(|p| p.direction == Direction::Approach && p.observables.amplitude_ratio >= 0.999)
            .map(|p| p.observables.phase_deg)
    });
    let shown = chart
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0));
    let left = shown.fold(f64::INFINITY, f64::min);
    if let (Some(free), true) = (free, left.is_finite()) {
        // Over the last quarter of the curves' span, where they leave it, and with points
        // along it so the legend keeps clear of it.
        let from = 1.0 - 0.25 * (1.0 - left);
        chart.series.push(Series::new(
            &format!("free phase {free:.1}°: attractive above, repulsive below"),
            (0..=10)
                .map(|i| (from + (1.0 - from) * f64::from(i) / 10.0, free))
                .collect(),
            Style::Dotted,
            0,
        ));
        chart.legend = Corner::quietest(&chart.series);
    }
    chart
}

/// `pick` of each setpoint against A/A₀ on the approach branch (free points A/A₀ ≥ 0.999
/// left out), one series per labelled curve, broken where φ jumps between the
/// attractive and the repulsive branch (a jump is no part of either).
pub fn vs_amplitude(
    (name, title): (&str, &str),
    y: Axis,
    pick: fn(&crate::dynamics::observables::TapObservables) -> f64,
    curves: &[(&str, &[SweepPoint])],
) -> Chart {
    let xy = |p: &SweepPoint| (p.observables.amplitude_ratio, pick(&p.observables));
    let mut series = Vec::new();
    let mut others = Vec::new();
    for (i, (label, points)) in curves.iter().enumerate() {
        let kept: Vec<&SweepPoint> = points.iter().filter(|p| touching_on_approach(p)).collect();
        for (k, part) in split_at_jumps(&kept).into_iter().enumerate() {
            let on: Vec<Located> = part.iter().map(|p| locate(p, &xy, i + 1)).collect();
            series.extend(period_one_lines(
                &on,
                if k == 0 { label } else { "" },
                Style::Line,
                i + 1,
            ));
            others.extend(on);
        }
    }
    series.extend(not_period_one(&others));
    Chart {
        name: name.into(),
        title: title.into(),
        x: Axis::linear("A/A₀", "amplitude_ratio"),
        y,
        legend: Corner::quietest(&series),
        series,
        labels: vec![],
    }
}

/// Whether a setpoint is on the approach and not free (A/A₀ < 0.999): what the views
/// against A/A₀ show.
fn touching_on_approach(p: &SweepPoint) -> bool {
    p.direction == Direction::Approach && p.observables.amplitude_ratio < 0.999
}

/// A value to plot and what it is.
#[derive(Debug, Clone, Copy)]
pub struct Located {
    /// The period of the motion behind it (`None`: irregular).
    pub period: Option<usize>,
    /// Whether that motion grazes a switch.
    pub grazing: bool,
    /// The point.
    pub xy: (f64, f64),
    /// Palette colour of the curve it belongs to.
    pub color: usize,
}

/// A change of φ between neighbouring setpoints (degrees) that is a jump between
/// branches, not a slope.
const JUMP_DEG: f64 = 20.0;

/// `points` in pieces, cut between neighbours whose phases differ by more than
/// [`JUMP_DEG`].
fn split_at_jumps<'a>(points: &[&'a SweepPoint]) -> Vec<Vec<&'a SweepPoint>> {
    let mut parts: Vec<Vec<&SweepPoint>> = vec![Vec::new()];
    for (k, &p) in points.iter().enumerate() {
        if k > 0 && (p.observables.phase_deg - points[k - 1].observables.phase_deg).abs() > JUMP_DEG
        {
            parts.push(Vec::new());
        }
        parts.last_mut().expect("a part").push(p);
    }
    parts
}

/// Lines through `points` (in order) that join neighbouring period-1 points only, the
/// first named `name` (a legend entry alone where there is none): a value of motion that is not period-1 is no point of a smooth
/// curve ([`not_period_one`] marks those).
pub fn period_one_lines(points: &[Located], name: &str, style: Style, color: usize) -> Vec<Series> {
    let mut runs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for p in points {
        if p.period == Some(1) {
            runs.last_mut().expect("a run").push(p.xy);
        } else if !runs.last().expect("a run").is_empty() {
            runs.push(Vec::new());
        }
    }
    runs.retain(|r| !r.is_empty());
    if runs.is_empty() {
        // No period-1 point: the curve's name still goes in the legend, its points are
        // all markers in its colour.
        return vec![Series::new(name, vec![], style, color)];
    }
    runs.into_iter()
        .enumerate()
        .map(|(i, r)| Series::new(if i == 0 { name } else { "" }, r, style, color))
        .collect()
}

/// Points that are not period-1, as markers in their curve's colour: circles for
/// periodic orbits of higher period, crosses for irregular motion (its values averages
/// over a window) and, around them, squares for every point whose motion grazes a switch
/// (its touch pattern set by perturbations below the thermal motion). Each kind has one
/// legend entry, in black; the curves' colours say whose points they are.
pub fn not_period_one(points: &[Located]) -> Vec<Series> {
    type Kind = (&'static str, Style, fn(&Located) -> bool);
    let kinds: [Kind; 3] = [
        ("period-n orbit (n ≥ 2)", Style::Markers, |p| {
            p.period.is_some_and(|n| n > 1)
        }),
        ("irregular (window average)", Style::Crosses, |p| {
            p.period.is_none()
        }),
        ("grazes a switch", Style::Squares, |p| p.grazing),
    ];
    let mut colors: Vec<usize> = points.iter().map(|p| p.color).collect();
    colors.sort_unstable();
    colors.dedup();
    let mut out = Vec::new();
    for (name, style, keep) in kinds {
        if !points.iter().any(keep) {
            continue;
        }
        // (With several curves, a marker takes the colour of the curve it belongs to.)
        let name = if colors.len() > 1 {
            format!("{name}, in its curve's colour")
        } else {
            name.to_string()
        };
        out.push(Series::new(&name, vec![], style, 0));
        for &color in &colors {
            let pts: Vec<(f64, f64)> = points
                .iter()
                .filter(|p| p.color == color && keep(p))
                .map(|p| p.xy)
                .collect();
            if !pts.is_empty() {
                out.push(Series::new("", pts, style, color));
            }
        }
    }
    out
}

/// A sweep point located for a plot by `xy`, on the curve drawn in palette colour
/// `color`.
pub fn locate(p: &SweepPoint, xy: &dyn Fn(&SweepPoint) -> (f64, f64), color: usize) -> Located {
    Located {
        period: p.observables.period,
        grazing: p.observables.grazing,
        xy: xy(p),
        color,
    }
}

/// An approach ramp drawn over an orbit branch: its points as markers, approach and
/// retract apart.
pub fn ramp_markers(ramp: &[SweepPoint], xy: &dyn Fn(&SweepPoint) -> (f64, f64)) -> Vec<Series> {
    [
        (Direction::Approach, "approach ramp", 5),
        (Direction::Retract, "retract ramp", 6),
    ]
    .into_iter()
    .filter_map(|(dir, name, color)| {
        let pts: Vec<(f64, f64)> = ramp.iter().filter(|p| p.direction == dir).map(xy).collect();
        (!pts.is_empty()).then(|| Series::new(name, pts, Style::Markers, color))
    })
    .collect()
}
