//! The GA of seed 000: a population of layouts, the seed's fitness, uniform crossover with a
//! random mask at stone level or at group level (probability 0.8), mutation (0.01 per gene,
//! a move to the neighbourhood), and selection by tournament with elitism (the best layout
//! is always kept, so the best fitness never decreases) or by the user's picks.

use rand::RngExt;
use rand_pcg::Pcg64;

use super::{random_layout, repair, rules, Layout, Settings};

/// The GA's parameters (the seed's: 100, 0.8, 0.01).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaParams {
    /// Layouts per generation.
    pub population: usize,
    /// Probability that two parents are crossed (else the first is copied).
    pub crossover: f64,
    /// Probability per gene (x, y, size of a stone) of a mutation.
    pub mutation: f64,
    /// Layouts drawn per tournament.
    pub tournament: usize,
    /// The best layouts carried over unchanged.
    pub elite: usize,
    /// Start from gathered groups ([`super::clustered_layout`]) instead of the seed's
    /// uniform scatter: for short runs.
    pub gathered: bool,
}

impl Default for GaParams {
    fn default() -> GaParams {
        GaParams {
            population: 100,
            crossover: 0.8,
            mutation: 0.01,
            tournament: 3,
            elite: 2,
            gathered: false,
        }
    }
}

/// A scored layout.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// The stones.
    pub layout: Layout,
    /// The five degrees of violation.
    pub scores: [f64; 5],
    /// 1 / sum(weight x degree).
    pub fitness: f64,
}

impl Candidate {
    /// Scores `layout`.
    pub fn of(layout: Layout, s: &Settings) -> Candidate {
        let scores = rules::scores(&layout, s);
        Candidate {
            fitness: rules::fitness(&scores),
            scores,
            layout,
        }
    }
}

/// A generation, best first.
#[derive(Debug, Clone)]
pub struct Population {
    /// The layouts, fittest first (ties by their order of making).
    pub members: Vec<Candidate>,
}

impl Population {
    /// A random first generation.
    pub fn random(s: &Settings, p: &GaParams, rng: &mut Pcg64) -> Population {
        let members = (0..p.population.max(1))
            .map(|_| {
                let l = if p.gathered {
                    super::clustered_layout(s, rng)
                } else {
                    random_layout(s, rng)
                };
                Candidate::of(l, s)
            })
            .collect();
        Population::sorted(members)
    }

    fn sorted(mut members: Vec<Candidate>) -> Population {
        // A stable sort: equal fitness keeps the order the layouts were made in.
        members.sort_by(|a, b| b.fitness.total_cmp(&a.fitness));
        Population { members }
    }

    /// The best layout.
    pub fn best(&self) -> &Candidate {
        &self.members[0]
    }

    /// The next generation bred by the GA's own selection.
    pub fn next(&self, s: &Settings, p: &GaParams, rng: &mut Pcg64) -> Population {
        let pick = |rng: &mut Pcg64| -> usize {
            (0..p.tournament.max(1))
                .map(|_| rng.random_range(0..self.members.len()))
                .min()
                .unwrap_or(0)
        };
        let mut out: Vec<Candidate> = self.members[..p.elite.min(self.members.len())].to_vec();
        while out.len() < p.population.max(1) {
            let (a, b) = (pick(rng), pick(rng));
            out.push(self.child(a, b, s, p, rng));
        }
        Population::sorted(out)
    }

    /// The next generation bred from the user's picks (indices into `members`): the picks
    /// are kept, every other layout is a child of two picks.
    pub fn next_from(
        &self,
        picks: &[usize],
        s: &Settings,
        p: &GaParams,
        rng: &mut Pcg64,
    ) -> Population {
        let picks: Vec<usize> = picks
            .iter()
            .copied()
            .filter(|&k| k < self.members.len())
            .collect();
        if picks.is_empty() {
            return self.next(s, p, rng);
        }
        let mut out: Vec<Candidate> = picks.iter().map(|&k| self.members[k].clone()).collect();
        while out.len() < p.population.max(1) {
            let a = picks[rng.random_range(0..picks.len())];
            let b = picks[rng.random_range(0..picks.len())];
            out.push(self.child(a, b, s, p, rng));
        }
        Population::sorted(out)
    }

    fn child(&self, a: usize, b: usize, s: &Settings, p: &GaParams, rng: &mut Pcg64) -> Candidate {
        let (pa, pb) = (&self.members[a].layout, &self.members[b].layout);
        let mut c = pa.clone();
        if rng.random::<f64>() < p.crossover {
            if rng.random_bool(0.5) {
                // Stone level: each stone from either parent.
                for (i, st) in c.stones.iter_mut().enumerate() {
                    if rng.random_bool(0.5) {
                        *st = pb.stones[i];
                    }
                }
            } else {
                // Group level: each group whole from either parent.
                let groups = pa.groups().len();
                let mask: Vec<bool> = (0..groups).map(|_| rng.random_bool(0.5)).collect();
                for (i, st) in c.stones.iter_mut().enumerate() {
                    if mask[st.group] {
                        *st = pb.stones[i];
                    }
                }
            }
        }
        let step = 0.05 * s.width.max(s.depth);
        for st in &mut c.stones {
            if rng.random::<f64>() < p.mutation {
                st.x += (rng.random::<f64>() * 2.0 - 1.0) * step;
            }
            if rng.random::<f64>() < p.mutation {
                st.y += (rng.random::<f64>() * 2.0 - 1.0) * step;
            }
            if rng.random::<f64>() < p.mutation {
                st.size *= 0.8 + 0.4 * rng.random::<f64>();
            }
        }
        repair(&mut c, s);
        // A child that came out as one of its parents (no crossover and no mutation, or two
        // picks of the same layout) has that parent's scores: scoring is a pure function of
        // the layout, and the distance field behind it is most of a garden's time.
        for parent in [&self.members[a], &self.members[b]] {
            if same_bits(&c, &parent.layout) {
                return Candidate {
                    layout: c,
                    scores: parent.scores,
                    fitness: parent.fitness,
                };
            }
        }
        Candidate::of(c, s)
    }
}

/// Whether two layouts are the same to the bit (`==` on floats would take -0 for 0).
fn same_bits(x: &Layout, y: &Layout) -> bool {
    x.stones.len() == y.stones.len()
        && x.stones.iter().zip(&y.stones).all(|(p, q)| {
            p.x.to_bits() == q.x.to_bits()
                && p.y.to_bits() == q.y.to_bits()
                && p.size.to_bits() == q.size.to_bits()
                && p.group == q.group
                && p.role == q.role
        })
}

/// Runs `generations` generations unattended; returns the last population and the best
/// fitness of each generation (the first generation included).
pub fn run(
    s: &Settings,
    p: &GaParams,
    generations: usize,
    rng: &mut Pcg64,
) -> (Population, Vec<f64>) {
    let mut pop = Population::random(s, p, rng);
    let mut history = vec![pop.best().fitness];
    for _ in 0..generations {
        pop = pop.next(s, p, rng);
        history.push(pop.best().fitness);
    }
    (pop, history)
}
