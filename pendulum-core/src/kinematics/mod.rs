//! The chain's geometry in one place: coordinate charts for the link directions.
//!
//! A chain of `n` rigid links is described by the unit direction `u_i` of each link (from
//! mass `i−1` to mass `i`, mass 0 the pivot); mass `k` sits at `r_k = p + Σ_{i≤k} l_i u_i`.
//! A [`Chart`] writes `u_i` in angle coordinates — [`PlanarAngles`] (eqs 1–2) and
//! [`SphericalAngles`] (eqs 27–29) — and owns what follows from it: the link velocities
//! and accelerations, the mass positions, and the gradient `∂T/∂q` of the kinetic energy.
//! Every model in angles names its chart (`Model::Chart`); the models in unit directions
//! ([`Directions`](crate::models::directions::Directions)) convert to and from the charts
//! here. Nothing else in the crate writes `sin θ cos φ`. [`TurningFrame`] is the frame
//! turning with a pivot that circles the vertical.

mod planar;
mod spherical;
pub(crate) mod tilt;
pub(crate) mod trig;
pub(crate) mod trig32;
mod turning;

use nalgebra::{DefaultAllocator, Dim, DimName, OVector, allocator::Allocator};

use crate::chain::Chain;

pub use planar::PlanarAngles;
pub use spherical::{
    SINGULARITY_TOLERANCE, SphericalAngles, SphericalLink, check_polar_angle, check_polar_sin,
};
pub use turning::TurningFrame;

/// Angle coordinates of a chain's links, as the models order them: `q` holds one block of
/// `n` entries per name in [`COORDINATES`](Chart::COORDINATES) (planar `(θ_1…θ_n)`,
/// spatial `(θ_1…θ_n, φ_1…φ_n)`, eq 30's order), `q̇` and `q̈` likewise.
///
/// Functions take the chain's `q` (and rates) as slices; link indices are 0-based.
pub trait Chart: Copy + Default + std::fmt::Debug + Send + Sync + 'static {
    /// The space the links live in: `U2` (x, y up) or `U3` (x, y, z up).
    type Space: DimName;

    /// The names of a link's coordinates, one block of `q` each (`"theta"`, `"phi"`).
    const COORDINATES: &'static [&'static str];

    /// Number of coordinates of a chain of `links` links.
    fn dof(links: usize) -> usize {
        links * Self::COORDINATES.len()
    }

    /// The unit direction `u_i` of link `i`.
    fn direction(q: &[f64], i: usize) -> OVector<f64, Self::Space>
    where
        DefaultAllocator: Allocator<Self::Space>;

    /// The link's rate `u̇_i = Σ_a ∂u_i/∂q_a q̇_a` (1/s).
    fn link_velocity(q: &[f64], qd: &[f64], i: usize) -> OVector<f64, Self::Space>
    where
        DefaultAllocator: Allocator<Self::Space>;

    /// The link's acceleration `ü_i = Σ_a ∂u_i/∂q_a q̈_a + Σ_ab ∂²u_i/∂q_a∂q_b q̇_a q̇_b`
    /// (1/s²).
    fn link_acceleration(q: &[f64], qd: &[f64], qdd: &[f64], i: usize) -> OVector<f64, Self::Space>
    where
        DefaultAllocator: Allocator<Self::Space>;

    /// The gradient `∂T/∂q` at fixed rates (N·m) of `T = ½ Σ_ij W_ij u̇_i·u̇_j`
    /// (`W_ij = M_max(i,j) l_i l_j`, eq 10 tail masses): `∂T/∂q_a = (∂u̇_k/∂q_a)·Σ_j W_kj u̇_j`
    /// for `q_a` a coordinate of link `k`. Written into `out` (`dof` entries).
    ///
    /// Panics if `q`, `q̇` or `out` do not have [`dof`](Chart::dof) entries for the chain.
    fn kinetic_gradient<L: Dim>(chain: &Chain<L>, q: &[f64], qd: &[f64], out: &mut [f64])
    where
        DefaultAllocator: Allocator<L>;

    /// The kinetic energy relative to the pivot, `T = ½ Σ_k m_k |v_k|²` with
    /// `v_k = Σ_{j≤k} l_j u̇_j` (J; eq 11 planar, eq 48 as derived spatial): O(n).
    fn kinetic_energy<L: Dim>(chain: &Chain<L>, q: &[f64], qd: &[f64]) -> f64
    where
        DefaultAllocator: Allocator<L> + Allocator<Self::Space>,
    {
        let mut v = OVector::<f64, Self::Space>::zeros();
        let mut t = 0.0;
        for k in 0..chain.links() {
            v += Self::link_velocity(q, qd, k) * chain.lengths()[k];
            t += 0.5 * chain.masses()[k] * v.norm_squared();
        }
        t
    }

    /// Positions of the masses `r_k = p + Σ_{i≤k} l_i u_i` (m), pivot at `p`, mass 1
    /// (nearest the pivot) first.
    fn positions(
        lengths: &[f64],
        q: &[f64],
        pivot: &OVector<f64, Self::Space>,
    ) -> Vec<OVector<f64, Self::Space>>
    where
        DefaultAllocator: Allocator<Self::Space>,
    {
        let mut r = pivot.clone();
        lengths
            .iter()
            .enumerate()
            .map(|(i, l)| {
                r += Self::direction(q, i) * *l;
                r.clone()
            })
            .collect()
    }
}
