//! Tests of `tapsim::app::report::records` (src/app/report/records.rs).

use serde::Serialize;
use serde_json::Value;
use tapsim::app::report::records::*;

/// Round-off that made a 90 into 89.99999999999999 or 16 nm into 1.599999999979915e-8
/// m is gone; a value with ten significant digits keeps them all; zeros are `0`.
#[test]
fn csv_numbers_drop_round_off_and_keep_ten_digits() {
    assert_eq!(csv_number(89.99999999999999), "90");
    assert_eq!(csv_number(90.00000000000001), "90");
    assert_eq!(csv_number(1.599999999979915e-8), "1.6e-8");
    assert_eq!(csv_number(2.3589743589743588e-8), "2.358974359e-8");
    assert_eq!(csv_number(-0.0), "0");
    assert_eq!(csv_number(0.0), "0");
    assert_eq!(csv_number(-1.25e-19), "-1.25e-19");
    // Against the standard library's own rounding, over many magnitudes: the cell
    // reads back as the value to within half a unit of the tenth digit.
    for i in 0..2000 {
        let x = (i as f64 * 0.7371).sin() * 10f64.powi(i % 60 - 30);
        if x == 0.0 {
            continue;
        }
        let back: f64 = csv_number(x).parse().unwrap();
        assert!(((back - x) / x).abs() <= 5e-10, "{x} -> {back}");
        let digits = csv_number(x)
            .split(['e', 'E'])
            .next()
            .unwrap()
            .chars()
            .filter(|c| c.is_ascii_digit())
            .collect::<String>();
        let significant = digits.trim_start_matches('0').trim_end_matches('0');
        assert!(significant.len() <= CSV_DIGITS, "{x}");
    }
}

/// Arrays become numbered columns, complex pairs `_re`/`_im`, no JSON in a cell.
#[test]
fn csv_cells_hold_no_json() {
    #[derive(Serialize)]
    struct R {
        floquet_multipliers: Vec<[f64; 2]>,
        materials: Vec<&'static str>,
        inner: Inner,
    }
    #[derive(Serialize)]
    struct Inner {
        e_j: f64,
    }
    let csv = records_csv(&[R {
        floquet_multipliers: vec![[0.5, 0.25], [0.5, -0.25]],
        materials: vec!["a", "b"],
        inner: Inner { e_j: 1.0 },
    }])
    .unwrap();
    let text = String::from_utf8(csv).unwrap();
    assert_eq!(
        text,
        "floquet_multipliers_1_re,floquet_multipliers_1_im,floquet_multipliers_2_re,\
         floquet_multipliers_2_im,materials_1,materials_2,inner_e_j\n\
         0.5,0.25,0.5,-0.25,a,b,1\n"
    );
}

/// Every document starts with its format version, then the value's own keys.
#[test]
fn a_document_leads_with_its_format_version() {
    let text = document(&serde_json::json!({"b": 1, "a": 2})).unwrap();
    let v: Value = serde_json::from_str(&text).unwrap();
    let keys: Vec<&String> = v.as_object().unwrap().keys().collect();
    assert_eq!(keys, ["format_version", "b", "a"]);
    assert_eq!(v["format_version"], FORMAT_VERSION);
    assert!(document(&[1, 2]).is_err());
}
