//! The architecture invariants of ARCHITECTURE.md, checked on the source: which module may
//! name which (`crate::x` paths and `use` lines), and which may touch the file system. A new
//! edge that runs back up the stages fails here, naming the file and the line.

use std::collections::{BTreeMap, BTreeSet};
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

/// Every `.rs` file under `dir`, into `out`.
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

/// The `.rs` files of each crate-level module (`src/x.rs` and everything under `src/x/`).
fn modules() -> BTreeMap<String, Vec<PathBuf>> {
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

/// ARCHITECTURE.md: no file in src/ over 600 lines (issue 58: a file a newcomer can read
/// whole; split by what its parts decide, as `generate/instance/` and `gltf/primitive.rs`).
#[test]
fn no_source_file_is_over_600_lines() {
    let mut files = Vec::new();
    walk(&src(), &mut files);
    assert!(
        files.len() > 100,
        "the walk found the sources: {}",
        files.len()
    );
    let mut long: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let n = std::fs::read_to_string(f).unwrap().lines().count();
            (n > 600).then(|| format!("{}: {n} lines", f.display()))
        })
        .collect();
    long.sort();
    assert!(
        long.is_empty(),
        "files over 600 lines:\n{}",
        long.join("\n")
    );
}

/// Whether `line` holds `word` not followed by more of a name (`&mut Plan`, not
/// `&mut PlannedHouse`).
fn holds_word(line: &str, word: &str) -> bool {
    line.match_indices(word).any(|(i, _)| {
        !line[i + word.len()..]
            .chars()
            .next()
            .is_some_and(|c| c.is_alphanumeric() || c == '_')
    })
}

/// The lines of `files` (outside unit tests and comments) holding `word`.
fn lines_holding(files: &[PathBuf], word: &str) -> Vec<String> {
    let mut found = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(f).unwrap();
        let body = text.split("#[cfg(test)]").next().unwrap_or("");
        for (n, line) in body.lines().enumerate() {
            if holds_word(code(line), word) {
                found.push(format!("{}:{}: {}", f.display(), n + 1, line.trim()));
            }
        }
    }
    found
}

/// Each analysis step takes what it reads and returns its product (`analyse/product.rs`);
/// only `analyse::analyse` files the products into the plan, so what a step depends on is
/// in its signature.
#[test]
fn no_analysis_step_writes_into_the_plan() {
    let mut files = Vec::new();
    walk(&src().join("analyse"), &mut files);
    assert!(files.len() > 10, "the walk found analyse/: {}", files.len());
    let steps: Vec<PathBuf> = files
        .into_iter()
        .filter(|f| !f.ends_with("analyse/mod.rs") && !f.ends_with("analyse/product.rs"))
        .collect();
    let wrong = lines_holding(&steps, "&mut Plan");
    assert!(
        wrong.is_empty(),
        "analysis steps taking the plan to write into:\n{}",
        wrong.join("\n")
    );
    // The check sees one.
    let dir = std::env::temp_dir().join(format!("arch-plan-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("step.rs");
    let text =
        "pub fn step(plan: &mut Plan) {}\n// plan: &mut Plan\nfn h(m: &mut PlannedHouse) {}\n";
    std::fs::write(&f, text).unwrap();
    assert_eq!(
        lines_holding(std::slice::from_ref(&f), "&mut Plan").len(),
        1
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A build's errors are typed where they are made: no catch-all string variant.
#[test]
fn build_errors_have_no_catch_all_string() {
    let mut files = Vec::new();
    walk(&src(), &mut files);
    let wrong = lines_holding(&files, "BuildError::Config");
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    let error = std::fs::read_to_string(src().join("build/error.rs")).unwrap();
    assert!(!error.contains("Config(String)"), "build/error.rs");
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

/// The sibling modules (children of the same parent) `text` (one file's code, comments
/// gone) names: by `super::x` when the file is the sibling's own (`p/f.rs`, `p/f/mod.rs`),
/// and by `crate::<parent>::x` from anywhere below it.
fn siblings_named(text: &str, parent: &str, direct: bool) -> BTreeSet<String> {
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = BTreeSet::new();
    let mut prefixes = vec![format!("crate::{parent}::")];
    if direct {
        prefixes.push("super::".to_string());
    }
    for prefix in &prefixes {
        let mut rest = text;
        while let Some(i) = rest.find(prefix.as_str()) {
            // `super::` inside `crate::a::super::`? Not Rust; but skip `xsuper::`.
            let before = rest[..i].chars().last();
            let after = &rest[i + prefix.len()..];
            rest = after;
            if prefix == "super::"
                && before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == ':')
            {
                continue;
            }
            if let Some(group) = after.strip_prefix('{') {
                // `super::{a, b::C, c::{D}}`: the first word of each top-level item.
                let (mut depth, mut item) = (0, String::new());
                for ch in group.chars() {
                    match ch {
                        '{' => depth += 1,
                        '}' if depth == 0 => break,
                        '}' => depth -= 1,
                        ',' if depth == 0 => {
                            out.insert(ident(item.trim()));
                            item.clear();
                            continue;
                        }
                        _ => {}
                    }
                    if depth == 0 {
                        item.push(ch);
                    }
                }
                out.insert(ident(item.trim()));
            } else {
                out.insert(ident(after));
            }
        }
    }
    out.retain(|n| !n.is_empty() && n != "self");
    out
}

/// Every module's children and which of them each one names, from the files under `src/`.
fn sibling_edges() -> BTreeMap<String, BTreeMap<String, BTreeSet<String>>> {
    let mut files = Vec::new();
    walk(&src(), &mut files);
    // parent module path -> child -> the siblings it names
    let mut edges: BTreeMap<String, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for f in files {
        let rel = f.strip_prefix(src()).unwrap().with_extension("");
        let mut parts: Vec<String> = rel
            .components()
            .map(|c| c.as_os_str().to_string_lossy().to_string())
            .collect();
        if parts.last().is_some_and(|l| l == "mod") {
            parts.pop();
        }
        if parts.first().is_some_and(|p| p == "lib" || p == "main") || parts.len() < 2 {
            continue;
        }
        // The code, without comments and without its unit tests (a test may build its case
        // from a sibling's helper).
        let whole = std::fs::read_to_string(&f).unwrap();
        let text: String = whole[..whole.find("#[cfg(test)]").unwrap_or(whole.len())]
            .lines()
            .map(|l| format!("{}\n", code(l)))
            .collect();
        // The file belongs to the child `parts[k]` of every ancestor `parts[..k]`.
        for k in 1..parts.len() {
            let parent = parts[..k].join("::");
            let child = parts[k].clone();
            let direct = k == parts.len() - 1;
            let named = siblings_named(&text, &parent, direct);
            let entry = edges.entry(parent).or_default();
            let set = entry.entry(child.clone()).or_default();
            set.extend(named.into_iter().filter(|n| *n != child));
        }
    }
    edges
}

/// A circle among `graph`'s nodes, if there is one, as the nodes around it.
fn circle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(n.to_string(), 1);
        path.push(n.to_string());
        for m in graph.get(n).into_iter().flatten() {
            if !graph.contains_key(m) {
                continue;
            }
            match state.get(m).copied().unwrap_or(0) {
                1 => {
                    let start = path.iter().position(|p| p == m).unwrap();
                    return Some(path[start..].to_vec());
                }
                0 => {
                    if let Some(c) = visit(m, graph, state, path) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        path.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in graph.keys() {
        if state.get(n).copied().unwrap_or(0) == 0 {
            if let Some(c) = visit(n, graph, &mut state, &mut Vec::new()) {
                return Some(c);
            }
        }
    }
    None
}

/// ARCHITECTURE.md: no module imports its own parent's children in a circle (issue 58:
/// `output/sink.rs` and the sinks, `gltf/` and `tiles3d/lod/`, the gpkg layers' files).
#[test]
fn no_children_of_one_module_import_each_other_in_a_circle() {
    let mut found = Vec::new();
    for (parent, graph) in sibling_edges() {
        if let Some(c) = circle(&graph) {
            found.push(format!("{parent}: {}", c.join(" -> ")));
        }
    }
    assert!(
        found.is_empty(),
        "circles among siblings:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_circle_finder_sees_a_circle_through_super_and_crate_paths() {
    let a = siblings_named(
        "use super::{b, c::{D, E}};\nlet x = crate::m::d::f();",
        "m",
        true,
    );
    assert_eq!(a, ["b", "c", "d"].iter().map(|s| s.to_string()).collect());
    assert!(
        siblings_named("use super::b;", "m", false).is_empty(),
        "not its own"
    );
    let graph: BTreeMap<String, BTreeSet<String>> = [
        ("a", vec!["b"]),
        ("b", vec!["c"]),
        ("c", vec!["a"]),
        ("d", vec!["a"]),
    ]
    .iter()
    .map(|(k, v)| (k.to_string(), v.iter().map(|s| s.to_string()).collect()))
    .collect();
    assert_eq!(circle(&graph).unwrap().len(), 3);
    let mut open = graph.clone();
    open.get_mut("c").unwrap().clear();
    assert!(circle(&open).is_none());
}
