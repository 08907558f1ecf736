//! `model!`: fixed-N chain models as straight-line code, implementing
//! `pendulum_core::Model` with the same results as the generic `Planar` and `Spatial`.
//!
//! ```
//! use pendulum_core::{Chain, Model};
//!
//! pendulum_macros::model! {
//!     /// An unrolled triple pendulum.
//!     pub struct Planar3 { kind: planar, links: 3 }
//!     pub(crate) struct Spatial2 { kind: spatial, links: 2 }
//! }
//!
//! let model = Planar3::new(Chain::uniform(3, 1.0, 0.5, 9.81)?);
//! let q = nalgebra::Vector3::new(0.3, -0.2, 1.0);
//! let mut qdd = nalgebra::Vector3::zeros();
//! model.accelerations(&q, &nalgebra::Vector3::zeros(), &model.zero_inputs(), &mut qdd)?;
//! # Ok::<(), pendulum_core::Error>(())
//! ```
//!
//! See [`model!`] for the syntax and what it generates; `expanded/` holds the formatted
//! expansion for a few `n`, kept current by a unit test.
//!
//! Inside: `parse` reads the input, `plan` describes what to emit as plain data,
//! `codegen` turns the plan into tokens.

mod codegen;
mod parse;
mod plan;

use proc_macro::TokenStream;

/// Generates one fixed-N chain model per item
/// `#[attrs] vis struct Name { kind: planar|spatial, links: N[, algorithm: dense|tension] }`.
///
/// - `kind: planar`: coordinates `q = (θ_1 … θ_n)`, `Dof = Const<n>`, `Space = U2`;
///   `kind: spatial`: `q = (θ_1 … θ_n, φ_1 … φ_n)`, `Dof = Const<2n>`, `Space = U3`.
/// - `links`: an integer literal from 1 to 16.
/// - `algorithm` (optional): how `accelerations` solves for `q̈`. `dense` factors the mass
///   matrix (below); `tension` solves the rods' tension system instead, O(n): the
///   algorithm of `pendulum_core::PlanarTension` and `Directions` unrolled in the model's
///   angles, its per-link constants (`1/m_i`, `l_i`, `1/l_i`, `λ_i/l_i`, the tension
///   system's diagonal) stored by `new`, the sines and cosines from one vectorised kernel
///   call, and the tridiagonal system by a twisted factorisation (eliminated from both
///   ends at once, continuants instead of divisions on the serial chains, a classical
///   fallback for chains whose continuants leave their range). Default: the faster one
///   measured for that size, `dense` below n = 4 planar and n = 2 spatial, `tension` from
///   there (`docs/bench.md`). `Name::ALGORITHM` is `"dense"` or `"tension"`.
///
/// Each item becomes `vis struct Name { chain: Chain<Const<n>> }` (the attributes and doc
/// comments pass through; `Clone` is derived, `Debug` and `PartialEq` show and compare
/// the chain) with `vis fn new(chain) -> Self`, `From<Chain<Const<n>>>` and an impl of
/// `pendulum_core::Model` that gives the same results as `pendulum_core::Planar` /
/// `pendulum_core::Spatial`, to round-off. Every method is straight-line code: each
/// angle's sine and cosine computed once, angle differences from the angle-sum
/// identities, no loops and no allocation; what depends on the chain alone
/// (`W_ij = M_max(i,j) l_i l_j`, `M_i l_i`, `1/W_00`) is computed by `new` and stored;
/// `energy` shares one set of temporaries between `T` and `U`.
/// With `algorithm: dense`, `accelerations` solves `M q̈ = Q − c − (k + d)` by an
/// unrolled `L D Lᵀ` factorisation (no square roots, one division per pivot). Both
/// algorithms run `check_polar_sin` on every link for spatial models (with the sines they
/// compute anyway), and return `Error::NotPositiveDefinite` (`dense`: a pivot not
/// positive or the result not finite) or `Error::NonFiniteAccelerations` (`tension`: the
/// result not finite), and on the way to any error runs `check_inputs` first, whose error (a non-finite or
/// missized input, named) takes precedence: a non-finite input always makes the result
/// non-finite, so the happy path does not check the inputs one by one.
///
/// A model with `algorithm: tension` also implements `pendulum_core::batch::Generated<n>`
/// (its stored constants and its chart) and `PlanarKernel<n>` (planar) or
/// `SpatialKernel<n>` (spatial): its
/// accelerations are written once, as a kernel over any lane type, which `accelerations`
/// runs on `f64` and `pendulum_core::batch::UnrolledBatch` (planar) or
/// `UnrolledSpatialBatch` (spatial) on four or eight chains at once (bit for bit, or in
/// single precision).
///
/// Mistakes in the input are compile errors pointing at the offending token, all
/// reported at once.
#[proc_macro]
pub fn model(input: TokenStream) -> TokenStream {
    syn::parse::<parse::Input>(input)
        .map_or_else(|e| e.to_compile_error(), |input| codegen::expand(&input))
        .into()
}
