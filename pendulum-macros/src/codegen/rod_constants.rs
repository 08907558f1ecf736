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

/// The per-link constants `accelerations` reads, as `(field, its value in new from the
/// lets m<i>, l<i>, lam<i>, doc)`: `1/m_i`, `l_i`, `1/l_i`, `λ_i/l_i` and the diagonal
/// `1/m_i + 1/m_{i−1}` of the tension system.
pub(super) fn stored(plan: &Plan) -> Vec<(Ident, TokenStream, String)> {
    let mut fields = Vec::new();
    for i in 0..plan.links {
        let (m, l, lam) = (id("m", i), id("l", i), id("lam", i));
        fields.push((id("rod_im", i), quote!(1.0 / #m), format!(" `1/m_{i}` (0-based), 1/kg.")));
        fields.push((id("rod_l", i), quote!(#l), format!(" `l_{i}` (0-based), m.")));
        fields.push((id("rod_il", i), quote!(1.0 / #l), format!(" `1/l_{i}` (0-based), 1/m.")));
        fields.push((id("rod_drag", i), quote!(#lam / #l), format!(" `λ_{i}/l_{i}` (0-based), N·s.")));
        let diagonal = if i == 0 {
            quote!(1.0 / #m)
        } else {
            let above = id("m", i - 1);
            quote!(1.0 / #m + 1.0 / #above)
        };
        let doc = if i == 0 {
            " `1/m_0` (0-based), 1/kg: the tension system's first diagonal entry.".to_owned()
        } else {
            format!(" `1/m_{i} + 1/m_{}` (0-based), 1/kg: the tension system's diagonal.", i - 1)
        };
        fields.push((id("rod_diag", i), diagonal, doc));
    }
    fields
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
