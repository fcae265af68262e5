//! Template expressions: parsed by `evalexpr`, then compiled to a flat program over numbered
//! slots and evaluated in `f64` only.
//!
//! evalexpr parses the text (operators, precedence, function calls, `if`), but evaluates with
//! integer and float values kept apart (`7 / 2` is 3) and looks names up in a hash map. A
//! template is evaluated tens of times per house for tens of thousands of houses, and its
//! authors expect arithmetic, so each expression is compiled once per template: every name
//! becomes a slot index, every number a float, a comparison is 1 or 0, and the tree becomes
//! a list of operations in postfix order run on a small stack that lives on the call's stack
//! frame (no allocation, no pointer chasing; the boxed tree it replaced was 7 % of a build).

mod program;

use evalexpr::{DefaultNumericTypes, Node, Operator, Value};
use program::{run, Emit, Op, STACK};

/// A compiled expression: operations in postfix order (see `program::Op`).
#[derive(Debug, Clone, PartialEq)]
pub struct Expr {
    ops: Box<[Op]>,
    /// The most values the stack holds at once while it runs.
    depth: usize,
}
/// The expression as parsed, names resolved: what [`Expr`] is compiled from.
#[derive(Debug, Clone, PartialEq)]
enum Tree {
    Const(f64),
    Slot(usize),
    Neg(Box<Tree>),
    Not(Box<Tree>),
    Bin(Bin, Box<Tree>, Box<Tree>),
    Call(Func, Vec<Tree>),
}

/// The binary operators (comparisons and logic give 1 or 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bin {
    /// `a + b`
    Add,
    /// `a - b`
    Sub,
    /// `a * b`
    Mul,
    /// `a / b`
    Div,
    /// `a % b`
    Rem,
    /// `a ^ b`
    Pow,
    /// `a == b`
    Eq,
    /// `a != b`
    Ne,
    /// `a > b`
    Gt,
    /// `a < b`
    Lt,
    /// `a >= b`
    Ge,
    /// `a <= b`
    Le,
    /// `a && b`
    And,
    /// `a || b`
    Or,
}

/// Functions a template may call. `lot_u0(v)` / `lot_u1(v)` give the lot's extent along the
/// street at depth `v`, so a part can follow a lot whose sides are not square to the street.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Func {
    /// `min(a, b, ...)`
    Min,
    /// `max(a, b, ...)`
    Max,
    /// `floor(x)`
    Floor,
    /// `ceil(x)`
    Ceil,
    /// `round(x)`
    Round,
    /// `abs(x)`
    Abs,
    /// `sqrt(x)`
    Sqrt,
    /// `sin(x)`, radians
    Sin,
    /// `cos(x)`
    Cos,
    /// `tan(x)`
    Tan,
    /// `atan2(y, x)`
    Atan2,
    /// `if(c, a, b)`: `a` when `c` is not 0, else `b`
    If,
    /// `clamp(x, lo, hi)`
    Clamp,
    /// `lot_u0(v)`: where the lot begins along the street at depth `v`
    LotU0,
    /// `lot_u1(v)`: where it ends
    LotU1,
}

/// The names and argument counts of the functions (`None` = one or more).
pub const FUNCTIONS: &[(&str, Func, Option<usize>)] = &[
    ("min", Func::Min, None),
    ("max", Func::Max, None),
    ("floor", Func::Floor, Some(1)),
    ("ceil", Func::Ceil, Some(1)),
    ("round", Func::Round, Some(1)),
    ("abs", Func::Abs, Some(1)),
    ("sqrt", Func::Sqrt, Some(1)),
    ("sin", Func::Sin, Some(1)),
    ("cos", Func::Cos, Some(1)),
    ("tan", Func::Tan, Some(1)),
    ("atan2", Func::Atan2, Some(2)),
    ("if", Func::If, Some(3)),
    ("clamp", Func::Clamp, Some(3)),
    ("lot_u0", Func::LotU0, Some(1)),
    ("lot_u1", Func::LotU1, Some(1)),
];

/// What an expression may ask about the feature beyond its slots.
pub trait Lot {
    /// The lot's extent along u at depth v (v clamped to the lot).
    fn extent_at(&self, v: f64) -> (f64, f64);
}

/// No lot: `lot_u0`/`lot_u1` give NaN (the caller reports it).
pub struct NoLot;

impl Lot for NoLot {
    fn extent_at(&self, _v: f64) -> (f64, f64) {
        (f64::NAN, f64::NAN)
    }
}

/// Parses `text` and compiles it, resolving each name with `slot`.
///
/// ```
/// use edo_city::templates::expr::{compile, NoLot};
/// let names = ["width", "depth"];
/// let e = compile("min(width, depth) / 2 + if(depth > 10, 1, 0)", &|n| {
///     names.iter().position(|m| *m == n)
/// })
/// .unwrap();
/// assert_eq!(e.eval(&[7.0, 12.0], &NoLot), 4.5);
/// ```
pub fn compile(text: &str, slot: &dyn Fn(&str) -> Option<usize>) -> Result<Expr, String> {
    let shown = crate::model::source::excerpt(text);
    check_size(text).map_err(|e| format!("`{shown}`: {e}"))?;
    let tree = evalexpr::build_operator_tree::<DefaultNumericTypes>(text)
        .map_err(|e| format!("cannot parse `{shown}`: {e}"))?;
    let tree = lower(&tree, slot, 0).map_err(|e| format!("in `{shown}`: {e}"))?;
    Ok(Expr::of(&tree))
}

/// Characters an expression may have: a template's longest is a few hundred.
pub const MAX_CHARS: usize = 4000;
/// Brackets an expression may nest, and operators deep its tree may be: evalexpr and
/// [`lower`] recurse once per level, and 20,000 levels overflow the stack.
pub const MAX_DEPTH: usize = 64;

/// Operator characters an expression may have (the shipped templates' most is 17).
pub const MAX_OPERATORS: usize = 256;

/// Refuses an expression too long or nested too deep before evalexpr reads it.
fn check_size(text: &str) -> Result<(), String> {
    if text.len() > MAX_CHARS {
        return Err(format!(
            "{} characters, more than {MAX_CHARS}: split it into named values",
            text.len()
        ));
    }
    // evalexpr descends once per operator it inserts under another (a run of `-`, a chain
    // of `^`): the operators are counted, as the brackets are.
    let operators = text.bytes().filter(|b| b"+-*/%^!<>=&|".contains(b)).count();
    if operators > MAX_OPERATORS {
        return Err(format!(
            "{operators} operator characters, more than {MAX_OPERATORS}: split it into named \
             values"
        ));
    }
    let mut depth = 0usize;
    for b in text.bytes() {
        match b {
            b'(' | b'[' | b'{' => depth += 1,
            b')' | b']' | b'}' => depth = depth.saturating_sub(1),
            _ => {}
        }
        if depth > MAX_DEPTH {
            return Err(format!(
                "brackets nested more than {MAX_DEPTH} deep: split it into named values"
            ));
        }
    }
    Ok(())
}

fn lower(node: &Node, slot: &dyn Fn(&str) -> Option<usize>, depth: usize) -> Result<Tree, String> {
    if depth > 4 * MAX_DEPTH {
        return Err(format!(
            "operators nested more than {} deep: split it into named values",
            4 * MAX_DEPTH
        ));
    }
    let kids = node.children();
    let child = |i: usize| -> Result<Box<Tree>, String> {
        kids.get(i)
            .ok_or_else(|| "an operator lacks an operand".to_string())
            .and_then(|k| lower(k, slot, depth + 1))
            .map(Box::new)
    };
    let bin = |op: Bin| -> Result<Tree, String> { Ok(Tree::Bin(op, child(0)?, child(1)?)) };
    Ok(match node.operator() {
        Operator::RootNode => match kids {
            [one] => lower(one, slot, depth + 1)?,
            [] => return Err("empty expression".into()),
            _ => return Err("a list of values is not a number".into()),
        },
        Operator::Add => bin(Bin::Add)?,
        Operator::Sub => bin(Bin::Sub)?,
        Operator::Mul => bin(Bin::Mul)?,
        Operator::Div => bin(Bin::Div)?,
        Operator::Mod => bin(Bin::Rem)?,
        Operator::Exp => bin(Bin::Pow)?,
        Operator::Eq => bin(Bin::Eq)?,
        Operator::Neq => bin(Bin::Ne)?,
        Operator::Gt => bin(Bin::Gt)?,
        Operator::Lt => bin(Bin::Lt)?,
        Operator::Geq => bin(Bin::Ge)?,
        Operator::Leq => bin(Bin::Le)?,
        Operator::And => bin(Bin::And)?,
        Operator::Or => bin(Bin::Or)?,
        Operator::Neg => Tree::Neg(child(0)?),
        Operator::Not => Tree::Not(child(0)?),
        Operator::Const { value } => Tree::Const(match value {
            Value::Float(f) => *f,
            Value::Int(i) => *i as f64,
            Value::Boolean(b) => f64::from(u8::from(*b)),
            other => return Err(format!("`{other}` is not a number")),
        }),
        Operator::VariableIdentifierRead { identifier } => match identifier.as_str() {
            "pi" => Tree::Const(std::f64::consts::PI),
            name => Tree::Slot(slot(name).ok_or_else(|| format!("unknown name `{name}`"))?),
        },
        Operator::FunctionIdentifier { identifier } => {
            let name = identifier.strip_prefix("math::").unwrap_or(identifier);
            let &(_, func, arity) =
                FUNCTIONS
                    .iter()
                    .find(|(n, _, _)| *n == name)
                    .ok_or_else(|| {
                        format!(
                            "unknown function `{identifier}` (known: {})",
                            FUNCTIONS.iter().map(|f| f.0).collect::<Vec<_>>().join(", ")
                        )
                    })?;
            let args = arguments(kids, slot, depth)?;
            let ok = match arity {
                Some(n) => args.len() == n,
                None => !args.is_empty(),
            };
            if !ok {
                return Err(format!(
                    "`{name}` takes {} argument(s), got {}",
                    arity.map_or("one or more".to_string(), |n| n.to_string()),
                    args.len()
                ));
            }
            Tree::Call(func, args)
        }
        other => return Err(format!("`{other}` is not allowed in a template expression")),
    })
}

/// A call's arguments: evalexpr gives one child, a tuple when there are several.
fn arguments(
    kids: &[Node],
    slot: &dyn Fn(&str) -> Option<usize>,
    depth: usize,
) -> Result<Vec<Tree>, String> {
    let mut node = match kids {
        [one] => one,
        [] => return Ok(Vec::new()),
        _ => return Err("a function call with a malformed argument list".into()),
    };
    while matches!(node.operator(), Operator::RootNode) && node.children().len() == 1 {
        node = &node.children()[0];
    }
    match node.operator() {
        Operator::Tuple => node
            .children()
            .iter()
            .map(|k| lower(k, slot, depth + 1))
            .collect(),
        Operator::RootNode if node.children().is_empty() => Ok(Vec::new()),
        _ => Ok(vec![lower(node, slot, depth + 1)?]),
    }
}
impl Expr {
    /// An expression that is always `x`.
    pub fn constant(x: f64) -> Expr {
        Expr {
            ops: Box::new([Op::Const(x)]),
            depth: 1,
        }
    }

    /// The operations of `tree`.
    fn of(tree: &Tree) -> Expr {
        let mut e = Emit::default();
        e.tree(tree);
        Expr {
            ops: e.ops.into(),
            depth: e.max,
        }
    }

    /// The value for the given slots. Arithmetic on NaN stays NaN for the caller to report.
    pub fn eval(&self, slots: &[f64], lot: &dyn Lot) -> f64 {
        match *self.ops {
            [Op::Const(c)] => c,
            [Op::Slot(i)] => slots[i],
            _ if self.depth <= STACK => run(&self.ops, slots, lot, &mut [0.0; STACK]),
            _ => run(&self.ops, slots, lot, &mut vec![0.0; self.depth]),
        }
    }

    /// The slots this expression reads, in the order they are written.
    pub fn slots(&self, out: &mut Vec<usize>) {
        out.extend(self.ops.iter().filter_map(|op| match op {
            Op::Slot(i) => Some(*i),
            _ => None,
        }));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eval(text: &str) -> f64 {
        let names = ["a", "b"];
        compile(text, &|n| names.iter().position(|m| *m == n))
            .unwrap()
            .eval(&[3.0, 4.0], &NoLot)
    }

    #[test]
    fn arithmetic_is_in_floats() {
        assert_eq!(eval("7 / 2"), 3.5);
        assert_eq!(eval("a ^ 2 + b ^ 2"), 25.0);
        assert_eq!(eval("-a + 1"), -2.0);
        assert_eq!(eval("sqrt(a*a + b*b)"), 5.0);
        assert_eq!(eval("math::sqrt(16)"), 4.0);
        assert_eq!(eval("ceil(7.2 / 1.818)"), 4.0);
        assert_eq!(eval("floor(2.7) + round(0.4)"), 2.0);
        assert_eq!(eval("min(a, b, 1)"), 1.0);
        assert_eq!(eval("max(a)"), 3.0);
        assert_eq!(eval("clamp(10, 0, b)"), 4.0);
        assert!((eval("atan2(1, 1) * 4") - std::f64::consts::PI).abs() < 1e-12);
        assert!((eval("sin(pi / 2) + cos(0) + tan(0)") - 2.0).abs() < 1e-12);
    }

    #[test]
    fn conditions_are_one_or_zero() {
        assert_eq!(eval("if(a > 2 && b < 5, 10, 20)"), 10.0);
        assert_eq!(eval("if(a > 2 && b > 5, 10, 20)"), 20.0);
        assert_eq!(eval("(a == 3) + (b != 4) + !(a < 1)"), 2.0);
        assert_eq!(eval("if(0, 1/0, 7)"), 7.0);
    }

    #[test]
    fn nan_is_not_hidden_by_min_or_max() {
        assert!(eval("min(0/0, 1)").is_nan());
        assert!(eval("max(1, 0/0)").is_nan());
    }

    #[test]
    fn errors_name_what_is_wrong() {
        let c = |t: &str| compile(t, &|n| (n == "a").then_some(0)).unwrap_err();
        assert!(c("a +").contains("lacks an operand"), "{}", c("a +"));
        assert!(c("(a").contains("cannot parse"), "{}", c("(a"));
        assert!(c("depth * 2").contains("unknown name `depth`"));
        assert!(c("cbrt(a)").contains("unknown function `cbrt`"));
        assert!(c("atan2(a)").contains("takes 2"));
        assert!(c("a = 2").contains("not allowed"));
        assert!(c("\"text\"").contains("not a number"));
    }

    #[test]
    fn slots_lists_every_name_read() {
        let names = ["a", "b", "c"];
        let e = compile("a + max(c, 2)", &|n| names.iter().position(|m| *m == n)).unwrap();
        let mut s = Vec::new();
        e.slots(&mut s);
        assert_eq!(s, vec![0, 2]);
    }

    #[test]
    fn deep_or_long_expressions_are_refused_before_parsing() {
        let none = |_: &str| None;
        let deep = format!("{}1{}", "(".repeat(1000), ")".repeat(1000));
        let e = compile(&deep, &none).unwrap_err();
        assert!(
            e.contains("nested more than 64"),
            "{}",
            &e[..e.len().min(200)]
        );
        assert!(e.len() < 300, "{e}");
        let chain = vec!["1"; 1500].join("+");
        let e = compile(&chain, &none).unwrap_err();
        assert!(e.contains("more than 256"), "{e}");
        // Within the counts, the tree's depth is still bounded as it is lowered.
        let chain = vec!["1"; 250].join("+");
        assert_eq!(compile(&chain, &none).unwrap().eval(&[], &NoLot), 250.0);
        let negs = format!("{}1", "-".repeat(3000));
        assert!(compile(&negs, &none).is_err());
        let long = "1".repeat(MAX_CHARS + 1);
        assert!(compile(&long, &none).unwrap_err().contains("characters"));
        let huge = format!("{}1{}", "(".repeat(20_000), ")".repeat(20_000));
        assert!(compile(&huge, &none).unwrap_err().contains("characters"));
        // Ordinary nesting is fine.
        assert_eq!(eval("((((1 + 1))))*((2))"), 4.0);
    }
}
