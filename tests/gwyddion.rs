//! Images in Gwyddion's formats (issue 49, item 1): a `.gsf` read back by a reader
//! written here from Gwyddion's published description of the format (user guide,
//! "Simple Field Files"), its values the scan's JSON to float32 rounding, the top row
//! the last line; bad paths refused before any work. (The `.gwy` is read back by the
//! independent `gwyfile` reader in the Python tests, and CI has Gwyddion itself open
//! both.)

use crate::common;
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

/// A sharded image merges into the Gwyddion files one whole run writes, byte for byte
/// (`merge --out image.gwy --out image.gsf`), in both imaging modes: the parts carry the
/// image's size and metadata. A map's parts have no image to write; a place no one may
/// write (sysfs, read-only for root too) is refused before any work, nothing written.
#[test]
fn a_sharded_image_merges_into_the_whole_runs_gwyddion_files() {
    let dir = scratch("gwyddion_merge");
    let run = |args: &[&str]| run_limited(args, &dir, Duration::from_secs(120));
    for mode in ["tapping", "peakforce"] {
        let scan = |extra: &[&str]| {
            let mut args = vec![
                "scan",
                "--mode",
                mode,
                "--lines",
                "4",
                "--pixels",
                "6",
                "--line-rate",
                "10",
                "--quiet",
            ];
            args.extend_from_slice(extra);
            let out = run(&args);
            assert_eq!(out.code, Some(0), "{args:?}: {}", out.stderr);
        };
        scan(&["--gwy", "whole.gwy", "--gsf", "whole.gsf"]);
        scan(&["--shard", "0/2", "--part", "p0.json"]);
        scan(&["--shard", "1/2", "--part", "p1.json"]);
        let out = run(&[
            "merge",
            "p1.json",
            "p0.json",
            "--out",
            "merged.gwy",
            "--out",
            "merged.gsf",
            "--quiet",
        ]);
        assert_eq!(out.code, Some(0), "{mode}: {}", out.stderr);
        let whole = std::fs::read(dir.join("whole.gwy")).unwrap();
        assert_eq!(&whole[..4], b"GWYP");
        assert_eq!(
            whole,
            std::fs::read(dir.join("merged.gwy")).unwrap(),
            "{mode}"
        );
        let mut files = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let name = entry.unwrap().file_name().into_string().unwrap();
            if let Some(channel) = name.strip_prefix("whole_") {
                let merged = dir.join(format!("merged_{channel}"));
                assert_eq!(
                    std::fs::read(dir.join(&name)).unwrap(),
                    std::fs::read(&merged).unwrap(),
                    "{mode}: {name}"
                );
                files += 1;
            }
        }
        assert!(files >= 10, "{mode}: {files} channel files");
        for entry in std::fs::read_dir(&dir).unwrap() {
            std::fs::remove_file(entry.unwrap().path()).unwrap();
        }
    }
    let out = run(&[
        "map", "--steps", "2", "--shard", "0/1", "--part", "map.json", "--quiet",
    ]);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    let out = run(&["merge", "map.json", "--out", "map.gwy"]);
    assert_eq!(out.code, Some(1));
    assert!(out.stderr.contains("scanned image's"), "{}", out.stderr);
    assert!(!dir.join("map.gwy").exists());
    if std::path::Path::new("/sys/kernel").is_dir() {
        let out = run(&[
            "scan",
            "--lines",
            "2",
            "--pixels",
            "4",
            "--gwy",
            "/sys/image.gwy",
            "--csv",
            "new.csv",
        ]);
        assert_eq!(out.code, Some(1), "{}", out.stderr);
        assert!(out.stderr.contains("/sys/image.gwy"), "{}", out.stderr);
        assert!(out.elapsed < Duration::from_secs(5));
        assert!(!dir.join("new.csv").exists());
    }
    let _ = std::fs::remove_dir_all(&dir);
}
