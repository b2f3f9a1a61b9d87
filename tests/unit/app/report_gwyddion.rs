//! Tests of `tapsim::app::report::gwyddion` (src/app/report/gwyddion.rs).

use tapsim::app::report::gwyddion::*;

fn channel() -> Channel {
    Channel {
        title: "Topography (trace)".into(),
        unit: "m".into(),
        xres: 3,
        yres: 2,
        size_m: (3e-6, 2e-6),
        values: vec![1e-9, 2e-9, 3e-9, 4e-9, f64::NAN, 6e-9],
    }
}

#[test]
fn a_gsf_header_is_aligned_and_its_data_follow_as_float32() {
    let bytes = gsf(&channel(), &[("law".into(), "hybrid".into())]);
    let nul = bytes.iter().position(|&b| b == 0).unwrap();
    let head = std::str::from_utf8(&bytes[..nul]).unwrap();
    assert!(head.starts_with("Gwyddion Simple Field 1.0\nXRes = 3\nYRes = 2\n"));
    assert!(head.contains("ZUnits = m\n") && head.contains("law = hybrid\n"));
    assert!(head.contains("MissingValues = 1 written as 0\n"));
    let start = bytes.len() - 6 * 4;
    assert_eq!(start % 4, 0);
    assert!((1..=4).contains(&(start - nul)));
    assert!(bytes[nul..start].iter().all(|&b| b == 0));
    let value =
        |i: usize| f32::from_le_bytes(bytes[start + 4 * i..start + 4 * i + 4].try_into().unwrap());
    assert_eq!(value(0), 1e-9_f32);
    assert_eq!(value(4), 0.0);
    assert_eq!(value(5), 6e-9_f32);
}

#[test]
fn a_gwy_object_states_the_size_of_its_components() {
    let bytes = gwy(&[channel()], &[("law".into(), "hybrid".into())]);
    assert_eq!(&bytes[..4], b"GWYP");
    assert_eq!(&bytes[4..17], b"GwyContainer\0");
    let size = u32::from_le_bytes(bytes[17..21].try_into().unwrap()) as usize;
    assert_eq!(21 + size, bytes.len());
    // The data array: 6 doubles after "data\0D" and its count.
    let at = bytes.windows(6).position(|w| w == b"data\0D").unwrap() + 6;
    assert_eq!(u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()), 6);
    let first = f64::from_le_bytes(bytes[at + 4..at + 12].try_into().unwrap());
    assert_eq!(first, 1e-9);
}

#[test]
fn levelling_removes_a_plane_and_keeps_what_lies_on_it_at_zero() {
    let (xres, yres) = (5, 4);
    let plane: Vec<f64> = (0..xres * yres)
        .map(|i| 2.0 + 0.3 * (i % xres) as f64 - 0.7 * (i / xres) as f64)
        .collect();
    for v in plane_levelled(&plane, xres) {
        assert!(v.abs() < 1e-12, "{v}");
    }
    let mut bump = plane.clone();
    bump[7] += 1.0;
    let levelled = plane_levelled(&bump, xres);
    assert!(levelled[7] > 0.9 && levelled.iter().sum::<f64>().abs() < 1e-12);
}
