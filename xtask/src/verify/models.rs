//! The models `verify` checks, behind one generic entry point: the generic
//! `Planar<Dyn>`/`Spatial<Dyn>` and the fixed-N models `pendulum_macros::model!`
//! generates, with their default algorithm and with each algorithm named.
//!
//! Each model has its own type, so callers pass a [`ModelVisitor`] whose generic
//! [`visit`](ModelVisitor::visit) runs on whichever concrete model the case needs.

use anyhow::{Context, Result};
use nalgebra::{DefaultAllocator, Dim, Dyn, allocator::Allocator};
use pendulum_core::{Chain, Derivatives, ModelAlloc, Planar, Spatial};

use crate::case::{Kind, Params};

pendulum_macros::model! {
    /// Generated planar model, 1 link.
    pub struct Planar1 { kind: planar, links: 1 }
    /// Generated planar model, 2 links.
    pub struct Planar2 { kind: planar, links: 2 }
    /// Generated planar model, 3 links.
    pub struct Planar3 { kind: planar, links: 3 }
    /// Generated planar model, 4 links.
    pub struct Planar4 { kind: planar, links: 4 }
    /// Generated planar model, 5 links.
    pub struct Planar5 { kind: planar, links: 5 }
    /// Generated planar model, 6 links.
    pub struct Planar6 { kind: planar, links: 6 }
    /// Generated planar model, 7 links.
    pub struct Planar7 { kind: planar, links: 7 }
    /// Generated planar model, 8 links.
    pub struct Planar8 { kind: planar, links: 8 }
    /// Generated spatial model, 1 link.
    pub struct Spatial1 { kind: spatial, links: 1 }
    /// Generated spatial model, 2 links.
    pub struct Spatial2 { kind: spatial, links: 2 }
    /// Generated spatial model, 3 links.
    pub struct Spatial3 { kind: spatial, links: 3 }
    /// Generated spatial model, 4 links.
    pub struct Spatial4 { kind: spatial, links: 4 }
    /// Generated spatial model, 5 links.
    pub struct Spatial5 { kind: spatial, links: 5 }
    // Each algorithm at each size, whatever the default (the O(n) routes table).
    /// Generated planar model, 1 link, by the mass matrix.
    pub struct PlanarDense1 { kind: planar, links: 1, algorithm: dense }
    /// Generated planar model, 1 link, by the rod tensions.
    pub struct PlanarTension1 { kind: planar, links: 1, algorithm: tension }
    /// Generated planar model, 2 links, by the mass matrix.
    pub struct PlanarDense2 { kind: planar, links: 2, algorithm: dense }
    /// Generated planar model, 2 links, by the rod tensions.
    pub struct PlanarTension2 { kind: planar, links: 2, algorithm: tension }
    /// Generated planar model, 3 links, by the mass matrix.
    pub struct PlanarDense3 { kind: planar, links: 3, algorithm: dense }
    /// Generated planar model, 3 links, by the rod tensions.
    pub struct PlanarTension3 { kind: planar, links: 3, algorithm: tension }
    /// Generated planar model, 4 links, by the mass matrix.
    pub struct PlanarDense4 { kind: planar, links: 4, algorithm: dense }
    /// Generated planar model, 4 links, by the rod tensions.
    pub struct PlanarTension4 { kind: planar, links: 4, algorithm: tension }
    /// Generated planar model, 5 links, by the mass matrix.
    pub struct PlanarDense5 { kind: planar, links: 5, algorithm: dense }
    /// Generated planar model, 5 links, by the rod tensions.
    pub struct PlanarTension5 { kind: planar, links: 5, algorithm: tension }
    /// Generated planar model, 6 links, by the mass matrix.
    pub struct PlanarDense6 { kind: planar, links: 6, algorithm: dense }
    /// Generated planar model, 6 links, by the rod tensions.
    pub struct PlanarTension6 { kind: planar, links: 6, algorithm: tension }
    /// Generated planar model, 7 links, by the mass matrix.
    pub struct PlanarDense7 { kind: planar, links: 7, algorithm: dense }
    /// Generated planar model, 7 links, by the rod tensions.
    pub struct PlanarTension7 { kind: planar, links: 7, algorithm: tension }
    /// Generated planar model, 8 links, by the mass matrix.
    pub struct PlanarDense8 { kind: planar, links: 8, algorithm: dense }
    /// Generated planar model, 8 links, by the rod tensions.
    pub struct PlanarTension8 { kind: planar, links: 8, algorithm: tension }
    /// Generated spatial model, 1 link, by the mass matrix.
    pub struct SpatialDense1 { kind: spatial, links: 1, algorithm: dense }
    /// Generated spatial model, 1 link, by the rod tensions.
    pub struct SpatialTension1 { kind: spatial, links: 1, algorithm: tension }
    /// Generated spatial model, 2 links, by the mass matrix.
    pub struct SpatialDense2 { kind: spatial, links: 2, algorithm: dense }
    /// Generated spatial model, 2 links, by the rod tensions.
    pub struct SpatialTension2 { kind: spatial, links: 2, algorithm: tension }
    /// Generated spatial model, 3 links, by the mass matrix.
    pub struct SpatialDense3 { kind: spatial, links: 3, algorithm: dense }
    /// Generated spatial model, 3 links, by the rod tensions.
    pub struct SpatialTension3 { kind: spatial, links: 3, algorithm: tension }
    /// Generated spatial model, 4 links, by the mass matrix.
    pub struct SpatialDense4 { kind: spatial, links: 4, algorithm: dense }
    /// Generated spatial model, 4 links, by the rod tensions.
    pub struct SpatialTension4 { kind: spatial, links: 4, algorithm: tension }
    /// Generated spatial model, 5 links, by the mass matrix.
    pub struct SpatialDense5 { kind: spatial, links: 5, algorithm: dense }
    /// Generated spatial model, 5 links, by the rod tensions.
    pub struct SpatialTension5 { kind: spatial, links: 5, algorithm: tension }
}

/// Something to do with one model, whatever its concrete type.
pub trait ModelVisitor {
    /// What the visit returns.
    type Output;

    /// Runs on `model`.
    fn visit<M: Derivatives>(self, model: &M) -> Self::Output
    where
        DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + Allocator<M::Dof, M::Space>;
}

/// The chain of `params`, with `L = Dyn` or `Const<N>`.
pub fn chain<L: Dim>(params: &Params) -> Result<Chain<L>>
where
    DefaultAllocator: Allocator<L>,
{
    Chain::<L>::new(&params.masses, &params.lengths, params.gravity)
        .and_then(|c| c.with_damping(&params.damping))
        .with_context(|| format!("invalid chain parameters {params:?}"))
}

/// Runs `visitor` on the generic model of `kind` (`Planar<Dyn>` or `Spatial<Dyn>`)
/// built from `params`.
pub fn with_generic<V: ModelVisitor>(kind: Kind, params: &Params, visitor: V) -> Result<V::Output> {
    let chain = chain::<Dyn>(params)?;
    Ok(match kind {
        Kind::Planar => visitor.visit(&Planar::new(chain)),
        Kind::Spatial => visitor.visit(&Spatial::new(chain)),
    })
}

/// Runs `visitor` on the generated model of `kind` with `links` links built from
/// `params`, with the size's default algorithm, or returns `None` if no model of that size
/// is generated.
pub fn with_generated<V: ModelVisitor>(
    kind: Kind,
    links: usize,
    params: &Params,
    visitor: V,
) -> Result<Option<V::Output>> {
    dispatch(kind, links, None, params, visitor)
}

/// The generated algorithms, as named in `model!` (`algorithm: dense | tension`).
pub const ALGORITHMS: [&str; 2] = ["dense", "tension"];

/// Runs `visitor` on the generated model of `kind` with `links` links and `algorithm`
/// (`"dense"` or `"tension"`) built from `params`, or returns `None` if no such model is
/// generated.
pub fn with_generated_algorithm<V: ModelVisitor>(
    kind: Kind,
    links: usize,
    algorithm: &str,
    params: &Params,
    visitor: V,
) -> Result<Option<V::Output>> {
    dispatch(kind, links, Some(algorithm), params, visitor)
}

/// The one dispatch over the generated types: the default model of `(kind, links)` for
/// `algorithm: None`, else the one with that algorithm.
fn dispatch<V: ModelVisitor>(
    kind: Kind,
    links: usize,
    algorithm: Option<&str>,
    params: &Params,
    visitor: V,
) -> Result<Option<V::Output>> {
    /// One line per size: `Kind n => Default, Dense, Tension`.
    macro_rules! dispatch {
        ($($kind:ident $n:literal => $default:ty, $dense:ty, $tension:ty),* $(,)?) => {{
            $(
                if (kind, links) == (Kind::$kind, $n) {
                    let chain = chain::<nalgebra::Const<$n>>(params)?;
                    return Ok(match algorithm {
                        None => Some(visitor.visit(&<$default>::new(chain))),
                        Some("dense") => Some(visitor.visit(&<$dense>::new(chain))),
                        Some("tension") => Some(visitor.visit(&<$tension>::new(chain))),
                        Some(_) => None,
                    });
                }
            )*
            Ok(None)
        }};
    }
    dispatch! {
        Planar 1 => Planar1, PlanarDense1, PlanarTension1,
        Planar 2 => Planar2, PlanarDense2, PlanarTension2,
        Planar 3 => Planar3, PlanarDense3, PlanarTension3,
        Planar 4 => Planar4, PlanarDense4, PlanarTension4,
        Planar 5 => Planar5, PlanarDense5, PlanarTension5,
        Planar 6 => Planar6, PlanarDense6, PlanarTension6,
        Planar 7 => Planar7, PlanarDense7, PlanarTension7,
        Planar 8 => Planar8, PlanarDense8, PlanarTension8,
        Spatial 1 => Spatial1, SpatialDense1, SpatialTension1,
        Spatial 2 => Spatial2, SpatialDense2, SpatialTension2,
        Spatial 3 => Spatial3, SpatialDense3, SpatialTension3,
        Spatial 4 => Spatial4, SpatialDense4, SpatialTension4,
        Spatial 5 => Spatial5, SpatialDense5, SpatialTension5,
    }
}
