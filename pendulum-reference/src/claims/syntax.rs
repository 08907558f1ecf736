//! The claims file: its tokens, its grammar and its printed form (`reference/CLAIMS.md`).
//!
//! ```text
//! file    := { comment | claim }
//! claim   := 'claim' STRING NL  'chain' ('planar' | 'spatial') [ 'n' range ] NL  { entry }
//!            [ 'corrected' NL { entry } ]                (a corrected form, checked too)
//! range   := '=' INT [ '..' INT ] | '>=' INT | '<=' INT
//! entry   := lhs '=' expr [ 'if' cond ] NL { '=' expr ( 'if' cond | 'otherwise' ) NL }
//!            (a line continues the one before while a bracket is open, or when it
//!            starts with + - * / ^)
//! lhs     := QUANTITY [ '[' index { ',' index } ']' ]
//! expr    := term { ('+' | '-') term }
//! term    := unary { [ '*' | '/' ] unary }            (juxtaposition multiplies)
//! unary   := '-' unary | power
//! power   := primary [ '^' [ '-' ] INT ]
//! primary := NUMBER | '(' expr ')' | FUNC '(' expr ')' | SYMBOL [ '[' index ']' ]
//!          | MATRIX '[' index ',' index ']'           (the reference's own entry)
//!          | 'sum' '(' VAR '=' index '..' index [ 'if' cond ] ')' term
//! index   := item { ('+' | '-') item },  item := INT | VAR | 'n' | ('max' | 'min') '(' index ',' index ')'
//! cond    := index CMP index { 'and' index CMP index }
//! ```

pub use super::lex::{Pos, SyntaxError};
use super::lex::{Tok, lex};

/// An index expression (1-based, integer valued).
#[derive(Clone, Debug, PartialEq)]
pub enum Index {
    Int(i64),
    /// An index variable (`i`, `j`, a sum's variable) or `n`.
    Var(String, Pos),
    Add(Box<Index>, Box<Index>),
    Sub(Box<Index>, Box<Index>),
    Max(Box<Index>, Box<Index>),
    Min(Box<Index>, Box<Index>),
}

/// A function of a value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Func {
    Sin,
    Cos,
    Tan,
    Cot,
    Sqrt,
}

impl Func {
    fn named(name: &str) -> Option<Func> {
        Some(match name {
            "sin" => Func::Sin,
            "cos" => Func::Cos,
            "tan" => Func::Tan,
            "cot" => Func::Cot,
            "sqrt" => Func::Sqrt,
            _ => return None,
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Cot => "cot",
            Func::Sqrt => "sqrt",
        }
    }
}

/// A value expression.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    Num(f64),
    /// A symbol as written (`theta`, `θ`, `m`, `g`, …), with its index if it has one.
    Sym {
        name: String,
        index: Option<Index>,
        pos: Pos,
    },
    /// An entry of one of the reference's matrices (`S[i,j]`, `B11[i,j]`, `M[i,j]`): a
    /// name with two indices.
    Ref {
        name: String,
        indices: Vec<Index>,
        pos: Pos,
    },
    Neg(Box<Expr>),
    Add(Box<Expr>, Box<Expr>),
    Sub(Box<Expr>, Box<Expr>),
    /// A product; `explicit` when written with `*` (else by juxtaposition).
    Mul(Box<Expr>, Box<Expr>, bool),
    Div(Box<Expr>, Box<Expr>),
    Pow(Box<Expr>, i32),
    Call(Func, Box<Expr>),
    Sum {
        var: String,
        from: Index,
        to: Index,
        body: Box<Expr>,
        /// Only the terms where this holds (`sum(k = 1..n if k != j) …`).
        when: Option<Vec<Compare>>,
        pos: Pos,
    },
}

impl Expr {
    /// The same node with each child expression replaced by `f` of it.
    pub fn map_children(&self, f: &mut dyn FnMut(&Expr) -> Expr) -> Expr {
        let mut go = |a: &Expr| Box::new(f(a));
        match self {
            Expr::Num(_) | Expr::Sym { .. } | Expr::Ref { .. } => self.clone(),
            Expr::Neg(a) => Expr::Neg(go(a)),
            Expr::Pow(a, k) => Expr::Pow(go(a), *k),
            Expr::Call(func, a) => Expr::Call(*func, go(a)),
            Expr::Add(a, b) => Expr::Add(go(a), go(b)),
            Expr::Sub(a, b) => Expr::Sub(go(a), go(b)),
            Expr::Mul(a, b, x) => Expr::Mul(go(a), go(b), *x),
            Expr::Div(a, b) => Expr::Div(go(a), go(b)),
            Expr::Sum { var, from, to, body, when, pos } => Expr::Sum {
                var: var.clone(),
                from: from.clone(),
                to: to.clone(),
                body: go(body),
                when: when.clone(),
                pos: *pos,
            },
        }
    }
}

/// A comparison of two indices.
#[derive(Clone, Debug, PartialEq)]
pub struct Compare {
    pub left: Index,
    pub op: &'static str,
    pub right: Index,
}

/// One branch of an entry: the value, and the condition it holds under (none: always,
/// or `otherwise` for the last).
#[derive(Clone, Debug, PartialEq)]
pub struct Branch {
    pub value: Expr,
    pub when: Option<Vec<Compare>>,
    pub otherwise: bool,
    pub pos: Pos,
}

/// `quantity[indices] = branches`.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    pub quantity: String,
    pub indices: Vec<Index>,
    pub branches: Vec<Branch>,
    pub pos: Pos,
}

/// Planar or spatial chains, for `n` in `low..=high` (`high` none: no bound).
#[derive(Clone, Debug, PartialEq)]
pub struct Chains {
    pub spatial: bool,
    pub low: usize,
    pub high: Option<usize>,
}

/// One claim: its title, the chains it covers and its entries.
#[derive(Clone, Debug, PartialEq)]
pub struct Claim {
    pub title: String,
    pub chains: Chains,
    pub entries: Vec<Entry>,
    /// The entries after a line `corrected`: the claim's corrected form, checked too.
    pub corrected: Vec<Entry>,
    /// Where the line `corrected` is, if there is one.
    pub corrected_at: Option<Pos>,
    pub pos: Pos,
}

impl Claim {
    /// The entries lines are added to now: the corrected form's after `corrected`.
    fn current(&mut self) -> &mut Vec<Entry> {
        if self.corrected_at.is_some() { &mut self.corrected } else { &mut self.entries }
    }
}

/// Parses a claims file; every error found, not only the first.
///
/// A line continues the one before while that one leaves a bracket open, or when it
/// starts with an operator (`+ - * / ^`).
pub fn parse(text: &str) -> Result<Vec<Claim>, Vec<SyntaxError>> {
    let mut errors = Vec::new();
    // Logical lines: their tokens, and where the last physical line ends.
    let mut logical: Vec<(Vec<(Tok, Pos)>, Pos)> = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let end = Pos { line: number + 1, col: line.chars().count() + 1 };
        let tokens = match lex(line, number + 1) {
            Ok(tokens) if tokens.is_empty() => continue,
            Ok(tokens) => tokens,
            Err(e) => {
                errors.push(e);
                continue;
            }
        };
        let leads_with_operator = matches!(tokens.first(), Some((Tok::Op("+" | "-" | "*" | "/" | "^"), _)));
        match logical.last_mut() {
            Some((previous, at)) if open_brackets(previous) > 0 || leads_with_operator => {
                previous.extend(tokens);
                *at = end;
            }
            _ => logical.push((tokens, end)),
        }
    }
    let mut claims: Vec<Claim> = Vec::new();
    for (tokens, end) in logical {
        let mut p = Parser { tokens, at: 0, line: end.line, end: end.col };
        if let Err(e) = p.line_into(&mut claims) {
            errors.push(e);
        }
    }
    // A claim with a bad line is not also reported for lacking entries.
    let faulty = |claim: &Claim, next: Option<&Claim>| {
        errors.iter().any(|e| e.pos.line > claim.pos.line && next.is_none_or(|n| e.pos.line < n.pos.line))
    };
    let mut empty = Vec::new();
    for (k, claim) in claims.iter().enumerate() {
        if let Some(at) = claim.corrected_at.filter(|_| claim.corrected.is_empty()) {
            empty.push(SyntaxError {
                pos: at,
                found: "corrected".into(),
                message: "the corrected form's entries after `corrected`".into(),
            });
        }
        if claim.entries.is_empty() && !faulty(claim, claims.get(k + 1)) {
            empty.push(SyntaxError {
                pos: claim.pos,
                found: format!("claim {:?}", claim.title),
                message: "at least one entry (a line `quantity[indices] = value`)".into(),
            });
        }
    }
    errors.extend(empty);
    errors.sort_by_key(|e| (e.pos.line, e.pos.col));
    if errors.is_empty() { Ok(claims) } else { Err(errors) }
}

/// Brackets left open by `tokens`.
fn open_brackets(tokens: &[(Tok, Pos)]) -> i64 {
    tokens
        .iter()
        .map(|(t, _)| match t {
            Tok::Op("(" | "[") => 1,
            Tok::Op(")" | "]") => -1,
            _ => 0,
        })
        .sum()
}

struct Parser {
    tokens: Vec<(Tok, Pos)>,
    at: usize,
    line: usize,
    end: usize,
}

impl Parser {
    fn peek(&self) -> Option<&Tok> {
        self.tokens.get(self.at).map(|(t, _)| t)
    }

    fn pos(&self) -> Pos {
        self.tokens.get(self.at).map_or(Pos { line: self.line, col: self.end }, |(_, p)| *p)
    }

    fn error(&self, expected: &str) -> SyntaxError {
        let found = self.peek().map_or_else(|| "the end of the line".into(), Tok::text);
        SyntaxError { pos: self.pos(), found, message: expected.into() }
    }

    fn is_op(&self, op: &str) -> bool {
        matches!(self.peek(), Some(Tok::Op(o)) if *o == op)
    }

    fn is_word(&self, word: &str) -> bool {
        matches!(self.peek(), Some(Tok::Ident(w)) if w == word)
    }

    fn expect_op(&mut self, op: &str, expected: &str) -> Result<(), SyntaxError> {
        if self.is_op(op) {
            self.at += 1;
            Ok(())
        } else {
            Err(self.error(expected))
        }
    }

    fn int(&mut self, expected: &str) -> Result<i64, SyntaxError> {
        match self.peek() {
            Some(Tok::Int(v)) => {
                let v = *v;
                self.at += 1;
                Ok(v)
            }
            _ => Err(self.error(expected)),
        }
    }

    fn done(&self) -> Result<(), SyntaxError> {
        match self.peek() {
            None => Ok(()),
            Some(_) => Err(self.error("the end of the line (or an operator joining what came before)")),
        }
    }

    /// One non-empty line, added to the claims.
    fn line_into(&mut self, claims: &mut Vec<Claim>) -> Result<(), SyntaxError> {
        let pos = self.pos();
        if self.is_word("claim") {
            self.at += 1;
            let Some(Tok::Str(title)) = self.peek().cloned() else {
                return Err(self.error("the claim's title in quotes, e.g. claim \"Eq 22: the mass matrix\""));
            };
            self.at += 1;
            self.done()?;
            let chains = Chains { spatial: false, low: 0, high: None };
            claims.push(Claim {
                title,
                chains,
                entries: Vec::new(),
                corrected: Vec::new(),
                corrected_at: None,
                pos,
            });
            return Ok(());
        }
        let Some(claim) = claims.last_mut() else {
            return Err(self.error("a claim first: claim \"title\""));
        };
        if self.is_word("chain") {
            self.at += 1;
            claim.chains = self.chains()?;
            return self.done();
        }
        if claim.chains.low == 0 {
            return Err(self.error("the chains the claim covers first: chain planar|spatial [n = 1..8]"));
        }
        if self.is_word("corrected") && self.tokens.len() == 1 {
            if claim.corrected_at.is_some() || claim.entries.is_empty() {
                return Err(self.error("one `corrected` per claim, after its entries"));
            }
            claim.corrected_at = Some(pos);
            return Ok(());
        }
        if self.is_op("=") {
            let Some(entry) = claim.current().last_mut() else {
                return Err(self.error("an entry first: quantity[indices] = value"));
            };
            self.at += 1;
            let branch = self.branch(pos, true)?;
            entry.branches.push(branch);
            return Ok(());
        }
        let Some(Tok::Ident(quantity)) = self.peek().cloned() else {
            return Err(self.error("an entry: quantity[indices] = value"));
        };
        self.at += 1;
        let mut indices = Vec::new();
        if self.is_op("[") {
            self.at += 1;
            loop {
                indices.push(self.index()?);
                if self.is_op(",") {
                    self.at += 1;
                    continue;
                }
                self.expect_op("]", "`,` or `]` after an index")?;
                break;
            }
        }
        self.expect_op("=", "`=` after the entry's name")?;
        let branch = self.branch(pos, false)?;
        claim.current().push(Entry { quantity, indices, branches: vec![branch], pos });
        Ok(())
    }

    fn branch(&mut self, pos: Pos, continued: bool) -> Result<Branch, SyntaxError> {
        let value = self.expr()?;
        let mut branch = Branch { value, when: None, otherwise: false, pos };
        if self.is_word("if") {
            self.at += 1;
            branch.when = Some(self.condition()?);
        } else if self.is_word("otherwise") {
            if !continued {
                return Err(self.error("`if` on a first branch (`otherwise` belongs to the last)"));
            }
            self.at += 1;
            branch.otherwise = true;
        }
        self.done()?;
        Ok(branch)
    }

    fn chains(&mut self) -> Result<Chains, SyntaxError> {
        let spatial = match self.peek() {
            Some(Tok::Ident(w)) if w == "planar" => false,
            Some(Tok::Ident(w)) if w == "spatial" => true,
            _ => return Err(self.error("planar or spatial")),
        };
        self.at += 1;
        if self.is_op(",") {
            self.at += 1;
        }
        if self.peek().is_none() {
            return Ok(Chains { spatial, low: 1, high: None });
        }
        if !self.is_word("n") {
            return Err(self.error("n = N, n = A..B, n >= A or n <= B"));
        }
        self.at += 1;
        let what = "a number of links (at least 1)";
        let (low, high) = if self.is_op("=") {
            self.at += 1;
            let low = self.int(what)?;
            if self.is_op("..") {
                self.at += 1;
                (low, Some(self.int(what)?))
            } else {
                (low, Some(low))
            }
        } else if self.is_op(">=") {
            self.at += 1;
            (self.int(what)?, None)
        } else if self.is_op("<=") {
            self.at += 1;
            (1, Some(self.int(what)?))
        } else {
            return Err(self.error("=, >= or <= after n"));
        };
        if low < 1 || high.is_some_and(|h| h < low) {
            return Err(SyntaxError {
                pos: self.pos(),
                found: format!("n from {low} to {}", high.map_or("any".into(), |h| h.to_string())),
                message: "a range of at least one chain of at least 1 link".into(),
            });
        }
        Ok(Chains { spatial, low: low as usize, high: high.map(|h| h as usize) })
    }

    fn condition(&mut self) -> Result<Vec<Compare>, SyntaxError> {
        let mut all = Vec::new();
        loop {
            let left = self.index()?;
            let op = match self.peek() {
                Some(Tok::Op(op @ (">=" | "<=" | "==" | "!=" | "<" | ">"))) => *op,
                _ => return Err(self.error("a comparison: < <= == != >= >")),
            };
            self.at += 1;
            let right = self.index()?;
            all.push(Compare { left, op, right });
            if !self.is_word("and") {
                return Ok(all);
            }
            self.at += 1;
        }
    }

    fn index(&mut self) -> Result<Index, SyntaxError> {
        let mut left = self.index_item()?;
        loop {
            if self.is_op("+") {
                self.at += 1;
                left = Index::Add(Box::new(left), Box::new(self.index_item()?));
            } else if self.is_op("-") {
                self.at += 1;
                left = Index::Sub(Box::new(left), Box::new(self.index_item()?));
            } else {
                return Ok(left);
            }
        }
    }

    fn index_item(&mut self) -> Result<Index, SyntaxError> {
        let pos = self.pos();
        match self.peek().cloned() {
            Some(Tok::Int(v)) => {
                self.at += 1;
                Ok(Index::Int(v))
            }
            Some(Tok::Ident(w)) if w == "max" || w == "min" => {
                self.at += 1;
                self.expect_op("(", "`(` after max or min")?;
                let a = self.index()?;
                self.expect_op(",", "`,` between the two indices of max or min")?;
                let b = self.index()?;
                self.expect_op(")", "`)` closing max or min")?;
                Ok(if w == "max" {
                    Index::Max(Box::new(a), Box::new(b))
                } else {
                    Index::Min(Box::new(a), Box::new(b))
                })
            }
            Some(Tok::Ident(w)) if w.chars().all(|c| c.is_ascii_alphanumeric()) => {
                self.at += 1;
                Ok(Index::Var(w, pos))
            }
            Some(Tok::Op("(")) => {
                self.at += 1;
                let inner = self.index()?;
                self.expect_op(")", "`)` closing the index")?;
                Ok(inner)
            }
            _ => Err(self.error("an index: a whole number, an index name, n, max(…, …) or min(…, …)")),
        }
    }

    fn expr(&mut self) -> Result<Expr, SyntaxError> {
        let first = self.term()?;
        self.more_terms(first)
    }

    fn more_terms(&mut self, mut left: Expr) -> Result<Expr, SyntaxError> {
        loop {
            if self.is_op("+") {
                self.at += 1;
                left = Expr::Add(Box::new(left), Box::new(self.term()?));
            } else if self.is_op("-") {
                self.at += 1;
                left = Expr::Sub(Box::new(left), Box::new(self.term()?));
            } else {
                return Ok(left);
            }
        }
    }

    /// Whether the next token starts a factor (for juxtaposition).
    fn starts_factor(&self) -> bool {
        match self.peek() {
            Some(Tok::Int(_) | Tok::Num(_)) => true,
            Some(Tok::Op("(")) => true,
            Some(Tok::Ident(w)) => !matches!(w.as_str(), "if" | "otherwise" | "and"),
            _ => false,
        }
    }

    fn term(&mut self) -> Result<Expr, SyntaxError> {
        let mut left = self.unary()?;
        loop {
            if self.is_op("*") {
                self.at += 1;
                left = Expr::Mul(Box::new(left), Box::new(self.unary()?), true);
            } else if self.is_op("/") {
                self.at += 1;
                left = Expr::Div(Box::new(left), Box::new(self.unary()?));
            } else if self.starts_factor() {
                left = Expr::Mul(Box::new(left), Box::new(self.unary()?), false);
            } else {
                return Ok(left);
            }
        }
    }

    fn unary(&mut self) -> Result<Expr, SyntaxError> {
        if self.is_op("-") {
            self.at += 1;
            return Ok(Expr::Neg(Box::new(self.unary()?)));
        }
        let base = self.primary()?;
        if !self.is_op("^") {
            return Ok(base);
        }
        self.at += 1;
        let negative = self.is_op("-");
        if negative {
            self.at += 1;
        }
        let k = self.int("a whole exponent, e.g. ^2 or ^-1")?;
        let k = i32::try_from(k).map_err(|_| self.error("an exponent of at most 2^31"))?;
        Ok(Expr::Pow(Box::new(base), if negative { -k } else { k }))
    }

    fn primary(&mut self) -> Result<Expr, SyntaxError> {
        let pos = self.pos();
        match self.peek().cloned() {
            Some(Tok::Int(v)) => {
                self.at += 1;
                Ok(Expr::Num(v as f64))
            }
            Some(Tok::Num(v)) => {
                self.at += 1;
                Ok(Expr::Num(v))
            }
            Some(Tok::Op("(")) => {
                self.at += 1;
                let inner = self.expr()?;
                self.expect_op(")", "`)` closing the bracket")?;
                Ok(inner)
            }
            Some(Tok::Ident(w)) if w == "sum" => {
                self.at += 1;
                self.expect_op("(", "`(` after sum: sum(k = 1..n) term")?;
                let var = match self.peek().cloned() {
                    Some(Tok::Ident(v)) => v,
                    _ => return Err(self.error("the sum's index name: sum(k = 1..n) term")),
                };
                self.at += 1;
                self.expect_op("=", "`=` after the sum's index: sum(k = 1..n) term")?;
                let from = self.index()?;
                self.expect_op("..", "`..` between the sum's bounds: sum(k = 1..n) term")?;
                let to = self.index()?;
                let when = if self.is_word("if") {
                    self.at += 1;
                    Some(self.condition()?)
                } else {
                    None
                };
                self.expect_op(")", "`)` after the sum's bounds (or `if` and a condition)")?;
                let body = self.term()?;
                Ok(Expr::Sum { var, from, to, body: Box::new(body), when, pos })
            }
            Some(Tok::Ident(w)) => {
                self.at += 1;
                if let Some(f) = Func::named(&w) {
                    self.expect_op("(", &format!("`(` after {w}"))?;
                    let arg = self.expr()?;
                    self.expect_op(")", &format!("`)` closing {w}(…)"))?;
                    return Ok(Expr::Call(f, Box::new(arg)));
                }
                if !self.is_op("[") {
                    return Ok(Expr::Sym { name: w, index: None, pos });
                }
                self.at += 1;
                let mut indices = vec![self.index()?];
                while self.is_op(",") {
                    self.at += 1;
                    indices.push(self.index()?);
                }
                self.expect_op("]", "`,` or `]` after an index")?;
                if indices.len() == 1 {
                    Ok(Expr::Sym { name: w, index: indices.pop(), pos })
                } else {
                    Ok(Expr::Ref { name: w, indices, pos })
                }
            }
            _ => Err(self.error("a value: a number, a symbol, a function, sum(…) or a bracket")),
        }
    }
}

#[cfg(test)]
mod tests;
