//! Tests of `tapsim::analysis::fit::solve` (src/analysis/fit/solve.rs).

use nalgebra::DVector;
use tapsim::analysis::fit::local::LocalRun;
use tapsim::analysis::fit::model::{Curve, Nuisance, Parameter};
use tapsim::analysis::fit::solve::*;
use tapsim::dynamics::setup::default_setup;

fn run_at(values: [f64; 2], out_of_budget: bool) -> LocalRun {
    LocalRun {
        setup: default_setup(),
        nuisance: Nuisance::offset(0.0),
        values: values.to_vec(),
        curve: Curve::default(),
        residuals: DVector::from_vec(vec![3.0, 4.0]),
        termination: String::new(),
        lm_converged: !out_of_budget,
        out_of_budget,
    }
}

/// A run cut short by its budget is listed as such, unless a run that converged
/// ended at the same point (then it is a minimum, whichever came first).
#[test]
fn a_run_cut_short_is_no_minimum_unless_another_converged_there() {
    let params = [Parameter::Modulus, Parameter::WorkOfAdhesion];
    let (a, b) = ([0.8e9, 0.07], [1.34e9, 0.116]);
    let runs = [run_at(a, true), run_at(a, false), run_at(b, true)];
    let minima = distinct_minima(runs.iter(), &params, 10);
    assert_eq!(minima.len(), 2);
    assert_eq!((minima[0].runs, minima[0].cut_short), (2, false));
    assert_eq!((minima[1].runs, minima[1].cut_short), (1, true));
    assert_eq!(minima[1].reduced_chi_square, 2.5);
}
