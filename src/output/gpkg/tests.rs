//! The container: tables as the standard names them, the same bytes for the same layers,
//! no temporary left behind.

use super::*;
use geo_types::{point, polygon, Geometry};

fn srs() -> Srs {
    Srs::of_build("", Some(WKT), "+proj=tmerc", false)
}

const WKT: &str = "PROJCS[\"JGD2011 / Japan Plane Rectangular CS VI\",GEOGCS[\"JGD2011\"],\
                   UNIT[\"metre\",1],AUTHORITY[\"EPSG\",\"6674\"]]";

fn small(path: &Path) {
    let mut g = GeoPackage::create(path, srs()).unwrap();
    let mut w = g
        .layer(
            "lots",
            Some(GeomKind::Polygon),
            &[text("id"), int("record"), real("area")],
            "lots",
            Some(styles::single(
                styles::Shape::Fill,
                styles::Look::of([1, 2, 3]),
            )),
        )
        .unwrap();
    let p: Geometry<f64> = polygon![(x: 0.0, y: 0.0), (x: 10.0, y: 0.0), (x: 10.0, y: 5.0)].into();
    w.add(
        Some(&p),
        &[
            Value::Text("a".into()),
            Value::Integer(0),
            Value::Real(25.0),
        ],
    )
    .unwrap();
    w.add(
        None,
        &[Value::Text("b".into()), Value::Integer(1), Value::Null],
    )
    .unwrap();
    w.end().unwrap();
    let mut w = g
        .layer("trees", Some(GeomKind::Point), &[text("id")], "trees", None)
        .unwrap();
    w.add(
        Some(&point!(x: 3.0, y: 4.0).into()),
        &[Value::Text("t".into())],
    )
    .unwrap();
    w.end().unwrap();
    g.finish().unwrap();
}

#[test]
fn a_package_has_the_standard_tables_its_srs_and_an_index() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plan.gpkg");
    small(&path);
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["plan.gpkg"], "no temporary is left");
    let c = Connection::open(&path).unwrap();
    let app: i64 = c
        .query_row("PRAGMA application_id", [], |r| r.get(0))
        .unwrap();
    assert_eq!(app, 0x4750_4B47, "'GPKG'");
    let (org, code): (String, i64) = c
        .query_row(
            "SELECT organization, organization_coordsys_id FROM gpkg_spatial_ref_sys \
             WHERE srs_id = 6674",
            [],
            |r| Ok((r.get(0)?, r.get(1)?)),
        )
        .unwrap();
    assert_eq!((org.as_str(), code), ("EPSG", 6674));
    let extent: (f64, f64, f64, f64) = c
        .query_row(
            "SELECT min_x, max_x, min_y, max_y FROM gpkg_contents WHERE table_name = 'lots'",
            [],
            |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?, r.get(3)?)),
        )
        .unwrap();
    assert_eq!(extent, (0.0, 10.0, 0.0, 5.0));
    // The spatial index finds the polygon by its box, and holds nothing for the feature
    // without a geometry.
    let hits: i64 = c
        .query_row(
            "SELECT count(*) FROM rtree_lots_geom WHERE maxx >= 9 AND minx <= 11",
            [],
            |r| r.get(0),
        )
        .unwrap();
    assert_eq!(hits, 1);
    let styled: i64 = c
        .query_row(
            "SELECT count(*) FROM layer_styles WHERE f_table_name = 'lots' AND useAsDefault",
            [],
            |r| r.get(0),
        )
        .unwrap();
    assert_eq!(styled, 1);
    let triggers: i64 = c
        .query_row(
            "SELECT count(*) FROM sqlite_master WHERE type = 'trigger'",
            [],
            |r| r.get(0),
        )
        .unwrap();
    assert_eq!(triggers, 12, "six for each of the two spatial layers");
}

#[test]
fn the_same_layers_give_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.gpkg"), dir.path().join("b.gpkg"));
    small(&a);
    small(&b);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn a_package_given_up_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plan.gpkg");
    {
        let mut g = GeoPackage::create(&path, srs()).unwrap();
        let w = g
            .layer("lots", Some(GeomKind::Polygon), &[], "", None)
            .unwrap();
        drop(w);
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn the_srs_comes_from_the_parameters_or_the_prj() {
    let s = Srs::of_build("EPSG:6675", Some(WKT), "+proj=tmerc", true);
    assert_eq!((s.id, s.organization.as_str()), (6675, "EPSG"));
    let s = srs();
    assert_eq!((s.id, s.definition.as_str()), (6674, WKT));
    assert_eq!(s.name, "JGD2011 / Japan Plane Rectangular CS VI");
    // An ESRI .prj names no authority: its own SRS, the WKT kept for GDAL to read.
    let esri = "PROJCS[\"x\",GEOGCS[\"y\"],UNIT[\"metre\",1]]";
    let s = Srs::of_build("", Some(esri), "+proj=tmerc", false);
    assert_eq!((s.id, s.organization.as_str()), (100_000, "NONE"));
    assert_eq!(s.definition, esri);
    // Reprojected from degrees into the UTM zone the build chose: its EPSG code.
    let utm = "+proj=utm +zone=53 +datum=WGS84 +units=m +no_defs";
    let s = Srs::of_build("", Some(esri), utm, true);
    assert_eq!((s.id, s.organization.as_str()), (32653, "EPSG"));
    assert_eq!(s.description, utm);
    let s = Srs::of_build("", None, &utm.replace("+zone=53", "+zone=19 +south"), true);
    assert_eq!(s.id, 32719);
    // Any other proj string: its own SRS, the definition left undefined.
    let s = Srs::of_build("", Some(esri), "+proj=tmerc +lat_0=36", true);
    assert_eq!((s.id, s.definition.as_str()), (100_000, "undefined"));
}
