//! Bracketed L-systems (seed 003; Prusinkiewicz & Lindenmayer, *The Algorithmic Beauty of
//! Plants*): an axiom rewritten in parallel by its rules for n generations, then read by a 3D
//! turtle into a [`Skeleton`].
//!
//! Limits are errors, not memory exhaustion: a word may hold at most `max_symbols` modules,
//! at most [`MAX_GENERATIONS`] generations are run, and rewriting stops with an error once it
//! has written [`WORK_FACTOR`] times `max_symbols` modules in all (rules that keep rewriting a
//! short word for ever, e.g. `A=B`, `B=A` with a billion generations).

pub mod expr;
pub mod grammar;
pub mod presets;
pub mod turtle;

use rand_pcg::Pcg64;

pub use grammar::{Rules, Word};
pub use turtle::TurtleParams;

use super::skeleton::Skeleton;

/// The most generations an L-system may ask for.
pub const MAX_GENERATIONS: usize = 10_000;
/// Rewriting may write this many times `max_symbols` modules in all.
pub const WORK_FACTOR: usize = 20;
/// The default of `max_symbols`.
pub const DEFAULT_MAX_SYMBOLS: usize = 2_000_000;
/// The largest `max_symbols` one may ask for: a word of this many modules and their
/// parameters is about a gigabyte, and rewriting may write [`WORK_FACTOR`] times it.
pub const MAX_MAX_SYMBOLS: usize = 50_000_000;

/// Where in an L-system a problem is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Place {
    /// The axiom.
    Axiom,
    /// The n-th rule, from 1.
    Rule(usize),
}

impl std::fmt::Display for Place {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Place::Axiom => write!(f, "the axiom"),
            Place::Rule(n) => write!(f, "rule {n}"),
        }
    }
}

/// What can go wrong with an L-system.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LsError {
    /// A text that does not parse.
    #[error("{place} `{text}`, column {column}: {message}")]
    Syntax {
        /// The axiom or the rule.
        place: Place,
        /// Its text.
        text: String,
        /// The column (from 1, in characters) of the problem.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// The word outgrew `max_symbols`.
    #[error(
        "generation {generation} would hold more than max_symbols = {max} symbols{}; ask for \
         fewer generations or raise max_symbols",
        rule.as_ref().map(|r| format!(" (rule `{r}` was rewriting)")).unwrap_or_default()
    )]
    TooLong {
        /// The limit.
        max: usize,
        /// The generation that passed it.
        generation: usize,
        /// The rule that was being applied.
        rule: Option<String>,
    },
    /// More generations than [`MAX_GENERATIONS`].
    #[error("{0} generations asked for; at most {MAX_GENERATIONS}")]
    TooManyGenerations(usize),
    /// A `max_symbols` over [`MAX_MAX_SYMBOLS`] (or 0).
    #[error("max_symbols = {0}: give 1 to {MAX_MAX_SYMBOLS}")]
    MaxSymbols(usize),
    /// The rules kept rewriting without end.
    #[error(
        "the rules never end: {written} symbols written over {generation} generations \
         (more than {WORK_FACTOR} x max_symbols) and still rewriting; ask for fewer generations"
    )]
    NeverEnds {
        /// Modules written so far.
        written: usize,
        /// The generation reached.
        generation: usize,
    },
}

/// An L-system: axiom, rules and how many generations to rewrite.
#[derive(Debug, Clone)]
pub struct LSystem {
    /// The starting word.
    pub axiom: Word,
    /// The rules.
    pub rules: Rules,
    /// How many parallel rewrites.
    pub generations: usize,
    /// The largest word allowed.
    pub max_symbols: usize,
}

impl LSystem {
    /// Parses an axiom and rules (`A=...`, `A:0.3=...`, `A(l)=...`).
    pub fn parse(
        axiom: &str,
        rules: &[String],
        generations: usize,
        max_symbols: usize,
    ) -> Result<LSystem, LsError> {
        if generations > MAX_GENERATIONS {
            return Err(LsError::TooManyGenerations(generations));
        }
        if max_symbols == 0 || max_symbols > MAX_MAX_SYMBOLS {
            return Err(LsError::MaxSymbols(max_symbols));
        }
        let axiom = grammar::parse_axiom(axiom)?;
        let rules = rules
            .iter()
            .enumerate()
            .map(|(i, r)| grammar::parse_rule(r, i + 1))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(LSystem {
            axiom,
            rules: Rules::new(rules),
            generations,
            max_symbols,
        })
    }

    /// The word after `generations` rewrites; stochastic choices from `rng`. Stops early
    /// once a rewrite changes nothing (no rule applied).
    pub fn expand(&self, rng: &mut Pcg64) -> Result<Word, LsError> {
        if self.axiom.modules.len() > self.max_symbols {
            return Err(LsError::TooLong {
                max: self.max_symbols,
                generation: 0,
                rule: None,
            });
        }
        let mut word = self.axiom.clone();
        let mut next = Word::default();
        let mut written = 0usize;
        for g in 1..=self.generations {
            self.rules
                .rewrite(&word, &mut next, rng, self.max_symbols, g)?;
            if next == word {
                break;
            }
            written += next.modules.len();
            std::mem::swap(&mut word, &mut next);
            if written > WORK_FACTOR.saturating_mul(self.max_symbols) && g < self.generations {
                return Err(LsError::NeverEnds {
                    written,
                    generation: g,
                });
            }
        }
        Ok(word)
    }

    /// Expands and reads the result with the turtle.
    pub fn grow(&self, turtle: &TurtleParams, rng: &mut Pcg64) -> Result<Skeleton, LsError> {
        Ok(turtle::interpret(&self.expand(rng)?, turtle))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn sys(axiom: &str, rules: &[&str], n: usize, max: usize) -> LSystem {
        let rules: Vec<String> = rules.iter().map(|r| r.to_string()).collect();
        LSystem::parse(axiom, &rules, n, max).unwrap()
    }

    #[test]
    fn limits_are_errors_that_say_what_to_change() {
        let mut rng = Pcg64::seed_from_u64(0);
        let e = sys("A", &["A=AA"], 30, 1000).expand(&mut rng).unwrap_err();
        assert!(matches!(e, LsError::TooLong { generation: 10, .. }), "{e}");
        assert!(e.to_string().contains("rule `A=AA`"), "{e}");
        let e = sys("A", &["A=B", "B=A"], 1000, 10)
            .expand(&mut rng)
            .unwrap_err();
        assert!(matches!(e, LsError::NeverEnds { .. }), "{e}");
        let e = LSystem::parse("A", &[], 10_001, 10).unwrap_err();
        assert!(matches!(e, LsError::TooManyGenerations(10_001)));
        let e = LSystem::parse("A", &["A=AA".into()], 60, 1_000_000_000_000_000).unwrap_err();
        assert!(e.to_string().contains("give 1 to 50000000"), "{e}");
        assert!(LSystem::parse("A", &[], 1, 0).is_err());
    }

    #[test]
    fn a_word_no_rule_changes_stops_rewriting() {
        let mut rng = Pcg64::seed_from_u64(0);
        let w = sys("F", &["A=B"], 1000, 10).expand(&mut rng).unwrap();
        assert_eq!(w.to_text(), "F");
    }
}
