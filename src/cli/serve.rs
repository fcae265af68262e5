//! `edo-city serve <out> [<more outs>]`: the web viewer and one or more builds of the same
//! place (hypotheses, eras) on 127.0.0.1, with the right MIME types (the HTTP side in
//! `serve/http.rs`: hyper and tower-http, with bounds on connections and time).
//!
//! Routes: `/` the viewer page; `/viewer/<file>` its scripts (and `cesium.html`, the build in
//! CesiumJS); `/node_modules/<pkg>/...` the npm packages they import (three.js,
//! 3d-tiles-renderer, CesiumJS), from `viewer/node_modules`;
//! `/hypotheses.json` the builds, in the order given; `/h/<k>/<path>` a file of build k;
//! `/api/gardens...` the rock-garden designer (`serve/api.rs`), which writes only the file
//! `--designs` names. Nothing outside those directories is ever served, no request naming
//! another host is answered, and a write must come from the served origin with a page
//! token (`serve/guard.rs`).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;

mod api;
mod designer;
mod guard;
mod http;
mod workbench;

/// The flags of `edo-city serve`.
#[derive(Args)]
pub struct ServeArgs {
    /// Build directories (each with a tileset.json: build with the glb format), in the order
    /// the viewer's hypothesis button steps through them; `/?h=K` opens the K-th (from 0).
    #[arg(required = true)]
    pub outs: Vec<PathBuf>,
    /// Port on 127.0.0.1; 0 picks a free one (the URL printed says which).
    #[arg(long, default_value_t = 8080)]
    pub port: u16,
    /// Open the page in the machine's browser (xdg-open).
    #[arg(long)]
    pub open: bool,
    /// The viewer directory (index.html, main.js, node_modules/); default: the one of the
    /// source tree edo-city was built from.
    #[arg(long)]
    pub viewer: Option<PathBuf>,
    /// The designs file the garden designer keeps designs in (created at the first keep;
    /// a build reads it through `[garden] designs`). Without it the designer is read-only.
    #[arg(long)]
    pub designs: Option<PathBuf>,
    /// Edit a hypothesis in the browser (docs/workbench.md): the first build is rebuilt from
    /// its input with this parameter file as you change parameters and lots, keeping the
    /// tiles that stay the same; `save` writes the file (created if it does not exist), its
    /// overrides (`<params>.overrides.csv`) and its log (`<params>.history.jsonl`).
    #[arg(long, value_name = "PARAMS.toml")]
    pub edit: Option<PathBuf>,
    /// With --edit: the input directory the first build was made from (found by itself when
    /// it is where the build was run from, beside the build, or beside the parameter file).
    #[arg(long, requires = "edit")]
    pub input: Option<PathBuf>,
    /// With --edit: worker threads of the rebuilds (0 = one per core).
    #[arg(short = 'j', long, default_value_t = 0, requires = "edit")]
    pub threads: usize,
}

/// One build being served.
struct Hypothesis {
    name: String,
    dir: PathBuf,
    tiles: usize,
}

/// The MIME type of a file, by its extension.
fn mime(path: &Path) -> &'static str {
    match path.extension().and_then(|e| e.to_str()).unwrap_or("") {
        "html" => "text/html; charset=utf-8",
        "js" | "mjs" => "text/javascript; charset=utf-8",
        "json" => "application/json",
        "glb" => "model/gltf-binary",
        "gltf" => "model/gltf+json",
        "png" => "image/png",
        "jpg" | "jpeg" => "image/jpeg",
        "css" => "text/css; charset=utf-8",
        "wasm" => "application/wasm",
        "svg" => "image/svg+xml",
        "obj" | "mtl" | "csv" | "txt" | "map" => "text/plain; charset=utf-8",
        _ => "application/octet-stream",
    }
}

/// `rel` under `root`, or `None` when it would leave it (`..`, absolute, a link out).
fn contained(root: &Path, rel: &str) -> Option<PathBuf> {
    let rel = rel.trim_start_matches('/');
    if rel.split('/').any(|p| p == ".." || p.contains('\\')) {
        return None;
    }
    let path = root.join(rel);
    let real = path.canonicalize().ok()?;
    let root = root.canonicalize().ok()?;
    (real.starts_with(&root) && real.is_file()).then_some(real)
}

/// The file a URL path names, if any.
fn route(url: &str, viewer: &Path, builds: &[Hypothesis]) -> Option<PathBuf> {
    let path = url.split(['?', '#']).next().unwrap_or("");
    let path = percent_decode(path)?;
    if path == "/" || path == "/index.html" {
        return contained(viewer, "index.html");
    }
    if let Some(rest) = path.strip_prefix("/viewer/") {
        return contained(viewer, rest);
    }
    if path.starts_with("/node_modules/") {
        return contained(viewer, &path);
    }
    let rest = path.strip_prefix("/h/")?;
    let (k, file) = rest.split_once('/')?;
    let b = builds.get(k.parse::<usize>().ok()?)?;
    contained(&b.dir, file)
}

/// `%xx` escapes decoded; `None` when the result is not UTF-8.
fn percent_decode(s: &str) -> Option<String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = std::str::from_utf8(&b[i + 1..i + 3]).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// The builds, checked: each has a manifest and a tileset.
fn hypotheses(outs: &[PathBuf]) -> Result<Vec<Hypothesis>> {
    let mut hs = Vec::new();
    for dir in outs {
        let manifest = dir.join("manifest.json");
        let bytes = edo_city::bounded::read(&manifest, 2 << 30).with_context(|| {
            format!(
                "{} is not a build directory (no manifest.json): give the --out of `edo-city build`",
                dir.display()
            )
        })?;
        if !dir.join("tileset.json").is_file() {
            bail!(
                "{} has no tileset.json: build it with the glb format (`--format obj,glb`, the default)",
                dir.display()
            );
        }
        let m: serde_json::Value = serde_json::from_slice(&bytes)
            .with_context(|| format!("{}: not a manifest", manifest.display()))?;
        let tiles = m["tiles"].as_array().map_or(0, |t| t.len());
        let name = dir
            .canonicalize()
            .ok()
            .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
            .unwrap_or_else(|| dir.display().to_string());
        hs.push(Hypothesis {
            name,
            dir: dir.clone(),
            tiles,
        });
    }
    Ok(hs)
}

/// The viewer directory: given, else the source tree's.
fn viewer_dir(given: Option<PathBuf>) -> Result<PathBuf> {
    let dir = given.unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("viewer"));
    if !dir.join("index.html").is_file() {
        bail!(
            "{}: no viewer here (index.html); give the viewer directory with --viewer",
            dir.display()
        );
    }
    if !dir.join("node_modules/three").is_dir() {
        bail!(
            "{}: the viewer's npm packages are missing: run `make viewer-deps` (npm ci in {})",
            dir.display(),
            dir.display()
        );
    }
    Ok(dir)
}

/// `edo-city serve`.
pub fn serve_command(args: ServeArgs) -> Result<()> {
    let viewer = viewer_dir(args.viewer)?;
    let builds = hypotheses(&args.outs)?;
    let dirs: Vec<PathBuf> = builds.iter().map(|b| b.dir.clone()).collect();
    let designer = api::Api::new(&dirs, args.designs.clone())?;
    let bench = match &args.edit {
        Some(params) => Some(start_workbench(
            params,
            &dirs,
            args.input.as_deref(),
            args.threads,
        )?),
        None => None,
    };
    let list = serde_json::to_vec(&serde_json::json!(builds
        .iter()
        .enumerate()
        .map(|(k, b)| serde_json::json!({
            "index": k,
            "name": b.name,
            "tileset": format!("/h/{k}/tileset.json"),
            "base": format!("/h/{k}/"),
            "tiles": b.tiles,
            "links": b.dir.join("links.json").is_file(),
        }))
        .collect::<Vec<_>>()))?;
    let listener = std::net::TcpListener::bind(("127.0.0.1", args.port)).with_context(|| {
        format!(
            "cannot listen on 127.0.0.1:{} (another server there? try --port 0)",
            args.port
        )
    })?;
    let port = listener.local_addr().map_or(args.port, |a| a.port());
    let url = format!("http://127.0.0.1:{port}/");
    // Printed once, ignoring a closed stdout: the server goes on whoever reads it.
    let mut text = format!("serving {} build(s) at {url}\n", builds.len());
    for (k, b) in builds.iter().enumerate() {
        text += &format!("  {url}?h={k}  {} ({} tiles)\n", b.dir.display(), b.tiles);
    }
    if viewer.join("node_modules/cesium").is_dir() {
        text += &format!("  in CesiumJS: {url}viewer/cesium.html?h=0\n");
    }
    if let Some(b) = &bench {
        let f = b.files();
        text += &format!(
            "  editing {} (overrides {}, log {}): build 0 is rebuilt as you edit\n",
            f.params.display(),
            f.overrides.display(),
            f.history.display()
        );
    }
    if let Some(d) = &args.designs {
        text += &format!("  garden designs are kept in {}\n", d.display());
    }
    text += "press Ctrl-C to stop\n";
    {
        use std::io::Write as _;
        let mut out = std::io::stdout();
        let _ = out.write_all(text.as_bytes());
        let _ = out.flush();
    }
    if args.open {
        let _ = std::process::Command::new("xdg-open").arg(&url).spawn();
    }
    let guard = guard::Guard::new(port);
    let handler: http::Handler = std::sync::Arc::new(move |call: &http::Call| {
        if let Err(r) = guard.host(&call.headers) {
            return http::Answer::Refused {
                status: r.status,
                message: r.message,
            };
        }
        if let Some(a) = workbench::routes::answer(bench.as_deref(), call, &guard) {
            return a;
        }
        if let Some(a) = designer.answer(call, &guard) {
            return a;
        }
        match call.post {
            true => http::Answer::NotAllowed { allow: "GET, HEAD" },
            false => answer(&call.target, &viewer, &builds, &list),
        }
    });
    http::serve(listener, handler, http::Limits::default()).context("the server stopped")
}

/// The workbench of `--edit params` over the build in `out`, its input found (given, else
/// where the manifest says, checked by its fingerprint) and its first build started.
fn start_workbench(
    params: &Path,
    dirs: &[PathBuf],
    input: Option<&Path>,
    threads: usize,
) -> Result<std::sync::Arc<workbench::Workbench>> {
    let out = &dirs[0];
    let bytes = edo_city::bounded::read(&out.join("manifest.json"), 2 << 30)?;
    let m: serde_json::Value = serde_json::from_slice(&bytes)
        .with_context(|| format!("{}: not a manifest", out.join("manifest.json").display()))?;
    let input = find_input(&m, out, params, input)?;
    let templates = m["input"]["templates"].as_str().map(PathBuf::from);
    // The parameter file first, before it is read: `--edit IN/lots.shp` is a file of the
    // input, not a parameter file that does not parse.
    outside_the_build(
        params,
        &workbench::absolute(params),
        "the parameter file",
        &input,
        out,
    )?;
    let files = workbench::Files::of(params)?;
    // The hypothesis's files are written at `save`: never into what the build reads or
    // writes (an overrides file named `lots.csv` in the input would replace the lots' table).
    for (path, what) in [
        (&files.params, "the parameter file"),
        (&files.overrides, "its overrides"),
        (&files.history, "its log"),
    ] {
        outside_the_build(params, path, what, &input, out)?;
    }
    let place = workbench::Place {
        input,
        out: out.to_path_buf(),
        templates,
        threads,
        served: dirs.to_vec(),
    };
    workbench::Workbench::start(files, place)
}

/// Refuses a file of the hypothesis (`what`, at `path`) inside the input or the build.
fn outside_the_build(
    params: &Path,
    path: &Path,
    what: &str,
    input: &Path,
    out: &Path,
) -> Result<()> {
    {
        let real = path
            .parent()
            .and_then(|d| d.canonicalize().ok())
            .map(|d| d.join(path.file_name().unwrap_or_default()));
        for (dir, name) in [(input, "the input"), (out, "the build")] {
            let inside = match (&real, dir.canonicalize()) {
                (Some(r), Ok(d)) => r.starts_with(&d),
                _ => false,
            };
            if inside {
                bail!(
                    "--edit {}: {what} ({}) would be written inside {name} ({}); keep the \
                     hypothesis beside it, not in it",
                    params.display(),
                    path.display(),
                    dir.display()
                );
            }
        }
    }
    Ok(())
}

/// The input directory a build was made from: `given`, else the manifest's own path (a
/// shard's), else its name looked for where the build was run from, beside the build and
/// beside the parameter file, each checked against the manifest's fingerprint of it.
fn find_input(
    m: &serde_json::Value,
    out: &Path,
    params: &Path,
    given: Option<&Path>,
) -> Result<PathBuf> {
    if let Some(dir) = given {
        if !dir.is_dir() {
            bail!("--input {}: not a directory", dir.display());
        }
        return Ok(workbench::absolute(dir));
    }
    let named = m["input"]["input"].as_str().unwrap_or_default();
    let id = m["input"]["input_id"].as_str();
    let mut tried = Vec::new();
    let near = |p: &Path| p.parent().map(|d| workbench::absolute(d).join(named));
    for candidate in [Some(PathBuf::from(named)), near(out), near(params)]
        .into_iter()
        .flatten()
    {
        let abs = workbench::absolute(&candidate);
        let same = match id {
            Some(id) => edo_city::output::report::input_id(&abs) == id,
            None => true,
        };
        if abs.is_dir() && same {
            return Ok(abs);
        }
        let shown = abs.display().to_string();
        if !tried.contains(&shown) {
            tried.push(shown);
        }
    }
    bail!(
        "cannot find the input {} was built from (`{named}`; looked at {}): give it with --input",
        out.display(),
        tried.join(", ")
    )
}

/// The answer to a GET of `url`: a file, the hypotheses list, or 404.
fn answer(url: &str, viewer: &Path, builds: &[Hypothesis], list: &[u8]) -> http::Answer {
    if url.split('?').next() == Some("/hypotheses.json") {
        return http::Answer::Bytes {
            status: 200,
            content_type: "application/json",
            body: list.to_vec(),
        };
    }
    match route(url, viewer, builds) {
        Some(path) => http::Answer::File {
            content_type: mime(&path),
            path,
        },
        None => http::Answer::text(404, format!("not found: {url}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_stay_inside_their_directories() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("index.html"), "x").unwrap();
        std::fs::create_dir(dir.path().join("b")).unwrap();
        std::fs::write(dir.path().join("b/tileset.json"), "{}").unwrap();
        let builds = [Hypothesis {
            name: "b".into(),
            dir: dir.path().join("b"),
            tiles: 0,
        }];
        assert!(route("/", dir.path(), &builds).is_some());
        assert!(route("/h/0/tileset.json?x=1", dir.path(), &builds).is_some());
        assert!(route("/h/0/../index.html", dir.path(), &builds).is_none());
        assert!(route("/h/0/%2e%2e/index.html", dir.path(), &builds).is_none());
        assert!(route("/h/1/tileset.json", dir.path(), &builds).is_none());
        assert!(route("/viewer/../b/tileset.json", dir.path(), &builds).is_none());
        assert_eq!(mime(Path::new("a.glb")), "model/gltf-binary");
        assert_eq!(mime(Path::new("a.js")), "text/javascript; charset=utf-8");
    }
}
