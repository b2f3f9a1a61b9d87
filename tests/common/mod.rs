//! What several test files share: running the binary (plainly, for its JSON, or with a
//! time limit).

// Each test file that includes this uses what it needs of it.
#![allow(dead_code)]

use std::ffi::OsStr;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// How a run of the binary ended.
pub struct Run {
    /// Its exit code (`None`: killed at the limit, or by a signal).
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
    pub elapsed: Duration,
}

/// Run the binary with `args` in `dir` (its Lennard-Jones cache in `dir/cache`), killing
/// it once it has run for `limit`.
pub fn run_limited<S: AsRef<OsStr>>(args: &[S], dir: &Path, limit: Duration) -> Run {
    let start = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_tapsim"))
        .args(args)
        .current_dir(dir)
        .env("TAPSIM_CACHE", dir.join("cache"))
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts");
    let drain = |mut pipe: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut text = Vec::new();
            let _ = pipe.read_to_end(&mut text);
            String::from_utf8_lossy(&text).into_owned()
        })
    };
    let out = drain(Box::new(child.stdout.take().expect("piped")));
    let err = drain(Box::new(child.stderr.take().expect("piped")));
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break Some(status);
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    Run {
        code: status.and_then(|s| s.code()),
        elapsed: start.elapsed(),
        stdout: out.join().unwrap_or_default(),
        stderr: err.join().unwrap_or_default(),
    }
}

/// Run `work` on every item, two at a time from one queue (the machine has two cores);
/// a panic in either thread fails the caller.
pub fn two_at_a_time<T: Sync>(items: &[T], work: impl Fn(&T) + Sync) {
    let next = std::sync::atomic::AtomicUsize::new(0);
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| {
                while let Some(item) =
                    items.get(next.fetch_add(1, std::sync::atomic::Ordering::Relaxed))
                {
                    work(item);
                }
            });
        }
    });
}

/// Run the binary with `args`.
pub fn tapsim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tapsim"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// [`json`] of a fixed `head` of arguments followed by `tail`: one command line run
/// with several variations.
pub fn json_of(head: &[&str], tail: &[&str]) -> serde_json::Value {
    json(&[head, tail].concat())
}

/// Run `args`, asserting success, and read the one JSON object it prints.
pub fn json(args: &[&str]) -> serde_json::Value {
    let out = tapsim(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("exactly one JSON object on stdout")
}

/// A column of numbers of a command's JSON (an object of arrays).
pub fn column(v: &serde_json::Value, key: &str) -> Vec<f64> {
    v[key]
        .as_array()
        .unwrap_or_else(|| panic!("no column {key}"))
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// The number under `key`.
pub fn num(v: &serde_json::Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("key {key} missing or not a number in {v}"))
}

/// The cells of a map's grid (an array of rows) in the order the CSV lists them.
pub fn cells(rows: &serde_json::Value) -> Vec<serde_json::Value> {
    rows.as_array()
        .expect("an array of rows")
        .iter()
        .flat_map(|r| r.as_array().expect("a row").clone())
        .collect()
}

/// An empty scratch directory `name` of this test binary and process, under the system's
/// temporary directory.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "tapsim-{}-{}-{name}",
        env!("CARGO_CRATE_NAME"),
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Run `args`, asserting that it is refused: exit code 1 and `says` in the message.
pub fn refused(args: &[&str], says: &str) {
    let out = tapsim(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    assert!(err.contains(says), "{args:?}: {err}");
}

/// The rows of a `--json` document of columns (format_version 2: one array per key, an
/// entry per row): one object per row, the document's scalars (format_version) left out.
pub fn rows(doc: &serde_json::Value) -> Vec<serde_json::Value> {
    let columns: Vec<(&String, &Vec<serde_json::Value>)> = doc
        .as_object()
        .expect("a document is an object")
        .iter()
        .filter_map(|(k, v)| v.as_array().map(|a| (k, a)))
        .collect();
    let n = columns.first().map_or(0, |(_, a)| a.len());
    assert!(
        columns.iter().all(|(_, a)| a.len() == n),
        "columns of unequal length"
    );
    (0..n)
        .map(|i| {
            serde_json::Value::Object(
                columns
                    .iter()
                    .map(|(k, a)| ((*k).clone(), a[i].clone()))
                    .collect(),
            )
        })
        .collect()
}

/// The paper's finite-stiffness cycle (§4) as a simulated experiment: the hybrid
/// contact of Tabor parameter `mu` (R 20 nm, Δγ 0.1 J/m², ε 0.3 nm) on a lever of
/// dimensionless stiffness `k_hat` (eq. 22) with Q = 1 (it rings out at once), its
/// closed form (eq. 26), the support's travel from beyond the spring's pull-off down to
/// a compressive force of about the pull-off force (top, bottom, m), and the unit of
/// energy μεRΔγ (J) and of length με (m).
pub struct PaperCycle {
    pub setup: tapsim::TapSetup,
    pub closed: tapsim::physics::contact::spring::SpringHysteresis,
    pub top_m: f64,
    pub bottom_m: f64,
    pub energy_unit_j: f64,
    pub length_unit_m: f64,
}

pub fn paper_cycle(mu: f64, k_hat: f64) -> PaperCycle {
    use tapsim::physics::contact::{hybrid, spring};
    let (r, dg, eps) = (20e-9_f64, 0.1_f64, 0.3e-9_f64);
    let e_star = (r * dg * dg / (mu.powi(3) * eps.powi(3))).sqrt();
    let mut setup = tapsim::TapSetup {
        law: tapsim::LawKind::Hybrid.into(),
        ..tapsim::default_setup()
    };
    setup.contact = tapsim::Contact::new(r, e_star, dg, eps).unwrap();
    setup.cantilever.stiffness_n_m = k_hat * r * dg / (mu * eps);
    setup.cantilever.quality = 1.0;
    let closed = spring::hysteresis(mu, k_hat, hybrid::JumpIn::Fit).unwrap();
    let me = mu * eps;
    PaperCycle {
        top_m: (closed.support_alpha_hat_c.max(4.0) + 1.0) * me,
        bottom_m: (-1.5 * std::f64::consts::PI / k_hat - 3.0) * me,
        closed,
        setup,
        energy_unit_j: me * r * dg,
        length_unit_m: me,
    }
}

/// The limit Q₀ of Q = Q₀ + a s^{2/3} + b s through three points (s, Q) (Cramer's
/// rule): how a slow cycle's loss and pull-off approach the quasi-static ones (the slow
/// passage through the fold, and the slow motion's damping).
pub fn limit_two_thirds(s: [f64; 3], q: [f64; 3]) -> f64 {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let a = s.map(|s| [1.0, s.powf(2.0 / 3.0), s]);
    let mut a0 = a;
    for i in 0..3 {
        a0[i][0] = q[i];
    }
    det(a0) / det(a)
}

/// The commands of the first `sh` block after `heading` in `file` (from the repository's
/// root): one per line (a trailing `\` joins the next), comments (`#` after whitespace)
/// dropped, `tapsim` first.
pub fn tour_block(file: &str, heading: &str) -> Vec<Vec<String>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    let readme = std::fs::read_to_string(&path).expect(file);
    let start = readme.find(heading).expect("the tour's heading");
    let block = &readme[start..];
    let block = &block[block.find("```sh\n").expect("a sh block") + 6..];
    let block = &block[..block.find("```").expect("the block ends")];
    let mut commands = Vec::new();
    let mut current = String::new();
    for line in block.lines() {
        let code = match line.find(" #") {
            Some(i) => &line[..i],
            None => line,
        };
        let code = code.trim();
        let (code, joined) = match code.strip_suffix('\\') {
            Some(c) => (c, true),
            None => (code, false),
        };
        current.push(' ');
        current.push_str(code);
        if !joined {
            let words: Vec<String> = current.split_whitespace().map(String::from).collect();
            if !words.is_empty() {
                assert_eq!(words[0], "tapsim", "{current}");
                commands.push(words[1..].to_vec());
            }
            current.clear();
        }
    }
    commands
}

/// A command a page shows in a ```console block (`$ tapsim …`, continued over lines
/// ending in `\`), and the lines of output shown under it.
pub struct Shown {
    /// The page's line of the `$`.
    pub line: usize,
    /// The arguments after `tapsim`.
    pub args: Vec<String>,
    /// The output shown: `...` stands for lines left out, `[..]` for part of a line.
    pub output: Vec<String>,
}

/// The commands and outputs of every ```console block of a Markdown `text`.
pub fn console_blocks(text: &str) -> Vec<Shown> {
    let mut shown: Vec<Shown> = Vec::new();
    let (mut inside, mut joined) = (false, false);
    for (i, line) in text.lines().enumerate() {
        let fence = line.trim_start();
        if fence.starts_with("```") {
            inside = !inside && fence == "```console";
            continue;
        }
        if !inside {
            continue;
        }
        let continued = |code: &str, shown: &mut Vec<Shown>| {
            let (code, more) = match code.trim_end().strip_suffix('\\') {
                Some(c) => (c, true),
                None => (code, false),
            };
            let last = shown.last_mut().expect("a command");
            last.args.extend(code.split_whitespace().map(String::from));
            more
        };
        if let Some(command) = line.strip_prefix("$ ") {
            let mut words = command.split_whitespace();
            assert_eq!(words.next(), Some("tapsim"), "line {}: {line}", i + 1);
            shown.push(Shown {
                line: i + 1,
                args: Vec::new(),
                output: Vec::new(),
            });
            let rest = command.trim_start()["tapsim".len()..].to_string();
            joined = continued(&rest, &mut shown);
        } else if joined {
            joined = continued(line, &mut shown);
        } else {
            let last = shown
                .last_mut()
                .expect("a ```console block starts with `$ tapsim`");
            last.output.push(line.trim_end().to_string());
        }
    }
    shown
}

/// Whether the `actual` lines are what `shown` shows: line for line, where a line `...`
/// stands for any number of lines and `[..]` within a line for any part of it.
pub fn shows(shown: &[String], actual: &[&str]) -> bool {
    fn line(shown: &str, actual: &str) -> bool {
        let actual = actual.trim_end();
        let pieces: Vec<&str> = shown.split("[..]").collect();
        if pieces.len() == 1 {
            return shown == actual;
        }
        let (first, last) = (pieces[0], pieces[pieces.len() - 1]);
        if !actual.starts_with(first) || !actual[first.len()..].ends_with(last) {
            return false;
        }
        let mut rest = &actual[first.len()..actual.len() - last.len()];
        for piece in &pieces[1..pieces.len() - 1] {
            match rest.find(piece) {
                Some(at) => rest = &rest[at + piece.len()..],
                None => return false,
            }
        }
        true
    }
    match shown.split_first() {
        None => actual.is_empty(),
        Some((first, rest)) if first == "..." => {
            (0..=actual.len()).any(|skip| shows(rest, &actual[skip..]))
        }
        Some((first, rest)) => {
            !actual.is_empty() && line(first, actual[0]) && shows(rest, &actual[1..])
        }
    }
}

/// The arguments as a tour gives them, with `examples/…` pointing into the repository's
/// examples wherever the command runs.
pub fn with_examples(args: &[String]) -> Vec<String> {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    args.iter()
        .map(|a| match a.strip_prefix("examples/") {
            Some(rest) => examples.join(rest).to_string_lossy().into_owned(),
            None => a.clone(),
        })
        .collect()
}

/// Both tours' commands, the README's first (every ```console block of its section).
pub fn tour() -> Vec<Vec<String>> {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let section = &readme[readme.find("## Five-minute tour").expect("the tour")..];
    let section = &section[..section[3..].find("\n## ").map_or(section.len(), |i| i + 3)];
    let mut commands: Vec<Vec<String>> = console_blocks(section)
        .into_iter()
        .map(|shown| shown.args)
        .collect();
    commands.extend(tour_block("docs/src/reference/cli-tour.md", "# CLI tour"));
    commands
}

/// The blend's materials at the instrument's tolerance.
pub fn blend() -> (
    tapsim::sample::Sample,
    Vec<tapsim::dynamics::setup::Prepared>,
) {
    let sample = tapsim::sample::Sample::from_toml(
        tapsim::sample::BLEND,
        &tapsim::config::TapInputs::default(),
    )
    .unwrap();
    let numerics = tapsim::dynamics::setup::Numerics {
        rtol: tapsim::instrument::MARCH_RTOL,
        atol: 1e-2 * tapsim::instrument::MARCH_RTOL,
        ..tapsim::dynamics::setup::Numerics::default()
    };
    let prepared = sample
        .materials
        .iter()
        .map(|(_, s)| tapsim::dynamics::setup::Prepared::new(s, &numerics).unwrap())
        .collect();
    (sample, prepared)
}
