//! The physics library stands on its own: no command line, plots or progress bars in
//! its dependencies (checked in CI with `cargo build --lib --no-default-features` and
//! `cargo tree`), no file or environment access in its modules, and no command-line
//! flag in its messages.

use std::path::{Path, PathBuf};

/// The library's modules (everything outside the `app` feature).
const LIBRARY: [&str; 19] = [
    "src/bimodal.rs",
    "src/coexist.rs",
    "src/lib.rs",
    "src/contact",
    "src/contrast.rs",
    "src/dynamics",
    "src/error.rs",
    "src/fit",
    "src/identification.rs",
    "src/instrument",
    "src/interrupt.rs",
    "src/law",
    "src/numeric.rs",
    "src/params.rs",
    "src/quasistatic.rs",
    "src/reconstruct.rs",
    "src/setpoint.rs",
    "src/summary.rs",
    "src/sweep.rs",
];

#[test]
fn every_module_outside_the_app_feature_is_checked_as_library() {
    let lib =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("src/lib.rs")).unwrap();
    let mut behind_app = false;
    for line in lib.lines().map(str::trim) {
        if let Some(name) = line
            .strip_prefix("pub mod ")
            .and_then(|l| l.strip_suffix(';'))
        {
            let listed = LIBRARY
                .iter()
                .any(|p| *p == format!("src/{name}.rs") || *p == format!("src/{name}"));
            assert_eq!(
                listed, !behind_app,
                "module {name}: library modules are listed here, application ones are not"
            );
        }
        behind_app = line == "#[cfg(feature = \"app\")]";
    }
}

fn sources(path: &Path, out: &mut Vec<PathBuf>) {
    if path.is_dir() {
        for entry in std::fs::read_dir(path).unwrap() {
            sources(&entry.unwrap().path(), out);
        }
    } else if path.extension().is_some_and(|e| e == "rs") {
        out.push(path.to_path_buf());
    }
}

#[test]
fn library_modules_touch_no_file_no_environment_and_name_no_flag() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for part in LIBRARY {
        sources(&root.join(part), &mut files);
    }
    assert!(files.len() > 30, "{files:?}");
    let forbidden = [
        "std::fs",
        "fs::",
        "std::env",
        "env::var",
        "File::",
        "clap",
        "plotters",
        "indicatif",
        "crate::config",
        "crate::report",
        "crate::cli",
        "crate::figures",
        "crate::units",
    ];
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            // (Test modules may use the application: they are not the library.)
            if line.trim_start().starts_with("#[cfg(test)]") {
                break;
            }
            // Library errors name parameters, not the command line's flags.
            let flag = code
                .match_indices("--")
                .any(|(at, _)| code[at + 2..].starts_with(|c: char| c.is_ascii_lowercase()));
            assert!(
                !flag,
                "{}:{}: a command-line flag in the library: {line}",
                file.display(),
                n + 1
            );
            for word in forbidden {
                let allowed = word == "clap" && line.contains("cfg_attr(feature = \"app\"");
                assert!(
                    !code.contains(word) || allowed,
                    "{}:{}: `{word}` in the library: {line}",
                    file.display(),
                    n + 1
                );
            }
        }
    }
}
