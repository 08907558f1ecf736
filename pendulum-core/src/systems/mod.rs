//! A chain model as a first-order system `x' = f(t, x)` for the integrators: in velocities
//! ([`FirstOrder`], `x = (q, q̇)`) or in canonical momenta ([`Canonical`], `x = (q, p)`).

pub(crate) mod canonical;
pub(crate) mod first_order;

pub use canonical::Canonical;
pub use first_order::{Analytic, Differences, FirstOrder};
