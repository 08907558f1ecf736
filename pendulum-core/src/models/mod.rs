//! The chain models: the generic dense models in angles ([`Planar`], [`Spatial`]), and the
//! O(n) routes by the rod tensions ([`PlanarTension`] in planar angles, [`Directions`] in
//! unit link directions), with the tension solve and the sine kernel they share; and the
//! document's closed-form double pendulum ([`DoublePendulum`], eq 50 corrected).

pub(crate) mod closed_form;
pub(crate) mod directions;
pub(crate) mod planar;
pub(crate) mod rod_midpoint;
pub(crate) mod rod_newton;
pub(crate) mod rods;
pub(crate) mod spatial;
pub(crate) mod tension;
pub(crate) mod trig;

pub use closed_form::DoublePendulum;
pub use directions::Directions;
pub use planar::Planar;
pub use rod_midpoint::RodMidpoint;
pub use spatial::Spatial;
pub use tension::{PlanarTangents, PlanarTension};
