//! Never a panic on user data, with every stage at once: random towns (star-shaped lots of
//! every use, some with a courtyard hole, streets at any angle) and random parameters go
//! through frontage, kura, fences and billboards. Whatever is built is finite and stands in
//! its lot; whatever is not is skipped with a reason; parameters out of range are refused.

mod common;

use common::star;
use edo_city::model::{BillboardKind, Dataset, Lot, LotUse, Plan, Street};
use edo_city::params::Params;
use geo::{orient::Direction, Contains, Distance, Euclidean, Orient};
use geo_types::{Coord, LineString, Point, Polygon};
use proptest::prelude::*;

/// One random lot: its place in a 3 x 2 grid of 60 m cells, its ring around that place, its
/// use, and the size of a square courtyard at its centre (a share of the ring's inner
/// radius; 0 = none).
#[derive(Debug, Clone)]
struct RandomLot {
    ring: Vec<Coord<f64>>,
    lot_use: LotUse,
    courtyard: f64,
}

/// A star of any radii (concave, thin and tiny lots), or a town strip as narrow and deep as
/// Kyoto's, where kura stand, turned any way.
fn ring() -> impl Strategy<Value = Vec<Coord<f64>>> {
    prop_oneof![
        (prop::collection::vec(0.05f64..28.0, 3..12), 0.0f64..6.3)
            .prop_map(|(radii, twist)| star(0.0, 0.0, &radii, twist)),
        (2.0f64..14.0, 10.0f64..55.0, 0.0f64..6.3).prop_map(|(w, d, turn)| {
            let (c, s) = (turn.cos(), turn.sin());
            [(-w, -d), (w, -d), (w, d), (-w, d), (-w, -d)]
                .iter()
                .map(|&(x, y)| Coord {
                    x: (x * c - y * s) / 2.0,
                    y: (x * s + y * c) / 2.0,
                })
                .collect()
        }),
    ]
}

fn random_lot() -> impl Strategy<Value = RandomLot> {
    (
        ring(),
        prop::sample::select(vec![
            LotUse::Machiya,
            LotUse::Machiya,
            LotUse::Buke,
            LotUse::Kuge,
            LotUse::Jisha,
            LotUse::Other("hatake".into()),
        ]),
        prop_oneof![Just(0.0), 0.2f64..0.45],
    )
        .prop_map(|(ring, lot_use, courtyard)| RandomLot {
            ring,
            lot_use,
            courtyard,
        })
}

/// A lot's polygon: its ring in its cell, with its courtyard when the ring holds it whole.
fn outline(k: usize, lot: &RandomLot) -> Polygon<f64> {
    let (cx, cy) = (60.0 * (k % 3) as f64, 60.0 * (k / 3) as f64);
    let ring: Vec<Coord<f64>> = lot
        .ring
        .iter()
        .map(|p| Coord {
            x: p.x + cx,
            y: p.y + cy,
        })
        .collect();
    // The distance from the centre to the nearest edge bounds a courtyard that fits.
    let centre = Point::new(cx, cy);
    let inner = Euclidean.distance(&centre, &LineString(ring.clone())) * lot.courtyard;
    let holes = if inner > 0.3 {
        let h = inner / std::f64::consts::SQRT_2;
        vec![LineString::from(vec![
            (cx - h, cy - h),
            (cx - h, cy + h),
            (cx + h, cy + h),
            (cx + h, cy - h),
            (cx - h, cy - h),
        ])]
    } else {
        vec![]
    };
    Polygon::new(LineString(ring), holes).orient(Direction::Default)
}

/// The parameters under test, with values from the sensible to the absurd.
#[derive(Debug, Clone)]
struct RandomParams {
    seed: u64,
    tile_size: f64,
    people: f64,
    trees: f64,
    trees_machiya: f64,
    kura: bool,
    collision: bool,
    depth: f64,
    gate_width: f64,
}

fn random_params() -> impl Strategy<Value = RandomParams> {
    (
        0..i64::MAX as u64, // TOML integers are i64
        prop_oneof![4 => Just(250.0), 4 => 5.0f64..400.0, 1 => -10.0f64..0.0],
        prop_oneof![4 => Just(0.0), 4 => 0.0f64..80.0, 1 => -5.0f64..0.0],
        prop_oneof![Just(0.0), 0.0f64..400.0],
        0.0f64..200.0,
        prop::bool::weighted(0.8),
        any::<bool>(),
        prop_oneof![4 => Just(12.0), 4 => 0.5f64..60.0, 1 => -1.0f64..0.0],
        prop_oneof![4 => Just(3.0), 4 => 0.2f64..40.0, 1 => -1.0f64..0.0],
    )
        .prop_map(
            |(seed, tile_size, people, trees, trees_machiya, kura, collision, depth, gate)| {
                RandomParams {
                    seed,
                    tile_size,
                    people,
                    trees,
                    trees_machiya,
                    kura,
                    collision,
                    depth,
                    gate_width: gate,
                }
            },
        )
}

impl RandomParams {
    fn toml(&self) -> String {
        format!(
            "seed = {}\ntile_size = {}\n\
             [people]\nper_100m = {}\n\
             [trees]\nper_ha = {}\nper_ha_machiya = {}\n\
             [kura]\nenabled = {}\ncollision = {}\n\
             [machiya]\ndepth = {}\n\
             [fence]\ngate_width = {}\n",
            self.seed,
            self.tile_size,
            self.people,
            self.trees,
            self.trees_machiya,
            self.kura,
            self.collision,
            self.depth,
            self.gate_width
        )
    }

    /// The parameters out of their ranges.
    fn out_of_range(&self) -> Vec<&'static str> {
        [
            ("tile_size", self.tile_size <= 0.0),
            ("people.per_100m", self.people < 0.0),
            ("machiya.depth", self.depth <= 0.0),
            ("fence.gate_width", self.gate_width <= 0.0),
        ]
        .into_iter()
        .filter(|(_, bad)| *bad)
        .map(|(key, _)| key)
        .collect()
    }
}

/// How far `q` is from `lot` (0 inside it; a courtyard is outside).
fn outside(lot: &Polygon<f64>, q: Coord<f64>) -> f64 {
    let p = Point::from(q);
    if lot.contains(&p) {
        0.0
    } else {
        Euclidean.distance(&p, lot)
    }
}

/// A vertex of the output frame (millimetres, y up, z south) as map metres and height.
fn map(p: [i64; 3], origin: [f64; 2]) -> (Coord<f64>, f64) {
    let c = Coord {
        x: p[0] as f64 / 1000.0 + origin[0],
        y: -(p[2] as f64) / 1000.0 + origin[1],
    };
    (c, p[1] as f64 / 1000.0)
}

/// The lot a mesh belongs to, by its object name (`machiya_3`, `kura_3`, `fence_3`,
/// `gate_3_2`), or None for the people and trees of a tile.
fn owner(name: &str) -> Option<usize> {
    let rest = ["machiya_", "kura_", "fence_", "gate_", "garden_", "stone_"]
        .iter()
        .find_map(|p| name.strip_prefix(p))?;
    rest.split('_').next()?.parse().ok()
}

fn check_billboards(plan: &Plan, data: &Dataset) -> Result<(), TestCaseError> {
    for b in plan.billboards.values().flatten() {
        prop_assert!(b.at.x.is_finite() && b.at.y.is_finite() && b.facing.is_finite());
        prop_assert!(b.height > 0.0 && b.height < 40.0, "{b:?}");
        match b.kind {
            // A person stands within the street's width of its centreline.
            BillboardKind::Person => {
                let near = data.streets.iter().any(|s| {
                    Euclidean.distance(&Point::from(b.at), &s.line) <= s.width / 2.0 + 1e-6
                });
                prop_assert!(near, "person {} at {:?} is off every street", b.id, b.at);
            }
            // A tree grows in a lot.
            BillboardKind::Tree => {
                let inside = data.lots.iter().any(|l| outside(&l.outline, b.at) < 1e-6);
                prop_assert!(inside, "tree {} at {:?} is in no lot", b.id, b.at);
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { rng_seed: proptest::test_runner::RngSeed::Fixed(2008), ..ProptestConfig::with_cases(200) })]

    #[test]
    fn any_town_builds_inside_its_lots_or_says_why(
        lots in prop::collection::vec(random_lot(), 1..6),
        streets in prop::collection::vec((-30.0f64..150.0, -30.0f64..90.0, 0.0f64..3.2, 0.5f64..25.0), 1..4),
        p in random_params(),
    ) {
        let params = match Params::from_toml_str(&p.toml(), "random.toml") {
            Ok(params) => {
                prop_assert!(p.out_of_range().is_empty(), "{:?} was accepted", p.out_of_range());
                params
            }
            Err(e) => {
                let keys = p.out_of_range();
                prop_assert!(keys.iter().any(|k| e.to_string().contains(k)), "{e} ({keys:?})");
                return Ok(());
            }
        };
        let outlines: Vec<Polygon<f64>> = lots.iter().enumerate().map(|(k, l)| outline(k, l)).collect();
        let data = Dataset {
            lots: lots
                .iter()
                .zip(&outlines)
                .enumerate()
                .map(|(k, (l, o))| Lot {
                    id: (k + 1).to_string(),
                    record: k,
                    outline: o.clone(),
                    lot_use: l.lot_use.clone(),
                    mtype: None,
                    district: None,
                    tile: None,
                    attrs: Default::default(),
                    ground: 0.0,
                })
                .collect(),
            streets: streets
                .iter()
                .enumerate()
                .map(|(k, &(x, y, angle, width))| {
                    let (dx, dy) = (200.0 * angle.cos(), 200.0 * angle.sin());
                    Street {
                        id: format!("s{k}"),
                        line: LineString::from(vec![(x - dx, y - dy), (x + dx, y + dy)]),
                        width,
                    }
                })
                .collect(),
            ..Default::default()
        };
        let catalog = edo_city::templates::Catalog::load(None).unwrap();
        let plan = edo_city::analyse::analyse(&data, &params, &catalog, "lots.shp", &|_| {});
        check_billboards(&plan, &data)?;
        let files = edo_city::generate::LayerFiles::default();
        let variants = edo_city::generate::variant::Variants::of(&params);
        let mut built = std::collections::BTreeSet::new();
        let mut skipped: std::collections::BTreeSet<String> =
            plan.skipped.iter().map(|s| s.id.clone()).collect();
        for id in &plan.tiles {
            let tile = edo_city::generate::TilePlan::of(&plan, id);
            let t = edo_city::generate::generate_tile(&tile, &catalog, &params, &variants, plan.origin, &files);
            for s in &t.stats.skipped {
                prop_assert!(!s.reason.is_empty() && !s.id.is_empty());
                skipped.insert(s.id.clone());
            }
            for mesh in &t.meshes {
                for f in &mesh.faces {
                    prop_assert!(f.corners.len() >= 3);
                    prop_assert!(f.corners.iter().all(|&(v, t)| (v as usize) < mesh.positions.len() && (t as usize) < mesh.uvs.len()));
                }
                let Some(k) = owner(&mesh.name) else {
                    // People and trees: near the town, within their height of the ground.
                    for &pos in &mesh.positions {
                        let (q, h) = map(pos, plan.origin);
                        prop_assert!(q.x.abs() < 1e4 && q.y.abs() < 1e4 && (0.0..40.0).contains(&h));
                    }
                    continue;
                };
                if mesh.name.starts_with("machiya_") {
                    built.insert(k);
                }
                let lot = &outlines[k - 1];
                for &pos in &mesh.positions {
                    let (q, h) = map(pos, plan.origin);
                    // A garden's stones are sunk a tenth of their height into the ground.
                    let low = if mesh.name.starts_with("stone_") { -1.0 } else { 0.0 };
                    prop_assert!((low..60.0).contains(&h), "{} vertex at {h} m", mesh.name);
                    let d = outside(lot, q);
                    // On the ground everything stands in its lot; a kura wholly; above, a
                    // machiya's pent roof reaches over the street and a wall's coping
                    // over its foot, 0.25 m and at a corner as far as its mitre limit of 2
                    // lets it (0.25 x sqrt 5).
                    let reach = if h <= 0.001 || mesh.name.starts_with("kura_") {
                        0.01
                    } else if mesh.name.starts_with("machiya_") {
                        0.78
                    } else {
                        0.25 * 5f64.sqrt() + 0.01
                    };
                    prop_assert!(d <= reach, "{} vertex {:?} at {h} m is {d} m outside", mesh.name, q);
                }
            }
        }
        // Every town lot is built or skipped with its reason, never lost in silence.
        for (k, l) in lots.iter().enumerate() {
            if l.lot_use == LotUse::Machiya {
                let id = k + 1;
                prop_assert!(
                    built.contains(&id) || skipped.contains(&id.to_string()),
                    "town lot {id} is neither built nor skipped"
                );
            }
        }
    }
}
