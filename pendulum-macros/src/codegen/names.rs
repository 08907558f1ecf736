//! Names the generated code shares: the `let` of a symbol, index literals, the chart and
//! the pivot-acceleration type of a model.

use proc_macro2::{Ident, Literal, Span};
use quote::format_ident;

use crate::plan::{Kind, Plan, Sym};

/// The name of the `let` of `sym`.
pub(super) fn ident(sym: Sym) -> Ident {
    Ident::new(&sym.name(), Span::call_site())
}

/// `i` as an unsuffixed literal.
pub(super) fn index(i: usize) -> Literal {
    Literal::usize_unsuffixed(i)
}

/// The chart of the model's coordinates (`pendulum_core::kinematics`).
pub(super) fn chart(plan: &Plan) -> Ident {
    match plan.kind {
        Kind::Planar => format_ident!("PlanarAngles"),
        Kind::Spatial => format_ident!("SphericalAngles"),
    }
}

/// The pivot-acceleration type: `U2` planar, `U3` spatial.
pub(super) fn space(plan: &Plan) -> Ident {
    format_ident!("U{}", plan.space())
}
