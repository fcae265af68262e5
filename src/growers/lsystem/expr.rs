//! The arithmetic of parametric modules: `F(l*0.8)`, `A(n+1)`, `+(n*137.5)`. Numbers, the
//! predecessor's parameter names, `+ - * / ^`, parentheses and `sqrt abs sin cos floor`
//! (radians). Parsed once per rule into a tree over parameter slots; evaluated per module
//! without allocation.

/// A compiled expression over the parameters of its rule's predecessor.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A number.
    Num(f64),
    /// The predecessor's parameter at this position.
    Var(usize),
    /// -e.
    Neg(Box<Expr>),
    /// A binary operation: one of `+ - * / ^`.
    Bin(u8, Box<Expr>, Box<Expr>),
    /// A function of one argument.
    Call(Func, Box<Expr>),
}

/// The functions an expression may call.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Func {
    /// Square root.
    Sqrt,
    /// Absolute value.
    Abs,
    /// Sine (radians).
    Sin,
    /// Cosine (radians).
    Cos,
    /// Round down.
    Floor,
}

impl Expr {
    /// The value for the predecessor's actual parameters `vars`.
    pub fn eval(&self, vars: &[f64]) -> f64 {
        match self {
            Expr::Num(v) => *v,
            Expr::Var(i) => vars.get(*i).copied().unwrap_or(f64::NAN),
            Expr::Neg(e) => -e.eval(vars),
            Expr::Bin(op, a, b) => {
                let (a, b) = (a.eval(vars), b.eval(vars));
                match op {
                    b'+' => a + b,
                    b'-' => a - b,
                    b'*' => a * b,
                    b'/' => a / b,
                    _ => a.powf(b),
                }
            }
            Expr::Call(f, e) => {
                let v = e.eval(vars);
                match f {
                    Func::Sqrt => v.sqrt(),
                    Func::Abs => v.abs(),
                    Func::Sin => v.sin(),
                    Func::Cos => v.cos(),
                    Func::Floor => v.floor(),
                }
            }
        }
    }
}

/// Parses `text` (one argument of a module) with `names` as the parameters it may use.
/// An error gives the character offset in `text` and what is wrong.
pub fn parse(text: &[char], names: &[String]) -> Result<Expr, (usize, String)> {
    check_size(text)?;
    let mut p = Parser {
        s: text,
        i: 0,
        names,
    };
    let e = p.sum()?;
    p.space();
    if p.i < p.s.len() {
        return Err((p.i, format!("unexpected `{}` in an expression", p.s[p.i])));
    }
    Ok(e)
}

/// Operators an argument may hold: the parser and [`Expr::eval`] recurse once per level,
/// and a run of 20,000 `(` or `-` overflows the stack. The presets' most is 4.
pub const MAX_OPERATORS: usize = 128;
/// Brackets an argument may nest.
pub const MAX_DEPTH: usize = 32;

/// Refuses an argument with too many operators or brackets nested too deep, before
/// parsing: the error gives where the limit is passed.
fn check_size(text: &[char]) -> Result<(), (usize, String)> {
    let (mut ops, mut depth) = (0usize, 0usize);
    for (i, c) in text.iter().enumerate() {
        match c {
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            '+' | '-' | '*' | '/' | '^' => ops += 1,
            _ => {}
        }
        if depth > MAX_DEPTH {
            return Err((
                i,
                format!("brackets nested more than {MAX_DEPTH} deep: simplify the expression"),
            ));
        }
        if ops > MAX_OPERATORS {
            return Err((
                i,
                format!("more than {MAX_OPERATORS} operators: simplify the expression"),
            ));
        }
    }
    Ok(())
}

struct Parser<'a> {
    s: &'a [char],
    i: usize,
    names: &'a [String],
}

impl Parser<'_> {
    fn space(&mut self) {
        while self.i < self.s.len() && self.s[self.i].is_whitespace() {
            self.i += 1;
        }
    }

    fn peek(&mut self) -> Option<char> {
        self.space();
        self.s.get(self.i).copied()
    }

    fn sum(&mut self) -> Result<Expr, (usize, String)> {
        let mut e = self.product()?;
        while let Some(c @ ('+' | '-')) = self.peek() {
            self.i += 1;
            e = Expr::Bin(c as u8, Box::new(e), Box::new(self.product()?));
        }
        Ok(e)
    }

    fn product(&mut self) -> Result<Expr, (usize, String)> {
        let mut e = self.power()?;
        while let Some(c @ ('*' | '/')) = self.peek() {
            self.i += 1;
            e = Expr::Bin(c as u8, Box::new(e), Box::new(self.power()?));
        }
        Ok(e)
    }

    fn power(&mut self) -> Result<Expr, (usize, String)> {
        let base = self.unary()?;
        if self.peek() == Some('^') {
            self.i += 1;
            // Right-associative: 2^3^2 = 2^(3^2).
            return Ok(Expr::Bin(b'^', Box::new(base), Box::new(self.power()?)));
        }
        Ok(base)
    }

    fn unary(&mut self) -> Result<Expr, (usize, String)> {
        match self.peek() {
            Some('-') => {
                self.i += 1;
                Ok(Expr::Neg(Box::new(self.unary()?)))
            }
            Some('+') => {
                self.i += 1;
                self.unary()
            }
            _ => self.atom(),
        }
    }

    fn atom(&mut self) -> Result<Expr, (usize, String)> {
        let start = self.i;
        match self.peek() {
            None => Err((self.i, "an expression ends too early".into())),
            Some('(') => {
                self.i += 1;
                let e = self.sum()?;
                if self.peek() != Some(')') {
                    return Err((self.i, "a `(` is not closed".into()));
                }
                self.i += 1;
                Ok(e)
            }
            Some(c) if c.is_ascii_digit() || c == '.' => {
                let from = self.i;
                while self.i < self.s.len()
                    && (self.s[self.i].is_ascii_digit()
                        || self.s[self.i] == '.'
                        || (matches!(self.s[self.i], 'e' | 'E')
                            && self.s.get(self.i + 1).is_some_and(|d| d.is_ascii_digit())))
                {
                    self.i += 1;
                }
                let text: String = self.s[from..self.i].iter().collect();
                text.parse::<f64>()
                    .map(Expr::Num)
                    .map_err(|_| (from, format!("`{text}` is not a number")))
            }
            Some(c) if c.is_alphabetic() || c == '_' => {
                let from = self.i;
                while self.i < self.s.len()
                    && (self.s[self.i].is_alphanumeric() || self.s[self.i] == '_')
                {
                    self.i += 1;
                }
                let name: String = self.s[from..self.i].iter().collect();
                let func = match name.as_str() {
                    "sqrt" => Some(Func::Sqrt),
                    "abs" => Some(Func::Abs),
                    "sin" => Some(Func::Sin),
                    "cos" => Some(Func::Cos),
                    "floor" => Some(Func::Floor),
                    _ => None,
                };
                if let Some(f) = func {
                    if self.peek() == Some('(') {
                        let arg = self.atom()?;
                        return Ok(Expr::Call(f, Box::new(arg)));
                    }
                }
                match self.names.iter().position(|n| *n == name) {
                    Some(k) => Ok(Expr::Var(k)),
                    None => Err((
                        from,
                        if self.names.is_empty() {
                            format!("unknown parameter `{name}`: the predecessor has none")
                        } else {
                            format!(
                                "unknown parameter `{name}` (the predecessor has {})",
                                self.names.join(", ")
                            )
                        },
                    )),
                }
            }
            Some(c) => Err((start, format!("unexpected `{c}` in an expression"))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eval(s: &str, names: &[&str], vars: &[f64]) -> f64 {
        let chars: Vec<char> = s.chars().collect();
        let names: Vec<String> = names.iter().map(|n| n.to_string()).collect();
        parse(&chars, &names).unwrap().eval(vars)
    }

    #[test]
    fn arithmetic_follows_the_usual_precedence() {
        assert_eq!(eval("1+2*3", &[], &[]), 7.0);
        assert_eq!(eval("(1+2)*3", &[], &[]), 9.0);
        assert_eq!(eval("2^3^2", &[], &[]), 512.0);
        assert_eq!(eval("-l*0.5", &["l"], &[4.0]), -2.0);
        assert_eq!(eval("sqrt(n) + 1e1", &["n"], &[9.0]), 13.0);
    }

    #[test]
    fn an_unknown_name_is_an_error_with_its_position() {
        let chars: Vec<char> = "l*k".chars().collect();
        let err = parse(&chars, &["l".to_string()]).unwrap_err();
        assert_eq!(err.0, 2);
        assert!(err.1.contains("unknown parameter `k`"), "{}", err.1);
    }

    #[test]
    fn deep_nesting_and_long_chains_are_refused_not_overflowed() {
        let refuse = |s: String| {
            let chars: Vec<char> = s.chars().collect();
            parse(&chars, &[]).unwrap_err()
        };
        let (at, m) = refuse(format!("{}1{}", "(".repeat(20_000), ")".repeat(20_000)));
        assert!(at == MAX_DEPTH && m.contains("nested"), "{at} {m}");
        let (_, m) = refuse(format!("{}1", "-".repeat(20_000)));
        assert!(m.contains("operators"), "{m}");
        let (_, m) = refuse(vec!["1"; 20_000].join("^"));
        assert!(m.contains("operators"), "{m}");
        assert_eq!(eval(&vec!["1"; 100].join("+"), &[], &[]), 100.0);
    }
}
