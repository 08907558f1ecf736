//! The methods of the `Model` impl other than `accelerations`, one function each.

use proc_macro2::TokenStream;
use quote::quote;

use super::body::{Body, expr, vector_outputs};
use super::names::index;
use crate::plan::{Expr, Plan, Sym};

/// `SVector<f64, dof>`, the type of `q`, `q̇` and the per-coordinate outputs.
fn vector(plan: &Plan) -> TokenStream {
    let dof = index(plan.dof());
    quote!(SVector<f64, #dof>)
}

/// `fn chain`: the chain the model was made of.
pub(super) fn chain_accessor(plan: &Plan) -> TokenStream {
    let n = index(plan.links);
    quote! {
        fn chain(&self) -> &Chain<Const<#n>> {
            &self.chain
        }
    }
}

/// `fn dof`: the number of coordinates, as a `Const`.
pub(super) fn dof_accessor(plan: &Plan) -> TokenStream {
    let dof = index(plan.dof());
    quote! {
        fn dof(&self) -> Const<#dof> {
            Const::<#dof>
        }
    }
}

/// `fn mass_matrix`: every entry of `M(q)`, `0.0` where identically zero.
pub(super) fn mass_matrix(plan: &Plan) -> TokenStream {
    let (dof, vector) = (index(plan.dof()), vector(plan));
    let entries: Vec<Expr> = plan.mass_entries().into_iter().map(Expr::of).collect();
    let body = Body::new(plan, &entries);
    let (q, lets) = (body.q(), &body.lets);
    let assigns = (0..plan.dof()).flat_map(|r| (0..plan.dof()).map(move |c| (r, c))).map(|(r, c)| {
        let value = plan.mass_entry(r, c).map_or_else(|| quote!(0.0), |s| expr(&Expr::of(s)));
        let (r, c) = (index(r), index(c));
        quote!(out[(#r, #c)] = #value;)
    });
    quote! {
        fn mass_matrix(&self, #q: &#vector, out: &mut SMatrix<f64, #dof, #dof>) {
            #lets
            #(#assigns)*
        }
    }
}

/// `fn velocity_terms`: `c(q, q̇)`.
pub(super) fn velocity_terms(plan: &Plan) -> TokenStream {
    let vector = vector(plan);
    let (body, assigns) = vector_outputs(plan, Sym::VelocityTerm);
    let (q, qd, lets) = (body.q(), body.qd(), &body.lets);
    quote! {
        fn velocity_terms(&self, #q: &#vector, #qd: &#vector, out: &mut #vector) {
            #lets
            #assigns
        }
    }
}

/// `fn gravity_terms`: `k(q) = ∂U/∂q`.
pub(super) fn gravity_terms(plan: &Plan) -> TokenStream {
    let vector = vector(plan);
    let (body, assigns) = vector_outputs(plan, Sym::GravityTerm);
    let (q, lets) = (body.q(), &body.lets);
    quote! {
        fn gravity_terms(&self, #q: &#vector, out: &mut #vector) {
            #lets
            #assigns
        }
    }
}

/// `fn pivot_terms`: `d(q, p̈)`.
pub(super) fn pivot_terms(plan: &Plan) -> TokenStream {
    let (vector, space_dim) = (vector(plan), index(plan.space()));
    let (body, assigns) = vector_outputs(plan, Sym::PivotTerm);
    let (q, lets) = (body.q(), &body.lets);
    quote! {
        fn pivot_terms(&self, #q: &#vector, pivot_acceleration: &SVector<f64, #space_dim>, out: &mut #vector) {
            #lets
            #assigns
        }
    }
}

/// `fn generalized_forces`: `Q = σ − ∂D/∂q̇`, the torques less the damping.
pub(super) fn generalized_forces(plan: &Plan) -> TokenStream {
    let vector = vector(plan);
    let (body, assigns) = vector_outputs(plan, Sym::Force);
    let (q, qd, lets) = (body.q(), body.qd(), &body.lets);
    quote! {
        fn generalized_forces(
            &self,
            #q: &#vector,
            #qd: &#vector,
            torque: &#vector,
            out: &mut #vector,
        ) {
            #lets
            #assigns
        }
    }
}

/// `fn kinetic_energy`, `fn potential_energy` and `fn energy`, the last from one set of
/// lets for both.
pub(super) fn energies(plan: &Plan) -> TokenStream {
    let (kinetic, potential) = (plan.kinetic_energy(), plan.potential_energy());
    let methods = [
        kinetic_energy(plan, &kinetic),
        potential_energy(plan, &potential),
        energy(plan, &kinetic, &potential),
    ];
    quote!(#(#methods)*)
}

/// `fn kinetic_energy`: `T(q, q̇)`, the expression `kinetic`.
fn kinetic_energy(plan: &Plan, kinetic: &Expr) -> TokenStream {
    let vector = vector(plan);
    let body = Body::new(plan, [kinetic]);
    let (q, qd, lets, value) = (body.q(), body.qd(), &body.lets, expr(kinetic));
    quote! {
        fn kinetic_energy(&self, #q: &#vector, #qd: &#vector) -> f64 {
            #lets
            #value
        }
    }
}

/// `fn potential_energy`: `U(q)`, the expression `potential`.
fn potential_energy(plan: &Plan, potential: &Expr) -> TokenStream {
    let vector = vector(plan);
    let body = Body::new(plan, [potential]);
    let (q, lets, value) = (body.q(), &body.lets, expr(potential));
    quote! {
        fn potential_energy(&self, #q: &#vector) -> f64 {
            #lets
            #value
        }
    }
}

/// `fn energy`: `H = T + U` from one set of lets, each sum as in its own method (the same
/// rounding).
fn energy(plan: &Plan, kinetic: &Expr, potential: &Expr) -> TokenStream {
    let vector = vector(plan);
    let body = Body::new(plan, [kinetic, potential]);
    let (q, qd, lets) = (body.q(), body.qd(), &body.lets);
    let (kinetic, potential) = (expr(kinetic), expr(potential));
    quote! {
        fn energy(&self, #q: &#vector, #qd: &#vector) -> f64 {
            #lets
            let kinetic = #kinetic;
            let potential = #potential;
            kinetic + potential
        }
    }
}

/// `fn check_configuration`: the polar-angle checks, `None` (the trait's default) when no
/// link can be singular.
pub(super) fn check_configuration(plan: &Plan) -> Option<TokenStream> {
    (!plan.singular_links().is_empty()).then(|| {
        let vector = vector(plan);
        let checks = &Body::checked(plan, [], &TokenStream::new()).lets;
        quote! {
            fn check_configuration(&self, q: &#vector) -> Result<()> {
                #checks
                Ok(())
            }
        }
    })
}
