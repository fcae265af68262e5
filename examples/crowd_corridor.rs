//! `make crowd-fd`'s trajectories of our crowd (issue 41): the city's boids (`[crowd]` as the
//! defaults give it, `growers::boids`) in a straight corridor, the same experiment JuPedSim
//! runs in `scripts/crowd_fd.py`: a crowd standing at a given density in the corridor's
//! first 20 m sets out toward its far end; the script measures speed against density in a
//! measurement area as the crowd passes through, for both, and against Weidmann (1993).
//!
//! Writes, per density, `boids_<rho>.txt` (PedPy's text trajectories: `id frame x y`, metres,
//! frame rate in the header) and `start_<rho>.csv` (`id,x,y,speed`: where and how fast each
//! agent starts, so JuPedSim starts from the same places at the same desired speeds); and
//! `walkers_<rho>.txt`, the same start walked by the city's street crowd as `people.motion =
//! "boids"` builds walk it (`analyse::crowds::walk`: errands along a street as wide as the
//! corridor, pushed by the seed's zones), each walker's errand at its start speed.
//!
//! Usage: cargo run --release --example crowd_corridor -- <out dir> [length width seconds]

use std::fmt::Write as _;
use std::path::PathBuf;

use edo_city::analyse::crowds::{network, route, walk};
use edo_city::growers::boids::{Boid, Flock};
use edo_city::model::{Dataset, Street};
use edo_city::params::Params;
use rand::RngExt;

/// The densities of the experiments, persons per square metre (Weidmann's curve runs to 5.4).
const DENSITIES: [f64; 7] = [0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0];
/// The length of corridor the crowd stands in at the start, metres.
const START: f64 = 20.0;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(out) = args.first().map(PathBuf::from) else {
        eprintln!("usage: crowd_corridor <out dir> [length width seconds]");
        std::process::exit(2);
    };
    let num = |i: usize, d: f64| args.get(i).and_then(|a| a.parse().ok()).unwrap_or(d);
    let (length, width, seconds) = (num(1, 60.0), num(2, 4.0), num(3, 25.0));
    std::fs::create_dir_all(&out).expect("the output directory");
    let params = Params::from_toml_str("", "defaults").expect("the defaults are valid");
    let model = params.crowd.model();
    let steps = (seconds / model.dt).round() as usize;
    for rho in DENSITIES {
        let n = (rho * START * width).round() as usize;
        let mut rng = edo_city::rng::feature_rng(params.seed, "corridor", &rho.to_string());
        // A jittered grid over the first START metres: as many columns as the density asks
        // rows of the width, each agent near its cell's centre, so two are at least 0.84 of
        // a cell apart (0.42 m at 4 /m2: JuPedSim's agents of radius 0.2 m must not touch).
        let rows = ((n as f64 * width / START).sqrt().round() as usize).max(1);
        let cols = n.div_ceil(rows);
        let (dx, dy) = (START / cols as f64, width / rows as f64);
        let boids: Vec<Boid> = (0..n)
            .map(|i| {
                let (c, r) = ((i / rows) as f64, (i % rows) as f64);
                Boid {
                    pos: [
                        (c + rng.random_range(0.42..0.58)) * dx,
                        (r + rng.random_range(0.42..0.58)) * dy,
                    ],
                    heading: [1.0, 0.0],
                    speed: rng.random_range(model.min_speed..=model.max_speed),
                }
            })
            .collect();
        let mut start = String::from("id,x,y,speed\n");
        for (i, b) in boids.iter().enumerate() {
            writeln!(start, "{i},{:.3},{:.3},{:.3}", b.pos[0], b.pos[1], b.speed).unwrap();
        }
        let walked = walkers(&boids, length, width, &params, steps);
        let seed = rng.random::<u64>();
        let mut flock = Flock::from_boids(boids, length, width, model, true, seed);
        let mut traj = format!(
            "# edo-city boids, {n} agents, {rho} /m2 in the first {START} m of a {length} x \
             {width} m corridor\n# framerate: {}\n# id frame x y\n",
            1.0 / model.dt
        );
        for frame in 0..=steps {
            if frame > 0 {
                flock.step();
            }
            for (i, b) in flock.boids.iter().enumerate() {
                writeln!(traj, "{i}\t{frame}\t{:.3}\t{:.3}", b.pos[0], b.pos[1]).unwrap();
            }
        }
        std::fs::write(out.join(format!("start_{rho}.csv")), start).expect("write");
        std::fs::write(out.join(format!("boids_{rho}.txt")), traj).expect("write");
        let mut traj = format!(
            "# edo-city street walkers, {n} agents, {rho} /m2 in the first {START} m of a \
             {length} x {width} m corridor\n# framerate: {}\n# id frame x y\n",
            1.0 / model.dt
        );
        for (i, track) in walked.iter().enumerate() {
            for (frame, p) in track.iter().enumerate() {
                writeln!(traj, "{i}\t{frame}\t{:.3}\t{:.3}", p.x, p.y).unwrap();
            }
        }
        std::fs::write(out.join(format!("walkers_{rho}.txt")), traj).expect("write");
        println!("{rho} /m2: {n} agents, {steps} steps of {} s", model.dt);
    }
}

/// The city's walkers from the same start: one street along the corridor's centreline, as
/// wide as the corridor plus `people.edge_margin` each side and far longer (no walker reaches
/// its end), each walker's errand straight on from its start at its start speed (an errand
/// of `speed x period / 2` metres, the period long enough that nobody turns within the run),
/// its lane its offset from the centreline. Positions every `dt` for `steps` steps.
fn walkers(
    start: &[Boid],
    length: f64,
    width: f64,
    params: &Params,
    steps: usize,
) -> Vec<Vec<geo_types::Coord<f64>>> {
    let margin = params.people.edge_margin;
    let data = Dataset {
        streets: vec![Street {
            id: "corridor".into(),
            line: geo_types::LineString::from(vec![
                [0.0, width / 2.0],
                [10.0 * length, width / 2.0],
            ]),
            width: width + 2.0 * margin,
        }],
        ..Dataset::default()
    };
    let net = network::network(&data, margin);
    let period = 20.0 * length;
    let mut rng = edo_city::rng::feature_rng(params.seed, "corridor", "walkers");
    let crowd: Vec<walk::Walker> = start
        .iter()
        .map(|b| walk::Walker {
            route: route::route(
                &net,
                0,
                b.pos[0],
                true,
                [0.0, b.speed * period / 2.0],
                0.0,
                &mut rng,
            ),
            phase: 0.0,
            lane: b.pos[1] - width / 2.0,
        })
        .collect();
    let model = params.crowd.model();
    walk::run(&net, &crowd, &model, model.dt, steps, period, 0.0)
}
