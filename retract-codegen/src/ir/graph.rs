//! A flat, hash-consed expression DAG over f64.
//!
//! Nodes live in one `Vec`, children before parents; inserting a node that exists returns
//! its id, so common subexpressions are shared by construction. Constructors simplify:
//! constant folding, `x + 0`, `x * 1`, `x * 0`, `-(-x)`, `x - x`, `x^0`, `x^1`, and
//! commutative operands in a canonical order.
//!
//! While the user's function is lowered ([`Graph::keep_domain`]), folds that would change
//! it where it is not finite are not made: `x / x`, `0 / x` stay unless `x` is a constant,
//! and `0 * x`, `x - x`, `(x - b) + b` and `a - (a - c)` unless the expression folded away is
//! total (finite wherever the jet is: no division, negative power, `powf`, or function with a
//! restricted domain). The derivatives built afterwards fold freely: they are needed only
//! where the function is finite.
//!
//! A graph holds at most [`MAX_NODES`] nodes: past that it stops growing (constructors return
//! an existing node) and [`Graph::overflowed`] tells the pipeline to end the expansion with an
//! error, so that an expansion too large to compile ends in seconds instead of building
//! millions of nodes.

use std::collections::HashMap;

/// The most nodes one expansion may build. The largest expansions in the repository (the
/// 12-link chain from T - V: 268 585 nodes, 0.8 s) stay well below it; a graph of this size
/// takes about 5 s to build and emits code rustc would take minutes to compile.
pub const MAX_NODES: usize = 1_000_000;

/// Index of a node in a [`Graph`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Id(pub u32);

/// A leaf symbol.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Var {
    /// Component `index` of the derivative q^(order).
    Jet { order: u8, index: u32 },
    /// Component `index` of parameter `param` (0 for a scalar).
    Param { param: u32, index: u32 },
    /// Component `index` of the current element of the slice parameter `param`.
    Elem { param: u32, index: u32 },
    /// Component of the state z_0 at the start of a step.
    Z0(u32),
    /// Component of the Newton unknowns w = (z_1, u) of a step.
    W(u32),
    /// The step size h.
    Step,
    /// The scheme parameter theta.
    Theta,
    /// Core variable m of the reduced step: the value at the evaluation point of a jet
    /// component on which the Hessian of L depends.
    Core(u32),
    /// Component `index` of block `block` of the covector w1 (`side` 0) or w2 (`side` 1)
    /// that contracts a discretization map's points (`#[discretization_map]`).
    Covector { side: u8, block: u8, index: u32 },
    /// Component `index` (`j * n + i` for q^(j)_i) of a direction d in the jet (x, u), for a
    /// Hessian-vector product H d.
    Direction(u32),
    /// Value `index` of the values computed before the emitted code (named `__h`): the nodes
    /// evaluated once before a run-time loop, in code that the loop repeats (the Hessian's
    /// columns), or the entries of the reduced step's cached factor K (`Reduced::scaled`).
    Hoisted(u32),
}

/// A unary function.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Func {
    Sqrt,
    Exp,
    Ln,
    Sin,
    Cos,
    Tan,
    Tanh,
    Abs,
    Signum,
    Asin,
    Acos,
    Atan,
    Sinh,
    Cosh,
    Cbrt,
    Ln1p,
    ExpM1,
    Log2,
    Log10,
    /// The Stumpff function c_k (`retract::stumpff(k, s)`), entire in s.
    Stumpff(u8),
}

impl Func {
    /// The f64 method that computes it.
    pub fn method(self) -> &'static str {
        match self {
            Func::Sqrt => "sqrt",
            Func::Exp => "exp",
            Func::Ln => "ln",
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Tanh => "tanh",
            Func::Abs => "abs",
            Func::Signum => "signum",
            Func::Asin => "asin",
            Func::Acos => "acos",
            Func::Atan => "atan",
            Func::Sinh => "sinh",
            Func::Cosh => "cosh",
            Func::Cbrt => "cbrt",
            Func::Ln1p => "ln_1p",
            Func::ExpM1 => "exp_m1",
            Func::Log2 => "log2",
            Func::Log10 => "log10",
            Func::Stumpff(_) => "stumpff",
        }
    }

    pub(crate) fn eval(self, x: f64) -> f64 {
        match self {
            Func::Sqrt => x.sqrt(),
            Func::Exp => x.exp(),
            Func::Ln => x.ln(),
            Func::Sin => x.sin(),
            Func::Cos => x.cos(),
            Func::Tan => x.tan(),
            Func::Tanh => x.tanh(),
            Func::Abs => x.abs(),
            Func::Signum => x.signum(),
            Func::Asin => x.asin(),
            Func::Acos => x.acos(),
            Func::Atan => x.atan(),
            Func::Sinh => x.sinh(),
            Func::Cosh => x.cosh(),
            Func::Cbrt => x.cbrt(),
            Func::Ln1p => x.ln_1p(),
            Func::ExpM1 => x.exp_m1(),
            Func::Log2 => x.log2(),
            Func::Log10 => x.log10(),
            Func::Stumpff(k) => stumpff_value(k, x),
        }
    }
}

/// c_k(s) = sum_m (-s)^m / (2m + k)! at compile time (a constant argument; the generated
/// code calls `retract::stumpff`): the series, summed until a term no longer changes the sum,
/// where |s| <= max(4, (k+1)(k+2)) (its terms fall from the first, little cancels); beyond,
/// c_0 = cos x, c_1 = sin x / x or c_2 = 2 sin(x/2)^2 / s (x = sqrt s; cosh and sinh for
/// s < 0) raised by c_{j+2} = (1/j! - c_j) / s, stable there.
fn stumpff_value(k: u8, s: f64) -> f64 {
    let k = u32::from(k);
    let inverse_factorial = |j: u32| 1.0 / (2..=j).fold(1.0, |f, i| f * f64::from(i));
    let kf = f64::from(k);
    if s.abs() <= 4f64.max((kf + 1.0) * (kf + 2.0)) || s.is_nan() {
        let mut term = inverse_factorial(k);
        let mut sum = term;
        for m in 0..500u32 {
            let a = f64::from(2 * m + k + 1);
            term *= -s / (a * (a + 1.0));
            if sum + term == sum {
                break;
            }
            sum += term;
        }
        return sum;
    }
    let x = s.abs().sqrt();
    let (c0, c1, c2) = if s > 0.0 {
        (x.cos(), x.sin() / x, 2.0 * (x / 2.0).sin().powi(2) / s)
    } else {
        (x.cosh(), x.sinh() / x, -2.0 * (x / 2.0).sinh().powi(2) / s)
    };
    let (mut j, mut c) = match k {
        0 => (0, c0),
        _ if k % 2 == 1 => (1, c1),
        _ => (2, c2),
    };
    while j < k {
        c = (inverse_factorial(j) - c) / s;
        j += 2;
    }
    c
}

/// A node of the DAG.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Node {
    /// A constant, stored by its bits.
    Const(u64),
    /// A symbol.
    Var(Var),
    /// An opaque constant named by a path of the user's crate (index into `Graph::named`).
    Named(u32),
    Add(Id, Id),
    Sub(Id, Id),
    Mul(Id, Id),
    Div(Id, Id),
    Neg(Id),
    Powi(Id, i32),
    /// `base.powf(exponent)` with an exponent that does not depend on the jet.
    Powf(Id, Id),
    Unary(Func, Id),
    /// `y.atan2(x)` as `Atan2(y, x)`.
    Atan2(Id, Id),
    Hypot(Id, Id),
    /// Sum over the elements of slice parameter `param` of `body` (which may use
    /// `Var::Elem { param, .. }`), evaluated by a run-time loop.
    Sum {
        param: u32,
        body: Id,
    },
}

/// The DAG.
#[derive(Default, Debug)]
pub struct Graph {
    nodes: Vec<Node>,
    /// Whether each node is total (module docs), by id.
    total: Vec<bool>,
    index: HashMap<Node, Id>,
    /// Folds keep the function's domain (module docs): set while the user's function is
    /// lowered.
    pub keep_domain: bool,
    /// Source text of the named constants (paths), for emission.
    pub named: Vec<String>,
    /// Whether a node was refused because the graph holds [`MAX_NODES`].
    overflowed: bool,
}

impl Graph {
    /// The node behind `id`.
    pub fn node(&self, id: Id) -> &Node {
        &self.nodes[id.0 as usize]
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether a node was refused because the graph reached [`MAX_NODES`]: the graph no
    /// longer computes what was asked of it, and the expansion must end with an error.
    pub fn overflowed(&self) -> bool {
        self.overflowed
    }

    /// The values of the nodes up to `root` (children before parents), with the symbols and
    /// named constants given by `leaf`; `None` where a leaf has no value (and above it). Not
    /// for sums over slices (`None`).
    pub fn evaluate(&self, root: Id, leaf: &dyn Fn(&Node) -> Option<f64>) -> Vec<Option<f64>> {
        let mut values: Vec<Option<f64>> = Vec::with_capacity(root.0 as usize + 1);
        for i in 0..=root.0 as usize {
            let node = &self.nodes[i];
            let at = |id: Id| values[id.0 as usize];
            let value = match *node {
                Node::Const(bits) => Some(f64::from_bits(bits)),
                Node::Var(_) | Node::Named(_) => leaf(node),
                Node::Sum { .. } => None,
                Node::Neg(a) => at(a).map(|a| -a),
                Node::Powi(a, n) => at(a).map(|a| a.powi(n)),
                Node::Unary(f, a) => at(a).map(|a| f.eval(a)),
                Node::Add(a, b) => at(a).zip(at(b)).map(|(a, b)| a + b),
                Node::Sub(a, b) => at(a).zip(at(b)).map(|(a, b)| a - b),
                Node::Mul(a, b) => at(a).zip(at(b)).map(|(a, b)| a * b),
                Node::Div(a, b) => at(a).zip(at(b)).map(|(a, b)| a / b),
                Node::Powf(a, b) => at(a).zip(at(b)).map(|(a, b)| a.powf(b)),
                Node::Atan2(a, b) => at(a).zip(at(b)).map(|(a, b)| a.atan2(b)),
                Node::Hypot(a, b) => at(a).zip(at(b)).map(|(a, b)| a.hypot(b)),
            };
            values.push(value);
        }
        values
    }

    fn add(&mut self, node: Node) -> Id {
        if let Some(&id) = self.index.get(&node) {
            return id;
        }
        if self.nodes.len() >= MAX_NODES {
            // any existing node will do: the caller reports `overflowed` and drops the graph
            self.overflowed = true;
            return Id(0);
        }
        let id = Id(self.nodes.len() as u32);
        for child in children(&node) {
            assert!(child < id, "children before parents");
        }
        let total = self.node_is_total(&node);
        self.nodes.push(node.clone());
        self.total.push(total);
        self.index.insert(node, id);
        id
    }

    /// Whether `node` is finite wherever its children are and the jet is (finite constants,
    /// symbols, `+ - *`, non-negative powers, entire functions; `exp` counts though it
    /// overflows).
    fn node_is_total(&self, node: &Node) -> bool {
        let all = |ids: &[Id]| ids.iter().all(|c| self.total[c.0 as usize]);
        match node {
            Node::Const(bits) => f64::from_bits(*bits).is_finite(),
            Node::Var(_) | Node::Named(_) => true,
            Node::Add(a, b) | Node::Sub(a, b) | Node::Mul(a, b) => all(&[*a, *b]),
            Node::Atan2(a, b) | Node::Hypot(a, b) => all(&[*a, *b]),
            Node::Neg(a) => all(&[*a]),
            Node::Powi(a, n) => *n >= 0 && all(&[*a]),
            Node::Unary(f, a) => {
                let entire = matches!(
                    f,
                    Func::Exp
                        | Func::Sin
                        | Func::Cos
                        | Func::Tanh
                        | Func::Abs
                        | Func::Signum
                        | Func::Atan
                        | Func::Sinh
                        | Func::Cosh
                        | Func::Cbrt
                        | Func::ExpM1
                        | Func::Stumpff(_)
                );
                entire && all(&[*a])
            }
            Node::Sum { body, .. } => all(&[*body]),
            Node::Div(..) | Node::Powf(..) => false,
        }
    }

    /// Whether folding `id` away keeps the function (always, unless [`Self::keep_domain`]
    /// asks for a total `id`).
    fn foldable(&self, id: Id) -> bool {
        !self.keep_domain || self.total[id.0 as usize]
    }

    /// The constant `value`, by its bits: `-0.0` stays negative (`1 / -0.0` is `-inf`) and
    /// NaN stays NaN, so that folding constants computes exactly what f64 does.
    pub fn constant(&mut self, value: f64) -> Id {
        self.add(Node::Const(value.to_bits()))
    }

    /// The value of a constant node.
    pub fn as_const(&self, id: Id) -> Option<f64> {
        match self.node(id) {
            Node::Const(bits) => Some(f64::from_bits(*bits)),
            _ => None,
        }
    }

    /// Whether `id` is the constant `value`.
    pub fn is_const(&self, id: Id, value: f64) -> bool {
        self.as_const(id) == Some(value)
    }

    /// Whether `id` is a constant that is infinite or NaN.
    fn is_non_finite(&self, id: Id) -> bool {
        self.as_const(id).is_some_and(|v| !v.is_finite())
    }

    /// A symbol.
    pub fn var(&mut self, var: Var) -> Id {
        self.add(Node::Var(var))
    }

    /// A named constant with source text `path`.
    pub fn named(&mut self, path: String) -> Id {
        let index = match self.named.iter().position(|p| *p == path) {
            Some(i) => i,
            None => {
                self.named.push(path);
                self.named.len() - 1
            }
        };
        self.add(Node::Named(index as u32))
    }

    pub fn add_op(&mut self, a: Id, b: Id) -> Id {
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => return self.constant(x + y),
            (Some(0.0), _) => return b,
            (_, Some(0.0)) => return a,
            _ => {}
        }
        if let Node::Neg(nb) = *self.node(b) {
            return self.sub(a, nb);
        }
        if let Node::Neg(na) = *self.node(a) {
            return self.sub(b, na);
        }
        // (x - b) + b = x (not for a constant b = inf or NaN: inf - inf is NaN)
        if let Node::Sub(x, c) = *self.node(a)
            && c == b
            && !self.is_non_finite(b)
            && self.foldable(b)
        {
            return x;
        }
        if let Node::Sub(x, c) = *self.node(b)
            && c == a
            && !self.is_non_finite(a)
            && self.foldable(a)
        {
            return x;
        }
        let (a, b) = if a <= b { (a, b) } else { (b, a) };
        self.add(Node::Add(a, b))
    }

    pub fn sub(&mut self, a: Id, b: Id) -> Id {
        // constants first: inf - inf and NaN - NaN are NaN, not 0
        if let (Some(x), Some(y)) = (self.as_const(a), self.as_const(b)) {
            return self.constant(x - y);
        }
        if a == b && self.foldable(a) {
            return self.constant(0.0);
        }
        match (self.as_const(a), self.as_const(b)) {
            (Some(0.0), _) => return self.neg(b),
            (_, Some(0.0)) => return a,
            _ => {}
        }
        if let Node::Neg(nb) = *self.node(b) {
            return self.add_op(a, nb);
        }
        // a - (a - c) = c and (a - c) - a = -c (not for a constant a = inf or NaN)
        if let Node::Sub(x, c) = *self.node(b)
            && x == a
            && !self.is_non_finite(a)
            && self.foldable(a)
        {
            return c;
        }
        if let Node::Sub(x, c) = *self.node(a)
            && x == b
            && !self.is_non_finite(b)
            && self.foldable(b)
        {
            return self.neg(c);
        }
        self.add(Node::Sub(a, b))
    }

    pub fn mul(&mut self, a: Id, b: Id) -> Id {
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => return self.constant(x * y),
            (Some(0.0), _) if self.foldable(b) => return self.constant(0.0),
            (_, Some(0.0)) if self.foldable(a) => return self.constant(0.0),
            (Some(1.0), _) => return b,
            (_, Some(1.0)) => return a,
            (Some(-1.0), _) => return self.neg(b),
            (_, Some(-1.0)) => return self.neg(a),
            _ => {}
        }
        // constants first, and c1 * (c2 * x) = (c1 c2) * x
        let (a, b) = if self.as_const(b).is_some() || (self.as_const(a).is_none() && b < a) {
            (b, a)
        } else {
            (a, b)
        };
        // only where c1 c2 neither overflows nor underflows, so that the value is that of
        // c1 * (c2 * x) up to rounding
        if let (Some(x), Node::Mul(c, rest)) = (self.as_const(a), self.node(b).clone())
            && let Some(y) = self.as_const(c)
            && (x * y).is_normal()
        {
            let folded = self.constant(x * y);
            return self.mul(folded, rest);
        }
        if let Node::Neg(na) = *self.node(a) {
            let m = self.mul(na, b);
            return self.neg(m);
        }
        if let Node::Neg(nb) = *self.node(b) {
            let m = self.mul(a, nb);
            return self.neg(m);
        }
        if a == b {
            return self.powi(a, 2);
        }
        self.add(Node::Mul(a, b))
    }

    pub fn div(&mut self, a: Id, b: Id) -> Id {
        match (self.as_const(a), self.as_const(b)) {
            // exactly as f64 evaluates it: 0 / 0 is NaN, x / 0 is +-inf
            (Some(x), Some(y)) => return self.constant(x / y),
            (Some(0.0), _) if !self.keep_domain => return self.constant(0.0),
            (_, Some(1.0)) => return a,
            (_, Some(-1.0)) => return self.neg(a),
            _ => {}
        }
        if a == b && !self.keep_domain {
            return self.constant(1.0);
        }
        self.add(Node::Div(a, b))
    }

    pub fn neg(&mut self, a: Id) -> Id {
        if let Some(x) = self.as_const(a) {
            return self.constant(-x);
        }
        match *self.node(a) {
            Node::Neg(inner) => inner,
            Node::Sub(x, y) => self.sub(y, x),
            _ => self.add(Node::Neg(a)),
        }
    }

    pub fn powi(&mut self, a: Id, n: i32) -> Id {
        match n {
            0 => return self.constant(1.0),
            1 => return a,
            _ => {}
        }
        if let Some(x) = self.as_const(a) {
            return self.constant(x.powi(n));
        }
        if let Node::Powi(base, m) = *self.node(a)
            && let Some(nm) = m.checked_mul(n)
        {
            return self.powi(base, nm);
        }
        self.add(Node::Powi(a, n))
    }

    pub fn powf(&mut self, a: Id, b: Id) -> Id {
        if let (Some(x), Some(y)) = (self.as_const(a), self.as_const(b)) {
            return self.constant(x.powf(y));
        }
        if let Some(y) = self.as_const(b) {
            if y == 0.0 {
                return self.constant(1.0);
            }
            if y == 1.0 {
                return a;
            }
            if y.fract() == 0.0 && y.abs() < 64.0 {
                return self.powi(a, y as i32);
            }
            if y == 0.5 {
                return self.unary(Func::Sqrt, a);
            }
        }
        self.add(Node::Powf(a, b))
    }

    pub fn unary(&mut self, f: Func, a: Id) -> Id {
        if let Some(x) = self.as_const(a) {
            return self.constant(f.eval(x));
        }
        self.add(Node::Unary(f, a))
    }

    pub fn atan2(&mut self, y: Id, x: Id) -> Id {
        if let (Some(a), Some(b)) = (self.as_const(y), self.as_const(x)) {
            return self.constant(a.atan2(b));
        }
        self.add(Node::Atan2(y, x))
    }

    pub fn hypot(&mut self, a: Id, b: Id) -> Id {
        if let (Some(x), Some(y)) = (self.as_const(a), self.as_const(b)) {
            return self.constant(x.hypot(y));
        }
        if self.is_const(a, 0.0) {
            return self.unary(Func::Abs, b);
        }
        if self.is_const(b, 0.0) {
            return self.unary(Func::Abs, a);
        }
        self.add(Node::Hypot(a, b))
    }

    pub fn sum(&mut self, param: u32, body: Id) -> Id {
        if self.is_const(body, 0.0) {
            return body;
        }
        self.add(Node::Sum { param, body })
    }
}

impl Graph {
    /// The degree of `id` as a polynomial in the jet (`Var::Jet`), with parameters, slice
    /// elements and named constants as constants: `None` where it is not a polynomial
    /// (a jet-dependent denominator, function, `powf`, `atan2`, `hypot`, a negative power, a
    /// sum over a slice or another symbol) or its degree exceeds `cap`.
    pub fn jet_degree(&self, id: Id, cap: u32) -> Option<u32> {
        let mut memo: HashMap<Id, Option<u32>> = HashMap::new();
        self.degree_memo(id, cap, &mut memo)
    }

    fn degree_memo(&self, id: Id, cap: u32, memo: &mut HashMap<Id, Option<u32>>) -> Option<u32> {
        if let Some(d) = memo.get(&id) {
            return *d;
        }
        let mut of = |c: Id| self.degree_memo(c, cap, memo);
        let degree = match *self.node(id) {
            Node::Const(_) | Node::Named(_) => Some(0),
            Node::Var(Var::Jet { .. }) => Some(1),
            Node::Var(Var::Param { .. } | Var::Elem { .. }) => Some(0),
            Node::Var(_) | Node::Sum { .. } => None,
            Node::Add(a, b) | Node::Sub(a, b) => of(a).zip(of(b)).map(|(a, b)| a.max(b)),
            Node::Mul(a, b) => of(a).zip(of(b)).map(|(a, b)| a + b),
            Node::Neg(a) => of(a),
            Node::Powi(a, n) => match (of(a), u32::try_from(n)) {
                (Some(0), _) => Some(0),
                (Some(d), Ok(n)) => d.checked_mul(n),
                _ => None,
            },
            Node::Div(a, b) => match (of(a), of(b)) {
                (Some(d), Some(0)) => Some(d),
                _ => None,
            },
            Node::Unary(_, a) => of(a).filter(|d| *d == 0),
            Node::Powf(a, b) | Node::Atan2(a, b) | Node::Hypot(a, b) => of(a)
                .zip(of(b))
                .filter(|(a, b)| *a == 0 && *b == 0)
                .map(|_| 0),
        };
        let degree = degree.filter(|d| *d <= cap);
        memo.insert(id, degree);
        degree
    }
}

/// The children of a node, in order.
pub fn children(node: &Node) -> Vec<Id> {
    match *node {
        Node::Const(_) | Node::Var(_) | Node::Named(_) => vec![],
        Node::Neg(a) | Node::Powi(a, _) | Node::Unary(_, a) => vec![a],
        Node::Sum { body, .. } => vec![body],
        Node::Add(a, b)
        | Node::Sub(a, b)
        | Node::Mul(a, b)
        | Node::Div(a, b)
        | Node::Powf(a, b)
        | Node::Atan2(a, b)
        | Node::Hypot(a, b) => vec![a, b],
    }
}

#[cfg(test)]
pub mod tests {
    use super::*;

    /// A test-only printer: fully parenthesised infix.
    pub fn show(g: &Graph, id: Id) -> String {
        match g.node(id).clone() {
            Node::Const(bits) => format!("{}", f64::from_bits(bits)),
            Node::Var(Var::Jet { order, index }) => format!("q{order}_{index}"),
            Node::Var(v) => format!("{v:?}"),
            Node::Named(i) => g.named[i as usize].clone(),
            Node::Add(a, b) => format!("({} + {})", show(g, a), show(g, b)),
            Node::Sub(a, b) => format!("({} - {})", show(g, a), show(g, b)),
            Node::Mul(a, b) => format!("({} * {})", show(g, a), show(g, b)),
            Node::Div(a, b) => format!("({} / {})", show(g, a), show(g, b)),
            Node::Neg(a) => format!("-{}", show(g, a)),
            Node::Powi(a, n) => format!("{}^{n}", show(g, a)),
            Node::Powf(a, b) => format!("{}^{}", show(g, a), show(g, b)),
            Node::Unary(f, a) => format!("{}({})", f.method(), show(g, a)),
            Node::Atan2(a, b) => format!("atan2({}, {})", show(g, a), show(g, b)),
            Node::Hypot(a, b) => format!("hypot({}, {})", show(g, a), show(g, b)),
            Node::Sum { param, body } => format!("sum{param}[{}]", show(g, body)),
        }
    }

    fn q(g: &mut Graph, i: u32) -> Id {
        g.var(Var::Jet { order: 0, index: i })
    }

    #[test]
    fn compile_time_stumpff_values_are_the_closed_forms() {
        let value = |k, s| Func::Stumpff(k).eval(s);
        assert!((value(0, 2500.0) - 50f64.cos()).abs() < 1e-14);
        assert!((value(1, 1e4) - 100f64.sin() / 100.0).abs() < 1e-16);
        assert!((value(2, 0.49) - (1.0 - 0.7f64.cos()) / 0.49).abs() < 1e-15);
        assert!((value(3, -16.0) - (4f64.sinh() - 4.0) / 64.0).abs() < 1e-15);
        assert!((value(4, 1e6) - (1.0 / 2.0 - value(2, 1e6)) / 1e6).abs() < 1e-20);
        assert_eq!(value(3, 0.0), 1.0 / 6.0);
    }

    #[test]
    fn jet_degrees_of_polynomials_and_the_rest() {
        let mut g = Graph::default();
        let (x, y) = (q(&mut g, 0), q(&mut g, 1));
        let r = g.var(Var::Param { param: 0, index: 0 });
        // x^2 + y^2 - r^2, and (x - r) / r
        let (x2, y2, r2) = (g.powi(x, 2), g.powi(y, 2), g.powi(r, 2));
        let sum = g.add_op(x2, y2);
        let disc = g.sub(sum, r2);
        let shifted = g.sub(x, r);
        let scaled = g.div(shifted, r);
        assert_eq!(g.jet_degree(disc, 2), Some(2));
        assert_eq!(g.jet_degree(scaled, 2), Some(1));
        // x^3 is above the cap; 1 / x, sin x and x^-1 are not polynomials; sin r is constant
        let cube = g.powi(x, 3);
        assert_eq!(g.jet_degree(cube, 2), None);
        assert_eq!(g.jet_degree(cube, 3), Some(3));
        let one = g.constant(1.0);
        let inverse = g.div(one, x);
        let sine = g.unary(Func::Sin, x);
        let negative = g.powi(x, -1);
        let constant = g.unary(Func::Sin, r);
        assert_eq!(g.jet_degree(inverse, 2), None);
        assert_eq!(g.jet_degree(sine, 2), None);
        assert_eq!(g.jet_degree(negative, 2), None);
        let product = g.mul(constant, disc);
        assert_eq!(g.jet_degree(product, 2), Some(2));
    }

    #[test]
    fn hash_consing_shares_nodes() {
        let mut g = Graph::default();
        let a = q(&mut g, 0);
        let b = q(&mut g, 1);
        let s1 = g.add_op(a, b);
        let s2 = g.add_op(b, a);
        assert_eq!(s1, s2);
        assert_eq!(g.len(), 3);
    }

    #[test]
    fn identities_simplify() {
        let mut g = Graph::default();
        let x = q(&mut g, 0);
        let zero = g.constant(0.0);
        let one = g.constant(1.0);
        let two = g.constant(2.0);
        let three = g.constant(3.0);
        let cases = [
            (g.add_op(x, zero), "q0_0"),
            (g.mul(one, x), "q0_0"),
            (g.mul(x, zero), "0"),
            (g.sub(x, x), "0"),
            (g.mul(two, three), "6"),
            (g.powi(x, 1), "q0_0"),
            (g.mul(x, x), "q0_0^2"),
        ];
        for (id, want) in cases {
            assert_eq!(show(&g, id), want);
        }
        let m = g.mul(three, x);
        let mm = g.mul(two, m);
        assert_eq!(show(&g, mm), "(6 * q0_0)");
        let n = g.neg(x);
        let nn = g.neg(n);
        assert_eq!(nn, x);
    }

    /// While the user's function is lowered, `x / x`, `0 * (1 / x)`, `0 / x` and `y - y`,
    /// `(2 - y) + y` for y = 1 / x stay (they are NaN at x = 0, as the function is); folds
    /// of total expressions (`0 * sin x`, `x - x`) and every fold after the lowering are made.
    #[test]
    fn folds_keep_the_domain_while_the_function_is_lowered() {
        let mut g = Graph::default();
        let x = q(&mut g, 0);
        let (zero, one, c) = (g.constant(0.0), g.constant(1.0), g.constant(2.0));
        g.keep_domain = true;
        let y = g.div(one, x);
        let kept = [
            (g.div(x, x), "(q0_0 / q0_0)"),
            (g.mul(zero, y), "(0 * (1 / q0_0))"),
            (g.div(zero, x), "(0 / q0_0)"),
            (g.sub(y, y), "((1 / q0_0) - (1 / q0_0))"),
        ];
        for (id, want) in kept {
            assert_eq!(show(&g, id), want);
        }
        let shifted = g.sub(c, y);
        assert_ne!(g.add_op(shifted, y), c);
        let sine = g.unary(Func::Sin, x);
        let folded = g.mul(zero, sine);
        assert!(g.is_const(folded, 0.0));
        let folded = g.sub(x, x);
        assert!(g.is_const(folded, 0.0));
        g.keep_domain = false;
        let folded = g.div(x, x);
        assert!(g.is_const(folded, 1.0));
        let folded = g.mul(zero, y);
        assert!(g.is_const(folded, 0.0));
        let folded = g.sub(y, y);
        assert!(g.is_const(folded, 0.0));
        assert_eq!(g.add_op(shifted, y), c);
    }
}
