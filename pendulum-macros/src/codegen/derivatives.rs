//! `impl Derivatives for Name`: `∂(M v)/∂q` and the Jacobians of the right-hand side as
//! straight-line code from the plan's own derivatives (`plan::derivatives`); the trait's
//! `acceleration_jacobians` combines them with one Cholesky factorisation of `M`.

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use super::body::{Body, expr};
use super::names::index;
use crate::plan::{Algorithm, Expr, Kind, Plan, Sym, Var};

/// The `Derivatives` impl; a planar model on the tension route takes its Jacobians from the
/// kept tension solve instead of factoring `M` ([`tension_jacobians`]).
pub(super) fn derivatives_impl(name: &Ident, plan: &Plan, algorithm: Algorithm) -> TokenStream {
    let mass = mass_matrix_partials(plan);
    let force = force_jacobians(plan);
    let jacobians =
        (algorithm == Algorithm::Tension && plan.kind == Kind::Planar).then(|| tension_jacobians(plan));
    quote! {
        #[automatically_derived]
        #[allow(clippy::suboptimal_flops, clippy::eq_op)]
        impl Derivatives for #name {
            #mass
            #force
            #jacobians
        }
    }
}

/// `fn acceleration_jacobians` and `fn state_jacobians` by `pendulum_core`'s kept planar tension solve in the links'
/// own angles (O(n) solve, O(n²) Jacobians, stack arrays), from the stored rod constants.
fn tension_jacobians(plan: &Plan) -> TokenStream {
    let d = index(plan.dof());
    let rods = super::rod_constants::constants_view();
    let method = |name: &str, parts: &str, doc: &str| {
        let (name, parts) = (format_ident!("{name}"), format_ident!("{parts}"));
        quote! {
            #[doc = #doc]
            fn #name(
                &self,
                q: &SVector<f64, #d>,
                qd: &SVector<f64, #d>,
                inputs: &Inputs<Const<#d>, U2>,
                out: &mut ::pendulum_core::Jacobians<Self>,
            ) -> Result<()> {
                ::pendulum_core::__private::planar_tension_jacobians(
                    self, #rods, q, qd, inputs, out, ::pendulum_core::Parts::#parts,
                )
            }
        }
    };
    let all = method(
        "acceleration_jacobians",
        "All",
        " `q̈` and its Jacobians by the kept tension solve in the links' own angles \
         (`pendulum_core::PlanarTangents`): O(n²), no factorisation of `M`.",
    );
    let state = method("state_jacobians", "State", " `q̈`, `∂q̈/∂q` and `∂q̈/∂q̇` alone, by the same solve.");
    quote!(#all #state)
}

/// `fn mass_matrix_partials`: `out[(a, x)] = Σ_b ∂M_ab/∂q_x v_b`, the partials as lets.
fn mass_matrix_partials(plan: &Plan) -> TokenStream {
    let dof = plan.dof();
    let entries: Vec<Expr> = (0..dof)
        .flat_map(|a| (0..dof).map(move |x| (a, x)))
        .map(|(a, x)| {
            let mut e = Expr::default();
            for b in 0..dof {
                if let Some(partial) = plan.mass_partial(a, b, x) {
                    e.terms.push(crate::plan::Term { coef: 1.0, factors: vec![partial, Sym::Probe(b)] });
                }
            }
            e
        })
        .collect();
    let body = Body::new(plan, &entries);
    let (q, v, lets) = (body.q(), body.param("v", |s| matches!(s, Sym::Probe(_))), &body.lets);
    let assigns = entries.iter().enumerate().map(|(k, e)| {
        let (a, x, value) = (index(k / dof), index(k % dof), expr(e));
        quote!(out[(#a, #x)] = #value;)
    });
    let d = index(dof);
    quote! {
        fn mass_matrix_partials(&self, #q: &SVector<f64, #d>, #v: &SVector<f64, #d>, out: &mut SMatrix<f64, #d, #d>) {
            #lets
            #(#assigns)*
        }
    }
}

/// `fn force_jacobians`: every `∂F_a/∂q_x`, `∂F_a/∂q̇_x` and `∂F_a/∂p̈_k`, the plan's
/// derivative inline, `0.0` where identically zero.
fn force_jacobians(plan: &Plan) -> TokenStream {
    let cells: Vec<(usize, Var, Expr)> = (0..plan.dof())
        .flat_map(|a| plan.variables().map(move |var| (a, var)))
        .map(|(a, var)| (a, var, plan.definition(Sym::RhsPartial(a, var)).unwrap_or_default()))
        .collect();
    let body = Body::new(plan, cells.iter().map(|(_, _, e)| e));
    let (q, qd, lets) = (body.q(), body.qd(), &body.lets);
    let reads_pivot = body.uses(|s| matches!(s, Sym::Pivot(_)));
    let inputs = body.param("inputs", |s| matches!(s, Sym::Pivot(_)));
    let pivot = reads_pivot.then(|| quote!(let pivot_acceleration = &inputs.pivot_acceleration;));
    let assigns = cells.iter().map(|(a, var, e)| {
        let (a, value) = (index(*a), expr(e));
        match *var {
            Var::Coord(x) => {
                let x = index(x);
                quote!(dq[(#a, #x)] = #value;)
            }
            Var::Rate(x) => {
                let x = index(x);
                quote!(dqd[(#a, #x)] = #value;)
            }
            Var::Pivot(k) => {
                let k = index(k);
                quote!(dp[(#a, #k)] = #value;)
            }
        }
    });
    let (d, s, k) = (index(plan.dof()), super::names::space(plan), index(plan.space()));
    quote! {
        fn force_jacobians(
            &self,
            #q: &SVector<f64, #d>,
            #qd: &SVector<f64, #d>,
            #inputs: &Inputs<Const<#d>, #s>,
            dq: &mut SMatrix<f64, #d, #d>,
            dqd: &mut SMatrix<f64, #d, #d>,
            dp: &mut SMatrix<f64, #d, #k>,
        ) {
            #pivot
            #lets
            #(#assigns)*
        }
    }
}
