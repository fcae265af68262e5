//! Helpers shared by the end-to-end tests: run the real binary, re-read what it wrote.
#![allow(dead_code)]

pub mod cityjson;
pub mod corpus;
mod corpus_ledger;
pub mod designer;
pub mod glb;

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use assert_cmd::Command;
use geo::{Contains, Distance, Euclidean};
use geo_types::{Coord, LineString, Point, Polygon};

pub fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(name)
}

/// The binary, with its analysis cache in the build's temporary directory (not the home
/// directory of whoever runs the tests).
pub fn edo_city() -> Command {
    let mut c = Command::cargo_bin("edo-city").expect("binary built");
    c.env(
        "EDO_CITY_CACHE",
        Path::new(env!("CARGO_TARGET_TMPDIR")).join("edo-city-cache"),
    );
    c
}

/// Runs `edo-city build <input> --out <out> <extra...>` and asserts it succeeded.
pub fn build_ok(input: &Path, out: &Path, extra: &[&str]) -> serde_json::Value {
    let output = edo_city()
        .arg("build")
        .arg(input)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .expect("runs");
    assert!(
        output.status.success(),
        "build failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    read_json(&out.join("report.json"))
}

/// A synthetic town of `lots` lots written by the library's `synth` (the same as the CLI's).
#[allow(dead_code)]
pub fn synth(dir: &Path, lots: usize, seed: u64) {
    edo_city::synth::write_town(dir, lots, seed, edo_city::synth::Profile::Grid, true)
        .expect("synth writes the town");
}

pub fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).expect("json exists")).expect("valid json")
}

/// Copies a fixture directory so a test can change it.
pub fn copy_fixture(name: &str, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(fixture(name)).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
}

/// Every file under `dir`, relative path -> bytes.
pub fn all_files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().display().to_string();
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

/// Fails unless directories `a` and `b` hold the same files with the same bytes.
pub fn assert_same_tree(a: &Path, b: &Path) {
    let (fa, fb) = (all_files(a), all_files(b));
    assert_eq!(
        fa.keys().collect::<Vec<_>>(),
        fb.keys().collect::<Vec<_>>(),
        "same files"
    );
    for (name, bytes) in &fa {
        assert!(bytes == &fb[name], "{name} differs");
    }
}

/// Lots of a shapefile: id -> (use, mtype, polygon).
pub fn read_lots(shp: &Path) -> HashMap<String, (String, String, Polygon<f64>)> {
    let mut reader = shapefile::Reader::from_path(shp).expect("lots readable");
    let mut out = HashMap::new();
    for item in reader.iter_shapes_and_records() {
        let (shape, record) = item.unwrap();
        let text = |k: &str| match record.get(k) {
            Some(dbase::FieldValue::Character(Some(s))) => s.trim().to_string(),
            Some(dbase::FieldValue::Numeric(Some(n))) => format!("{}", *n as i64),
            _ => String::new(),
        };
        let shapefile::Shape::Polygon(p) = shape else {
            panic!("lots are polygons")
        };
        let ring: Vec<Coord<f64>> = p.rings()[0]
            .points()
            .iter()
            .map(|q| Coord { x: q.x, y: q.y })
            .collect();
        out.insert(
            text("id"),
            (
                text("use"),
                text("mtype"),
                Polygon::new(LineString(ring), vec![]),
            ),
        );
    }
    out
}

/// One machiya object as re-read by tobj: its name, map-frame vertices, materials used.
pub struct ObjObject {
    pub name: String,
    /// (east, north, up) in map metres.
    pub vertices: Vec<[f64; 3]>,
    pub materials: Vec<String>,
}

/// Every object of every tile a build in `out` wrote (through [`load_tile`]), in map metres.
pub fn build_objects(out: &Path) -> Vec<ObjObject> {
    let m = read_json(&out.join("manifest.json"));
    let origin = [
        m["origin"][0].as_f64().unwrap(),
        m["origin"][1].as_f64().unwrap(),
    ];
    m["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|t| load_tile(&out.join(t["obj"]["path"].as_str().unwrap()), origin))
        .collect()
}

/// Loads a tile with tobj, checks indices, UVs, materials and textures; returns its objects.
pub fn load_tile(obj: &Path, origin: [f64; 2]) -> Vec<ObjObject> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ..Default::default()
    };
    let (models, materials) = tobj::load_obj(obj, &opts).expect("tobj reads the OBJ");
    let materials = materials.expect("tobj reads the MTL");
    assert!(!materials.is_empty());
    let tiles_dir = obj.parent().unwrap();
    for m in &materials {
        if let Some(tex) = &m.diffuse_texture {
            assert!(
                tiles_dir.join(tex).exists(),
                "texture {tex} of material {} missing",
                m.name
            );
        }
    }
    let mut by_name: BTreeMap<String, ObjObject> = BTreeMap::new();
    for model in &models {
        let mesh = &model.mesh;
        let nv = mesh.positions.len() / 3;
        let nt = mesh.texcoords.len() / 2;
        assert!(
            mesh.indices.iter().all(|&i| (i as usize) < nv),
            "{}",
            model.name
        );
        assert!(
            mesh.texcoord_indices.iter().all(|&i| (i as usize) < nt),
            "{}",
            model.name
        );
        assert_eq!(
            mesh.texcoord_indices.len(),
            mesh.indices.len(),
            "{}: every face has UVs",
            model.name
        );
        assert!(
            mesh.texcoords.iter().all(|t| t.is_finite()),
            "{}",
            model.name
        );
        assert!(
            mesh.positions.iter().all(|p| p.is_finite()),
            "{}",
            model.name
        );
        let mat = mesh
            .material_id
            .map(|i| materials[i].name.clone())
            .expect("every face has a material");
        let entry = by_name
            .entry(model.name.clone())
            .or_insert_with(|| ObjObject {
                name: model.name.clone(),
                vertices: Vec::new(),
                materials: Vec::new(),
            });
        entry.materials.push(mat);
        for &i in &mesh.indices {
            let k = i as usize * 3;
            let (x, y, z) = (
                mesh.positions[k],
                mesh.positions[k + 1],
                mesh.positions[k + 2],
            );
            entry.vertices.push([x + origin[0], -z + origin[1], y]);
        }
    }
    by_name.into_values().collect()
}

/// Distance from a map point to a lot (0 inside).
pub fn distance_to_lot(lot: &Polygon<f64>, east: f64, north: f64) -> f64 {
    let p = Point::new(east, north);
    if lot.contains(&p) {
        0.0
    } else {
        Euclidean.distance(&p, lot.exterior())
    }
}

/// `edo-city build <input> --out <out> <extra...>`, to run and assert on.
pub fn build_cmd(input: &Path, out: &Path, extra: &[&str]) -> Command {
    let mut cmd = edo_city();
    cmd.arg("build")
        .arg(input)
        .arg("--out")
        .arg(out)
        .args(extra);
    cmd
}

/// Runs a build and asserts it succeeded, without reading its report (shards write theirs
/// under another name).
pub fn run_ok(input: &Path, out: &Path, extra: &[&str]) {
    let output = build_cmd(input, out, extra).output().expect("runs");
    assert!(
        output.status.success(),
        "build failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
}

/// A star-shaped ring around (cx, cy), closed: any radii, so concave, thin and tiny outlines
/// come up in property tests.
pub fn star(cx: f64, cy: f64, radii: &[f64], twist: f64) -> Vec<Coord<f64>> {
    let n = radii.len();
    let mut pts: Vec<Coord<f64>> = radii
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let a = twist + i as f64 / n as f64 * std::f64::consts::TAU;
            Coord {
                x: cx + r * a.cos(),
                y: cy + r * a.sin(),
            }
        })
        .collect();
    pts.push(pts[0]);
    pts
}

/// Two parameter files differing in their seed, and the complete city each makes of `town`
/// (every file's bytes by relative path): the old and the new version a build replaces.
pub struct OldAndNew {
    pub old_params: String,
    pub new_params: String,
    pub old_files: BTreeMap<String, Vec<u8>>,
    pub new_files: BTreeMap<String, Vec<u8>>,
}

pub fn old_and_new(town: &Path, work: &Path) -> OldAndNew {
    let (old_params, new_params) = (work.join("old.toml"), work.join("new.toml"));
    std::fs::write(&old_params, "seed = 1\n").unwrap();
    std::fs::write(&new_params, "seed = 2\n").unwrap();
    let p = |f: &Path| f.to_str().unwrap().to_string();
    let (old_ref, new_ref) = (work.join("old"), work.join("new"));
    build_ok(town, &old_ref, &["--quiet", "--params", &p(&old_params)]);
    build_ok(town, &new_ref, &["--quiet", "--params", &p(&new_params)]);
    OldAndNew {
        old_params: p(&old_params),
        new_params: p(&new_params),
        old_files: all_files(&old_ref),
        new_files: all_files(&new_ref),
    }
}

/// A zip archive's entries (an XLSX workbook's), with the entry named `entry` passed
/// through `f`, zipped again: the way to damage or edit a workbook's XML past the checksums.
pub fn rezip(good: &[u8], entry: &str, f: impl FnOnce(&[u8]) -> Vec<u8>) -> Vec<u8> {
    use std::io::{Read, Write};
    let mut zin = zip::ZipArchive::new(std::io::Cursor::new(good)).unwrap();
    let mut out = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let mut f = Some(f);
    for i in 0..zin.len() {
        let mut e = zin.by_index(i).unwrap();
        let name = e.name().unwrap().to_string();
        let mut bytes = Vec::new();
        e.read_to_end(&mut bytes).unwrap();
        if name == entry {
            bytes = (f.take().unwrap())(&bytes);
        }
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated);
        out.start_file(name, options).unwrap();
        out.write_all(&bytes).unwrap();
    }
    out.finish().unwrap().into_inner()
}

/// An `edo-city serve` process, stopped however the test ends.
pub struct Server(pub std::process::Child);

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts `cmd` (an `edo-city serve`, stdout piped) and reads the URL it prints first; what
/// it prints later is read and dropped as it comes.
pub fn start_server(mut cmd: std::process::Command) -> (Server, String) {
    use std::io::BufRead;
    let mut child = cmd.stdout(std::process::Stdio::piped()).spawn().unwrap();
    let stdout = child.stdout.take().unwrap();
    let server = Server(child);
    let mut first = String::new();
    let mut reader = std::io::BufReader::new(stdout);
    reader.read_line(&mut first).unwrap();
    std::thread::spawn(move || std::io::copy(&mut reader, &mut std::io::sink()));
    let url = first
        .split_whitespace()
        .find(|w| w.starts_with("http://127.0.0.1:"))
        .unwrap_or_else(|| panic!("no URL in {first:?}"))
        .to_string();
    (server, url)
}

/// Builds the fixture into `dir/out` with a machiya type `odd` drawn for every lot without a
/// type: NaN on narrow lots (the sqrt of a negative number), an upside-down part on wide ones,
/// both found only when the tiles are made. Returns the output directory and its report.
#[allow(dead_code)]
pub fn build_with_failing_template(dir: &Path) -> (PathBuf, serde_json::Value) {
    let mydir = dir.join("t");
    std::fs::create_dir(&mydir).unwrap();
    std::fs::write(
        mydir.join("odd.toml"),
        "name = \"odd\"\nextends = \"machiya\"\n[derived]\nodd_w = \"sqrt(width - 5.0)\"\n\
         [[part]]\nname = \"upside_down\"\nwhen = \"odd_w > 1\"\nv0 = \"1\"\nv1 = \"2\"\n\
         bottom = \"3\"\ntop = \"2\"\n",
    )
    .unwrap();
    let params = dir.join("p.toml");
    std::fs::write(&params, "[type_mix]\nodd = 1.0\n").unwrap();
    let input = dir.join("in");
    copy_fixture("kyoto-small", &input);
    std::fs::remove_file(input.join("lots.csv")).unwrap();
    // The fixture's DBF names types for some lots; those are built as named.
    let out = dir.join("out");
    let r = build_ok(
        &input,
        &out,
        &[
            "--quiet",
            "--no-plan",
            "--templates",
            mydir.to_str().unwrap(),
            "--params",
            params.to_str().unwrap(),
        ],
    );
    (out, r)
}

/// One HTTP/1.1 request on a connection of its own (closed after it): the status and the
/// whole response (head and body) as text.
#[allow(dead_code)]
pub fn http(port: u16, method: &str, target: &str, body: &str) -> (u16, String) {
    http_with(port, method, target, &[], body)
}

/// [`http`] with more headers (a page token, an `Origin`).
#[allow(dead_code)]
pub fn http_with(
    port: u16,
    method: &str,
    target: &str,
    headers: &[(&str, &str)],
    body: &str,
) -> (u16, String) {
    use std::io::{Read, Write};
    let mut s = std::net::TcpStream::connect(("127.0.0.1", port)).unwrap();
    s.set_read_timeout(Some(std::time::Duration::from_secs(60)))
        .unwrap();
    // The server's own Host and a JSON body, unless `headers` say otherwise.
    let given = |name: &str| headers.iter().any(|(k, _)| k.eq_ignore_ascii_case(name));
    let mut head = format!("{method} {target} HTTP/1.1\r\n");
    if !given("host") {
        head += &format!("Host: 127.0.0.1:{port}\r\n");
    }
    if !given("content-type") {
        head += "Content-Type: application/json\r\n";
    }
    for (k, v) in headers {
        head += &format!("{k}: {v}\r\n");
    }
    write!(
        s,
        "{head}Content-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    )
    .unwrap();
    let mut bytes = Vec::new();
    s.read_to_end(&mut bytes).unwrap();
    let text = String::from_utf8_lossy(&bytes).into_owned();
    let status = text
        .split(' ')
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    (status, text)
}

/// Runs a viewer test script (`viewer/test/<script>`) under node in Debian's chromium
/// (`$CHROMIUM`, default /usr/bin/chromium), with `args` and `envs`; fails the test with the
/// script's output unless it succeeds. Returns its last stdout line as JSON and all its
/// output. The browser keeps the real clock: under scripts/test-future.sh libfaketime would
/// be preloaded into chromium's processes too, whose timers it stalls.
pub fn run_browser_script(
    script: &str,
    args: &[&std::ffi::OsStr],
    envs: &[(&str, &std::ffi::OsStr)],
) -> (serde_json::Value, String) {
    let viewer = Path::new(env!("CARGO_MANIFEST_DIR")).join("viewer");
    let chromium = std::env::var("CHROMIUM").unwrap_or_else(|_| "/usr/bin/chromium".into());
    assert!(
        Path::new(&chromium).exists() && viewer.join("node_modules/playwright-core").is_dir(),
        "chromium or the viewer's npm packages are missing: run `make viewer-deps`"
    );
    let mut cmd = std::process::Command::new("node");
    cmd.current_dir(&viewer)
        .arg(format!("test/{script}"))
        .args(args)
        .env("CHROMIUM", &chromium)
        .env_remove("LD_PRELOAD")
        .env_remove("FAKETIME");
    for (k, v) in envs {
        cmd.env(k, v);
    }
    let o = cmd.output().expect("node runs");
    let text = succeeded(&o);
    let stdout = String::from_utf8_lossy(&o.stdout);
    let last = stdout.lines().last().unwrap_or("null");
    (serde_json::from_str(last).unwrap(), text)
}

/// Khronos' glTF-Validator over every GLB of the build in `out` (`viewer/test/validate.mjs`):
/// its output, after asserting it ran and found no error or warning.
#[allow(dead_code)]
pub fn validate_glbs(out: &Path) -> String {
    let viewer = Path::new(env!("CARGO_MANIFEST_DIR")).join("viewer");
    assert!(
        viewer.join("node_modules/gltf-validator").is_dir(),
        "viewer/node_modules is missing: run `make viewer-deps` (npm ci in viewer/)"
    );
    let o = std::process::Command::new("node")
        .current_dir(&viewer)
        .arg("test/validate.mjs")
        .arg(out)
        .output()
        .expect("node runs");
    let text = succeeded(&o);
    assert!(text.contains("0 with errors or warnings"), "{text}");
    text
}

/// A finished tool's stdout and stderr together, after failing the test with them unless it
/// succeeded.
pub fn succeeded(o: &std::process::Output) -> String {
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.status.success(), "{text}");
    text
}

/// Every tree of a build's plan.gpkg: its id, place, species and height.
#[allow(dead_code)]
pub fn plan_trees(out: &Path) -> Vec<(String, String, Option<String>, f64)> {
    let db = rusqlite::Connection::open(out.join("plan.gpkg")).unwrap();
    let mut q = db
        .prepare("SELECT id, hex(geom), species, height FROM trees ORDER BY id")
        .unwrap();
    q.query_map([], |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?, r.get(3)?)))
        .unwrap()
        .map(Result::unwrap)
        .collect()
}

/// Each tile's file of each of `formats` by its sha256, from the build's manifest, sorted
/// (tile id, hash); a tile without one of them fails.
#[allow(dead_code)]
pub fn tile_hashes(out: &Path, formats: &[&str]) -> Vec<(String, String)> {
    let m = read_json(&out.join("manifest.json"));
    let mut v: Vec<(String, String)> = m["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|t| {
            formats.iter().map(move |f| {
                let hash = t[*f]["sha256"].as_str();
                let id = t["id"].as_str().unwrap().to_string();
                (
                    id,
                    hash.unwrap_or_else(|| panic!("tile without {f}"))
                        .to_string(),
                )
            })
        })
        .collect();
    v.sort();
    v
}
