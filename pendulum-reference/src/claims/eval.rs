//! What a claim's names mean, and its value at one state of one reference case.
//!
//! The left side names a quantity of the reference (`M q̈ + c + k + d = Q`; T, U; the
//! accelerations; the planar velocity coefficients S, `S θ̇² = −c`; the spatial blocks of
//! eq 30: A11…A22 of M, B11…B22 and C1, C2 with `B [θ̇²; φ̇²] − C [θ̇φ̇] = −c`; `qdd` the
//! accelerations of the free chain, `M⁻¹(−c − k)`: no torques, damping or pivot motion). The right
//! side is evaluated with [`Scaled`] arithmetic, so its round-off scale is tracked as the
//! document's checks do.

use std::cell::OnceCell;
use std::collections::HashMap;

use super::state::{State, tail_masses};
use super::syntax::{Compare, Entry, Expr, Func, Index, Pos};
use crate::case::Kind;
use crate::expr::Scaled;

/// A quantity a claim's entry can name, with its shape for `n` links.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    MassMatrix,
    Velocity,
    Gravity,
    Pivot,
    Forces,
    Kinetic,
    Potential,
    Accelerations,
    /// `(M q̈ + c + k)_i` at the accelerations θ̈, φ̈ drawn with the state: the
    /// Euler–Lagrange expression `d/dt ∂L/∂q̇_i − ∂L/∂q_i`.
    EulerLagrange,
    /// `−(c + k)`: the right side of the free chain's `M q̈ = −(c + k)`.
    FreeRhs,
    /// Planar `S`, `S θ̇² = −c`.
    S,
    /// Spatial block `(row block, column block)` of M, 0-based.
    A(usize, usize),
    /// Spatial block of B.
    B(usize, usize),
    /// Spatial C1 (θ rows) or C2 (φ rows).
    C(usize),
}

/// Every quantity name a claim may use, and what it means.
pub const QUANTITIES: &str = "M (mass matrix) [i,j], c (velocity terms) [i], k (gravity terms) [i], \
d (pivot terms) [i], Q (generalized forces) [i], T, U, qdd (free accelerations) [i], \
EL (M θ̈ + c + k at random θ̈) [i], rhs (−c − k) [i]; planar S [i,j]; \
spatial A11 A12 A21 A22 B11 B12 B21 B22 C1 C2 [i,j]";

impl Quantity {
    pub fn named(name: &str) -> Option<Quantity> {
        Some(match name {
            "M" | "mass_matrix" => Quantity::MassMatrix,
            "c" | "velocity_terms" => Quantity::Velocity,
            "k" | "h" | "gravity_terms" => Quantity::Gravity,
            "d" | "pivot_terms" => Quantity::Pivot,
            "Q" | "f" | "forces" => Quantity::Forces,
            "T" => Quantity::Kinetic,
            "U" => Quantity::Potential,
            "qdd" | "accelerations" => Quantity::Accelerations,
            "EL" | "lagrange" => Quantity::EulerLagrange,
            "rhs" => Quantity::FreeRhs,
            "S" => Quantity::S,
            "A11" => Quantity::A(0, 0),
            "A12" => Quantity::A(0, 1),
            "A21" => Quantity::A(1, 0),
            "A22" => Quantity::A(1, 1),
            "B11" => Quantity::B(0, 0),
            "B12" => Quantity::B(0, 1),
            "B21" => Quantity::B(1, 0),
            "B22" => Quantity::B(1, 1),
            "C1" => Quantity::C(0),
            "C2" => Quantity::C(1),
            _ => return None,
        })
    }

    /// The chains it exists for (`None`: both).
    pub fn only(self) -> Option<Kind> {
        match self {
            Quantity::S => Some(Kind::Planar),
            Quantity::A(..) | Quantity::B(..) | Quantity::C(_) => Some(Kind::Spatial),
            _ => None,
        }
    }

    /// Its shape for `n` links of `kind`: the number of indices and each one's range.
    pub fn shape(self, kind: Kind, n: usize) -> Vec<usize> {
        let dof = kind.dof(n);
        match self {
            Quantity::Kinetic | Quantity::Potential => vec![],
            Quantity::MassMatrix => vec![dof, dof],
            Quantity::Velocity
            | Quantity::Gravity
            | Quantity::Pivot
            | Quantity::Forces
            | Quantity::Accelerations
            | Quantity::EulerLagrange
            | Quantity::FreeRhs => vec![dof],
            Quantity::S | Quantity::A(..) | Quantity::B(..) | Quantity::C(_) => vec![n, n],
        }
    }
}

/// A symbol of a claim's right side.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Symbol {
    Theta,
    Phi,
    ThetaDot,
    PhiDot,
    /// The accelerations `EL` is taken at: random, drawn with the state.
    ThetaDdot,
    PhiDdot,
    Mass,
    TailMass,
    Length,
    Damping,
    Torque,
    Gravity,
    Links,
    Pi,
    Pivot(usize),
}

/// Every symbol a claim may use.
pub const SYMBOLS: &str = "theta θ, phi φ, thetadot θ̇, phidot φ̇ (coordinates and rates) [i], \
thetaddot θ̈, phiddot φ̈ (the accelerations EL is taken at) [i], m (masses) [i], \
M (tail masses M_i = Σ_{k≥i} m_k) [i], l (lengths) [i], lambda λ (damping) [i], sigma σ (torques) [i], \
g, n, pi, ax ay az (pivot acceleration)";

impl Symbol {
    pub fn named(name: &str) -> Option<Symbol> {
        Some(match name {
            "theta" | "θ" | "th" => Symbol::Theta,
            "phi" | "φ" | "ph" => Symbol::Phi,
            "thetadot" | "θ̇" | "dtheta" | "thd" => Symbol::ThetaDot,
            "phidot" | "φ̇" | "dphi" | "phd" => Symbol::PhiDot,
            "thetaddot" | "θ̈" | "ddtheta" => Symbol::ThetaDdot,
            "phiddot" | "φ̈" | "ddphi" => Symbol::PhiDdot,
            "m" => Symbol::Mass,
            "M" => Symbol::TailMass,
            "l" => Symbol::Length,
            "lambda" | "λ" => Symbol::Damping,
            "sigma" | "σ" => Symbol::Torque,
            "g" => Symbol::Gravity,
            "n" => Symbol::Links,
            "pi" | "π" => Symbol::Pi,
            "ax" => Symbol::Pivot(0),
            "ay" => Symbol::Pivot(1),
            "az" => Symbol::Pivot(2),
            _ => return None,
        })
    }

    pub fn indexed(self) -> bool {
        !matches!(self, Symbol::Gravity | Symbol::Links | Symbol::Pi | Symbol::Pivot(_))
    }
}

/// A problem found while evaluating: where, and what.
#[derive(Clone, Debug, PartialEq)]
pub struct EvalError {
    pub pos: Pos,
    pub found: String,
    pub message: String,
}

/// The most terms a sum may have (a bound that stops a mistyped range from running on).
const MAX_TERMS: i64 = 100_000;

/// Index variables bound at a point of the evaluation (1-based values).
pub type Bindings = HashMap<String, i64>;

/// An index's value.
pub fn index_value(index: &Index, bound: &Bindings, n: usize) -> Result<i64, EvalError> {
    Ok(match index {
        Index::Int(v) => *v,
        Index::Var(name, pos) => match bound.get(name) {
            Some(v) => *v,
            None if name == "n" => n as i64,
            None => {
                return Err(EvalError {
                    pos: *pos,
                    found: name.clone(),
                    message: "an index bound here: one of the entry's indices, a sum's index, or n".into(),
                });
            }
        },
        Index::Add(a, b) => index_value(a, bound, n)?.saturating_add(index_value(b, bound, n)?),
        Index::Sub(a, b) => index_value(a, bound, n)?.saturating_sub(index_value(b, bound, n)?),
        Index::Max(a, b) => index_value(a, bound, n)?.max(index_value(b, bound, n)?),
        Index::Min(a, b) => index_value(a, bound, n)?.min(index_value(b, bound, n)?),
    })
}

/// Calls `term` on the body of the sum `sum` once for every value of its index where its
/// condition holds, with the index bound to it (and unbound, or as before, after). A
/// range of `MAX_TERMS` or more is an error.
pub fn each_term(
    sum: &Expr,
    bound: &mut Bindings,
    n: usize,
    mut term: impl FnMut(&Expr, &mut Bindings) -> Result<(), EvalError>,
) -> Result<(), EvalError> {
    let Expr::Sum { var, from, to, body, when, pos } = sum else { return term(sum, bound) };
    let (lo, hi) = (index_value(from, bound, n)?, index_value(to, bound, n)?);
    if hi.saturating_sub(lo) >= MAX_TERMS {
        return Err(EvalError {
            pos: *pos,
            found: format!("sum({var} = {from}..{to}) over {lo}..{hi}"),
            message: format!("a sum of fewer than {MAX_TERMS} terms"),
        });
    }
    let saved = bound.get(var).copied();
    let mut outcome = Ok(());
    for k in lo..=hi {
        bound.insert(var.clone(), k);
        outcome = match when.as_ref().map_or(Ok(true), |w| holds(w, bound, n)) {
            Ok(true) => term(body, bound),
            Ok(false) => Ok(()),
            Err(e) => Err(e),
        };
        if outcome.is_err() {
            break;
        }
    }
    match saved {
        Some(v) => bound.insert(var.clone(), v),
        None => bound.remove(var),
    };
    outcome
}

/// Whether every comparison holds.
pub fn holds(all: &[Compare], bound: &Bindings, n: usize) -> Result<bool, EvalError> {
    for c in all {
        let (a, b) = (index_value(&c.left, bound, n)?, index_value(&c.right, bound, n)?);
        let ok = match c.op {
            ">=" => a >= b,
            "<=" => a <= b,
            "==" => a == b,
            "!=" => a != b,
            "<" => a < b,
            _ => a > b,
        };
        if !ok {
            return Ok(false);
        }
    }
    Ok(true)
}

/// The reference and the symbols' values at one state of one case.
pub struct Truth<'a> {
    pub(crate) st: State<'a>,
    /// The accelerations `EL` is taken at.
    qdd: Vec<Scaled>,
    n: usize,
    tail: Vec<Scaled>,
    /// Lazily: `c` at unit rates `e_j` (columns) and at `e_j + e_{n+j}` (spatial pairs).
    unit: OnceCell<Vec<Vec<Scaled>>>,
    pairs: OnceCell<Vec<Vec<Scaled>>>,
    accelerations: OnceCell<Option<Vec<Scaled>>>,
}

impl<'a> Truth<'a> {
    /// The reference at `st`, with `EL` taken at the accelerations `qdd`.
    pub(crate) fn new(st: State<'a>, qdd: Vec<f64>) -> Self {
        let n = st.case.links;
        let tail = tail_masses(&st.params.masses);
        let exact = qdd.iter().map(|&v| Scaled::exact(v)).collect();
        let (unit, pairs, accelerations) = (OnceCell::new(), OnceCell::new(), OnceCell::new());
        Self { st, qdd: exact, n, tail, unit, pairs, accelerations }
    }

    /// The symbol's value at 1-based `index` (ignored for scalars); None out of range.
    fn symbol(&self, symbol: Symbol, index: i64) -> Option<Scaled> {
        let (n, st) = (self.n, &self.st);
        // The 0-based link of a per-link symbol, if in range.
        let link = usize::try_from(index - 1).ok().filter(|&k| k < n);
        let at = |v: &[f64], offset: usize| link.and_then(|k| v.get(offset + k)).map(|&x| Scaled::exact(x));
        match symbol {
            Symbol::Theta => at(&st.point.q, 0),
            Symbol::Phi => at(&st.point.q, n),
            Symbol::ThetaDot => at(&st.point.qd, 0),
            Symbol::PhiDot => at(&st.point.qd, n),
            Symbol::ThetaDdot => link.and_then(|k| self.qdd.get(k)).copied(),
            Symbol::PhiDdot => link.and_then(|k| self.qdd.get(n + k)).copied(),
            Symbol::Mass => at(&st.params.masses, 0),
            // M_{n+1} = 0: the sum over no masses.
            Symbol::TailMass => {
                let k = usize::try_from(index - 1).ok()?;
                if k == n { Some(Scaled::zero()) } else { self.tail.get(k).copied() }
            }
            Symbol::Length => at(&st.params.lengths, 0),
            Symbol::Damping => at(&st.params.damping, 0),
            Symbol::Torque => at(&st.point.torque, 0),
            Symbol::Gravity => Some(Scaled::exact(st.params.gravity)),
            Symbol::Links => Some(Scaled::exact(n as f64)),
            Symbol::Pi => Some(Scaled::exact(std::f64::consts::PI)),
            Symbol::Pivot(k) => st.point.pivot_acceleration.get(k).map(|&v| Scaled::exact(v)),
        }
    }

    /// `expr` with the index variables `bound`.
    pub fn value(&self, expr: &Expr, bound: &mut Bindings) -> Result<Scaled, EvalError> {
        let n = self.n;
        Ok(match expr {
            Expr::Num(v) => Scaled::exact(*v),
            Expr::Sym { name, index, pos } => {
                let symbol = Symbol::named(name).ok_or_else(|| EvalError {
                    pos: *pos,
                    found: name.clone(),
                    message: format!("a known symbol: {SYMBOLS}"),
                })?;
                let k = match (index, symbol.indexed()) {
                    (Some(i), true) => index_value(i, bound, n)?,
                    (None, false) => 0,
                    (None, true) => {
                        return Err(EvalError {
                            pos: *pos,
                            found: name.clone(),
                            message: format!("an index: {name}[i]"),
                        });
                    }
                    (Some(_), false) => {
                        return Err(EvalError {
                            pos: *pos,
                            found: format!("{name}[…]"),
                            message: format!("{name} without an index (it is one number)"),
                        });
                    }
                };
                if matches!(symbol, Symbol::Phi | Symbol::PhiDot | Symbol::PhiDdot)
                    && self.st.case.kind == Kind::Planar
                {
                    return Err(EvalError {
                        pos: *pos,
                        found: name.clone(),
                        message: "a planar symbol (φ and φ̇ exist only for spatial chains)".into(),
                    });
                }
                self.symbol(symbol, k).ok_or_else(|| EvalError {
                    pos: *pos,
                    found: format!(
                        "{name}[{}] = {name}[{k}]",
                        index.as_ref().map_or(String::new(), |i| i.to_string())
                    ),
                    message: format!("an index in 1..{n} (n = {n})"),
                })?
            }
            Expr::Ref { name, indices, pos } => {
                let kind = self.st.case.kind;
                let shape = Quantity::named(name)
                    .map(|q| (q, q.shape(kind, n)))
                    .filter(|(q, shape)| shape.len() == indices.len() && q.only().is_none_or(|k| k == kind));
                let Some((quantity, shape)) = shape else {
                    return Err(EvalError {
                        pos: *pos,
                        found: format!("{name}[…] with {} indices", indices.len()),
                        message: format!(
                            "a matrix of the reference for {kind} chains (M, S or A11…C2) with two indices"
                        ),
                    });
                };
                let mut at = Vec::new();
                for (index, size) in indices.iter().zip(&shape) {
                    let k = index_value(index, bound, n)?;
                    if !(1..=*size as i64).contains(&k) {
                        return Err(EvalError {
                            pos: *pos,
                            found: format!("{name}[…{index}…] = {k}"),
                            message: format!("an index in 1..{size} (n = {n})"),
                        });
                    }
                    at.push(k as usize - 1);
                }
                self.reference(quantity, &at).ok_or_else(|| EvalError {
                    pos: *pos,
                    found: name.clone(),
                    message: "a state where the reference has it (its mass matrix is singular here)".into(),
                })?
            }
            Expr::Neg(e) => -self.value(e, bound)?,
            Expr::Add(a, b) => self.value(a, bound)? + self.value(b, bound)?,
            Expr::Sub(a, b) => self.value(a, bound)? - self.value(b, bound)?,
            Expr::Mul(a, b, _) => self.value(a, bound)? * self.value(b, bound)?,
            Expr::Div(a, b) => self.value(a, bound)? / self.value(b, bound)?,
            Expr::Pow(e, k) => self.value(e, bound)?.powi(*k),
            Expr::Call(f, e) => {
                let x = self.value(e, bound)?;
                match f {
                    Func::Sin => x.sin(),
                    Func::Cos => x.cos(),
                    Func::Tan => x.sin() / x.cos(),
                    Func::Cot => x.cos() / x.sin(),
                    Func::Sqrt => {
                        Scaled::with_scale(x.v.sqrt(), 0.5 * x.s / x.v.abs().sqrt().max(f64::MIN_POSITIVE))
                    }
                }
            }
            Expr::Sum { .. } => {
                let mut total = Scaled::zero();
                each_term(expr, bound, n, |body, bound| {
                    total = total + self.value(body, bound)?;
                    Ok(())
                })?;
                total
            }
        })
    }

    /// The velocity terms at unit rates: column `j` of `c(e_j)` (every rate, θ then φ).
    fn unit(&self) -> &Vec<Vec<Scaled>> {
        let dof = self.st.case.dof();
        self.unit.get_or_init(|| (0..dof).map(|j| self.st.velocity_terms_unit(j, None)).collect())
    }

    fn pairs(&self) -> &Vec<Vec<Scaled>> {
        let n = self.n;
        self.pairs.get_or_init(|| (0..n).map(|j| self.st.velocity_terms_unit(j, Some(n + j))).collect())
    }

    /// The free accelerations `M⁻¹(−c − k)` (no torques, damping or pivot motion), with
    /// their round-off scales; None if M is singular.
    fn accelerations(&self) -> Option<&Vec<Scaled>> {
        self.accelerations.get_or_init(|| self.st.free_accelerations()).as_ref()
    }

    /// The reference's entry (0-based indices within the quantity's shape).
    pub fn reference(&self, q: Quantity, at: &[usize]) -> Option<Scaled> {
        let n = self.n;
        let st = &self.st;
        Some(match q {
            Quantity::MassMatrix => st.mass(at[0], at[1]),
            Quantity::Velocity => st.velocity(at[0]),
            Quantity::Gravity => st.gravity(at[0]),
            Quantity::Pivot => Scaled::with_scale(st.ev.pivot_terms[at[0]], st.sc.pivot_terms[at[0]]),
            Quantity::Forces => st.force(at[0]),
            Quantity::Kinetic => st.kinetic(),
            Quantity::Potential => st.potential(),
            Quantity::Accelerations => self.accelerations()?[at[0]],
            Quantity::EulerLagrange => st.lagrange_lhs(&self.qdd, at[0]),
            Quantity::FreeRhs => -(st.velocity(at[0]) + st.gravity(at[0])),
            Quantity::S => -self.unit()[at[1]][at[0]],
            Quantity::A(r, c) => st.mass(r * n + at[0], c * n + at[1]),
            Quantity::B(r, c) => -self.unit()[c * n + at[1]][r * n + at[0]],
            Quantity::C(r) => {
                let row = r * n + at[0];
                let pair = self.pairs()[at[1]][row];
                let unit = self.unit();
                pair - unit[at[1]][row] - unit[n + at[1]][row]
            }
        })
    }
}

/// The entry's value at the entry indices `bound` (its first branch whose condition
/// holds); None when no branch applies.
pub fn entry_value(truth: &Truth, entry: &Entry, bound: &mut Bindings) -> Result<Option<Scaled>, EvalError> {
    let n = truth.n;
    for branch in &entry.branches {
        let applies = match &branch.when {
            Some(all) => holds(all, bound, n)?,
            None => true,
        };
        if applies {
            return truth.value(&branch.value, bound).map(Some);
        }
    }
    Ok(None)
}
