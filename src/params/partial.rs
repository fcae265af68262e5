//! The schema of the parameter file again, every field optional, for checking a user's
//! partial file: an unknown key or a wrong type is reported at the user's own line and
//! column. A new key goes into both this copy and the full one in `params.rs` (the
//! unknown-key test catches a miss).

use serde::Deserialize;
use std::collections::BTreeMap;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
pub struct Params {
    extends: Option<String>,
    seed: Option<u64>,
    seeds: Option<BTreeMap<String, u64>>,
    tile_size: Option<f64>,
    tile_origin: Option<[f64; 2]>,
    origin: Option<[f64; 2]>,
    crs: Option<String>,
    layers: Option<Layers>,
    input: Option<super::input::partial::Input>,
    frontage: Option<Frontage>,
    machiya: Option<Machiya>,
    kura: Option<Kura>,
    simplify: Option<Simplify>,
    fence: Option<Fence>,
    people: Option<super::billboards::partial::People>,
    trees: Option<super::billboards::partial::Trees>,
    crowd: Option<super::crowd::partial::Crowd>,
    garden: Option<super::garden::partial::Garden>,
    halls: Option<super::halls::partial::Halls>,
    ground: Option<super::halls::partial::Ground>,
    landmarks: Option<super::landmarks::partial::Landmarks>,
    output: Option<super::output::partial::Output>,
    origin_lonlat: Option<[f64; 3]>,
    type_mix: Option<BTreeMap<String, f64>>,
    textures: Option<String>,
    terrain: Option<bool>,
    template: Option<BTreeMap<String, BTreeMap<String, f64>>>,
    district: Option<BTreeMap<String, District>>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct District {
    type_mix: Option<BTreeMap<String, f64>>,
    template: Option<BTreeMap<String, BTreeMap<String, f64>>>,
    people_per_100m: Option<f64>,
    trees_per_ha: Option<f64>,
    trees_per_ha_machiya: Option<f64>,
    people_motion: Option<String>,
    trees_style: Option<String>,
    tree_species: Option<BTreeMap<String, BTreeMap<String, f64>>>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct Layers {
    lots: Option<Lots>,
    blocks: Option<Blocks>,
    streets: Option<Streets>,
    street_widths: Option<Widths>,
    footprints: Option<Footprints>,
    districts: Option<Districts>,
    fences: Option<FencesLayer>,
    people: Option<super::billboards::partial::PointsLayer>,
    trees: Option<super::billboards::partial::PointsLayer>,
    gardens: Option<FencesLayer>,
    water: Option<FencesLayer>,
    links: Option<LinksLayer>,
    landmarks: Option<super::landmarks::partial::LandmarksLayer>,
    dem: Option<DemLayer>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct LinksLayer {
    file: Option<String>,
    layer: Option<String>,
    encoding: Option<String>,
    id_field: Option<String>,
    title_field: Option<String>,
    url_field: Option<String>,
    image_field: Option<String>,
    x_field: Option<String>,
    y_field: Option<String>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct DemLayer {
    file: Option<String>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct FencesLayer {
    file: Option<String>,
    layer: Option<String>,
    encoding: Option<String>,
    id_field: Option<String>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct Districts {
    file: Option<String>,
    layer: Option<String>,
    encoding: Option<String>,
    id_field: Option<String>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct Widths {
    file: Option<String>,
    layer: Option<String>,
    encoding: Option<String>,
    width_field: Option<String>,
    max_distance: Option<f64>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct Footprints {
    file: Option<String>,
    layer: Option<String>,
    encoding: Option<String>,
    fields: Option<FootprintFields>,
    values: Option<BTreeMap<String, BTreeMap<String, String>>>,
    default_type: Option<String>,
    storey_height: Option<f64>,
    default_height: Option<f64>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct FootprintFields {
    id: Option<String>,
    mtype: Option<String>,
    height: Option<String>,
    storeys: Option<String>,
    ground: Option<String>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct Lots {
    file: Option<String>,
    layer: Option<String>,
    encoding: Option<String>,
    table: Option<String>,
    sheet: Option<String>,
    fields: Option<LotFields>,
    values: Option<BTreeMap<String, BTreeMap<String, String>>>,
    constants: Option<BTreeMap<String, String>>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct LotFields {
    id: Option<String>,
    #[serde(rename = "use")]
    lot_use: Option<String>,
    mtype: Option<String>,
    district: Option<String>,
    tile: Option<String>,
    ground: Option<String>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct Blocks {
    file: Option<String>,
    layer: Option<String>,
    encoding: Option<String>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct Streets {
    file: Option<String>,
    layer: Option<String>,
    encoding: Option<String>,
    width_field: Option<String>,
    default_width: Option<f64>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct Frontage {
    max_angle_deg: Option<f64>,
    min_length: Option<f64>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct Machiya {
    depth: Option<f64>,
    min_depth: Option<f64>,
    templates: Option<String>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct Fence {
    enabled: Option<bool>,
    uses: Option<Vec<String>>,
    types: Option<BTreeMap<String, String>>,
    default_type: Option<String>,
    gate_template: Option<String>,
    gate_width: Option<f64>,
    type_field: Option<String>,
    gate_field: Option<String>,
    height_field: Option<String>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct Simplify {
    tolerance: Option<f64>,
    max_vertices: Option<usize>,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct Kura {
    enabled: Option<bool>,
    template: Option<String>,
    min_frontage: Option<f64>,
    depth_ratio: Option<f64>,
    width: Option<f64>,
    depth: Option<f64>,
    min_width: Option<f64>,
    min_depth: Option<f64>,
    gap: Option<f64>,
    back_margin: Option<f64>,
    side_margin: Option<f64>,
    collision: Option<bool>,
    overlap_tolerance: Option<f64>,
}
