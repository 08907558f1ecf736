//! Expressions of the sympy reference (`reference/README.md`): parsing JSON trees with
//! clear errors, evaluation, and the absolute scale ([`Scaled`]) used for relative error.
//!
//! Grammar (JSON): an integer is a constant; a string is a symbol; `["+", e, ...]` and
//! `["*", e, ...]` are sums and products; `["^", e, k]` an integer power (k may be
//! negative); `["/", p, q]` the rational constant p/q; `["sin", e]`, `["cos", e]`.

use std::collections::HashMap;
use std::iter::Sum;
use std::ops::{Add, Div, Mul, Neg, Sub};

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

    /// The value and the absolute [scale](Scaled) of the expression, in one pass.
    ///
    /// The tree is evaluated in [`Scaled`] arithmetic: every constant and symbol is an
    /// exact input ([`Scaled::exact`]), sums, products and powers are those of
    /// [`Scaled`]. The value is exactly that of [`Expr::eval`] (up to the sign of a zero).
    pub fn eval_with_scale(&self, slots: &[f64]) -> Scaled {
        match self {
            Expr::Const(c) => Scaled::exact(*c),
            Expr::Symbol(i) => Scaled::exact(slots[*i]),
            Expr::Sum(terms) => terms.iter().map(|t| t.eval_with_scale(slots)).sum(),
            Expr::Product(factors) => {
                factors.iter().fold(Scaled::exact(1.0), |p, f| p * f.eval_with_scale(slots))
            }
            Expr::Power(base, k) => base.eval_with_scale(slots).powi(*k),
            Expr::Sin(arg) => arg.eval_with_scale(slots).sin(),
            Expr::Cos(arg) => arg.eval_with_scale(slots).cos(),
        }
    }
}

/// A value `v` with its absolute round-off scale `s ≥ |v|`: the natural size of its
/// round-off, the one scale rule of `verify` (for the reference, [`Expr::eval_with_scale`])
/// and of the document check (for the printed formulas, xtask's `verify::document`).
///
/// The scale is the value computed with every input replaced by its absolute value and
/// every sum by the sum of its terms' scales, so cancellation does not shrink it:
/// computing the value in floating point (in any reasonable order) errs by a few units
/// of round-off times this scale, times the number of operations. The non-polynomial
/// operations use first-order error propagation:
/// - `sin e`: `|sin v|` when `e` is an exact input ([`Scaled::exact`], or its
///   negation), so only the sine's own rounding; else `|sin v| + |cos v|·S(e)` (`v` the
///   value of `e`, `S(e)` its scale): the argument's absolute error, of order `S(e)`
///   units of round-off, passes through with slope `cos v`; `cos e` likewise;
/// - `e^k`, `k < 0`: `S(e)^|k| / |v|^(2|k|)`, the error of `1/e^|k|` when `e^|k|` errs
///   by its scale (equal to `|v^k|` when `e` has no cancellation);
/// - `a / b`: `(S(a) + |a/b|·S(b)) / |b|`, likewise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scaled {
    /// The value.
    pub v: f64,
    /// Its absolute scale.
    pub s: f64,
    /// Whether `v` is an exact input (no round-off of its own).
    exact: bool,
}

impl Scaled {
    /// An exact input: its own scale, no round-off.
    pub fn exact(v: f64) -> Scaled {
        Scaled { v, s: v.abs(), exact: true }
    }

    /// A value computed elsewhere with scale `s` (raised to `|v|` if below).
    pub fn with_scale(v: f64, s: f64) -> Scaled {
        Scaled { v, s: s.abs().max(v.abs()), exact: false }
    }

    /// An exact zero.
    pub fn zero() -> Scaled {
        Scaled::exact(0.0)
    }

    /// The absolute error scale of this value as an argument of `sin`/`cos`: none for an
    /// exact input, its scale otherwise.
    fn argument_error(self) -> f64 {
        if self.exact { 0.0 } else { self.s }
    }

    /// `sin v`.
    pub fn sin(self) -> Scaled {
        let (sin, cos) = self.v.sin_cos();
        Scaled { v: sin, s: sin.abs() + cos.abs() * self.argument_error(), exact: false }
    }

    /// `cos v`.
    pub fn cos(self) -> Scaled {
        let (sin, cos) = self.v.sin_cos();
        Scaled { v: cos, s: cos.abs() + sin.abs() * self.argument_error(), exact: false }
    }

    /// `v^k`.
    pub fn powi(self, k: i32) -> Scaled {
        // k < 0: s^|k| / |v|^(2|k|) = (v²/s)^k, with no |k| or 2|k| to overflow an i32.
        let s = if k >= 0 { self.s.powi(k) } else { (self.v * self.v / self.s).powi(k) };
        Scaled { v: self.v.powi(k), s, exact: false }
    }

    /// `v²`.
    pub fn sq(self) -> Scaled {
        self * self
    }
}

impl Add for Scaled {
    type Output = Scaled;
    fn add(self, o: Scaled) -> Scaled {
        Scaled { v: self.v + o.v, s: self.s + o.s, exact: false }
    }
}

impl Sub for Scaled {
    type Output = Scaled;
    fn sub(self, o: Scaled) -> Scaled {
        Scaled { v: self.v - o.v, s: self.s + o.s, exact: false }
    }
}

impl Mul for Scaled {
    type Output = Scaled;
    fn mul(self, o: Scaled) -> Scaled {
        Scaled { v: self.v * o.v, s: self.s * o.s, exact: false }
    }
}

impl Mul<Scaled> for f64 {
    type Output = Scaled;
    fn mul(self, o: Scaled) -> Scaled {
        Scaled { v: self * o.v, s: self.abs() * o.s, exact: false }
    }
}

impl Div for Scaled {
    type Output = Scaled;
    fn div(self, o: Scaled) -> Scaled {
        let v = self.v / o.v;
        Scaled { v, s: (self.s + v.abs() * o.s) / o.v.abs(), exact: false }
    }
}

impl Neg for Scaled {
    type Output = Scaled;
    /// Negation is exact: an exact input stays one.
    fn neg(self) -> Scaled {
        Scaled { v: -self.v, ..self }
    }
}

impl Sum for Scaled {
    fn sum<I: Iterator<Item = Scaled>>(iter: I) -> Scaled {
        iter.fold(Scaled::zero(), |a, b| a + b)
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

    #[test]
    fn a_huge_negative_power_has_a_scale_and_no_overflow() {
        // Found by the fuzzer: ["^", 1, -2008667332] overflowed `-2 * k`.
        for (v, k) in [(1.0, -2_008_667_332), (2.0, i32::MIN), (0.5, -3), (3.0, -1)] {
            let p = Scaled::exact(v).powi(k);
            assert_eq!(p.v, f64::powi(v, k));
            let expected = f64::powi(v * v / v.abs(), k);
            assert_eq!(p.s, expected, "{v}^{k}");
        }
        assert_eq!(Scaled::exact(2.0).powi(-3).s, 0.125);
    }

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

    /// Value and scale of `value` parsed at [`SLOTS`].
    fn scaled(value: Value) -> (f64, f64) {
        let Scaled { v, s, .. } = parse_ok(value).eval_with_scale(&SLOTS);
        (v, s)
    }

    #[test]
    fn scale_ignores_cancellation() {
        // x + y = −1, but its scale is |x| + |y| = 5.
        assert_eq!(scaled(json!(["+", "x", "y"])), (-1.0, 5.0));
        // −x·y·(−1/2) = −3; products keep magnitudes.
        assert_eq!(scaled(json!(["*", -1, "x", "y", ["/", -1, 2]])), (-3.0, 3.0));
        // (x + y)² = 1 with scale 25; (x + y)⁻¹ = −1 with scale 5 / 1.
        assert_eq!(scaled(json!(["^", ["+", "x", "y"], 2])), (1.0, 25.0));
        assert_eq!(scaled(json!(["^", ["+", "x", "y"], -1])), (-1.0, 5.0));
        // Without cancellation the scale is the magnitude.
        assert_eq!(scaled(json!(["^", "y", -2])), (1.0 / 9.0, 1.0 / 9.0));
        // sin(x + y): value sin(−1), scale |sin 1| + |cos 1|·5.
        assert_eq!(
            scaled(json!(["sin", ["+", "x", "y"]])),
            ((-1.0f64).sin(), 1.0f64.sin() + 1.0f64.cos() * 5.0)
        );
        // cos θ of an exact input: only its own rounding.
        assert_eq!(scaled(json!(["cos", "th1"])), (0.5f64.cos(), 0.5f64.cos()));
        assert_eq!(
            scaled(json!(["sin", ["*", -1, "th1"]])),
            (-(0.5f64.sin()), 0.5f64.sin() + 0.5f64.cos() * 0.5)
        );
    }

    #[test]
    fn values_are_those_of_eval() {
        for value in [
            json!(["+", 1, "x", ["*", ["/", -1, 2], "y"], ["^", "x", -2], ["sin", "th1"]]),
            json!(["*", 3, ["^", ["+", "x", "y"], 3], ["cos", ["*", 2, "th1"]]]),
            json!(["sin", ["+", "x", ["cos", ["+", "y", "th1"]]]]),
        ] {
            let e = parse_ok(value);
            assert_eq!(e.eval_with_scale(&SLOTS).v, e.eval(&SLOTS));
        }
    }

    /// The document check's formulas, in [`Scaled`] arithmetic, follow the rule of the
    /// reference's expression trees: the same formula has the same value and scale.
    #[test]
    fn arithmetic_follows_the_expression_rule() {
        let [x, y, th] = SLOTS.map(Scaled::exact);
        let pairs = [
            (x + y, json!(["+", "x", "y"])),
            (x - y, json!(["+", "x", ["*", -1, "y"]])),
            (x * y * th, json!(["*", "x", "y", "th1"])),
            (-2.0 * th, json!(["*", -2, "th1"])),
            (x.powi(-2), json!(["^", "x", -2])),
            ((x + y).powi(-1), json!(["^", ["+", "x", "y"], -1])),
            (th.sin(), json!(["sin", "th1"])),
            (th.cos() * x.sin(), json!(["*", ["cos", "th1"], ["sin", "x"]])),
            ((x + y).sin(), json!(["sin", ["+", "x", "y"]])),
            ((x * th).cos().sq(), json!(["^", ["cos", ["*", "x", "th1"]], 2])),
            ([x, y, th].into_iter().sum::<Scaled>(), json!(["+", "x", "y", "th1"])),
        ];
        for (computed, value) in pairs {
            let (v, s) = scaled(value.clone());
            assert_eq!((computed.v, computed.s), (v, s), "{value}");
        }
        // Negation is exact: sin(−θ) of an input is only the sine's rounding.
        assert_eq!((-th).sin().s, 0.5f64.sin());
        // A quotient errs by both operands' scales.
        let q = (x + y) / th;
        assert_eq!((q.v, q.s), (-2.0, (5.0 + 2.0 * 0.5) / 0.5));
        assert_eq!(Scaled::with_scale(-3.0, 1.0), Scaled { v: -3.0, s: 3.0, exact: false });
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
