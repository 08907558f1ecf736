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

/// The per-link constants `accelerations` reads, the fields of
/// `pendulum_core::batch::LinkConstants` stored by `new` as `self.rods`, as
/// `(local name in accelerations, field, its entries in new from the lets m<i>, l<i>, lam<i>)`:
/// `1/m_i`, `l_i`, `1/l_i`, `λ_i/l_i` and the diagonal `1/m_i + 1/m_{i−1}` of the tension
/// system. The first four are also the `RodConstants` view of the Jacobians
/// ([`constants_view`]).
pub(super) fn stored(plan: &Plan) -> Vec<(Ident, Ident, Vec<TokenStream>)> {
    let (m, l, lam) = (|i| id("m", i), |i| id("l", i), |i| id("lam", i));
    let per_link = |entry: &dyn Fn(usize) -> TokenStream| (0..plan.links).map(entry).collect::<Vec<_>>();
    let field = |local: &str, name: &str, entries: Vec<TokenStream>| {
        (format_ident!("{local}"), format_ident!("{name}"), entries)
    };
    vec![
        field(
            "rod_im",
            "inverse_mass",
            per_link(&|i| {
                let m = m(i);
                quote!(1.0 / #m)
            }),
        ),
        field(
            "rod_l",
            "length",
            per_link(&|i| {
                let l = l(i);
                quote!(#l)
            }),
        ),
        field(
            "rod_il",
            "inverse_length",
            per_link(&|i| {
                let l = l(i);
                quote!(1.0 / #l)
            }),
        ),
        field(
            "rod_drag",
            "drag",
            per_link(&|i| {
                let (lam, l) = (lam(i), l(i));
                quote!(#lam / #l)
            }),
        ),
        field(
            "rod_diag",
            "diagonal",
            per_link(&|i| {
                let m = m(i);
                if i == 0 {
                    quote!(1.0 / #m)
                } else {
                    let above = id("m", i - 1);
                    quote!(1.0 / #m + 1.0 / #above)
                }
            }),
        ),
    ]
}

/// `LinkConstants { … }` of the chain, for `new` (after [`constructor_lets`]).
pub(super) fn constructor_value(plan: &Plan) -> TokenStream {
    let fields = stored(plan).into_iter().map(|(_, field, entries)| quote!(#field: [#(#entries),*]));
    quote!(::pendulum_core::batch::LinkConstants { #(#fields,)* gravity: chain.gravity() })
}

/// The lets that name the stored constants as `accelerations` reads them (`rod_im` …, `g`)
/// from `c`, a `LinkConstants`, and the numbers `one` and `zero` of its lane type `V`.
pub(super) fn locals(plan: &Plan, c: &TokenStream, lane: &TokenStream) -> TokenStream {
    let lets = stored(plan).into_iter().map(|(local, field, _)| quote!(let #local = &#c.#field;));
    quote! {
        #(#lets)*
        let g = #c.gravity;
        let one = <#lane as ::pendulum_core::lanes::Lane>::splat(1.0);
        let zero = <#lane as ::pendulum_core::lanes::Lane>::splat(0.0);
    }
}

/// `RodConstants { … }` of the stored arrays, for `planar_tension_jacobians`.
pub(super) fn constants_view() -> TokenStream {
    quote! {
        ::pendulum_core::__private::RodConstants {
            inverse_mass: &self.rods.inverse_mass,
            length: &self.rods.length,
            inverse_length: &self.rods.inverse_length,
            drag: &self.rods.drag,
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
