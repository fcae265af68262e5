//! The architecture invariants of ARCHITECTURE.md, checked on the source: which module may
//! name which (`crate::x` paths and `use` lines), and which may touch the file system. A new
//! edge that runs back up the stages fails here, naming the file and the line.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// What the two middle stages, analyse and generate, may name.
const STAGE: &[&str] = &[
    "model",
    "geom",
    "params",
    "templates",
    "rng",
    "materials",
    "growers",
];

/// Every crate-level module and the modules of ours it may depend on. The pipeline reads in
/// one direction: read inputs -> analyse -> generate -> write outputs, over `model` (plain
/// data) and `geom` (plane geometry); `materials` and `rng` are libraries every stage may use.
const ALLOWED: &[(&str, &[&str])] = &[
    ("model", &[]),
    ("geom", &[]),
    ("materials", &[]),
    ("rng", &[]),
    // Reading a file a user named within bounds: for every module that reads one.
    ("bounded", &[]),
    // The procedural growers know nothing of GIS: plane geometry and the RNG only.
    ("growers", &["geom", "rng"]),
    ("params", &["model", "growers", "bounded"]),
    (
        "templates",
        &["materials", "geom", "model", "growers", "bounded"],
    ),
    ("input", &["model", "geom", "params", "bounded"]),
    ("analyse", STAGE),
    ("generate", STAGE),
    (
        "output",
        &[
            "model",
            "geom",
            "params",
            "generate",
            "materials",
            "growers",
            "templates",
            "rng",
            "bounded",
        ],
    ),
    ("synth", &["rng", "model", "geom"]),
    ("init", &["input", "params", "synth"]),
    (
        "author",
        &[
            "generate",
            "output",
            "params",
            "templates",
            "model",
            "geom",
            "materials",
        ],
    ),
    ("compare", &["build", "model", "output"]),
    (
        "build",
        &[
            "analyse",
            "generate",
            "input",
            "materials",
            "model",
            "output",
            "params",
            "templates",
            "geom",
            "growers",
            "bounded",
        ],
    ),
];

/// The modules that may touch the file system: the readers and writers, the command-line
/// edge, and the modules whose input is itself a file (parameter and template files, the
/// synthetic town's shapefiles, `init`'s walk, `author`'s template preview).
const FILE_SYSTEM: &[&str] = &[
    "bounded",
    "input",
    "output",
    "build",
    "params",
    "templates",
    "synth",
    "init",
    "author",
];

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// The `.rs` files of each crate-level module (`src/x.rs` and everything under `src/x/`).
fn modules() -> BTreeMap<String, Vec<PathBuf>> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    let mut out: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
    for e in std::fs::read_dir(src()).unwrap().flatten() {
        let p = e.path();
        let name = p.file_stem().unwrap().to_string_lossy().to_string();
        if name == "lib" || name == "main" || name == "cli" {
            continue;
        }
        let files = out.entry(name).or_default();
        if p.is_dir() {
            walk(&p, files);
        } else {
            files.push(p);
        }
    }
    out
}

/// The code of a line, without a `//` comment (doc comments name other modules freely).
fn code(line: &str) -> &str {
    match line.find("//") {
        Some(i) => &line[..i],
        None => line,
    }
}

/// The crate-level modules a line names through `crate::x`.
fn named(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = code(line);
    while let Some(i) = rest.find("crate::") {
        let after = &rest[i + "crate::".len()..];
        let name: String = after
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect();
        // `use crate::{a, b}` names several.
        if name.is_empty() && after.starts_with('{') {
            let inner = &after[1..after.find('}').unwrap_or(after.len())];
            out.extend(
                inner
                    .split(',')
                    .map(|s| s.trim().split("::").next().unwrap_or("").to_string()),
            );
        } else {
            out.push(name);
        }
        rest = after;
    }
    out.retain(|n| !n.is_empty());
    out
}

#[test]
fn every_module_is_in_the_table() {
    let known: Vec<&str> = ALLOWED.iter().map(|(m, _)| *m).collect();
    for m in modules().keys() {
        assert!(
            known.contains(&m.as_str()),
            "src/{m}: a new module; add it to ALLOWED in tests/architecture.rs and to \
             ARCHITECTURE.md's dependency list"
        );
    }
}

#[test]
fn modules_depend_only_on_what_architecture_md_allows() {
    let allowed: BTreeMap<&str, &[&str]> = ALLOWED.iter().copied().collect();
    let mut wrong = Vec::new();
    for (m, files) in modules() {
        let ok = allowed.get(m.as_str()).copied().unwrap_or(&[]);
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap();
            for (n, line) in text.lines().enumerate() {
                for dep in named(line) {
                    if dep != m && !ok.contains(&dep.as_str()) {
                        wrong.push(format!(
                            "{}:{}: {m} -> {dep}: {}",
                            f.display(),
                            n + 1,
                            line.trim()
                        ));
                    }
                }
                if code(line).contains("super::super::") {
                    wrong.push(format!(
                        "{}:{}: `super::super::` climbs out of a module: name the module by \
                         `crate::` so the dependency shows",
                        f.display(),
                        n + 1
                    ));
                }
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "edges ARCHITECTURE.md forbids:\n{}",
        wrong.join("\n")
    );
}

#[test]
fn only_the_readers_writers_and_the_cli_touch_the_file_system() {
    let mut wrong = Vec::new();
    for (m, files) in modules() {
        if FILE_SYSTEM.contains(&m.as_str()) {
            continue;
        }
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap();
            // Unit tests may write scratch files.
            let body = text.split("#[cfg(test)]").next().unwrap_or("");
            for (n, line) in body.lines().enumerate() {
                let c = code(line);
                if c.contains("std::fs") || c.contains("fs::") || c.contains("File::") {
                    wrong.push(format!("{}:{}: {}", f.display(), n + 1, line.trim()));
                }
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "file system access outside input/, output/, build and the CLI:\n{}",
        wrong.join("\n")
    );
}

#[test]
fn the_checker_sees_an_edge_and_ignores_comments() {
    assert_eq!(named("use crate::input::dem::Dem;"), vec!["input"]);
    assert_eq!(
        named("use crate::{model, geom::frame};"),
        vec!["model", "geom"]
    );
    assert!(named("/// see [`crate::input`]").is_empty());
    assert_eq!(
        named("let d: crate::model::dem::Dem; // crate::output"),
        vec!["model"]
    );
}
