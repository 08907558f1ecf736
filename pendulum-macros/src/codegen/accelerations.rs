//! `Model::accelerations`: `M q̈ = Q − c − (k + d)` solved by an unrolled `L D Lᵀ`
//! factorisation, with the polar-angle and input checks.

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use super::body::Body;
use super::guards::{failure, finite_probe};
use super::names::{ident, index, space};
use crate::plan::{Expr, Plan, Sym};

/// `fn accelerations`: `M` and `Q − c − (k + d)` as lets with the polar-angle checks among
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
pub(super) fn accelerations(plan: &Plan) -> TokenStream {
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
    let failure = failure(plan);
    let (factor, low) = factorisation(plan);
    let (solve, xs) = substitution(plan, &low);
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
            #failure
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

/// The factor `L` below the diagonal: `low[i][j] = (L_ij d_j, L_ij)` for `i > j`, as the
/// names of their lets, `None` where known to be zero.
type Lower = Vec<Vec<Option<(Ident, Ident)>>>;

/// `1/d_j`.
fn inv(j: usize) -> Ident {
    format_ident!("inv{j}")
}

/// The pivot `d_j`.
fn piv(j: usize) -> Ident {
    format_ident!("piv{j}")
}

/// The acceleration `x_i = q̈_i`.
fn x(i: usize) -> Ident {
    format_ident!("x{i}")
}

/// The lets of `M = L D Lᵀ`, column by column, each pivot checked, and the factor `L`.
fn factorisation(plan: &Plan) -> (TokenStream, Lower) {
    let d = plan.dof();
    let entry = |r: usize, c: usize| plan.mass_entry(r, c).map(ident);
    let mut low: Lower = vec![vec![None; d]; d];
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
    (factor, low)
}

/// The lets of the forward (`L y = r`) and back (`D Lᵀ x = y`) substitutions, and the
/// accelerations `x_i` they end in.
fn substitution(plan: &Plan, low: &Lower) -> (TokenStream, Vec<TokenStream>) {
    let d = plan.dof();
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
    let xs = (0..d)
        .map(|i| {
            let xi = x(i);
            quote!(#xi)
        })
        .collect();
    (solve, xs)
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
