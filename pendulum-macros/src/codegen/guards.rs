//! What both `accelerations` bodies end with: the out-of-line failure path (the input
//! checks first) and the finiteness probe of the results.

use proc_macro2::TokenStream;
use quote::quote;

use super::names::{index, space};
use crate::plan::Plan;

/// `fn failure` inside `accelerations`: the error of a failed evaluation, the input
/// checks' first.
pub(super) fn failure(plan: &Plan) -> TokenStream {
    let dof = index(plan.dof());
    let space = space(plan);
    quote! {
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
    }
}

/// `Σ (x − x)` over `values` as a balanced tree of additions (latency `log₂` of their
/// number): `0.0` exactly when every value is finite, NaN otherwise (`x − x` is NaN for
/// ±∞ and NaN). One subtraction and one addition per value, no branch per value.
pub(super) fn finite_probe(values: &[TokenStream]) -> TokenStream {
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
