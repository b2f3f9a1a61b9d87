//! Tests of `tapsim::app::cli` (src/app/cli/mod.rs).

/// A command line summarises only the subcommand it runs, and that subcommand's
/// `-h` and `--help` read as they do from the whole summarised definition.
#[test]
fn the_running_subcommand_is_summarised_as_in_the_whole_definition() {
    let words = |line: &str| -> Vec<std::ffi::OsString> {
        line.split_whitespace().map(Into::into).collect()
    };
    assert_eq!(
        tapsim::app::cli::subcommand_named(&words("tapsim tap -h")),
        "tap"
    );
    assert_eq!(
        tapsim::app::cli::subcommand_named(&words("tapsim help scan")),
        "scan"
    );
    assert_eq!(
        tapsim::app::cli::subcommand_named(&words("tapsim --version")),
        ""
    );
    let mut whole = tapsim::app::cli::command();
    for name in ["tap", "scan", "fit", "thermal"] {
        let mut alone = tapsim::app::cli::command_for(Some(name));
        let (a, w) = (
            alone.find_subcommand_mut(name).unwrap(),
            whole.find_subcommand_mut(name).unwrap(),
        );
        assert_eq!(a.render_help().to_string(), w.render_help().to_string());
        assert_eq!(
            a.render_long_help().to_string(),
            w.render_long_help().to_string()
        );
    }
}

/// The summary keeps what says what a flag is and its default, and leaves the
/// remarks, the equation numbers and the next sentences to --help.
#[test]
fn a_summary_is_the_first_clause_without_remarks() {
    for (help, summary) in [
        (
            "Dimensionless support stiffness k̂ = μεk/(RΔγ), eq. (23) [> 0]",
            "Dimensionless support stiffness k̂ = μεk/(RΔγ) [> 0]",
        ),
        (
            "Amplitude setpoint A/A₀ in place of a rest separation (between 0 and 1; as \
             an AFM's z feedback holds it): every stable state",
            "Amplitude setpoint A/A₀ in place of a rest separation",
        ),
        (
            "Quality factor Q [default 400]. (Also --Q.)",
            "Quality factor Q [default 400]",
        ),
        (
            "The branch whose states a setpoint lists [default: all]. Attractive: the \
             phase lag above",
            "The branch whose states a setpoint lists [default: all]",
        ),
        (
            "Cantilever eigenmodes [1 to 3; default 1]. 2 is bimodal AFM",
            "Cantilever eigenmodes [1 to 3; default 1]",
        ),
        (
            "A material, name:key=value,... (repeat; at least two).",
            "A material, name:key=value,...",
        ),
        (
            "Tabor parameter μ, eq. (8) [dimensionless]",
            "Tabor parameter μ [dimensionless]",
        ),
        ("Print help", "Print help"),
    ] {
        assert_eq!(tapsim::app::cli::first_clause(help), summary, "{help}");
    }
}
