//! The chain models: the generic dense models in angles ([`Planar`], [`Spatial`]), the
//! O(n) routes by the rod tensions ([`PlanarTension`] in planar angles, [`Directions`] in
//! unit link directions; their solves live in [`rods`](crate::rods)), and the document's
//! closed-form double pendulum ([`DoublePendulum`], eq 50 corrected).

pub(crate) mod closed_form;
pub(crate) mod directions;
pub(crate) mod planar;
pub(crate) mod spatial;
pub(crate) mod tension;

pub use closed_form::DoublePendulum;
pub use directions::Directions;
pub use planar::Planar;
pub use spatial::Spatial;
pub use tension::PlanarTension;
