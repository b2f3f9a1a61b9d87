//! The data of the paper's figures, as [`Chart`]s: Fig. 1 (JKR cycle), Fig. 3 (jump-in
//! separation), Fig. 4 (hysteresis vs μ), Fig. 5 (cycle with a finite-stiffness
//! support), Fig. 6 (hysteresis vs k̂); Figs. 2–4 include the full Lennard-Jones
//! solution (computed once per μ and cached).

use crate::app::lj_cache;
use crate::app::report::chart::{Axis, Chart, Corner, Label, Series, Style};
use crate::error::{Error, Result};
use crate::physics::contact::hybrid::{self, JumpIn};
use crate::physics::contact::jkr::{self, JkrPoint};
use crate::physics::contact::lj::{LjSolution, Reach};
use crate::physics::contact::semi_rigid::{self, EighthPower};
use crate::physics::contact::spring;
use crate::physics::quasistatic::{self, Segment};

/// The figure numbers this build can draw.
pub const AVAILABLE: [u32; 6] = [1, 2, 3, 4, 5, 6];

/// Tabor parameters of the numerical points of Figs. 3 and 4.
pub const LJ_MUS: [f64; 13] = [
    1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0, 20.0, 30.0, 50.0,
];

/// Tabor parameter of Fig. 2.
pub const FIG2_MU: f64 = 5.0;

/// The numerical solutions of Figs. 3 and 4 (from the cache when there).
pub fn lj_solutions() -> Result<Vec<LjSolution>> {
    LJ_MUS
        .iter()
        .map(|&mu| lj_cache::solve(mu, Reach::Rigid, true))
        .collect()
}

/// Tabor parameters of the curves of Fig. 6.
pub const FIG6_MUS: [f64; 4] = [2.0, 5.0, 10.0, 20.0];

/// The paper's numerical hysteresis at μ = 5 (Section 3), quoted for comparison.
pub const PAPER_W_HAT_LJ_MU5: f64 = 3.2482;

/// `n` points from `lo` to `hi`, evenly spaced (geometrically when `log`).
fn grid(lo: f64, hi: f64, n: usize, log: bool) -> impl Iterator<Item = f64> {
    (0..n).map(move |i| {
        let t = i as f64 / (n - 1) as f64;
        if log {
            lo * (hi / lo).powf(t)
        } else {
            lo + (hi - lo) * t
        }
    })
}

fn label(text: &str, x: f64, y: f64) -> Label {
    Label {
        text: text.into(),
        x,
        y,
    }
}

/// Add the jumps A→B and C→D of a hysteresis loop to a chart's `series` and `labels`:
/// their dotted lines (colours `colors`, the markers in the first), the four markers,
/// and labels `drop` below A and D and `rise` above B and C.
fn add_jumps(
    (series, labels): (&mut Vec<Series>, &mut Vec<Label>),
    [a, b, c, d]: [(f64, f64); 4],
    colors: (usize, usize),
    (drop, rise): (f64, f64),
) {
    series.extend([
        Series::new("jump-in A→B", vec![a, b], Style::Dotted, colors.0),
        Series::new("jump-out C→D", vec![c, d], Style::Dotted, colors.1),
        Series::new("A, B, C, D", vec![a, b, c, d], Style::Markers, colors.0),
    ]);
    labels.extend([
        label("A", a.0 + 0.04, a.1 - drop),
        label("B", b.0 + 0.04, b.1 + rise),
        label("C", c.0 + 0.04, c.1 + rise),
        // (Above D: D lies on the far approach branch, near T̂ = 0 and the axis.)
        label("D", d.0 + 0.04, d.1 + rise),
    ]);
}

/// Options of the figures that have free parameters.
#[derive(Debug, Clone, Copy)]
pub struct FigureOptions {
    /// Tabor parameter of Fig. 5.
    pub fig5_mu: f64,
    /// Support stiffness k̂ of Fig. 5.
    pub fig5_k_hat: f64,
    /// Jump-in variant for Figs. 4–6.
    pub jump_in: JumpIn,
}

impl Default for FigureOptions {
    fn default() -> Self {
        Self {
            fig5_mu: 5.0,
            fig5_k_hat: 2.0,
            jump_in: JumpIn::Fit,
        }
    }
}

/// Build figure `number`.
pub fn figure(number: u32, opts: &FigureOptions) -> Result<Chart> {
    match number {
        1 => Ok(fig1()),
        2 => fig2(
            &lj_cache::solve(FIG2_MU, Reach::Rigid, true)?,
            &lj_cache::solve(FIG2_MU, Reach::Whole, true)?,
        ),
        3 => fig3(&lj_solutions()?),
        4 => fig4(opts.jump_in, &lj_solutions()?),
        5 => fig5(opts.fig5_mu, opts.fig5_k_hat, opts.jump_in),
        6 => fig6(
            opts.jump_in,
            &FIG6_MUS
                .iter()
                .map(|&mu| lj_cache::solve(mu, Reach::Springs, true))
                .collect::<Result<Vec<_>>>()?,
        ),
        n => Err(Error::NotApplicable(format!(
            "the paper has figures 1 to 6; there is no figure {n}"
        ))),
    }
}

/// Fig. 1: the JKR force–separation curve (5) with the rigid-grip cycle O→B→C→D→O.
pub fn fig1() -> Chart {
    let b = jkr::point_b();
    let c = jkr::point_c();
    let deepest = 2.4;
    let pts = |lo: f64, hi: f64| -> Vec<(f64, f64)> {
        grid(lo, hi, 400, false)
            .map(JkrPoint::at)
            .map(|p| (p.alpha_hat, p.t_hat))
            .collect()
    };
    let d = (c.alpha_hat, 0.0);
    Chart {
        name: "fig1_jkr_cycle".into(),
        title: "Fig. 1  JKR loading and unloading (rigid grips)".into(),
        x: Axis::linear("separation α/(με)", "alpha_hat"),
        y: Axis::linear("force T/(RΔγ)  (tensile > 0)", "t_hat"),
        series: vec![
            Series::new(
                "JKR stable branch (5)",
                pts(c.a_hat, deepest),
                Style::Line,
                0,
            ),
            Series::new(
                "JKR unstable branch (5)",
                pts(0.0, c.a_hat),
                Style::Dashed,
                0,
            ),
            Series::new(
                "approach and retract (T = 0)",
                vec![(2.2, 0.0), (0.0, 0.0)],
                Style::Line,
                2,
            ),
            Series::new(
                "jump-in O→B",
                vec![(0.0, 0.0), (0.0, b.t_hat)],
                Style::Dotted,
                3,
            ),
            Series::new(
                "jump-out C→D",
                vec![(c.alpha_hat, c.t_hat), d],
                Style::Dotted,
                1,
            ),
            Series::new(
                "O, B, C, D (8)",
                vec![(0.0, 0.0), (0.0, b.t_hat), (c.alpha_hat, c.t_hat), d],
                Style::Markers,
                1,
            ),
        ],
        labels: vec![
            // (O and D above the T = 0 line, clear of the axis.)
            label("O", -0.12, 0.35),
            label("B", 0.05, b.t_hat + 0.35),
            label("C", c.alpha_hat + 0.05, c.t_hat + 0.35),
            label("D", c.alpha_hat + 0.05, 0.35),
        ],
        legend: Corner::UpperLeft,
    }
}

/// Largest separation shown in Fig. 2.
const FIG2_ALPHA_MAX: f64 = 4.0;

/// Fig. 2: the Lennard-Jones force–separation curve for μ = 5 (numerical), with its
/// folds A and C, the jumps, and the JKR curve (5) for comparison: the folds and Ŵ of
/// `s` (the rigid-support solution `tapsim lj` reports), the curve of `traced` (the
/// same μ traced whole, the unstable branch included).
pub fn fig2(s: &LjSolution, traced: &LjSolution) -> Result<Chart> {
    let c = jkr::point_c();
    let jkr_curve: Vec<(f64, f64)> = grid(c.a_hat, 2.4, 300, false)
        .map(|a| (jkr::separation_hat(a), jkr::force_hat(a)))
        .collect();
    // That trace starts far out (for soft support springs); the figure shows the loop.
    let lj_curve: Vec<(f64, f64)> = traced
        .curve
        .iter()
        .filter(|p| p.alpha_hat <= FIG2_ALPHA_MAX)
        .map(|p| (p.alpha_hat, p.t_hat))
        .collect();
    let (a, cc) = (
        (s.alpha_hat_a.value, s.t_hat_a.value),
        (s.alpha_hat_c.value, s.t_hat_c.value),
    );
    // Where the jumps land: the contact branch at α̂_A, the approach branch at α̂_C.
    let b = (
        a.0,
        LjSolution::force_on(traced.contact_branch(), a.0).unwrap_or(f64::NAN),
    );
    let d = (
        cc.0,
        LjSolution::force_on(traced.approach_branch(), cc.0).unwrap_or(f64::NAN),
    );
    let mut series = vec![
        Series::new("JKR (5)", jkr_curve, Style::Line, 0),
        Series::new("Lennard-Jones (10), numerical", lj_curve, Style::Dashed, 1),
    ];
    let mut labels = Vec::new();
    add_jumps(
        (&mut series, &mut labels),
        [a, b, cc, d],
        (2, 3),
        (0.3, 0.3),
    );
    labels.push(label(
        &format!("Ŵ = {:.5} ± {:.1e}", s.w_hat.value, s.w_hat.error),
        -1.5,
        0.5,
    ));
    Ok(Chart {
        name: "fig2_lj_mu5".into(),
        title: format!("Fig. 2  Force–separation relation for μ = {}", s.tabor_mu),
        x: Axis::linear("separation α/(με)", "alpha_hat"),
        y: Axis::linear("force T/(RΔγ)  (tensile > 0)", "t_hat"),
        series,
        labels,
        legend: Corner::UpperRight,
    })
}

/// The numerical jump-in separations against the fit (17) and the closed form (16), as
/// CSV (`mu, alpha_hat_a, alpha_hat_a_error, fit17, fit17_rel, closed_form16`).
pub fn lj_fit_table(solutions: &[LjSolution]) -> Result<Vec<u8>> {
    let rows: Vec<serde_json::Value> = solutions
        .iter()
        .map(|s| {
            let mu = s.tabor_mu;
            let fit = semi_rigid::alpha_hat_a_fit(mu);
            serde_json::json!({
                "mu": mu,
                "alpha_hat_a": s.alpha_hat_a.value,
                "alpha_hat_a_error": s.alpha_hat_a.error,
                "fit17": fit,
                "fit17_rel": (fit - s.alpha_hat_a.value) / s.alpha_hat_a.value,
                "closed_form16": semi_rigid::alpha_hat_a_closed_form(mu),
                "w_hat": s.w_hat.value,
                "w_hat_error": s.w_hat.error,
                "w_hat_hybrid": hybrid::w_hat_fit(mu),
            })
        })
        .collect();
    crate::app::report::records::records_csv(&rows)
}

/// The paper's range of μ in Fig. 3 (the table `fig3_lj_vs_fit.csv` goes on to 50).
const FIG3_MAX_MU: f64 = 10.0;

/// Fig. 3: jump-in separation α̂_A vs μ — the numerical Lennard-Jones points, the exact
/// semi-rigid turning point (14)–(15), the closed form (16) and the fit (17).
pub fn fig3(solutions: &[LjSolution]) -> Result<Chart> {
    let mus: Vec<f64> = grid(1.0, FIG3_MAX_MU, 181, false).collect();
    let exact = mus
        .iter()
        .map(|&mu| {
            semi_rigid::jump_in_exact(mu, EighthPower::Keep).map(|a| a.map(|a| (mu, a.alpha_hat)))
        })
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .flatten()
        .collect();
    let of = |f: fn(f64) -> f64| mus.iter().map(|&mu| (mu, f(mu))).collect();
    let exact: Vec<(f64, f64)> = exact;
    // The closed form lies on the turning point's curve: the legend says how close.
    let apart = exact
        .iter()
        .map(|&(mu, a)| (semi_rigid::alpha_hat_a_closed_form(mu) / a - 1.0).abs())
        .fold(0.0, f64::max);
    Ok(Chart {
        name: "fig3_jump_in".into(),
        title: "Fig. 3  Separation at the jump-in point A".into(),
        x: Axis::linear("Tabor parameter μ", "tabor_mu"),
        y: Axis::linear("jump-in separation α_A/(με)", "alpha_hat_a"),
        series: vec![
            Series::new(
                "semi-rigid turning point (14), (15)",
                exact,
                Style::Dashed,
                0,
            ),
            Series::new(
                &format!(
                    "closed form (16): on (14), (15) within {:.2} %",
                    100.0 * apart
                ),
                of(semi_rigid::alpha_hat_a_closed_form),
                Style::Dotted,
                2,
            ),
            Series::new("fit (17)", of(semi_rigid::alpha_hat_a_fit), Style::Line, 1),
            Series::new(
                "Lennard-Jones (10), numerical",
                solutions
                    .iter()
                    .filter(|s| s.tabor_mu <= FIG3_MAX_MU)
                    .map(|s| (s.tabor_mu, s.alpha_hat_a.value))
                    .collect(),
                Style::Markers,
                3,
            ),
        ],
        labels: vec![],
        legend: Corner::UpperRight,
    })
}

/// Fig. 4: hysteresis Ŵ vs μ — the numerical Lennard-Jones points, the hybrid theory
/// (18) and the JKR level (9), with the paper's numerical value at μ = 5 for reference.
pub fn fig4(jump_in: JumpIn, solutions: &[LjSolution]) -> Result<Chart> {
    let mu_min = hybrid::min_hysteretic_mu(jump_in)?;
    let hybrid_line = std::iter::once(mu_min)
        .chain(grid(mu_min * 1.0001, 1000.0, 300, true))
        .map(|mu| Ok((mu, hybrid::hysteresis(mu, jump_in)?.w_hat)))
        .collect::<Result<Vec<_>>>()?;
    let w_jkr = jkr::w_hat_jkr();
    Ok(Chart {
        name: "fig4_hysteresis_vs_mu".into(),
        title: "Fig. 4  Hysteresis loss per cycle vs Tabor parameter".into(),
        x: Axis::log("Tabor parameter μ", "tabor_mu").with_range(1.0, 1000.0),
        y: Axis::linear("hysteresis loss W/(μεRΔγ)", "w_hat").with_range(0.0, 8.0),
        series: vec![
            Series::new(
                &format!("hybrid theory (18), jump-in {jump_in}"),
                hybrid_line,
                Style::Line,
                0,
            ),
            Series::new(
                "JKR (9): 7.092",
                vec![(1.0, w_jkr), (1000.0, w_jkr)],
                Style::Dashed,
                1,
            ),
            Series::new(
                "Lennard-Jones (10), numerical",
                solutions
                    .iter()
                    .map(|s| (s.tabor_mu, s.w_hat.value))
                    .collect(),
                Style::Markers,
                3,
            ),
            Series::new(
                "paper's numerical LJ value at μ = 5",
                vec![(5.0, PAPER_W_HAT_LJ_MU5)],
                Style::Markers,
                2,
            ),
        ],
        labels: vec![],
        legend: Corner::LowerRight,
    })
}

/// Fig. 5: the loading–unloading path A→B→C→D for a support of stiffness k̂,
/// support separation α̂_S (22) vs force.
pub fn fig5(tabor_mu: f64, k_hat: f64, jump_in: JumpIn) -> Result<Chart> {
    let cycle = quasistatic::cycle(tabor_mu, k_hat, jump_in, 400)?;
    let segment = |seg: Segment| -> Vec<(f64, f64)> {
        cycle
            .points
            .iter()
            .filter(|p| p.segment == seg)
            .map(|p| (p.support_alpha_hat, p.t_hat))
            .collect()
    };
    let h = &cycle.hysteresis;
    let b = h
        .landing
        .expect("cycle() succeeds only with a landing point");
    let a = (h.alpha_hat_a.unwrap_or(b.alpha_hat), 0.0);
    let b = (spring::support_separation_hat(&b, k_hat), b.t_hat);
    let c = (h.support_alpha_hat_c, h.jump_out.t_hat);
    let d = (h.support_alpha_hat_c, 0.0);
    let left = cycle
        .points
        .iter()
        .map(|p| p.support_alpha_hat)
        .fold(f64::INFINITY, f64::min);
    let mut approach = segment(Segment::Approach);
    approach.extend(segment(Segment::Retract));
    approach.sort_by(|p, q| p.0.total_cmp(&q.0));
    let mut series = vec![
        Series::new(
            "contact branch (5), (22)",
            segment(Segment::Unloading),
            Style::Line,
            0,
        ),
        Series::new("force-free approach/retract", approach, Style::Line, 2),
    ];
    let mut labels = Vec::new();
    add_jumps(
        (&mut series, &mut labels),
        [a, b, c, d],
        (1, 3),
        (0.2, 0.35),
    );
    labels.push(label(
        &format!("W/(μεRΔγ) = {:.4}  (26)", h.w_hat),
        left,
        0.9 * jkr::PULL_OFF_T_HAT,
    ));
    Ok(Chart {
        name: "fig5_finite_stiffness_cycle".into(),
        title: format!(
            "Fig. 5  Cycle with a compliant support: μεk/(RΔγ) = {k_hat}, μ = {tabor_mu}"
        ),
        x: Axis::linear(
            "support separation (α + T/k)/(με)  (22)",
            "support_alpha_hat",
        ),
        y: Axis::linear("force T/(RΔγ)  (tensile > 0)", "t_hat"),
        series,
        labels,
        legend: Corner::LowerRight,
    })
}

/// Support stiffnesses of the numerical points of Fig. 6.
pub const FIG6_LJ_K_HATS: [f64; 12] = [
    0.01, 0.03, 0.1, 0.3, 1.0, 2.0, 5.0, 10.0, 30.0, 100.0, 300.0, 1000.0,
];

/// Fig. 6: hysteresis Ŵ(k̂) (26) for μ = 2, 5, 10, 20, with the soft-support asymptote
/// (27), the rigid-grip levels (18), and the numerical Lennard-Jones loss through the
/// same spring (the S-curve seen in α̂ + T̂/k̂, [`LjSolution::spring_loop`]) for each
/// solution in `lj` (those of [`FIG6_MUS`]).
pub fn fig6(jump_in: JumpIn, lj: &[LjSolution]) -> Result<Chart> {
    let (k_lo, k_hi) = (1e-2, 1e3);
    let mut series = Vec::new();
    for (i, &mu) in FIG6_MUS.iter().enumerate() {
        let line = grid(k_lo, k_hi, 200, true)
            .map(|k| Ok((k, spring::hysteresis(mu, k, jump_in)?.w_hat)))
            .collect::<Result<Vec<_>>>()?;
        let rigid = hybrid::hysteresis(mu, jump_in)?.w_hat;
        series.push(Series::new(
            &format!("μ = {mu} (26)"),
            line,
            Style::Line,
            i + 1,
        ));
        series.push(Series::new(
            &format!("μ = {mu}, rigid support (18)"),
            vec![(k_lo, rigid), (k_hi, rigid)],
            Style::Dashed,
            i + 1,
        ));
        if let Some(solution) = lj.iter().find(|s| s.tabor_mu == mu) {
            let points = FIG6_LJ_K_HATS
                .iter()
                .map(|&k| Ok((k, solution.spring_loop(k)?.w_hat)))
                .collect::<Result<Vec<_>>>()?;
            series.push(Series::new(
                &format!("μ = {mu}, Lennard-Jones (10), numerical"),
                points,
                Style::Markers,
                i + 1,
            ));
        }
    }
    series.push(Series::new(
        "soft-support limit (27)",
        grid(k_lo, k_hi, 2, true)
            .map(|k| (k, spring::w_hat_soft_limit(k)))
            .collect(),
        Style::Dashed,
        0,
    ));
    Ok(Chart {
        name: "fig6_hysteresis_vs_stiffness".into(),
        title: "Fig. 6  Hysteresis loss vs support stiffness".into(),
        x: Axis::log("support stiffness μεk/(RΔγ)", "k_hat").with_range(k_lo, k_hi),
        y: Axis::log("hysteresis loss W/(μεRΔγ)", "w_hat").with_range(1.0, 2e3),
        series,
        labels: vec![],
        legend: Corner::UpperRight,
    })
}
