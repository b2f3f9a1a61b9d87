//! The documentation a newcomer reads: a short README that reaches every task's guide
//! page in one click, a book in docs/ whose table of contents lists every page, and no
//! link that leads nowhere.

use crate::common;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Every Markdown page of the book.
fn pages() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "md") {
                out.push(path);
            }
        }
    }
    let mut out = Vec::new();
    walk(&root().join("docs/src"), &mut out);
    out.sort();
    out
}

/// The targets of the inline Markdown links `[text](target)` of `text`, outside code
/// blocks and code spans.
fn links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        // Drop code spans.
        let plain: String = line
            .split('`')
            .enumerate()
            .filter(|(i, _)| i % 2 == 0)
            .map(|(_, s)| s)
            .collect::<Vec<_>>()
            .join(" ");
        let mut rest = plain.as_str();
        while let Some(i) = rest.find("](") {
            let after = &rest[i + 2..];
            let Some(end) = after.find(')') else { break };
            out.push(after[..end].to_string());
            rest = &after[end..];
        }
    }
    out
}

/// The anchors of a page's headings, as GitHub and mdBook make them.
fn anchors(text: &str) -> BTreeSet<String> {
    text.lines()
        .filter(|l| l.starts_with('#'))
        .map(|l| {
            l.trim_start_matches('#')
                .trim()
                .to_lowercase()
                .chars()
                .filter_map(|c| match c {
                    ' ' => Some('-'),
                    c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
                    _ => None,
                })
                .collect()
        })
        .collect()
}

/// Every relative link of `file` resolves: its file exists, and an anchor names a
/// heading of the page it points to.
fn check_links(file: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(file).unwrap();
    let mut broken = Vec::new();
    for target in links(&text) {
        if target.starts_with("http://") || target.starts_with("https://") {
            continue;
        }
        let (path, anchor) = match target.split_once('#') {
            Some((p, a)) => (p, Some(a)),
            None => (target.as_str(), None),
        };
        let resolved = if path.is_empty() {
            file.to_path_buf()
        } else {
            file.parent().unwrap().join(path)
        };
        if !resolved.exists() {
            broken.push(format!("{}: {target} (no such file)", file.display()));
            continue;
        }
        if let Some(anchor) = anchor {
            let page = std::fs::read_to_string(&resolved).unwrap_or_default();
            if !anchors(&page).contains(anchor) {
                broken.push(format!("{}: {target} (no such heading)", file.display()));
            }
        }
    }
    broken
}

#[test]
fn no_link_in_the_readme_or_the_book_leads_nowhere() {
    let mut broken = check_links(&root().join("README.md"));
    for page in pages() {
        broken.extend(check_links(&page));
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn the_books_contents_list_every_page_once() {
    let summary = root().join("docs/src/SUMMARY.md");
    let listed: Vec<String> = links(&std::fs::read_to_string(&summary).unwrap());
    let unique: BTreeSet<&String> = listed.iter().collect();
    assert_eq!(unique.len(), listed.len(), "a page listed twice");
    for page in pages() {
        let rel = page
            .strip_prefix(root().join("docs/src"))
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        if rel != "SUMMARY.md" {
            assert!(listed.contains(&rel), "{rel} is not in SUMMARY.md");
        }
    }
}

/// README.md stays short, and each of a newcomer's six tasks is one click from it: its
/// guide page exists, is linked from the README, and shows the command that does it.
#[test]
fn the_readme_is_short_and_reaches_every_task() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(lines <= 250, "README.md has {lines} lines");
    let linked = links(&readme);
    for (task, page, shows) in [
        (
            "phase contrast between two polymers at A/A₀ = 0.8",
            "docs/src/how-to/contrast.md",
            "tapsim contrast",
        ),
        ("a scanned image", "docs/src/how-to/scans.md", "tapsim scan"),
        (
            "fitting a curve approach --csv wrote",
            "docs/src/how-to/fitting.md",
            "tapsim fit",
        ),
        (
            "a thermal calibration",
            "docs/src/how-to/noise.md",
            "tapsim thermal",
        ),
        (
            "bimodal phase on the defaults",
            "docs/src/how-to/modes.md",
            "--modes",
        ),
        ("a Slurm map", "docs/src/how-to/maps.md", "sbatch"),
    ] {
        assert!(
            linked.iter().any(|l| l == page),
            "{task}: README.md does not link {page}"
        );
        let text = std::fs::read_to_string(root().join(page)).unwrap();
        assert!(text.contains(shows), "{task}: {page} does not show {shows}");
    }
}

/// No file of the project sends a reader outside the repository for what they need.
#[test]
fn the_documentation_stands_on_its_own() {
    let mut files = vec![root().join("README.md")];
    files.extend(pages());
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        assert!(
            !text.contains("../shared"),
            "{} points outside the repository",
            file.display()
        );
    }
}

/// The command reference in the book is the command line's own `--help`, current: what
/// `tapsim man --markdown` writes now.
#[test]
fn the_command_reference_is_current() {
    let dir = common::scratch("docs");
    let fresh = dir.join("commands.md");
    let out = common::tapsim(&["man", "--markdown", fresh.to_str().unwrap(), "--quiet"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let fresh = std::fs::read_to_string(&fresh).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let committed = std::fs::read_to_string(root().join("docs/src/reference/commands.md")).unwrap();
    assert!(
        fresh == committed,
        "docs/src/reference/commands.md is stale: run `tapsim man --markdown docs/src/reference/commands.md`"
    );
}

/// The how-to pages' recipes are commands the tours run (`tests/tour.rs`), word for word.
#[test]
fn every_recipe_is_a_command_the_tours_run() {
    let tours = common::tour();
    let mut recipes = 0;
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        if !text.contains("## Recipes") {
            continue;
        }
        let rel = page
            .strip_prefix(root())
            .unwrap()
            .to_string_lossy()
            .into_owned();
        for command in common::tour_block(&rel, "## Recipes") {
            assert!(
                tours.contains(&command),
                "{rel}: `tapsim {}` is in no tour",
                command.join(" ")
            );
            recipes += 1;
        }
    }
    assert!(recipes >= 15, "{recipes} recipes");
}

/// Every output the README and the book show under a command (a ```console block) is
/// what that command prints now, line for line (`...` standing for lines left out,
/// `[..]` for part of a line): the numbers the pages print are the program's. Each
/// page's commands run in order in a directory of its own (a later command may read a
/// file an earlier one wrote).
#[test]
fn every_output_the_docs_show_is_what_tapsim_prints() {
    let mut files = vec![root().join("README.md")];
    files.extend(pages());
    let jobs: Vec<(PathBuf, Vec<common::Shown>)> = files
        .into_iter()
        .map(|f| {
            let shown = common::console_blocks(&std::fs::read_to_string(&f).unwrap());
            (f, shown)
        })
        .filter(|(_, shown)| !shown.is_empty())
        .collect();
    let count: usize = jobs.iter().map(|(_, s)| s.len()).sum();
    assert!(count >= 20, "{count} commands shown with their output");
    let failures = std::sync::Mutex::new(Vec::new());
    common::two_at_a_time(&jobs, |(file, shown)| {
        let rel = file.strip_prefix(root()).unwrap().display().to_string();
        let dir = common::scratch(&rel.replace('/', "_"));
        for one in shown {
            let r = common::run_limited(
                &common::with_examples(&one.args),
                &dir,
                std::time::Duration::from_secs(60),
            );
            let actual: Vec<&str> = r.stdout.lines().collect();
            if r.code != Some(0) || !common::shows(&one.output, &actual) {
                failures.lock().unwrap().push(format!(
                    "{rel}:{}: `tapsim {}` (exit {:?}) printed\n{}\nwhere the page shows\n{}\n{}",
                    one.line,
                    one.args.join(" "),
                    r.code,
                    r.stdout,
                    one.output.join("\n"),
                    r.stderr
                ));
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
    });
    let failures = failures.into_inner().unwrap();
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// The matcher itself: `...` and `[..]` stand for what they say and no more.
#[test]
fn the_output_matcher_elides_only_what_it_is_told_to() {
    let s = |v: &[&str]| v.iter().map(|l| l.to_string()).collect::<Vec<_>>();
    assert!(common::shows(&s(&["a", "...", "d"]), &["a", "b", "c", "d"]));
    assert!(common::shows(
        &s(&["...", "c", "..."]),
        &["a", "b", "c", "d"]
    ));
    assert!(!common::shows(&s(&["a", "d"]), &["a", "b", "c", "d"]));
    assert!(!common::shows(&s(&["a", "b"]), &["a", "b", "c"]));
    assert!(common::shows(&s(&["A = 0.9[..] nm"]), &["A = 0.9415 nm  "]));
    assert!(!common::shows(&s(&["A = 0.9[..] nm"]), &["A = 0.8415 nm"]));
    assert!(!common::shows(&s(&["x [..]y[..] z"]), &["x  z"]));
    let shown = common::console_blocks(
        "text\n```console\n$ tapsim tap \\\n    --json\n{\n...\n```\n```sh\n$ tapsim no\n```\n",
    );
    assert_eq!(shown.len(), 1);
    assert_eq!(shown[0].args, ["tap", "--json"]);
    assert_eq!(shown[0].output, ["{", "..."]);
    assert_eq!(shown[0].line, 3);
}
