//! `tapsim reconstruct` from the command line: the CSV `tapsim approach --csv` writes,
//! read back as the force that made it, and data refused with a message that says why.

use crate::common;
use common::{json, refused, scratch, tapsim};

/// A DMT approach curve written by `tapsim approach --csv` gives back, through the
/// command line, the law's force at every reconstructed distance within 5 % of the
/// largest (the library test holds the numbers; this checks the file's path through the
/// reader and the outputs: JSON columns, CSV, plot, and the law beside).
#[test]
fn an_approach_csv_is_reconstructed_with_the_law_beside() {
    let dir = scratch("reconstruct-cli");
    let csv = dir.join("dmt.csv");
    let csv = csv.to_str().unwrap();
    let law = ["--law", "dmt", "--work-of-adhesion", "0.02"];
    let mut approach = vec![
        "approach", "--from", "30nm", "--to", "6nm", "--points", "120", "-q", "--csv", csv,
    ];
    approach.extend(law);
    let out = tapsim(&approach);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out_csv = dir.join("force.csv");
    let plot = dir.join("force.svg");
    let mut args = vec![
        "reconstruct",
        csv,
        "--with-law",
        "--json",
        "-q",
        "--csv",
        out_csv.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
    ];
    args.extend(law);
    let v = json(&args);
    let p = &v;
    let col = |k: &str| -> Vec<f64> {
        p[k].as_array()
            .unwrap_or_else(|| panic!("no column {k}"))
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let (f, law_in, d) = (
        col("force_n"),
        col("law_approach_force_n"),
        col("closest_m"),
    );
    assert!(f.len() > 60, "{}", f.len());
    assert!(d.windows(2).all(|w| w[0] < w[1]), "D not increasing");
    let largest = law_in.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for (a, b) in f.iter().zip(&law_in) {
        assert!((a - b).abs() < 0.05 * largest, "{a:e} vs {b:e}");
    }
    assert_eq!(col("law_retract_force_n"), law_in, "a conservative law");
    let written = std::fs::read_to_string(&out_csv).unwrap();
    assert!(written.starts_with("separation_m,closest_m,"), "{written}");
    assert_eq!(written.lines().count(), f.len() + 1);
    assert!(std::fs::read_to_string(&plot).unwrap().contains("<svg"));

    // The retract rows, asked for, are another branch: read, not mixed in.
    let both = dir.join("both.csv");
    let both = both.to_str().unwrap();
    let mut approach = vec![
        "approach", "--from", "30nm", "--to", "6nm", "--points", "30", "-q", "--csv", both,
    ];
    approach.extend(law);
    assert!(tapsim(&approach).status.success());
    let mut args = vec!["reconstruct", both, "--direction", "retract", "--json"];
    args.extend(law);
    let v = json(&args);
    assert!(v["force_n"].as_array().unwrap().len() > 3);
}

/// Files it cannot invert are refused with the reason: no phase column, a plot that is
/// not .png or .svg, no rows of the branch asked for, a file that is not there.
#[test]
fn curves_it_cannot_read_are_refused() {
    let dir = scratch("reconstruct-cli-bad");
    let no_phase = dir.join("no_phase.csv");
    std::fs::write(&no_phase, "z_nm,amplitude_nm\n30,20\n29,19.9\n28,19.8\n").unwrap();
    refused(
        &["reconstruct", no_phase.to_str().unwrap()],
        "both the amplitude and the phase",
    );
    let ok = dir.join("ok.csv");
    std::fs::write(
        &ok,
        "z_nm,amplitude_nm,phase_deg,direction\n30,20,90,approach\n29,19.9,91,approach\n\
         28,19.8,92,approach\n",
    )
    .unwrap();
    let ok = ok.to_str().unwrap();
    refused(&["reconstruct", ok, "--plot", "f.pdf"], ".png or .svg");
    refused(&["reconstruct", ok, "--direction", "retract"], "no rows");
    refused(&["reconstruct", "/nonexistent/curve.csv"], "curve.csv");
}
