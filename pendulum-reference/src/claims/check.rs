//! A claim against the reference: every entry at every random state of every case it
//! covers, with the relative error of the document's checks.

use std::cell::RefCell;
use std::collections::{BTreeSet, HashMap};
use std::rc::Rc;

use rand::Rng;

use super::eval::{Bindings, EvalError, QUANTITIES, Quantity, Truth, entry_value};
use super::state::State;
use super::syntax::{Claim, Entry, Index};
use crate::case::{Case, Kind};
use crate::expr::Scaled;

/// A claim agrees with the reference if its worst relative error is below this.
pub const AGREEMENT: f64 = 1e-10;

/// `|c − r| / (scale_c + scale_r)`; 0 if they are equal, ∞ if they differ at zero scale.
pub fn relative_error(claimed: Scaled, reference: Scaled) -> f64 {
    let diff = (claimed.v - reference.v).abs();
    if diff == 0.0 {
        return 0.0;
    }
    diff / (claimed.s + reference.s)
}

/// What checking one entry found.
#[derive(Clone, Debug, Default)]
pub struct Tally {
    /// Compared numbers.
    pub count: usize,
    /// The worst relative error.
    pub worst: f64,
    /// The first disagreeing entry: case, state, entry, claimed and reference values.
    pub first: Option<String>,
    /// Of the disagreeing entries, the one with the largest claimed value: (claim, reference).
    pub largest: Option<(f64, f64)>,
}

impl Tally {
    pub fn agrees(&self) -> bool {
        self.count > 0 && self.worst < AGREEMENT
    }

    fn record(&mut self, claimed: Scaled, reference: Scaled, entry: impl FnOnce() -> String) {
        let rel = relative_error(claimed, reference);
        self.count += 1;
        if rel > self.worst || (rel.is_nan() && !self.worst.is_nan()) {
            self.worst = rel;
        }
        if rel >= AGREEMENT || rel.is_nan() {
            if self.first.is_none() {
                self.first =
                    Some(format!("{}: claimed {:.6e}, reference {:.6e}", entry(), claimed.v, reference.v));
            }
            if self.largest.is_none_or(|(c, _)| claimed.v.abs() > c.abs()) {
                self.largest = Some((claimed.v, reference.v));
            }
        }
    }
}

/// The cases a claim covers.
pub fn covered<'a>(claim: &Claim, cases: &'a [Case]) -> Vec<&'a Case> {
    let kind = if claim.chains.spatial { Kind::Spatial } else { Kind::Planar };
    cases
        .iter()
        .filter(|c| {
            c.kind == kind && c.links >= claim.chains.low && claim.chains.high.is_none_or(|h| c.links <= h)
        })
        .collect()
}

/// The names of an entry's indices, in order (checked: names or whole numbers only).
fn entry_indices(entry: &Entry) -> Result<Vec<IndexSlot>, EvalError> {
    entry
        .indices
        .iter()
        .map(|index| match index {
            Index::Int(v) => Ok(IndexSlot::Fixed(*v)),
            Index::Var(name, _) => Ok(IndexSlot::Name(name.clone())),
            other => Err(EvalError {
                pos: entry.pos,
                found: other.to_string(),
                message: "an entry index that is a name (i, j, …) or a whole number".into(),
            }),
        })
        .collect()
}

enum IndexSlot {
    Fixed(i64),
    Name(String),
}

/// The quantity an entry names, checked against the chains and its number of indices.
pub fn quantity_of(entry: &Entry, kind: Kind) -> Result<Quantity, EvalError> {
    let q = Quantity::named(&entry.quantity).ok_or_else(|| EvalError {
        pos: entry.pos,
        found: entry.quantity.clone(),
        message: format!("a quantity: {QUANTITIES}"),
    })?;
    if let Some(only) = q.only().filter(|&k| k != kind) {
        return Err(EvalError {
            pos: entry.pos,
            found: entry.quantity.clone(),
            message: format!(
                "a quantity of {kind} chains ({} is defined for {only} chains only)",
                entry.quantity
            ),
        });
    }
    let rank = q.shape(kind, 1).len();
    if entry.indices.len() != rank {
        let count = |k: usize| match k {
            0 => "no index".to_string(),
            1 => "1 index".to_string(),
            k => format!("{k} indices"),
        };
        let what = ["a number", "a vector", "a matrix"][rank.min(2)];
        return Err(EvalError {
            pos: entry.pos,
            found: format!("{} with {}", entry.quantity, count(entry.indices.len())),
            message: format!("{} ({} is {what})", count(rank), entry.quantity),
        });
    }
    Ok(q)
}

/// Every combination of the entry's indices for the quantity's shape, 1-based, with the
/// bindings of its index names; a fixed index outside the shape is an error.
pub fn combinations(
    entry: &Entry,
    shape: &[usize],
    n: usize,
) -> Result<Vec<(Vec<usize>, Bindings)>, EvalError> {
    let slots = entry_indices(entry)?;
    let mut all = vec![(Vec::new(), Bindings::new())];
    for (slot, &size) in slots.iter().zip(shape) {
        let mut next = Vec::new();
        for (at, bound) in all {
            let values: Vec<i64> = match slot {
                IndexSlot::Fixed(v) => {
                    if !(1..=size as i64).contains(v) {
                        return Err(EvalError {
                            pos: entry.pos,
                            found: format!("{}[…{v}…]", entry.quantity),
                            message: format!("an entry the quantity has: indices 1..{size} for n = {n}"),
                        });
                    }
                    vec![*v]
                }
                IndexSlot::Name(name) => match bound.get(name) {
                    Some(v) => vec![*v],
                    None => (1..=size as i64).collect(),
                },
            };
            for v in values {
                let mut bound = bound.clone();
                if let IndexSlot::Name(name) = slot {
                    bound.insert(name.clone(), v);
                }
                let mut at = at.clone();
                at.push(v as usize);
                next.push((at, bound));
            }
        }
        all = next;
    }
    Ok(all)
}

/// The entry's label at 1-based indices: `M[1,2]`.
fn label(entry: &Entry, at: &[usize]) -> String {
    if at.is_empty() {
        return entry.quantity.clone();
    }
    let at: Vec<String> = at.iter().map(usize::to_string).collect();
    format!("{}[{}]", entry.quantity, at.join(","))
}

/// One state's reference, shared by every entry that reads it.
type Shared<'a> = Rc<Truth<'a>>;

/// The reference at the random states, each evaluated once for every entry and claim
/// that asks (with the coefficient matrices it derives, as they are asked for).
pub struct Samples<'a> {
    seed: u64,
    evaluated: RefCell<HashMap<(String, usize), Shared<'a>>>,
}

impl<'a> Samples<'a> {
    /// The states of `cargo xtask verify` for `seed` ([`crate::sample::state`]).
    pub fn new(seed: u64) -> Self {
        Self { seed, evaluated: RefCell::new(HashMap::new()) }
    }

    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// State `index` of `case`, evaluated by the reference.
    fn get(&self, case: &'a Case, index: usize) -> Shared<'a> {
        let key = (case.name.clone(), index);
        if let Some(truth) = self.evaluated.borrow().get(&key) {
            return Rc::clone(truth);
        }
        // The accelerations EL is taken at are drawn after the state, from the same
        // generator: the ones the document check draws.
        let (params, point, mut rng) = crate::sample::state_with_rng(self.seed, case.kind, case.links, index);
        let qdd: Vec<f64> = (0..case.dof()).map(|_| rng.random_range(-2.0..2.0)).collect();
        let (ev, sc) = case.evaluate_with_scales(&params, &point);
        let truth = Rc::new(Truth::new(State { case, params, point, ev, sc }, qdd));
        self.evaluated.borrow_mut().insert(key, Rc::clone(&truth));
        truth
    }
}

/// Checks one entry of a claim at `states` random states of every covered case.
pub fn check_entry<'a>(
    entry: &Entry,
    cases: &[&'a Case],
    states: usize,
    samples: &Samples<'a>,
) -> Result<Tally, BTreeSet<(usize, usize, String, String)>> {
    let mut tally = Tally::default();
    let mut errors = BTreeSet::new();
    let mut fail = |e: EvalError| {
        errors.insert((e.pos.line, e.pos.col, e.found, e.message));
    };
    for &case in cases {
        let n = case.links;
        let quantity = match quantity_of(entry, case.kind) {
            Ok(q) => q,
            Err(e) => {
                fail(e);
                continue;
            }
        };
        let combos = match combinations(entry, &quantity.shape(case.kind, n), n) {
            Ok(c) => c,
            Err(e) => {
                fail(e);
                continue;
            }
        };
        for index in 0..states {
            let truth = samples.get(case, index);
            for (at, bound) in &combos {
                let mut bound = bound.clone();
                let claimed = match entry_value(&truth, entry, &mut bound) {
                    Ok(Some(v)) => v,
                    Ok(None) => continue,
                    Err(e) => {
                        fail(e);
                        continue;
                    }
                };
                let zero_based: Vec<usize> = at.iter().map(|v| v - 1).collect();
                let Some(reference) = truth.reference(quantity, &zero_based) else { continue };
                tally.record(claimed, reference, || {
                    format!("{} state {index}: {}", case.name, label(entry, at))
                });
            }
        }
    }
    if errors.is_empty() { Ok(tally) } else { Err(errors) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_error_is_scaled_and_zero_safe() {
        assert_eq!(relative_error(Scaled::zero(), Scaled::zero()), 0.0);
        assert_eq!(relative_error(Scaled::exact(1.0), Scaled::zero()), 1.0);
        let a = Scaled::exact(0.3).sin() * Scaled::exact(2.0);
        assert!(relative_error(a, Scaled::with_scale(2.0 * 0.3f64.sin(), 2.0)) < 1e-15);
        assert!(relative_error(-a, Scaled::with_scale(2.0 * 0.3f64.sin(), 2.0)) > 0.1);
    }
}
