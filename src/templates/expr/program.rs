//! The flat form of an expression: its operations in postfix order, run on a stack.

use super::{Bin, Func, Lot, Tree};

/// One step of an [`Expr`]. Operands are on the stack, the last pushed on top; jumps name
/// the index of the operation to go on with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Op {
    /// Push a number.
    Const(f64),
    /// Push a slot's value (an input, parameter, attribute, derived value, `u` or `v`).
    Slot(usize),
    /// Negate the top.
    Neg,
    /// The top to 1 when it is 0 (or NaN), else to 0.
    Not,
    /// The top to 1 when it is not 0 (and not NaN), else to 0.
    Truth,
    /// Pop the top two, push the operator's value. Never `And` or `Or` (see below).
    Bin(Bin),
    /// `a && b` after `a`: when the top is false it becomes 0 and the run jumps past `b`;
    /// else it is popped and `b` follows (then `Truth`).
    AndThen(usize),
    /// `a || b` after `a`: when the top is true it becomes 1 and the run jumps past `b`.
    OrElse(usize),
    /// Pop the top; jump when it is false (an `if` to its else branch).
    JumpUnless(usize),
    /// Jump (an `if`'s then branch past the else branch).
    Jump(usize),
    /// Pop the top `n` values (the arguments, first pushed first) and push the function's.
    Call(Func, usize),
}
/// Whether a value counts as true: not 0 and not NaN.
fn truth(x: f64) -> bool {
    x != 0.0 && !x.is_nan()
}

/// 1 or 0.
fn t(c: bool) -> f64 {
    f64::from(u8::from(c))
}

/// Values an expression may hold on its stack without allocating; deeper ones (nested more
/// than a person writes) get a vector.
pub(super) const STACK: usize = 16;
/// Runs `ops` on `stack` (at least as deep as the expression needs).
pub(super) fn run(ops: &[Op], slots: &[f64], lot: &dyn Lot, stack: &mut [f64]) -> f64 {
    // `top` values are on the stack; `pc` is the next operation.
    let (mut top, mut pc) = (0, 0);
    while let Some(&op) = ops.get(pc) {
        pc += 1;
        match op {
            Op::Const(c) => {
                stack[top] = c;
                top += 1;
            }
            Op::Slot(i) => {
                stack[top] = slots[i];
                top += 1;
            }
            Op::Neg => stack[top - 1] = -stack[top - 1],
            Op::Not => stack[top - 1] = t(!truth(stack[top - 1])),
            Op::Truth => stack[top - 1] = t(truth(stack[top - 1])),
            Op::Bin(op) => {
                top -= 1;
                stack[top - 1] = binary(op, stack[top - 1], stack[top]);
            }
            Op::AndThen(to) => {
                if truth(stack[top - 1]) {
                    top -= 1;
                } else {
                    stack[top - 1] = 0.0;
                    pc = to;
                }
            }
            Op::OrElse(to) => {
                if truth(stack[top - 1]) {
                    stack[top - 1] = 1.0;
                    pc = to;
                } else {
                    top -= 1;
                }
            }
            Op::JumpUnless(to) => {
                top -= 1;
                if !truth(stack[top]) {
                    pc = to;
                }
            }
            Op::Jump(to) => pc = to,
            Op::Call(f, n) => {
                let x = call(f, &stack[top - n..top], lot);
                top -= n;
                stack[top] = x;
                top += 1;
            }
        }
    }
    stack[0]
}

/// A binary operator. A compiled program never meets `And` or `Or` here (it jumps past the
/// right side instead); the test's tree evaluator does, with both sides evaluated.
fn binary(op: Bin, x: f64, y: f64) -> f64 {
    match op {
        Bin::Add => x + y,
        Bin::Sub => x - y,
        Bin::Mul => x * y,
        Bin::Div => x / y,
        Bin::Rem => x % y,
        Bin::Pow => x.powf(y),
        Bin::Eq => t(x == y),
        Bin::Ne => t(x != y),
        Bin::Gt => t(x > y),
        Bin::Lt => t(x < y),
        Bin::Ge => t(x >= y),
        Bin::Le => t(x <= y),
        Bin::And => t(truth(x) && truth(y)),
        Bin::Or => t(truth(x) || truth(y)),
    }
}

/// A function of its arguments (their number checked when compiled). A compiled `if`
/// jumps instead; the test's tree evaluator comes here with all three evaluated.
fn call(f: Func, args: &[f64], lot: &dyn Lot) -> f64 {
    match f {
        Func::Min => args.iter().copied().fold(f64::INFINITY, nan_min),
        Func::Max => args.iter().copied().fold(f64::NEG_INFINITY, nan_max),
        Func::Floor => args[0].floor(),
        Func::Ceil => args[0].ceil(),
        Func::Round => args[0].round(),
        Func::Abs => args[0].abs(),
        Func::Sqrt => args[0].sqrt(),
        Func::Sin => args[0].sin(),
        Func::Cos => args[0].cos(),
        Func::Tan => args[0].tan(),
        Func::Atan2 => args[0].atan2(args[1]),
        Func::Clamp => nan_min(nan_max(args[0], args[1]), args[2]),
        Func::LotU0 => lot.extent_at(args[0]).0,
        Func::LotU1 => lot.extent_at(args[0]).1,
        Func::If => {
            if truth(args[0]) {
                args[1]
            } else {
                args[2]
            }
        }
    }
}

/// Writes a tree's operations, keeping count of the stack's depth.
#[derive(Default)]
pub(super) struct Emit {
    pub(super) ops: Vec<Op>,
    depth: usize,
    pub(super) max: usize,
}

impl Emit {
    fn push(&mut self, op: Op, depth_after: usize) {
        self.ops.push(op);
        self.depth = depth_after;
        self.max = self.max.max(depth_after);
    }

    /// Emits `tree`: its value ends up on top, one deeper than before.
    pub(super) fn tree(&mut self, tree: &Tree) {
        let d = self.depth;
        match tree {
            Tree::Const(c) => self.push(Op::Const(*c), d + 1),
            Tree::Slot(i) => self.push(Op::Slot(*i), d + 1),
            Tree::Neg(a) => {
                self.tree(a);
                self.push(Op::Neg, d + 1);
            }
            Tree::Not(a) => {
                self.tree(a);
                self.push(Op::Not, d + 1);
            }
            Tree::Bin(op @ (Bin::And | Bin::Or), a, b) => {
                // `and` / `or` evaluate their right side only when needed, like `if`.
                self.tree(a);
                let at = self.ops.len();
                self.push(Op::Jump(0), d);
                self.tree(b);
                self.push(Op::Truth, d + 1);
                let end = self.ops.len();
                self.ops[at] = match op {
                    Bin::And => Op::AndThen(end),
                    _ => Op::OrElse(end),
                };
            }
            Tree::Bin(op, a, b) => {
                self.tree(a);
                self.tree(b);
                self.push(Op::Bin(*op), d + 1);
            }
            Tree::Call(Func::If, args) => {
                self.tree(&args[0]);
                let unless = self.ops.len();
                self.push(Op::JumpUnless(0), d);
                self.tree(&args[1]);
                let jump = self.ops.len();
                self.push(Op::Jump(0), d + 1);
                self.depth = d;
                self.ops[unless] = Op::JumpUnless(self.ops.len());
                self.tree(&args[2]);
                self.ops[jump] = Op::Jump(self.ops.len());
            }
            Tree::Call(f, args) => {
                args.iter().for_each(|a| self.tree(a));
                self.push(Op::Call(*f, args.len()), d + 1);
            }
        }
    }
}

/// `min` that lets NaN through (f64::min would hide it), so a broken template is reported.
fn nan_min(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.min(b)
    }
}

fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}
#[cfg(test)]
mod tests {
    use super::*;
    use crate::templates::expr::{compile, Expr, NoLot, FUNCTIONS};

    #[test]
    fn nesting_deeper_than_the_stack_still_evaluates() {
        // Right-nested sums keep every left operand on the stack: 40 deep.
        let text = format!("{}a{}", "1 + (".repeat(40), ")".repeat(40));
        let e = compile(&text, &|n| (n == "a").then_some(0)).unwrap();
        assert!(e.depth > STACK, "{}", e.depth);
        assert_eq!(e.eval(&[2.0], &NoLot), 42.0);
    }

    /// The boxed tree evaluated node by node, as `Expr` did before it was flattened: what
    /// the flat program must give, bit for bit.
    fn reference(tree: &Tree, slots: &[f64], lot: &dyn Lot) -> f64 {
        let r = |x: &Tree| reference(x, slots, lot);
        match tree {
            Tree::Const(c) => *c,
            Tree::Slot(i) => slots[*i],
            Tree::Neg(a) => -r(a),
            Tree::Not(a) => t(!truth(r(a))),
            Tree::Bin(Bin::And, a, b) => t(truth(r(a)) && truth(r(b))),
            Tree::Bin(Bin::Or, a, b) => t(truth(r(a)) || truth(r(b))),
            Tree::Bin(op, a, b) => binary(*op, r(a), r(b)),
            Tree::Call(Func::If, args) => {
                if truth(r(&args[0])) {
                    r(&args[1])
                } else {
                    r(&args[2])
                }
            }
            Tree::Call(f, args) => call(*f, &args.iter().map(r).collect::<Vec<_>>(), lot),
        }
    }

    /// A lot whose extent at depth v is (v - 1, 2v).
    struct Slanted;

    impl Lot for Slanted {
        fn extent_at(&self, v: f64) -> (f64, f64) {
            (v - 1.0, 2.0 * v)
        }
    }

    fn trees() -> impl proptest::strategy::Strategy<Value = Tree> {
        use proptest::prelude::*;
        let leaf = prop_oneof![
            prop::sample::select(vec![0.0, -0.0, 1.0, 2.5, -3.0, f64::NAN, f64::INFINITY])
                .prop_map(Tree::Const),
            (0..3usize).prop_map(Tree::Slot),
        ];
        let bins = vec![
            Bin::Add,
            Bin::Sub,
            Bin::Mul,
            Bin::Div,
            Bin::Rem,
            Bin::Pow,
            Bin::Eq,
            Bin::Ne,
            Bin::Gt,
            Bin::Lt,
            Bin::Ge,
            Bin::Le,
            Bin::And,
            Bin::Or,
        ];
        leaf.prop_recursive(6, 64, 4, move |inner| {
            prop_oneof![
                inner.clone().prop_map(|a| Tree::Neg(Box::new(a))),
                inner.clone().prop_map(|a| Tree::Not(Box::new(a))),
                (
                    prop::sample::select(bins.clone()),
                    inner.clone(),
                    inner.clone()
                )
                    .prop_map(|(op, a, b)| Tree::Bin(op, Box::new(a), Box::new(b))),
                (
                    prop::sample::select(FUNCTIONS.to_vec()),
                    prop::collection::vec(inner, 1..4)
                )
                    .prop_map(|((_, f, arity), mut args)| {
                        // Cycle the arguments to the function's count.
                        let n = arity.unwrap_or(args.len());
                        args = args.iter().cycle().take(n).cloned().collect();
                        Tree::Call(f, args)
                    }),
            ]
        })
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig {
            rng_seed: proptest::test_runner::RngSeed::Fixed(2008),
            ..proptest::prelude::ProptestConfig::with_cases(2000)
        })]
        #[test]
        fn the_flat_program_gives_what_the_tree_gives(tree in trees(), a in -5.0..5.0f64) {
            let slots = [a, 0.0, f64::NAN];
            let want = reference(&tree, &slots, &Slanted);
            let got = Expr::of(&tree).eval(&slots, &Slanted);
            proptest::prop_assert!(
                got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                "{tree:?}: {got} vs {want}"
            );
        }
    }
}
