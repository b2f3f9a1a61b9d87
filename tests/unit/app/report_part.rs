//! Tests of `tapsim::app::report::part` (src/app/report/part.rs).

use tapsim::app::report::part::*;

#[test]
fn missing_parts_read_as_an_sbatch_array() {
    assert_eq!(array_spec(&[2]), "2");
    assert_eq!(array_spec(&[0, 1, 2, 5, 7, 8]), "0-2,5,7-8");
    assert_eq!(array_spec(&[]), "");
}
