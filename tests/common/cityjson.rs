//! Reading a build's `city.city.jsonl` in tests: CityJSON's official validator (cjval) over
//! the header and every feature, and the city objects as JSON.

use std::io::BufRead;
use std::path::Path;

use serde_json::Value;

/// What cjval said of a CityJSONSeq: its features, and every error and warning with the
/// lines it is on.
pub struct Validated {
    pub features: usize,
    pub errors: Vec<String>,
    pub warnings: Vec<String>,
}

/// How many features cjval checks in one document: it compiles CityJSON's schema again for
/// every `validate()` (~0.1 s), which one call a feature made minutes of a real town.
const CHUNK: usize = 400;

/// Validates the CityJSONSeq at `path`: each feature on its own for what cjval checks of a
/// feature alone (its indices within its own vertices, materials, textures and texture
/// vertices; no vertex twice), then the features in documents of [`CHUNK`] for everything
/// else cjval checks (the schema, parents and children, semantics, materials, textures,
/// unused vertices), their vertices and appearances renumbered after each other. Vertices
/// two features share count as duplicates only inside a feature.
pub fn validate(path: &Path) -> Validated {
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let mut lines = file.lines();
    let first = lines.next().expect("a header").unwrap();
    let header: Value = serde_json::from_str(&first).expect("the header is JSON");
    let mut out = Validated {
        features: 0,
        errors: Vec::new(),
        warnings: Vec::new(),
    };
    check(&cjval::CJValidator::from_str(&first), "line 1", &mut out);
    let mut doc = Chunk::new(&header);
    for (i, line) in lines.enumerate() {
        let line = line.unwrap();
        let n = i + 2;
        out.features += 1;
        let f: Value = match serde_json::from_str(&line) {
            Ok(f) => f,
            Err(e) => {
                out.errors.push(format!("line {n}: {e}"));
                continue;
            }
        };
        if f["type"] != "CityJSONFeature" {
            out.errors.push(format!("line {n}: not a CityJSONFeature"));
            continue;
        }
        out.errors
            .extend(alone(&f).into_iter().map(|e| format!("line {n}: {e}")));
        doc.add(f, n);
        if doc.features == CHUNK {
            doc.validate(&mut out);
            doc = Chunk::new(&header);
        }
    }
    if doc.features > 0 {
        doc.validate(&mut out);
    }
    out
}

/// cjval's errors and warnings on `v`, said of `what`; `duplicate_vertices` left to
/// [`alone`] in a document of several features.
fn check(v: &cjval::CJValidator, what: &str, out: &mut Validated) {
    for (criterion, s) in v.validate() {
        if !s.has_errors() {
            continue;
        }
        let said = format!("{what}: {criterion}: {:?}", s.get_errors());
        match s.is_warning() {
            true => out.warnings.push(said),
            false => out.errors.push(said),
        }
    }
}

/// What is wrong with one feature on its own: an index past its own lists, a vertex twice.
fn alone(f: &Value) -> Vec<String> {
    let mut errors = Vec::new();
    let vertices = f["vertices"].as_array().map_or(0, |v| v.len()) as u64;
    let a = &f["appearance"];
    let len = |k: &str| a[k].as_array().map_or(0, |v| v.len()) as u64;
    let (materials, textures, uvs) = (len("materials"), len("textures"), len("vertices-texture"));
    let mut seen = std::collections::HashSet::new();
    for v in f["vertices"].as_array().into_iter().flatten() {
        if !seen.insert(v.to_string()) {
            errors.push(format!("vertex {v} twice"));
        }
    }
    for (id, o) in f["CityObjects"].as_object().into_iter().flatten() {
        for g in o["geometry"].as_array().into_iter().flatten() {
            if ints(&g["boundaries"]).any(|i| i >= vertices) {
                errors.push(format!("{id}: a vertex index past its {vertices} vertices"));
            }
            for (_, m) in g["material"].as_object().into_iter().flatten() {
                let values = ints(&m["values"]).chain(m["value"].as_u64());
                if values.into_iter().any(|i| i >= materials) {
                    errors.push(format!("{id}: a material past its {materials}"));
                }
            }
            for (_, t) in g["texture"].as_object().into_iter().flatten() {
                for ring in rings(&t["values"]) {
                    let Some(tex) = ring.first().and_then(Value::as_u64) else {
                        continue;
                    };
                    let bad = tex >= textures
                        || ring[1..]
                            .iter()
                            .any(|k| k.as_u64().is_none_or(|k| k >= uvs));
                    if bad {
                        errors.push(format!("{id}: a texture ring past its lists: {ring:?}"));
                    }
                }
            }
        }
    }
    errors
}

/// Every integer in nested arrays.
fn ints(v: &Value) -> Box<dyn Iterator<Item = u64> + '_> {
    match v {
        Value::Array(a) => Box::new(a.iter().flat_map(ints)),
        Value::Number(n) => Box::new(n.as_u64().into_iter()),
        _ => Box::new(std::iter::empty()),
    }
}

/// The innermost arrays (a texture's rings: `[t, uv, ...]` or `[null]`) of nested arrays.
fn rings(v: &Value) -> Vec<&Vec<Value>> {
    match v {
        Value::Array(a) if a.iter().all(|x| !x.is_array()) => vec![a],
        Value::Array(a) => a.iter().flat_map(rings).collect(),
        _ => Vec::new(),
    }
}

/// Features gathered into one CityJSON document, renumbered after each other.
struct Chunk {
    doc: Value,
    features: usize,
    lines: (usize, usize),
    twice: Vec<String>,
}

impl Chunk {
    fn new(header: &Value) -> Chunk {
        let mut doc = header.clone();
        doc["CityObjects"] = serde_json::json!({});
        doc["vertices"] = serde_json::json!([]);
        Chunk {
            doc,
            features: 0,
            lines: (0, 0),
            twice: Vec::new(),
        }
    }

    fn add(&mut self, f: Value, line: usize) {
        if self.features == 0 {
            self.lines.0 = line;
        }
        self.lines.1 = line;
        self.features += 1;
        let len = |d: &Value, k: &str| d["appearance"][k].as_array().map_or(0, |v| v.len()) as u64;
        let base = self.doc["vertices"].as_array().unwrap().len() as u64;
        let (m0, t0, uv0) = (
            len(&self.doc, "materials"),
            len(&self.doc, "textures"),
            len(&self.doc, "vertices-texture"),
        );
        for (id, mut o) in f["CityObjects"].as_object().cloned().unwrap_or_default() {
            if !self.doc["CityObjects"][&id].is_null() {
                self.twice
                    .push(format!("line {line}: city object {id} twice"));
            }
            // (`get_mut`, not `[]`: indexing a map for writing adds the key as null.)
            let geometries = o.get_mut("geometry").and_then(Value::as_array_mut);
            for g in geometries.into_iter().flatten() {
                if let Some(b) = g.get_mut("boundaries") {
                    shift(b, base);
                }
                let themes = g.get_mut("material").and_then(Value::as_object_mut);
                for m in themes.into_iter().flat_map(|t| t.values_mut()) {
                    for k in ["values", "value"] {
                        if let Some(v) = m.get_mut(k) {
                            shift(v, m0);
                        }
                    }
                }
                let themes = g.get_mut("texture").and_then(Value::as_object_mut);
                for t in themes.into_iter().flat_map(|t| t.values_mut()) {
                    if let Some(v) = t.get_mut("values") {
                        shift_textures(v, t0, uv0);
                    }
                }
            }
            self.doc["CityObjects"][id] = o;
        }
        let put = |doc: &mut Value, k: &str, v: Value| {
            if v.is_array() {
                doc[k]
                    .as_array_mut()
                    .unwrap()
                    .extend(v.as_array().unwrap().clone());
            }
        };
        put(&mut self.doc, "vertices", f["vertices"].clone());
        for k in ["materials", "textures", "vertices-texture"] {
            let v = f["appearance"][k].clone();
            if v.is_array() {
                let app = &mut self.doc["appearance"];
                if app.is_null() {
                    *app = serde_json::json!({});
                }
                if app[k].is_null() {
                    app[k] = serde_json::json!([]);
                }
                put(app, k, v);
            }
        }
    }

    fn validate(&self, out: &mut Validated) {
        let v = cjval::CJValidator::from_str(&self.doc.to_string());
        let mut said = Validated {
            features: 0,
            errors: Vec::new(),
            warnings: Vec::new(),
        };
        let what = format!("lines {}-{}", self.lines.0, self.lines.1);
        check(&v, &what, &mut said);
        out.errors.extend(self.twice.iter().cloned());
        out.errors.extend(said.errors);
        out.warnings
            .extend((said.warnings.into_iter()).filter(|w| !w.contains(": duplicate_vertices: ")));
    }
}

/// Every integer in nested arrays moved by `by`.
fn shift(v: &mut Value, by: u64) {
    match v {
        Value::Array(a) => a.iter_mut().for_each(|x| shift(x, by)),
        Value::Number(n) => {
            if let Some(i) = n.as_u64() {
                *v = Value::from(i + by);
            }
        }
        _ => {}
    }
}

/// A texture's values renumbered: each ring's first number is a texture, the rest are
/// texture vertices.
fn shift_textures(v: &mut Value, tex: u64, uv: u64) {
    let Value::Array(a) = v else { return };
    if a.iter().any(Value::is_array) {
        a.iter_mut().for_each(|x| shift_textures(x, tex, uv));
        return;
    }
    for (i, x) in a.iter_mut().enumerate() {
        if let Some(k) = x.as_u64() {
            *x = Value::from(k + if i == 0 { tex } else { uv });
        }
    }
}

/// The header and the features of a CityJSONSeq, as JSON.
pub fn read(path: &Path) -> (Value, Vec<Value>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text
        .lines()
        .map(|l| serde_json::from_str::<Value>(l).unwrap());
    let header = lines.next().unwrap();
    (header, lines.collect())
}

/// Every city object of `features` by id, with its type.
pub fn objects(features: &[Value]) -> Vec<(String, Value)> {
    features
        .iter()
        .flat_map(|f| f["CityObjects"].as_object().unwrap().clone())
        .collect()
}
