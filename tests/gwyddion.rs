//! Images in Gwyddion's formats (issue 49, item 1): a `.gsf` read back by a reader
//! written here from Gwyddion's published description of the format (user guide,
//! "Simple Field Files"), its values the scan's JSON to float32 rounding, the top row
//! the last line; bad paths refused before any work. (The `.gwy` is read back by the
//! independent `gwyfile` reader in the Python tests, and CI has Gwyddion itself open
//! both.)

mod common;
use common::{run_limited, scratch};
use std::collections::HashMap;
use std::time::Duration;

/// A GSF file: the magic line, `name = value` lines, one to four NULs to a multiple of
/// 4, then XRes·YRes little-endian float32 values, row by row.
fn read_gsf(bytes: &[u8]) -> (HashMap<String, String>, Vec<f32>) {
    let magic = b"Gwyddion Simple Field 1.0\n";
    assert_eq!(&bytes[..magic.len()], magic);
    let end = bytes
        .iter()
        .position(|&b| b == 0)
        .expect("a NUL ends the header");
    let header: HashMap<String, String> = std::str::from_utf8(&bytes[magic.len()..end])
        .unwrap()
        .lines()
        .map(|l| {
            let (k, v) = l.split_once('=').expect("name = value");
            (k.trim().to_string(), v.trim().to_string())
        })
        .collect();
    let start = (end / 4 + 1) * 4;
    assert!(bytes[end..start].iter().all(|&b| b == 0));
    let values: Vec<f32> = bytes[start..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let (xres, yres): (usize, usize) = (
        header["XRes"].parse().unwrap(),
        header["YRes"].parse().unwrap(),
    );
    assert_eq!(values.len(), xres * yres);
    assert_eq!(bytes.len() - start, 4 * xres * yres);
    (header, values)
}

#[test]
fn a_qnm_image_reads_back_from_its_gsf_files() {
    let dir = scratch("gwyddion");
    let run = |args: &[&str]| run_limited(args, &dir, Duration::from_secs(60));
    let (lines, pixels) = (3usize, 6usize);
    let out = run(&[
        "scan",
        "--mode",
        "peakforce",
        "--lines",
        "3",
        "--pixels",
        "6",
        "--json",
        "--gsf",
        "image.gsf",
        "--gwy",
        "image.gwy",
    ]);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    let v: serde_json::Value = serde_json::from_str(&out.stdout).unwrap();
    let trace: Vec<usize> = (0..2 * lines * pixels)
        .filter(|&i| v["direction"][i] == "trace")
        .collect();
    assert_eq!(trace.len(), lines * pixels);
    for (file, key, unit) in [
        ("image_topography_trace.gsf", "topography_m", "m"),
        ("image_adhesion_trace.gsf", "adhesion_n", "N"),
        ("image_dissipation_trace.gsf", "dissipation_j", "J"),
    ] {
        let (header, values) = read_gsf(&std::fs::read(dir.join(file)).unwrap());
        assert_eq!(header["XRes"], "6");
        assert_eq!(header["YRes"], "3");
        assert_eq!(header["XReal"].parse::<f64>().unwrap(), 1e-6);
        assert_eq!(header["YReal"].parse::<f64>().unwrap(), 1e-6);
        assert_eq!(header["XYUnits"], "m");
        assert_eq!(header["ZUnits"], unit);
        assert_eq!(header["Mode"], "off-resonance tapping (peak-force)");
        // Row r of the file is line lines−1−r (the top of the image first).
        for (k, &i) in trace.iter().enumerate() {
            let (line, pixel) = (k / pixels, k % pixels);
            let row = lines - 1 - line;
            let json = v[key][i].as_f64().unwrap();
            assert_eq!(
                values[row * pixels + pixel],
                json as f32,
                "{file} ({line}, {pixel})"
            );
        }
    }
    // The levelled topography lies on no plane.
    let (_, levelled) =
        read_gsf(&std::fs::read(dir.join("image_topography_levelled_trace.gsf")).unwrap());
    assert!(levelled.iter().map(|&x| f64::from(x)).sum::<f64>().abs() < 1e-15);
    let gwy = std::fs::read(dir.join("image.gwy")).unwrap();
    assert_eq!(&gwy[..4], b"GWYP");
    // Bad paths: refused before any work, nothing written.
    for (args, says) in [
        (vec!["--gwy", "image.png"], "give a .gwy file"),
        (vec!["--gsf", "missing/x.gsf"], "missing"),
        (
            vec!["--gwy", "part.gwy", "--shard", "0/2"],
            "writes only its part file",
        ),
    ] {
        let mut all = vec!["scan", "--lines", "2", "--pixels", "4"];
        all.extend(&args);
        let out = run(&all);
        assert_eq!(out.code, Some(1), "{args:?}: {}", out.stderr);
        assert!(out.stderr.contains(says), "{args:?}: {}", out.stderr);
        assert!(out.elapsed < Duration::from_secs(5), "{args:?}");
    }
    assert!(!dir.join("part.gwy").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
