//! The models `verify` checks, behind one generic entry point: the generic
//! `Planar<Dyn>`/`Spatial<Dyn>` and the fixed-N models `pendulum_macros::model!`
//! generates.
//!
//! Each model has its own type, so callers pass a [`ModelVisitor`] whose generic
//! [`visit`](ModelVisitor::visit) runs on whichever concrete model the case needs.

use anyhow::{Context, Result};
use nalgebra::{DefaultAllocator, Dim, Dyn, allocator::Allocator};
use pendulum_core::{Chain, Model, ModelAlloc, Planar, Spatial};

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
}

/// Something to do with one model, whatever its concrete type.
pub trait ModelVisitor {
    /// What the visit returns.
    type Output;

    /// Runs on `model`.
    fn visit<M: Model>(self, model: &M) -> Self::Output
    where
        DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>;
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
/// `params`, or returns `None` if no model of that size is generated.
pub fn with_generated<V: ModelVisitor>(
    kind: Kind,
    links: usize,
    params: &Params,
    visitor: V,
) -> Result<Option<V::Output>> {
    /// One line per generated type: `Kind n => Type`.
    macro_rules! dispatch {
        ($($kind:ident $n:literal => $model:ty),* $(,)?) => {{
            $(
                if (kind, links) == (Kind::$kind, $n) {
                    return Ok(Some(visitor.visit(&<$model>::new(chain::<nalgebra::Const<$n>>(params)?))));
                }
            )*
            Ok(None)
        }};
    }
    dispatch! {
        Planar 1 => Planar1,
        Planar 2 => Planar2,
        Planar 3 => Planar3,
        Planar 4 => Planar4,
        Planar 5 => Planar5,
        Planar 6 => Planar6,
        Planar 7 => Planar7,
        Planar 8 => Planar8,
        Spatial 1 => Spatial1,
        Spatial 2 => Spatial2,
        Spatial 3 => Spatial3,
        Spatial 4 => Spatial4,
        Spatial 5 => Spatial5,
    }
}
