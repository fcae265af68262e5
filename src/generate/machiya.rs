//! Machiya (町家) townhouses, section 4.1 of the paper.
//!
//! A machiya is built to the full width of its frontage, side walls against its neighbours,
//! facing the street with no gap (the paper: "建物は間口いっぱいに建てられて"). What the house
//! looks like is its type's template (`templates/machiya/`); this module gives the template
//! its site (the lot in the frontage frame) and its inputs.

use super::clip::{area, dedup, LocalPoly, LocalRing};
use super::instance::{building_facts, instantiate, Local, Site};
use super::mesh::{Frame, Mesh};
use crate::model::PlannedHouse;
use crate::params::MachiyaParams;
use crate::templates::expr::Lot;
use crate::templates::template::{SiteInputs, N_INPUTS};
use crate::templates::Template;

/// The lot of `m` in its frontage frame.
pub fn site_of(m: &PlannedHouse) -> Result<Site, String> {
    let f = &m.frontage;
    let local = Local {
        a: f.a,
        u: f.u_axis(),
        v: f.v_axis(),
    };
    let to_ring = |ls: &geo_types::LineString<f64>| -> LocalRing {
        dedup(
            crate::geom::ring::open(ls)
                .iter()
                .map(|c| local.local(*c))
                .collect(),
        )
    };
    // Courtyards (holes) stay open: the house is built around them.
    let lot = LocalPoly {
        exterior: to_ring(m.outline.exterior()),
        holes: m
            .outline
            .interiors()
            .iter()
            .map(|h| {
                let mut r = to_ring(h);
                if area(&r) > 0.0 {
                    r.reverse();
                }
                r
            })
            .filter(|r| r.len() >= 3)
            .collect(),
    };
    if lot.exterior.len() < 3 || area(&lot.exterior) <= 0.0 {
        return Err("the outline is degenerate in the frontage frame".into());
    }
    Ok(Site {
        lot,
        local,
        ground: m.ground,
        slope: 0.0,
    })
}

/// What every template is told about a feature (see `template::INPUTS`).
pub fn inputs(
    site: &Site,
    m: &PlannedHouse,
    params: &MachiyaParams,
    random: f64,
) -> [f64; N_INPUTS] {
    use geo::Centroid;
    let f = &m.frontage;
    SiteInputs {
        width: f.width(),
        lot_depth: site.depth(),
        a: f.a,
        b: f.b,
        centroid: m.outline.centroid().map_or(f.a, |p| p.0),
        ground: m.ground,
        id: &m.id,
        district: m.district.as_deref(),
        building_height: m.footprint_height().unwrap_or(0.0),
        machiya_depth: params.depth,
        min_depth: params.min_depth,
        random,
        ..SiteInputs::default()
    }
    .slots()
}

/// Builds the mesh of one machiya, or says why it cannot be built.
pub fn build(
    m: &PlannedHouse,
    t: &Template,
    overrides: &[(usize, f64)],
    params: &MachiyaParams,
    random: f64,
    frame: Frame,
) -> Result<Mesh, String> {
    let site = site_of(m)?;
    let slots = t.evaluate(
        &inputs(&site, m, params, random),
        overrides,
        &m.attrs,
        &site as &dyn Lot,
    )?;
    let mut mesh = Mesh::object(m.object_name(), m.object_kind(), m.owner());
    instantiate(t, &slots, &site, frame, &mut mesh)?;
    mesh.building = Some(building_facts(t, &slots, &site, &m.attrs, m.ground));
    if mesh.faces.is_empty() {
        return Err(format!("template {} gives no faces on this lot", t.name));
    }
    Ok(mesh.finish())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::clip::is_convex;
    use crate::generate::mesh::open_edges;
    use crate::model::Frontage;
    use crate::params::Params;
    use crate::templates::Catalog;
    use geo_types::Coord;

    fn build_plain(m: &PlannedHouse, t: &Template, params: &MachiyaParams) -> Result<Mesh, String> {
        build(m, t, &[], params, 0.5, Frame { origin: [0.0, 0.0] })
    }

    fn declared_height(m: &PlannedHouse, t: &Template, params: &MachiyaParams) -> f64 {
        let site = site_of(m).unwrap();
        let slots = t
            .evaluate(&inputs(&site, m, params, 0.5), &[], &[], &site)
            .unwrap();
        t.height.as_ref().unwrap().0.eval(&slots, &site)
    }

    fn machiya_types(cat: &Catalog) -> Vec<&Template> {
        cat.names_of(crate::templates::Kind::Machiya)
            .into_iter()
            .map(|n| cat.get(n).unwrap())
            .collect()
    }
    use geo_types::{LineString, Polygon};
    use proptest::prelude::*;

    fn planned(ring: &[[f64; 2]]) -> PlannedHouse {
        let mut pts: Vec<Coord<f64>> = ring.iter().map(|p| Coord { x: p[0], y: p[1] }).collect();
        pts.push(pts[0]);
        PlannedHouse {
            id: "1".into(),
            record: 0,
            outline: Polygon::new(LineString(pts), vec![]),
            frontage: Frontage {
                a: Coord {
                    x: ring[0][0],
                    y: ring[0][1],
                },
                b: Coord {
                    x: ring[1][0],
                    y: ring[1][1],
                },
                fallback: false,
            },
            mtype: String::new(),
            type_given: false,
            district: None,
            tile: "0_0".into(),
            ground: 0.0,
            source: crate::model::HouseSource::Lot,
            attrs: Vec::new(),
            kura: Default::default(),
        }
    }

    /// Ground vertices of a mesh, back in map metres.
    fn ground(mesh: &Mesh) -> Vec<[f64; 2]> {
        mesh.positions
            .iter()
            .filter(|p| p[1] == 0)
            .map(|p| [p[0] as f64 / 1000.0, -(p[2] as f64) / 1000.0])
            .collect()
    }

    fn inside_or_on(ring: &[[f64; 2]], p: [f64; 2], tol: f64) -> bool {
        use geo::{Contains, Distance, Euclidean};
        let poly = planned(ring).outline;
        let pt = geo_types::Point::new(p[0], p[1]);
        poly.contains(&pt) || Euclidean.distance(&pt, poly.exterior()) <= tol
    }

    #[test]
    fn every_shipped_type_is_a_closed_shell_on_a_town_lot() {
        let cat = Catalog::load(None).unwrap();
        let params = Params::default().machiya;
        let lot = [[0.0, 0.0], [5.4, 0.0], [5.5, 30.0], [0.1, 30.0]];
        let types = machiya_types(&cat);
        assert_eq!(types.len(), 8);
        for t in types {
            let m = planned(&lot);
            let mesh = build_plain(&m, t, &params).unwrap_or_else(|e| panic!("{}: {e}", t.name));
            assert!(open_edges(&mesh).is_empty(), "{}: open edges", t.name);
            let top = mesh.positions.iter().map(|p| p[1]).max().unwrap();
            let declared = declared_height(&m, t, &params);
            assert!(
                (top as f64 / 1000.0 - declared).abs() < 0.002,
                "{}: top {top} mm, declared {declared} m",
                t.name
            );
            for p in ground(&mesh) {
                assert!(inside_or_on(&lot, p, 0.001), "{}: {p:?} outside", t.name);
            }
        }
    }

    #[test]
    fn a_courtyard_stays_open_and_the_house_stays_closed() {
        let cat = Catalog::load(None).unwrap();
        let params = Params::default().machiya;
        let mut m = planned(&[[0.0, 0.0], [10.0, 0.0], [10.0, 30.0], [0.0, 30.0]]);
        // A courtyard (tsuboniwa 坪庭) 4 m x 4 m inside the house's 12 m band.
        let hole = LineString::from(vec![
            (3.0, 4.0),
            (7.0, 4.0),
            (7.0, 8.0),
            (3.0, 8.0),
            (3.0, 4.0),
        ]);
        m.outline = Polygon::new(m.outline.exterior().clone(), vec![hole]);
        let mesh = build_plain(&m, cat.get("hiraya").unwrap(), &params).unwrap();
        assert!(open_edges(&mesh).is_empty(), "closed around the courtyard");
        for p in ground(&mesh) {
            let strictly_inside = p[0] > 3.001 && p[0] < 6.999 && p[1] > 4.001 && p[1] < 7.999;
            assert!(!strictly_inside, "{p:?} is inside the courtyard");
        }
        // Walls stand on the courtyard's four sides, up to the roof.
        let courtyard_corners = mesh
            .positions
            .iter()
            .filter(|p| [3000, 7000].contains(&p[0]) && [-4000, -8000].contains(&p[2]))
            .count();
        assert_eq!(
            courtyard_corners, 8,
            "4 corners at the ground and 4 under the roof"
        );
    }

    #[test]
    fn a_lot_too_shallow_is_refused_with_a_reason() {
        let cat = Catalog::load(None).unwrap();
        let params = Params::default().machiya;
        let lot = [[0.0, 0.0], [5.0, 0.0], [5.0, 1.0], [0.0, 1.0]];
        let err = build_plain(&planned(&lot), cat.get("hiraya").unwrap(), &params).unwrap_err();
        assert!(err.contains("1.00 m deep"), "{err}");
    }

    proptest! {
        #![proptest_config(ProptestConfig { rng_seed: proptest::test_runner::RngSeed::Fixed(2008), ..ProptestConfig::with_cases(256) })]

        /// Any strip lot, any type: the house is closed, stands inside its lot, and only
        /// the pent roof reaches over the street.
        #[test]
        fn houses_are_closed_and_stay_in_their_lots(
            width in 2.7f64..12.0,
            d1 in 3.0f64..60.0,
            d2 in 3.0f64..60.0,
            s1 in -0.3f64..0.3,
            s2 in -0.3f64..0.3,
            type_index in 0usize..8,
            ox in -50_000.0f64..50_000.0,
        ) {
            let cat = Catalog::load(None).unwrap();
            let types = machiya_types(&cat);
            let t = types[type_index % types.len()];
            let params = Params::default().machiya;
            let lot = [[ox, 0.0], [ox + width, 0.0], [ox + width + s1 * d1, d1], [ox + s2 * d2, d2]];
            let local: Vec<[f64; 2]> = lot.iter().map(|p| [p[0] - ox, p[1]]).collect();
            prop_assume!(is_convex(&local));
            let hisashi_depth = t.defaults[t.slot("hisashi_depth").unwrap() - N_INPUTS];
            match build_plain(&planned(&lot), t, &params) {
                Ok(mesh) => {
                    prop_assert!(open_edges(&mesh).is_empty(), "open edges on {:?}", lot);
                    for p in ground(&mesh) {
                        prop_assert!(inside_or_on(&lot, p, 0.002), "{:?} outside {:?}", p, lot);
                    }
                    for p in &mesh.positions {
                        let q = [p[0] as f64 / 1000.0, -(p[2] as f64) / 1000.0];
                        let over_street = !inside_or_on(&lot, q, 0.002);
                        prop_assert!(!over_street || (q[1] >= -hisashi_depth - 0.002 && p[1] > 2000),
                            "{:?} leaves the lot other than as eaves", q);
                    }
                }
                Err(reason) => prop_assert!(reason.contains("deep"), "{}", reason),
            }
        }
    }
}
