//! Expressions of the sympy reference (`reference/README.md`): parsing JSON trees with
//! clear errors, evaluation, and the absolute-scale evaluation used for relative error.
//!
//! Grammar (JSON): an integer is a constant; a string is a symbol; `["+", e, ...]` and
//! `["*", e, ...]` are sums and products; `["^", e, k]` an integer power (k may be
//! negative); `["/", p, q]` the rational constant p/q; `["sin", e]`, `["cos", e]`.

use std::collections::HashMap;

use anyhow::{Result, anyhow, bail};
use serde_json::Value;

/// Symbol names and the slots they occupy in the value slice given to [`Expr::eval`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Symbols {
    names: Vec<String>,
    slots: HashMap<String, usize>,
}

impl Symbols {
    /// An empty table.
    pub fn new() -> Self {
        Self::default()
    }

    /// Gives `name` the next slot and returns it; errors if `name` already has one.
    pub fn add(&mut self, name: &str) -> Result<usize> {
        if self.slots.contains_key(name) {
            bail!("symbol {name:?} is listed twice");
        }
        let slot = self.names.len();
        self.names.push(name.to_owned());
        self.slots.insert(name.to_owned(), slot);
        Ok(slot)
    }

    /// The slot of `name`, if it is in the table.
    pub fn slot(&self, name: &str) -> Option<usize> {
        self.slots.get(name).copied()
    }

    /// The name in slot `slot`.
    pub fn name(&self, slot: usize) -> &str {
        &self.names[slot]
    }

    /// Number of symbols (the length of the slot slice [`Expr::eval`] needs).
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Whether the table has no symbols.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }
}

/// A parsed expression with its symbols resolved to slots of a [`Symbols`] table.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// An integer or rational constant.
    Const(f64),
    /// The value in a slot.
    Symbol(usize),
    /// `e1 + e2 + …` (at least one term).
    Sum(Vec<Expr>),
    /// `e1 · e2 · …` (at least one factor).
    Product(Vec<Expr>),
    /// `e^k`, integer `k`.
    Power(Box<Expr>, i32),
    /// `sin e`.
    Sin(Box<Expr>),
    /// `cos e`.
    Cos(Box<Expr>),
}

impl Expr {
    /// Parses one expression tree. `at` says where it comes from and starts every error
    /// message, e.g. `reference/cases/planar_n3.json: case planar_n3: mass_matrix[2][1]`.
    pub fn parse(value: &Value, symbols: &Symbols, at: &str) -> Result<Expr> {
        parse(value, symbols).map_err(|message| anyhow!("{at}: {message}"))
    }

    /// The value of the expression with symbol slot `i` set to `slots[i]`.
    ///
    /// Panics if a slot is out of range of `slots`.
    pub fn eval(&self, slots: &[f64]) -> f64 {
        match self {
            Expr::Const(c) => *c,
            Expr::Symbol(i) => slots[*i],
            Expr::Sum(terms) => terms.iter().map(|t| t.eval(slots)).sum(),
            Expr::Product(factors) => factors.iter().map(|f| f.eval(slots)).product(),
            Expr::Power(base, k) => base.eval(slots).powi(*k),
            Expr::Sin(arg) => arg.eval(slots).sin(),
            Expr::Cos(arg) => arg.eval(slots).cos(),
        }
    }

    /// The absolute scale of the expression: the natural size of its round-off.
    ///
    /// The tree is evaluated with every constant and symbol replaced by its absolute
    /// value and every sum by the sum of its terms' scales, so cancellation does not
    /// shrink it: evaluating the expression in floating point (in any reasonable order)
    /// errs by a few units of round-off times this scale, times the number of
    /// operations. It is never below the magnitude of the value. The non-polynomial
    /// nodes use first-order error propagation:
    /// - `sin e`: `|sin v|` when `e` is a symbol or constant (an exact input, so only
    ///   the sine's own rounding), else `|sin v| + |cos v|·S(e)` (`v` the value of `e`,
    ///   `S(e)` its scale): the argument's absolute error, of order `S(e)` units of
    ///   round-off, passes through with slope `cos v`; `cos e` likewise;
    /// - `e^k`, `k < 0`: `S(e)^|k| / |v|^(2|k|)`, the error of `1/e^|k|` when `e^|k|`
    ///   errs by its scale (equal to `|v^k|` when `e` has no cancellation).
    pub fn scale(&self, slots: &[f64]) -> f64 {
        self.eval_with_scale(slots).1
    }

    /// The value and the [scale](Expr::scale) together, in one pass.
    pub fn eval_with_scale(&self, slots: &[f64]) -> (f64, f64) {
        match self {
            Expr::Const(c) => (*c, c.abs()),
            Expr::Symbol(i) => (slots[*i], slots[*i].abs()),
            Expr::Sum(terms) => terms.iter().fold((0.0, 0.0), |(v, s), t| {
                let (tv, ts) = t.eval_with_scale(slots);
                (v + tv, s + ts)
            }),
            Expr::Product(factors) => factors.iter().fold((1.0, 1.0), |(v, s), f| {
                let (fv, fs) = f.eval_with_scale(slots);
                (v * fv, s * fs)
            }),
            Expr::Power(base, k) => {
                let (v, s) = base.eval_with_scale(slots);
                let scale = if *k >= 0 { s.powi(*k) } else { s.powi(-k) / v.abs().powi(-2 * k) };
                (v.powi(*k), scale)
            }
            Expr::Sin(arg) => {
                let (v, s) = arg.eval_with_scale(slots);
                let (sin, cos) = v.sin_cos();
                (sin, sin.abs() + cos.abs() * arg.argument_error(s))
            }
            Expr::Cos(arg) => {
                let (v, s) = arg.eval_with_scale(slots);
                let (sin, cos) = v.sin_cos();
                (cos, cos.abs() + sin.abs() * arg.argument_error(s))
            }
        }
    }

    /// The absolute error scale of this expression as an argument of `sin`/`cos`, given
    /// its scale: none for a leaf (inputs are exact), its scale otherwise.
    fn argument_error(&self, scale: f64) -> f64 {
        match self {
            Expr::Const(_) | Expr::Symbol(_) => 0.0,
            _ => scale,
        }
    }

    /// Number of nodes in the tree.
    pub fn size(&self) -> usize {
        1 + match self {
            Expr::Const(_) | Expr::Symbol(_) => 0,
            Expr::Sum(items) | Expr::Product(items) => items.iter().map(Expr::size).sum(),
            Expr::Power(e, _) | Expr::Sin(e) | Expr::Cos(e) => e.size(),
        }
    }
}

/// A short description of a JSON value for error messages.
fn describe(value: &Value) -> String {
    let text = value.to_string();
    if text.chars().count() > 40 { format!("{}…", text.chars().take(40).collect::<String>()) } else { text }
}

/// A JSON integer as f64, or `None` for anything else (floats included).
fn integer(value: &Value) -> Option<f64> {
    match value {
        Value::Number(n) => n.as_i64().map(|i| i as f64).or_else(|| n.as_u64().map(|u| u as f64)),
        _ => None,
    }
}

fn parse(value: &Value, symbols: &Symbols) -> Result<Expr, String> {
    match value {
        Value::Number(_) => integer(value).map(Expr::Const).ok_or_else(|| {
            format!("constant {} is not an integer (write rationals as [\"/\", p, q])", describe(value))
        }),
        Value::String(name) => {
            symbols.slot(name).map(Expr::Symbol).ok_or_else(|| format!("unknown symbol {name:?}"))
        }
        Value::Array(items) => {
            let Some((head, args)) = items.split_first() else {
                return Err("empty array: expected [operator, operands...]".to_owned());
            };
            let Value::String(op) = head else {
                return Err(format!("operator must be a string, got {}", describe(head)));
            };
            let operands = || args.iter().map(|a| parse(a, symbols)).collect::<Result<Vec<_>, _>>();
            let unary = |make: fn(Box<Expr>) -> Expr| match args {
                [arg] => Ok(make(Box::new(parse(arg, symbols)?))),
                _ => Err(format!("{op:?} needs exactly one operand, got {}", args.len())),
            };
            match op.as_str() {
                "+" | "*" if args.is_empty() => Err(format!("{op:?} needs at least one operand")),
                "+" => Ok(Expr::Sum(operands()?)),
                "*" => Ok(Expr::Product(operands()?)),
                "^" => match args {
                    [base, exponent] => {
                        let k = exponent.as_i64().ok_or_else(|| {
                            format!("\"^\" needs an integer exponent, got {}", describe(exponent))
                        })?;
                        let k =
                            i32::try_from(k).map_err(|_| format!("\"^\" exponent {k} is out of range"))?;
                        Ok(Expr::Power(Box::new(parse(base, symbols)?), k))
                    }
                    _ => Err(format!("\"^\" needs a base and an exponent, got {} operands", args.len())),
                },
                "/" => match args {
                    [p, q] => {
                        let (Some(p), Some(q)) = (integer(p), integer(q)) else {
                            return Err(format!(
                                "\"/\" is a rational constant and needs two integers, got {} and {}",
                                describe(p),
                                describe(q)
                            ));
                        };
                        if q == 0.0 {
                            return Err("\"/\" has a zero denominator".to_owned());
                        }
                        Ok(Expr::Const(p / q))
                    }
                    _ => Err(format!("\"/\" needs two integers, got {} operands", args.len())),
                },
                "sin" => unary(Expr::Sin),
                "cos" => unary(Expr::Cos),
                _ => Err(format!("unknown operator {op:?} (expected +, *, ^, /, sin or cos)")),
            }
        }
        Value::Null | Value::Bool(_) | Value::Object(_) => Err(format!(
            "expected an integer, a symbol name or an [operator, ...] array, got {}",
            describe(value)
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn table() -> Symbols {
        let mut s = Symbols::new();
        for name in ["x", "y", "th1"] {
            s.add(name).unwrap();
        }
        s
    }

    fn parse_ok(value: Value) -> Expr {
        Expr::parse(&value, &table(), "test").unwrap()
    }

    fn parse_err(value: Value) -> String {
        Expr::parse(&value, &table(), "file.json: case c: mass_matrix[2][1]").unwrap_err().to_string()
    }

    const SLOTS: [f64; 3] = [2.0, -3.0, 0.5];

    #[test]
    fn parses_every_node() {
        let e = parse_ok(json!(["+", 1, "x", ["*", ["/", -1, 2], "y"], ["^", "x", -2], ["sin", "th1"]]));
        assert_eq!(
            e,
            Expr::Sum(vec![
                Expr::Const(1.0),
                Expr::Symbol(0),
                Expr::Product(vec![Expr::Const(-0.5), Expr::Symbol(1)]),
                Expr::Power(Box::new(Expr::Symbol(0)), -2),
                Expr::Sin(Box::new(Expr::Symbol(2))),
            ])
        );
        assert_eq!(e.size(), 10);
        assert_eq!(parse_ok(json!(["cos", 0])), Expr::Cos(Box::new(Expr::Const(0.0))));
    }

    #[test]
    fn evaluates() {
        // 1 + x − y/2 + x⁻² + sin θ  at x = 2, y = −3, θ = 0.5
        let e = parse_ok(json!(["+", 1, "x", ["*", ["/", -1, 2], "y"], ["^", "x", -2], ["sin", "th1"]]));
        assert_eq!(e.eval(&SLOTS), 1.0 + 2.0 + 1.5 + 0.25 + 0.5f64.sin());
        let e = parse_ok(json!(["*", 3, ["^", ["+", "x", "y"], 3], ["cos", ["*", 2, "th1"]]]));
        assert_eq!(e.eval(&SLOTS), 3.0 * (-1.0f64).powi(3) * 1.0f64.cos());
    }

    #[test]
    fn scale_ignores_cancellation() {
        // x + y = −1, but its scale is |x| + |y| = 5.
        let e = parse_ok(json!(["+", "x", "y"]));
        assert_eq!(e.eval_with_scale(&SLOTS), (-1.0, 5.0));
        // −x·y·(−1/2) = −3; products keep magnitudes.
        let e = parse_ok(json!(["*", -1, "x", "y", ["/", -1, 2]]));
        assert_eq!(e.eval_with_scale(&SLOTS), (-3.0, 3.0));
        // (x + y)² = 1 with scale 25; (x + y)⁻¹ = −1 with scale 5 / 1.
        assert_eq!(parse_ok(json!(["^", ["+", "x", "y"], 2])).eval_with_scale(&SLOTS), (1.0, 25.0));
        assert_eq!(parse_ok(json!(["^", ["+", "x", "y"], -1])).eval_with_scale(&SLOTS), (-1.0, 5.0));
        // Without cancellation the scale is the magnitude.
        assert_eq!(parse_ok(json!(["^", "y", -2])).eval_with_scale(&SLOTS), (1.0 / 9.0, 1.0 / 9.0));
        // sin(x + y): value sin(−1), scale |sin 1| + |cos 1|·5.
        let (v, s) = parse_ok(json!(["sin", ["+", "x", "y"]])).eval_with_scale(&SLOTS);
        assert_eq!(v, (-1.0f64).sin());
        assert_eq!(s, 1.0f64.sin() + 1.0f64.cos() * 5.0);
        // cos θ of an exact input: only its own rounding.
        let (v, s) = parse_ok(json!(["cos", "th1"])).eval_with_scale(&SLOTS);
        assert_eq!((v, s), (0.5f64.cos(), 0.5f64.cos()));
        let (v, s) = parse_ok(json!(["sin", ["*", -1, "th1"]])).eval_with_scale(&SLOTS);
        assert_eq!((v, s), (-(0.5f64.sin()), 0.5f64.sin() + 0.5f64.cos() * 0.5));
    }

    #[test]
    fn every_error_names_the_entry() {
        let cases = [
            (json!(["+", 1, "th9"]), "unknown symbol \"th9\""),
            (json!(["tan", "x"]), "unknown operator \"tan\""),
            (json!(["^", "x", ["/", 1, 2]]), "\"^\" needs an integer exponent, got [\"/\",1,2]"),
            (json!(["^", "x", 0.5]), "\"^\" needs an integer exponent, got 0.5"),
            (json!(["^", "x", "y"]), "\"^\" needs an integer exponent, got \"y\""),
            (json!(["^", "x", 4_000_000_000i64]), "\"^\" exponent 4000000000 is out of range"),
            (json!(["^", "x"]), "\"^\" needs a base and an exponent, got 1 operands"),
            (json!(["/", 1, 0]), "\"/\" has a zero denominator"),
            (json!(["/", "x", 2]), "\"/\" is a rational constant and needs two integers"),
            (json!(["/", 1, 2, 3]), "\"/\" needs two integers, got 3 operands"),
            (json!(["sin", "x", "y"]), "\"sin\" needs exactly one operand, got 2"),
            (json!(["cos"]), "\"cos\" needs exactly one operand, got 0"),
            (json!(["+"]), "\"+\" needs at least one operand"),
            (json!(["*"]), "\"*\" needs at least one operand"),
            (json!([]), "empty array"),
            (json!([1, "x"]), "operator must be a string, got 1"),
            (json!(1.5), "constant 1.5 is not an integer"),
            (json!(null), "expected an integer, a symbol name or an [operator, ...] array, got null"),
            (json!(true), "got true"),
            (json!({"+": [1]}), "got {\"+\":[1]}"),
            (json!(["*", 2, ["sin", ["+", "x", ["cos", "zz"]]]]), "unknown symbol \"zz\""),
        ];
        for (value, expected) in cases {
            let message = parse_err(value.clone());
            assert!(
                message.starts_with("file.json: case c: mass_matrix[2][1]: ") && message.contains(expected),
                "{value}: {message}"
            );
        }
    }

    #[test]
    fn long_values_are_shortened_in_messages() {
        let long = json!(["^", "x", ["+", "x", "x", "x", "x", "x", "x", "x", "x", "x", "x"]]);
        assert!(parse_err(long).contains("…"));
    }

    #[test]
    fn duplicate_symbol_is_an_error() {
        let mut s = table();
        assert_eq!(s.add("y").unwrap_err().to_string(), "symbol \"y\" is listed twice");
        assert_eq!(s.add("z").unwrap(), 3);
        assert_eq!((s.name(3), s.len(), s.is_empty()), ("z", 4, false));
    }
}
