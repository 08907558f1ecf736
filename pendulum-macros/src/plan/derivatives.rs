//! The plan differentiates its own terms: `∂M/∂q` and the Jacobians of the right-hand
//! side `F = Q − c − (k + d)` as sums of signed products of the symbols the model already
//! computes, by the product rule on the expanded definitions.
//!
//! The leaves of an expansion are the inputs, the stored symbols and the sines and cosines
//! (of single angles and of differences), whose derivatives are leaves again:
//! `∂ sin a/∂a = cos a`, `∂ cos a/∂a = −sin a`, `∂ cos(a − b)/∂a = −sin(a − b)`,
//! `∂ sin(a − b)/∂a = cos(a − b)` (the opposite signs by `b`).

use super::{Expr, Plan, Sym, Term, Trig};

/// A variable to differentiate by.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Var {
    /// Generalized coordinate `q_x`.
    Coord(usize),
    /// Rate `q̇_x`.
    Rate(usize),
    /// Pivot-acceleration component `p̈_k`.
    Pivot(usize),
}

impl Var {
    /// `q`, `v` or `p` and the index, for symbol names.
    pub(super) fn tag(self) -> String {
        match self {
            Var::Coord(x) => format!("q{x}"),
            Var::Rate(x) => format!("v{x}"),
            Var::Pivot(k) => format!("p{k}"),
        }
    }
}

impl Plan {
    /// `sym`'s definition with every computed symbol that is not a leaf (module docs)
    /// replaced by its own expansion.
    pub(super) fn expanded(&self, sym: Sym) -> Expr {
        let Some(def) = self.definition(sym) else { return Expr::of(sym) };
        let mut out = Expr::default();
        for term in &def.terms {
            // The product of the factors' expansions, one factor at a time.
            let mut product = vec![Term { coef: term.coef, factors: Vec::new() }];
            for &factor in &term.factors {
                let e = if is_leaf(factor) { Expr::of(factor) } else { self.expanded(factor) };
                product = product
                    .iter()
                    .flat_map(|p| {
                        e.terms.iter().map(move |t| Term {
                            coef: p.coef * t.coef,
                            factors: [p.factors.as_slice(), &t.factors].concat(),
                        })
                    })
                    .collect();
            }
            out.terms.extend(product);
        }
        out
    }

    /// `∂e/∂var` by the product rule, like terms merged (each term's factors sorted).
    pub(super) fn derivative(&self, e: &Expr, var: Var) -> Expr {
        let mut out: Vec<Term> = Vec::new();
        for term in &e.terms {
            for (k, &factor) in term.factors.iter().enumerate() {
                for (sign, replacement) in self.leaf_derivative(factor, var) {
                    let mut factors: Vec<Sym> = term.factors.clone();
                    match replacement {
                        Some(r) => factors[k] = r,
                        None => {
                            factors.remove(k);
                        }
                    }
                    factors.sort();
                    let coef = term.coef * sign;
                    match out.iter_mut().find(|t| t.factors == factors) {
                        Some(t) => t.coef += coef,
                        None => out.push(Term { coef, factors }),
                    }
                }
            }
        }
        out.retain(|t| t.coef != 0.0);
        Expr { terms: out }
    }

    /// `∂leaf/∂var` as signed replacements of the factor (`None`: the factor becomes 1);
    /// empty where zero.
    fn leaf_derivative(&self, leaf: Sym, var: Var) -> Vec<(f64, Option<Sym>)> {
        let on = |angle| Var::Coord(self.index(angle)) == var;
        match leaf {
            Sym::Trig(a, Trig::Sin) if on(a) => vec![(1.0, Some(Sym::Trig(a, Trig::Cos)))],
            Sym::Trig(a, Trig::Cos) if on(a) => vec![(-1.0, Some(Sym::Trig(a, Trig::Sin)))],
            Sym::CosDiff(a, b) => {
                let s = Some(Sym::SinDiff(a, b));
                [(on(a), -1.0), (on(b), 1.0)]
                    .into_iter()
                    .filter(|(hit, _)| *hit)
                    .map(|(_, c)| (c, s))
                    .collect()
            }
            Sym::SinDiff(a, b) => {
                let c = Some(Sym::CosDiff(a, b));
                [(on(a), 1.0), (on(b), -1.0)]
                    .into_iter()
                    .filter(|(hit, _)| *hit)
                    .map(|(_, k)| (k, c))
                    .collect()
            }
            Sym::Rate(a) if var == Var::Rate(self.index(a)) => vec![(1.0, None)],
            Sym::Pivot(k) if var == Var::Pivot(k) => vec![(1.0, None)],
            _ => Vec::new(),
        }
    }

    /// `∂M_rc/∂q_x` (`r ≥ c`), as [`Sym::MassPartial`] defines it.
    pub(super) fn mass_partial_expr(&self, r: usize, c: usize, x: usize) -> Expr {
        self.derivative(&self.expanded(Sym::MassEntry(r, c)), Var::Coord(x))
    }

    /// `∂F_a/∂var`, as [`Sym::RhsPartial`] defines it.
    pub(super) fn rhs_partial_expr(&self, a: usize, var: Var) -> Expr {
        self.derivative(&self.expanded(Sym::Rhs(a)), var)
    }

    /// The symbol of `∂M_rc/∂q_x` (either triangle), `None` where identically zero.
    pub fn mass_partial(&self, r: usize, c: usize, x: usize) -> Option<Sym> {
        let sym = Sym::MassPartial(r.max(c), r.min(c), x);
        (!self.is_zero(sym)).then_some(sym)
    }

    /// Every variable `F` is differentiated by: `q`, `q̇`, then `p̈`.
    pub fn variables(&self) -> impl Iterator<Item = Var> + '_ {
        let dof = self.dof();
        (0..dof).map(Var::Coord).chain((0..dof).map(Var::Rate)).chain((0..self.space()).map(Var::Pivot))
    }
}

/// Whether an expansion stops at `sym`: inputs, stored symbols, sines and cosines.
fn is_leaf(sym: Sym) -> bool {
    sym.is_input() || sym.is_stored() || matches!(sym, Sym::CosDiff(..) | Sym::SinDiff(..))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::Kind;

    #[test]
    fn planar_mass_partials_are_the_sines_of_the_differences() {
        let plan = Plan::new(Kind::Planar, 3);
        // M_20 = W_02 cos(θ_0 − θ_2): ∂/∂θ_2 = W_02 sin(θ_0 − θ_2), ∂/∂θ_0 the opposite.
        let by2 = plan.mass_partial_expr(2, 0, 2);
        assert_eq!(by2.to_string(), "sth0_2*w0_2");
        assert_eq!(plan.mass_partial_expr(2, 0, 0).to_string(), "-sth0_2*w0_2");
        assert!(plan.mass_partial_expr(2, 0, 1).is_zero());
        assert!(plan.mass_partial(1, 1, 0).is_none());
    }

    #[test]
    fn squares_merge_and_rates_drop() {
        let plan = Plan::new(Kind::Planar, 2);
        // F_0 = σ_0 − λ_0 θ̇_0 − W_01 sin(θ_0 − θ_1) θ̇_1² − M_0 l_0 (p̈_x cθ_0 + (p̈_y + g) sθ_0).
        let by_rate = plan.rhs_partial_expr(0, Var::Rate(1));
        assert_eq!(by_rate.to_string(), "-2*dth1*sth0_1*w0_1");
        assert_eq!(plan.rhs_partial_expr(0, Var::Rate(0)).to_string(), "-lam0");
        let by_pivot = plan.rhs_partial_expr(1, Var::Pivot(0));
        assert_eq!(by_pivot.to_string(), "-ct1*ml1");
    }
}
