//! `make bench`'s grower figures: space colonization at 2,000 and 20,000 attraction points,
//! and each shipped species' skeleton and LOD0-2 meshes, in milliseconds (best of five).

use std::time::Instant;

use edo_city::generate::mesh::{Frame, Mesh};
use edo_city::generate::tree::{mesh_tree, Lod, Look, Placement};
use edo_city::growers::colonization::{self, Attach, Envelope, Group, Params};
use rand::SeedableRng;

fn best_ms(mut f: impl FnMut()) -> f64 {
    (0..5)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1000.0
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    for points in [2_000usize, 20_000] {
        let groups = [Group {
            name: "crown".into(),
            envelope: Envelope::Ellipsoid {
                center: [0.0, 0.0, 8.0],
                radii: [6.0, 6.0, 5.0],
            },
            points,
            attach: Attach::Base,
            weight: None,
        }];
        let p = Params::with_step(0.25);
        let mut nodes = 0;
        let ms = best_ms(|| {
            let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
            let (sk, _) = colonization::grow(&p, &groups, &mut rng).unwrap();
            nodes = sk.nodes.len();
        });
        println!("colonization {points:>6} points: {ms:8.1} ms ({nodes} nodes)");
    }
    for (w, d) in [(25.0, 25.0), (25.0, 10.0)] {
        let s = edo_city::growers::garden::Settings::sized(w, d);
        let p = edo_city::growers::garden::ga::GaParams::default();
        let ms = best_ms(|| {
            let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
            edo_city::growers::garden::ga::run(&s, &p, 20, &mut rng);
        });
        println!(
            "garden GA {w} x {d}: {:.0} generations a second at population 100",
            20.0 / (ms / 1000.0)
        );
    }
    let catalog = edo_city::templates::Catalog::load(None).unwrap();
    for s in catalog.species.values() {
        let h = s.nominal_height();
        let grow = best_ms(|| {
            let mut rng = edo_city::rng::feature_rng(1, "tree", &s.name);
            s.grow_in_city(h, &mut rng).unwrap();
        });
        let mut rng = edo_city::rng::feature_rng(1, "tree", &s.name);
        let sk = s.grow_in_city(h, &mut rng).unwrap().skeleton;
        let look = Look::of(s, h, "summer");
        let place = Placement {
            at: geo_types::Coord { x: 0.0, y: 0.0 },
            ground: 0.0,
            rotation: 0.0,
        };
        let lods: Vec<f64> = [Lod::Full, Lod::Reduced, Lod::Billboard]
            .iter()
            .map(|&lod| {
                best_ms(|| {
                    let mut m = Mesh::new(String::new());
                    mesh_tree(
                        &sk,
                        &s.mesh,
                        look,
                        lod,
                        place,
                        Frame { origin: [0.0, 0.0] },
                        &mut m,
                    );
                })
            })
            .collect();
        println!(
            "{:<15} {:<12} skeleton {:7.2} ms  LOD0 {:6.2} ms  LOD1 {:6.2} ms  LOD2 {:5.3} ms",
            s.name, s.method, grow, lods[0], lods[1], lods[2]
        );
    }
}
