//! Fences and gates along lot outlines, section 4.3 of the paper.
//!
//! Every lot whose use is in `fence.uses` (samurai, noble and temple lots by default) is
//! walled along every edge of its outline. Each edge becomes one fence segment: the site of a
//! fence template, running from the edge's first vertex to its second with the lot on its
//! left. The gate (`gate` attribute: 1 = the edge facing the street, `eN` = edge N) is a gate
//! of `fence.gate_width` centred on its edge, with the wall split into the two side parts of
//! Fig.11; an edge shorter than the gate is filled by the gate, with a warning.

use geo::Centroid;
use geo_types::Coord;

use super::room::{LotEdges, MAX_ROOM};
use super::street::StreetEdges;
use crate::model::{FenceKind, FenceLine, Lot, PlannedFence};
use crate::params::Params;

/// cot of half the interior angle at `p` (neighbours `q` before, `r` after, ring
/// counter-clockwise): how far, per metre of wall thickness, a wall's inner edge runs past
/// the corner so that two walls meet on the angle's bisector. 1 at a right angle, 0 for a
/// straight continuation, negative at a reflex corner.
pub fn mitre(q: Coord<f64>, p: Coord<f64>, r: Coord<f64>) -> f64 {
    let (a, b) = ((p.x - q.x, p.y - q.y), (r.x - p.x, r.y - p.y));
    // Turn to the left, (-pi, pi]; the interior angle is pi - turn.
    let turn = (a.0 * b.1 - a.1 * b.0).atan2(a.0 * b.0 + a.1 * b.1);
    let half = (std::f64::consts::PI - turn) / 2.0;
    let cot = half.cos() / half.sin();
    // A hairpin (interior angle near 0) would run the wall to infinity: cap it. The cap is
    // high so that the mitre line stays on the bisector of any real corner and the wall
    // never crosses the hairpin's other side (a wall's template keeps its inner corners
    // within the edge, so a large mitre thins the wall rather than lengthening it).
    cot.clamp(-1e4, 1e4)
}

/// Which edge holds the gate, from the `gate` attribute: `1`/`street` = the edge whose middle
/// is nearest a street edge, `eN`/`edge N` = edge N (from 1), `0`/empty = none.
pub fn gate_edge(
    raw: &str,
    ring: &[Coord<f64>],
    edges: &StreetEdges,
) -> Result<Option<usize>, String> {
    let t = raw.trim().to_lowercase();
    let n = ring.len();
    match t.as_str() {
        "" | "0" | "no" | "none" => Ok(None),
        "1" | "street" | "yes" | "true" => Ok((0..n)
            .map(|i| {
                let (a, b) = (ring[i], ring[(i + 1) % n]);
                let mid = Coord {
                    x: (a.x + b.x) / 2.0,
                    y: (a.y + b.y) / 2.0,
                };
                (edges.distance(mid), i)
            })
            .min_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)))
            .map(|(_, i)| i)),
        other => {
            let num = other
                .strip_prefix("edge")
                .or_else(|| other.strip_prefix('e'))
                .map(str::trim)
                .and_then(|s| s.parse::<usize>().ok());
            match num {
                Some(k) if (1..=n).contains(&k) => Ok(Some(k - 1)),
                _ => Err(format!(
                    "gate `{raw}` is not 0, 1 (the edge facing the street) or eN with N from 1 to {n}"
                )),
            }
        }
    }
}

/// The fence template of a lot: its `fence` attribute, else the one for its use.
fn template_of(lot: &Lot, params: &Params) -> String {
    let f = &params.fence;
    lot.attrs
        .iter()
        .find(|(k, _)| k.eq_ignore_ascii_case(&f.type_field))
        .map(|(_, v)| v.trim().to_string())
        .filter(|v| !v.is_empty())
        .or_else(|| f.types.get(lot.lot_use.name()).cloned())
        .unwrap_or_else(|| f.default_type.clone())
}

/// A line's value of the attribute `field` (case ignored), trimmed.
fn attr<'a>(attrs: &'a crate::model::Attrs, field: &str) -> Option<&'a str> {
    attrs
        .iter()
        .find(|(k, _)| k.eq_ignore_ascii_case(field))
        .map(|(_, v)| v.trim())
        .filter(|v| !v.is_empty())
}

/// What every segment of one outline or line shares.
struct Walled<'a> {
    id: &'a str,
    record: usize,
    layer: &'static str,
    file: &'a str,
    template: String,
    ground: f64,
    district: Option<String>,
    tile: String,
    attrs: Vec<(String, f64)>,
}

/// The segments of a closed ring (`closed`, points not repeated) or an open line, with the
/// wall on the left of each segment and the gate on segment `gate`.
fn segments(
    w: &Walled,
    pts: &[Coord<f64>],
    closed: bool,
    gate: Option<usize>,
    params: &Params,
    warnings: &mut Vec<crate::model::Warning>,
) -> Vec<PlannedFence> {
    let n = pts.len();
    let count = if closed { n } else { n - 1 };
    let seg = |a: Coord<f64>, b: Coord<f64>, c0: f64, c1: f64, kind: FenceKind, edge: usize| {
        PlannedFence {
            id: w.id.to_string(),
            record: w.record,
            layer: w.layer.into(),
            template: match kind {
                FenceKind::Wall => w.template.clone(),
                FenceKind::Gate => params.fence.gate_template.clone(),
            },
            kind,
            edge,
            a,
            b,
            start_mitre: c0,
            end_mitre: c1,
            ground: w.ground,
            ground_end: w.ground,
            room: MAX_ROOM,
            district: w.district.clone(),
            tile: w.tile.clone(),
            attrs: w.attrs.clone(),
        }
    };
    let mut out = Vec::new();
    for i in 0..count {
        let (a, b) = (pts[i], pts[(i + 1) % n]);
        // A free end of an open line is square; every other end is mitred.
        let c0 = if closed || i > 0 {
            mitre(pts[(i + n - 1) % n], a, b)
        } else {
            0.0
        };
        let c1 = if closed || i + 2 < n {
            mitre(a, b, pts[(i + 2) % n])
        } else {
            0.0
        };
        let len = (b.x - a.x).hypot(b.y - a.y);
        if len < 1e-6 {
            continue;
        }
        if gate != Some(i) {
            out.push(seg(a, b, c0, c1, FenceKind::Wall, i));
            continue;
        }
        let gw = params.fence.gate_width;
        if len <= gw {
            warnings.push(crate::model::Warning::feature(
                w.layer,
                w.file,
                w.id,
                format!(
                    "{}: {} {}: edge {} is {len:.2} m, shorter than the gate ({gw} m): the gate \
                 fills the edge",
                    w.file,
                    if w.layer == "lots" { "lot" } else { "fence" },
                    w.id,
                    i + 1
                ),
            ));
            out.push(seg(a, b, 0.0, 0.0, FenceKind::Gate, i));
            continue;
        }
        // Fig.11: the wall's two side parts, the gate between them, centred on the edge.
        let at = |t: f64| Coord {
            x: a.x + (b.x - a.x) * t,
            y: a.y + (b.y - a.y) * t,
        };
        let (t0, t1) = (0.5 - gw / 2.0 / len, 0.5 + gw / 2.0 / len);
        out.push(seg(a, at(t0), c0, 0.0, FenceKind::Wall, i));
        out.push(seg(at(t0), at(t1), 0.0, 0.0, FenceKind::Gate, i));
        out.push(seg(at(t1), b, 0.0, c1, FenceKind::Wall, i));
    }
    out
}

/// The highest wall a `height` attribute may ask for, metres (castle walls stand 30 m).
pub const MAX_WALL_HEIGHT: f64 = 100.0;

/// The height attribute, for the template's `height`. A value that is not a height (not a
/// number, not above 0, over [`MAX_WALL_HEIGHT`]) gives a warning naming the feature, and
/// the template's own height stands.
fn height_attr(
    attrs: &crate::model::Attrs,
    params: &Params,
    what: &str,
    warnings: &mut Vec<crate::model::Warning>,
) -> Vec<(String, f64)> {
    let Some(raw) = attr(attrs, &params.fence.height_field) else {
        return Vec::new();
    };
    match raw.trim().parse::<f64>() {
        Ok(h) if h.is_finite() && h > 0.0 && h <= MAX_WALL_HEIGHT => {
            vec![("height".to_string(), h)]
        }
        _ => {
            warnings.push(
                crate::model::Warning::new(
                    crate::model::WarningClass::Feature,
                    format!(
                        "{what}: `{}` = `{raw}` is not a wall height in metres (above 0, up to \
                 {MAX_WALL_HEIGHT}); its wall has the template's height",
                        params.fence.height_field
                    ),
                )
                .for_key("fence.height_field"),
            );
            Vec::new()
        }
    }
}

/// The gate of a walled outline or line, or a warning.
fn gate_of(
    attrs: &crate::model::Attrs,
    pts: &[Coord<f64>],
    edges: &StreetEdges,
    params: &Params,
    what: &str,
    warnings: &mut Vec<crate::model::Warning>,
) -> Option<usize> {
    let raw = attr(attrs, &params.fence.gate_field).unwrap_or("");
    gate_edge(raw, pts, edges).unwrap_or_else(|e| {
        warnings.push(crate::model::Warning::new(
            crate::model::WarningClass::Feature,
            format!("{what}: {e}; no gate built"),
        ));
        None
    })
}

/// The fence segments and gate of one walled lot, and any warnings.
pub fn plan_lot_fences(
    lot: &Lot,
    edges: &StreetEdges,
    params: &Params,
    lots_file: &str,
) -> (Vec<PlannedFence>, Vec<crate::model::Warning>) {
    let mut warnings = Vec::new();
    let ring: Vec<Coord<f64>> = crate::geom::ring::open(lot.outline.exterior()).to_vec();
    if ring.len() < 3 {
        return (Vec::new(), warnings);
    }
    let centroid = lot.outline.centroid().map_or(ring[0], |c| c.0);
    let what = format!("{lots_file}: lot {}", lot.id);
    let gate = gate_of(&lot.attrs, &ring, edges, params, &what, &mut warnings);
    let w = Walled {
        id: &lot.id,
        record: lot.record,
        layer: "lots",
        file: lots_file,
        template: template_of(lot, params),
        ground: lot.ground,
        district: lot.district.clone(),
        tile: crate::model::tile::tile_id(centroid, params.tile_size, params.tile_origin),
        attrs: height_attr(&lot.attrs, params, &what, &mut warnings),
    };
    let mut out = segments(&w, &ring, true, gate, params, &mut warnings);
    let lot_edges = LotEdges::new(&lot.outline);
    for f in &mut out {
        f.room = lot_edges.room(f.edge, f.a, f.b, [f.start_mitre, f.end_mitre]);
    }
    (out, warnings)
}

/// The segments of a free-standing fence line: a closed line (first point = last) walls in
/// its inside whichever way it was drawn, an open one has its wall on its left.
pub fn plan_line_fences(
    f: &FenceLine,
    edges: &StreetEdges,
    params: &Params,
    file: &str,
) -> (Vec<PlannedFence>, Vec<crate::model::Warning>) {
    let mut warnings = Vec::new();
    let mut pts = f.line.0.clone();
    let closed = pts.len() >= 4 && {
        let (a, b) = (pts[0], pts[pts.len() - 1]);
        (a.x - b.x).hypot(a.y - b.y) < 1e-3
    };
    if closed {
        pts.pop();
        let area: f64 = (0..pts.len())
            .map(|i| {
                let (p, q) = (pts[i], pts[(i + 1) % pts.len()]);
                p.x * q.y - q.x * p.y
            })
            .sum();
        if area < 0.0 {
            pts.reverse();
        }
    }
    if pts.len() < 2 {
        return (Vec::new(), warnings);
    }
    let Some(b) = crate::geom::bbox::bbox(pts.iter().copied()) else {
        return (Vec::new(), warnings);
    };
    let centre = Coord {
        x: (b[0] + b[2]) / 2.0,
        y: (b[1] + b[3]) / 2.0,
    };
    let what = format!("{file}: fence {}", f.id);
    // Segment numbering for `eN` and `1` follows the line as it is walled.
    let gate = gate_of(&f.attrs, &pts, edges, params, &what, &mut warnings);
    let gate = if closed {
        gate
    } else {
        gate.filter(|g| *g + 1 < pts.len())
    };
    let template = attr(&f.attrs, &params.fence.type_field)
        .map(str::to_string)
        .unwrap_or_else(|| params.fence.default_type.clone());
    let w = Walled {
        id: &f.id,
        record: f.record,
        layer: "fences",
        file,
        template,
        ground: 0.0,
        district: None,
        tile: crate::model::tile::tile_id(centre, params.tile_size, params.tile_origin),
        attrs: height_attr(&f.attrs, params, &what, &mut warnings),
    };
    let out = segments(&w, &pts, closed, gate, params, &mut warnings);
    (out, warnings)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    #[test]
    fn the_gate_attribute_names_an_edge() {
        use geo_types::{LineString, Polygon};
        let ring = vec![c(0.0, 0.0), c(40.0, 0.0), c(40.0, 30.0), c(0.0, 30.0)];
        // The street runs along the top (y = 30..36).
        let block = Polygon::new(
            LineString::from(vec![
                (-50.0, -50.0),
                (90.0, -50.0),
                (90.0, 30.0),
                (-50.0, 30.0),
                (-50.0, -50.0),
            ]),
            vec![],
        );
        let edges = StreetEdges::new(&[block], &[]);
        assert_eq!(gate_edge("1", &ring, &edges), Ok(Some(2)));
        assert_eq!(gate_edge("street", &ring, &edges), Ok(Some(2)));
        assert_eq!(gate_edge("e2", &ring, &edges), Ok(Some(1)));
        assert_eq!(gate_edge("edge 4", &ring, &edges), Ok(Some(3)));
        assert_eq!(gate_edge("0", &ring, &edges), Ok(None));
        assert_eq!(gate_edge("", &ring, &edges), Ok(None));
        let err = gate_edge("e9", &ring, &edges).unwrap_err();
        assert!(err.contains("N from 1 to 4"), "{err}");
    }

    #[test]
    fn mitres_of_right_straight_reflex_and_acute_corners() {
        let right = mitre(c(0.0, 0.0), c(10.0, 0.0), c(10.0, 10.0));
        assert!((right - 1.0).abs() < 1e-12);
        let straight = mitre(c(0.0, 0.0), c(5.0, 0.0), c(10.0, 0.0));
        assert!(straight.abs() < 1e-12);
        let reflex = mitre(c(0.0, 0.0), c(10.0, 0.0), c(10.0, -10.0));
        assert!((reflex + 1.0).abs() < 1e-12);
        // 60 degrees inside: cot(30) = 1.732.
        let acute = mitre(c(0.0, 0.0), c(10.0, 0.0), c(5.0, 8.660254));
        assert!((acute - 3f64.sqrt()).abs() < 1e-5, "{acute}");
    }
}
