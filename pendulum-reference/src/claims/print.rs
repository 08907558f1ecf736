//! A claim's entries printed back in the file's syntax (the corrected claims a diagnosis
//! prints; `parse` of the printed text gives the same text again).

use std::fmt::{self, Write as _};

use super::syntax::{Compare, Entry, Expr, Index};

impl fmt::Display for Index {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Index::Int(v) => write!(f, "{v}"),
            Index::Var(v, _) => f.write_str(v),
            Index::Add(a, b) => write!(f, "{a}+{b}"),
            Index::Sub(a, b) => match **b {
                Index::Add(..) | Index::Sub(..) => write!(f, "{a}-({b})"),
                _ => write!(f, "{a}-{b}"),
            },
            Index::Max(a, b) => write!(f, "max({a},{b})"),
            Index::Min(a, b) => write!(f, "min({a},{b})"),
        }
    }
}

/// Binding strength of an expression's top: 1 sums, 2 products, 3 unary minus, 4 powers
/// and atoms.
fn strength(e: &Expr) -> u8 {
    match e {
        Expr::Add(..) | Expr::Sub(..) => 1,
        Expr::Mul(..) | Expr::Div(..) | Expr::Sum { .. } => 2,
        Expr::Neg(_) => 3,
        Expr::Num(v) if *v < 0.0 => 3,
        _ => 4,
    }
}

/// Whether `e` printed ends in a sum's body, which would run on into what follows.
fn ends_open(e: &Expr) -> bool {
    match e {
        Expr::Sum { .. } => true,
        Expr::Mul(_, b, _) => ends_open(b),
        Expr::Neg(b) => ends_open(b),
        _ => false,
    }
}

fn wrapped(e: &Expr, at_least: u8) -> String {
    if strength(e) < at_least { format!("({e})") } else { e.to_string() }
}

impl fmt::Display for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            // Whole numbers as such; large ones in exponent form (they would lex as
            // integers too large).
            Expr::Num(v) if v.fract() == 0.0 && v.abs() < 1e15 => write!(f, "{}", *v as i64),
            Expr::Num(v) if v.abs() >= 1e15 => write!(f, "{v:e}"),
            Expr::Num(v) => write!(f, "{v}"),
            Expr::Sym { name, index: Some(i), .. } => write!(f, "{name}[{i}]"),
            Expr::Sym { name, index: None, .. } => f.write_str(name),
            Expr::Ref { name, indices, .. } => {
                let all: Vec<String> = indices.iter().map(Index::to_string).collect();
                write!(f, "{name}[{}]", all.join(","))
            }
            // A product's sign may stand before its first factor.
            Expr::Neg(e) => write!(f, "-{}", wrapped(e, 2)),
            Expr::Add(a, b) => write!(f, "{a} + {}", wrapped(b, 2)),
            Expr::Sub(a, b) => write!(f, "{a} - {}", wrapped(b, 2)),
            Expr::Mul(a, b, explicit) => {
                // A sum's body runs to the end of its product: it must come last.
                let left = if ends_open(a) { format!("({a})") } else { wrapped(a, 2) };
                // a (b c) = a b c and a (b / c) = a b / c; a sum on the right runs to the end.
                // A right factor that prints with a sign would read as a subtraction.
                let right = wrapped(b, 2);
                let right = if right.starts_with('-') { format!("({right})") } else { right };
                write!(f, "{left}{}{right}", if *explicit { " * " } else { " " })
            }
            Expr::Div(a, b) => {
                let left = if ends_open(a) { format!("({a})") } else { wrapped(a, 2) };
                write!(f, "{left} / {}", wrapped(b, 4))
            }
            Expr::Pow(e, k) if matches!(**e, Expr::Pow(..)) => write!(f, "({e})^{k}"),
            Expr::Pow(e, k) => write!(f, "{}^{k}", wrapped(e, 4)),
            Expr::Call(func, e) => write!(f, "{}({e})", func.name()),
            Expr::Sum { var, from, to, body, when, .. } => {
                let when = when.as_ref().map_or(String::new(), |w| {
                    format!(" if {}", w.iter().map(Compare::to_string).collect::<Vec<_>>().join(" and "))
                });
                write!(f, "sum({var} = {from}..{to}{when}) {}", wrapped(body, 2))
            }
        }
    }
}

impl fmt::Display for Compare {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {} {}", self.left, self.op, self.right)
    }
}

impl Entry {
    /// The entry in the file's syntax, one branch per line.
    pub fn render(&self) -> String {
        let mut out = self.quantity.clone();
        if !self.indices.is_empty() {
            let indices: Vec<String> = self.indices.iter().map(Index::to_string).collect();
            let _ = write!(out, "[{}]", indices.join(","));
        }
        let width = out.chars().count();
        for (k, b) in self.branches.iter().enumerate() {
            if k > 0 {
                out.push('\n');
                out.push_str(&" ".repeat(width));
            }
            let _ = write!(out, " = {}", b.value);
            if let Some(when) = &b.when {
                let all: Vec<String> = when.iter().map(Compare::to_string).collect();
                let _ = write!(out, "  if {}", all.join(" and "));
            } else if b.otherwise {
                out.push_str("  otherwise");
            }
        }
        out
    }
}
