//! The rock-garden designer behind `serve`'s `/api/gardens` (issue 42): one session per
//! visitor designing one garden by the interactive GA of seed 000, on the server.
//!
//! A session starts from a generation of gathered random layouts with the garden as the
//! build placed it (and the design kept for it, when the designs file has one) among them.
//! Each generation shows its [`SHOWN`] best distinct layouts; the visitor picks some and the
//! next generation is bred from the picks (`Population::next_from`: the picks kept, every
//! other layout a child of two picks), or by the GA's own selection when nothing is picked.
//! "Undo" goes back one generation. Every draw comes from `feature_rng(seed,
//! "garden-design", "<garden>/<generation>/<picks>")`: the same picks from the same start
//! give the same answers, whoever asks and whenever.

use std::collections::BTreeMap;

use edo_city::growers::garden::ga::{Candidate, GaParams, Population};
use edo_city::growers::garden::{rules, Layout, Settings};
use edo_city::model::design::{Design, DesignStone, Generation};
use edo_city::model::GardenStat;

/// Layouts shown per generation (the seed's sheets show a handful; 6-9 fit a screen).
pub const SHOWN: usize = 9;
/// Generations a session keeps for "undo" at most.
pub const UNDO_DEPTH: usize = 200;
/// Layouts a session keeps in all (its generations x its population): about 7 MB, so the
/// server's sessions together stay within a bound whatever the visitors ask for. A session
/// of 100 layouts undoes 100 generations, one of 1000 undoes 10.
pub const MAX_KEPT_LAYOUTS: usize = 10_000;
/// Generations a session may breed.
pub const MAX_GENERATIONS: usize = 10_000;
/// The largest population a visitor may ask for.
pub const MAX_POPULATION: usize = 1000;
/// The most stones a layout read from a build's report may have (a garden's groups hold 200
/// at most).
const MAX_STONES: usize = 200;

/// One generation as a session holds it.
struct Step {
    population: Population,
    /// Members shown, by their place in `population`: the best distinct layouts.
    shown: Vec<usize>,
}

/// One visitor designing one garden.
pub struct Session {
    /// The garden's key.
    pub key: String,
    /// The build it belongs to (its place in `serve`'s list).
    pub build: usize,
    /// The design the designs file held for the garden when the session opened (a keep
    /// refuses to write over a different one: someone else kept theirs since).
    pub base: Option<Design>,
    seed: u64,
    settings: Settings,
    params: GaParams,
    /// The generations, the current last; at most [`UNDO_DEPTH`] + 1.
    steps: Vec<Step>,
    /// The number of the current generation (0: the start).
    pub generation: usize,
    history: Vec<Generation>,
}

/// What went wrong with a request, as an HTTP status and a message.
#[derive(Debug)]
pub struct Refusal {
    /// 400, 404, 409 ...
    pub status: u16,
    /// What is wrong and what to do.
    pub message: String,
}

pub fn refuse(status: u16, message: String) -> Refusal {
    Refusal { status, message }
}

impl Session {
    /// A session on a placed garden of a build run with `seed`; a garden whose size the GA
    /// cannot lay stones in (a damaged or hand-edited report) is a 422.
    pub fn open(
        garden: &GardenStat,
        build: usize,
        seed: u64,
        population: usize,
        base: Option<Design>,
    ) -> Result<Session, Refusal> {
        let settings = Settings::sized(garden.size[0], garden.size[1]);
        if let Some(why) = settings.problem() {
            return Err(refuse(
                422,
                format!(
                    "garden `{}` cannot be designed: {why}; build the city again",
                    garden.key
                ),
            ));
        }
        let params = GaParams {
            population,
            gathered: true,
            ..GaParams::default()
        };
        let mut rng = edo_city::rng::feature_rng(seed, "garden-design", &garden.key);
        let mut first = Population::random(&settings, &params, &mut rng);
        // The garden as built, and the kept design, take the places of the last layouts
        // (a layout of more stones than a garden holds is no layout of the GA's).
        let mut start: Vec<Layout> = (garden.layout.len() <= MAX_STONES)
            .then(|| Layout::from_rows(&garden.layout))
            .into_iter()
            .collect();
        if let Some(d) = &base {
            start.push(Layout::from_rows(&d.stone_rows()));
        }
        // Only layouts of the GA's own stones and groups: crossover takes stone i of one
        // parent for stone i of the other.
        let genes = |l: &Layout| l.stones.iter().map(|s| s.group).collect::<Vec<_>>();
        let want = genes(&first.members[0].layout);
        start.retain(|l| genes(l) == want);
        let n = first.members.len();
        for (k, l) in start.into_iter().enumerate().take(n) {
            first.members[n - 1 - k] = Candidate::of(l, &settings);
        }
        let population = sorted(first.members);
        Ok(Session {
            key: garden.key.clone(),
            build,
            base,
            seed,
            settings,
            params,
            steps: vec![step(population)],
            generation: 0,
            history: Vec::new(),
        })
    }

    /// Checks that the visitor answers the generation the session is at.
    pub fn at(&self, generation: usize) -> Result<(), Refusal> {
        if generation == self.generation {
            return Ok(());
        }
        Err(refuse(
            409,
            format!(
                "generation {generation} is not the current one ({}): the page is stale; \
                 reload the designer",
                self.generation
            ),
        ))
    }

    fn current(&self) -> &Step {
        // A session always has its start.
        &self.steps[self.steps.len() - 1]
    }

    /// The next generation, bred from `picks` (distinct places among the shown candidates),
    /// or by the GA itself when `picks` is empty. The picks are kept in the design's history
    /// as sent, so they are checked first: a body of 32,000 picks made one design 86 MB.
    pub fn next(&mut self, picks: &[usize]) -> Result<(), Refusal> {
        let cur = self.current();
        let mut distinct = picks.to_vec();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() != picks.len() {
            return Err(refuse(
                400,
                "a candidate is picked twice: pick each at most once".into(),
            ));
        }
        if let Some(&bad) = picks.iter().find(|&&k| k >= cur.shown.len()) {
            return Err(refuse(
                400,
                format!(
                    "pick {bad} is out of range: generation {} shows candidates 0 to {}",
                    self.generation,
                    cur.shown.len() - 1
                ),
            ));
        }
        if self.generation >= MAX_GENERATIONS {
            return Err(refuse(
                409,
                format!("a session breeds at most {MAX_GENERATIONS} generations: keep a design"),
            ));
        }
        let mut members: Vec<usize> = picks.iter().map(|&k| cur.shown[k]).collect();
        members.sort_unstable();
        members.dedup();
        let g = self.generation + 1;
        let tag = format!("{}/{g}/{members:?}", self.key);
        let mut rng = edo_city::rng::feature_rng(self.seed, "garden-design", &tag);
        let next = if members.is_empty() {
            cur.population.next(&self.settings, &self.params, &mut rng)
        } else {
            cur.population
                .next_from(&members, &self.settings, &self.params, &mut rng)
        };
        let best = next.best().fitness;
        self.steps.push(step(next));
        if self.steps.len() > self.undo_depth() + 1 {
            self.steps.remove(0);
        }
        self.generation = g;
        self.history.push(Generation {
            generation: g,
            picks: picks.to_vec(),
            best,
        });
        Ok(())
    }

    /// The generations this session keeps for "undo": [`UNDO_DEPTH`], fewer for a large
    /// population ([`MAX_KEPT_LAYOUTS`]).
    pub fn undo_depth(&self) -> usize {
        (MAX_KEPT_LAYOUTS / self.params.population.max(1)).clamp(1, UNDO_DEPTH)
    }

    /// Back one generation.
    pub fn undo(&mut self) -> Result<(), Refusal> {
        if self.steps.len() < 2 {
            return Err(refuse(
                409,
                match self.generation {
                    0 => "this is the first generation: nothing to undo".to_string(),
                    _ => format!(
                        "a session of {} layouts undoes at most {} generations",
                        self.params.population,
                        self.undo_depth()
                    ),
                },
            ));
        }
        self.steps.pop();
        self.history.pop();
        self.generation -= 1;
        Ok(())
    }

    /// The shown candidate `k` as a design to keep.
    pub fn design(&self, k: usize) -> Result<Design, Refusal> {
        let cur = self.current();
        let Some(&m) = cur.shown.get(k) else {
            return Err(refuse(
                400,
                format!(
                    "candidate {k} is out of range: generation {} shows 0 to {}",
                    self.generation,
                    cur.shown.len() - 1
                ),
            ));
        };
        let c = &cur.population.members[m];
        Ok(Design {
            lot: self.key.clone(),
            seed: self.seed,
            size: [self.settings.width, self.settings.depth],
            stones: c
                .layout
                .stones
                .iter()
                .map(|s| DesignStone {
                    x: s.x,
                    y: s.y,
                    size: s.size,
                    group: s.group,
                })
                .collect(),
            fitness: c.fitness,
            scores: scores(c),
            history: self.history.clone(),
            kept: k,
        })
    }

    /// The session as the viewer shows it.
    pub fn state(&self, id: &str) -> serde_json::Value {
        let cur = self.current();
        let candidates: Vec<serde_json::Value> = cur
            .shown
            .iter()
            .map(|&m| {
                let c = &cur.population.members[m];
                serde_json::json!({
                    "fitness": c.fitness,
                    "scores": scores(c),
                    "stones": c.layout.stones.iter().map(|s| serde_json::json!({
                        "x": s.x, "y": s.y, "size": s.size, "group": s.group,
                        "role": s.role.name(),
                    })).collect::<Vec<_>>(),
                })
            })
            .collect();
        serde_json::json!({
            "session": id,
            "lot": self.key,
            "build": self.build,
            "seed": self.seed,
            "generation": self.generation,
            "population": cur.population.members.len(),
            "size": [self.settings.width, self.settings.depth],
            "viewpoint": self.settings.viewpoint,
            "candidates": candidates,
            "history": self.history,
            "can_undo": self.steps.len() > 1,
        })
    }
}

/// A generation, best first, with its shown members.
fn step(population: Population) -> Step {
    let mut shown: Vec<usize> = Vec::new();
    for (k, c) in population.members.iter().enumerate() {
        if shown.len() == SHOWN {
            break;
        }
        let same = |&j: &usize| population.members[j].layout == c.layout;
        if !shown.iter().any(same) {
            shown.push(k);
        }
    }
    Step { population, shown }
}

/// Members sorted best first, as `Population` keeps them (a stable sort).
fn sorted(mut members: Vec<Candidate>) -> Population {
    members.sort_by(|a, b| b.fitness.total_cmp(&a.fitness));
    Population { members }
}

/// A candidate's five degrees of violation by rule name.
fn scores(c: &Candidate) -> BTreeMap<String, f64> {
    rules::WEIGHTS
        .iter()
        .zip(c.scores)
        .map(|((rule, _), v)| (rule.to_string(), v))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn garden() -> GardenStat {
        let s = Settings::sized(10.0, 4.0);
        let mut rng = edo_city::rng::feature_rng(9, "test", "");
        GardenStat {
            key: "343".into(),
            lot: "343".into(),
            placed: true,
            size: [10.0, 4.0],
            layout: edo_city::growers::garden::random_layout(&s, &mut rng).to_rows(),
            ..GardenStat::default()
        }
    }

    #[test]
    fn the_same_picks_give_the_same_generations_and_other_picks_others() {
        let mut a = Session::open(&garden(), 0, 5, 30, None).unwrap();
        let mut b = Session::open(&garden(), 0, 5, 30, None).unwrap();
        assert_eq!(a.state("1"), b.state("1"));
        assert!((6..=SHOWN).contains(&a.current().shown.len()));
        a.next(&[0, 3]).unwrap();
        b.next(&[0, 3]).unwrap();
        assert_eq!(a.state("1"), b.state("1"));
        let mut c = Session::open(&garden(), 0, 5, 30, None).unwrap();
        c.next(&[1, 2]).unwrap();
        assert_ne!(a.state("1")["candidates"], c.state("1")["candidates"]);
        // The picks are kept: the first pick of a is among its next generation.
        let before = Session::open(&garden(), 0, 5, 30, None).unwrap();
        let picked = before.design(0).unwrap().stones;
        let now = a.state("1");
        let kept = now["candidates"].as_array().unwrap().iter().any(|c| {
            c["stones"][0]["x"].as_f64() == Some(picked[0].x)
                && c["stones"][0]["y"].as_f64() == Some(picked[0].y)
        });
        assert!(kept, "the pick survives into the next generation");
    }

    #[test]
    fn bad_picks_stale_generations_and_undo_past_the_start_are_refused() {
        let mut s = Session::open(&garden(), 0, 5, 30, None).unwrap();
        assert_eq!(s.next(&[SHOWN + 3]).unwrap_err().status, 400);
        assert_eq!(s.generation, 0, "nothing bred");
        assert_eq!(s.undo().unwrap_err().status, 409);
        s.next(&[]).unwrap();
        assert_eq!(s.at(0).unwrap_err().status, 409);
        assert!(s.at(1).is_ok());
        let one = s.state("1");
        s.next(&[0]).unwrap();
        s.undo().unwrap();
        assert_eq!(s.state("1"), one, "undo gives back the generation before");
        assert_eq!(s.design(99).unwrap_err().status, 400);
        // Undo reaches back as far as the session's bound, no farther.
        let mut big = Session::open(&garden(), 0, 5, MAX_KEPT_LAYOUTS / 3, None).unwrap();
        assert_eq!(big.undo_depth(), 3);
        for _ in 0..5 {
            big.next(&[]).unwrap();
        }
        for _ in 0..3 {
            big.undo().unwrap();
        }
        assert_eq!(big.generation, 2);
        let e = big.undo().unwrap_err();
        assert!(e.message.contains("at most 3"), "{}", e.message);
        let d = s.design(0).unwrap();
        assert_eq!((d.lot.as_str(), d.seed, d.history.len()), ("343", 5, 1));
        assert!(d.problem().is_none() && d.outside(10.0, 4.0).is_none());
    }

    #[test]
    fn the_start_holds_the_garden_as_built() {
        let s = Session::open(&garden(), 0, 5, 30, None).unwrap();
        let built = Layout::from_rows(&garden().layout);
        let has = s
            .current()
            .population
            .members
            .iter()
            .any(|c| c.layout == built);
        assert!(has);
    }
}
