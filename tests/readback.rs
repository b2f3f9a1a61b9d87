//! Files tapsim reads back from its own earlier runs are input too (issue 25): part files
//! of a sharded map or batch, and the on-disk Lennard-Jones cache. Doctored ones are
//! refused (parts) or recomputed (cache), never believed; nothing panics, hangs or prints
//! a number that a whole run would not.

use crate::common;
use common::{Run, scratch};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

/// Every run here must end within this.
const LIMIT: Duration = Duration::from_secs(20);

/// Run the binary in `dir`, killing it at [`LIMIT`].
fn run<S: AsRef<std::ffi::OsStr>>(args: &[S], dir: &Path) -> Run {
    common::run_limited(args, dir, LIMIT)
}

fn ok(r: &Run, what: &str) {
    assert_eq!(r.code, Some(0), "{what}: {}", r.stderr);
}

/// A refusal: exit 1 (not a panic's 101, not a hang), a message on stderr, no output.
fn refused(r: &Run, what: &str) {
    assert_eq!(r.code, Some(1), "{what}: exit {:?}, {}", r.code, r.stderr);
    assert!(r.stderr.starts_with("error: "), "{what}: {}", r.stderr);
}

/// The parts of a job: (whole run's CSV, part files' JSON).
struct Job {
    dir: PathBuf,
    whole_csv: Vec<u8>,
    parts: Vec<Value>,
}

/// A job run whole into `whole.csv` and in two parts, by `command` (its arguments
/// before the output flags).
fn sharded(dir: &Path, command: &[&str]) -> Job {
    let mut whole = command.to_vec();
    whole.extend(["--quiet", "--csv", "whole.csv"]);
    ok(&run(&whole, dir), command[0]);
    let parts = (0..2)
        .map(|i| {
            let name = format!("p{i}.json");
            let shard = format!("{i}/2");
            let mut args = command.to_vec();
            args.extend(["--quiet", "--shard", &shard, "--part", &name]);
            ok(&run(&args, dir), "a part");
            serde_json::from_slice(&std::fs::read(dir.join(&name)).unwrap()).unwrap()
        })
        .collect();
    Job {
        whole_csv: std::fs::read(dir.join("whole.csv")).unwrap(),
        dir: dir.to_path_buf(),
        parts,
    }
}

fn map_job(dir: &Path) -> Job {
    sharded(dir, &["map", "--steps", "2"])
}

fn batch_job(dir: &Path) -> Job {
    std::fs::write(
        dir.join("t.csv"),
        "name,separation,command,points\na,16nm,tap,\nb,18nm,tap,\nc,,approach,3\n",
    )
    .unwrap();
    sharded(dir, &["batch", "t.csv"])
}

impl Job {
    /// Merge the parts as `change` leaves them, into a CSV and (for a map) a PNG.
    fn merge(&self, change: &dyn Fn(&mut Vec<Value>)) -> Run {
        let mut parts = self.parts.clone();
        change(&mut parts);
        let names: Vec<String> = (0..parts.len()).map(|i| format!("q{i}.json")).collect();
        for (name, p) in names.iter().zip(&parts) {
            std::fs::write(self.dir.join(name), serde_json::to_vec(p).unwrap()).unwrap();
        }
        let _ = std::fs::remove_file(self.dir.join("m.csv"));
        let mut args = vec!["merge", "--quiet", "--out", "m.csv"];
        if self.parts[0]["job"]["kind"] == "map" {
            args.extend(["--out", "m.png"]);
        }
        args.extend(names.iter().map(String::as_str));
        run(&args, &self.dir)
    }

    /// A doctored merge either is refused, or (where the change was no change to what
    /// the parts say, such as a number written another way) gives the whole run's CSV.
    fn refused_or_same(&self, r: &Run, what: &str) {
        match r.code {
            Some(0) => assert_eq!(
                std::fs::read(self.dir.join("m.csv")).unwrap(),
                self.whole_csv,
                "{what}: merged with exit 0 into another CSV than the whole run's"
            ),
            _ => refused(r, what),
        }
    }
}

/// A change of the parts.
type Change = Box<dyn Fn(&mut Vec<Value>)>;

/// The change that sets the value at `pointer` to `value` in every part.
fn set_all(pointer: &'static str, value: Value) -> Change {
    Box::new(move |ps| {
        for p in ps {
            *p.pointer_mut(pointer).expect("the field is there") = value.clone();
        }
    })
}

#[test]
fn merge_refuses_the_reported_doctored_parts() {
    let job = map_job(&scratch("reported-map"));
    // Each record of a part holds every key once (tabor_mu was written twice).
    for i in 0..2 {
        let text = std::fs::read_to_string(job.dir.join(format!("p{i}.json"))).unwrap();
        let records = job.parts[i]["records"].as_array().unwrap().len();
        assert_eq!(text.matches("\"tabor_mu\"").count(), records);
    }
    // Unchanged (read and written again): merged, the whole run's CSV.
    ok(&job.merge(&|_| {}), "unchanged");
    job.refused_or_same(&job.merge(&|_| {}), "unchanged");
    let cases: Vec<(&str, Change, &str)> = vec![
        (
            "records doubled",
            Box::new(|ps| {
                for p in ps {
                    for r in p["records"].as_array_mut().unwrap() {
                        let once = r.as_array().unwrap().clone();
                        let twice: Vec<Value> = once.iter().chain(&once).cloned().collect();
                        *r = Value::Array(twice);
                    }
                }
            }),
            "records hold 2 records for cell",
        ),
        (
            "an empty axis",
            Box::new(|ps| {
                for p in ps {
                    p["job"]["work_of_adhesion_j_m2"] = Value::Array(vec![]);
                    p["items"] = Value::Array(vec![]);
                    p["records"] = Value::Array(vec![]);
                }
            }),
            "job.work_of_adhesion_j_m2 is empty",
        ),
        (
            "a log axis holding 0",
            set_all("/job/work_of_adhesion_j_m2", serde_json::json!([0.0, 0.2])),
            "job.work_of_adhesion_j_m2 is not an axis",
        ),
        (
            "a span of 1e-300 to 1e300",
            set_all("/job/modulus_pa", serde_json::json!([1e-300, 1e300])),
            "job.modulus_pa is not",
        ),
        (
            "a zeroed hash and version 9.9.9",
            Box::new(|ps| {
                for p in ps {
                    p["config_hash"] = "0000000000000000".into();
                    p["tapsim_version"] = "9.9.9".into();
                }
            }),
            "tapsim_version is \"9.9.9\"",
        ),
        (
            "a zeroed hash",
            set_all("/config_hash", serde_json::json!("0000000000000000")),
            "config_hash does not match",
        ),
        (
            "emptied records",
            Box::new(|ps| {
                for p in ps {
                    for r in p["records"].as_array_mut().unwrap() {
                        *r = Value::Array(vec![]);
                    }
                }
            }),
            "records hold 0 records",
        ),
        (
            "a descending axis",
            set_all("/job/modulus_pa", serde_json::json!([3e9, 3e8])),
            "job.modulus_pa is not an axis",
        ),
        (
            "a negative axis",
            set_all("/job/modulus_pa", serde_json::json!([-3e9, 3e8])),
            "job.modulus_pa is not an axis",
        ),
        (
            "a 100 000-cell map",
            Box::new(|ps| {
                let axis: Vec<f64> = (0..50_000).map(|i| 3e8 * (1.0 + i as f64)).collect();
                for p in ps {
                    p["job"]["modulus_pa"] = serde_json::json!(axis);
                }
            }),
            "job.modulus_pa is not an axis",
        ),
        (
            "a value changed",
            Box::new(|ps| {
                ps[0]["records"][0][0]["amplitude_ratio"] = 0.5.into();
            }),
            "do not match records_checksum",
        ),
        (
            "two cells' records swapped",
            Box::new(|ps| {
                let r = ps[1]["records"].as_array_mut().unwrap();
                r.swap(0, 1);
            }),
            "records hold for cell",
        ),
        (
            "the law renamed",
            set_all("/job/law", serde_json::json!("jkr")),
            "config_hash does not match",
        ),
        (
            "the configuration changed",
            set_all("/config/0/separation_m", serde_json::json!(1.5e-8)),
            "config_hash does not match",
        ),
        (
            "a batch of 0 cases",
            set_all("/job", serde_json::json!({"kind": "batch", "cases": 0})),
            "job.cases is 0",
        ),
        (
            "10^18 parts",
            Box::new(|ps| ps[0]["shards"] = 1_000_000_000_000_000_000u64.into()),
            "shard",
        ),
    ];
    for (what, change, says) in cases {
        let r = job.merge(&*change);
        refused(&r, what);
        assert!(r.stderr.contains(says), "{what}: {}", r.stderr);
        assert!(r.stderr.contains("q0.json") || r.stderr.contains("q1.json"));
        assert!(
            !job.dir.join("m.csv").exists(),
            "{what}: an output was written"
        );
    }
}

#[test]
fn a_batch_part_whose_case_was_changed_is_refused() {
    let job = batch_job(&scratch("batch"));
    ok(&job.merge(&|_| {}), "unchanged");
    job.refused_or_same(&job.merge(&|_| {}), "unchanged");
    let r = job.merge(&|ps| ps[0]["item_configs"][0]["setup"]["separation_m"] = 1.7e-8.into());
    refused(&r, "a case's separation changed");
    assert!(
        r.stderr.contains("config_hash does not match"),
        "{}",
        r.stderr
    );
    let r = job.merge(&|ps| ps[1]["records"][0] = Value::Array(vec![]));
    refused(&r, "a case without records");
    let r = job.merge(&|ps| ps[0]["job"]["cases"] = 4.into());
    refused(&r, "a case more");
}

/// Every leaf of `v` (numbers, strings, booleans, nulls) by its JSON pointer.
fn leaves(v: &Value, at: String, out: &mut Vec<String>) {
    match v {
        Value::Object(m) => m
            .iter()
            .for_each(|(k, x)| leaves(x, format!("{at}/{k}"), out)),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, x)| leaves(x, format!("{at}/{i}"), out)),
        _ => out.push(at),
    }
}

#[test]
fn merge_refuses_every_changed_field_of_a_part() {
    // A generator of doctored parts: every leaf of both part files of a map and of a
    // batch, changed in turn to another value of its kind (numbers scaled, negated,
    // zeroed or made huge; strings, booleans and nulls replaced), and every key removed.
    // Each merge is refused or, where the change changes nothing the part says, gives
    // the whole run's CSV; none panics, hangs or writes other numbers.
    for (name, job) in [
        ("map", map_job(&scratch("leaves-map"))),
        ("batch", batch_job(&scratch("leaves-batch"))),
    ] {
        let mut tried = 0;
        for part in 0..job.parts.len() {
            let mut all = Vec::new();
            leaves(&job.parts[part], String::new(), &mut all);
            for (i, pointer) in all.iter().enumerate() {
                let doctor = |ps: &mut Vec<Value>| {
                    let leaf = ps[part].pointer_mut(pointer).unwrap();
                    *leaf = match leaf {
                        Value::Number(n) => {
                            let x = n.as_f64().unwrap();
                            let y = [2.0 * x + 1.0, -x - 1.0, 0.0, 1e300][i % 4];
                            serde_json::json!(y)
                        }
                        Value::String(s) => Value::String(format!("{s}x")),
                        Value::Bool(b) => Value::Bool(!*b),
                        _ => serde_json::json!(1),
                    };
                };
                let what = format!("{name}: part {part}, {pointer} changed");
                job.refused_or_same(&job.merge(&doctor), &what);
                tried += 1;
                // Every third leaf also removed from its object or array.
                if i % 3 == 0 {
                    let (parent, key) = pointer.rsplit_once('/').unwrap();
                    let remove = |ps: &mut Vec<Value>| match ps[part].pointer_mut(parent).unwrap() {
                        Value::Object(m) => {
                            m.remove(key);
                        }
                        Value::Array(a) => {
                            a.remove(key.parse::<usize>().unwrap());
                        }
                        _ => unreachable!("a parent is an object or an array"),
                    };
                    let what = format!("{name}: part {part}, {pointer} removed");
                    job.refused_or_same(&job.merge(&remove), &what);
                    tried += 1;
                }
            }
        }
        println!("{name}: {tried} doctored merges, none believed");
        assert!(tried > 100, "{name}: {tried}");
    }
}

/// The cache file of the rigid solution for `mu` among `dir/cache`'s.
fn cache_file(dir: &Path, mu_bits: u64, reach: &str) -> PathBuf {
    std::fs::read_dir(dir.join("cache"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| {
            let n = p.file_name().unwrap().to_string_lossy().into_owned();
            n.contains(&format!("-mu{mu_bits:016x}-{reach}-"))
        })
        .expect("a cache file")
}

#[test]
fn a_doctored_lj_cache_is_solved_again_never_believed() {
    let dir = scratch("cache");
    let fresh = run(&["lj", "--mu", "3", "--json"], &dir);
    ok(&fresh, "lj");
    let file = cache_file(&dir, 3.0f64.to_bits(), "rigid");
    let pristine = std::fs::read(&file).unwrap();
    // The cases, with the checksum left as it was and with it forged to match
    // (then the solution's own checks refuse it).
    type Doctor = fn(&mut Value);
    let doctored: [(&str, Doctor); 4] = [
        ("w_hat -1e308, tabor_mu 0", |s| {
            s["w_hat"]["value"] = (-1e308).into();
            s["tabor_mu"] = 0.0.into();
        }),
        ("w_hat -1e308", |s| s["w_hat"]["value"] = (-1e308).into()),
        ("alpha_hat_a 0", |s| s["alpha_hat_a"]["value"] = 0.0.into()),
        ("the curve cut", |s| s["curve"] = Value::Array(vec![])),
    ];
    for (what, doctor) in doctored {
        for forge in [false, true] {
            let mut entry: Value = serde_json::from_slice(&pristine).unwrap();
            doctor(&mut entry["solution"]);
            if forge {
                entry["checksum"] = tapsim::lj_cache::checksum(&entry["solution"]).into();
            }
            std::fs::write(&file, serde_json::to_vec(&entry).unwrap()).unwrap();
            let r = run(&["lj", "--mu", "3", "--json"], &dir);
            ok(&r, what);
            assert_eq!(r.stdout, fresh.stdout, "{what} (forged {forge})");
            assert!(
                r.stderr.contains("is not used") && r.stderr.contains("solving again"),
                "{what} (forged {forge}): {}",
                r.stderr
            );
            // Replaced by a sound file: the next run reads it without a note.
            let again = run(&["lj", "--mu", "3", "--json"], &dir);
            assert_eq!(again.stdout, fresh.stdout);
            assert!(again.stderr.is_empty(), "{}", again.stderr);
        }
    }
    // Not JSON at all.
    std::fs::write(&file, b"\x00garbage").unwrap();
    let r = run(&["lj", "--mu", "3", "--json"], &dir);
    ok(&r, "garbage");
    assert_eq!(r.stdout, fresh.stdout);
}

#[test]
fn a_doctored_cache_never_moves_a_tap_with_the_lj_law() {
    // The issue: alpha_hat_a = 0 in the μ = 2.76 file gave A/A₀ 0.0148, φ −164.3°.
    let dir = scratch("cache-tap");
    let fresh = run(&["tap", "--law", "lj", "--json"], &dir);
    ok(&fresh, "tap");
    let mu = tapsim::dynamics::setup::default_setup().contact.tabor_mu();
    for reach in ["rigid", "springs", "whole"] {
        let Ok(list) = std::fs::read_dir(dir.join("cache")) else {
            continue;
        };
        let files: Vec<PathBuf> = list
            .map(|e| e.unwrap().path())
            .filter(|p| {
                let n = p.file_name().unwrap().to_string_lossy().into_owned();
                n.contains(&format!("-mu{:016x}-{reach}-", mu.to_bits()))
            })
            .collect();
        for file in files {
            let mut entry: Value = serde_json::from_slice(&std::fs::read(&file).unwrap()).unwrap();
            entry["solution"]["alpha_hat_a"]["value"] = 0.0.into();
            entry["checksum"] = tapsim::lj_cache::checksum(&entry["solution"]).into();
            std::fs::write(&file, serde_json::to_vec(&entry).unwrap()).unwrap();
            let r = run(&["tap", "--law", "lj", "--json"], &dir);
            ok(&r, reach);
            assert_eq!(r.stdout, fresh.stdout, "{reach}");
            assert!(r.stderr.contains("is not used"), "{reach}: {}", r.stderr);
        }
    }
}

#[test]
fn a_fifo_in_the_cache_is_neither_read_nor_written_through() {
    let dir = scratch("cache-fifo");
    let fresh = run(&["lj", "--mu", "3", "--json"], &dir);
    ok(&fresh, "lj");
    let file = cache_file(&dir, 3.0f64.to_bits(), "rigid");
    std::fs::remove_file(&file).unwrap();
    let made = Command::new("mkfifo").arg(&file).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("skipped: mkfifo not permitted here");
        return;
    }
    // Reading it would block for a writer, writing it for a reader: neither happens.
    let r = run(&["lj", "--mu", "3", "--json"], &dir);
    ok(&r, "a FIFO in the cache");
    assert_eq!(r.stdout, fresh.stdout);
    assert!(r.stderr.contains("not a regular file"), "{}", r.stderr);
    assert!(
        !std::fs::metadata(&file).unwrap().is_file(),
        "the FIFO was replaced"
    );
}
