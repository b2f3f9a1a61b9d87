//! What tapsim does to the files it is pointed at: special files are written through and
//! never replaced, links are followed, missing directories and foreign directories are
//! refused, an interrupted run leaves no temporary file; and how much memory the most
//! demanding requests take.

use crate::common;
use common::scratch;
use std::os::unix::fs::FileTypeExt;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn tapsim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_tapsim"))
}

fn run(args: &[&str]) -> Output {
    tapsim().args(args).output().expect("the binary runs")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Names in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Make a special file with `tool` (mknod, mkfifo); false (with a message) where this
/// machine does not permit it.
fn make(tool: &str, args: &[&str]) -> bool {
    match Command::new(tool).args(args).output() {
        Ok(out) if out.status.success() => true,
        Ok(out) => {
            eprintln!(
                "skipped: {tool} not permitted here: {}",
                stderr(&out).trim()
            );
            false
        }
        Err(e) => {
            eprintln!("skipped: no {tool}: {e}");
            false
        }
    }
}

#[test]
fn a_device_node_is_written_through_not_replaced() {
    let dir = scratch("mknod");
    let null = dir.join("null");
    if !make("mknod", &[path(&null), "c", "1", "3"]) {
        return;
    }
    for flag in ["--trajectory", "--plot"] {
        let out = run(&["tap", flag, path(&null)]);
        // --plot refuses a name without .png/.svg before touching anything.
        if flag == "--trajectory" {
            assert!(out.status.success(), "{}", stderr(&out));
        }
        let kind = std::fs::symlink_metadata(&null).unwrap().file_type();
        assert!(
            kind.is_char_device(),
            "{flag}: the device node was replaced"
        );
    }
    assert_eq!(listing(&dir), ["null"]);
}

#[test]
fn a_full_device_is_an_error_and_stays_a_device() {
    let dir = scratch("full");
    let full = dir.join("full");
    if !make("mknod", &[path(&full), "c", "1", "7"]) {
        return;
    }
    let out = run(&["tap", "--trajectory", path(&full)]);
    assert_eq!(out.status.code(), Some(1));
    let e = stderr(&out);
    assert!(e.contains("No space left") && e.contains("full"), "{e}");
    assert!(!e.contains("partial"), "{e}");
    assert!(
        std::fs::symlink_metadata(&full)
            .unwrap()
            .file_type()
            .is_char_device()
    );
    assert_eq!(listing(&dir), ["full"]);
}

#[test]
fn a_fifo_is_written_through_to_its_reader() {
    let dir = scratch("fifo");
    let fifo = dir.join("pipe.csv");
    if !make("mkfifo", &[path(&fifo)]) {
        return;
    }
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
    };
    let out = run(&["tap", "--trajectory", path(&fifo)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = reader.join().unwrap();
    assert!(
        text.starts_with("t_s,z_m,"),
        "{}",
        &text[..text.len().min(80)]
    );
    assert!(
        std::fs::symlink_metadata(&fifo)
            .unwrap()
            .file_type()
            .is_fifo()
    );
    assert_eq!(listing(&dir), ["pipe.csv"]);
}

#[test]
fn a_symlink_is_kept_and_its_target_replaced() {
    let dir = scratch("link");
    std::fs::write(dir.join("target.csv"), "old").unwrap();
    std::os::unix::fs::symlink("target.csv", dir.join("link.csv")).unwrap();
    let out = run(&["tap", "--trajectory", path(&dir.join("link.csv"))]);
    assert!(out.status.success(), "{}", stderr(&out));
    let link = std::fs::symlink_metadata(dir.join("link.csv")).unwrap();
    assert!(link.file_type().is_symlink());
    let text = std::fs::read_to_string(dir.join("target.csv")).unwrap();
    assert!(text.starts_with("t_s,z_m,"));
    assert_eq!(listing(&dir), ["link.csv", "target.csv"]);
}

#[test]
fn missing_and_foreign_directories_are_refused() {
    let dir = scratch("dirs");
    let plot = dir.join("no/such/dir/x.png");
    let out = run(&["tap", "--plot", path(&plot)]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("does not exist"), "{}", stderr(&out));
    assert!(!dir.join("no").exists());
    // A directory holding someone else's files is not filled with reproduce's.
    std::fs::write(dir.join("thesis.tex"), "mine").unwrap();
    let out = run(&["reproduce", "--quiet", "--out", path(&dir)]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("not empty"), "{}", stderr(&out));
    assert_eq!(listing(&dir), ["thesis.tex"]);
    // `figure` writes into figures/, not into the committed results/.
    let out = tapsim()
        .args(["figure", "1"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(listing(&dir), ["figures", "thesis.tex"]);
    assert!(dir.join("figures/fig1_jkr_cycle.png").is_file());
}

#[test]
fn an_interrupted_run_leaves_no_temporary_file() {
    let dir = scratch("sigint");
    let fifo = dir.join("pipe.csv");
    if !make("mkfifo", &[path(&fifo)]) {
        return;
    }
    let tmp = dir.join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    // With no reader, writing through to the FIFO blocks while the rendered output waits
    // in the temporary directory: interrupt it there.
    let mut child = tapsim()
        .args(["tap", "--trajectory", path(&fifo)])
        .env("TMPDIR", &tmp)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while listing(&tmp).is_empty() {
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "no temporary file"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(listing(&tmp)[0].contains(".partial-"));
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    assert!(listing(&tmp).is_empty(), "{:?}", listing(&tmp));
}

/// Peak resident memory of a run in bytes (the kernel's high-water mark, read until the
/// process ends) and its output.
fn peak_memory(args: &[&str], dir: &Path) -> (u64, Output) {
    let child = tapsim()
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let status = format!("/proc/{}/status", child.id());
    let watcher = std::thread::spawn(move || {
        let mut peak = 0u64;
        while let Ok(text) = std::fs::read_to_string(&status) {
            let Some(kb) = text
                .lines()
                .find_map(|l| l.strip_prefix("VmHWM:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
            else {
                break; // a zombie has no memory left to report
            };
            peak = peak.max(kb * 1024);
            std::thread::sleep(Duration::from_millis(2));
        }
        peak
    });
    let out = child.wait_with_output().unwrap();
    (watcher.join().unwrap(), out)
}

/// The bound the guide states.
const MEMORY_BOUND: u64 = 300 << 20;

#[test]
fn peak_memory_is_bounded_at_the_largest_requests() {
    if !Path::new("/proc/self/status").exists() {
        eprintln!("skipped: no /proc to read peak memory from");
        return;
    }
    let dir = scratch("memory");
    let cases: &[&[&str]] = &[
        // The most trajectory a run records, with every output.
        &[
            "tap",
            "--record-cycles",
            "300",
            "--trajectory",
            "t.csv",
            "--plot",
            "t.svg",
        ],
        // More than it records: refused once the cap is reached.
        &["tap", "--record-cycles", "1000", "--trajectory", "t.csv"],
        // The most Poincaré samples.
        &[
            "bifurcation",
            "--law",
            "none",
            "--points",
            "20",
            "--samples",
            "10000",
            "--csv",
            "b.csv",
            "--plot",
            "b.svg",
            "--json",
            "--quiet",
        ],
        // The largest map.
        &[
            "map", "--law", "none", "--steps", "200", "--csv", "m.csv", "--plot", "m.svg",
            "--json", "--quiet",
        ],
        // The longest approach.
        &[
            "approach", "--law", "none", "--points", "2000", "--csv", "a.csv", "--plot", "a.svg",
            "--json", "--quiet",
        ],
    ];
    for args in cases {
        let (peak, out) = peak_memory(args, &dir);
        println!("{args:?}: peak {} MB", peak >> 20);
        assert!(
            out.status.code() == Some(0) || args[2] == "1000",
            "{args:?}: {}",
            stderr(&out)
        );
        assert!(peak > 0, "{args:?}: no memory reading");
        assert!(peak < MEMORY_BOUND, "{args:?}: peak {} MB", peak >> 20);
    }
    // Requests beyond the limits are refused before anything is allocated.
    for args in [
        &["approach", "--points", "100000000"][..],
        &["map", "--steps", "100000"],
        &["tap", "--record-cycles", "100000", "--trajectory", "t.csv"],
        &["bifurcation", "--points", "2000", "--samples", "10000"],
        &["map", "--threads", "1000000000"],
    ] {
        let (peak, out) = peak_memory(args, &dir);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert!(peak < 64 << 20, "{args:?}: peak {} MB", peak >> 20);
    }
}

/// Start `tapsim reproduce` into `out`, interrupt it (SIGINT) once it has written its
/// first figure, and check it stopped as interrupted (exit 130), unfinished (no README)
/// and marked as such.
fn reproduce_interrupted(dir: &Path, out: &Path) {
    let mut child = tapsim()
        .args(["reproduce", "--quiet", "--out", path(out)])
        .env("TAPSIM_CACHE", dir.join("cache"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !out.join("fig1_jkr_cycle.csv").exists() {
        if let Some(status) = child.try_wait().unwrap() {
            let mut why = String::new();
            std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut why).unwrap();
            panic!("reproduce ended with {status} before writing: {why}");
        }
        assert!(start.elapsed() < Duration::from_secs(60), "nothing written");
        std::thread::sleep(Duration::from_millis(5));
    }
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    assert_eq!(child.wait().unwrap().code(), Some(130));
    assert!(!out.join("README.md").exists(), "it was not interrupted");
    assert!(
        listing(out)
            .iter()
            .any(|n| n.starts_with(".tapsim-reproduce"))
    );
}

#[test]
fn an_interrupted_reproduce_can_be_rerun_into_its_own_directory() {
    let dir = scratch("reproduce-interrupted");
    let out = dir.join("results");
    reproduce_interrupted(&dir, &out);
    // Run again into the same directory: accepted (it writes its first figure again
    // rather than refusing the directory). (That a finished run leaves its README
    // alone, no marker, tests/cli.rs checks.)
    std::fs::remove_file(out.join("fig1_jkr_cycle.csv")).unwrap();
    reproduce_interrupted(&dir, &out);
}
