//! `cityjson`: the city as a CityJSON 2.0 model for 3D GIS (issue 60), written as a
//! CityJSONSeq (`<out>/city.city.jsonl`: one `CityJSON` line, then one `CityJSONFeature` per
//! line) that 3DCityDB, cjio, FME, QGIS's loader and ninja read, and citygml-tools turns into
//! CityGML (docs/cityjson.md).
//!
//! Each tile writes its features as they are made into `tiles/<id>.city.jsonl` (a fragment:
//! feature lines only), with the geometry template of each grown-tree variant it plants once
//! per build in `tiles/templates/<name>.json` (shared as the GLB's models are). Once every
//! tile is in the manifest, [`CityJsonSink::finish`] writes the header (the transform, the
//! CRS, the extent, the hypothesis, the templates) and streams every tile's fragment after
//! it in the manifest's order, a line at a time: constant memory, the same bytes for any
//! `-j`, `--tiles` and `--shard` + `merge` (a tree names its template by name in the
//! fragment, by its index in the file).

use std::collections::{BTreeMap, BTreeSet};
use std::io::{BufRead, Write};
use std::path::Path;
use std::sync::Mutex;

use serde_json::{json, Value};
use sha2::{Digest, Sha256};

use super::features::Feature;
use super::report::{Manifest, ManifestFile};
use super::sink::{Sink, TileContent, TileFiles};

mod appearance;
mod geometry;
mod objects;
mod text;

/// The model's file, in the output directory.
pub const FILE: &str = "city.city.jsonl";
/// Where the grown trees' geometry templates are written.
pub const TEMPLATES_DIR: &str = "tiles/templates";
/// CityJSON's version written.
pub const VERSION: &str = "2.0";
/// The largest fragment line or template read back (a feature of a big landmark).
const MAX_TEMPLATE_BYTES: u64 = 256 << 20;

/// The CityJSON sink.
pub struct CityJsonSink {
    /// The build's hypothesis (its parameters' fingerprint), an attribute of every object.
    pub hypothesis: String,
    /// Surfaces name their textures (`[output] cityjson_textures`).
    pub textures: bool,
    /// Templates written by this run: each once, whatever tile plants it first.
    pub shared: Mutex<BTreeMap<String, ManifestFile>>,
}

impl Sink for CityJsonSink {
    fn format(&self) -> &'static str {
        "cityjson"
    }

    fn write_tile(&self, out: &Path, tile: &TileContent) -> std::io::Result<TileFiles> {
        let cx = objects::Context {
            tile: tile.id,
            hypothesis: &self.hypothesis,
            palette: tile.palette,
            textures: self.textures,
        };
        let mut text = String::new();
        let instanced = !tile.instanced.is_empty();
        for (mesh, f) in tile.meshes.iter().zip(tile.features) {
            // Grown trees come one by one, from their variant's template.
            if instanced && mesh.kind == crate::model::object::ObjectKind::GrownTrees {
                continue;
            }
            if objects::feature(&mut text, mesh, f, &cx) {
                text.push('\n');
            }
        }
        let mut files = Vec::new();
        let mut rows = tile.instance_features.iter();
        for g in tile.instanced.iter().filter(|g| !g.trees.is_empty()) {
            let template = self.template(out, &g.model)?;
            for tree in &g.trees {
                let f = rows.next().cloned().unwrap_or_default();
                let v = tree_feature(tree, &g.model.name, &f, tile.origin, &self.hypothesis);
                text.push_str(&v.to_string());
                text.push('\n');
            }
            if let Some(t) = template {
                if !files.contains(&t) {
                    files.push(t);
                }
            }
        }
        let path = format!("tiles/{}.city.jsonl", tile.id);
        files.insert(0, super::write_listed(out, path, &[text.as_bytes()])?);
        Ok(TileFiles {
            files,
            mesh_bytes: None,
        })
    }

    fn finish(
        &self,
        out: &Path,
        manifest: &Manifest,
        _warnings: &mut Vec<String>,
    ) -> std::io::Result<Vec<ManifestFile>> {
        Ok(vec![write_model(out, manifest)?])
    }
}

impl CityJsonSink {
    /// The sink of a build whose parameters have the fingerprint `hypothesis`; `textures`
    /// when surfaces name their textures.
    pub fn new(hypothesis: String, textures: bool) -> Self {
        CityJsonSink {
            hypothesis,
            textures,
            shared: Mutex::default(),
        }
    }

    /// The template file of a variant `model` (written the first time a tile asks); `None`
    /// for a model without faces.
    fn template(
        &self,
        out: &Path,
        model: &crate::generate::mesh::Mesh,
    ) -> std::io::Result<Option<ManifestFile>> {
        if model.faces.is_empty() {
            return Ok(None);
        }
        let mut shared = self.shared.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(f) = shared.get(&model.name) {
            return Ok(Some(f.clone()));
        }
        let text = template_json(model).to_string();
        let dir = out.join(TEMPLATES_DIR);
        std::fs::create_dir_all(&dir)?;
        let path = format!("{TEMPLATES_DIR}/{}.json", model.name);
        let f = super::write_listed(out, path, &[text.as_bytes()])?;
        shared.insert(model.name.clone(), f.clone());
        Ok(Some(f))
    }
}

/// A variant's geometry as a template: a `MultiSurface` over vertices in metres around the
/// trunk's foot (east, north, up).
fn template_json(model: &crate::generate::mesh::Mesh) -> Value {
    let mut vertices = geometry::Vertices::default();
    let s = geometry::surfaces(model, &model.faces, 0, &mut vertices);
    let boundaries: Vec<Value> = s.iter().map(|s| json!([s.ring])).collect();
    let mut points = String::new();
    vertices.write(&mut points);
    json!({
        "geometry": {"type": "MultiSurface", "lod": "2", "boundaries": boundaries},
        "vertices": serde_json::from_str::<Value>(&points).expect("vertices are JSON"),
    })
}

/// One grown tree: a `SolitaryVegetationObject` drawing its variant's template (named here,
/// numbered when the file is written) turned and scaled at its trunk's foot.
fn tree_feature(
    tree: &crate::generate::planted::InstancedTree,
    template: &str,
    f: &Feature,
    origin: [f64; 2],
    hypothesis: &str,
) -> Value {
    let st = tree.stance;
    let mm = |v: f64| (v * 1000.0).round() as i64;
    let foot = [
        mm(st.place.at.x - origin[0]),
        mm(st.place.at.y - origin[1]),
        mm(st.place.ground),
    ];
    let (w, h) = (st.scale * st.squeeze, st.scale);
    let (s, c) = st.place.rotation.sin_cos();
    let r = |v: f64| (v * 1e9).round() / 1e9;
    let matrix = [
        r(w * c),
        r(-w * s),
        0.0,
        0.0,
        r(w * s),
        r(w * c),
        0.0,
        0.0,
        0.0,
        0.0,
        r(h),
        0.0,
        0.0,
        0.0,
        0.0,
        1.0,
    ];
    let id = format!("tree_{}", tree.id);
    let mut attributes = serde_json::Map::new();
    attributes.insert("species".into(), json!(species_of(template)));
    attributes.insert("height".into(), json!((st.scale * 1000.0).round() / 1000.0));
    if !f.lot.is_empty() {
        attributes.insert("lot".into(), json!(f.lot));
    }
    if !f.source.is_empty() {
        attributes.insert("source".into(), json!(f.source));
    }
    attributes.insert("hypothesis".into(), json!(hypothesis));
    json!({
        "type": "CityJSONFeature",
        "id": id,
        "CityObjects": {id.clone(): {
            "type": "SolitaryVegetationObject",
            "attributes": attributes,
            "geometry": [{
                "type": "GeometryInstance",
                "template": template,
                "boundaries": [0],
                "transformationMatrix": matrix,
            }],
        }},
        "vertices": [foot],
    })
}

/// A variant's species: its name without `_<k>`.
fn species_of(variant: &str) -> &str {
    variant.rsplit_once('_').map_or(variant, |(s, _)| s)
}

/// Writes `city.city.jsonl`: the header, then every tile's fragment in the manifest's
/// order, the trees' template names made indices; through a temporary renamed when whole.
fn write_model(out: &Path, manifest: &Manifest) -> std::io::Result<ManifestFile> {
    let templates: BTreeSet<&str> = (manifest.tiles.iter())
        .flat_map(|t| &t.models)
        .filter_map(|f| {
            f.path
                .strip_prefix(TEMPLATES_DIR)?
                .strip_prefix('/')?
                .strip_suffix(".json")
        })
        .collect();
    let index: BTreeMap<&str, usize> = templates.iter().enumerate().map(|(i, n)| (*n, i)).collect();
    let header = header(out, manifest, &templates)?;
    let path = out.join(FILE);
    let tmp = super::atomic::temporary_for(&path);
    let written = (|| -> std::io::Result<ManifestFile> {
        let mut h = Sha256::new();
        let mut bytes = 0u64;
        let mut w = std::io::BufWriter::new(std::fs::File::create(&tmp)?);
        let mut put = |s: &[u8]| -> std::io::Result<()> {
            h.update(s);
            bytes += s.len() as u64;
            w.write_all(s)
        };
        put(header.to_string().as_bytes())?;
        put(b"\n")?;
        let mut line = Vec::new();
        let key = memchr::memmem::Finder::new(TEMPLATE_KEY);
        for t in &manifest.tiles {
            let Some(f) = &t.cityjson else { continue };
            let real = super::listed::locate(out, &f.path).map_err(std::io::Error::other)?;
            let (file, _) = crate::bounded::open(&real).map_err(std::io::Error::other)?;
            let mut r = std::io::BufReader::with_capacity(1 << 20, file);
            loop {
                line.clear();
                if r.read_until(b'\n', &mut line)? == 0 {
                    break;
                }
                if line.last() != Some(&b'\n') {
                    line.push(b'\n');
                }
                match key.find(&line) {
                    // Only a grown tree's line names a template.
                    Some(at) => put(&number_template(&line, at, &index))?,
                    None => put(&line)?,
                }
            }
        }
        w.into_inner().map_err(|e| e.into_error())?;
        Ok(ManifestFile {
            path: FILE.into(),
            bytes,
            sha256: super::hex(&h.finalize()),
        })
    })();
    match written.and_then(|f| std::fs::rename(&tmp, &path).map(|()| f)) {
        Ok(f) => Ok(f),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(super::at_file(&path, e))
        }
    }
}

/// What a grown tree's line names its template by.
const TEMPLATE_KEY: &[u8] = b"\"template\":\"";

/// `line` with a tree's `"template":"<name>"` (found at `at`) made `"template":<index>`;
/// unchanged when the name is not a template of the build.
fn number_template(line: &[u8], at: usize, index: &BTreeMap<&str, usize>) -> Vec<u8> {
    let rest = &line[at + TEMPLATE_KEY.len()..];
    let Some(end) = rest.iter().position(|&b| b == b'"') else {
        return line.to_vec();
    };
    let name = std::str::from_utf8(&rest[..end]).unwrap_or("");
    match index.get(name) {
        Some(i) => {
            let mut out = Vec::with_capacity(line.len());
            out.extend_from_slice(&line[..at]);
            out.extend_from_slice(format!("\"template\":{i}").as_bytes());
            out.extend_from_slice(&rest[end + 1..]);
            out
        }
        None => line.to_vec(),
    }
}

/// The first line: version, transform (millimetres around the origin), metadata (extent,
/// CRS, the hypothesis and seed) and the trees' geometry templates.
fn header(out: &Path, m: &Manifest, templates: &BTreeSet<&str>) -> std::io::Result<Value> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for b in m.tiles.iter().filter_map(|t| t.bounds) {
        for k in 0..3 {
            lo[k] = lo[k].min(b[k]);
            hi[k] = hi[k].max(b[k + 3]);
        }
    }
    let o = [m.origin[0], m.origin[1], 0.0];
    let extent: Vec<f64> = match lo[0].is_finite() {
        true => (0..6)
            .map(|i| match i {
                0..3 => lo[i] + o[i],
                _ => hi[i - 3] + o[i - 3],
            })
            .map(|v| (v * 1000.0).round() / 1000.0)
            .collect(),
        false => vec![o[0], o[1], 0.0, o[0], o[1], 0.0],
    };
    let hypothesis = super::report::params_id(&m.params);
    let mut metadata = json!({
        "geographicalExtent": extent,
        "identifier": format!("edo-city/{hypothesis}/seed-{}", m.params.seed),
        "title": format!(
            "edo-city {}: a city of Edo-era Kyoto, hypothesis {hypothesis}, seed {}",
            m.version, m.params.seed
        ),
    });
    if let Some(code) = epsg(m) {
        metadata["referenceSystem"] =
            json!(format!("https://www.opengis.net/def/crs/EPSG/0/{code}"));
    }
    let mut v = json!({
        "type": "CityJSON",
        "version": VERSION,
        "transform": {"scale": [0.001, 0.001, 0.001], "translate": o},
        "CityObjects": {},
        "vertices": [],
        "metadata": metadata,
    });
    if !templates.is_empty() {
        let (mut list, mut points) = (Vec::new(), Vec::<Value>::new());
        for name in templates {
            let path = format!("{TEMPLATES_DIR}/{name}.json");
            let real = super::listed::locate(out, &path).map_err(std::io::Error::other)?;
            let bytes =
                crate::bounded::read(&real, MAX_TEMPLATE_BYTES).map_err(std::io::Error::other)?;
            let t: Value = serde_json::from_slice(&bytes).map_err(std::io::Error::other)?;
            let base = points.len() as u64;
            let mut g = t["geometry"].clone();
            shift(&mut g["boundaries"], base);
            list.push(g);
            // Template vertices are real coordinates: metres from the foot.
            points.extend(t["vertices"].as_array().into_iter().flatten().map(|p| {
                json!(p
                    .as_array()
                    .into_iter()
                    .flatten()
                    .map(|c| c.as_i64().unwrap_or(0) as f64 / 1000.0)
                    .collect::<Vec<_>>())
            }));
        }
        v["geometry-templates"] = json!({"templates": list, "vertices-templates": points});
    }
    Ok(v)
}

/// Every vertex index in `b` (nested arrays) moved by `by`.
fn shift(b: &mut Value, by: u64) {
    match b {
        Value::Array(a) => a.iter_mut().for_each(|x| shift(x, by)),
        Value::Number(n) => {
            if let Some(i) = n.as_u64() {
                *b = json!(i + by);
            }
        }
        _ => {}
    }
}

/// The EPSG code of the build's output CRS, when one is known.
fn epsg(m: &Manifest) -> Option<i32> {
    let reprojected = (m.input.layers.iter())
        .filter(|l| l.role == "lots" || l.role == "footprints")
        .any(|l| l.reprojected);
    let srs = super::gpkg::Srs::of_build(&m.params.crs, m.crs_wkt.as_deref(), &m.crs, reprojected);
    match srs.organization.as_str() {
        "EPSG" => Some(srs.code),
        // A `.prj` without AUTHORITY: its CRS found by name.
        _ => crate::geom::crs::Crs::epsg_named(&srs.name).map(i32::from),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_trees_template_is_numbered_by_its_name() {
        let index: BTreeMap<&str, usize> = [("matsu_1", 0), ("sakura_3", 1)].into_iter().collect();
        let line = br#"{"a":{"template":"sakura_3","boundaries":[0]}}"#;
        let at = memchr::memmem::find(line, TEMPLATE_KEY).unwrap();
        assert_eq!(
            number_template(line, at, &index),
            br#"{"a":{"template":1,"boundaries":[0]}}"#
        );
        let other = br#"{"template":"kusu_0"}"#;
        assert_eq!(number_template(other, 1, &index), other);
        assert_eq!(species_of("shidare_zakura_4"), "shidare_zakura");
    }
}
