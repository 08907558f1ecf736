//! The chain in unit link directions: no angles, no coordinate singularity, O(n) per
//! evaluation. The representation for large chains and for 3D chains that hang straight
//! down, swing through the vertical and spin.

use std::marker::PhantomData;

use nalgebra::{DVector, DefaultAllocator, DimName, Dyn, OVector, U2, U3, allocator::Allocator};

use crate::chain::Chain;
use crate::drive::{Drive, Fixed};
use crate::error::{Error, Result};
use crate::integrate::{Constrained, System};
use crate::kinematics::{Chart, PlanarAngles, SphericalAngles, SphericalLink, check_polar_sin};
use crate::lanes::Lane;
use crate::model::check_vector;
use crate::rods::{Load, Rods, with_scratch};

mod tangents;

pub(crate) use tangents::state_column;

/// A chain of `n` point masses on rigid rods in the plane (`S = U2`, y up) or in space
/// (`S = U3`, z up), described by the unit direction `u_i` of each rod (from mass `i−1` to
/// mass `i`, mass 0 the pivot) and its rate `w_i = u̇_i` (1/s), with the pivot moved by
/// the drive `Dr` (default [`Fixed`]).
///
/// State `x = (u_1, …, u_n, w_1, …, w_n)`, each vector's `S` components in a row:
/// `2·S·n` entries. The equations of motion are Newton's for the masses with the rod
/// tensions as unknowns (`rods` module docs):
/// ```text
/// u̇_i = w_i,   ẇ_i = ü_i(u, w, p̈(t))    (one tridiagonal solve, O(n))
/// ```
/// with gravity `g` along −y (planar) or −z (spatial) and the damping of the chain's
/// Rayleigh function `D = ½ Σ λ_i |u̇_i|²` (the force pair `F_i = −λ_i w_i / l_i` on rod
/// `i`; planar this is eq 26's `−λ_i θ̇_i`, spatial the same `λ` as the spherical models).
/// The same physics as [`Planar`](crate::models::Planar) and [`Spatial`](crate::models::Spatial) (tests
/// compare them to round-off), without their coordinates: the spatial model in angles is
/// singular where a link hangs straight down; this one is not.
///
/// The exact flow keeps `|u_i| = 1` and `u_i · w_i = 0`; a numerical one drifts off
/// them by its truncation error. [`project`](Constrained::project) puts a state back
/// (normalise `u_i`, remove the radial part of `w_i`) and
/// [`Projected`](crate::integrate::Projected) does it after every step, which keeps the
/// rod lengths exact to round-off (`docs/large-chains.md`).
///
/// Only dynamic sizes (`Dyn`): the representation is for long chains; fixed small chains
/// have the angle models and the generated code.
#[derive(Debug, Clone)]
pub struct Directions<S: DimName, Dr = Fixed> {
    chain: Chain<Dyn>,
    rods: Rods,
    drive: Dr,
    space: PhantomData<S>,
}

impl<S: DimName> Directions<S, Fixed> {
    /// The chain with its pivot at rest.
    ///
    /// The space must be `U2` or `U3` (other dimensions do not compile into a model:
    /// [`System::rhs`] would refuse them at run time).
    pub fn new(chain: Chain<Dyn>) -> Self {
        let rods =
            Rods::new(chain.masses().as_slice(), chain.lengths().as_slice(), chain.damping().as_slice());
        Self { chain, rods, drive: Fixed, space: PhantomData }
    }
}

impl<S: DimName, Dr> Directions<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    /// The same chain with its pivot moved by `drive`.
    pub fn with_drive<D2: Drive<S>>(self, drive: D2) -> Directions<S, D2> {
        Directions { chain: self.chain, rods: self.rods, drive, space: PhantomData }
    }

    /// The tension solve's constants.
    pub(crate) fn rods(&self) -> &Rods {
        &self.rods
    }

    /// The chain's parameters.
    pub fn chain(&self) -> &Chain<Dyn> {
        &self.chain
    }

    /// The pivot drive.
    pub fn drive(&self) -> &Dr {
        &self.drive
    }

    /// The pivot drive, to change between steps (a drive steered while it runs, such as
    /// [`Steered`](crate::Steered)).
    pub fn drive_mut(&mut self) -> &mut Dr {
        &mut self.drive
    }

    /// Number of links.
    pub fn links(&self) -> usize {
        self.chain.links()
    }

    /// Length of the state vector, `2·S·n`.
    pub fn state_len(&self) -> usize {
        2 * S::DIM * self.links()
    }

    /// The chain hanging straight down at rest: `u_i = −e_up`, `w_i = 0`.
    pub fn hanging(&self) -> DVector<f64> {
        let mut x = DVector::zeros(self.state_len());
        for i in 0..self.links() {
            x[i * S::DIM + S::DIM - 1] = -1.0;
        }
        x
    }

    /// Direction `u_i` of link `i` (0-based) in the state `x`.
    pub fn direction(&self, x: &DVector<f64>, i: usize) -> OVector<f64, S> {
        OVector::<f64, S>::from_column_slice(&x.as_slice()[i * S::DIM..(i + 1) * S::DIM])
    }

    /// Rate `w_i = u̇_i` (1/s) of link `i` (0-based) in the state `x`.
    pub fn rate(&self, x: &DVector<f64>, i: usize) -> OVector<f64, S> {
        let base = (self.links() + i) * S::DIM;
        OVector::<f64, S>::from_column_slice(&x.as_slice()[base..base + S::DIM])
    }

    /// Errors unless `x` has `2·S·n` finite entries.
    pub fn check_state(&self, x: &DVector<f64>) -> Result<()> {
        self.check_state_slice(x.as_slice())
    }

    /// [`check_state`](Self::check_state) of a state held as a slice.
    pub(crate) fn check_state_slice(&self, x: &[f64]) -> Result<()> {
        check_vector("x", x, self.state_len())
    }

    /// Positions of the masses relative to the pivot, `r_i − p = Σ_{j≤i} l_j u_j` (m).
    pub fn relative_positions(&self, x: &DVector<f64>) -> Vec<OVector<f64, S>> {
        self.cumulative(x, 0)
    }

    /// Velocities of the masses relative to the pivot, `Σ_{j≤i} l_j w_j` (m/s).
    pub fn relative_velocities(&self, x: &DVector<f64>) -> Vec<OVector<f64, S>> {
        self.cumulative(x, self.links())
    }

    fn cumulative(&self, x: &DVector<f64>, first: usize) -> Vec<OVector<f64, S>> {
        self.running_sums(x.as_slice(), first).collect()
    }

    /// `Σ_{j≤i} l_j x_{first + j}` for each link `i` in turn (`x_j` the `j`-th vector of
    /// `S` entries of `x`), one at a time: no array of them.
    fn running_sums<'a>(&'a self, x: &'a [f64], first: usize) -> impl Iterator<Item = OVector<f64, S>> + 'a {
        let lengths = self.chain.lengths();
        let mut sum = OVector::<f64, S>::zeros();
        (0..self.links()).map(move |i| {
            let base = (first + i) * S::DIM;
            for k in 0..S::DIM {
                sum[k] += lengths[i] * x[base + k];
            }
            sum.clone()
        })
    }

    /// Kinetic energy relative to the pivot, `T = ½ Σ m_i |Σ_{j≤i} l_j w_j|²` (J).
    pub fn kinetic_energy(&self, x: &DVector<f64>) -> f64 {
        let masses = self.chain.masses();
        self.relative_velocities(x).iter().zip(masses.iter()).map(|(v, m)| 0.5 * m * v.norm_squared()).sum()
    }

    /// Potential energy relative to the pivot, `U = Σ m_i g (r_i − p)·e_up` (J).
    pub fn potential_energy(&self, x: &DVector<f64>) -> f64 {
        let (masses, g) = (self.chain.masses(), self.chain.gravity());
        self.relative_positions(x).iter().zip(masses.iter()).map(|(r, m)| m * g * r[S::DIM - 1]).sum()
    }

    /// `H = T + U` relative to the pivot (J): conserved when the pivot is at rest and
    /// there is no damping.
    pub fn energy(&self, x: &DVector<f64>) -> f64 {
        self.kinetic_energy(x) + self.potential_energy(x)
    }

    /// The worst violation of the rod constraints in `x`: `max_i max(||u_i| − 1|, |u_i·w_i| / max(|w_i|, 1))`.
    pub fn constraint_violation(&self, x: &DVector<f64>) -> f64 {
        (0..self.links())
            .map(|i| {
                let (u, w) = (self.direction(x, i), self.rate(x, i));
                (u.norm() - 1.0).abs().max(u.dot(&w).abs() / w.norm().max(1.0))
            })
            .fold(0.0, f64::max)
    }

    /// The accelerations `ü_i` (1/s²) and the rod tensions `T_i` (N) at `(t, x)`, written
    /// into `out` (`S·n` entries) and `tensions` (`n` entries).
    ///
    /// Errors: [`Error::LengthMismatch`] / [`Error::NonFinite`] for a bad state or
    /// buffers.
    pub fn accelerations(
        &self,
        t: f64,
        x: &DVector<f64>,
        out: &mut [f64],
        tensions: Option<&mut [f64]>,
    ) -> Result<()>
    where
        Dr: Drive<S>,
    {
        self.check_state(x)?;
        self.accelerations_of_valid(t, x.as_slice(), out, tensions)
    }

    /// [`accelerations`](Self::accelerations) for a state already checked.
    pub(crate) fn accelerations_of_valid(
        &self,
        t: f64,
        x: &[f64],
        out: &mut [f64],
        tensions: Option<&mut [f64]>,
    ) -> Result<()>
    where
        Dr: Drive<S>,
    {
        self.accelerations_at_pivot(&self.drive.acceleration(t), x, out, tensions)
    }

    /// [`accelerations_of_valid`](Self::accelerations_of_valid) with the pivot's
    /// acceleration `p̈` (m/s²) given.
    fn accelerations_at_pivot(
        &self,
        pivot: &OVector<f64, S>,
        x: &[f64],
        out: &mut [f64],
        tensions: Option<&mut [f64]>,
    ) -> Result<()> {
        let n = self.links();
        if out.len() != S::DIM * n {
            return Err(Error::LengthMismatch { what: "out", expected: S::DIM * n, got: out.len() });
        }
        if let Some(t) = &tensions
            && t.len() != n
        {
            return Err(Error::LengthMismatch { what: "tensions", expected: n, got: t.len() });
        }
        match S::DIM {
            2 => self.solve::<2>(x, [pivot[0], pivot[1]], out, tensions),
            3 => self.solve::<3>(x, [pivot[0], pivot[1], pivot[2]], out, tensions),
            d => return Err(Error::LengthMismatch { what: "space", expected: 3, got: d }),
        }
        Ok(())
    }

    /// [`System::rhs`] on slices, `out = (w, ü(t, x))`, for systems that hold the chain's
    /// state inside a longer one ([`Accounted`](crate::energy::Accounted)).
    pub(crate) fn flow(&self, t: f64, x: &[f64], out: &mut [f64]) -> Result<()>
    where
        Dr: Drive<S>,
    {
        self.flow_at_pivot(&self.drive.acceleration(t), x, out)
    }

    /// [`flow`](Self::flow) with the pivot's acceleration `p̈` (m/s²) given.
    pub(crate) fn flow_at_pivot(&self, pivot: &OVector<f64, S>, x: &[f64], out: &mut [f64]) -> Result<()> {
        let half = S::DIM * self.links();
        if out.len() != 2 * half {
            return Err(Error::LengthMismatch { what: "out", expected: 2 * half, got: out.len() });
        }
        self.check_state_slice(x)?;
        let (velocity, acceleration) = out.split_at_mut(half);
        velocity.copy_from_slice(&x[half..]);
        self.accelerations_at_pivot(pivot, x, acceleration, None)
    }

    /// The tension solve for `C`-dimensional space (`C = S::DIM`).
    fn solve<const C: usize>(
        &self,
        x: &[f64],
        pivot: [f64; C],
        out: &mut [f64],
        tensions: Option<&mut [f64]>,
    ) {
        let n = self.links();
        let drag = self.rods.drag();
        let mut gravity = [0.0; C];
        gravity[C - 1] = -self.chain.gravity();
        let (directions, rates) = x.split_at(C * n);
        let mut tensions = tensions;
        with_scratch::<C, _>(n, |s| {
            // Built where the solve asks, twice per rod (`Rods::solve`): a few products,
            // cheaper than the spills of carrying it (measured: the call got faster).
            let load = |i: usize| {
                let (mut u, mut w) = ([0.0; C], [0.0; C]);
                u.copy_from_slice(&directions[i * C..(i + 1) * C]);
                w.copy_from_slice(&rates[i * C..(i + 1) * C]);
                rate_load(u, w, drag[i])
            };
            self.rods.solve(gravity, pivot, &mut s.rows, load, |i, a, _, t| {
                out[i * C..(i + 1) * C].copy_from_slice(&a);
                if let Some(tensions) = tensions.as_deref_mut() {
                    tensions[i] = t;
                }
            });
        });
    }
}

/// Rod `i`'s [`Load`] from its direction `u_i`, rate `w_i` (1/s) and drag `λ_i / l_i` (N·s):
/// `|u̇_i|² = |w_i|²` and the damping's force pair `F_i = −(λ_i / l_i) w_i`.
#[inline(always)]
pub(crate) fn rate_load<const C: usize, V: Lane>(u: [V; C], w: [V; C], drag: V) -> Load<C, V> {
    let pull = -drag;
    let zero = V::splat(0.0);
    let mut load = Load { direction: [zero; C], rate_squared: zero, pair: [zero; C] };
    for k in 0..C {
        load.direction[k] = u[k];
        load.pair[k] = pull * w[k];
        load.rate_squared += w[k] * w[k];
    }
    load
}

impl<S: DimName, Dr: Drive<S>> Directions<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    /// Positions of the masses in the inertial frame, `p(t) + Σ_{j≤i} l_j u_j` (m).
    pub fn positions(&self, t: f64, x: &DVector<f64>) -> Vec<OVector<f64, S>> {
        let p = self.drive.position(t);
        self.relative_positions(x).into_iter().map(|r| r + &p).collect()
    }

    /// The inertial-frame energy `H = ½ Σ m_i |ṗ + v_i|² + Σ m_i g (p + r_i)·e_up` (J) of a
    /// driven chain (`v_i`, `r_i` relative to the pivot).
    pub fn inertial_energy(&self, t: f64, x: &DVector<f64>) -> f64 {
        self.inertial_energy_of(t, x.as_slice())
    }

    /// [`inertial_energy`](Self::inertial_energy) of a state held as a slice, without an
    /// array (an energy is taken at every sample of a whirl).
    pub(crate) fn inertial_energy_of(&self, t: f64, x: &[f64]) -> f64 {
        let (masses, g) = (self.chain.masses(), self.chain.gravity());
        let (p, pd) = self.drive.position_and_velocity(t);
        let kinetic: f64 = self
            .running_sums(x, self.links())
            .zip(masses.iter())
            .map(|(v, m)| 0.5 * m * (v + &pd).norm_squared())
            .sum();
        let height = p[S::DIM - 1];
        kinetic
            + self
                .running_sums(x, 0)
                .zip(masses.iter())
                .map(|(r, m)| m * g * (height + r[S::DIM - 1]))
                .sum::<f64>()
    }
}

impl<Dr> Directions<U2, Dr> {
    /// The state of planar angles `θ_i` (rad, from the downward vertical) and rates `θ̇_i`
    /// (rad/s): `u_i = (sin θ_i, −cos θ_i)`, `w_i = θ̇_i (cos θ_i, sin θ_i)`.
    ///
    /// Errors: [`Error::LengthMismatch`], [`Error::NonFinite`].
    pub fn from_angles(&self, theta: &[f64], rates: &[f64]) -> Result<DVector<f64>> {
        let n = self.links();
        check_vector("theta", theta, n)?;
        check_vector("rates", rates, n)?;
        let mut x = DVector::zeros(4 * n);
        for i in 0..n {
            x.fixed_rows_mut::<2>(2 * i).copy_from(&PlanarAngles::direction(theta, i));
            x.fixed_rows_mut::<2>(2 * (n + i)).copy_from(&PlanarAngles::link_velocity(theta, rates, i));
        }
        Ok(x)
    }

    /// The angle accelerations `θ̈_i = n_i · ü_i` (rad/s²; `n_i = (cos θ_i, sin θ_i)`,
    /// since `ü_i = θ̈_i n_i − θ̇_i² u_i`) at `(t, x)`: what [`Planar`](crate::models::Planar)
    /// computes, by the O(n) route.
    pub fn angle_accelerations(&self, t: f64, x: &DVector<f64>) -> Result<DVector<f64>>
    where
        Dr: Drive<U2>,
    {
        let n = self.links();
        let mut udd = vec![0.0; 2 * n];
        self.accelerations(t, x, &mut udd, None)?;
        Ok(DVector::from_fn(n, |i, _| {
            PlanarAngles::angle_acceleration([x[2 * i], x[2 * i + 1]], [udd[2 * i], udd[2 * i + 1]])
        }))
    }

    /// The angles `θ_i = atan2(u_x, −u_y)` (rad, in (−π, π]) and rates `θ̇_i = n_i·w_i`
    /// (rad/s) of a planar state.
    pub fn to_angles(&self, x: &DVector<f64>) -> Result<(DVector<f64>, DVector<f64>)> {
        self.check_state(x)?;
        let n = self.links();
        let (mut theta, mut rates) = (DVector::zeros(n), DVector::zeros(n));
        for i in 0..n {
            let w = [x[2 * (n + i)], x[2 * (n + i) + 1]];
            (theta[i], rates[i]) = PlanarAngles::from_direction([x[2 * i], x[2 * i + 1]], w);
        }
        Ok((theta, rates))
    }
}

impl<Dr> Directions<U3, Dr> {
    /// The state of spherical angles `q = (θ_1 … θ_n, φ_1 … φ_n)` (rad; `θ` from −z, `φ`
    /// azimuth from +x, eqs 27–29) and rates `q̇` (rad/s):
    /// `u = (sin θ cos φ, sin θ sin φ, −cos θ)`, `w = θ̇ e_θ + φ̇ sin θ e_φ` with
    /// `e_θ = (cos θ cos φ, cos θ sin φ, sin θ)` and `e_φ = (−sin φ, cos φ, 0)`. Any angles
    /// are fine here, `θ = 0` included.
    ///
    /// Errors: [`Error::LengthMismatch`], [`Error::NonFinite`].
    pub fn from_spherical(&self, q: &[f64], qd: &[f64]) -> Result<DVector<f64>> {
        let n = self.links();
        check_vector("q", q, 2 * n)?;
        check_vector("qd", qd, 2 * n)?;
        let mut x = DVector::zeros(6 * n);
        for i in 0..n {
            let link = SphericalLink::of(q, i);
            x.fixed_rows_mut::<3>(3 * i).copy_from(&link.u);
            x.fixed_rows_mut::<3>(3 * (n + i)).copy_from(&link.velocity(qd[i], qd[n + i]));
        }
        Ok(x)
    }

    /// The spherical angles and rates of a state (inverse of
    /// [`from_spherical`](Self::from_spherical)), `θ ∈ [0, π]`, `φ ∈ (−π, π]`.
    ///
    /// Errors: [`Error::SingularAngle`] for a link within
    /// [`SINGULARITY_TOLERANCE`](crate::kinematics::SINGULARITY_TOLERANCE) of the vertical, where `φ`
    /// is undefined; a bad state.
    pub fn to_spherical(&self, x: &DVector<f64>) -> Result<(DVector<f64>, DVector<f64>)> {
        self.check_state(x)?;
        let n = self.links();
        let (mut q, mut qd) = (DVector::zeros(2 * n), DVector::zeros(2 * n));
        for i in 0..n {
            let (theta, phi) = SphericalAngles::angles_of(&self.direction(x, i));
            let link = SphericalLink::new(theta, phi);
            check_polar_sin(i + 1, theta, link.sin_theta)?;
            q[i] = theta;
            q[n + i] = phi;
            (qd[i], qd[n + i]) = link.rates(&self.rate(x, i));
        }
        Ok((q, qd))
    }
}

impl<Dr: Drive<U3>> Directions<U3, Dr> {
    /// The spherical accelerations `q̈ = (θ̈_1 … θ̈_n, φ̈_1 … φ̈_n)` (rad/s²) at time `t`
    /// and spherical angles `q`, rates `q̇` (rad, rad/s),
    /// from the direction accelerations `ü_i` of the tension solve:
    /// ```text
    /// θ̈ = e_θ·ü + φ̇² sin θ cos θ,   φ̈ = (e_φ·ü − 2 θ̇ φ̇ cos θ) / sin θ
    /// ```
    /// (differentiate `u̇ = θ̇ e_θ + φ̇ sin θ e_φ` once more). What the spherical model
    /// [`Spatial`](crate::models::Spatial) computes, by an O(n) route; `cargo xtask verify`
    /// checks it against the sympy reference.
    ///
    /// The angles may be any (negative `θ` included) except at the vertical.
    ///
    /// Errors: [`Error::SingularAngle`] for `|sin θ_i|` below
    /// [`SINGULARITY_TOLERANCE`](crate::kinematics::SINGULARITY_TOLERANCE); those of
    /// [`from_spherical`](Self::from_spherical).
    pub fn spherical_accelerations(&self, t: f64, q: &[f64], qd: &[f64]) -> Result<DVector<f64>> {
        let x = self.from_spherical(q, qd)?;
        let n = self.links();
        let mut udd = vec![0.0; 3 * n];
        self.accelerations_of_valid(t, x.as_slice(), &mut udd, None)?;
        let mut out = DVector::zeros(2 * n);
        for i in 0..n {
            let link = SphericalLink::of(q, i);
            check_polar_sin(i + 1, q[i], link.sin_theta)?;
            let a = nalgebra::Vector3::new(udd[3 * i], udd[3 * i + 1], udd[3 * i + 2]);
            (out[i], out[n + i]) = link.angle_accelerations(&a, qd[i], qd[n + i]);
        }
        Ok(out)
    }
}

impl<S: DimName, Dr: Drive<S>> System for Directions<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    type Dim = Dyn;

    fn dim(&self) -> Dyn {
        Dyn(self.state_len())
    }

    /// `x = (u, w)`, `u' = w`.
    fn second_order(&self) -> Option<usize> {
        Some(S::DIM * self.links())
    }

    /// `x' = (w, ü(t, x))`: one O(n) tension solve.
    fn rhs(&self, t: f64, x: &DVector<f64>, out: &mut DVector<f64>) -> Result<()> {
        self.flow(t, x.as_slice(), out.as_mut_slice())
    }

    /// `[[0, I], [∂ü/∂u, ∂ü/∂w]]` from the tangents of the solve
    /// ([`analytic_jacobian`](Self::analytic_jacobian)), not by differences.
    fn jacobian(&self, t: f64, x: &DVector<f64>, out: &mut nalgebra::DMatrix<f64>) -> Result<()> {
        self.analytic_jacobian(t, x, out)
    }
}

impl<S: DimName, Dr: Drive<S>> Constrained for Directions<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    /// Normalises each `u_i` and removes the part of `w_i` along it:
    /// `u_i ← u_i/|u_i|`, `w_i ← w_i − (u_i·w_i) u_i` (the nearest point of the constraint
    /// manifold `|u_i| = 1, u_i·w_i = 0`, link by link).
    fn project(&self, x: &mut DVector<f64>) {
        self.project_slice(x.as_mut_slice());
    }
}

impl<S: DimName, Dr> Directions<S, Dr> {
    /// [`Constrained::project`] on a slice (a state of the wrong length is left alone).
    pub(crate) fn project_slice(&self, x: &mut [f64]) {
        let (n, d) = (self.chain.links(), S::DIM);
        if x.len() != 2 * d * n {
            return;
        }
        let (directions, rates) = x.split_at_mut(d * n);
        for (u, w) in directions.chunks_exact_mut(d).zip(rates.chunks_exact_mut(d)) {
            project_link(u, w);
        }
    }
}

/// One link of [`Constrained::project`]: `u ← u/|u|`, `w ← w − (u·w) u` (`u`, `w` of the same
/// length, at least 1).
#[inline(always)]
pub(crate) fn project_link<V: Lane>(u: &mut [V], w: &mut [V]) {
    let mut norm = u[0] * u[0];
    for v in &u[1..] {
        norm += *v * *v;
    }
    let norm = norm.sqrt();
    for v in u.iter_mut() {
        *v = *v / norm;
    }
    let mut radial = u[0] * w[0];
    for (a, b) in u[1..].iter().zip(&w[1..]) {
        radial += *a * *b;
    }
    for (b, a) in w.iter_mut().zip(u.iter()) {
        *b -= radial * *a;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn planar_state_round_trips_through_angles() {
        let model = Directions::<U2>::new(Chain::uniform(3, 1.0, 0.5, 9.81).unwrap());
        let (theta, rates) = ([0.3, -2.0, 3.0], [1.0, -0.5, 2.0]);
        let x = model.from_angles(&theta, &rates).unwrap();
        let (t2, r2) = model.to_angles(&x).unwrap();
        assert_relative_eq!(t2.as_slice(), &theta[..], epsilon = 1e-15);
        assert_relative_eq!(r2.as_slice(), &rates[..], epsilon = 1e-15);
    }

    #[test]
    fn hanging_chain_stays_at_rest_with_no_singularity() {
        let model = Directions::<U3>::new(Chain::uniform(4, 1.0, 0.5, 9.81).unwrap());
        let x = model.hanging();
        let mut f = DVector::zeros(x.len());
        model.rhs(0.0, &x, &mut f).unwrap();
        assert!(f.amax() < 1e-13, "{f}");
        assert!(matches!(model.to_spherical(&x), Err(Error::SingularAngle { link: 1, .. })));
    }

    #[test]
    fn projection_restores_unit_directions_and_tangent_rates() {
        let model = Directions::<U3>::new(Chain::uniform(2, 1.0, 0.5, 9.81).unwrap());
        let mut x = model.from_spherical(&[0.5, 1.0, 0.2, -1.0], &[1.0, 2.0, -3.0, 0.5]).unwrap();
        x.iter_mut().enumerate().for_each(|(i, v)| *v *= 1.0 + 1e-3 * (i as f64 + 1.0));
        assert!(model.constraint_violation(&x) > 1e-3);
        model.project(&mut x);
        assert!(model.constraint_violation(&x) < 1e-15);
    }

    #[test]
    fn bad_states_are_errors() {
        let model = Directions::<U2>::new(Chain::uniform(2, 1.0, 0.5, 9.81).unwrap());
        let mut f = DVector::zeros(8);
        let err = model.rhs(0.0, &DVector::zeros(6), &mut f).unwrap_err();
        assert_eq!(err, Error::LengthMismatch { what: "x", expected: 8, got: 6 });
        let mut x = model.hanging();
        x[5] = f64::NAN;
        assert!(matches!(model.rhs(0.0, &x, &mut f), Err(Error::NonFinite { what: "x", index: 5, .. })));
        assert!(matches!(
            model.from_angles(&[0.0], &[0.0, 1.0]),
            Err(Error::LengthMismatch { what: "theta", .. })
        ));
    }
}
