//! Layers beside shapefiles (issue 77): GeoPackage layers and GeoJSON files, converted from
//! the example town by GDAL's `ogr2ogr` (Debian's gdal-bin, `make gis-deps`), built as the
//! shapefiles are; and what a GeoPackage from elsewhere may not do.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::*;

/// `ogr2ogr` with `args`; fails the test with GDAL's words.
fn ogr2ogr(args: &[&str]) {
    let o = Command::new("ogr2ogr")
        .args(args)
        .output()
        .unwrap_or_else(|e| {
            panic!("ogr2ogr is missing ({e}): run `make gis-deps`");
        });
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// The example town's lots, blocks and streets as the layers of one GeoPackage, with its
/// tables beside it; the parameter file naming them.
fn town_gpkg(dir: &Path) -> (PathBuf, PathBuf) {
    let input = dir.join("in");
    std::fs::create_dir_all(&input).unwrap();
    let gpkg = input.join("town.gpkg");
    let fixture = fixture("kyoto-small");
    for (i, layer) in ["lots", "blocks", "streets"].iter().enumerate() {
        let shp = fixture.join(format!("{layer}.shp"));
        let mut args = vec!["-f", "GPKG", "-nln", layer];
        if i > 0 {
            args.push("-update");
        }
        args.extend([gpkg.to_str().unwrap(), shp.to_str().unwrap()]);
        ogr2ogr(&args);
    }
    for table in ["lots.csv", "links.csv"] {
        std::fs::copy(fixture.join(table), input.join(table)).unwrap();
    }
    let params = dir.join("gpkg.toml");
    std::fs::write(
        &params,
        "[layers.lots]\nfile = \"town.gpkg\"\nlayer = \"lots\"\n\
         [layers.blocks]\nfile = \"town.gpkg\"\nlayer = \"blocks\"\n\
         [layers.streets]\nfile = \"town.gpkg\"\nlayer = \"streets\"\n",
    )
    .unwrap();
    (input, params)
}

/// A parameter file's text naming the example town's lots, blocks and streets as
/// `<role>.<ext>` (one file a layer: GeoJSON, FlatGeobuf).
fn one_file_a_layer(ext: &str) -> String {
    ["lots", "blocks", "streets"]
        .map(|role| format!("[layers.{role}]\nfile = \"{role}.{ext}\"\n"))
        .concat()
}

/// Builds `input` with `params` into `dir/converted` and the example town's shapefiles into
/// `dir/shp`, and asserts their OBJ tiles are the same bytes; both directories.
fn builds_the_shapefiles_obj(dir: &Path, input: &Path, params: &Path) -> (PathBuf, PathBuf) {
    let converted = dir.join("converted");
    build_ok(
        input,
        &converted,
        &["--quiet", "--params", params.to_str().unwrap()],
    );
    let from_shp = dir.join("shp");
    build_ok(&fixture("kyoto-small"), &from_shp, &["--quiet"]);
    assert_eq!(
        tile_hashes(&converted, &["obj"]),
        tile_hashes(&from_shp, &["obj"])
    );
    (converted, from_shp)
}

/// Builds `input` into `out` with `args`, which must be refused (exit 2); what it said.
fn refused(input: &Path, out: &Path, args: &[&str]) -> String {
    let o = build_cmd(input, out, args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "{err}");
    err
}

/// A GLB's JSON chunk and its binary chunk.
fn glb_parts(path: &Path) -> (serde_json::Value, Vec<u8>) {
    let b = std::fs::read(path).unwrap();
    let n = u32::from_le_bytes(b[12..16].try_into().unwrap()) as usize;
    let json = serde_json::from_slice(&b[20..20 + n]).unwrap();
    (json, b[20 + n..].to_vec())
}

#[test]
fn a_geopackage_of_the_town_builds_the_shapefiles_tiles() {
    let dir = tempfile::tempdir().unwrap();
    let (input, params) = town_gpkg(dir.path());
    // Every OBJ tile byte for byte.
    let (from_gpkg, from_shp) = builds_the_shapefiles_obj(dir.path(), &input, &params);
    // Every GLB: the same binary chunk; its metadata's list of source files names the
    // GeoPackage instead of lots.shp, and nothing else differs.
    let tiles = tile_hashes(&from_shp, &["glb"]);
    assert!(!tiles.is_empty());
    for (id, _) in tiles {
        let (mut a, bin_a) = glb_parts(&from_gpkg.join(format!("tiles/{id}.glb")));
        let (mut b, bin_b) = glb_parts(&from_shp.join(format!("tiles/{id}.glb")));
        assert_eq!(bin_a, bin_b, "{id}");
        let sources = "/extensions/EXT_structural_metadata/schema/enums/source/values";
        let names = |v: &serde_json::Value| -> Vec<String> {
            v.pointer(sources).map_or(Vec::new(), |s| {
                s.as_array()
                    .unwrap()
                    .iter()
                    .map(|e| e["name"].as_str().unwrap().to_string())
                    .collect()
            })
        };
        let (na, nb) = (names(&a), names(&b));
        assert_eq!(
            na.iter()
                .map(|n| n.replace("town.gpkg", "lots.shp"))
                .collect::<Vec<_>>(),
            nb,
            "{id}"
        );
        for v in [&mut a, &mut b] {
            if let Some(s) = v.pointer_mut(sources) {
                *s = serde_json::Value::Null;
            }
        }
        assert_eq!(a, b, "{id}");
    }
}

/// Writes each layer of `gpkg` as GeoJSON beside it with every coordinate's every bit
/// (Python's json writes the shortest text that reads back as the same double; GDAL's
/// GeoJSON writer rounds some to 15 digits: -109616.40000000001 became -109616.4), naming
/// its CRS as GDAL does.
fn exact_geojson(gpkg: &Path, layers: &[&str]) {
    let script = r#"
import json, sqlite3, struct, sys
c = sqlite3.connect(sys.argv[1])
def geom(w, o):
    t = struct.unpack('<I', w[o + 1:o + 5])[0]; o += 5
    def pts(o):
        n = struct.unpack('<I', w[o:o + 4])[0]; o += 4
        return [list(struct.unpack('<dd', w[o + 16 * i:o + 16 * i + 16])) for i in range(n)], o + 16 * n
    def rings(o):
        n = struct.unpack('<I', w[o:o + 4])[0]; o += 4; out = []
        for _ in range(n):
            r, o = pts(o); out.append(r)
        return out, o
    if t == 2: c, o = pts(o); return {'type': 'LineString', 'coordinates': c}, o
    if t == 3: c, o = rings(o); return {'type': 'Polygon', 'coordinates': c}, o
    n = struct.unpack('<I', w[o:o + 4])[0]; o += 4; parts = []
    for _ in range(n):
        g, o = geom(w, o); parts.append(g['coordinates'])
    return {'type': {5: 'MultiLineString', 6: 'MultiPolygon'}[t], 'coordinates': parts}, o
for layer in sys.argv[2:]:
    cur = c.execute('SELECT * FROM "%s" ORDER BY fid' % layer)
    names = [d[0] for d in cur.description]
    feats = []
    for row in cur:
        props = {n: v for n, v in zip(names, row) if n not in ('fid', 'geom')}
        b = row[names.index('geom')]
        env = {0: 0, 1: 32, 2: 48, 3: 48, 4: 64}[(b[3] >> 1) & 7]
        g, _ = geom(b[8 + env:], 0)
        feats.append({'type': 'Feature', 'properties': props, 'geometry': g})
    fc = {'type': 'FeatureCollection', 'name': layer,
          'crs': {'type': 'name', 'properties': {'name': 'urn:ogc:def:crs:EPSG::6674'}},
          'features': feats}
    with open(sys.argv[1].rsplit('/', 1)[0] + '/' + layer + '.geojson', 'w') as f:
        json.dump(fc, f, ensure_ascii=False)
"#;
    let mut args = vec!["-c", script, gpkg.to_str().unwrap()];
    args.extend(layers);
    let o = Command::new("python3").args(&args).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn geojson_of_the_town_builds_the_shapefiles_tiles() {
    let dir = tempfile::tempdir().unwrap();
    let (input, _) = town_gpkg(dir.path());
    exact_geojson(&input.join("town.gpkg"), &["lots", "blocks", "streets"]);
    std::fs::remove_file(input.join("town.gpkg")).unwrap();
    let p = dir.path().join("json.toml");
    std::fs::write(&p, one_file_a_layer("geojson")).unwrap();
    builds_the_shapefiles_obj(dir.path(), &input, &p);
}

#[test]
fn a_geopackage_attributes_table_is_joined_as_the_csv_is() {
    let dir = tempfile::tempdir().unwrap();
    let (input, params) = town_gpkg(dir.path());
    let csv = input.join("lots.csv");
    let gpkg = input.join("town.gpkg");
    ogr2ogr(&[
        "-f",
        "GPKG",
        "-update",
        "-nln",
        "lot_attributes",
        gpkg.to_str().unwrap(),
        csv.to_str().unwrap(),
    ]);
    std::fs::remove_file(&csv).unwrap();
    let text = std::fs::read_to_string(&params).unwrap().replace(
        "layer = \"lots\"\n",
        "layer = \"lots\"\ntable = \"town.gpkg\"\nsheet = \"lot_attributes\"\n",
    );
    std::fs::write(&params, text).unwrap();
    let (joined, _) = builds_the_shapefiles_obj(dir.path(), &input, &params);
    let report = read_json(&joined.join("report.json"));
    let t = &report["tables"][0];
    assert_eq!(
        (t["rows"].as_u64(), t["matched"].as_u64()),
        (Some(3), Some(2)),
        "{t}"
    );
    assert!(t["file"].as_str().unwrap().ends_with("town.gpkg"), "{t}");
}

#[test]
fn a_geopackage_layer_is_found_by_its_name_and_a_wrong_one_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let (input, _) = town_gpkg(dir.path());
    // No `layer`: the layer named as the role.
    let p = dir.path().join("roles.toml");
    std::fs::write(
        &p,
        "[layers.lots]\nfile = \"town.gpkg\"\n[layers.blocks]\nfile = \"town.gpkg\"\n\
         [layers.streets]\nfile = \"town.gpkg\"\n",
    )
    .unwrap();
    build_ok(
        &input,
        &dir.path().join("o"),
        &["--quiet", "--params", p.to_str().unwrap()],
    );
    std::fs::write(
        &p,
        "[layers.lots]\nfile = \"town.gpkg\"\nlayer = \"parcels\"\n",
    )
    .unwrap();
    let err = refused(
        &input,
        &dir.path().join("o2"),
        &["--params", p.to_str().unwrap()],
    );
    assert!(
        err.contains("town.gpkg")
            && err.contains("no feature layer `parcels`")
            && err.contains("`lots`"),
        "{err}"
    );
}

#[test]
fn geojson_in_lon_lat_and_in_a_named_crs_builds() {
    let dir = tempfile::tempdir().unwrap();
    let fixture = fixture("kyoto-small");
    for (name, extra) in [("lonlat", vec!["-lco", "RFC7946=YES"]), ("named", vec![])] {
        let input = dir.path().join(name);
        std::fs::create_dir_all(&input).unwrap();
        for layer in ["lots", "blocks", "streets"] {
            let out = input.join(format!("{layer}.geojson"));
            let shp = fixture.join(format!("{layer}.shp"));
            let mut args = vec!["-f", "GeoJSON"];
            args.extend(extra.iter().copied());
            args.extend([out.to_str().unwrap(), shp.to_str().unwrap()]);
            ogr2ogr(&args);
        }
        std::fs::copy(fixture.join("lots.csv"), input.join("lots.csv")).unwrap();
        let p = dir.path().join(format!("{name}.toml"));
        std::fs::write(&p, one_file_a_layer("geojson")).unwrap();
        let report = build_ok(
            &input,
            &dir.path().join(format!("out-{name}")),
            &["--quiet", "--params", p.to_str().unwrap()],
        );
        let lots = report["accounting"]
            .as_array()
            .unwrap()
            .iter()
            .find(|a| a["role"] == "lots")
            .unwrap()
            .clone();
        assert_eq!(lots["read"], 400, "{name}: {lots}");
        assert_eq!(lots["unaccounted"], 0, "{name}: {lots}");
        assert!(lots["built"].as_u64().unwrap() > 300, "{name}: {lots}");
    }
}

#[test]
fn a_geopackage_from_elsewhere_runs_nothing_and_reads_no_view() {
    let dir = tempfile::tempdir().unwrap();
    let (input, params) = town_gpkg(dir.path());
    let gpkg = input.join("town.gpkg");
    // A view named as a layer (here one that would recurse forever if it were read), and a
    // geometry blob that lies about its ring's size.
    let sql = "CREATE VIEW forever AS WITH RECURSIVE n(x) AS (SELECT 1 UNION ALL SELECT x + 1 \
               FROM n) SELECT x AS fid, NULL AS geom FROM n; \
               INSERT INTO gpkg_contents (table_name, data_type, identifier, srs_id) VALUES \
               ('forever', 'features', 'forever', 0); \
               INSERT INTO gpkg_geometry_columns VALUES ('forever', 'geom', 'POLYGON', 0, 0, 0); \
               UPDATE lots SET geom = X'4750000100000000010300000001000000FFFFFF7F' WHERE fid = 1;";
    assert!(hostile_sql(&gpkg, sql), "the hostile package was made");
    let p = dir.path().join("view.toml");
    std::fs::write(
        &p,
        "[layers.lots]\nfile = \"town.gpkg\"\nlayer = \"forever\"\n",
    )
    .unwrap();
    let err = refused(
        &input,
        &dir.path().join("o"),
        &["--params", p.to_str().unwrap()],
    );
    assert!(err.contains("`forever` is a view, not a table"), "{err}");
    // The lying blob: lot 1 is read as empty and skipped, with a warning; the rest builds.
    let report = build_ok(
        &input,
        &dir.path().join("o3"),
        &["--quiet", "--params", params.to_str().unwrap()],
    );
    let text = serde_json::to_string(&report).unwrap();
    assert!(text.contains("could not be decoded"), "{text}");
    // A FIFO named as the package is refused, not waited on.
    let fifo = input.join("fifo.gpkg");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    std::fs::write(&p, "[layers.lots]\nfile = \"fifo.gpkg\"\n").unwrap();
    let err = refused(
        &input,
        &dir.path().join("o4"),
        &["--params", p.to_str().unwrap()],
    );
    assert!(err.contains("fifo.gpkg"), "{err}");
}

/// Runs `sql` on the package with the sqlite3 of Python's standard library (the test's own
/// hands, not the build's), its R-tree triggers dropped first (they call GDAL's functions);
/// whether it went through.
fn hostile_sql(gpkg: &Path, sql: &str) -> bool {
    let script = "import sqlite3,sys\nc=sqlite3.connect(sys.argv[1])\n\
                  for (n,) in c.execute(\"SELECT name FROM sqlite_master WHERE type='trigger'\").fetchall():\n\
                  \x20   c.execute('DROP TRIGGER \"%s\"' % n)\n\
                  c.executescript(sys.argv[2])\nc.commit()\n";
    Command::new("python3")
        .args(["-c", script, gpkg.to_str().unwrap(), sql])
        .status()
        .is_ok_and(|s| s.success())
}

#[test]
fn a_directory_holding_only_a_geopackage_is_named_by_build_and_read_by_init() {
    let dir = tempfile::tempdir().unwrap();
    let (input, _) = town_gpkg(dir.path());
    for table in ["lots.csv", "links.csv"] {
        std::fs::remove_file(input.join(table)).unwrap();
    }
    let err = refused(&input, &dir.path().join("o"), &[]);
    assert!(
        err.contains("the directory holds town.gpkg") && err.contains("edo-city init"),
        "{err}"
    );
    let params = dir.path().join("init.toml");
    let o = edo_city()
        .arg("init")
        .arg(&input)
        .arg("-o")
        .arg(&params)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&params).unwrap();
    for role in ["lots", "blocks", "streets"] {
        assert!(
            text.contains(&format!("file = \"town.gpkg\"\nlayer = \"{role}\"")),
            "{text}"
        );
    }
    let report = build_ok(
        &input,
        &dir.path().join("built"),
        &["--quiet", "--params", params.to_str().unwrap()],
    );
    assert!(
        report["accounting"][0]["built"].as_u64().unwrap() > 300,
        "{report}"
    );
}

/// The example town's lots, blocks and streets as FlatGeobuf files (`more` options to GDAL's
/// writer), with its tables; the parameter file naming them.
fn town_fgb(dir: &Path, more: &[&str]) -> (PathBuf, PathBuf) {
    let input = dir.join("fgb");
    std::fs::create_dir_all(&input).unwrap();
    let fixture = fixture("kyoto-small");
    for layer in ["lots", "blocks", "streets"] {
        let out = input.join(format!("{layer}.fgb"));
        let shp = fixture.join(format!("{layer}.shp"));
        let mut args = vec!["-f", "FlatGeobuf"];
        args.extend(more);
        args.extend([out.to_str().unwrap(), shp.to_str().unwrap()]);
        ogr2ogr(&args);
    }
    for table in ["lots.csv", "links.csv"] {
        std::fs::copy(fixture.join(table), input.join(table)).unwrap();
    }
    let params = dir.join("fgb.toml");
    std::fs::write(&params, one_file_a_layer("fgb")).unwrap();
    (input, params)
}

#[test]
fn flatgeobuf_of_the_town_builds_the_shapefiles_tiles() {
    let dir = tempfile::tempdir().unwrap();
    // Without GDAL's spatial index the features keep the shapefile's order, and so do the
    // draws that follow it: every OBJ tile byte for byte.
    let (input, params) = town_fgb(dir.path(), &["-lco", "SPATIAL_INDEX=NO"]);
    builds_the_shapefiles_obj(dir.path(), &input, &params);
    // With it (GDAL's default), GDAL writes the features in the index's order: the file's
    // records are others, and every lot is still built.
    let indexed = tempfile::tempdir().unwrap();
    let (input, params) = town_fgb(indexed.path(), &[]);
    let report = build_ok(
        &input,
        &indexed.path().join("o"),
        &["--quiet", "--params", params.to_str().unwrap()],
    );
    let lots = &report["accounting"][0];
    assert_eq!(
        (lots["read"].as_u64(), lots["unaccounted"].as_u64()),
        (Some(400), Some(0)),
        "{lots}"
    );
}

#[test]
fn a_flatgeobuf_whose_feature_lies_about_its_length_is_refused_before_it_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let (input, params) = town_fgb(dir.path(), &["-lco", "SPATIAL_INDEX=NO"]);
    let lots = input.join("lots.fgb");
    let mut bytes = std::fs::read(&lots).unwrap();
    let header = u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize;
    // The first feature says it is 4 GiB long.
    let at = 12 + header;
    bytes[at..at + 4].copy_from_slice(&0xffff_fff0u32.to_le_bytes());
    std::fs::write(&lots, &bytes).unwrap();
    let err = refused(
        &input,
        &dir.path().join("o"),
        &["--params", params.to_str().unwrap()],
    );
    assert!(
        err.contains("lots.fgb") && err.contains("feature 0 says it is 4294967280 bytes"),
        "{err}"
    );
    // Cut short: the header's count is not what the file holds.
    let mut bytes = std::fs::read(fixture_fgb(dir.path())).unwrap();
    bytes.truncate(bytes.len() - 10);
    std::fs::write(&lots, &bytes).unwrap();
    let err = refused(
        &input,
        &dir.path().join("o2"),
        &["--params", params.to_str().unwrap()],
    );
    assert!(err.contains("cut short"), "{err}");
}

/// A fresh FlatGeobuf of the example town's lots, without an index.
fn fixture_fgb(dir: &Path) -> PathBuf {
    let out = dir.join("fresh-lots.fgb");
    let shp = fixture("kyoto-small").join("lots.shp");
    ogr2ogr(&[
        "-f",
        "FlatGeobuf",
        "-lco",
        "SPATIAL_INDEX=NO",
        out.to_str().unwrap(),
        shp.to_str().unwrap(),
    ]);
    out
}

/// `sql` run on a copy of a build's plan.gpkg at `to`, as a person's edit in QGIS would
/// change it.
fn edited_plan(plan: &Path, to: &Path, sql: &str) {
    std::fs::copy(plan, to).unwrap();
    assert!(hostile_sql(to, sql), "the edit was made");
}

#[test]
fn a_plan_gpkg_edited_in_qgis_is_read_back_as_overrides() {
    let dir = tempfile::tempdir().unwrap();
    let first = dir.path().join("first");
    build_ok(&fixture("kyoto-small"), &first, &["--quiet"]);
    let before = tile_hashes(&first, &["obj", "glb"]);
    // Lot 9 made a sangai in the lots layer of the build's plan.gpkg.
    let edited = dir.path().join("edited.gpkg");
    edited_plan(
        &first.join("plan.gpkg"),
        &edited,
        "UPDATE lots SET type = 'sangai' WHERE id = '9';",
    );
    let params = dir.path().join("qgis.toml");
    std::fs::write(&params, "[input]\noverrides = \"edited.gpkg\"\n").unwrap();
    let second = dir.path().join("second");
    let report = build_ok(
        &fixture("kyoto-small"),
        &second,
        &["--quiet", "--params", params.to_str().unwrap()],
    );
    let after = tile_hashes(&second, &["obj", "glb"]);
    let changed: Vec<&String> = (before.iter().zip(&after))
        .filter(|(a, b)| a != b)
        .map(|(a, _)| &a.0)
        .collect();
    assert_eq!(changed.len(), 2, "one tile, as OBJ and GLB: {changed:?}");
    assert!(changed.iter().all(|t| **t == *changed[0]), "{changed:?}");
    let table = (report["tables"].as_array().unwrap().iter())
        .find(|t| t["file"] == "edited.gpkg")
        .unwrap_or_else(|| panic!("{}", report["tables"]));
    assert!(table["rows"].as_u64().unwrap() >= 400, "{table}");
    // A lot the input does not have, and a use that is none: the build's own messages.
    for (sql, says) in [
        (
            "UPDATE lots SET id = 'lost' WHERE id = '9';",
            "no lot has the id `lost`",
        ),
        (
            "UPDATE lots SET use = 'castle' WHERE id = '9';",
            "`castle` is not a lot use",
        ),
    ] {
        edited_plan(&first.join("plan.gpkg"), &edited, sql);
        let err = refused(
            &fixture("kyoto-small"),
            &dir.path().join("refused"),
            &["--params", params.to_str().unwrap()],
        );
        assert!(err.contains(says) && err.contains("edited.gpkg"), "{err}");
    }
    // The build's own plan.gpkg named as its overrides: refused, never written over.
    std::fs::write(
        &params,
        format!(
            "[input]\noverrides = {:?}\n",
            first.join("plan.gpkg").display().to_string()
        ),
    )
    .unwrap();
    let plan_before = std::fs::read(first.join("plan.gpkg")).unwrap();
    let err = refused(
        &fixture("kyoto-small"),
        &first,
        &["--force", "--params", params.to_str().unwrap()],
    );
    assert!(err.contains("lies inside its --out"), "{err}");
    assert_eq!(std::fs::read(first.join("plan.gpkg")).unwrap(), plan_before);
}

/// Each tile's id and the sha256 of its files, as `tile_hashes` lists them.
type Hashes = Vec<(String, String)>;

/// The real-data cut `set` (fixtures/real) built with its example parameter file, and again
/// with every shapefile it names converted by `ogr2ogr` to `format` (one GeoPackage of all
/// of them, or a FlatGeobuf each, without GDAL's index): the OBJ tiles of both builds.
fn real_in(set: &str, example: &str, format: &str) -> (Hashes, Hashes) {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    let copied = Command::new("cp")
        .arg("-r")
        .arg(repo.join("fixtures/real").join(set))
        .arg(&input)
        .status()
        .unwrap();
    assert!(copied.success());
    // The example's layers rewritten to the converted files (Python's tomllib reads it; the
    // text is edited so that its comments and order stay).
    let script = r#"
import subprocess, sys, tomllib
example, fmt, input_dir, out_toml, repo = sys.argv[1:6]
params = tomllib.load(open(example, 'rb'))
text = open(example).read()
first = True
for role, t in params.get('layers', {}).items():
    f = t.get('file', '')
    if not f.endswith('.shp'):
        continue
    if fmt == 'gpkg':
        args = ['ogr2ogr', '-f', 'GPKG', '-nln', role] + ([] if first else ['-update'])
        args += [input_dir + '/town.gpkg', input_dir + '/' + f]
        new = 'file = "town.gpkg"\nlayer = "%s"' % role
    else:
        # FlatGeobuf holds one geometry type a layer: mixed lines and multi-lines are
        # written as multi-lines.
        args = ['ogr2ogr', '-f', 'FlatGeobuf', '-lco', 'SPATIAL_INDEX=NO',
                '-nlt', 'PROMOTE_TO_MULTI', input_dir + '/' + role + '.fgb', input_dir + '/' + f]
        new = 'file = "%s.fgb"' % role
    subprocess.run(args, check=True, capture_output=True)
    first = False
    text = text.replace('file = "%s"' % f, new)
text = text.replace('models_dir = "fixtures/', 'models_dir = "%s/fixtures/' % repo)
open(out_toml, 'w').write(text)
"#;
    let example = repo.join("params/examples").join(format!("{example}.toml"));
    let shp_params = dir.path().join("shp.toml");
    let converted = dir.path().join("converted.toml");
    let text = std::fs::read_to_string(&example).unwrap().replace(
        "models_dir = \"fixtures/",
        &format!("models_dir = \"{}/fixtures/", repo.display()),
    );
    std::fs::write(&shp_params, text).unwrap();
    let o = Command::new("python3")
        .args(["-c", script])
        .arg(&example)
        .arg(format)
        .arg(&input)
        .arg(&converted)
        .arg(repo)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let a = dir.path().join("from-shp");
    build_ok(
        &input,
        &a,
        &["--quiet", "--params", shp_params.to_str().unwrap()],
    );
    let b = dir.path().join("converted");
    build_ok(
        &input,
        &b,
        &["--quiet", "--params", converted.to_str().unwrap()],
    );
    (tile_hashes(&a, &["obj"]), tile_hashes(&b, &["obj"]))
}

#[test]
fn the_real_data_cut_builds_the_same_tiles_from_a_geopackage_and_flatgeobuf() {
    // Chino: Shift_JIS parcels, multi-part road lines, split lines carrying widths,
    // districts and landmarks; Osaka: PLATEAU footprints on road surfaces.
    for (set, example) in [
        ("chino_plateau_devpermit", "chino"),
        ("osaka_plateau", "osaka"),
    ] {
        for format in ["gpkg", "fgb"] {
            let (shp, converted) = real_in(set, example, format);
            assert!(!shp.is_empty(), "{set}");
            assert_eq!(shp, converted, "{set} from {format}");
        }
    }
}

#[test]
fn three_d_lots_from_a_geopackage_build_as_three_d_shapefiles_do() {
    // The example town's lots given a z of 7 m (GDAL's -zfield takes it from a field; here
    // a constant column made first), written as a 3D shapefile and as a 3D GeoPackage:
    // both build the same tiles, each house on its lot's lowest z.
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in3d");
    std::fs::create_dir_all(&input).unwrap();
    let fixture = fixture("kyoto-small");
    let lots = fixture.join("lots.shp");
    let sql = "SELECT *, 7.0 AS z FROM lots";
    ogr2ogr(&[
        "-f",
        "ESRI Shapefile",
        "-dialect",
        "SQLite",
        "-sql",
        sql,
        "-zfield",
        "z",
        "-dim",
        "XYZ",
        input.join("lots.shp").to_str().unwrap(),
        lots.to_str().unwrap(),
    ]);
    let gpkg = input.join("town.gpkg");
    ogr2ogr(&[
        "-f",
        "GPKG",
        "-nln",
        "lots",
        gpkg.to_str().unwrap(),
        input.join("lots.shp").to_str().unwrap(),
    ]);
    for f in [
        "blocks.shp",
        "blocks.shx",
        "blocks.dbf",
        "blocks.prj",
        "blocks.cpg",
        "streets.shp",
        "streets.shx",
        "streets.dbf",
        "streets.prj",
        "streets.cpg",
        "lots.csv",
    ] {
        std::fs::copy(fixture.join(f), input.join(f)).unwrap();
    }
    let info = Command::new("ogrinfo")
        .args(["-so", "-al", gpkg.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        String::from_utf8_lossy(&info.stdout).contains("3D Polygon"),
        "a 3D layer"
    );
    let from_shp = dir.path().join("shp3d");
    build_ok(&input, &from_shp, &["--quiet"]);
    let p = dir.path().join("gpkg3d.toml");
    std::fs::write(&p, "[layers.lots]\nfile = \"town.gpkg\"\n").unwrap();
    let from_gpkg = dir.path().join("gpkg3d");
    build_ok(
        &input,
        &from_gpkg,
        &["--quiet", "--params", p.to_str().unwrap()],
    );
    assert_eq!(
        tile_hashes(&from_gpkg, &["obj"]),
        tile_hashes(&from_shp, &["obj"])
    );
    // And the z is taken: the 2D town's tiles are other.
    let flat = dir.path().join("flat");
    build_ok(&fixture, &flat, &["--quiet", "--format", "obj"]);
    assert_ne!(
        tile_hashes(&from_shp, &["obj"]),
        tile_hashes(&flat, &["obj"])
    );
}

#[test]
fn a_geopackage_in_the_wrong_crs_is_named_for_its_own_spatial_reference() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("wrong");
    std::fs::create_dir_all(&input).unwrap();
    let gpkg = input.join("town.gpkg");
    // Metres assigned WGS84 degrees (a slip in QGIS's Assign Projection).
    let lots = fixture("kyoto-small").join("lots.shp");
    ogr2ogr(&[
        "-f",
        "GPKG",
        "-nln",
        "lots",
        "-a_srs",
        "EPSG:4326",
        gpkg.to_str().unwrap(),
        lots.to_str().unwrap(),
    ]);
    let p = dir.path().join("wrong.toml");
    std::fs::write(&p, "[layers.lots]\nfile = \"town.gpkg\"\n[layers.blocks]\nfile = \"\"\n[layers.streets]\nfile = \"\"\n").unwrap();
    let err = refused(
        &input,
        &dir.path().join("o"),
        &["--params", p.to_str().unwrap()],
    );
    assert!(
        err.contains("town.gpkg")
            && err.contains("its GeoPackage spatial reference says longitude/latitude"),
        "{err}"
    );
    assert!(!err.contains(".prj"), "{err}");
}
