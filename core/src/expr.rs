//! Smooth time functions written as expressions, `{ expr = "…" }`: parsed
//! once into a tree and evaluated over any dual number, so that a prescribed
//! motion's velocity and acceleration are the exact derivatives of its
//! position (second-order duals of num-dual), never finite differences.
//!
//! Grammar (usual precedence, `^` right-associative and above unary minus,
//! so `-2^2 = -4`):
//!
//! ```text
//! expr  := or
//! or    := and ("||" and)*
//! and   := cmp ("&&" cmp)*
//! cmp   := sum (("<" | "<=" | ">" | ">=" | "==" | "!=") sum)?
//! sum   := term (("+" | "-") term)*
//! term  := unary (("*" | "/") unary)*
//! unary := ("-" | "+" | "!") unary | power
//! power := atom ("^" unary)?
//! atom  := number | name | name "(" expr ("," expr)* ")" | "(" expr ")"
//! ```
//!
//! Names: the variable — `t` for time functions (in statics also `lambda`,
//! the load factor), `psi` for the released translation of an expression
//! joint ([`Expression::parse_with`]) — the constants `pi` and `e`, the
//! named parameters given with the text; functions `sin cos tan asin acos atan sinh cosh
//! tanh exp ln log sqrt abs` (one argument), `atan2 min max pow` (two) and
//! `if(condition, a, b)` (a condition is true when non-zero; comparisons and
//! `&&`, `||`, `!` give 1 or 0 and have zero derivative). `min`, `max`,
//! `abs` and `if` take the derivative of the branch they choose.

use crate::{cst, Scalar};
use std::fmt;

/// A parsed expression of one variable and named parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Expression {
    text: String,
    root: Node,
    uses_lambda: bool,
    /// The named parameters' values, in the order of [`Node::Param`].
    parameters: Vec<(String, f64)>,
}

/// Why an expression was refused: the 0-based character where it went
/// wrong and what was expected.
#[derive(Debug, Clone, PartialEq)]
pub struct ExprError {
    /// Character position in the text (0-based).
    pub position: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for ExprError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "at character {}: {}", self.position + 1, self.message)
    }
}

/// Functions of one argument.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Fn1 {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sinh,
    Cosh,
    Tanh,
    Exp,
    Ln,
    Sqrt,
    Abs,
    Neg,
    Not,
}

/// Functions and operators of two arguments.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Fn2 {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Atan2,
    Min,
    Max,
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,
    And,
    Or,
}

#[derive(Debug, Clone, PartialEq)]
enum Node {
    Number(f64),
    Var,
    /// A named parameter (index into [`Expression::parameters`]).
    Param(usize),
    Call1(Fn1, Box<Node>),
    Call2(Fn2, Box<Node>, Box<Node>),
    If(Box<Node>, Box<Node>, Box<Node>),
}

const FUNCTIONS_1: [(&str, Fn1); 13] = [
    ("sin", Fn1::Sin),
    ("cos", Fn1::Cos),
    ("tan", Fn1::Tan),
    ("asin", Fn1::Asin),
    ("acos", Fn1::Acos),
    ("atan", Fn1::Atan),
    ("sinh", Fn1::Sinh),
    ("cosh", Fn1::Cosh),
    ("tanh", Fn1::Tanh),
    ("exp", Fn1::Exp),
    ("ln", Fn1::Ln),
    ("sqrt", Fn1::Sqrt),
    ("abs", Fn1::Abs),
];
const FUNCTIONS_2: [(&str, Fn2); 4] = [
    ("atan2", Fn2::Atan2),
    ("min", Fn2::Min),
    ("max", Fn2::Max),
    ("pow", Fn2::Pow),
];

/// The constants and functions a user may write, for the "unknown name"
/// message (after the variable and the parameters).
const NAMES: &str = "pi, e, sin, cos, tan, asin, acos, atan, atan2, sinh, cosh, tanh, exp, ln, \
                     log, sqrt, abs, min, max, pow, if";

/// Whether `name` is taken by the expression language — a variable (`t`,
/// `lambda`, `psi`), a constant or a function — so that a parameter may
/// not be called so.
pub fn reserved(name: &str) -> bool {
    matches!(name, "t" | "lambda" | "psi" | "pi" | "e" | "log" | "if")
        || FUNCTIONS_1.iter().any(|(n, _)| *n == name)
        || FUNCTIONS_2.iter().any(|(n, _)| *n == name)
}

impl Expression {
    /// Parses a time function's `text`: the variable is `t` (in statics also
    /// `lambda`, the load factor).
    pub fn parse(text: &str) -> Result<Self, ExprError> {
        Self::parse_with(text, "t", &[])
    }

    /// Parses `text` with the variable `variable` (`"t"` also accepts
    /// `lambda`) and the named constants `parameters`, which must not be
    /// [`reserved`] names (the caller checks; a reserved name here is never
    /// looked up).
    pub fn parse_with(
        text: &str,
        variable: &str,
        parameters: &[(String, f64)],
    ) -> Result<Self, ExprError> {
        let chars: Vec<char> = text.chars().collect();
        let mut p = Parser {
            chars: &chars,
            at: 0,
            uses_lambda: false,
            depth: 0,
            operators: 0,
            variable,
            parameters,
        };
        let root = p.or()?;
        p.skip_space();
        if p.at < chars.len() {
            return Err(p.error(format!(
                "unexpected `{}` after a complete expression",
                chars[p.at]
            )));
        }
        Ok(Self {
            text: text.to_string(),
            root,
            uses_lambda: p.uses_lambda,
            parameters: parameters.to_vec(),
        })
    }

    /// The named parameters and their values.
    pub fn parameters(&self) -> &[(String, f64)] {
        &self.parameters
    }

    /// The text it was parsed from.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// Whether it names `lambda` (a static analysis's load factor).
    pub fn uses_lambda(&self) -> bool {
        self.uses_lambda
    }

    /// The value at `t` (any dual number: its derivatives come along).
    pub fn eval<T: Scalar>(&self, t: T) -> T {
        eval(&self.root, &Params::Plain(&self.parameters), t)
    }

    /// The index of the named parameter `name`, if the expression was
    /// parsed with one.
    pub fn parameter(&self, name: &str) -> Option<usize> {
        self.parameters.iter().position(|(n, _)| n == name)
    }

    /// The value of parameter `k` ([`Expression::parameter`]).
    pub fn parameter_value(&self, k: usize) -> f64 {
        self.parameters[k].1
    }

    /// The value at `t` with parameter `param` taking `value` (a dual
    /// number seeded for it: the derivative by the parameter comes along).
    pub fn eval_seeded<T: Scalar>(&self, t: T, param: usize, value: T) -> T {
        eval(
            &self.root,
            &Params::Seeded(&self.parameters, param, value),
            t,
        )
    }

    /// The value and its first and second derivatives at `t`, exact (by
    /// second-order dual numbers).
    pub fn derivatives(&self, t: f64) -> (f64, f64, f64) {
        num_dual::second_derivative(|x| self.eval(x), t)
    }
}

fn truth<T: Scalar>(b: bool) -> T {
    cst(if b { 1.0 } else { 0.0 })
}

/// The parameters' values an evaluation takes: as parsed, or with one of
/// them replaced by a seeded dual number.
enum Params<'a, T> {
    Plain(&'a [(String, f64)]),
    Seeded(&'a [(String, f64)], usize, T),
}

impl<T: Scalar> Params<'_, T> {
    fn value(&self, i: usize) -> T {
        match self {
            Params::Seeded(_, k, v) if *k == i => *v,
            Params::Plain(p) | Params::Seeded(p, _, _) => cst(p[i].1),
        }
    }

    /// Whether `node` takes the seeded parameter (then it is no constant).
    fn seeds(&self, node: &Node) -> bool {
        match self {
            Params::Plain(_) => false,
            Params::Seeded(_, k, _) => node.uses_param(*k),
        }
    }

    fn values(&self) -> &[(String, f64)] {
        match self {
            Params::Plain(p) | Params::Seeded(p, _, _) => p,
        }
    }
}

fn eval<T: Scalar>(node: &Node, params: &Params<'_, T>, t: T) -> T {
    let eval = |node: &Node, t: T| eval(node, params, t);
    match node {
        Node::Number(v) => cst(*v),
        Node::Var => t,
        Node::Param(i) => params.value(*i),
        Node::Call1(f, a) => {
            let a = eval(a, t);
            match f {
                Fn1::Sin => a.sin(),
                Fn1::Cos => a.cos(),
                Fn1::Tan => a.tan(),
                Fn1::Asin => a.asin(),
                Fn1::Acos => a.acos(),
                Fn1::Atan => a.atan(),
                Fn1::Sinh => a.sinh(),
                Fn1::Cosh => a.cosh(),
                Fn1::Tanh => a.tanh(),
                Fn1::Exp => a.exp(),
                Fn1::Ln => a.ln(),
                Fn1::Sqrt => a.sqrt(),
                Fn1::Abs => {
                    if a.value() < 0.0 {
                        -a
                    } else {
                        a
                    }
                }
                Fn1::Neg => -a,
                Fn1::Not => truth(a.value() == 0.0),
            }
        }
        Node::Call2(Fn2::Pow, a, b) if !b.depends_on_t() && !params.seeds(b) => {
            // A constant exponent: integer powers of negative bases stay
            // defined (t^2 at t < 0), and no logarithm is taken.
            let plain = Params::Plain(params.values());
            let (a, n) = (eval(a, t), self::eval::<f64>(b, &plain, 0.0));
            if n.fract() == 0.0 && n.abs() <= f64::from(i32::MAX) {
                a.powi(n as i32)
            } else {
                a.powf(cst(n))
            }
        }
        Node::Call2(f, a, b) => {
            let (a, b) = (eval(a, t), eval(b, t));
            match f {
                Fn2::Add => a + b,
                Fn2::Sub => a - b,
                Fn2::Mul => a * b,
                Fn2::Div => a / b,
                Fn2::Pow => a.powf(b),
                Fn2::Atan2 => a.atan2(b),
                Fn2::Min => {
                    if b.value() < a.value() {
                        b
                    } else {
                        a
                    }
                }
                Fn2::Max => {
                    if b.value() > a.value() {
                        b
                    } else {
                        a
                    }
                }
                Fn2::Lt => truth(a.value() < b.value()),
                Fn2::Le => truth(a.value() <= b.value()),
                Fn2::Gt => truth(a.value() > b.value()),
                Fn2::Ge => truth(a.value() >= b.value()),
                Fn2::Eq => truth(a.value() == b.value()),
                Fn2::Ne => truth(a.value() != b.value()),
                Fn2::And => truth(a.value() != 0.0 && b.value() != 0.0),
                Fn2::Or => truth(a.value() != 0.0 || b.value() != 0.0),
            }
        }
        Node::If(c, a, b) => {
            if eval(c, t).value() != 0.0 {
                eval(a, t)
            } else {
                eval(b, t)
            }
        }
    }
}

impl Node {
    /// Whether the value changes with `t`.
    /// Whether parameter `k` appears in it.
    fn uses_param(&self, k: usize) -> bool {
        match self {
            Node::Param(i) => *i == k,
            Node::Number(_) | Node::Var => false,
            Node::Call1(_, a) => a.uses_param(k),
            Node::Call2(_, a, b) => a.uses_param(k) || b.uses_param(k),
            Node::If(c, a, b) => c.uses_param(k) || a.uses_param(k) || b.uses_param(k),
        }
    }

    fn depends_on_t(&self) -> bool {
        match self {
            Node::Number(_) | Node::Param(_) => false,
            Node::Var => true,
            Node::Call1(_, a) => a.depends_on_t(),
            Node::Call2(_, a, b) => a.depends_on_t() || b.depends_on_t(),
            Node::If(c, a, b) => c.depends_on_t() || a.depends_on_t() || b.depends_on_t(),
        }
    }
}

/// Deepest nesting of parentheses, calls and unary operators the parser
/// follows (it recurses; a hostile file must not overflow the stack).
const MAX_DEPTH: usize = 256;

/// Most binary operators in one expression: with [`MAX_DEPTH`] it bounds
/// the tree's depth, which evaluation recurses through.
const MAX_OPERATORS: usize = 2_000;

struct Parser<'a> {
    chars: &'a [char],
    at: usize,
    uses_lambda: bool,
    depth: usize,
    operators: usize,
    /// The variable's name.
    variable: &'a str,
    /// The named parameters.
    parameters: &'a [(String, f64)],
}

impl Parser<'_> {
    fn error(&self, message: String) -> ExprError {
        ExprError {
            position: self.at,
            message,
        }
    }

    fn skip_space(&mut self) {
        while self.at < self.chars.len() && self.chars[self.at].is_whitespace() {
            self.at += 1;
        }
    }

    /// Consumes `token` (after spaces) if it comes next.
    fn eat(&mut self, token: &str) -> bool {
        self.skip_space();
        let t: Vec<char> = token.chars().collect();
        if self.chars[self.at..].starts_with(&t) {
            self.at += t.len();
            true
        } else {
            false
        }
    }

    /// A binary node, counted against [`MAX_OPERATORS`].
    fn binary(&mut self, f: Fn2, a: Node, b: Node) -> Result<Node, ExprError> {
        self.operators += 1;
        if self.operators > MAX_OPERATORS {
            return Err(self.error(format!(
                "more than {MAX_OPERATORS} operators; simplify the expression"
            )));
        }
        Ok(Node::Call2(f, Box::new(a), Box::new(b)))
    }

    fn or(&mut self) -> Result<Node, ExprError> {
        let mut left = self.and()?;
        while self.eat("||") {
            let right = self.and()?;
            left = self.binary(Fn2::Or, left, right)?;
        }
        Ok(left)
    }

    fn and(&mut self) -> Result<Node, ExprError> {
        let mut left = self.cmp()?;
        while self.eat("&&") {
            let right = self.cmp()?;
            left = self.binary(Fn2::And, left, right)?;
        }
        Ok(left)
    }

    fn cmp(&mut self) -> Result<Node, ExprError> {
        let left = self.sum()?;
        // Two-character operators first.
        let ops = [
            ("<=", Fn2::Le),
            (">=", Fn2::Ge),
            ("==", Fn2::Eq),
            ("!=", Fn2::Ne),
            ("<", Fn2::Lt),
            (">", Fn2::Gt),
        ];
        for (token, op) in ops {
            if self.eat(token) {
                let right = self.sum()?;
                return self.binary(op, left, right);
            }
        }
        Ok(left)
    }

    fn sum(&mut self) -> Result<Node, ExprError> {
        let mut left = self.term()?;
        loop {
            let op = if self.eat("+") {
                Fn2::Add
            } else if self.eat("-") {
                Fn2::Sub
            } else {
                return Ok(left);
            };
            let right = self.term()?;
            left = self.binary(op, left, right)?;
        }
    }

    fn term(&mut self) -> Result<Node, ExprError> {
        let mut left = self.unary()?;
        loop {
            let op = if self.eat("*") {
                Fn2::Mul
            } else if self.eat("/") {
                Fn2::Div
            } else {
                return Ok(left);
            };
            let right = self.unary()?;
            left = self.binary(op, left, right)?;
        }
    }

    fn unary(&mut self) -> Result<Node, ExprError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(self.error(format!(
                "nested more than {MAX_DEPTH} levels deep; simplify the expression"
            )));
        }
        let node = self.unary_inner();
        self.depth -= 1;
        node
    }

    fn unary_inner(&mut self) -> Result<Node, ExprError> {
        if self.eat("-") {
            Ok(Node::Call1(Fn1::Neg, Box::new(self.unary()?)))
        } else if self.eat("+") {
            self.unary()
        } else if self.peek_not() {
            Ok(Node::Call1(Fn1::Not, Box::new(self.unary()?)))
        } else {
            self.power()
        }
    }

    /// A `!` that is not the start of `!=`.
    fn peek_not(&mut self) -> bool {
        self.skip_space();
        if self.chars.get(self.at) == Some(&'!') && self.chars.get(self.at + 1) != Some(&'=') {
            self.at += 1;
            true
        } else {
            false
        }
    }

    fn power(&mut self) -> Result<Node, ExprError> {
        let base = self.atom()?;
        if self.eat("^") {
            let exponent = self.unary()?;
            self.binary(Fn2::Pow, base, exponent)
        } else {
            Ok(base)
        }
    }

    fn atom(&mut self) -> Result<Node, ExprError> {
        self.skip_space();
        let start = self.at;
        let Some(&c) = self.chars.get(self.at) else {
            return Err(self.error("the expression ends where a value is expected".into()));
        };
        if c == '(' {
            self.at += 1;
            let inner = self.or()?;
            if !self.eat(")") {
                return Err(self.error("expected `)`".into()));
            }
            return Ok(inner);
        }
        if c.is_ascii_digit() || c == '.' {
            return self.number();
        }
        if c.is_alphabetic() || c == '_' {
            while self
                .chars
                .get(self.at)
                .is_some_and(|c| c.is_alphanumeric() || *c == '_')
            {
                self.at += 1;
            }
            let name: String = self.chars[start..self.at].iter().collect();
            return self.named(&name, start);
        }
        Err(self.error(format!("unexpected `{c}` where a value is expected")))
    }

    fn number(&mut self) -> Result<Node, ExprError> {
        let start = self.at;
        let digits = |p: &mut Self| {
            while p.chars.get(p.at).is_some_and(|c| c.is_ascii_digit()) {
                p.at += 1;
            }
        };
        digits(self);
        if self.chars.get(self.at) == Some(&'.') {
            self.at += 1;
            digits(self);
        }
        if matches!(self.chars.get(self.at), Some('e' | 'E')) {
            let save = self.at;
            self.at += 1;
            if matches!(self.chars.get(self.at), Some('+' | '-')) {
                self.at += 1;
            }
            if self.chars.get(self.at).is_some_and(|c| c.is_ascii_digit()) {
                digits(self);
            } else {
                self.at = save;
            }
        }
        let s: String = self.chars[start..self.at].iter().collect();
        s.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .map(Node::Number)
            .ok_or(ExprError {
                position: start,
                message: format!("`{s}` is not a finite number"),
            })
    }

    fn named(&mut self, name: &str, start: usize) -> Result<Node, ExprError> {
        let mut known = vec![self.variable.to_string()];
        if self.variable == "t" {
            known.push("lambda (statics)".into());
        }
        known.extend(self.parameters.iter().map(|(n, _)| n.clone()));
        let unknown = |what: &str| ExprError {
            position: start,
            message: format!(
                "unknown {what} `{name}`; known names: {}, {NAMES}",
                known.join(", ")
            ),
        };
        if !self.eat("(") {
            if name == self.variable {
                return Ok(Node::Var);
            }
            if let Some(i) = self.parameters.iter().position(|(n, _)| n == name) {
                return Ok(Node::Param(i));
            }
            return match name {
                "lambda" if self.variable == "t" => {
                    self.uses_lambda = true;
                    Ok(Node::Var)
                }
                "pi" => Ok(Node::Number(std::f64::consts::PI)),
                "e" => Ok(Node::Number(std::f64::consts::E)),
                _ => Err(unknown("name")),
            };
        }
        let mut args = vec![self.or()?];
        while self.eat(",") {
            args.push(self.or()?);
        }
        if !self.eat(")") {
            return Err(self.error(format!("expected `,` or `)` in the arguments of `{name}`")));
        }
        let expect = |n: usize| {
            if args.len() == n {
                Ok(())
            } else {
                Err(ExprError {
                    position: start,
                    message: format!(
                        "`{name}` takes {n} argument{}, found {}",
                        if n == 1 { "" } else { "s" },
                        args.len()
                    ),
                })
            }
        };
        let one = if name == "log" {
            Some(Fn1::Ln)
        } else {
            FUNCTIONS_1
                .iter()
                .find(|(n, _)| *n == name)
                .map(|&(_, f)| f)
        };
        if let Some(f) = one {
            expect(1)?;
            let mut args = args.into_iter();
            return Ok(Node::Call1(f, Box::new(args.next().unwrap_or(Node::Var))));
        }
        if let Some(&(_, f)) = FUNCTIONS_2.iter().find(|(n, _)| *n == name) {
            expect(2)?;
            let mut args = args.into_iter().map(Box::new);
            let (a, b) = (args.next(), args.next());
            return match (a, b) {
                (Some(a), Some(b)) => Ok(Node::Call2(f, a, b)),
                _ => Err(unknown("function")),
            };
        }
        if name == "if" {
            expect(3)?;
            let mut args = args.into_iter().map(Box::new);
            return match (args.next(), args.next(), args.next()) {
                (Some(c), Some(a), Some(b)) => Ok(Node::If(c, a, b)),
                _ => Err(unknown("function")),
            };
        }
        Err(unknown("function"))
    }
}
