//! `links.json`: the links layer's points for the viewer's markers, in the build's frame
//! (x east, y north from the output origin, z the ground of the lot holding the point, else
//! 0), with the title and the addresses they open.

use std::path::Path;

use geo::Contains;
use serde_json::json;

use super::report::ManifestFile;
use crate::model::Dataset;

/// Writes `<out>/links.json` when the input has links; returns its manifest entry.
pub fn write_links(
    out: &Path,
    data: &Dataset,
    origin: [f64; 2],
) -> std::io::Result<Option<ManifestFile>> {
    if data.links.is_empty() {
        let _ = std::fs::remove_file(out.join("links.json"));
        return Ok(None);
    }
    let items: Vec<_> = data
        .links
        .iter()
        .map(|l| {
            let ground = data
                .lots
                .iter()
                .find(|lot| lot.outline.contains(&geo::Point(l.at)))
                .map_or(0.0, |lot| lot.ground);
            let r = |v: f64| (v * 1000.0).round() / 1000.0;
            json!({
                "id": l.id,
                "title": l.title,
                "url": l.url,
                "image": l.image,
                "x": r(l.at.x - origin[0]),
                "y": r(l.at.y - origin[1]),
                "z": r(ground),
            })
        })
        .collect();
    let bytes = serde_json::to_vec_pretty(&items).expect("serialises");
    super::write_listed(out, "links.json".into(), &[&bytes]).map(Some)
}
