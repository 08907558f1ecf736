//! Tokens from a [`Plan`]: the struct, its constructor and its `pendulum_core::Model` impl,
//! as straight-line code (one `let` per symbol, in the plan's order).

use std::collections::BTreeSet;

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};

use crate::parse::{Input, ModelDef};
use crate::plan::{Angle, Expr, Kind, Plan, Sym, Trig};

/// Everything `model!` emits for its input.
pub fn expand(input: &Input) -> TokenStream {
    input.models.iter().map(model).collect()
}

fn ident(sym: Sym) -> Ident {
    Ident::new(&sym.name(), Span::call_site())
}

fn index(i: usize) -> Literal {
    Literal::usize_unsuffixed(i)
}

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

fn expr(e: &Expr) -> TokenStream {
    let mut terms = e.terms.iter();
    let Some(first) = terms.next() else { return quote!(0.0) };
    let p = product(first.coef, &first.factors);
    let start = if first.coef < 0.0 { quote!(-#p) } else { p };
    terms.fold(start, |acc, t| {
        let p = product(t.coef, &t.factors);
        if t.coef < 0.0 { quote!(#acc - #p) } else { quote!(#acc + #p) }
    })
}

/// The pivot-acceleration type: `U2` planar, `U3` spatial.
fn space(plan: &Plan) -> Ident {
    format_ident!("U{}", plan.space())
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
fn lets_from(
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
struct Body {
    lets: TokenStream,
    uses: BTreeSet<Sym>,
}

impl Body {
    fn new<'a>(plan: &Plan, exprs: impl IntoIterator<Item = &'a Expr>) -> Self {
        Self::build(plan, exprs, None)
    }

    /// [`Body::new`] that also runs the [`polar_checks`] as soon as their sines are known,
    /// `first` before a failed one returns.
    fn checked<'a>(plan: &Plan, exprs: impl IntoIterator<Item = &'a Expr>, first: &TokenStream) -> Self {
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

    fn uses(&self, f: fn(&Sym) -> bool) -> bool {
        self.uses.iter().any(f)
    }

    fn q(&self) -> Ident {
        param("q", self.uses(|s| matches!(s, Sym::Trig(..))))
    }

    fn qd(&self) -> Ident {
        param("qd", self.uses(|s| matches!(s, Sym::Rate(_))))
    }
}

/// `out[a] = …;` for each coordinate: the symbol's definition inline, `0.0` where it is
/// identically zero.
fn vector_outputs(plan: &Plan, sym: fn(usize) -> Sym) -> (Body, TokenStream) {
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

fn model(def: &ModelDef) -> TokenStream {
    let plan = Plan::new(def.kind, def.links);
    let ModelDef { attrs, vis, ident: name, .. } = def;
    let n = index(plan.links);
    let dof = index(plan.dof());
    let space = space(&plan);
    let space_dim = index(plan.space());
    let vector = quote!(SVector<f64, #dof>);
    let matrix = quote!(SMatrix<f64, #dof, #dof>);

    // A `#[cfg]` on the struct must also remove its impls.
    let cfgs = attrs.iter().filter(|a| a.path().is_ident("cfg"));
    let mut doc = Vec::new();
    if attrs.iter().any(|a| a.path().is_ident("doc")) {
        doc.push(String::new());
    }
    doc.push(match plan.kind {
        Kind::Planar => format!(
            " A planar chain of {n} links in straight-line code, generated by `pendulum_macros::model!`: \
             coordinates `q = (θ_1 … θ_{n})` from the downward vertical, rad."
        ),
        Kind::Spatial => format!(
            " A spatial chain of {n} links in straight-line code, generated by `pendulum_macros::model!`: \
             coordinates `q = (θ_1 … θ_{n}, φ_1 … φ_{n})`, θ from −z and φ the azimuth from +x, rad."
        ),
    });

    // mass_matrix
    let entries: Vec<Expr> = plan.mass_entries().into_iter().map(Expr::of).collect();
    let mass = Body::new(&plan, &entries);
    let mass_q = mass.q();
    let mass_lets = &mass.lets;
    let mass_assigns = (0..plan.dof()).flat_map(|r| (0..plan.dof()).map(move |c| (r, c))).map(|(r, c)| {
        let value = plan.mass_entry(r, c).map_or_else(|| quote!(0.0), |s| expr(&Expr::of(s)));
        let (r, c) = (index(r), index(c));
        quote!(out[(#r, #c)] = #value;)
    });

    let (velocity, velocity_assigns) = vector_outputs(&plan, Sym::VelocityTerm);
    let (velocity_q, velocity_qd, velocity_lets) = (velocity.q(), velocity.qd(), &velocity.lets);
    let (gravity, gravity_assigns) = vector_outputs(&plan, Sym::GravityTerm);
    let (gravity_q, gravity_lets) = (gravity.q(), &gravity.lets);
    let (pivot, pivot_assigns) = vector_outputs(&plan, Sym::PivotTerm);
    let (pivot_q, pivot_lets) = (pivot.q(), &pivot.lets);
    let (forces, forces_assigns) = vector_outputs(&plan, Sym::Force);
    let (forces_q, forces_qd, forces_lets) = (forces.q(), forces.qd(), &forces.lets);

    let kinetic_expr = plan.kinetic_energy();
    let kinetic = Body::new(&plan, [&kinetic_expr]);
    let (kinetic_q, kinetic_qd, kinetic_lets) = (kinetic.q(), kinetic.qd(), &kinetic.lets);
    let kinetic_value = expr(&kinetic_expr);
    let potential_expr = plan.potential_energy();
    let potential = Body::new(&plan, [&potential_expr]);
    let (potential_q, potential_lets) = (potential.q(), &potential.lets);
    let potential_value = expr(&potential_expr);
    // H = T + U from one set of lets, each sum as in its own method (the same rounding).
    let energy = Body::new(&plan, [&kinetic_expr, &potential_expr]);
    let (energy_q, energy_qd, energy_lets) = (energy.q(), energy.qd(), &energy.lets);

    let check_configuration = (!plan.singular_links().is_empty()).then(|| {
        let checks = &Body::checked(&plan, [], &TokenStream::new()).lets;
        quote! {
            fn check_configuration(&self, q: &#vector) -> Result<()> {
                #checks
                Ok(())
            }
        }
    });
    let accelerations = accelerations(&plan);

    // What depends on the chain alone (the weights `W_ij`, the moments `M_i l_i`): computed
    // once by `new`, stored as fields named like the symbols.
    let method_roots = plan.mass_entries().into_iter().chain((0..plan.dof()).flat_map(|a| {
        [Sym::VelocityTerm(a), Sym::GravityTerm(a), Sym::PivotTerm(a), Sym::Force(a), Sym::Rhs(a)]
    }));
    let stored: Vec<Sym> = plan.closure(method_roots).into_iter().filter(|s| s.is_stored()).collect();
    let stored_idents: Vec<Ident> = stored.iter().map(|&s| ident(s)).collect();
    let stored_docs = stored.iter().map(|&s| {
        let what = match s {
            Sym::Weight(i, j) => format!(" `W_{i}{j} = M_{j} l_{i} l_{j}` (0-based), kg·m²."),
            Sym::Moment(i) => format!(" `M_{i} l_{i}` (0-based), kg·m."),
            _ => unreachable!("{s:?} is not stored"),
        };
        quote!(#[doc = #what])
    });
    let constructor_lets =
        lets_from(&plan, &plan.full_closure(stored.clone()), TokenStream::new(), &quote!(chain), false);
    // The first pivot of `accelerations`' factorisation is `M_00 = W_00`: its reciprocal too.
    let w00 = ident(Sym::Weight(0, 0));
    assert!(stored.contains(&Sym::Weight(0, 0)), "W_00 is stored");

    quote! {
        #(#attrs)*
        #(#[doc = #doc])*
        #[derive(::core::clone::Clone)]
        #vis struct #name {
            chain: ::pendulum_core::Chain<::pendulum_core::__private::nalgebra::Const<#n>>,
            #(#stored_docs #stored_idents: ::core::primitive::f64,)*
            /// `1/W_00`, kg⁻¹·m⁻², the first pivot's reciprocal; NaN when `W_00` is not
            /// positive (underflow), which makes every acceleration NaN and
            /// `accelerations` fail as not positive definite.
            inv0: ::core::primitive::f64,
        }

        #(#cfgs)*
        const _: () = {
            use ::core::primitive::f64;
            use ::core::result::Result::{Err, Ok};
            use ::pendulum_core::__private::nalgebra::{Const, SMatrix, SVector, #space};
            use ::pendulum_core::{Chain, Error, Inputs, Model, Result};

            impl #name {
                /// The model of `chain`.
                #vis fn new(chain: Chain<Const<#n>>) -> Self {
                    #constructor_lets
                    let inv0 = if #w00 > 0.0 { 1.0 / #w00 } else { ::core::primitive::f64::NAN };
                    Self { chain, #(#stored_idents,)* inv0 }
                }
            }

            // The stored quantities are functions of the chain: it alone is shown and compared.
            #[automatically_derived]
            impl ::core::fmt::Debug for #name {
                fn fmt(&self, f: &mut ::core::fmt::Formatter<'_>) -> ::core::fmt::Result {
                    f.debug_struct(::core::stringify!(#name)).field("chain", &self.chain).finish_non_exhaustive()
                }
            }

            #[automatically_derived]
            impl ::core::cmp::PartialEq for #name {
                fn eq(&self, other: &Self) -> bool {
                    self.chain == other.chain
                }
            }

            #[automatically_derived]
            impl ::core::convert::From<Chain<Const<#n>>> for #name {
                fn from(chain: Chain<Const<#n>>) -> Self {
                    Self::new(chain)
                }
            }

            // `mul_add` would be a slow libm call on targets without FMA, and would round
            // differently from the generic models. `x - x` is the finiteness probe
            // (NaN for ±∞ and NaN, 0 otherwise).
            #[automatically_derived]
            #[allow(clippy::suboptimal_flops, clippy::eq_op)]
            impl Model for #name {
                type Links = Const<#n>;
                type Dof = Const<#dof>;
                type Space = #space;

                fn chain(&self) -> &Chain<Const<#n>> {
                    &self.chain
                }

                fn dof(&self) -> Const<#dof> {
                    Const::<#dof>
                }

                fn mass_matrix(&self, #mass_q: &#vector, out: &mut #matrix) {
                    #mass_lets
                    #(#mass_assigns)*
                }

                fn velocity_terms(&self, #velocity_q: &#vector, #velocity_qd: &#vector, out: &mut #vector) {
                    #velocity_lets
                    #velocity_assigns
                }

                fn gravity_terms(&self, #gravity_q: &#vector, out: &mut #vector) {
                    #gravity_lets
                    #gravity_assigns
                }

                fn pivot_terms(&self, #pivot_q: &#vector, pivot_acceleration: &SVector<f64, #space_dim>, out: &mut #vector) {
                    #pivot_lets
                    #pivot_assigns
                }

                fn generalized_forces(
                    &self,
                    #forces_q: &#vector,
                    #forces_qd: &#vector,
                    torque: &#vector,
                    out: &mut #vector,
                ) {
                    #forces_lets
                    #forces_assigns
                }

                fn kinetic_energy(&self, #kinetic_q: &#vector, #kinetic_qd: &#vector) -> f64 {
                    #kinetic_lets
                    #kinetic_value
                }

                fn potential_energy(&self, #potential_q: &#vector) -> f64 {
                    #potential_lets
                    #potential_value
                }

                fn energy(&self, #energy_q: &#vector, #energy_qd: &#vector) -> f64 {
                    #energy_lets
                    let kinetic = #kinetic_value;
                    let potential = #potential_value;
                    kinetic + potential
                }

                #check_configuration

                #accelerations
            }
        };
    }
}

/// `a - p·q - …` (or `-p·q - …` when `a` is zero); `None` when everything is zero.
fn minus_products(first: Option<TokenStream>, products: &[(Ident, Ident)]) -> Option<TokenStream> {
    let mut products = products.iter().map(|(p, q)| quote!(#p * #q));
    let start = match first {
        Some(a) => a,
        None => {
            let p = products.next()?;
            quote!(-#p)
        }
    };
    Some(products.fold(start, |acc, p| quote!(#acc - #p)))
}

/// `Σ (x − x)` over `values` as a balanced tree of additions (latency `log₂` of their
/// number): `0.0` exactly when every value is finite, NaN otherwise (`x − x` is NaN for
/// ±∞ and NaN). One subtraction and one addition per value, no branch per value.
fn finite_probe(values: &[TokenStream]) -> TokenStream {
    match values {
        [] => quote!(0.0),
        [x] => quote!((#x - #x)),
        _ => {
            let (a, b) = values.split_at(values.len() / 2);
            let (a, b) = (finite_probe(a), finite_probe(b));
            quote!((#a + #b))
        }
    }
}

/// `accelerations`: `M` and `Q − c − (k + d)` as lets with the polar-angle checks among
/// them, an unrolled `M = L D Lᵀ` factorisation (`L` unit lower triangular, column by
/// column; no square roots, one division per pivot; entries known to be zero are
/// skipped), forward and back substitution, and one finiteness probe of the result.
///
/// The inputs are checked (`pendulum_core::check_inputs`, sizes being fixed by the types)
/// only on the way to an error, which is where any non-finite input ends: every entry of
/// `q`, `q̇`, `σ` and `p̈` is an operand of the right-hand side `r_a` of its own
/// coordinate or link (`q` through `J_a·(p̈ + g ẑ)`, `q̇` through the damping, `σ`
/// directly), IEEE arithmetic keeps ±∞ and NaN non-finite through `+ − ×` and through
/// division by a finite pivot, and the pivots `d_j` depend on `q` alone (NaN, caught by
/// their check, or finite and positive). So a non-finite `r_a` makes `x_a` non-finite or
/// a pivot fail. `tests/agrees_with_generic.rs` checks every entry with NaN and ±∞.
fn accelerations(plan: &Plan) -> TokenStream {
    let d = plan.dof();
    let dof = index(d);
    let space = space(plan);
    // `M_00 = W_00` enters through its stored reciprocal alone.
    assert_eq!(plan.definition(Sym::MassEntry(0, 0)), Some(Expr::of(Sym::Weight(0, 0))));
    let mut roots: Vec<Expr> =
        plan.mass_entries().into_iter().filter(|&s| s != Sym::MassEntry(0, 0)).map(Expr::of).collect();
    roots.extend((0..d).map(|a| Expr::of(Sym::Rhs(a))));
    // The input checks, which name a bad value, run on the way to any error: a non-finite
    // input always ends there (see below), and its error comes before the others.
    let body = Body::checked(plan, &roots, &quote!(failure));
    let lets = &body.lets;
    let torque = body.uses(|s| matches!(s, Sym::Torque(_))).then(|| quote!(let torque = &inputs.torque;));
    let pivot = body
        .uses(|s| matches!(s, Sym::Pivot(_)))
        .then(|| quote!(let pivot_acceleration = &inputs.pivot_acceleration;));

    let entry = |r: usize, c: usize| plan.mass_entry(r, c).map(ident);
    let inv = |j: usize| format_ident!("inv{j}");
    let piv = |j: usize| format_ident!("piv{j}");
    // low[i][j] = (L_ij d_j, L_ij) for i > j, `None` where known to be zero.
    let mut low: Vec<Vec<Option<(Ident, Ident)>>> = vec![vec![None; d]; d];
    let mut factor = TokenStream::new();
    for j in 0..d {
        let (piv_j, inv_j) = (piv(j), inv(j));
        if j == 0 {
            // d_0 = M_00 = W_00: its reciprocal is stored, NaN if W_00 is not positive.
            factor.extend(quote!(let #inv_j = self.inv0;));
        } else {
            // d_j = M_jj − Σ_{k<j} (L_jk d_k) L_jk
            let products: Vec<(Ident, Ident)> = low[j][..j].iter().flatten().cloned().collect();
            let diagonal = entry(j, j).expect("the diagonal of M is never identically zero");
            let value = minus_products(Some(quote!(#diagonal)), &products).expect("non-empty");
            factor.extend(quote! {
                let #piv_j = #value;
                if #piv_j.is_nan() || #piv_j <= 0.0 {
                    return Err(failure(q, qd, inputs, Error::NotPositiveDefinite));
                }
            });
            // The last pivot divides once, in the back substitution.
            if j + 1 < d {
                factor.extend(quote!(let #inv_j = 1.0 / #piv_j;));
            }
        }
        for i in j + 1..d {
            // L_ij d_j = M_ij − Σ_{k<j} (L_ik d_k) L_jk
            let products: Vec<(Ident, Ident)> =
                (0..j).filter_map(|k| Some((low[i][k].clone()?.0, low[j][k].clone()?.1))).collect();
            let a = entry(i, j);
            let Some(sum) = minus_products(a.as_ref().map(|a| quote!(#a)), &products) else { continue };
            let unscaled = match (&a, products.is_empty()) {
                (Some(a), true) => a.clone(),
                _ => {
                    let u = format_ident!("u{i}_{j}");
                    factor.extend(quote!(let #u = #sum;));
                    u
                }
            };
            let fac = format_ident!("fac{i}_{j}");
            factor.extend(quote!(let #fac = #unscaled * #inv_j;));
            low[i][j] = Some((unscaled, fac));
        }
    }
    let fac = |i: usize, k: usize| low[i][k].as_ref().map(|(_, l)| l.clone());
    let mut solve = TokenStream::new();
    // L y = r
    let mut ys: Vec<Ident> = Vec::new();
    for i in 0..d {
        let products: Vec<(Ident, Ident)> =
            (0..i).filter_map(|k| Some((fac(i, k)?, ys[k].clone()))).collect();
        let r = ident(Sym::Rhs(i));
        if products.is_empty() {
            ys.push(r);
        } else {
            let sum = minus_products(Some(quote!(#r)), &products).expect("non-empty");
            let yi = format_ident!("y{i}");
            solve.extend(quote!(let #yi = #sum;));
            ys.push(yi);
        }
    }
    // D Lᵀ x = y: x_i = y_i / d_i − Σ_{k>i} L_ki x_k
    let x = |i: usize| format_ident!("x{i}");
    for i in (0..d).rev() {
        let products: Vec<(Ident, Ident)> = (i + 1..d).filter_map(|k| Some((fac(k, i)?, x(k)))).collect();
        let yi = &ys[i];
        let scaled = if i + 1 == d && i > 0 {
            let p = piv(i);
            quote!(#yi / #p)
        } else {
            let v = inv(i);
            quote!(#yi * #v)
        };
        let value = minus_products(Some(scaled), &products).expect("non-empty");
        let xi = x(i);
        solve.extend(quote!(let #xi = #value;));
    }
    let xs: Vec<TokenStream> = (0..d)
        .map(|i| {
            let xi = x(i);
            quote!(#xi)
        })
        .collect();
    let output_probe = finite_probe(&xs);
    let indices = (0..d).map(index);
    // Small models: the call would cost as much as the arithmetic.
    let inline = (d <= 4).then(|| quote!(#[inline]));
    quote! {
        #inline
        fn accelerations(
            &self,
            q: &SVector<f64, #dof>,
            qd: &SVector<f64, #dof>,
            inputs: &Inputs<Const<#dof>, #space>,
            out: &mut SVector<f64, #dof>,
        ) -> Result<()> {
            /// The error of a failed evaluation: the input checks' if they fail (a
            /// non-finite input always ends here), else `error`. Out of line: the hot path
            /// stays small.
            #[cold]
            #[inline(never)]
            fn failure(
                q: &SVector<f64, #dof>,
                qd: &SVector<f64, #dof>,
                inputs: &Inputs<Const<#dof>, #space>,
                error: Error,
            ) -> Error {
                match ::pendulum_core::check_inputs(#dof, q, qd, inputs) {
                    Err(input_error) => input_error,
                    Ok(()) => error,
                }
            }
            #torque
            #pivot
            #lets
            #factor
            #solve
            if #output_probe != 0.0 {
                return Err(failure(q, qd, inputs, Error::NotPositiveDefinite));
            }
            #(out[#indices] = #xs;)*
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;
    use std::io::Write;
    use std::path::Path;
    use std::process::{Command, Stdio};

    use proc_macro2::{Delimiter, TokenTree};

    use super::*;

    /// Expansions committed under `pendulum-macros/expanded/` so reviewers read diffs of
    /// real generated code.
    const EXPANSIONS: [(&str, &str); 2] = [
        ("planar3.rs", "pub struct Planar3 { kind: planar, links: 3 }"),
        ("spatial2.rs", "pub struct Spatial2 { kind: spatial, links: 2 }"),
    ];

    fn rustfmt(code: &str) -> String {
        let rustfmt = std::env::var("RUSTFMT").unwrap_or_else(|_| "rustfmt".into());
        let mut child = Command::new(&rustfmt)
            .args(["--edition", "2024", "--config", "max_width=110,use_small_heuristics=Max"])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("cannot run `{rustfmt}` to format the expansions: {e}"));
        child.stdin.take().unwrap().write_all(code.as_bytes()).unwrap();
        let output = child.wait_with_output().unwrap();
        assert!(output.status.success(), "rustfmt failed on the expansion");
        String::from_utf8(output.stdout).unwrap()
    }

    /// Writes the expansions (`write`) or checks that the committed ones are current.
    fn generate(write: bool) {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("expanded");
        for (file, item) in EXPANSIONS {
            let input: Input = syn::parse_str(item).unwrap();
            let header = format!(
                "// The expansion of `pendulum_macros::model! {{ {item} }}`, formatted.\n\
                 // Written by `UPDATE_EXPANSIONS=1 cargo test -p pendulum-macros --lib`; do not edit.\n\n"
            );
            let text = header + &rustfmt(&expand(&input).to_string());
            let path = dir.join(file);
            if write {
                std::fs::create_dir_all(&dir).unwrap();
                std::fs::write(&path, text).unwrap();
            } else {
                let committed = std::fs::read_to_string(&path).unwrap_or_default();
                assert!(
                    committed == text,
                    "{} is stale: run `UPDATE_EXPANSIONS=1 cargo test -p pendulum-macros --lib` \
                     and review the diff",
                    path.display()
                );
            }
        }
    }

    #[test]
    fn committed_expansions_are_current() {
        generate(std::env::var_os("UPDATE_EXPANSIONS").is_some());
    }

    fn idents(tokens: TokenStream, out: &mut Vec<String>) {
        for token in tokens {
            match token {
                proc_macro2::TokenTree::Ident(i) => out.push(i.to_string()),
                proc_macro2::TokenTree::Group(g) => idents(g.stream(), out),
                _ => {}
            }
        }
    }

    /// Every `fn name(…) … { body }` in `tokens`, at any depth, as (name, body).
    fn methods(tokens: TokenStream, out: &mut Vec<(String, TokenStream)>) {
        let tokens: Vec<TokenTree> = tokens.into_iter().collect();
        let mut k = 0;
        while k < tokens.len() {
            match &tokens[k] {
                TokenTree::Ident(i) if i == "fn" => {
                    let name = tokens[k + 1].to_string();
                    let (at, body) = tokens[k..]
                        .iter()
                        .enumerate()
                        .find_map(|(j, t)| match t {
                            TokenTree::Group(g) if g.delimiter() == Delimiter::Brace => Some((k + j, g)),
                            _ => None,
                        })
                        .expect("a fn has a body");
                    out.push((name, body.stream()));
                    k = at + 1;
                }
                TokenTree::Group(g) => {
                    methods(g.stream(), out);
                    k += 1;
                }
                _ => k += 1,
            }
        }
    }

    /// `i` if `tokens` start with `q[i]`.
    fn q_index(tokens: &[TokenTree]) -> Option<String> {
        match tokens {
            [TokenTree::Ident(q), TokenTree::Group(g), ..]
                if q == "q" && g.delimiter() == Delimiter::Bracket =>
            {
                Some(g.stream().to_string())
            }
            _ => None,
        }
    }

    /// What one method body does with the angles `q[i]`: the trig calls on each (`.sin()`,
    /// `.cos()`, `.sin_cos()`, and `check_polar_angle(_, q[i])`, which takes the sine
    /// itself), the names bound to each sine, and the `check_polar_sin(_, q[i], s)` calls.
    #[derive(Default)]
    struct AngleUses {
        trig: Vec<(String, String)>,
        sine: BTreeMap<String, String>,
        checks: Vec<(String, String)>,
    }

    fn angle_uses(body: TokenStream, uses: &mut AngleUses) {
        let tokens: Vec<TokenTree> = body.into_iter().collect();
        for (k, token) in tokens.iter().enumerate() {
            match token {
                TokenTree::Group(g) => angle_uses(g.stream(), uses),
                TokenTree::Ident(f) if f == "check_polar_angle" || f == "check_polar_sin" => {
                    let Some(TokenTree::Group(args)) = tokens.get(k + 1) else { continue };
                    let args: Vec<TokenTree> = args.stream().into_iter().collect();
                    let args: Vec<&[TokenTree]> =
                        args.split(|t| matches!(t, TokenTree::Punct(p) if p.as_char() == ',')).collect();
                    let i = q_index(args[1]).expect("the checks take q[i]");
                    if f == "check_polar_angle" {
                        uses.trig.push((i, f.to_string()));
                    } else {
                        uses.checks.push((i, args[2].iter().map(ToString::to_string).collect()));
                    }
                }
                TokenTree::Ident(_) => {
                    let Some(i) = q_index(&tokens[k..]) else { continue };
                    let Some(TokenTree::Ident(method)) = tokens.get(k + 3) else { continue };
                    let method = method.to_string();
                    if !["sin", "cos", "sin_cos"].contains(&method.as_str()) {
                        continue;
                    }
                    // `let s = q[i].sin()` or `let (s, c) = q[i].sin_cos()`
                    let bound = match (k.checked_sub(3).map(|p| &tokens[p..k]), method.as_str()) {
                        (Some([TokenTree::Ident(l), TokenTree::Ident(s), TokenTree::Punct(eq)]), "sin")
                            if l == "let" && eq.as_char() == '=' =>
                        {
                            Some(s.to_string())
                        }
                        (
                            Some([TokenTree::Ident(l), TokenTree::Group(pair), TokenTree::Punct(eq)]),
                            "sin_cos",
                        ) if l == "let" && eq.as_char() == '=' => {
                            pair.stream().into_iter().next().map(|s| s.to_string())
                        }
                        _ => None,
                    };
                    if let Some(s) = bound {
                        uses.sine.insert(s, i.clone());
                    }
                    uses.trig.push((i, method));
                }
                _ => {}
            }
        }
    }

    /// Per method of `tokens`: an angle with more than one trig call, or a
    /// `check_polar_sin` given something other than its angle's sine from this method.
    fn repeated_trig(tokens: TokenStream) -> Vec<String> {
        let mut found = Vec::new();
        let mut all = Vec::new();
        methods(tokens, &mut all);
        for (name, body) in all {
            let mut uses = AngleUses::default();
            angle_uses(body, &mut uses);
            let mut per_angle: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
            for (i, call) in &uses.trig {
                per_angle.entry(i).or_default().push(call);
            }
            for (i, calls) in per_angle.into_iter().filter(|(_, calls)| calls.len() > 1) {
                found.push(format!("{name}: q[{i}] has {calls:?}"));
            }
            for (i, sine) in &uses.checks {
                if uses.sine.get(sine) != Some(i) {
                    found.push(format!("{name}: check_polar_sin of q[{i}] is given `{sine}`"));
                }
            }
        }
        found
    }

    fn expansion(item: &str) -> TokenStream {
        expand(&syn::parse_str::<Input>(item).unwrap())
    }

    #[test]
    fn expansion_has_no_loops() {
        let mut words = Vec::new();
        idents(expansion("struct S3 { kind: spatial, links: 3 }"), &mut words);
        for word in ["in", "while", "loop", "Vec", "vec", "Box", "iter", "collect"] {
            assert!(!words.iter().any(|w| w == word), "the expansion contains `{word}`");
        }
    }

    #[test]
    fn every_method_takes_each_angles_sine_and_cosine_once() {
        for kind in ["planar", "spatial"] {
            for links in [1, 2, 3, 5] {
                let tokens = expansion(&format!("struct S {{ kind: {kind}, links: {links} }}"));
                let found = repeated_trig(tokens.clone());
                assert!(found.is_empty(), "{kind} {links}: {found:#?}");
                // The spatial checks: every link's, in both methods that make them.
                let mut all = Vec::new();
                methods(tokens, &mut all);
                for (name, body) in all {
                    let mut uses = AngleUses::default();
                    angle_uses(body, &mut uses);
                    let checked: Vec<String> = uses.checks.into_iter().map(|(i, _)| i).collect();
                    let want: Vec<String> = match (kind, name.as_str()) {
                        ("spatial", "check_configuration" | "accelerations") => {
                            (0..links).map(|i| i.to_string()).collect()
                        }
                        _ => Vec::new(),
                    };
                    assert_eq!(checked, want, "{kind} {links}: {name}");
                }
            }
        }
    }

    #[test]
    fn repeated_trig_finds_a_second_use_of_an_angle() {
        let bad = [
            // the sine twice: once in the check, once in the let
            quote!(
                fn a(q: V) {
                    check_polar_angle(1, q[0])?;
                    let (st0, ct0) = q[0].sin_cos();
                }
            ),
            quote!(
                fn b(q: V) {
                    let st0 = q[0].sin();
                    let (s, c) = q[0].sin_cos();
                }
            ),
            quote!(
                fn c(q: V) {
                    let x = 1.0 + q[1].cos() * q[1].cos();
                }
            ),
            // the check given another angle's sine, or a sine from nowhere
            quote!(
                fn d(q: V) {
                    let (st0, ct0) = q[0].sin_cos();
                    let st1 = q[1].sin();
                    check_polar_sin(1, q[0], st1)?;
                }
            ),
            quote!(
                fn e(q: V) {
                    check_polar_sin(1, q[0], st0)?;
                }
            ),
            quote!(
                fn f(q: V) {
                    let x = st0 * q[0].sin();
                    check_polar_sin(1, q[0], st0)?;
                }
            ),
        ];
        for tokens in bad {
            assert_eq!(repeated_trig(tokens.clone()).len(), 1, "{tokens}");
        }
        let good = quote! {
            fn f(q: V) { let (st0, ct0) = q[0].sin_cos(); check_polar_sin(1, q[0], st0)?; let c1 = q[1].cos(); }
            fn g(q: V) { let st0 = q[0].sin(); check_polar_sin(1, q[0], st0)?; let c1 = q[1].cos(); }
        };
        assert_eq!(repeated_trig(good), Vec::<String>::new());
    }
}
