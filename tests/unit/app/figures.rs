//! Tests of `tapsim::app::figures` (src/app/figures.rs).

#[test]
fn the_figures_without_a_lennard_jones_solution_have_clear_legends() {
    for n in [1, 5] {
        let c = tapsim::app::figures::figure(n, &Default::default()).unwrap();
        assert_eq!(
            tapsim::app::report::plot::legend_covers(&c),
            0,
            "figure {n}"
        );
    }
}
