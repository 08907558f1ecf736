//! Method bodies: the `let` statements for the symbols a method needs (one per symbol, in
//! the plan's order) and the expressions of its outputs.

use std::collections::BTreeSet;

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use super::names::{ident, index};
use crate::plan::{Angle, Expr, Plan, Sym, Trig};

/// `name` if the generated body uses it, `_name` otherwise (no unused-variable warnings).
fn param(name: &str, used: bool) -> Ident {
    if used { format_ident!("{name}") } else { format_ident!("_{name}") }
}

/// `a · b · c` with the term's constant in front when it is not ±1; the sign is the caller's.
fn product(coef: f64, factors: &[Sym]) -> TokenStream {
    let mut parts = factors.iter().map(|&s| {
        let s = ident(s);
        quote!(#s)
    });
    let magnitude = coef.abs();
    let first = if magnitude == 1.0 {
        parts.next().unwrap_or_else(|| quote!(1.0))
    } else {
        let lit = Literal::f64_unsuffixed(magnitude);
        quote!(#lit)
    };
    parts.fold(first, |acc, p| quote!(#acc * #p))
}

/// The sum of signed products `e`, `0.0` when it has no terms.
pub(super) fn expr(e: &Expr) -> TokenStream {
    let mut terms = e.terms.iter();
    let Some(first) = terms.next() else { return quote!(0.0) };
    let p = product(first.coef, &first.factors);
    let start = if first.coef < 0.0 { quote!(-#p) } else { p };
    terms.fold(start, |acc, t| {
        let p = product(t.coef, &t.factors);
        if t.coef < 0.0 { quote!(#acc - #p) } else { quote!(#acc + #p) }
    })
}

/// `check_polar_sin(link, q[i], st_i)?;` for every link whose polar angle can be singular,
/// and the sines `st_i` they need from the lets: the one place the checks are written, for
/// `check_configuration` and `accelerations` alike. With a non-empty `first` (a function
/// of `q`, `qd`, `inputs` and the error), a failed check returns `first`'s error
/// (`accelerations`: the input checks', which come first).
fn polar_checks(plan: &Plan, first: &TokenStream) -> (Vec<Sym>, TokenStream) {
    let mut sines = Vec::new();
    let mut checks = TokenStream::new();
    for (link, i) in plan.singular_links() {
        let sin = Sym::Trig(plan.angle(i), Trig::Sin);
        sines.push(sin);
        let (link, i, sin) = (index(link), index(i), ident(sin));
        let check = quote!(::pendulum_core::check_polar_sin(#link, q[#i], #sin));
        checks.extend(if first.is_empty() {
            quote!(#check?;)
        } else {
            quote! {
                if let Err(error) = #check {
                    return Err(#first(q, qd, inputs, error));
                }
            }
        });
    }
    (sines, checks)
}

/// The `let` statements that compute `syms` (a sorted closure) from the chain and the
/// arguments `q`, `qd`, `torque`, `pivot_acceleration`; `checks` go right after the lets
/// of the polar angles' sines and cosines.
fn lets(plan: &Plan, syms: &[Sym], checks: TokenStream) -> TokenStream {
    lets_from(plan, syms, checks, &quote!(self.chain), true)
}

/// [`lets`] reading the parameters from the chain `chain`; [stored](Sym::is_stored)
/// symbols are read from `self` when `read_stored`, else computed (the constructor).
pub(super) fn lets_from(
    plan: &Plan,
    syms: &[Sym],
    checks: TokenStream,
    chain: &TokenStream,
    read_stored: bool,
) -> TokenStream {
    let has = |f: fn(&Sym) -> bool| syms.iter().any(f);
    let mut out = TokenStream::new();
    // Each chain vector is borrowed once, each entry read once.
    if has(|s| matches!(s, Sym::Mass(_))) {
        out.extend(quote!(let masses = #chain.masses();));
    }
    if has(|s| matches!(s, Sym::Tail(_))) {
        out.extend(quote!(let tail_masses = #chain.tail_masses();));
    }
    if has(|s| matches!(s, Sym::Length(_))) {
        out.extend(quote!(let lengths = #chain.lengths();));
    }
    if has(|s| matches!(s, Sym::Damping(_))) {
        out.extend(quote!(let damping = #chain.damping();));
    }
    let set: BTreeSet<Sym> = syms.iter().copied().collect();
    let last_polar = syms.iter().rposition(|s| matches!(s, Sym::Trig(Angle::Theta(_), _)));
    assert!(checks.is_empty() || last_polar.is_some(), "the checks need the sines of the polar angles");
    let mut checks = Some(checks);
    for (k, &sym) in syms.iter().enumerate() {
        let name = ident(sym);
        let stmt = match sym {
            Sym::Gravity => quote!(let #name = #chain.gravity();),
            _ if sym.is_stored() && read_stored => quote!(let #name = self.#name;),
            Sym::Mass(i) => vector_entry(&name, "masses", i),
            Sym::Tail(i) => vector_entry(&name, "tail_masses", i),
            Sym::Length(i) => vector_entry(&name, "lengths", i),
            Sym::Damping(i) => vector_entry(&name, "damping", i),
            Sym::Trig(angle, trig) => trig_let(plan, &set, angle, trig),
            Sym::Rate(angle) => vector_entry(&name, "qd", plan.index(angle)),
            Sym::Torque(angle) => vector_entry(&name, "torque", plan.index(angle)),
            Sym::Pivot(axis) => vector_entry(&name, "pivot_acceleration", axis),
            Sym::Probe(b) => vector_entry(&name, "v", b),
            _ => {
                let value = expr(&plan.definition(sym).expect("computed symbols have a definition"));
                quote!(let #name = #value;)
            }
        };
        out.extend(stmt);
        if Some(k) == last_polar {
            out.extend(checks.take());
        }
    }
    out
}

/// `let name = vector[i];`.
fn vector_entry(name: &Ident, vector: &str, i: usize) -> TokenStream {
    let vector = format_ident!("{vector}");
    let i = index(i);
    quote!(let #name = #vector[#i];)
}

/// `let (s, c) = q[i].sin_cos();` when both are needed (emitted with the sine), else the
/// one that is.
fn trig_let(plan: &Plan, set: &BTreeSet<Sym>, angle: Angle, trig: Trig) -> TokenStream {
    let i = index(plan.index(angle));
    let (sin, cos) = (Sym::Trig(angle, Trig::Sin), Sym::Trig(angle, Trig::Cos));
    let both = set.contains(&sin) && set.contains(&cos);
    let (s, c) = (ident(sin), ident(cos));
    match (trig, both) {
        (Trig::Sin, true) => quote!(let (#s, #c) = q[#i].sin_cos();),
        (Trig::Cos, true) => TokenStream::new(),
        (Trig::Sin, false) => quote!(let #s = q[#i].sin();),
        (Trig::Cos, false) => quote!(let #c = q[#i].cos();),
    }
}

/// A method body's computations: the lets for every symbol the outputs need.
pub(super) struct Body {
    pub(super) lets: TokenStream,
    uses: BTreeSet<Sym>,
}

impl Body {
    /// The lets for every symbol of `exprs`.
    pub(super) fn new<'a>(plan: &Plan, exprs: impl IntoIterator<Item = &'a Expr>) -> Self {
        Self::build(plan, exprs, None)
    }

    /// [`Body::new`] that also runs the [`polar_checks`] as soon as their sines are known,
    /// `first` before a failed one returns.
    pub(super) fn checked<'a>(
        plan: &Plan,
        exprs: impl IntoIterator<Item = &'a Expr>,
        first: &TokenStream,
    ) -> Self {
        Self::build(plan, exprs, Some(first))
    }

    fn build<'a>(
        plan: &Plan,
        exprs: impl IntoIterator<Item = &'a Expr>,
        checked: Option<&TokenStream>,
    ) -> Self {
        let mut roots: Vec<Sym> = exprs.into_iter().flat_map(Expr::symbols).collect();
        let mut checks = TokenStream::new();
        if let Some(first) = checked {
            let sines;
            (sines, checks) = polar_checks(plan, first);
            roots.extend(sines);
        }
        let syms = plan.closure(roots);
        Body { lets: lets(plan, &syms, checks), uses: syms.into_iter().collect() }
    }

    /// Whether the lets use a symbol for which `f` holds.
    pub(super) fn uses(&self, f: fn(&Sym) -> bool) -> bool {
        self.uses.iter().any(f)
    }

    /// The name of the `q` parameter: `_q` when the body does not read it.
    pub(super) fn q(&self) -> Ident {
        param("q", self.uses(|s| matches!(s, Sym::Trig(..))))
    }

    /// The name of a vector parameter: `_name` when the body reads no symbol `f` holds for.
    pub(super) fn param(&self, name: &str, f: fn(&Sym) -> bool) -> Ident {
        param(name, self.uses(f))
    }

    /// The name of the `qd` parameter: `_qd` when the body does not read it.
    pub(super) fn qd(&self) -> Ident {
        param("qd", self.uses(|s| matches!(s, Sym::Rate(_))))
    }
}

/// `out[a] = …;` for each coordinate: the symbol's definition inline, `0.0` where it is
/// identically zero.
pub(super) fn vector_outputs(plan: &Plan, sym: fn(usize) -> Sym) -> (Body, TokenStream) {
    let exprs: Vec<Expr> = plan
        .per_coordinate(sym)
        .into_iter()
        .map(|s| s.and_then(|s| plan.definition(s)).unwrap_or_default())
        .collect();
    let body = Body::new(plan, &exprs);
    let assigns = exprs.iter().enumerate().map(|(a, e)| {
        let (a, value) = (index(a), expr(e));
        quote!(out[#a] = #value;)
    });
    (body, quote!(#(#assigns)*))
}
