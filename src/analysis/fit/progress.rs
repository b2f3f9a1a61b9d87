//! What a running fit tells its caller: the stage, the curves simulated, the best χ²
//! so far and an estimate of the time left (no I/O: the caller draws it).

use serde::Serialize;
use std::sync::Mutex;
use std::time::Instant;

/// A fit's stage.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case", tag = "stage")]
pub enum Stage {
    /// The global stage: design points screened so far of all.
    Design {
        /// Points screened.
        done: usize,
        /// Points in the design.
        total: usize,
    },
    /// Levenberg–Marquardt from start `index` (from 1) of `of`.
    Local {
        /// Which start.
        index: usize,
        /// Starts in all.
        of: usize,
    },
    /// A run cut short at its first share of the budget going on (`index` of `of`
    /// such runs, the lowest χ² first), none of the starts having ended on a minimum
    /// that describes the data.
    Continue {
        /// Which cut run.
        index: usize,
        /// Cut runs in all.
        of: usize,
    },
    /// Levenberg–Marquardt again from the best minimum, without the points grazing a
    /// switch there.
    WithoutGrazing {
        /// Points left out.
        left_out: usize,
    },
    /// The Jacobian and statistics at the best minimum.
    Assess,
    /// A profile: a parameter held at values about its estimate.
    Profile,
}

/// One report of progress.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Progress {
    /// Where the fit is.
    pub stage: Stage,
    /// Curves simulated so far.
    pub curves: usize,
    /// The least χ² met so far (None before the first curve).
    pub best_chi_square: Option<f64>,
    /// Seconds since the fit began.
    pub elapsed_s: f64,
    /// A rough estimate of the seconds left (the curves still expected at the mean
    /// time a curve has taken in this stage — the design's screened curves are far
    /// cheaper than the local runs' whole ones), where one can be made.
    pub remaining_s: Option<f64>,
}

/// The shared state behind [`Progress`] reports (used from the design's threads).
#[doc(hidden)]
pub struct Tracker<'a> {
    state: Mutex<State>,
    report: &'a (dyn Fn(&Progress) + Sync),
    began: Instant,
}

struct State {
    stage: Stage,
    curves: usize,
    best: Option<f64>,
    /// Curves still expected after this stage's (for the estimate).
    expected_after: usize,
    /// Curves expected in this stage in all, and simulated when it began.
    expected_stage: usize,
    stage_began_at: usize,
    /// Seconds from the start of the fit to the start of this stage.
    stage_began_s: f64,
}

impl<'a> Tracker<'a> {
    /// A tracker reporting to `report`.
    pub fn new(report: &'a (dyn Fn(&Progress) + Sync)) -> Self {
        Self {
            state: Mutex::new(State {
                stage: Stage::Assess,
                curves: 0,
                best: None,
                expected_after: 0,
                expected_stage: 0,
                stage_began_at: 0,
                stage_began_s: 0.0,
            }),
            report,
            began: Instant::now(),
        }
    }

    /// Enter `stage`, expecting `curves` in it and `after` in the stages that follow.
    pub fn stage(&self, stage: Stage, curves: usize, after: usize) {
        let progress = {
            let mut s = self.state.lock().expect("progress lock");
            s.stage = stage;
            s.expected_stage = curves;
            s.expected_after = after;
            s.stage_began_at = s.curves;
            s.stage_began_s = self.began.elapsed().as_secs_f64();
            self.progress(&s)
        };
        (self.report)(&progress);
    }

    /// One curve simulated, with its χ² (None: it could not be).
    pub fn curve(&self, chi_square: Option<f64>) {
        let progress = {
            let mut s = self.state.lock().expect("progress lock");
            s.curves += 1;
            if let Some(c) = chi_square.filter(|c| c.is_finite()) {
                s.best = Some(s.best.map_or(c, |b: f64| b.min(c)));
            }
            self.progress(&s)
        };
        (self.report)(&progress);
    }

    /// A design point screened (its curves were counted as they came).
    pub fn design_point(&self) {
        let progress = {
            let mut s = self.state.lock().expect("progress lock");
            if let Stage::Design { done, .. } = &mut s.stage {
                *done += 1;
            }
            self.progress(&s)
        };
        (self.report)(&progress);
    }

    /// Curves simulated so far.
    pub fn curves(&self) -> usize {
        self.state.lock().expect("progress lock").curves
    }

    fn progress(&self, s: &State) -> Progress {
        let elapsed = self.began.elapsed().as_secs_f64();
        let in_stage = s.curves - s.stage_began_at;
        let left = s.expected_stage.saturating_sub(in_stage) + s.expected_after;
        let per_curve_s = if in_stage > 0 {
            Some((elapsed - s.stage_began_s) / in_stage as f64)
        } else {
            (s.curves > 0).then(|| elapsed / s.curves as f64)
        };
        Progress {
            stage: s.stage,
            curves: s.curves,
            best_chi_square: s.best,
            elapsed_s: elapsed,
            remaining_s: per_curve_s.map(|t| t * left as f64),
        }
    }
}
