//! A leaf tile's GLB read back as the content its parents are made from: the surfaces in the
//! root's frame (z up, metres), coloured by their material (a texture by its mean colour),
//! the cut-outs with their texture coordinates, and the metadata table's rows.
//!
//! Parents are made from the leaves' files, not from the meshes in memory, so that a full
//! build, `--tiles` and `merge` (whose leaves were written by other processes) make the same
//! parents from the same bytes, and so that no more than a group of leaves is in memory.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::{Arc, Mutex};

use gltf::Semantic;
use serde_json::Value;

use super::colours::{texture_colours, KnownColours};
use super::{Content, Cutout, Part, TextureColours, MAX_FILE_BYTES};
use crate::output::features::Feature;
use crate::output::glb::metadata;
use crate::output::tiles3d::globe::Affine;

/// The kinds a parent leaves out: people are the size of the error of the first level.
pub const LEFT_OUT: &[&str] = &["people"];

/// What one leaf read back may take: its buffers (its shared models' and decoded views
/// included) and the elements of any accessor. A leaf of ours is under a megabyte and a
/// model a few; a leaf edited to declare more is refused, not allocated (issue 57).
pub const BUDGET: crate::geom::buffers::Budget = crate::geom::buffers::Budget {
    bytes: 1 << 30,
    elements: 1 << 26,
};

/// What reading the leaves needs besides their own bytes: the textures' colours and the
/// shared models they draw, each read once.
pub struct Sources {
    /// The mean colour of each texture.
    pub textures: TextureColours,
    /// The build's directory, where the leaves' external buffers (`tiles/models/<name>.bin`)
    /// are.
    out: std::path::PathBuf,
    /// The external buffers read so far, by URI.
    models: Mutex<BTreeMap<String, Arc<Vec<u8>>>>,
}

impl Sources {
    /// The sources of the build in `out`; with `known` (the workbench's memory), the
    /// textures' colours measured before are taken again for the textures whose bytes are
    /// the same, and `known` is left holding this build's.
    pub fn of(out: &Path, known: Option<&Mutex<KnownColours>>) -> Sources {
        let mut known = known.map(|k| k.lock().unwrap_or_else(|e| e.into_inner()));
        let textures = texture_colours(out, known.as_deref_mut());
        Sources {
            textures,
            out: out.to_path_buf(),
            models: Mutex::default(),
        }
    }

    /// The external buffer `uri` of a leaf (`shown`): a shared model the build wrote, read
    /// once. A URI that is not one (another directory, a scheme, `..`) is refused: a leaf
    /// read back names only what the build wrote.
    fn model(&self, uri: &str, shown: &str) -> Result<Arc<Vec<u8>>, String> {
        if !crate::output::glb::is_shared_uri(uri) {
            return Err(format!(
                "{shown}: its buffer `{uri}` is not a shared model of this build \
                 (models/<name>.bin): build the tiles again"
            ));
        }
        let mut models = self.models.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(b) = models.get(uri) {
            return Ok(b.clone());
        }
        let bytes = read_listed(&self.out, &format!("tiles/{uri}"))
            .map_err(|e| format!("{shown}: its shared model {e}: build the tiles again"))?;
        let b = Arc::new(bytes);
        models.insert(uri.to_string(), b.clone());
        Ok(b)
    }
}

/// Reads `tiles/<id>.glb` (its bytes `bytes`) placed by `transform` (leaf frame, z up, to
/// the root's frame).
pub fn leaf(
    bytes: &[u8],
    shown: &str,
    transform: &Affine,
    sources: &Sources,
) -> Result<Content, String> {
    let textures = &sources.textures;
    let g = gltf::Gltf::from_slice_without_validation(bytes)
        .map_err(|e| format!("{shown}: not a readable GLB: {e}"))?;
    let mut buffers = crate::geom::buffers::gather(&g, &BUDGET, shown, |uri, left| {
        let model = sources.model(uri, shown)?;
        match model.len() as u64 <= left {
            true => Ok(model.to_vec()),
            false => Err(format!(
                "{shown}: its buffers hold more than {} bytes: build the tiles again",
                BUDGET.bytes
            )),
        }
    })?;
    crate::geom::meshopt::decode(&g.document, &mut buffers, shown)?;
    let get = |b: gltf::Buffer| buffers.get(b.index()).map(|d| &d.0[..]);
    let mut content = Content {
        features: features(&g.document, &buffers, shown)?,
        ..Content::default()
    };
    // glTF's y-up leaf frame to the 3D Tiles z-up one, then to the root's frame.
    let place = |p: [f32; 3]| transform.apply([p[0] as f64, -p[2] as f64, p[1] as f64]);
    for node in g.document.nodes() {
        let Some(mesh) = node.mesh() else { continue };
        let walker = is_walker(&node);
        let kind = if walker {
            "people"
        } else {
            node.name().unwrap_or("")
        };
        // A node drawn at many places (instanced trees): each copy placed, with its own row.
        let copies = instances(&node, &g.document, &get, shown)?;
        // Its own transform (the grid of its quantized positions), once for all its vertices.
        let matrix = node.transform().matrix();
        for prim in mesh.primitives() {
            let reader = prim.reader(get);
            let Some(model) = crate::geom::accessor::positions(&prim, get) else {
                continue;
            };
            let (positions, ids, indices) = match &copies {
                // Drawn once, where its node puts it (quantized positions: the grid's
                // translation and scale).
                None => (
                    model
                        .iter()
                        .map(|&p| place(moved(&matrix, p)))
                        .collect::<Vec<_>>(),
                    None,
                    None,
                ),
                Some(copies) => {
                    let one: Vec<u32> = match reader.read_indices() {
                        Some(i) => i.into_u32().collect(),
                        None => (0..model.len() as u32).collect(),
                    };
                    let mut pos = Vec::with_capacity(model.len() * copies.len());
                    let (mut ids, mut idx) = (Vec::new(), Vec::new());
                    for c in copies {
                        let base = pos.len() as u32;
                        pos.extend(model.iter().map(|&p| place(c.apply(p))));
                        ids.extend(std::iter::repeat_n(c.feature, model.len()));
                        idx.extend(one.iter().map(|i| i + base));
                    }
                    (pos, Some(ids), Some(idx))
                }
            };
            if LEFT_OUT.contains(&kind) {
                // A walker's figure is 1 m tall, drawn at its node's scale.
                let scale = match walker {
                    true => f64::from(node.transform().decomposed().2[1]),
                    false => 1.0,
                };
                let indices: Vec<u32> = reader
                    .read_indices()
                    .map(|i| i.into_u32().collect())
                    .unwrap_or_default();
                let size = largest_figure(&positions, &indices) * scale;
                content.dropped = content.dropped.max(size);
                continue;
            }
            let ids: Vec<u32> = match (ids, prim.get(&Semantic::Extras("FEATURE_ID_0".into()))) {
                (Some(ids), _) => ids,
                (None, Some(a)) => gltf::accessor::Iter::<f32>::new(a, get)
                    .map(|it| it.map(|v| v as u32).collect())
                    .unwrap_or_default(),
                (None, None) => vec![0; positions.len()],
            };
            let indices: Vec<u32> = match (indices, reader.read_indices()) {
                (Some(i), _) => i,
                (None, Some(i)) => i.into_u32().collect(),
                (None, None) => (0..positions.len() as u32).collect(),
            };
            if ids.len() != positions.len()
                || indices.iter().any(|&i| i as usize >= positions.len())
            {
                return Err(format!("{shown}: a primitive's accessors disagree"));
            }
            let material = prim.material();
            let uvs = || {
                reader
                    .read_tex_coords(0)
                    .map(|t| t.into_f32().collect::<Vec<_>>())
            };
            let Some(part) = part_of(&mut content, &material, textures, positions.len(), uvs)
            else {
                continue;
            };
            let base = part.positions.len() as u32;
            part.positions.extend(positions);
            part.ids.extend(ids);
            part.indices.extend(indices.iter().map(|i| i + base));
        }
    }
    Ok(content)
}

/// Whether `node` draws walkers, who are people: a tile's skinned crowd (its figures at the
/// origin, placed by the joints its clip moves), or a walker's own node as tiles had it
/// before.
fn is_walker(node: &gltf::Node) -> bool {
    node.skin().is_some()
        || node.extras().as_ref().is_some_and(|e| {
            serde_json::from_str::<serde_json::Value>(e.get())
                .is_ok_and(|v| v.get("person").is_some())
        })
}

/// The size of the largest figure (a card or a mesh of its own: a part joined by its
/// triangles) of a primitive left out, not of the whole object (a tile's people are one);
/// 0 when its indices do not fit its positions.
fn largest_figure(positions: &[[f64; 3]], indices: &[u32]) -> f64 {
    if indices.iter().any(|&i| (i as usize) >= positions.len()) {
        return 0.0;
    }
    super::components(indices, positions.len())
        .iter()
        .map(|part| {
            extent(
                &part
                    .iter()
                    .map(|&v| positions[v as usize])
                    .collect::<Vec<_>>(),
            )
        })
        .fold(0.0, f64::max)
}

/// Where a primitive of `material` goes in `content`: the cut-outs of its texture (with its
/// `vertices`' uvs, zeros when it has none), or the solid part with its colour (its
/// texture's mean, else its own) for each vertex. `None` for a cut-out with no texture.
fn part_of<'c>(
    content: &'c mut Content,
    material: &gltf::Material,
    textures: &TextureColours,
    vertices: usize,
    uvs: impl FnOnce() -> Option<Vec<[f32; 2]>>,
) -> Option<&'c mut Part> {
    let texture = material
        .pbr_metallic_roughness()
        .base_color_texture()
        .and_then(|t| match t.texture().source().source() {
            gltf::image::Source::Uri { uri, .. } => Some(uri.to_string()),
            _ => None,
        });
    if material.alpha_mode() == gltf::material::AlphaMode::Mask {
        let uri = texture?;
        let name = material.name().unwrap_or("cutout").to_string();
        let uvs = uvs().unwrap_or_else(|| vec![[0.0; 2]; vertices]);
        let c = content.cutouts.entry(name).or_insert_with(|| Cutout {
            uri: uri.clone(),
            part: Part::default(),
        });
        c.part.uvs.extend(uvs);
        return Some(&mut c.part);
    }
    let colour = match &texture {
        Some(uri) => textures.mean(uri),
        None => material.pbr_metallic_roughness().base_color_factor(),
    };
    let c = colour.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8);
    content
        .solid
        .colours
        .extend(std::iter::repeat_n(c, vertices));
    Some(&mut content.solid)
}

/// One copy of an instanced node (`EXT_mesh_gpu_instancing`): scale, then rotation, then
/// translation, in the leaf's y-up frame; and its metadata row.
struct Copy {
    t: [f32; 3],
    r: [f32; 4],
    s: [f32; 3],
    feature: u32,
}

impl Copy {
    /// `p` of the model where this copy has it.
    fn apply(&self, p: [f32; 3]) -> [f32; 3] {
        let v = [p[0] * self.s[0], p[1] * self.s[1], p[2] * self.s[2]];
        // v + 2w (q x v) + 2 q x (q x v), q the quaternion's vector part.
        let [x, y, z, w] = self.r;
        let cross = |a: [f32; 3], b: [f32; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let c1 = cross([x, y, z], v);
        let c2 = cross([x, y, z], c1);
        [0, 1, 2].map(|k| v[k] + 2.0 * w * c1[k] + 2.0 * c2[k] + self.t[k])
    }
}

/// The copies of an instanced node, or `None` for a node drawn once.
fn instances<'a>(
    node: &gltf::Node,
    doc: &'a gltf::Document,
    get: &(impl Fn(gltf::Buffer<'a>) -> Option<&'a [u8]> + Clone),
    shown: &str,
) -> Result<Option<Vec<Copy>>, String> {
    let Some(ext) = node.extension_value("EXT_mesh_gpu_instancing") else {
        return Ok(None);
    };
    let bad = || format!("{shown}: an instanced node's attributes are unreadable");
    // An attribute's values (none when the node does not give it).
    fn read<'a, T: gltf::accessor::Item>(
        ext: &serde_json::Value,
        name: &str,
        doc: &'a gltf::Document,
        get: impl Fn(gltf::Buffer<'a>) -> Option<&'a [u8]> + Clone,
    ) -> Option<Option<Vec<T>>> {
        let Some(i) = ext["attributes"][name].as_u64() else {
            return Some(None);
        };
        let a = doc.accessors().nth(i as usize)?;
        Some(Some(gltf::accessor::Iter::<T>::new(a, get)?.collect()))
    }
    let t: Vec<[f32; 3]> = read(ext, "TRANSLATION", doc, get.clone())
        .ok_or_else(bad)?
        .unwrap_or_default();
    let s: Vec<[f32; 3]> = read(ext, "SCALE", doc, get.clone())
        .ok_or_else(bad)?
        .unwrap_or_default();
    let r: Vec<[f32; 4]> = read(ext, "ROTATION", doc, get.clone())
        .ok_or_else(bad)?
        .unwrap_or_default();
    let ids: Vec<f32> = read(ext, "_FEATURE_ID_0", doc, get.clone())
        .ok_or_else(bad)?
        .unwrap_or_default();
    let n = t.len().max(s.len()).max(r.len());
    Ok(Some(
        (0..n)
            .map(|i| Copy {
                t: t.get(i).copied().unwrap_or([0.0; 3]),
                r: r.get(i).copied().unwrap_or([0.0, 0.0, 0.0, 1.0]),
                s: s.get(i).copied().unwrap_or([1.0; 3]),
                feature: ids.get(i).map_or(0, |&v| v as u32),
            })
            .collect(),
    ))
}

/// `p` moved by a node's own transform `m` (column-major; a leaf's nodes are at the tile's
/// root).
fn moved(m: &[[f32; 4]; 4], p: [f32; 3]) -> [f32; 3] {
    [0, 1, 2].map(|r| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r])
}

/// The largest side of the box around `points`.
pub fn extent(points: &[[f64; 3]]) -> f64 {
    let (lo, hi) = bounds(points);
    (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max)
}

/// The lowest and highest corners of the box around `points` (infinities, lowest above
/// highest, when there are none).
pub fn bounds<'a>(points: impl IntoIterator<Item = &'a [f64; 3]>) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// The rows of the GLB's property table, as the writer laid them out
/// ([`crate::output::glb::metadata`]); a column the table leaves out is empty in every row.
/// The table's `count` must be no more than its `name` column holds rows: a count of 1e10
/// in a few bytes was allocated before it was believed (issue 57).
fn features(
    doc: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    shown: &str,
) -> Result<Vec<Feature>, String> {
    let Some(table) = doc
        .extension_value("EXT_structural_metadata")
        .and_then(|m| m.get("propertyTables"))
        .and_then(|t| t.get(0))
    else {
        return Ok(Vec::new());
    };
    let count = table["count"].as_u64().unwrap_or(0);
    let view = |v: &Value| -> &[u8] {
        let Some(view) = v.as_u64().and_then(|i| doc.views().nth(i as usize)) else {
            return &[];
        };
        buffers
            .get(view.buffer().index())
            .and_then(|b| b.0.get(view.offset()..view.offset() + view.length()))
            .unwrap_or(&[])
    };
    // Each row has a name: its end in the name column's string offsets (4 bytes a row).
    let rows = (view(&table["properties"]["name"]["stringOffsets"]).len() / 4).saturating_sub(1);
    if count > rows as u64 {
        return Err(format!(
            "{shown}: its property table claims {count} rows and holds {rows}: it is damaged; \
             build the tiles again"
        ));
    }
    let count = count as usize;
    let enums = doc
        .extension_value("EXT_structural_metadata")
        .map(|m| &m["schema"]["enums"]);
    let column = |key: &str| -> Vec<String> {
        let p = &table["properties"][key];
        let values = view(&p["values"]);
        if let Some(e) = enums.map(|e| &e[key]).filter(|e| e.is_object()) {
            // An enum: a byte or two a row, named by the schema; "no value" is empty.
            let names: BTreeMap<u64, &str> = (e["values"].as_array().into_iter().flatten())
                .filter_map(|v| Some((v["value"].as_u64()?, v["name"].as_str()?)))
                .collect();
            let wide = e["valueType"] == "UINT16";
            return (0..count)
                .map(|i| {
                    let v = match wide {
                        true => values
                            .get(2 * i..2 * i + 2)
                            .map(|b| u16::from_le_bytes([b[0], b[1]]) as u64),
                        false => values.get(i).map(|&b| b as u64),
                    };
                    match v.and_then(|v| names.get(&v)) {
                        Some(&n) if n != metadata::NO_VALUE => n.to_string(),
                        _ => String::new(),
                    }
                })
                .collect();
        }
        let offsets: Vec<usize> = view(&p["stringOffsets"])
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as usize)
            .collect();
        (0..count)
            .map(|i| {
                let (Some(&a), Some(&b)) = (offsets.get(i), offsets.get(i + 1)) else {
                    return String::new();
                };
                values
                    .get(a..b)
                    .map(|s| String::from_utf8_lossy(s).into_owned())
                    .unwrap_or_default()
            })
            .collect()
    };
    let mut cols: BTreeMap<&str, Vec<String>> = BTreeMap::new();
    for key in ["name", "kind", "lot", "mtype", "district", "use", "source"] {
        cols.insert(key, column(key));
    }
    let kura = view(&table["properties"]["kura"]["values"]);
    let mut take = |key: &str, i: usize| std::mem::take(&mut cols.get_mut(key).unwrap()[i]);
    Ok((0..count)
        .map(|i| Feature {
            name: take("name", i),
            kind: take("kind", i),
            lot: take("lot", i),
            mtype: take("mtype", i),
            district: take("district", i),
            lot_use: take("use", i),
            source: take("source", i),
            kura: kura.get(i / 8).is_some_and(|b| b >> (i % 8) & 1 == 1),
            // Not in a GLB's table.
            record: None,
            street: String::new(),
        })
        .collect())
}

/// The bytes of a file a build listed (`dir/path`), checked as `output::listed` checks it
/// and read within [`MAX_FILE_BYTES`]; the error names the path as listed.
pub fn read_listed(dir: &Path, path: &str) -> Result<Vec<u8>, String> {
    let real = crate::output::listed::locate(dir, path).map_err(|e| e.to_string())?;
    crate::bounded::read(&real, MAX_FILE_BYTES).map_err(|e| format!("`{path}` {e}"))
}
