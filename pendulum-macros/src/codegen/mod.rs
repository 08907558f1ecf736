//! Tokens from a [`Plan`]: the struct, its constructor and its `pendulum_core::Model` impl,
//! as straight-line code (one `let` per symbol, in the plan's order).
//!
//! [`model`] composes the items, one function each: [`items`] has the struct and its impls
//! other than `Model`, [`model_impl`] the `Model` impl (its associated types here, its
//! methods in [`methods`], and `accelerations` by the chosen algorithm: [`accelerations`]
//! for `dense`, [`tension`] for `tension`, with the per-link constants of the latter in
//! [`rod_constants`]); [`body`] writes the methods' lets, [`guards`] the failure path and
//! finiteness probe both `accelerations` end with, [`names`] the shared identifiers.

mod accelerations;
mod body;
mod derivatives;
#[cfg(test)]
mod expansions;
mod guards;
mod items;
mod methods;
mod names;
mod rod_constants;
mod tension;
#[cfg(test)]
mod tests;

use proc_macro2::{Ident, TokenStream};
use quote::quote;

use self::names::{chart, index, space};
use crate::parse::{Input, ModelDef};
use crate::plan::{Algorithm, Plan};

/// Everything `model!` emits for its input.
pub fn expand(input: &Input) -> TokenStream {
    input.models.iter().map(model).collect()
}

/// One model: the struct, then its impls in a `const _` block that imports what they name.
fn model(def: &ModelDef) -> TokenStream {
    let plan = Plan::new(def.kind, def.links);
    let algorithm = def.algorithm.unwrap_or(Algorithm::default_for(def.kind, def.links));
    let stored = items::stored(&plan);
    let name = &def.ident;
    // A `#[cfg]` on the struct must also remove its impls.
    let cfgs = def.attrs.iter().filter(|a| a.path().is_ident("cfg"));
    let struct_item = items::struct_item(def, &plan, &stored, algorithm);
    let imports = imports(&plan);
    // Every impl, in the order emitted: another trait impl is one more entry (its trait
    // imported in `imports`).
    let mut impls = vec![
        items::constructor(def, &plan, &stored, algorithm),
        items::debug_impl(name),
        items::partial_eq_impl(name),
        items::from_impl(name, &plan),
        model_impl(name, &plan, algorithm),
        derivatives::derivatives_impl(name, &plan, algorithm),
    ];
    if algorithm == Algorithm::Tension {
        // The accelerations' kernel, which `pendulum_core::batch::UnrolledBatch` (planar)
        // and `UnrolledSpatialBatch` (spatial) run in lanes.
        impls.push(tension::kernel_impl(name, &plan));
    }
    quote! {
        #struct_item

        #(#cfgs)*
        const _: () = {
            #imports

            #(#impls)*
        };
    }
}

/// The `use` items of the `const _` block: the impls name these unqualified.
fn imports(plan: &Plan) -> TokenStream {
    let space = space(plan);
    quote! {
        use ::core::primitive::f64;
        use ::core::result::Result::{Err, Ok};
        use ::pendulum_core::__private::nalgebra::{Const, SMatrix, SVector, #space};
        use ::pendulum_core::{Chain, Derivatives, Error, Inputs, Model, Result};
    }
}

/// `impl Model for Name`: the [associated types](associated_types), then the methods, with
/// `accelerations` by the chosen [`Algorithm`].
fn model_impl(name: &Ident, plan: &Plan, algorithm: Algorithm) -> TokenStream {
    let associated_types = associated_types(plan);
    let methods = [
        methods::chain_accessor(plan),
        methods::dof_accessor(plan),
        methods::mass_matrix(plan),
        methods::velocity_terms(plan),
        methods::gravity_terms(plan),
        methods::pivot_terms(plan),
        methods::generalized_forces(plan),
        methods::energies(plan),
    ];
    let check_configuration = methods::check_configuration(plan);
    let accelerations = match algorithm {
        Algorithm::Dense => accelerations::accelerations(plan),
        Algorithm::Tension => tension::accelerations(plan),
    };
    // `mul_add` would be a slow libm call on targets without FMA, and would round
    // differently from the generic models. `x - x` is the finiteness probe
    // (NaN for ±∞ and NaN, 0 otherwise).
    quote! {
        #[automatically_derived]
        #[allow(clippy::suboptimal_flops, clippy::eq_op)]
        impl Model for #name {
            #associated_types

            #(#methods)*

            #check_configuration

            #accelerations
        }
    }
}

/// The `Model` impl's associated types: `Links`, `Dof` and `Space`.
fn associated_types(plan: &Plan) -> TokenStream {
    let n = index(plan.links);
    let dof = index(plan.dof());
    let space = space(plan);
    let chart = chart(plan);
    quote! {
        type Links = Const<#n>;
        type Dof = Const<#dof>;
        type Space = #space;
        type Chart = ::pendulum_core::kinematics::#chart;
    }
}
