//! A real Slurm run of `examples/slurm/`: the job array computes a map in parts, the
//! merge job (submitted with --dependency=afterok) joins them, and the result is the
//! unsharded map byte for byte. Ignored by a plain `cargo test` (which says so): run it
//! with `cargo test --release -- --ignored slurm::` where a Slurm cluster answers (`.ci/slurm
//! up` starts a single-node one); CI does, with TAPSIM_REQUIRE_SLURM set so that it
//! cannot pass without one.

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// Whether a Slurm node takes jobs here.
fn slurm_is_up() -> bool {
    Command::new("sinfo")
        .args(["-h", "-o", "%T"])
        .output()
        .is_ok_and(|o| {
            o.status.success()
                && String::from_utf8_lossy(&o.stdout)
                    .lines()
                    .any(|l| matches!(l.trim(), "idle" | "mixed" | "allocated"))
        })
}

fn sbatch(dir: &Path, args: &[&str]) -> std::process::Child {
    Command::new("sbatch")
        .args(args)
        .current_dir(dir)
        .env("TAPSIM", env!("CARGO_BIN_EXE_tapsim"))
        .env("STEPS", "5")
        .env("OUT", "merged")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("sbatch runs")
}

#[test]
#[ignore = "needs a Slurm cluster: `.ci/slurm up` (as root), then `cargo test --release -- --ignored slurm::`"]
fn the_example_job_array_and_merge_job_give_the_unsharded_map_on_slurm() {
    if !slurm_is_up() {
        assert!(
            std::env::var_os("TAPSIM_REQUIRE_SLURM").is_none(),
            "TAPSIM_REQUIRE_SLURM is set but no Slurm node answers (start one with .ci/slurm up)"
        );
        eprintln!("skipped: no Slurm cluster here (.ci/slurm up starts a single-node one)");
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("slurm-run");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("parts")).unwrap();
    std::fs::create_dir_all(dir.join("logs")).unwrap();
    let array = root.join("examples/slurm/map-array.sbatch");
    let merge = root.join("examples/slurm/merge.sbatch");
    let out = sbatch(&dir, &["--parsable", array.to_str().unwrap()])
        .wait_with_output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let job = String::from_utf8_lossy(&out.stdout)
        .trim()
        .split(';')
        .next()
        .unwrap()
        .to_string();
    // The merge job waits for the array; sbatch --wait returns when it has run.
    let dependency = format!("--dependency=afterok:{job}");
    let mut waiting = sbatch(&dir, &["--wait", &dependency, merge.to_str().unwrap()]);
    let deadline = Instant::now() + Duration::from_secs(300);
    let status = loop {
        if let Some(status) = waiting.try_wait().unwrap() {
            break status;
        }
        if Instant::now() > deadline {
            let _ = waiting.kill();
            let _ = Command::new("scancel").arg(&job).status();
            panic!("the Slurm jobs did not finish within 300 s");
        }
        std::thread::sleep(Duration::from_millis(200));
    };
    let logs = || {
        std::fs::read_dir(dir.join("logs"))
            .map(|d| {
                d.filter_map(|e| std::fs::read_to_string(e.ok()?.path()).ok())
                    .collect::<Vec<_>>()
                    .join("\n")
            })
            .unwrap_or_default()
    };
    assert!(status.success(), "the merge job failed; logs:\n{}", logs());
    // Eight parts, one per array task, each with its own cells.
    assert_eq!(
        std::fs::read_dir(dir.join("parts")).unwrap().count(),
        8,
        "{}",
        logs()
    );
    // The unsharded map, here.
    let whole = Command::new(env!("CARGO_BIN_EXE_tapsim"))
        .args([
            "map",
            "--steps",
            "5",
            "--quiet",
            "--csv",
            "whole.csv",
            "--plot",
            "whole.png",
        ])
        .current_dir(&dir)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("SLURM_ARRAY_TASK_COUNT")
        .output()
        .unwrap();
    assert!(whole.status.success());
    let json = Command::new(env!("CARGO_BIN_EXE_tapsim"))
        .args(["map", "--steps", "5", "--quiet", "--json"])
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("SLURM_ARRAY_TASK_COUNT")
        .output()
        .unwrap();
    let read = |name: &str| std::fs::read(dir.join(name)).unwrap();
    assert_eq!(read("merged.csv"), read("whole.csv"));
    assert_eq!(read("merged.png"), read("whole.png"));
    assert_eq!(read("merged.json"), json.stdout);
}
