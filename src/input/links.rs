//! The links layer (the paper's hyperlinks in the city, section 5): points that open a page
//! or an image about the place (a painting, a famous place's entry). A point layer
//! (`links.shp`) or a CSV table with `x`, `y` columns in the output CRS; either with
//! `title`, `url` and `image` (field names in `[layers.links]`). A link whose URL is not an
//! `http(s)://` address is skipped with its record.

use geo_types::Coord;

use super::fields::resolve_field;
use super::geometry::points_of;
use super::{to_target, InputError, Opened};
use crate::model::{Dataset, LayerInfo, Link, Skipped};
use crate::params::LinksLayer;

/// Why `s` cannot be a link's address, if it cannot (empty is allowed: the other one may
/// carry the link).
pub fn url_problem(s: &str) -> Option<String> {
    if s.is_empty() {
        return None;
    }
    let rest = s
        .strip_prefix("https://")
        .or_else(|| s.strip_prefix("http://"));
    let host = rest.map(|r| r.split(['/', '?', '#']).next().unwrap_or(""));
    let bad_char = s
        .chars()
        .any(|c| c.is_whitespace() || c.is_control() || c == '"' || c == '<' || c == '>');
    match host {
        Some(h) if !h.is_empty() && !bad_char && !h.starts_with(':') => None,
        _ => Some(format!(
            "not a web address (`{s}`): give a full http:// or https:// URL (no spaces)"
        )),
    }
}

/// A link from its attributes, or why it cannot be one.
fn link(
    id: String,
    record: usize,
    at: Coord<f64>,
    get: &dyn Fn(&str) -> String,
    l: &LinksLayer,
    city: Option<geo_types::Rect<f64>>,
) -> Result<Link, String> {
    let (title, url, image) = (get(&l.title_field), get(&l.url_field), get(&l.image_field));
    if let Some(p) = url_problem(&url).or_else(|| url_problem(&image)) {
        return Err(p);
    }
    if url.is_empty() && image.is_empty() {
        return Err(format!(
            "neither `{}` nor `{}` holds an address: give the page or the image to open",
            l.url_field, l.image_field
        ));
    }
    if let Some(why) = super::geometry::beyond_city(at, city) {
        return Err(why);
    }
    Ok(Link {
        id,
        record,
        at,
        title,
        url,
        image,
    })
}

/// The links of a point layer.
pub(super) fn read_link_points(
    l: &LinksLayer,
    o: &Opened,
    target: &Option<super::crs::Crs>,
    data: &mut Dataset,
) -> Result<(), InputError> {
    let field = |name: &str| resolve_field(name, &o.layer.fields, o.layer.text_encoding);
    let city = data.city_box();
    for f in &o.layer.features {
        let mut points =
            points_of(&f.shape).map_err(|kind| o.wrong_shape(f.record, kind, "points"))?;
        let get = |name: &str| {
            field(name)
                .and_then(|k| f.attrs.get(k))
                .map(|v| v.trim().to_string())
                .unwrap_or_default()
        };
        let id = Some(get(&l.id_field))
            .filter(|v| !v.is_empty())
            .unwrap_or_else(|| (f.record + 1).to_string());
        let result = match points.len() {
            0 => Err("null shape: the record has no point; place it or delete the record".into()),
            _ => to_target(o, target, &mut points[..1])
                .map_err(|e| e.to_string())
                .and_then(|_| link(id.clone(), f.record, points[0], &get, l, city)),
        };
        push(data, result, &o.file, id, f.record);
    }
    Ok(())
}

/// The links of a CSV table (coordinates in the output CRS).
pub(super) fn read_link_table(
    l: &LinksLayer,
    path: &std::path::Path,
    data: &mut Dataset,
) -> Result<(), InputError> {
    let file = path.display().to_string();
    let err = |message: String| InputError::Table {
        file: file.clone(),
        message,
    };
    let mut reader = csv::ReaderBuilder::new()
        .from_path(path)
        .map_err(|e| err(e.to_string()))?;
    let headers: Vec<String> = reader
        .headers()
        .map_err(|e| err(format!("cannot read the header row: {e}")))?
        .iter()
        .map(|h| h.trim().trim_start_matches('\u{feff}').to_string())
        .collect();
    for need in [&l.x_field, &l.y_field] {
        if !headers.iter().any(|h| h == need) {
            return Err(err(format!(
                "no column `{need}` (columns: {}); set `layers.links.x_field` / `y_field`",
                headers.join(", ")
            )));
        }
    }
    let mut rows = 0;
    let city = data.city_box();
    for (record, row) in reader.records().enumerate() {
        let row = row.map_err(|e| err(format!("row {}: {e}", record + 2)))?;
        rows += 1;
        let get = |name: &str| {
            headers
                .iter()
                .position(|h| h == name)
                .and_then(|i| row.get(i))
                .map(|v| v.trim().to_string())
                .unwrap_or_default()
        };
        let id = Some(get(&l.id_field))
            .filter(|v| !v.is_empty())
            .unwrap_or_else(|| (record + 1).to_string());
        let num = |name: &str| get(name).parse::<f64>().unwrap_or(f64::NAN);
        let at = Coord {
            x: num(&l.x_field),
            y: num(&l.y_field),
        };
        let result = link(id.clone(), record, at, &get, l, city);
        push(data, result, &file, id, record);
    }
    data.layers.push(LayerInfo {
        role: "links".into(),
        file,
        features: rows,
        encoding: "UTF-8 (CSV)".into(),
        crs: "the output CRS (a table's x, y)".into(),
        reprojected: false,
        vertices_before: 0,
        vertices_after: 0,
    });
    Ok(())
}

/// Keeps a link or lists it as skipped.
fn push(data: &mut Dataset, result: Result<Link, String>, file: &str, id: String, record: usize) {
    match result {
        Ok(link) => data.links.push(link),
        Err(reason) => data.skipped.push(Skipped {
            layer: "links".into(),
            file: file.to_string(),
            id,
            record: Some(record),
            reason,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::url_problem;

    #[test]
    fn only_web_addresses_are_links() {
        assert!(url_problem("https://www.kyoto-museum.jp/rakuchu").is_none());
        assert!(url_problem("http://example.org/a b").is_some());
        assert!(url_problem("javascript:alert(1)").is_some());
        assert!(url_problem("https://").is_some());
        assert!(url_problem("www.example.org").is_some());
        assert!(url_problem("").is_none());
    }
}
