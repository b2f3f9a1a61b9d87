//! The house's plan, checked (issue 46): the folders of `src/` are layers, and
//! - no module imports a module of a higher layer;
//! - no module imports itself round a circle of imports (at any length);
//! - the physics library (layers 0–4) names none of the application's dependencies, so
//!   that it builds without them (`cargo clippy --lib --no-default-features` in CI
//!   builds it so), touches no file and no environment, and names no command-line flag
//!   in its messages.
//!
//! An import is any path through `crate::` or `super::` in the code (a `use`, or a path
//! written inline), tests included (the library's own, in tests/unit/, for the module each
//! tests); doc comments and strings are not code. Each path is
//! resolved to the deepest module it names. A module's re-exports of its own children
//! are containment, not imports.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A module: its path below the crate root (empty for the root).
type Module = Vec<String>;

/// The layer of a module, from its first component.
fn layer(module: &Module) -> Option<usize> {
    match module.first().map(String::as_str) {
        None => None, // the root (lib.rs, main.rs) only declares and re-exports
        Some("error" | "numeric" | "interrupt") => Some(0),
        Some("physics") => Some(1),
        Some("dynamics") => Some(2),
        Some("instrument") => Some(3),
        Some("analysis") => Some(4),
        Some("app") => Some(5),
        Some(other) => panic!("src/{other} is in no layer: put it in one (see src/lib.rs)"),
    }
}

/// Every `.rs` file under `dir`.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The module a file defines.
fn module_of(src: &Path, file: &Path) -> Module {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Module = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    if parts == ["lib"] || parts == ["main"] {
        parts.clear();
    }
    parts
}

/// The code of `text` without comments, string and character literals (each replaced
/// by a space).
fn code_only(text: &str) -> String {
    let c: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < c.len() {
        let next = c.get(i + 1).copied();
        if c[i] == '/' && next == Some('/') {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if c[i] == '/' && next == Some('*') {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            out.push(' ');
        } else if c[i] == 'r' && (next == Some('"') || next == Some('#')) && {
            let mut j = i + 1;
            while c.get(j) == Some(&'#') {
                j += 1;
            }
            c.get(j) == Some(&'"') && (i == 0 || !(c[i - 1].is_alphanumeric() || c[i - 1] == '_'))
        } {
            let mut j = i + 1;
            let mut hashes = 0;
            while c[j] == '#' {
                hashes += 1;
                j += 1;
            }
            j += 1;
            loop {
                if j >= c.len() {
                    break;
                }
                if c[j] == '"' && (0..hashes).all(|h| c.get(j + 1 + h) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                j += 1;
            }
            i = j;
            out.push(' ');
        } else if c[i] == '"' {
            i += 1;
            while i < c.len() && c[i] != '"' {
                if c[i] == '\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            out.push(' ');
        } else if c[i] == '\''
            && (c.get(i + 2) == Some(&'\'') || (next == Some('\\') && c.get(i + 3) == Some(&'\'')))
        {
            i += if next == Some('\\') { 4 } else { 3 };
            out.push(' ');
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

/// The paths of a `use` tree (`a::{b, c::{d, e as f}}` → a::b, a::c::d, a::c::e).
fn expand(prefix: &[String], tree: &str, out: &mut Vec<Vec<String>>) {
    let tree = tree.trim();
    let (head, rest) = match tree.find('{') {
        Some(open) => (
            &tree[..open],
            Some(&tree[open + 1..tree.rfind('}').unwrap()]),
        ),
        None => (tree, None),
    };
    let head = head.split(" as ").next().unwrap();
    let mut path = prefix.to_vec();
    path.extend(
        head.split("::")
            .map(str::trim)
            .filter(|s| !s.is_empty() && *s != "*" && *s != "self")
            .map(String::from),
    );
    let Some(rest) = rest else {
        out.push(path);
        return;
    };
    let (mut depth, mut start) = (0, 0);
    let bytes = rest.as_bytes();
    for (k, &b) in bytes.iter().enumerate() {
        match b {
            b'{' => depth += 1,
            b'}' => depth -= 1,
            b',' if depth == 0 => {
                expand(&path, &rest[start..k], out);
                start = k + 1;
            }
            _ => {}
        }
    }
    if !rest[start..].trim().is_empty() {
        expand(&path, &rest[start..], out);
    }
    out.push(path);
}

/// Where each top-level inline module (`mod tests { … }`) of `code` begins and ends.
fn inline_modules(code: &str) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut from = 0;
    while let Some(at) = code[from..].find("\nmod ").map(|k| from + k + 1) {
        let line_end = code[at..].find('\n').map_or(code.len(), |k| at + k);
        from = line_end;
        let Some(open) = code[at..line_end].find('{').map(|k| at + k) else {
            continue;
        };
        let mut depth = 0;
        let mut end = code.len();
        for (k, ch) in code[open..].char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        end = open + k;
                        break;
                    }
                }
                _ => {}
            }
        }
        spans.push((open, end));
        from = end;
    }
    spans
}

/// Every path through `crate::` or `super::` in `code`, made absolute for a file of
/// module `here`.
fn paths(code: &str, here: &Module) -> Vec<Module> {
    let inline = inline_modules(code);
    let mut found = Vec::new();
    let is_ident = |ch: char| ch.is_alphanumeric() || ch == '_';
    for (start, _) in code.match_indices("use ") {
        if start > 0 && is_ident(code[..start].chars().next_back().unwrap()) {
            continue;
        }
        let Some(end) = code[start..].find(';') else {
            continue;
        };
        let tree = &code[start + 4..start + end];
        let first = tree.trim_start().split("::").next().unwrap_or("");
        if matches!(first, "crate" | "super" | "self") {
            let mut expanded = Vec::new();
            expand(&[], tree, &mut expanded);
            found.extend(expanded.into_iter().map(|p| (start, p)));
        }
    }
    for keyword in ["crate::", "super::"] {
        for (start, _) in code.match_indices(keyword) {
            if start > 0 {
                let before = code[..start].chars().next_back().unwrap();
                if is_ident(before) || before == ':' || before == '$' {
                    continue;
                }
            }
            let path: String = code[start..]
                .chars()
                .take_while(|&ch| is_ident(ch) || ch == ':')
                .collect();
            let parts: Vec<String> = path
                .split("::")
                .filter(|s| !s.is_empty())
                .map(String::from)
                .collect();
            found.push((start, parts));
        }
    }
    found
        .into_iter()
        .map(|(at, path)| {
            // Within an inline module, `super` is the file's own module.
            let mut base: Module = here.clone();
            if inline.iter().any(|&(a, b)| a < at && at < b) {
                base.push("(inline)".into());
            }
            let mut k = 0;
            let mut absolute = if path.first().is_some_and(|p| p == "crate") {
                k = 1;
                Vec::new()
            } else {
                base
            };
            while k < path.len() && (path[k] == "super" || path[k] == "self") {
                if path[k] == "super" {
                    absolute.pop();
                }
                k += 1;
            }
            absolute.retain(|p| p != "(inline)");
            absolute.extend(path[k..].iter().cloned());
            absolute
        })
        .collect()
}

/// The deepest module of `modules` that `path` names.
fn resolve(path: &Module, modules: &BTreeSet<Module>) -> Module {
    (0..=path.len())
        .rev()
        .map(|k| path[..k].to_vec())
        .find(|m| modules.contains(m))
        .unwrap_or_default()
}

/// The modules of `modules` that `code`, in module `here`, imports.
fn imports(code: &str, here: &Module, modules: &BTreeSet<Module>) -> BTreeSet<Module> {
    paths(code, here)
        .iter()
        .map(|path| resolve(path, modules))
        // Itself, the root, or its own ancestors' re-exports of it: not an import.
        .filter(|target| target != here && !target.is_empty() && !here.starts_with(target))
        .collect()
}

/// The import graph of the crate under `src`: module → the modules it imports.
fn graph(src: &Path) -> BTreeMap<Module, BTreeSet<Module>> {
    let mut files = Vec::new();
    sources(src, &mut files);
    let modules: BTreeSet<Module> = files.iter().map(|f| module_of(src, f)).collect();
    let mut edges = BTreeMap::new();
    for file in &files {
        let here = module_of(src, file);
        let code = code_only(&std::fs::read_to_string(file).unwrap());
        let to = imports(&code, &here, &modules);
        edges.insert(here, to);
    }
    // The library's own tests (tests/unit/) count for the module each tests, named by
    // its first line; they reach it through `tapsim::`.
    let mut tests = Vec::new();
    let unit = src.join("../tests/unit");
    if unit.is_dir() {
        sources(&unit, &mut tests);
    }
    for file in &tests {
        let text = std::fs::read_to_string(file).unwrap();
        let Some(named) = text
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("//! Tests of `tapsim::"))
            .and_then(|l| l.split('`').next())
        else {
            continue;
        };
        let here: Module = named.split("::").map(String::from).collect();
        assert!(
            modules.contains(&here),
            "{}: no module {named}",
            file.display()
        );
        let code = code_only(&text).replace("tapsim::", "crate::");
        let to = imports(&code, &here, &modules);
        edges.get_mut(&here).unwrap().extend(to);
    }
    edges
}

/// The circles of `edges`: strongly connected components of more than one module
/// (Tarjan's algorithm).
fn circles(edges: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<Vec<Module>> {
    struct Tarjan<'a> {
        edges: &'a BTreeMap<Module, BTreeSet<Module>>,
        index: BTreeMap<&'a Module, (usize, usize)>,
        stack: Vec<&'a Module>,
        next: usize,
        found: Vec<Vec<Module>>,
    }
    impl<'a> Tarjan<'a> {
        fn visit(&mut self, v: &'a Module) {
            self.index.insert(v, (self.next, self.next));
            self.next += 1;
            self.stack.push(v);
            for w in self.edges.get(v).into_iter().flatten() {
                match self.index.get(w).copied() {
                    None => {
                        self.visit(w);
                        let low = self.index[w].1.min(self.index[v].1);
                        self.index.get_mut(v).unwrap().1 = low;
                    }
                    Some((w_index, _)) if self.stack.contains(&w) => {
                        let low = w_index.min(self.index[v].1);
                        self.index.get_mut(v).unwrap().1 = low;
                    }
                    Some(_) => {}
                }
            }
            let (index, low) = self.index[v];
            if index == low {
                let mut component = Vec::new();
                while let Some(w) = self.stack.pop() {
                    component.push(w.clone());
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    self.found.push(component);
                }
            }
        }
    }
    let mut t = Tarjan {
        edges,
        index: BTreeMap::new(),
        stack: Vec::new(),
        next: 0,
        found: Vec::new(),
    };
    for v in edges.keys() {
        if !t.index.contains_key(v) {
            t.visit(v);
        }
    }
    t.found
}

fn name(m: &Module) -> String {
    if m.is_empty() {
        "crate".into()
    } else {
        m.join("::")
    }
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

#[test]
fn no_module_imports_a_higher_layer() {
    let edges = graph(&src());
    assert!(
        edges.len() > 100,
        "{} modules: the walk missed src/",
        edges.len()
    );
    let upward: Vec<String> = edges
        .iter()
        .flat_map(|(from, to)| to.iter().map(move |t| (from, t)))
        .filter(|(from, to)| matches!((layer(from), layer(to)), (Some(a), Some(b)) if b > a))
        .map(|(from, to)| format!("{} → {}", name(from), name(to)))
        .collect();
    assert!(
        upward.is_empty(),
        "imports up a layer:\n{}",
        upward.join("\n")
    );
}

#[test]
fn no_module_imports_itself_round_a_circle() {
    let found = circles(&graph(&src()));
    let said: Vec<String> = found
        .iter()
        .map(|c| c.iter().map(name).collect::<Vec<_>>().join(" ↔ "))
        .collect();
    assert!(said.is_empty(), "import circles:\n{}", said.join("\n"));
}

/// A new force law is one file plus its line in the registry: the rigid law (eq. (12))
/// was added so: no module imports it, its type is named in no other file, its entry
/// only in the registry's list (`physics::law`, which declares the file), and the
/// command line, parameter files, reports and Python reach it through the registry
/// alone (tests/dynamics.rs runs it by name).
#[test]
fn a_law_added_as_the_registry_says_is_imported_by_the_registry_alone() {
    let rigid: Module = ["physics", "law", "rigid"].map(String::from).to_vec();
    let edges = graph(&src());
    assert!(edges.contains_key(&rigid), "no src/physics/law/rigid.rs");
    let importers: Vec<String> = edges
        .iter()
        .filter(|(_, to)| to.contains(&rigid))
        .map(|(from, _)| name(from))
        .collect();
    assert!(importers.is_empty(), "{importers:?}");
    let mut files = Vec::new();
    sources(&src(), &mut files);
    let naming = |what: &str| -> Vec<String> {
        files
            .iter()
            .filter(|f| code_only(&std::fs::read_to_string(f).unwrap()).contains(what))
            .map(|f| f.strip_prefix(src()).unwrap().display().to_string())
            .collect()
    };
    assert_eq!(naming("RigidLaw"), ["physics/law/rigid.rs"]);
    assert_eq!(naming("rigid::RIGID"), ["physics/law/mod.rs"]);
}

#[test]
fn the_library_names_none_of_the_applications_dependencies() {
    // The dependencies behind the `app` feature, as Cargo.toml lists them.
    let manifest =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml")).unwrap();
    let line = manifest
        .lines()
        .find(|l| l.trim_start().starts_with("app = ["))
        .expect("the app feature");
    let app_crates: Vec<String> = line
        .split('"')
        .filter_map(|s| s.strip_prefix("dep:"))
        .map(|s| s.replace('-', "_"))
        .collect();
    assert!(app_crates.iter().any(|c| c == "clap"), "{app_crates:?}");
    let src = src();
    let mut files = Vec::new();
    sources(&src, &mut files);
    let mut named = Vec::new();
    for file in files {
        let module = module_of(&src, &file);
        if layer(&module).is_none_or(|l| l == 5) {
            continue;
        }
        // A derive behind the app feature (`cfg_attr(feature = "app", derive(clap::…))`)
        // is compiled only with it.
        let text: String = std::fs::read_to_string(&file)
            .unwrap()
            .lines()
            .filter(|l| !l.contains("cfg_attr(feature = \"app\""))
            .collect::<Vec<_>>()
            .join("\n");
        let code = code_only(&text);
        for c in &app_crates {
            let needle = format!("{c}::");
            let uses = code.match_indices(&needle).any(|(at, _)| {
                at == 0 || {
                    let before = code[..at].chars().next_back().unwrap();
                    !(before.is_alphanumeric() || before == '_' || before == ':')
                }
            });
            if uses {
                named.push(format!("{} names {c}", name(&module)));
            }
        }
    }
    assert!(named.is_empty(), "{}", named.join("\n"));
}

/// The checks themselves catch what they are for: a circle and an upward import written
/// into a scratch tree are found.
#[test]
fn the_checks_find_a_circle_and_an_upward_import() {
    let dir = std::env::temp_dir().join(format!("tapsim-architecture-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("dynamics")).unwrap();
    std::fs::create_dir_all(dir.join("analysis")).unwrap();
    let write = |p: &str, text: &str| std::fs::write(dir.join(p), text).unwrap();
    write("lib.rs", "pub mod dynamics;\npub mod analysis;\n");
    write("dynamics/mod.rs", "pub mod a;\npub mod b;\n");
    write(
        "dynamics/a.rs",
        "//! use crate::analysis::fit; (a comment)\nuse super::b::{X, c::{Y}};\nconst S: &str = \"crate::analysis\";\n",
    );
    write(
        "dynamics/b.rs",
        "pub fn f() { crate::dynamics::a::g(); }\n#[cfg(test)]\nmod tests {\n    use super::f;\n    fn t() { crate::analysis::fit::go(); }\n}\n",
    );
    write("analysis/mod.rs", "pub mod fit;\n");
    write("analysis/fit.rs", "use crate::dynamics::a;\n");
    let edges = graph(&dir);
    let dynamics = |m: &str| vec!["dynamics".to_string(), m.to_string()];
    let fit = vec!["analysis".to_string(), "fit".to_string()];
    assert_eq!(
        edges[&dynamics("a")],
        BTreeSet::from([dynamics("b")]),
        "comments and strings are not imports"
    );
    assert_eq!(
        edges[&dynamics("b")],
        BTreeSet::from([dynamics("a"), fit.clone()]),
        "a test module's imports count"
    );
    assert_eq!(edges[&fit], BTreeSet::from([dynamics("a")]));
    let found = circles(&edges);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].len(), 3, "a ↔ b, and b → fit → a");
    assert!(matches!(
        (layer(&dynamics("b")), layer(&fit)),
        (Some(2), Some(4))
    ));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn library_modules_touch_no_file_no_environment_and_name_no_flag() {
    let src = src();
    let mut files = Vec::new();
    sources(&src, &mut files);
    files.retain(|f| layer(&module_of(&src, f)).is_some_and(|l| l < 5));
    assert!(files.len() > 80, "{files:?}");
    let forbidden = ["std::fs", "fs::", "std::env", "env::var", "File::"];
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            // (Test modules may use files: they are not the library.)
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
                assert!(
                    !code.contains(word),
                    "{}:{}: `{word}` in the library: {line}",
                    file.display(),
                    n + 1
                );
            }
        }
    }
}

/// Within a layer, the order its folders' docs state: the parameters (which take the
/// adhesive length scale from contact mechanics) and the closed forms of contact
/// mechanics under the force laws, the laws under the quasi-static cycles, the reports
/// under the command line.
#[test]
fn within_a_layer_the_stated_order_holds() {
    let below = [
        ("physics::params", "physics::law"),
        ("physics::contact", "physics::law"),
        ("physics::contact", "physics::quasistatic"),
        ("physics::law", "physics::quasistatic"),
        ("physics::law", "physics::summary"),
        ("app::report", "app::cli"),
    ];
    let edges = graph(&src());
    let mut broken = Vec::new();
    for (from, to) in edges
        .iter()
        .flat_map(|(f, t)| t.iter().map(move |t| (f, t)))
    {
        let (from, to) = (name(from), name(to));
        for (lower, upper) in below {
            let within =
                |m: &str, folder: &str| m == folder || m.starts_with(&format!("{folder}::"));
            if within(&from, lower) && within(&to, upper) {
                broken.push(format!("{from} → {to} ({lower} is below {upper})"));
            }
        }
    }
    assert!(broken.is_empty(), "{}", broken.join("\n"));
}

/// Each crate of the build and the features it is built with, as `cargo tree` shows
/// them for the package `package` with the dependency kinds `edges`.
fn features(package: &str, edges: &str) -> BTreeMap<String, BTreeSet<String>> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .args([
            "tree",
            "--offline",
            "--locked",
            "--prefix",
            "none",
            "-p",
            package,
        ])
        .args(["-e", edges, "-f", "{p} [{f}]"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo runs");
    assert!(
        out.status.success(),
        "cargo tree: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut crates: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for line in String::from_utf8(out.stdout).unwrap().lines() {
        let line = line.trim_end_matches(" (*)");
        let Some((name, features)) = line.rsplit_once(" [") else {
            continue;
        };
        // "serde v1.0.229" (a path dependency adds its folder in parentheses).
        let name: String = name.split(" (").next().unwrap().to_string();
        crates
            .entry(name)
            .or_default()
            .insert(features.trim_end_matches(']').to_string());
    }
    crates
}

/// One build of every dependency serves the run (`cargo run --release`), the tests
/// (`cargo test --release`: the dev-dependencies too) and the Python package (maturin,
/// in the same target/): no crate the run builds is built with other features for the
/// tests or for the package, which would build it and everything above it a second
/// time (Cargo.toml turns those features on for tapsim itself; docs/src/speed.md).
#[test]
fn the_run_the_tests_and_the_python_package_share_one_build_of_each_dependency() {
    let run = features("tapsim", "normal,build");
    assert!(run.len() > 100, "{} crates", run.len());
    for (what, other) in [
        ("the tests", features("tapsim", "normal,build,dev")),
        (
            "the Python package",
            features("tapsim-python", "normal,build"),
        ),
    ] {
        for (name, built) in &run {
            if let Some(there) = other.get(name) {
                assert_eq!(
                    built, there,
                    "{name} is built with features {built:?} for the run and {there:?} for {what}: \
                     turn those on in Cargo.toml too"
                );
            }
        }
    }
}
