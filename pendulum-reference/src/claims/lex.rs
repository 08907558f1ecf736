//! The tokens of a claims file's lines, each with its position.

/// Where a token starts: 1-based line and column (in characters).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Pos {
    pub line: usize,
    pub col: usize,
}

/// An error in a claims file: where, the text there, and what was expected.
#[derive(Clone, Debug, PartialEq)]
pub struct SyntaxError {
    pub pos: Pos,
    pub found: String,
    pub message: String,
}

#[derive(Clone, Debug, PartialEq)]
pub(super) enum Tok {
    Ident(String),
    Int(i64),
    Num(f64),
    Str(String),
    Op(&'static str),
}

impl Tok {
    pub(super) fn text(&self) -> String {
        match self {
            Tok::Ident(s) => s.clone(),
            Tok::Int(v) => v.to_string(),
            Tok::Num(v) => v.to_string(),
            Tok::Str(s) => format!("{s:?}"),
            Tok::Op(o) => (*o).to_string(),
        }
    }
}

const OPS: [&str; 18] =
    ["..", ">=", "<=", "==", "!=", "+", "-", "*", "/", "^", "(", ")", "[", "]", ",", "=", "<", ">"];

/// The tokens of one line (comments from `#` dropped), each with its position.
pub(super) fn lex(line: &str, number: usize) -> Result<Vec<(Tok, Pos)>, SyntaxError> {
    let chars: Vec<char> = line.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let pos = Pos { line: number, col: i + 1 };
        if c == '#' {
            break;
        }
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        if c == '"' {
            let end = chars[i + 1..].iter().position(|&d| d == '"').ok_or_else(|| SyntaxError {
                pos,
                found: chars[i..].iter().collect(),
                message: "a string that ends on this line (a closing \")".into(),
            })?;
            out.push((Tok::Str(chars[i + 1..i + 1 + end].iter().collect()), pos));
            i += end + 2;
            continue;
        }
        if c.is_ascii_digit() || (c == '.' && chars.get(i + 1).is_some_and(|d| d.is_ascii_digit())) {
            let start = i;
            while i < chars.len() && chars[i].is_ascii_digit() {
                i += 1;
            }
            // A decimal point, unless it starts a range `1..n`.
            let mut float = false;
            if i < chars.len() && chars[i] == '.' && chars.get(i + 1) != Some(&'.') {
                float = true;
                i += 1;
                while i < chars.len() && chars[i].is_ascii_digit() {
                    i += 1;
                }
            }
            if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                let sign = usize::from(matches!(chars.get(i + 1), Some('+' | '-')));
                if chars.get(i + 1 + sign).is_some_and(|d| d.is_ascii_digit()) {
                    float = true;
                    i += 1 + sign;
                    while i < chars.len() && chars[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let text: String = chars[start..i].iter().collect();
            let tok = if float {
                let v: f64 = text.parse().map_err(|_| bad_number(pos, &text))?;
                if !v.is_finite() {
                    return Err(bad_number(pos, &text));
                }
                Tok::Num(v)
            } else {
                Tok::Int(text.parse().map_err(|_| bad_number(pos, &text))?)
            };
            out.push((tok, pos));
            continue;
        }
        if c.is_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len()
                && (chars[i].is_alphanumeric()
                    || chars[i] == '_'
                    || matches!(chars[i], '\u{307}' | '\u{308}'))
            {
                i += 1;
            }
            out.push((Tok::Ident(chars[start..i].iter().collect()), pos));
            continue;
        }
        let rest: String = chars[i..].iter().take(2).collect();
        let Some(op) = OPS.iter().find(|op| rest.starts_with(**op)) else {
            return Err(SyntaxError {
                pos,
                found: c.to_string(),
                message: "a number, a name, an operator (+ - * / ^), brackets or a comparison".into(),
            });
        };
        out.push((Tok::Op(op), pos));
        i += op.chars().count();
    }
    Ok(out)
}

fn bad_number(pos: Pos, text: &str) -> SyntaxError {
    SyntaxError { pos, found: text.into(), message: "a finite number (whole numbers below 2^63)".into() }
}
