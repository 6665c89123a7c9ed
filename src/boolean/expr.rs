//! CSG expressions: named solids combined with Python's set operators, evaluated as a
//! tree of Boolean operations (§6.3 once per operator).
//!
//! | operator | operation | binds |
//! |---|---|---|
//! | `-` | difference | tightest |
//! | `&` | intersection | |
//! | `^` | symmetric difference | |
//! | `\|` | union | loosest |
//!
//! as in Python, every operator associates to the left (`a - b - c` is `(a - b) - c`) and
//! parentheses group. A name is a letter or `_` followed by letters, digits or `_`.
//! Errors give the column (from 1, in characters) where the expression went wrong.
//!
//! Each operator is one evaluation (§6.3), all in one frame, the operands' common one.
//! Results stay exact between operators: a regularized result is the next operator's
//! operand as an [`ExactSolid`] (its intersection points implicit, nothing rounded,
//! nothing repaired), and only the whole expression's result is rounded to f64, checked
//! and repaired ([`super::output`]).

use std::fmt;

use super::operand::ExactSolid;
use super::{BooleanError, Evaluation, Names, Operation, Options, Repair};
use crate::gpu::Context;
use crate::mesh::Mesh;
use crate::mesh::frame::Frame;

/// A parsed expression.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// An operand, with the column of its name (0 when built by [`Expr::fold`]).
    Name {
        name: String,
        column: usize,
    },
    Binary {
        op: Operation,
        left: Box<Expr>,
        right: Box<Expr>,
    },
}

/// A syntax error or an unknown name, at a column of the expression.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("column {column} of the expression: {message}")]
pub struct ExprError {
    /// From 1, in characters; one past the end for "found the end".
    pub column: usize,
    pub message: String,
}

/// The operator written as `c`.
fn operator(c: char) -> Option<Operation> {
    Some(match c {
        '|' => Operation::Union,
        '&' => Operation::Intersection,
        '-' => Operation::Difference,
        '^' => Operation::SymmetricDifference,
        _ => return None,
    })
}

/// The character of `op` in an expression.
pub fn operator_char(op: Operation) -> char {
    match op {
        Operation::Union => '|',
        Operation::Intersection => '&',
        Operation::Difference => '-',
        Operation::SymmetricDifference => '^',
    }
}

/// Binding strength of each operator (higher binds tighter), Python's order.
fn precedence(op: Operation) -> u8 {
    match op {
        Operation::Union => 1,
        Operation::SymmetricDifference => 2,
        Operation::Intersection => 3,
        Operation::Difference => 4,
    }
}

/// Whether `s` is an operand name.
pub fn is_name(s: &str) -> bool {
    let mut chars = s.chars();
    chars.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

#[derive(Clone, Debug, PartialEq)]
enum Token {
    Name(String),
    Op(Operation),
    Open,
    Close,
    End,
}

impl Token {
    fn describe(&self) -> String {
        match self {
            Token::Name(n) => format!("'{n}'"),
            Token::Op(op) => format!("'{}'", operator_char(*op)),
            Token::Open => "'('".into(),
            Token::Close => "')'".into(),
            Token::End => "the end".into(),
        }
    }
}

/// The tokens with their columns; the last is [`Token::End`].
fn tokenize(text: &str) -> Result<Vec<(Token, usize)>, ExprError> {
    let chars: Vec<char> = text.chars().collect();
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let column = i + 1;
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        let token = if let Some(op) = operator(c) {
            Token::Op(op)
        } else if c == '(' {
            Token::Open
        } else if c == ')' {
            Token::Close
        } else if c.is_ascii_alphabetic() || c == '_' {
            let start = i;
            while i + 1 < chars.len() && (chars[i + 1].is_ascii_alphanumeric() || chars[i + 1] == '_') {
                i += 1;
            }
            Token::Name(chars[start..=i].iter().collect())
        } else {
            return Err(ExprError {
                column,
                message: format!(
                    "unexpected character {c:?} (operands are names; operators are | & - ^ and parentheses)"
                ),
            });
        };
        tokens.push((token, column));
        i += 1;
    }
    tokens.push((Token::End, chars.len() + 1));
    Ok(tokens)
}

struct Parser {
    tokens: Vec<(Token, usize)>,
    at: usize,
}

impl Parser {
    fn peek(&self) -> &(Token, usize) {
        &self.tokens[self.at.min(self.tokens.len() - 1)]
    }

    fn next(&mut self) -> (Token, usize) {
        let t = self.peek().clone();
        self.at += 1;
        t
    }

    /// Operators binding at least as tight as `min`, left-associative (precedence
    /// climbing: the right operand only takes operators that bind tighter).
    fn binary(&mut self, min: u8) -> Result<Expr, ExprError> {
        let mut left = self.atom()?;
        while let (Token::Op(op), _) = *self.peek() {
            if precedence(op) < min {
                break;
            }
            self.next();
            let right = self.binary(precedence(op) + 1)?;
            left = Expr::Binary { op, left: Box::new(left), right: Box::new(right) };
        }
        Ok(left)
    }

    fn atom(&mut self) -> Result<Expr, ExprError> {
        match self.next() {
            (Token::Name(name), column) => Ok(Expr::Name { name, column }),
            (Token::Open, open) => {
                let inner = self.binary(1)?;
                match self.next() {
                    (Token::Close, _) => Ok(inner),
                    (found, column) => Err(ExprError {
                        column,
                        message: format!(
                            "expected an operator or ')' closing the '(' of column {open}, found {}",
                            found.describe()
                        ),
                    }),
                }
            }
            (found, column) => Err(ExprError {
                column,
                message: format!("expected an operand name, found {}", found.describe()),
            }),
        }
    }
}

impl Expr {
    /// Parses `text` (see the module docs).
    pub fn parse(text: &str) -> Result<Expr, ExprError> {
        let mut p = Parser { tokens: tokenize(text)?, at: 0 };
        let expr = p.binary(1)?;
        match p.next() {
            (Token::End, _) => Ok(expr),
            (found, column) => Err(ExprError {
                column,
                message: format!("expected an operator, found {}", found.describe()),
            }),
        }
    }

    /// `op` over `names` folded from the left: `((n0 op n1) op n2) …`. None for no names.
    pub fn fold(op: Operation, names: impl IntoIterator<Item = String>) -> Option<Expr> {
        names.into_iter().map(|name| Expr::Name { name, column: 0 }).reduce(|left, right| Expr::Binary {
            op,
            left: Box::new(left),
            right: Box::new(right),
        })
    }

    /// Every name use with its column, left to right (a name may appear more than once).
    pub fn names(&self) -> Vec<(&str, usize)> {
        match self {
            Expr::Name { name, column } => vec![(name.as_str(), *column)],
            Expr::Binary { left, right, .. } => {
                let mut v = left.names();
                v.extend(right.names());
                v
            }
        }
    }

    /// The first name not among `known`, as an error at its column.
    pub fn check_names(&self, known: &[&str]) -> Result<(), ExprError> {
        match self.names().into_iter().find(|(n, _)| !known.contains(n)) {
            None => Ok(()),
            Some((name, column)) => Err(ExprError {
                column,
                message: format!("unknown operand '{name}' (given: {})", known.join(", ")),
            }),
        }
    }

    /// How many Boolean operations the expression takes.
    pub fn operations(&self) -> usize {
        match self {
            Expr::Name { .. } => 0,
            Expr::Binary { left, right, .. } => 1 + left.operations() + right.operations(),
        }
    }
}

/// Written back with the fewest parentheses Python needs.
impl fmt::Display for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Expr::Name { name, .. } => f.write_str(name),
            Expr::Binary { op, left, right } => {
                let p = precedence(*op);
                let needs = |e: &Expr, strict: bool| match e {
                    Expr::Binary { op, .. } => precedence(*op) < p || (strict && precedence(*op) == p),
                    Expr::Name { .. } => false,
                };
                let side = |f: &mut fmt::Formatter<'_>, e: &Expr, strict: bool| {
                    if needs(e, strict) { write!(f, "({e})") } else { write!(f, "{e}") }
                };
                side(f, left, false)?;
                write!(f, " {} ", operator_char(*op))?;
                side(f, right, true)
            }
        }
    }
}

/// A named operand of an expression; `label` names it in messages (e.g. `a (A.off)`).
pub struct Operand {
    pub name: String,
    pub label: String,
    pub mesh: Mesh,
}

/// One operator evaluated: what `--stats` reports about it.
pub struct Step<'a> {
    /// 1, 2, … in evaluation order (left operands first).
    pub index: usize,
    pub op: Operation,
    /// The sub-expression this step computes, e.g. `a | b`.
    pub expr: &'a Expr,
    /// The operands' labels (an operand's label, or a sub-expression in parentheses).
    pub names: Names<'a>,
    pub evaluation: &'a Evaluation,
    /// Triangles of the result.
    pub triangles: usize,
    /// What the check of the result after rounding found and repaired; `None` for a
    /// result kept exact as the next operator's operand.
    pub repair: Option<Repair>,
    /// Wall time of picking and assembling the result.
    pub assemble: std::time::Duration,
}

#[derive(Debug, thiserror::Error)]
pub enum CsgError {
    #[error(transparent)]
    Expr(#[from] ExprError),
    #[error(transparent)]
    Boolean(#[from] BooleanError),
}

/// Evaluates `expr` over `operands` (regularized operations), post-order, calling `step`
/// after each operator. Every name must be among `operands` ([`Expr::check_names`]). An
/// expression without operators returns its operand once it passes the operand checks.
pub fn evaluate(
    expr: &Expr,
    operands: &[Operand],
    options: &Options,
    ctx: Option<&Context>,
    mut step: impl FnMut(&Step),
) -> Result<Mesh, CsgError> {
    let known: Vec<&str> = operands.iter().map(|o| o.name.as_str()).collect();
    expr.check_names(&known)?;
    let meshes: Vec<&Mesh> = operands.iter().map(|o| &o.mesh).collect();
    let frame = Frame::of(&meshes);
    let mut at = At { operands, options, ctx, frame, count: 0 };
    let (value, label) = at.eval(expr, true, &mut step)?;
    match value {
        Value::Written(mesh) => Ok(mesh),
        Value::Given(m) => {
            super::input::check(&frame.mesh_in_ref(m), frame, options.allow_self_intersections)
                .map_err(|reason| BooleanError::Input { name: label, reason })?;
            Ok(m.clone())
        }
        Value::Exact(_) => unreachable!("the root's result is written"),
    }
}

/// The value of a sub-expression.
enum Value<'o> {
    /// An operand as given.
    Given(&'o Mesh),
    /// An inner operator's exact result, in the expression's frame.
    Exact(ExactSolid),
    /// The root operator's result, rounded, checked and repaired, in the operands' units.
    Written(Mesh),
}

/// What every step of one expression shares.
struct At<'o, 'c> {
    operands: &'o [Operand],
    options: &'c Options,
    ctx: Option<&'c Context>,
    frame: Frame,
    count: usize,
}

impl<'o> At<'o, '_> {
    /// The value of `expr` (written when `root`) and its label in messages.
    fn eval(
        &mut self,
        expr: &Expr,
        root: bool,
        step: &mut impl FnMut(&Step),
    ) -> Result<(Value<'o>, String), CsgError> {
        let (op, left, right) = match expr {
            Expr::Name { name, column } => {
                let o = self.operands.iter().find(|o| &o.name == name).ok_or_else(|| ExprError {
                    column: *column,
                    message: format!("unknown operand '{name}'"),
                })?;
                return Ok((Value::Given(&o.mesh), o.label.clone()));
            }
            Expr::Binary { op, left, right } => (*op, left, right),
        };
        let (a, a_label) = self.eval(left, false, step)?;
        let (b, b_label) = self.eval(right, false, step)?;
        let names = Names { a: &a_label, b: &b_label };
        let ev = match (a, b) {
            (Value::Given(a), Value::Given(b)) => {
                super::evaluate_in(a, b, names, self.options, self.ctx, self.frame)?
            }
            (a, b) => {
                let a = self.exact(a, &a_label)?;
                let b = self.exact(b, &b_label)?;
                super::evaluate_exact(a, b, names, self.options, self.ctx, self.frame)?
            }
        };
        let start = std::time::Instant::now();
        let (value, triangles, repair) = if root {
            let super::Output { mesh, repair, .. } = ev.output(op, true)?;
            let n = mesh.num_faces();
            (Value::Written(mesh), n, Some(repair))
        } else {
            let e = ev.exact_result(op, true)?;
            let n = e.triangles.len();
            (Value::Exact(e), n, None)
        };
        self.count += 1;
        step(&Step {
            index: self.count,
            op,
            expr,
            names,
            evaluation: &ev,
            triangles,
            repair,
            assemble: start.elapsed(),
        });
        Ok((value, format!("({expr})")))
    }

    /// A value as an exact operand: a given mesh once it passes the operand checks.
    fn exact(&self, value: Value, label: &str) -> Result<ExactSolid, CsgError> {
        match value {
            Value::Exact(e) => Ok(e),
            Value::Given(m) => {
                let framed = self.frame.mesh_in_ref(m);
                let (soup, _) = super::input::check_known(
                    &framed,
                    self.frame,
                    self.options.allow_self_intersections,
                    None,
                )
                .map_err(|reason| BooleanError::Input { name: label.to_string(), reason })?;
                Ok(ExactSolid::from_soup(&soup))
            }
            Value::Written(_) => unreachable!("only the root's result is written"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn show(text: &str) -> String {
        // Fully parenthesized, to see the tree.
        fn full(e: &Expr) -> String {
            match e {
                Expr::Name { name, .. } => name.clone(),
                Expr::Binary { op, left, right } => {
                    format!("({} {} {})", full(left), operator_char(*op), full(right))
                }
            }
        }
        full(&Expr::parse(text).unwrap())
    }

    fn error(text: &str) -> String {
        Expr::parse(text).unwrap_err().to_string()
    }

    #[test]
    fn python_precedence() {
        // - binds tightest, then &, then ^, then |.
        assert_eq!(show("a | b & c"), "(a | (b & c))");
        assert_eq!(show("a & b | c"), "((a & b) | c)");
        assert_eq!(show("a ^ b & c"), "(a ^ (b & c))");
        assert_eq!(show("a | b ^ c"), "(a | (b ^ c))");
        assert_eq!(show("a & b - c"), "(a & (b - c))");
        assert_eq!(show("a - b & c"), "((a - b) & c)");
        assert_eq!(show("a | b ^ c & d - e"), "(a | (b ^ (c & (d - e))))");
        assert_eq!(show("a - b & c ^ d | e"), "((((a - b) & c) ^ d) | e)");
    }

    #[test]
    fn left_associative() {
        assert_eq!(show("a - b - c"), "((a - b) - c)");
        assert_eq!(show("a-b-c-d"), "(((a - b) - c) - d)");
        assert_eq!(show("a ^ b ^ c"), "((a ^ b) ^ c)");
        assert_eq!(show("a | b | c"), "((a | b) | c)");
        assert_eq!(
            Expr::fold(Operation::Difference, ["a", "b", "c"].map(String::from)),
            Some(Expr::parse("a - b - c").unwrap().forget_columns())
        );
        assert_eq!(Expr::fold(Operation::Union, Vec::new()), None);
    }

    #[test]
    fn parentheses_group() {
        assert_eq!(show("a - (b - c)"), "(a - (b - c))");
        assert_eq!(show("(a | b) - c"), "((a | b) - c)");
        assert_eq!(show("((a))"), "a");
        assert_eq!(show(" ( a|b ) &(c^ d)"), "((a | b) & (c ^ d))");
        assert_eq!(show("_x1 | Y_2"), "(_x1 | Y_2)");
    }

    #[test]
    fn written_back_with_the_needed_parentheses() {
        for text in ["a - (b - c)", "(a | b) - c", "a - b - c", "a | b & c", "(a ^ b) & (c | d)", "a"] {
            let e = Expr::parse(text).unwrap();
            assert_eq!(e.to_string(), text);
            assert_eq!(Expr::parse(&e.to_string()).unwrap(), e);
        }
        assert_eq!(Expr::parse("((a | b)) | c").unwrap().to_string(), "a | b | c");
    }

    #[test]
    fn errors_give_the_column() {
        assert_eq!(error("(a | b) - )"), "column 11 of the expression: expected an operand name, found ')'");
        assert_eq!(error("a |"), "column 4 of the expression: expected an operand name, found the end");
        assert_eq!(error(""), "column 1 of the expression: expected an operand name, found the end");
        assert_eq!(error("a b"), "column 3 of the expression: expected an operator, found 'b'");
        assert_eq!(error("a | b)"), "column 6 of the expression: expected an operator, found ')'");
        assert_eq!(
            error("x & (a | b"),
            "column 11 of the expression: expected an operator or ')' closing the '(' of column 5, found the end"
        );
        assert_eq!(error("-a"), "column 1 of the expression: expected an operand name, found '-'");
        assert_eq!(error("a || b"), "column 4 of the expression: expected an operand name, found '|'");
        assert!(error("a + b").starts_with("column 3 of the expression: unexpected character '+'"));
        // Columns count characters, not bytes.
        assert!(error("é | a").starts_with("column 1 of the expression: unexpected character 'é'"));
        assert_eq!(error("a ∪ b").split(':').next(), Some("column 3 of the expression"));
        assert_eq!(
            error("1a"),
            "column 1 of the expression: unexpected character '1' (operands are names; operators are | & - ^ and parentheses)"
        );
    }

    #[test]
    fn unknown_names_give_their_column() {
        let e = Expr::parse("(a | b) - cc").unwrap();
        assert_eq!(e.names(), vec![("a", 2), ("b", 6), ("cc", 11)]);
        assert_eq!(e.operations(), 2);
        assert!(e.check_names(&["a", "b", "cc"]).is_ok());
        assert_eq!(
            e.check_names(&["a", "b", "c"]).unwrap_err().to_string(),
            "column 11 of the expression: unknown operand 'cc' (given: a, b, c)"
        );
        assert!(is_name("_a9") && !is_name("9a") && !is_name("") && !is_name("a-b"));
    }

    #[test]
    fn evaluates_like_the_operations_one_by_one() {
        use crate::boolean::Transform;
        use crate::mesh::covering::Covering;
        use crate::mesh::procedural;
        let moved = |steps: &str| Transform::parse(steps).unwrap().apply(&procedural::cube()).unwrap();
        let operands: Vec<Operand> = [
            ("a", procedural::cube()),
            ("b", moved("rotate 1 2 3 20; translate 0.7 0.3 0.2")),
            ("c", moved("scale 0.6; rotate 3 1 2 35; translate -0.9 0.4 0.1")),
        ]
        .into_iter()
        .map(|(name, mesh)| Operand { name: name.into(), label: name.into(), mesh })
        .collect();
        let options = Options::default();
        let mut steps = Vec::new();
        let mut exact = 0.0;
        let e = Expr::parse("a | b - c").unwrap();
        let got = evaluate(&e, &operands, &options, None, |s| {
            steps.push((s.index, s.op, s.expr.to_string(), s.names.a.to_string(), s.names.b.to_string()));
            exact = s.evaluation.exact_volume(s.op, true).value;
        })
        .unwrap();
        assert_eq!(
            steps,
            vec![
                (1, Operation::Difference, "b - c".into(), "b".into(), "c".into()),
                (2, Operation::Union, "a | b - c".into(), "a".into(), "(b - c)".into()),
            ]
        );
        let one = |a: &Mesh, b: &Mesh, op| {
            super::super::evaluate(a, b, Names::default(), &options, None).unwrap().result(op, true).unwrap()
        };
        let want = one(
            &operands[0].mesh,
            &one(&operands[1].mesh, &operands[2].mesh, Operation::Difference),
            Operation::Union,
        );
        // One by one, b − c is rounded before the union; in the expression it is not, so
        // the triple points come out rounded once, from the exact ones: the same solid up
        // to rounding, and the written volume is the exact one up to its rounding.
        let (v, w) = (Covering::new(&got).volume(), Covering::new(&want).volume());
        assert!((v - w).abs() <= 1e-12 * w && (v - exact).abs() <= 1e-12 * w, "{v} vs {w}, exact {exact}");
        assert!(v > 8.0 && v < 16.0, "{v}");
        // A lone operand comes back as it is.
        assert_eq!(
            evaluate(&Expr::parse("c").unwrap(), &operands, &options, None, |_| {}).unwrap().positions(),
            operands[2].mesh.positions()
        );
        // Names are checked before any work.
        let e = Expr::parse("a | d").unwrap();
        assert!(
            matches!(evaluate(&e, &operands, &options, None, |_| panic!("no step")), Err(CsgError::Expr(x)) if x.column == 5)
        );
    }

    impl Expr {
        fn forget_columns(self) -> Expr {
            match self {
                Expr::Name { name, .. } => Expr::Name { name, column: 0 },
                Expr::Binary { op, left, right } => Expr::Binary {
                    op,
                    left: Box::new(left.forget_columns()),
                    right: Box::new(right.forget_columns()),
                },
            }
        }
    }
}
