//! Diagnoses: the common slips of a hand derivation, each tried as a change to the
//! disagreeing entry; a change that makes it agree with the reference is the diagnosis,
//! and the changed entry is the corrected claim.
//!
//! Tried in order: a constant factor (its sign included: an overall sign, ½, 2, …); the
//! sign of one triangle (i > j or i < j); sin for cos or cos for sin at one place;
//! a coordinate for its rate (or the reverse) at one place; transposed indices; an index
//! off by one at one place; the wrong tail-mass index; a missing part of a sum (the rest
//! of its index range).

use super::check::{Samples, Tally, check_entry};
use super::syntax::{Branch, Compare, Entry, Expr, Func, Index, Pos};
use crate::case::Case;

/// A slip that explains a disagreement exactly, and the entry corrected.
#[derive(Clone, Debug)]
pub struct Diagnosis {
    pub slip: String,
    pub corrected: Entry,
}

/// States per case a candidate correction is checked at.
const STATES: usize = 3;

/// The first slip that makes `entry` agree, given what checking it found.
pub fn diagnose<'a>(
    entry: &Entry,
    tally: &Tally,
    cases: &[&'a Case],
    samples: &Samples<'a>,
) -> Option<Diagnosis> {
    candidates(entry, tally)
        .into_iter()
        .find(|(_, corrected)| check_entry(corrected, cases, STATES, samples).is_ok_and(|t| t.agrees()))
        .map(|(slip, corrected)| Diagnosis { slip, corrected })
}

/// A simple fraction near `r` (denominator up to 4, numerator up to 8), if there is one.
fn fraction(r: f64) -> Option<(i64, i64)> {
    (1..=4).find_map(|q| {
        let p = (r * q as f64).round();
        ((r - p / q as f64).abs() < 1e-9 * r.abs().max(1.0) && p != 0.0 && p.abs() <= 8.0)
            .then_some((p as i64, q))
    })
}

/// The rate of a coordinate, or the coordinate of a rate, in the same spelling.
fn partner(name: &str) -> Option<&'static str> {
    Some(match name {
        "theta" => "thetadot",
        "thetadot" => "theta",
        "θ" => "θ̇",
        "θ̇" => "θ",
        "phi" => "phidot",
        "phidot" => "phi",
        "φ" => "φ̇",
        "φ̇" => "φ",
        _ => return None,
    })
}

/// `entry` with branch `k`'s value replaced.
fn with_branch(entry: &Entry, k: usize, value: Expr) -> Entry {
    let mut changed = entry.clone();
    changed.branches[k].value = value;
    changed
}

fn with_values(entry: &Entry, mut f: impl FnMut(&Expr) -> Expr) -> Entry {
    let mut e = entry.clone();
    for b in &mut e.branches {
        b.value = f(&b.value);
    }
    e
}

/// Every candidate correction, with a sentence naming the slip.
fn candidates(entry: &Entry, tally: &Tally) -> Vec<(String, Entry)> {
    let mut out = Vec::new();
    // A constant factor, estimated from the largest disagreeing entry.
    if let Some((p, q)) = tally.largest.and_then(|(claimed, reference)| fraction(reference / claimed)) {
        let slip = match (p, q) {
            (-1, 1) => "the overall sign: the reference is −1 × the claim".to_string(),
            (p, q) if p < 0 => {
                format!("a constant factor and the sign: the reference is {} × the claim", ratio(p, q))
            }
            (p, q) => format!("a constant factor: the reference is {} × the claim", ratio(p, q)),
        };
        let corrected = with_values(entry, |v| match (p, q) {
            (-1, 1) => negate(v),
            (p, 1) => times(p as f64, v),
            (p, q) => {
                let factor = Expr::Div(Box::new(Expr::Num(p as f64)), Box::new(Expr::Num(q as f64)));
                Expr::Mul(Box::new(factor), Box::new(v.clone()), false)
            }
        });
        out.push((slip, corrected));
    }
    // The sign of one triangle.
    if let [Index::Var(i, _), Index::Var(j, _)] = entry.indices.as_slice() {
        let conditioned = entry.branches.iter().any(|b| b.when.is_some());
        if conditioned {
            for (k, b) in entry.branches.iter().enumerate() {
                let e = with_branch(entry, k, negate(&b.value));
                let when = b.when.as_ref().map_or("otherwise".to_string(), |w| {
                    format!("if {}", w.iter().map(Compare::to_string).collect::<Vec<_>>().join(" and "))
                });
                out.push((format!("the sign of one triangle: the branch `{when}` has the wrong sign"), e));
            }
        } else {
            for (op, name) in [(">", "lower"), ("<", "upper")] {
                let var = |v: &String| Index::Var(v.clone(), Pos::default());
                let when = vec![Compare { left: var(i), op, right: var(j) }];
                let mut e = entry.clone();
                let value = entry.branches[0].value.clone();
                e.branches = vec![
                    Branch { value: negate(&value), when: Some(when), otherwise: false, pos: entry.pos },
                    Branch { value, when: None, otherwise: true, pos: entry.pos },
                ];
                out.push((format!("the sign of the {name} triangle ({i} {op} {j})"), e));
            }
        }
    }
    for (k, b) in entry.branches.iter().enumerate() {
        let at = |e: Expr| with_branch(entry, k, e);
        // sin ↔ cos at one place.
        let trig = |e: &Expr| matches!(e, Expr::Call(Func::Sin | Func::Cos, _));
        for site in 0..count(&b.value, &trig) {
            let mut found = String::new();
            let e = replace_nth(&b.value, site, &mut 0, &trig, &mut |e| {
                let Expr::Call(f, arg) = e else { unreachable!() };
                let swapped = if *f == Func::Sin { Func::Cos } else { Func::Sin };
                found = format!(
                    "{} for {}: `{e}` should be `{}({arg})`",
                    f.name(),
                    swapped.name(),
                    swapped.name()
                );
                Expr::Call(swapped, arg.clone())
            });
            out.push((found, at(e)));
        }
    }
    // A coordinate for its rate, or a rate for its coordinate, at one place.
    for (k, b) in entry.branches.iter().enumerate() {
        let paired = |e: &Expr| matches!(e, Expr::Sym { name, .. } if partner(name).is_some());
        for site in 0..count(&b.value, &paired) {
            let mut found = String::new();
            let e = replace_nth(&b.value, site, &mut 0, &paired, &mut |e| {
                let Expr::Sym { name, index, pos } = e else { unreachable!() };
                let other = partner(name).unwrap_or(name).to_string();
                let changed = Expr::Sym { name: other, index: index.clone(), pos: *pos };
                found = format!("a coordinate confused with its rate: `{e}` should be `{changed}`");
                changed
            });
            out.push((found, with_branch(entry, k, e)));
        }
    }
    // The same, at every place it is written the same way (in every branch).
    let mut spellings: Vec<String> = Vec::new();
    for b in &entry.branches {
        let paired = |e: &Expr| matches!(e, Expr::Sym { name, .. } if partner(name).is_some());
        for site in 0..count(&b.value, &paired) {
            replace_nth(&b.value, site, &mut 0, &paired, &mut |e| {
                spellings.push(e.to_string());
                e.clone()
            });
        }
    }
    spellings.sort();
    spellings.dedup();
    for spelling in spellings {
        let same = |e: &Expr| {
            matches!(e, Expr::Sym { name, .. } if partner(name).is_some()) && e.to_string() == spelling
        };
        let mut changed_to = String::new();
        let changed = with_values(entry, |v| {
            let mut v = v.clone();
            while count(&v, &same) > 0 {
                v = replace_nth(&v, 0, &mut 0, &same, &mut |e| {
                    let Expr::Sym { name, index, pos } = e else { unreachable!() };
                    let other = Expr::Sym {
                        name: partner(name).unwrap_or(name).into(),
                        index: index.clone(),
                        pos: *pos,
                    };
                    changed_to = other.to_string();
                    other
                });
            }
            v
        });
        out.push((
            format!("a coordinate confused with its rate: every `{spelling}` should be `{changed_to}`"),
            changed,
        ));
    }
    // Transposed indices.
    if let [Index::Var(i, _), Index::Var(j, _)] = entry.indices.as_slice() {
        let swapped = with_values(entry, |v| rename(v, i, j));
        out.push((format!("transposed indices: {i} and {j} exchanged"), swapped));
    }
    for (k, b) in entry.branches.iter().enumerate() {
        let at = |e: Expr| with_branch(entry, k, e);
        let indexed = |e: &Expr| matches!(e, Expr::Sym { index: Some(_), .. });
        // An index off by one at one place.
        for site in 0..count(&b.value, &indexed) {
            for (shift, word) in [(1, "+1"), (-1, "-1")] {
                let mut found = String::new();
                let e = replace_nth(&b.value, site, &mut 0, &indexed, &mut |e| {
                    let Expr::Sym { name, index: Some(index), pos } = e else { unreachable!() };
                    let moved = shifted(index, shift);
                    found = format!(
                        "an index off by one: `{name}[{index}]` should be `{name}[{moved}]` ({word})"
                    );
                    Expr::Sym { name: name.clone(), index: Some(moved), pos: *pos }
                });
                out.push((found, at(e)));
            }
        }
        // The wrong tail-mass index.
        let tail = |e: &Expr| matches!(e, Expr::Sym { name, index: Some(_), .. } if name == "M");
        let choices = tail_choices(entry);
        for choice in &choices {
            let other = |e: &Expr| {
                tail(e)
                    && !matches!(e, Expr::Sym { index: Some(i), .. } if i.to_string() == choice.to_string())
            };
            for site in 0..count(&b.value, &other) {
                let mut found = String::new();
                let e = replace_nth(&b.value, site, &mut 0, &other, &mut |e| {
                    let Expr::Sym { name, index: Some(index), pos } = e else { unreachable!() };
                    found = format!("the wrong tail-mass index: `M[{index}]` should be `M[{choice}]`");
                    Expr::Sym { name: name.clone(), index: Some(choice.clone()), pos: *pos }
                });
                out.push((found, at(e)));
            }
        }
    }
    // A missing part of a sum, at either end of its range and at any depth of nesting:
    // the rest of the chain's range (1..from−1, to+1..n), or the one term next to either
    // end, with the tail-mass index as written or as one of the choices above. The sum is
    // mended where it stands, so a sum inside another keeps its bound indices; where the
    // body is the claim's own, the corrected sum runs over the whole range.
    for (k, b) in entry.branches.iter().enumerate() {
        let sums = |e: &Expr| matches!(e, Expr::Sum { .. });
        for site in 0..count(&b.value, &sums) {
            let mut found = Vec::new();
            replace_nth(&b.value, site, &mut 0, &sums, &mut |e| {
                found.push(e.clone());
                e.clone()
            });
            let Some(Expr::Sum { var, from, to, body, when, pos }) = found.pop() else { continue };
            let below = shifted(&from, -1);
            let above = shifted(&to, 1);
            // (low, high) of the missing part, and the range it makes with the claim's.
            let rests = [
                (Index::Int(1), below.clone(), (Index::Int(1), to.clone())),
                (
                    above.clone(),
                    Index::Var("n".into(), Pos::default()),
                    (from.clone(), Index::Var("n".into(), Pos::default())),
                ),
                (below.clone(), below.clone(), (below.clone(), to.clone())),
                (above.clone(), above.clone(), (from.clone(), above.clone())),
            ];
            let mut bodies = vec![(*body).clone()];
            let tail = |e: &Expr| matches!(e, Expr::Sym { name, index: Some(_), .. } if name == "M");
            for choice in tail_choices(entry).iter().chain([&Index::Var(var.clone(), Pos::default())]) {
                for site in 0..count(&body, &tail) {
                    bodies.push(replace_nth(&body, site, &mut 0, &tail, &mut |e| {
                        let Expr::Sym { name, pos, .. } = e else { unreachable!() };
                        Expr::Sym { name: name.clone(), index: Some(choice.clone()), pos: *pos }
                    }));
                }
            }
            let sum = |low: &Index, high: &Index, body: &Expr| Expr::Sum {
                var: var.clone(),
                from: low.clone(),
                to: high.clone(),
                body: Box::new(body.clone()),
                when: when.clone(),
                pos,
            };
            let claimed = sum(&from, &to, &body);
            for (low, high, (whole_low, whole_high)) in &rests {
                for (b_index, mended_body) in bodies.iter().enumerate() {
                    let term = sum(low, high, mended_body);
                    let (slip, mended) = if b_index == 0 {
                        let whole = sum(whole_low, whole_high, &body);
                        (
                            format!(
                                "a missing term: the sum `{claimed}` stops short; the reference's runs over \
                                 {var} = {whole_low}..{whole_high} (it has `+ {term}` that the claim lacks)"
                            ),
                            whole,
                        )
                    } else {
                        (
                            format!("a missing term: the reference has `+ {term}` that the claim lacks"),
                            Expr::Add(Box::new(claimed.clone()), Box::new(term.clone())),
                        )
                    };
                    let value = replace_nth(&b.value, site, &mut 0, &sums, &mut |_| mended.clone());
                    out.push((slip, with_branch(entry, k, value)));
                }
            }
        }
    }
    out
}

/// The tail-mass indices a slip may have confused: the entry's index names, and for
/// two, their max and min.
fn tail_choices(entry: &Entry) -> Vec<Index> {
    let names: Vec<String> = entry
        .indices
        .iter()
        .filter_map(|i| match i {
            Index::Var(v, _) => Some(v.clone()),
            _ => None,
        })
        .collect();
    let var = |v: &String| Index::Var(v.clone(), Pos::default());
    let mut choices: Vec<Index> = names.iter().map(var).collect();
    if let [a, b] = names.as_slice() {
        choices.push(Index::Max(Box::new(var(a)), Box::new(var(b))));
        choices.push(Index::Min(Box::new(var(a)), Box::new(var(b))));
    }
    choices
}

/// `k e` with the factor merged into a leading number or sign (`2 (-x y)` is `-2 x y`).
fn times(k: f64, e: &Expr) -> Expr {
    match e {
        Expr::Num(v) => Expr::Num(k * v),
        Expr::Neg(inner) => times(-k, inner),
        Expr::Mul(a, b, x) => Expr::Mul(Box::new(times(k, a)), b.clone(), *x),
        Expr::Div(a, b) => Expr::Div(Box::new(times(k, a)), b.clone()),
        other => Expr::Mul(Box::new(Expr::Num(k)), Box::new(other.clone()), false),
    }
}

/// `−e`, without a double sign: the sign goes on a product's first factor.
fn negate(e: &Expr) -> Expr {
    match e {
        Expr::Neg(inner) => (**inner).clone(),
        Expr::Num(v) => Expr::Num(-v),
        Expr::Mul(a, b, x) => Expr::Mul(Box::new(negate(a)), b.clone(), *x),
        Expr::Div(a, b) => Expr::Div(Box::new(negate(a)), b.clone()),
        other => Expr::Neg(Box::new(other.clone())),
    }
}

fn ratio(p: i64, q: i64) -> String {
    if q == 1 { p.to_string() } else { format!("{p}/{q}") }
}

/// `index + shift`, written simply.
fn shifted(index: &Index, shift: i64) -> Index {
    match index {
        Index::Int(v) => Index::Int(v + shift),
        Index::Add(a, b) if matches!(**b, Index::Int(_)) => {
            let Index::Int(v) = **b else { unreachable!() };
            simplify(a, v + shift)
        }
        Index::Sub(a, b) if matches!(**b, Index::Int(_)) => {
            let Index::Int(v) = **b else { unreachable!() };
            simplify(a, shift - v)
        }
        other => simplify(other, shift),
    }
}

fn simplify(base: &Index, offset: i64) -> Index {
    match offset {
        0 => base.clone(),
        k if k > 0 => Index::Add(Box::new(base.clone()), Box::new(Index::Int(k))),
        k => Index::Sub(Box::new(base.clone()), Box::new(Index::Int(-k))),
    }
}

/// How many nodes of `e` satisfy `eligible`.
fn count(e: &Expr, eligible: &dyn Fn(&Expr) -> bool) -> usize {
    let here = usize::from(eligible(e));
    here + match e {
        Expr::Num(_) | Expr::Sym { .. } | Expr::Ref { .. } => 0,
        Expr::Neg(a) | Expr::Pow(a, _) | Expr::Call(_, a) => count(a, eligible),
        Expr::Add(a, b) | Expr::Sub(a, b) | Expr::Mul(a, b, _) | Expr::Div(a, b) => {
            count(a, eligible) + count(b, eligible)
        }
        Expr::Sum { body, .. } => count(body, eligible),
    }
}

/// `e` with its `target`-th `eligible` node (in the order [`count`] visits them)
/// replaced by `make` of it.
fn replace_nth(
    e: &Expr,
    target: usize,
    seen: &mut usize,
    eligible: &dyn Fn(&Expr) -> bool,
    make: &mut dyn FnMut(&Expr) -> Expr,
) -> Expr {
    if eligible(e) {
        let hit = *seen == target;
        *seen += 1;
        if hit {
            return make(e);
        }
    }
    e.map_children(&mut |a| replace_nth(a, target, seen, eligible, make))
}

/// `e` with the index names `a` and `b` exchanged everywhere.
fn rename(e: &Expr, a: &str, b: &str) -> Expr {
    match e {
        Expr::Sym { name, index, pos } => {
            Expr::Sym { name: name.clone(), index: index.as_ref().map(|i| rename_index(i, a, b)), pos: *pos }
        }
        Expr::Ref { name, indices, pos } => Expr::Ref {
            name: name.clone(),
            indices: indices.iter().map(|i| rename_index(i, a, b)).collect(),
            pos: *pos,
        },
        Expr::Sum { var, from, to, body, when, pos } => Expr::Sum {
            var: var.clone(),
            from: rename_index(from, a, b),
            to: rename_index(to, a, b),
            body: Box::new(rename(body, a, b)),
            when: when.as_ref().map(|w| {
                w.iter()
                    .map(|c| Compare {
                        left: rename_index(&c.left, a, b),
                        op: c.op,
                        right: rename_index(&c.right, a, b),
                    })
                    .collect()
            }),
            pos: *pos,
        },
        other => other.map_children(&mut |x| rename(x, a, b)),
    }
}

fn rename_index(i: &Index, a: &str, b: &str) -> Index {
    let go = |x: &Index| Box::new(rename_index(x, a, b));
    match i {
        Index::Var(v, p) if v == a => Index::Var(b.into(), *p),
        Index::Var(v, p) if v == b => Index::Var(a.into(), *p),
        Index::Int(_) | Index::Var(..) => i.clone(),
        Index::Add(x, y) => Index::Add(go(x), go(y)),
        Index::Sub(x, y) => Index::Sub(go(x), go(y)),
        Index::Max(x, y) => Index::Max(go(x), go(y)),
        Index::Min(x, y) => Index::Min(go(x), go(y)),
    }
}
