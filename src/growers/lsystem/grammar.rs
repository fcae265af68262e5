//! Axioms, rules and their parallel rewriting. A word is a list of modules: a symbol with
//! optional numeric parameters (`F`, `F(1.5)`, `A(0,2)`). A rule is `A=...`,
//! `A:0.3=...` (a stochastic rule's weight; the rules of one symbol share out the draws by
//! weight) or `A(l,w)=F(l)[+A(l*0.8,w*0.7)]` (parametric: the successor's arguments are
//! expressions over the predecessor's parameters). Context-free: a rule applies to a module
//! of its symbol with as many parameters as it names.

use rand::RngExt;
use rand_pcg::Pcg64;

use super::expr::{self, Expr};
use super::{LsError, Place};

/// One module of a word.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Module {
    /// Its symbol (an ASCII character).
    pub sym: u8,
    /// Where its parameters start in the word's `args`.
    pub first: u32,
    /// How many parameters it has.
    pub len: u8,
}

/// A word: modules and their parameters side by side, so rewriting millions of symbols
/// allocates two vectors, not one per module.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Word {
    /// The modules in order.
    pub modules: Vec<Module>,
    /// Every module's parameters, in order.
    pub args: Vec<f64>,
}

impl Word {
    /// The parameters of module `m`.
    pub fn args_of(&self, m: &Module) -> &[f64] {
        &self.args[m.first as usize..m.first as usize + m.len as usize]
    }

    /// The word as text (`F(1.5)` with the shortest exact decimal of each parameter).
    pub fn to_text(&self) -> String {
        let mut s = String::with_capacity(self.modules.len());
        for m in &self.modules {
            s.push(m.sym as char);
            if m.len > 0 {
                s.push('(');
                for (k, a) in self.args_of(m).iter().enumerate() {
                    if k > 0 {
                        s.push(',');
                    }
                    s.push_str(&format!("{a}"));
                }
                s.push(')');
            }
        }
        s
    }
}

/// A successor's module: a symbol and argument expressions.
#[derive(Debug, Clone, PartialEq)]
struct Template {
    sym: u8,
    args: Vec<Expr>,
}

/// One rule.
#[derive(Debug, Clone, PartialEq)]
pub struct Rule {
    /// The predecessor's symbol.
    pub sym: u8,
    /// Its parameter names.
    pub params: Vec<String>,
    /// The weight among the rules of the same symbol and arity (1 when not given).
    pub weight: f64,
    succ: Vec<Template>,
    /// The rule as written, for messages.
    pub text: String,
}

/// Parses the axiom: modules with constant arguments, brackets balanced.
pub fn parse_axiom(text: &str) -> Result<Word, LsError> {
    let chars: Vec<char> = text.chars().collect();
    let templates = parse_modules(&chars, 0, &[], Place::Axiom, text)?;
    let mut w = Word::default();
    for t in templates {
        push(&mut w, t.sym, t.args.iter().map(|e| e.eval(&[])));
    }
    Ok(w)
}

/// Parses one rule; `index` numbers it (from 1) in messages.
pub fn parse_rule(text: &str, index: usize) -> Result<Rule, LsError> {
    let place = Place::Rule(index);
    let chars: Vec<char> = text.chars().collect();
    let err = |column: usize, message: String| LsError::Syntax {
        place,
        text: shown(text),
        column: column + 1,
        message,
    };
    let Some(eq) = chars.iter().position(|&c| c == '=') else {
        return Err(err(0, "a rule is `A=successor` (no `=` found)".into()));
    };
    let head: Vec<char> = chars[..eq].to_vec();
    let mut i = 0;
    while i < head.len() && head[i].is_whitespace() {
        i += 1;
    }
    let Some(&sym) = head.get(i) else {
        return Err(err(eq, "the rule names no symbol before `=`".into()));
    };
    let sym = symbol(sym).map_err(|m| err(i, m))?;
    i += 1;
    let mut params = Vec::new();
    if head.get(i) == Some(&'(') {
        let close = head[i..]
            .iter()
            .position(|&c| c == ')')
            .map(|k| i + k)
            .ok_or_else(|| err(i, "the predecessor's `(` is not closed".into()))?;
        for name in head[i + 1..close].iter().collect::<String>().split(',') {
            let name = name.trim();
            if name.is_empty()
                || !name.chars().all(|c| c.is_alphanumeric() || c == '_')
                || name.starts_with(|c: char| c.is_ascii_digit())
            {
                return Err(err(i + 1, format!("`{name}` is not a parameter name")));
            }
            params.push(name.to_string());
        }
        i = close + 1;
    }
    let mut weight = 1.0;
    let rest: String = head[i..].iter().collect();
    let rest = rest.trim();
    if let Some(w) = rest.strip_prefix(':') {
        weight = w
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|w| w.is_finite() && *w > 0.0)
            .ok_or_else(|| {
                err(
                    i,
                    format!("the weight `{}` is not a positive number", w.trim()),
                )
            })?;
    } else if !rest.is_empty() {
        return Err(err(i, format!("unexpected `{rest}` before `=`")));
    }
    let succ = parse_modules(&chars[eq + 1..], eq + 1, &params, place, text)?;
    Ok(Rule {
        sym,
        params,
        weight,
        succ,
        text: text.to_string(),
    })
}

/// The symbol of a module: printable ASCII, not a parenthesis or a comma.
fn symbol(c: char) -> Result<u8, String> {
    if c.is_ascii_graphic() && !matches!(c, '(' | ')' | ',' | '=') {
        Ok(c as u8)
    } else {
        Err(format!(
            "`{c}` cannot be a symbol (symbols are printable ASCII characters other than ( ) , =)"
        ))
    }
}

/// A rule's text as an error quotes it: its first 60 characters (a rule can be 100 KB).
fn shown(text: &str) -> String {
    match text.char_indices().nth(60) {
        Some((i, _)) => format!("{}...", &text[..i]),
        None => text.to_string(),
    }
}

/// Modules with argument expressions; `offset` is where `s` starts in the whole text.
fn parse_modules(
    s: &[char],
    offset: usize,
    names: &[String],
    place: Place,
    text: &str,
) -> Result<Vec<Template>, LsError> {
    let err = |column: usize, message: String| LsError::Syntax {
        place,
        text: shown(text),
        column: offset + column + 1,
        message,
    };
    let mut out = Vec::new();
    let mut open: Vec<(char, usize)> = Vec::new();
    let mut i = 0;
    while i < s.len() {
        let c = s[i];
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        let sym = symbol(c).map_err(|m| err(i, m))?;
        match c {
            '[' | '{' => open.push((c, i)),
            ']' | '}' => {
                let want = if c == ']' { '[' } else { '{' };
                match open.pop() {
                    Some((o, _)) if o == want => {}
                    Some((o, at)) => {
                        return Err(err(at, format!("`{o}` is closed by `{c}`")));
                    }
                    None => return Err(err(i, format!("`{c}` closes nothing"))),
                }
            }
            _ => {}
        }
        let mut args = Vec::new();
        i += 1;
        if s.get(i) == Some(&'(') {
            let mut depth = 0;
            let mut start = i + 1;
            let mut k = i;
            loop {
                let Some(&ch) = s.get(k) else {
                    return Err(err(i, format!("the `(` after `{c}` is not closed")));
                };
                match ch {
                    '(' => depth += 1,
                    ')' | ',' if depth == 1 => {
                        let e = expr::parse(&s[start..k], names)
                            .map_err(|(at, m)| err(start + at, m))?;
                        args.push(e);
                        start = k + 1;
                        if ch == ')' {
                            break;
                        }
                    }
                    ')' => depth -= 1,
                    _ => {}
                }
                k += 1;
            }
            if args.len() > u8::MAX as usize {
                return Err(err(i, "a module has more than 255 parameters".into()));
            }
            i = k + 1;
        }
        out.push(Template { sym, args });
    }
    if let Some((o, at)) = open.pop() {
        return Err(err(at, format!("`{o}` is never closed")));
    }
    Ok(out)
}

fn push(w: &mut Word, sym: u8, args: impl Iterator<Item = f64>) {
    let first = w.args.len() as u32;
    w.args.extend(args);
    let len = (w.args.len() - first as usize) as u8;
    w.modules.push(Module { sym, first, len });
}

/// The rules, indexed by symbol for rewriting.
#[derive(Debug, Clone, Default)]
pub struct Rules {
    rules: Vec<Rule>,
    /// For each ASCII symbol, the indices of its rules.
    by_symbol: Vec<Vec<usize>>,
}

impl Rules {
    /// Indexes `rules`.
    pub fn new(rules: Vec<Rule>) -> Rules {
        let mut by_symbol = vec![Vec::new(); 128];
        for (i, r) in rules.iter().enumerate() {
            by_symbol[r.sym as usize].push(i);
        }
        Rules { rules, by_symbol }
    }

    /// The rules as given.
    pub fn rules(&self) -> &[Rule] {
        &self.rules
    }

    /// One parallel rewrite of `word` into `out` (cleared first). Every module is replaced by
    /// its rule's successor, drawn by weight among the matching rules from `rng` when there
    /// are several; a module no rule matches stays as it is. Fails once `out` would pass
    /// `max` modules.
    pub fn rewrite(
        &self,
        word: &Word,
        out: &mut Word,
        rng: &mut Pcg64,
        max: usize,
        generation: usize,
    ) -> Result<(), LsError> {
        out.modules.clear();
        out.args.clear();
        let mut matching: Vec<usize> = Vec::new();
        for m in &word.modules {
            let vars = word.args_of(m);
            matching.clear();
            matching.extend(
                self.by_symbol[m.sym as usize]
                    .iter()
                    .copied()
                    .filter(|&r| self.rules[r].params.len() == m.len as usize),
            );
            let rule = match matching.len() {
                0 => None,
                1 => Some(&self.rules[matching[0]]),
                _ => {
                    let total: f64 = matching.iter().map(|&r| self.rules[r].weight).sum();
                    let mut pick = rng.random::<f64>() * total;
                    let mut chosen = matching[matching.len() - 1];
                    for &r in &matching {
                        pick -= self.rules[r].weight;
                        if pick < 0.0 {
                            chosen = r;
                            break;
                        }
                    }
                    Some(&self.rules[chosen])
                }
            };
            match rule {
                None => push(out, m.sym, vars.iter().copied()),
                Some(r) => {
                    for t in &r.succ {
                        push(out, t.sym, t.args.iter().map(|e| e.eval(vars)));
                    }
                }
            }
            if out.modules.len() > max {
                return Err(LsError::TooLong {
                    max,
                    generation,
                    rule: rule.map(|r| r.text.clone()),
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn expand(axiom: &str, rules: &[&str], n: usize) -> String {
        let rules = Rules::new(
            rules
                .iter()
                .enumerate()
                .map(|(i, r)| parse_rule(r, i + 1).unwrap())
                .collect(),
        );
        let mut w = parse_axiom(axiom).unwrap();
        let mut rng = Pcg64::seed_from_u64(1);
        for g in 0..n {
            let mut out = Word::default();
            rules
                .rewrite(&w, &mut out, &mut rng, 1_000_000, g + 1)
                .unwrap();
            w = out;
        }
        w.to_text()
    }

    #[test]
    fn the_seeds_first_example_grows_as_the_seed_says() {
        // The seed writes A=F+AF but draws (and its text derives) A=F+FA.
        assert_eq!(expand("A", &["A=F+FA"], 1), "F+FA");
        assert_eq!(expand("A", &["A=F+FA"], 2), "F+FF+FA");
        assert_eq!(expand("A", &["A=F+FA"], 3), "F+FF+FF+FA");
    }

    #[test]
    fn parametric_rules_evaluate_their_arguments() {
        assert_eq!(
            expand("A(1)", &["A(l)=F(l)A(l*0.5)"], 2),
            "F(1)F(0.5)A(0.25)"
        );
        // A module with another number of parameters than the rule names is left alone.
        assert_eq!(expand("A(1,2)A", &["A(l)=B"], 1), "A(1,2)A");
    }

    #[test]
    fn errors_name_the_rule_and_the_column() {
        let e = parse_rule("A=F[+F", 3).unwrap_err().to_string();
        assert!(e.contains("rule 3") && e.contains("column 4"), "{e}");
        let e = parse_rule("A(l)=F(l*k)", 1).unwrap_err().to_string();
        assert!(
            e.contains("unknown parameter `k`") && e.contains("column 10"),
            "{e}"
        );
        let e = parse_axiom("F]").unwrap_err().to_string();
        assert!(e.contains("axiom") && e.contains("closes nothing"), "{e}");
        assert!(parse_rule("A:-1=F", 1).is_err());
        assert!(parse_rule("AF", 1).is_err());
    }

    #[test]
    fn stochastic_rules_share_the_draws_by_weight() {
        let rules = Rules::new(vec![
            parse_rule("A:3=X", 1).unwrap(),
            parse_rule("A:1=Y", 2).unwrap(),
        ]);
        let w = parse_axiom(&"A".repeat(8000)).unwrap();
        let mut out = Word::default();
        let mut rng = Pcg64::seed_from_u64(9);
        rules.rewrite(&w, &mut out, &mut rng, 100_000, 1).unwrap();
        let x = out.modules.iter().filter(|m| m.sym == b'X').count() as f64 / 8000.0;
        assert!((x - 0.75).abs() < 0.02, "{x}");
    }

    #[test]
    fn a_rule_nested_20000_deep_is_an_error_quoting_a_short_excerpt() {
        let rule = format!("A=F({}1{})", "(".repeat(20_000), ")".repeat(20_000));
        let e = parse_rule(&rule, 0).unwrap_err().to_string();
        assert!(e.contains("nested more than"), "{}", &e[..e.len().min(300)]);
        assert!(e.len() < 300, "{} bytes", e.len());
    }
}
