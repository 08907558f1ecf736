//! The per-link constants of the tension route, stored by `new`: their fields, values and
//! docs, shared by the struct (`items`) and the route (`tension`).

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use super::names::index;
use crate::plan::Plan;

/// `name` with the link index appended: `st3`.
pub(super) fn id(name: &str, i: usize) -> Ident {
    format_ident!("{name}{i}")
}

/// The per-link constants `accelerations` reads, one array field of `n` entries each, as
/// `(field, its entries in new from the lets m<i>, l<i>, lam<i>, doc)`: `1/m_i`, `l_i`,
/// `1/l_i`, `λ_i/l_i` and the diagonal `1/m_i + 1/m_{i−1}` of the tension system. The
/// first four are also the `RodConstants` view of the Jacobians ([`constants_view`]).
pub(super) fn stored(plan: &Plan) -> Vec<(Ident, Vec<TokenStream>, String)> {
    let (m, l, lam) = (|i| id("m", i), |i| id("l", i), |i| id("lam", i));
    let per_link = |entry: &dyn Fn(usize) -> TokenStream| (0..plan.links).map(entry).collect::<Vec<_>>();
    let field =
        |name: &str, entries: Vec<TokenStream>, doc: &str| (format_ident!("{name}"), entries, doc.to_owned());
    vec![
        field(
            "rod_im",
            per_link(&|i| {
                let m = m(i);
                quote!(1.0 / #m)
            }),
            " `1/m_i` per link (0-based), 1/kg.",
        ),
        field(
            "rod_l",
            per_link(&|i| {
                let l = l(i);
                quote!(#l)
            }),
            " `l_i` per link, m.",
        ),
        field(
            "rod_il",
            per_link(&|i| {
                let l = l(i);
                quote!(1.0 / #l)
            }),
            " `1/l_i` per link, 1/m.",
        ),
        field(
            "rod_drag",
            per_link(&|i| {
                let (lam, l) = (lam(i), l(i));
                quote!(#lam / #l)
            }),
            " `λ_i/l_i` per link, N·s.",
        ),
        field(
            "rod_diag",
            per_link(&|i| {
                let m = m(i);
                if i == 0 {
                    quote!(1.0 / #m)
                } else {
                    let above = id("m", i - 1);
                    quote!(1.0 / #m + 1.0 / #above)
                }
            }),
            " `1/m_i + 1/m_{i−1}` per link (`1/m_0` for the first), 1/kg: the tension system's diagonal.",
        ),
    ]
}

/// `RodConstants { … }` of the stored arrays, for `planar_tension_jacobians`.
pub(super) fn constants_view() -> TokenStream {
    quote! {
        ::pendulum_core::__private::RodConstants {
            inverse_mass: &self.rod_im,
            length: &self.rod_l,
            inverse_length: &self.rod_il,
            drag: &self.rod_drag,
        }
    }
}

/// The lets `new` needs for [`stored`]: `m<i>`, `l<i>`, `lam<i>` from the chain.
pub(super) fn constructor_lets(plan: &Plan) -> TokenStream {
    let n = plan.links;
    let (m, l, lam) = ((0..n).map(|i| id("m", i)), (0..n).map(|i| id("l", i)), (0..n).map(|i| id("lam", i)));
    let idx = (0..n).map(index).collect::<Vec<_>>();
    quote! {
        let masses = chain.masses();
        let lengths = chain.lengths();
        let damping = chain.damping();
        #(let #m = masses[#idx];)*
        #(let #l = lengths[#idx];)*
        #(let #lam = damping[#idx];)*
    }
}
