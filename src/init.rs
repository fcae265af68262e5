//! `edo-city init <dir>`: inspects a directory of GIS layers (shapefiles, every feature layer
//! of a GeoPackage, GeoJSON and FlatGeobuf files) and writes a starting parameter
//! file with its guesses (which layer is the lots, the streets, ...; which field is the id),
//! every layer found listed in comments with its type, count, CRS, encoding and fields.
//! The guesses are a start for the user to correct, never applied silently to a build.

use std::fmt::Write;
use std::path::{Path, PathBuf};

use crate::input::shp;

/// One layer found under the directory.
#[derive(Debug, Clone)]
pub struct Found {
    /// Path relative to the directory, with `/`.
    pub rel: String,
    /// The layer of a GeoPackage (other files hold one).
    pub layer: Option<String>,
    /// What the layer holds: polygon, polyline, point, ...
    pub kind: &'static str,
    /// Its number of features.
    pub count: usize,
    /// Its DBF field names.
    pub fields: Vec<String>,
    /// The encoding its text was read in.
    pub encoding: String,
    /// Its CRS's name from the `.prj`, or `no .prj`.
    pub crs: String,
}

/// `word` as one word for a POSIX shell: quoted when it holds anything but letters, digits
/// and `_ . / - + , :`, so a printed command can be pasted as it is.
pub fn shell_word(word: &str) -> String {
    let plain = !word.is_empty()
        && word
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_./-+,:".contains(c));
    match plain {
        true => word.to_string(),
        false => format!("'{}'", word.replace('\'', "'\\''")),
    }
}

/// How deep `init` looks below the directory (data sets nest a few folders at most).
const MAX_DEPTH: usize = 8;

/// The shapefiles under `dir`, sorted. Symbolic links to directories are not followed (a
/// link to `/` would walk the whole file system, a link to `..` loop), and neither is a
/// folder deeper than [`MAX_DEPTH`]; the links left out are returned, for the user to see.
fn find_layer_files(dir: &Path) -> (Vec<PathBuf>, Vec<PathBuf>) {
    let mut out = Vec::new();
    let mut links = Vec::new();
    let mut stack = vec![(dir.to_path_buf(), 0usize)];
    while let Some((d, depth)) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            let Ok(kind) = e.file_type() else { continue };
            if kind.is_symlink() && p.is_dir() {
                links.push(p);
            } else if kind.is_dir() {
                if depth < MAX_DEPTH {
                    stack.push((p, depth + 1));
                }
            } else if is_layer_file(&p) {
                out.push(p);
            }
        }
    }
    out.sort();
    links.sort();
    (out, links)
}

/// Whether `path` is a file `init` reads: a shapefile, a GeoPackage, a `.geojson`, or a
/// `.json` that begins as GeoJSON does (not every JSON file is a layer).
fn is_layer_file(path: &Path) -> bool {
    let ext = path
        .extension()
        .map(|x| x.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "shp" | "gpkg" | "geojson" | "fgb" => true,
        "json" => crate::input::looks_like_geojson(path),
        _ => false,
    }
}

/// Every layer of the file at `path`: a GeoPackage's feature tables, else the file's one.
fn layers_of(path: &Path) -> Vec<(Option<String>, Result<shp::Layer, String>)> {
    use crate::input::gpkg;
    let ext = path
        .extension()
        .map(|x| x.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "gpkg" => match gpkg::tables(path) {
            Ok(tables) => tables
                .into_iter()
                .filter(|(_, kind)| kind == "features")
                .map(|(name, _)| {
                    let layer = gpkg::read_layer(path, &name, "").map_err(|e| e.to_string());
                    (Some(name), layer)
                })
                .collect(),
            Err(e) => vec![(None, Err(e.to_string()))],
        },
        "geojson" | "json" => vec![(
            None,
            crate::input::read_geojson(path).map_err(|e| e.to_string()),
        )],
        "fgb" => vec![(
            None,
            crate::input::read_flatgeobuf(path).map_err(|e| e.to_string()),
        )],
        _ => vec![(None, shp::read_layer(path, "").map_err(|e| e.to_string()))],
    }
}

/// Reads what `init` needs of every layer under `dir`; unreadable ones are listed with
/// their error instead.
pub fn inspect(dir: &Path) -> (Vec<Found>, Vec<String>) {
    let mut found = Vec::new();
    let mut problems = Vec::new();
    let (paths, links) = find_layer_files(dir);
    for link in links {
        problems.push(format!(
            "{}: a link to a directory, not followed (give its target as a directory of its \
             own, or copy the layers in)",
            link.strip_prefix(dir).unwrap_or(&link).display()
        ));
    }
    for path in paths {
        let rel = path
            .strip_prefix(dir)
            .unwrap_or(&path)
            .to_string_lossy()
            .replace('\\', "/");
        for (layer_name, read) in layers_of(&path) {
            let shown = match &layer_name {
                Some(l) => format!("{rel} layer {l}"),
                None => rel.clone(),
            };
            match read {
                Ok(layer) => {
                    let kind = layer
                        .features
                        .iter()
                        .map(|f| crate::input::geometry::shape_kind(&f.shape))
                        .find(|k| *k != "null shape")
                        .unwrap_or("empty");
                    let crs = layer
                        .prj
                        .as_deref()
                        .and_then(|w| w.split('"').nth(1).map(String::from))
                        .unwrap_or_else(|| "no .prj".into());
                    found.push(Found {
                        rel: rel.clone(),
                        layer: layer_name,
                        kind,
                        count: layer.features.len(),
                        fields: layer.fields,
                        encoding: layer.encoding,
                        crs,
                    });
                }
                Err(e) => problems.push(format!("{shown}: {e}")),
            }
        }
    }
    (found, problems)
}

fn name_score(f: &Found, words: &[&str]) -> usize {
    let l = match &f.layer {
        // A GeoPackage's layer by its own name: the file's is the town's.
        Some(layer) => layer.to_lowercase(),
        None => f.rel.to_lowercase(),
    };
    words.iter().filter(|w| l.contains(*w)).count()
}

impl Found {
    /// The lines that name this layer in a `[layers.*]` table.
    fn file_lines(&self) -> String {
        match &self.layer {
            Some(l) => format!("file = {:?}\nlayer = {:?}", self.rel, l),
            None => format!("file = {:?}", self.rel),
        }
    }

    /// The file and layer as the list of layers found shows them.
    fn shown(&self) -> String {
        match &self.layer {
            Some(l) => format!("{} layer {l}", self.rel),
            None => self.rel.clone(),
        }
    }
}

fn pick<'a>(found: &'a [Found], kind: &str, words: &[&str], avoid: &[&str]) -> Option<&'a Found> {
    found
        .iter()
        .filter(|f| f.kind == kind && name_score(f, avoid) == 0)
        .filter(|f| name_score(f, words) > 0)
        .max_by_key(|f| (name_score(f, words), f.count))
}

fn field<'a>(f: &'a Found, candidates: &[&str]) -> Option<&'a str> {
    candidates.iter().find_map(|c| {
        f.fields
            .iter()
            .find(|x| x.eq_ignore_ascii_case(c))
            .map(String::as_str)
    })
}

const ID_FIELDS: &[&str] = &[
    "id",
    "fid",
    "objectid",
    "gml_id",
    "osm_id",
    "chiban_id",
    "ag_cad_id",
    "object_id",
    "任意ID",
];

/// The parameter file text for `dir`.
pub fn params_text(dir: &Path) -> String {
    let (found, problems) = inspect(dir);
    let lots = pick(
        &found,
        "polygon",
        &[
            "lot", "parcel", "chiban", "地番", "敷地", "erf", "erven", "urban", "cadast",
            "shikichi",
        ],
        &["build", "bldg", "建物", "district", "road"],
    );
    let footprints = pick(
        &found,
        "polygon",
        &["build", "bldg", "建物", "footprint", "house"],
        &[],
    );
    let blocks = pick(
        &found,
        "polygon",
        &["block", "街区", "road_surface", "road"],
        &["build"],
    );
    let streets = pick(
        &found,
        "polyline",
        &["road", "street", "道路", "center", "centre", "route", "way"],
        &["split", "rail", "border"],
    );
    let districts = pick(
        &found,
        "polygon",
        &["district", "地区", "町丁", "chiku", "ward"],
        &["use_district", "youto"],
    );
    let widths = found.iter().find(|f| {
        f.kind == "polyline"
            && Some(f.shown()) != streets.map(Found::shown)
            && field(f, &["road_width", "width", "幅員"]).is_some()
    });

    let mut s = String::new();
    let _ = writeln!(
        s,
        "# edo-city parameters for {}, written by `edo-city init`.\n\
         # These are guesses from layer and field names: check every one, then build with\n\
         #   edo-city build {} --params <this file> --out out\n\
         # and look at out/plan.png. Keys left out keep the defaults of `edo-city params`.\n",
        dir.display(),
        shell_word(&dir.display().to_string())
    );
    let quote = |v: &str| format!("{v:?}");
    let _ = writeln!(s, "[layers.lots]");
    match lots {
        Some(l) => {
            let _ = writeln!(s, "{}", l.file_lines());
            let _ = writeln!(s, "[layers.lots.fields]");
            let id = field(l, ID_FIELDS).unwrap_or("id");
            let _ = writeln!(s, "id = {}", quote(id));
            if let Some(d) = field(l, &["district", "districtid", "地区", "town", "suburb"]) {
                let _ = writeln!(s, "district = {}", quote(d));
            }
            let _ = writeln!(
                s,
                "# No land-use field is assumed: every lot is a town lot (machiya). Map one with\n\
                 # use = \"<field>\" and [layers.lots.values.use] \"<code>\" = \"buke\", ..."
            );
        }
        None => {
            let _ = writeln!(s, "file = \"\"  # no lots layer recognised");
        }
    }
    let _ = writeln!(s, "\n[layers.footprints]");
    match footprints {
        Some(f) => {
            let _ = writeln!(s, "{}", f.file_lines());
            let _ = writeln!(s, "[layers.footprints.fields]");
            let _ = writeln!(s, "id = {}", quote(field(f, ID_FIELDS).unwrap_or("id")));
            let h = field(f, &["lod1_h", "height", "高さ", "measuredheight"]).unwrap_or("");
            let st = field(f, &["storeys", "building_l", "levels", "階数", "floors"]).unwrap_or("");
            let g = field(f, &["ground_z", "ground", "elevation", "標高"]).unwrap_or("");
            let _ = writeln!(
                s,
                "height = {}\nstoreys = {}\nground = {}\nmtype = \"\"",
                quote(h),
                quote(st),
                quote(g)
            );
        }
        None => {
            let _ = writeln!(s, "file = \"\"");
        }
    }
    let none = "file = \"\"".to_string();
    let _ = writeln!(s, "\n[layers.blocks]");
    let _ = writeln!(s, "{}", blocks.map_or(none.clone(), Found::file_lines));
    let _ = writeln!(s, "\n[layers.streets]");
    let _ = writeln!(s, "{}", streets.map_or(none, Found::file_lines));
    if let Some(w) = streets.and_then(|st| field(st, &["width", "road_width", "幅員"])) {
        let _ = writeln!(s, "width_field = {}", quote(w));
    }
    if let Some(w) = widths {
        let _ = writeln!(s, "\n[layers.street_widths]");
        let _ = writeln!(s, "{}", w.file_lines());
        let wf = field(w, &["road_width", "width", "幅員"]).unwrap_or("width");
        let _ = writeln!(s, "width_field = {}", quote(wf));
    }
    if let Some(d) = districts {
        let _ = writeln!(s, "\n[layers.districts]");
        let _ = writeln!(s, "{}", d.file_lines());
        let id = field(d, &["name", "disname", "district", "id", "districtid"]).unwrap_or("id");
        let _ = writeln!(s, "id_field = {}", quote(id));
    }
    let _ = writeln!(s, "\n# Layers found:");
    for f in &found {
        let _ = writeln!(
            s,
            "#   {}  {} x{}  CRS {}  text {}\n#     fields: {}",
            f.shown(),
            f.kind,
            f.count,
            f.crs,
            f.encoding,
            f.fields.join(", ")
        );
    }
    for p in &problems {
        let _ = writeln!(s, "#   could not read {p}");
    }
    if found.is_empty() {
        let _ = writeln!(
            s,
            "#   (no shapefiles, GeoPackages or GeoJSON files under {})",
            dir.display()
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_synthetic_town_is_recognised_and_the_file_parses() {
        let dir = tempfile::tempdir().unwrap();
        crate::synth::write_town(dir.path(), 80, 1, crate::synth::Profile::Grid, true).unwrap();
        let text = params_text(dir.path());
        assert!(text.contains("file = \"lots.shp\""), "{text}");
        assert!(text.contains("file = \"streets.shp\""), "{text}");
        assert!(text.contains("file = \"blocks.shp\""), "{text}");
        crate::params::Params::from_toml_str(&text, "init.toml").unwrap();
    }
}
