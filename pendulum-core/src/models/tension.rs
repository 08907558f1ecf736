//! The planar chain in angle coordinates with O(n) accelerations by the rod tensions.

use nalgebra::{DefaultAllocator, Dim, Dyn, OMatrix, OVector, U2, allocator::Allocator};

use crate::chain::Chain;
use crate::error::Result;
use crate::jacobians::{Derivatives, Jacobians, Parts};
use crate::kinematics::trig::sin_cos_into;
use crate::kinematics::{Chart, PlanarAngles};
use crate::lanes::Lane;
use crate::model::all_finite;
use crate::model::{Inputs, Model, ModelAlloc, check_inputs};
use crate::models::planar::Planar;
use crate::rods::{Load, PlanarTangents, RodConstants, Rods, damping_pull, pull, with_scratch};

/// A planar chain in absolute link angles, exactly [`Planar`] except for
/// [`accelerations`](Model::accelerations), which solve the rod tensions (a symmetric
/// tridiagonal system, `rods` module docs) instead of factoring the mass matrix: O(n)
/// work and memory per evaluation instead of O(n³), for chains of any length.
///
/// With `u_i = (sin θ_i, −cos θ_i)` and `n_i = ∂u_i/∂θ_i = (cos θ_i, sin θ_i)`:
/// `|u̇_i|² = θ̇_i²`, the generalized force `Q_i = σ_i − λ_i θ̇_i` (eq 26) acts as the force
/// pair `F_i = (Q_i / l_i) n_i` on rod `i` (its virtual work `F_i·l_i n_i δθ_i = Q_i δθ_i`),
/// and `θ̈_i = n_i · ü_i` (since `ü_i = θ̈_i n_i − θ̇_i² u_i`). The `sin θ_i`, `cos θ_i` come
/// first, all at once, from a vectorised polynomial kernel (`trig` module docs: within
/// 1 ulp of `f64::sin_cos`, which it calls for `|θ_i| > 8192`), then the loads, then the
/// solve: three loops over the links.
///
/// Mass matrix, force terms and energies are [`Planar`]'s, so the model plugs into
/// [`FirstOrder`](crate::systems::FirstOrder), [`Canonical`](crate::systems::Canonical) and
/// [`Accounted`](crate::energy::Accounted) unchanged. Evaluations allocate nothing after the
/// first on a thread (the solve's buffers are per thread).
#[derive(Debug, Clone, PartialEq)]
pub struct PlanarTension<L: Dim = Dyn>
where
    DefaultAllocator: Allocator<L>,
{
    dense: Planar<L>,
    rods: Rods,
}

impl<L: Dim> PlanarTension<L>
where
    DefaultAllocator: Allocator<L>,
{
    /// The O(n) planar model of `chain`.
    pub fn new(chain: Chain<L>) -> Self {
        let rods =
            Rods::new(chain.masses().as_slice(), chain.lengths().as_slice(), chain.damping().as_slice());
        Self { dense: Planar::new(chain), rods }
    }

    /// The tension solve's constants.
    pub(crate) fn rods(&self) -> &Rods {
        &self.rods
    }

    /// The same chain as a dense [`Planar`] model.
    pub fn dense(&self) -> &Planar<L> {
        &self.dense
    }

    /// Accelerations (rad/s²) like [`Model::accelerations`], and the rod tensions `T_i` (N,
    /// positive when the rod pulls) written into `tensions` (`n` entries).
    pub fn accelerations_and_tensions(
        &self,
        q: &OVector<f64, L>,
        qd: &OVector<f64, L>,
        inputs: &Inputs<L, U2>,
        out: &mut OVector<f64, L>,
        tensions: &mut [f64],
    ) -> Result<()>
    where
        DefaultAllocator: Allocator<L, L> + Allocator<U2>,
    {
        self.solve(q, qd, inputs, out, Some(tensions))
    }

    fn solve(
        &self,
        q: &OVector<f64, L>,
        qd: &OVector<f64, L>,
        inputs: &Inputs<L, U2>,
        out: &mut OVector<f64, L>,
        tensions: Option<&mut [f64]>,
    ) -> Result<()>
    where
        DefaultAllocator: Allocator<L, L> + Allocator<U2>,
    {
        let chain = self.dense.chain();
        let n = chain.links();
        check_inputs(n, q, qd, inputs)?;
        if out.len() != n {
            return Err(crate::error::Error::LengthMismatch { what: "out", expected: n, got: out.len() });
        }
        if let Some(t) = &tensions
            && t.len() != n
        {
            return Err(crate::error::Error::LengthMismatch { what: "tensions", expected: n, got: t.len() });
        }
        let (inverse_length, drag) = (self.rods.inverse_length(), self.rods.drag());
        let gravity = [0.0, -chain.gravity()];
        let pivot = [inputs.pivot_acceleration[0], inputs.pivot_acceleration[1]];
        let mut tensions = tensions;
        with_scratch::<2, _>(n, |s| {
            // The trigonometry in a vectorised loop of its own, before the solve. The loads
            // too: built inside the solve (bounds checks and all), the builder was not
            // inlined and cost a call per link.
            let (sin_cos, loads, rows) = s.staging(n);
            sin_cos_into(q.as_slice(), sin_cos);
            let (qd, torque) = (&qd.as_slice()[..n], &inputs.torque.as_slice()[..n]);
            let build = |[sin, cos]: [f64; 2], rate: f64, pull: f64| planar_load(sin, cos, rate, pull);
            // Without torques (the common case) the pull is the damping's alone.
            if all_zero(torque) {
                for (i, (load, &trig)) in loads.iter_mut().zip(&*sin_cos).enumerate() {
                    *load = build(trig, qd[i], damping_pull(drag[i], qd[i]));
                }
            } else {
                for (i, (load, &trig)) in loads.iter_mut().zip(&*sin_cos).enumerate() {
                    *load = build(trig, qd[i], pull(torque[i], inverse_length[i], drag[i], qd[i]));
                }
            }
            let loads = &*loads;
            let load = |i: usize| loads[i];
            self.rods.solve(gravity, pivot, rows, load, |i, a, u, t| {
                out[i] = angle_acceleration(a, u);
                if let Some(tensions) = tensions.as_deref_mut() {
                    tensions[i] = t;
                }
            });
        });
        if all_finite(out.as_slice()) { Ok(()) } else { Err(crate::error::Error::NonFiniteAccelerations) }
    }
}

/// Rod `i`'s [`Load`] in the planar chain at angle `θ_i` (from its `sin`, `cos`), rate `θ̇_i`
/// (rad/s) and `pull = Q_i / l_i` (N): `u_i = (sin θ_i, −cos θ_i)`, `|u̇_i|² = θ̇_i²`,
/// `F_i = pull · n_i` with `n_i = (cos θ_i, sin θ_i)`.
#[inline(always)]
pub(crate) fn planar_load<V: Lane>(sin: V, cos: V, rate: V, pull: V) -> Load<2, V> {
    Load { direction: [sin, -cos], rate_squared: rate * rate, pair: [pull * cos, pull * sin] }
}

/// `θ̈_i = n_i · ü_i` (rad/s²) from `ü_i` and `u_i`, with `n_i = (cos θ_i, sin θ_i) = (−u_y, u_x)`.
#[inline(always)]
pub(crate) fn angle_acceleration<V: Lane>([ax, ay]: [V; 2], &[ux, uy]: &[V; 2]) -> V {
    -uy * ax + ux * ay
}

/// Whether every entry of `v` is zero (no early exit, so that it vectorises).
fn all_zero(v: &[f64]) -> bool {
    v.iter().fold(true, |zero, x| zero & (*x == 0.0))
}

impl<L: Dim> PlanarTension<L>
where
    DefaultAllocator: Allocator<L> + Allocator<L, L> + Allocator<U2>,
{
    /// The solve at `(q, q̇, inputs)` kept for its tangents ([`PlanarTangents`]): O(n).
    ///
    /// Errors: [`crate::error::Error::LengthMismatch`] or [`crate::error::Error::NonFinite`]
    /// for bad inputs, [`crate::error::Error::NonFiniteAccelerations`] for a non-finite result.
    pub fn tangents(
        &self,
        q: &OVector<f64, L>,
        qd: &OVector<f64, L>,
        inputs: &Inputs<L, U2>,
    ) -> Result<PlanarTangents<'_, L>> {
        let chain = self.dense.chain();
        check_inputs(chain.links(), q, qd, inputs)?;
        let tangents = PlanarTangents::new(self.rods.constants(), chain.gravity(), q, qd, inputs);
        if tangents.accelerations().all(f64::is_finite) {
            Ok(tangents)
        } else {
            Err(crate::error::Error::NonFiniteAccelerations)
        }
    }
}

/// `θ̈` and its Jacobians (`parts`) for a planar chain of these rods by the kept tension
/// solve ([`PlanarTangents`]: O(n) solve, O(n²) Jacobians, fixed sizes on the stack): the
/// [`Derivatives::acceleration_jacobians`] and [`Derivatives::state_jacobians`] of
/// [`PlanarTension`] and of the generated planar models that take the tension route.
///
/// Errors: [`crate::error::Error::LengthMismatch`] or [`crate::error::Error::NonFinite`]
/// for bad inputs, [`crate::error::Error::NonFiniteAccelerations`] for a non-finite result.
pub fn planar_tension_jacobians<M, L>(
    model: &M,
    rods: RodConstants<'_>,
    q: &OVector<f64, L>,
    qd: &OVector<f64, L>,
    inputs: &Inputs<L, U2>,
    out: &mut Jacobians<M>,
    parts: Parts,
) -> Result<()>
where
    L: Dim,
    M: Model<Dof = L, Space = U2> + ?Sized,
    DefaultAllocator: ModelAlloc<M::Links, L, U2> + Allocator<L, U2>,
{
    let dim = model.dof();
    let n = dim.value();
    // Sizes first (a fixed-size model's always match); finiteness only on failure.
    if q.len() != n || qd.len() != n || inputs.torque.len() != n {
        check_inputs(n, q, qd, inputs)?;
    }
    let gravity = model.chain().gravity();
    #[cfg(target_arch = "x86_64")]
    let finite = if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2, checked just above.
        unsafe { solve_and_differentiate_avx2(rods, gravity, q, qd, inputs, out, parts) }
    } else {
        solve_and_differentiate(rods, gravity, q, qd, inputs, out, parts)
    };
    #[cfg(not(target_arch = "x86_64"))]
    let finite = solve_and_differentiate(rods, gravity, q, qd, inputs, out, parts);
    if !finite {
        check_inputs(n, q, qd, inputs)?;
        return Err(crate::error::Error::NonFiniteAccelerations);
    }
    Ok(())
}

/// The body of [`planar_tension_jacobians`] after its size checks: the kept solve, `θ̈`
/// into `out`, and, if `θ̈` is finite (the return value), the Jacobians `parts`.
#[inline(always)]
fn solve_and_differentiate<M, L>(
    rods: RodConstants<'_>,
    gravity: f64,
    q: &OVector<f64, L>,
    qd: &OVector<f64, L>,
    inputs: &Inputs<L, U2>,
    out: &mut Jacobians<M>,
    parts: Parts,
) -> bool
where
    L: Dim,
    M: Model<Dof = L, Space = U2> + ?Sized,
    DefaultAllocator: ModelAlloc<M::Links, L, U2> + Allocator<L, U2>,
{
    let tangents = PlanarTangents::new(rods, gravity, q, qd, inputs);
    for (o, a) in out.accelerations.iter_mut().zip(tangents.accelerations()) {
        *o = a;
    }
    if !all_finite(out.accelerations.as_slice()) {
        return false;
    }
    let (dq, dqd) = (out.q.as_mut_slice(), out.qd.as_mut_slice());
    match parts {
        Parts::All => tangents.jacobians(dq, dqd, out.torque.as_mut_slice(), out.pivot.as_mut_slice()),
        Parts::State => tangents.state_jacobians(dq, dqd),
    }
    true
}

/// [`solve_and_differentiate`] compiled for AVX2: four lanes instead of two in the O(n²)
/// part, the same operations (no fused multiply-adds), so the same results.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn solve_and_differentiate_avx2<M, L>(
    rods: RodConstants<'_>,
    gravity: f64,
    q: &OVector<f64, L>,
    qd: &OVector<f64, L>,
    inputs: &Inputs<L, U2>,
    out: &mut Jacobians<M>,
    parts: Parts,
) -> bool
where
    L: Dim,
    M: Model<Dof = L, Space = U2> + ?Sized,
    DefaultAllocator: ModelAlloc<M::Links, L, U2> + Allocator<L, U2>,
{
    solve_and_differentiate(rods, gravity, q, qd, inputs, out, parts)
}

/// The dense building blocks are [`Planar`]'s; the Jacobians come from the kept O(n) solve
/// instead ([`PlanarTangents`]): O(n²) in all.
impl<L: Dim> Derivatives for PlanarTension<L>
where
    DefaultAllocator: Allocator<L> + Allocator<L, L> + Allocator<U2> + Allocator<L, U2>,
{
    fn mass_matrix_partials(&self, q: &OVector<f64, L>, v: &OVector<f64, L>, out: &mut OMatrix<f64, L, L>) {
        self.dense.mass_matrix_partials(q, v, out)
    }

    fn force_jacobians(
        &self,
        q: &OVector<f64, L>,
        qd: &OVector<f64, L>,
        inputs: &Inputs<L, U2>,
        dq: &mut OMatrix<f64, L, L>,
        dqd: &mut OMatrix<f64, L, L>,
        dp: &mut OMatrix<f64, L, U2>,
    ) {
        self.dense.force_jacobians(q, qd, inputs, dq, dqd, dp)
    }

    /// Every column at once from the kept solve ([`planar_tension_jacobians`]).
    fn acceleration_jacobians(
        &self,
        q: &OVector<f64, L>,
        qd: &OVector<f64, L>,
        inputs: &Inputs<L, U2>,
        out: &mut Jacobians<Self>,
    ) -> Result<()> {
        planar_tension_jacobians(self, self.rods.constants(), q, qd, inputs, out, Parts::All)
    }

    /// `∂θ̈/∂θ`, `∂θ̈/∂θ̇` alone from the kept solve ([`planar_tension_jacobians`]).
    fn state_jacobians(
        &self,
        q: &OVector<f64, L>,
        qd: &OVector<f64, L>,
        inputs: &Inputs<L, U2>,
        out: &mut Jacobians<Self>,
    ) -> Result<()> {
        planar_tension_jacobians(self, self.rods.constants(), q, qd, inputs, out, Parts::State)
    }
}

impl<L: Dim> From<Chain<L>> for PlanarTension<L>
where
    DefaultAllocator: Allocator<L>,
{
    fn from(chain: Chain<L>) -> Self {
        Self::new(chain)
    }
}

impl<L: Dim> Model for PlanarTension<L>
where
    DefaultAllocator: Allocator<L> + Allocator<L, L> + Allocator<U2>,
{
    type Links = L;
    type Dof = L;
    type Space = U2;
    type Chart = PlanarAngles;

    fn chain(&self) -> &Chain<L> {
        self.dense.chain()
    }

    fn dof(&self) -> L {
        self.dense.dof()
    }

    fn mass_matrix(&self, q: &OVector<f64, L>, out: &mut OMatrix<f64, L, L>) {
        self.dense.mass_matrix(q, out)
    }

    fn velocity_terms(&self, q: &OVector<f64, L>, qd: &OVector<f64, L>, out: &mut OVector<f64, L>) {
        self.dense.velocity_terms(q, qd, out)
    }

    fn gravity_terms(&self, q: &OVector<f64, L>, out: &mut OVector<f64, L>) {
        self.dense.gravity_terms(q, out)
    }

    fn pivot_terms(&self, q: &OVector<f64, L>, a: &OVector<f64, U2>, out: &mut OVector<f64, L>) {
        self.dense.pivot_terms(q, a, out)
    }

    fn generalized_forces(
        &self,
        q: &OVector<f64, L>,
        qd: &OVector<f64, L>,
        torque: &OVector<f64, L>,
        out: &mut OVector<f64, L>,
    ) {
        self.dense.generalized_forces(q, qd, torque, out)
    }

    /// `T = ½ Σ_k m_k |v_k|²` by the chart's O(n) sum (the dense model's eq 11 is O(n²)).
    fn kinetic_energy(&self, q: &OVector<f64, L>, qd: &OVector<f64, L>) -> f64 {
        PlanarAngles::kinetic_energy(self.chain(), q.as_slice(), qd.as_slice())
    }

    fn potential_energy(&self, q: &OVector<f64, L>) -> f64 {
        self.dense.potential_energy(q)
    }

    /// `θ̈` by the O(n) tension solve (type docs). Errors: [`crate::error::Error::LengthMismatch`]
    /// or [`crate::error::Error::NonFinite`] for bad inputs.
    fn accelerations(
        &self,
        q: &OVector<f64, L>,
        qd: &OVector<f64, L>,
        inputs: &Inputs<L, U2>,
        out: &mut OVector<f64, L>,
    ) -> Result<()> {
        self.solve(q, qd, inputs, out, None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{DMatrix, DVector, Vector2};

    #[test]
    fn triple_pendulum_matches_the_dense_route() {
        let chain = Chain::<Dyn>::new(&[1.0, 0.3, 2.0], &[0.7, 1.2, 0.4], 9.81)
            .unwrap()
            .with_damping(&[0.1, 0.0, 0.3])
            .unwrap();
        let fast = PlanarTension::new(chain);
        let q = DVector::from_vec(vec![0.4, -2.0, 2.9]);
        let qd = DVector::from_vec(vec![1.1, -0.3, 4.0]);
        let inputs = Inputs {
            torque: DVector::from_vec(vec![0.5, -1.0, 0.2]),
            pivot_acceleration: Vector2::new(3.0, -1.5),
        };
        let (mut a, mut b) = (DVector::zeros(3), DVector::zeros(3));
        fast.accelerations(&q, &qd, &inputs, &mut a).unwrap();
        fast.dense().accelerations(&q, &qd, &inputs, &mut b).unwrap();
        assert_relative_eq!(a, b, epsilon = 1e-12, max_relative = 1e-12);
    }

    /// The O(n) kinetic energy (sum over masses) equals the dense double sum (eq 11).
    #[test]
    fn kinetic_energy_matches_the_dense_double_sum() {
        let chain = Chain::<Dyn>::new(&[1.0, 0.3, 2.0, 0.6, 1.7], &[0.7, 1.2, 0.4, 0.9, 0.3], 9.81).unwrap();
        let fast = PlanarTension::new(chain);
        let q = DVector::from_vec(vec![0.4, -2.0, 2.9, 1.0, -0.3]);
        let qd = DVector::from_vec(vec![1.1, -0.3, 4.0, -2.2, 0.8]);
        let (t, dense) = (fast.kinetic_energy(&q, &qd), fast.dense().kinetic_energy(&q, &qd));
        assert!(dense > 1.0 && (t - dense).abs() < 1e-14 * dense, "{t} vs {dense}");
    }

    #[test]
    fn with_and_without_torques_match_the_dense_route() {
        // Zero torques take the damping-only loop; one non-zero torque among zeros must not.
        let n = 40;
        let masses: Vec<f64> = (0..n).map(|i| 0.5 + (i as f64 * 0.37).sin().abs()).collect();
        let lengths: Vec<f64> = (0..n).map(|i| 0.2 + (i as f64 * 0.71).cos().abs()).collect();
        let chain = Chain::<Dyn>::new(&masses, &lengths, 9.81).unwrap().with_damping(&vec![0.05; n]).unwrap();
        let fast = PlanarTension::new(chain);
        let q = DVector::from_fn(n, |i, _| 0.3 + (i as f64 * 0.77) % 2.5);
        let qd = DVector::from_fn(n, |i, _| (i as f64 * 1.3).sin() * 3.0);
        let mut inputs = fast.zero_inputs();
        for torque in [0.0, 0.7] {
            inputs.torque[n / 2] = torque;
            let (mut a, mut b) = (DVector::zeros(n), DVector::zeros(n));
            fast.accelerations(&q, &qd, &inputs, &mut a).unwrap();
            fast.dense().accelerations(&q, &qd, &inputs, &mut b).unwrap();
            assert_relative_eq!(a, b, epsilon = 1e-10, max_relative = 1e-10);
        }
    }

    #[test]
    fn the_tangents_agree_with_the_dense_jacobians() {
        for n in [1, 2, 3, 12] {
            jacobians_agree_with_the_dense_route(n);
        }
    }

    fn jacobians_agree_with_the_dense_route(n: usize) {
        let masses: Vec<f64> = (0..n).map(|i| 0.5 + (i as f64 * 0.37).sin().abs()).collect();
        let lengths: Vec<f64> = (0..n).map(|i| 0.2 + (i as f64 * 0.71).cos().abs()).collect();
        let chain = Chain::<Dyn>::new(&masses, &lengths, 9.81).unwrap().with_damping(&vec![0.05; n]).unwrap();
        let fast = PlanarTension::new(chain);
        let q = DVector::from_fn(n, |i, _| 0.3 + (i as f64 * 0.77) % 2.5);
        let qd = DVector::from_fn(n, |i, _| (i as f64 * 1.3).sin() * 3.0);
        let inputs = Inputs {
            torque: DVector::from_fn(n, |i, _| 0.1 * i as f64 - 0.4),
            pivot_acceleration: Vector2::new(1.5, -2.0),
        };
        let (mut a, mut b) = (Jacobians::zeros(&fast), Jacobians::zeros(fast.dense()));
        fast.acceleration_jacobians(&q, &qd, &inputs, &mut a).unwrap();
        fast.dense().acceleration_jacobians(&q, &qd, &inputs, &mut b).unwrap();
        for (x, y) in [(&a.q, &b.q), (&a.qd, &b.qd), (&a.torque, &b.torque)] {
            assert!((x - y).amax() < 1e-9 * y.amax(), "{x} {y}");
        }
        assert!((&a.pivot - &b.pivot).amax() < 1e-9 * b.pivot.amax());
        assert!((&a.accelerations - &b.accelerations).amax() < 1e-10 * b.accelerations.amax());
        // The JVP along every part at once is the dense Jacobians' product, twice from one
        // kept solve.
        let mut kept = fast.tangents(&q, &qd, &inputs).unwrap();
        for k in [1.0, -0.5] {
            let dq = DVector::from_fn(n, |i, _| k * (i as f64 * 0.9).cos());
            let dqd = DVector::from_fn(n, |i, _| k * (0.4 - (i as f64 * 0.3).sin()));
            let dtorque = DVector::from_fn(n, |i, _| k * (0.2 + 0.05 * i as f64));
            let dpivot = Vector2::new(0.7 * k, -1.1 * k);
            let mut jvp = vec![0.0; n];
            kept.jvp(dq.as_slice(), dqd.as_slice(), dtorque.as_slice(), [dpivot[0], dpivot[1]], &mut jvp);
            let product = &b.q * &dq + &b.qd * &dqd + &b.torque * &dtorque + &b.pivot * dpivot;
            let jvp = DVector::from_vec(jvp);
            assert!((&jvp - &product).amax() < 1e-9 * product.amax(), "n = {n}: {jvp} {product}");
        }
    }

    /// Masses of 1e-150 kg take the kept solve's continuants out of their range within two
    /// links; the classical pivots then give what the same chain at 1 kg gives (the motion
    /// without torques or damping does not depend on the masses' scale).
    #[test]
    fn the_kept_solve_falls_back_to_pivots_for_extreme_masses() {
        let (masses, lengths) = ([1.0, 3.0, 2.0, 1.0], [1.0, 0.5, 2.0, 1.0]);
        let tiny: Vec<f64> = masses.iter().map(|m| m * 1e-150).collect();
        let normal = PlanarTension::new(Chain::<Dyn>::new(&masses, &lengths, 9.81).unwrap());
        let extreme = PlanarTension::new(Chain::<Dyn>::new(&tiny, &lengths, 9.81).unwrap());
        let q = DVector::from_vec(vec![0.4, -1.3, 2.2, 0.9]);
        let qd = DVector::from_vec(vec![1.5, -0.7, 2.1, 0.3]);
        let inputs = Inputs { torque: DVector::zeros(4), pivot_acceleration: Vector2::new(0.8, -0.3) };
        let (mut a, mut b) = (Jacobians::zeros(&normal), Jacobians::zeros(&extreme));
        normal.acceleration_jacobians(&q, &qd, &inputs, &mut a).unwrap();
        extreme.acceleration_jacobians(&q, &qd, &inputs, &mut b).unwrap();
        let close = |x: &DMatrix<f64>, y: &DMatrix<f64>| (x - y).amax() < 1e-12 * y.amax();
        assert!(close(&b.q, &a.q) && close(&b.qd, &a.qd), "{} {}", b.q, a.q);
        assert!(close(&(&b.torque * 1e-150), &a.torque));
        assert!((&b.accelerations - &a.accelerations).amax() < 1e-12 * a.accelerations.amax());
        let mut direct = DVector::zeros(4);
        extreme.accelerations(&q, &qd, &inputs, &mut direct).unwrap();
        assert!((&b.accelerations - &direct).amax() < 1e-12 * direct.amax());
    }

    /// The AVX2 build of the Jacobians does the same operations in the same order: the
    /// same bits as the baseline build (where the CPU has AVX2 to compare).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn the_avx2_jacobians_are_the_baseline_ones_bit_for_bit() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let n = 9;
        let masses: Vec<f64> = (0..n).map(|i| 0.5 + (i as f64 * 0.37).sin().abs()).collect();
        let lengths: Vec<f64> = (0..n).map(|i| 0.2 + (i as f64 * 0.71).cos().abs()).collect();
        let chain = Chain::<Dyn>::new(&masses, &lengths, 9.81).unwrap().with_damping(&vec![0.05; n]).unwrap();
        let model = PlanarTension::new(chain);
        let q = DVector::from_fn(n, |i, _| 0.3 + (i as f64 * 0.77) % 2.5);
        let qd = DVector::from_fn(n, |i, _| (i as f64 * 1.3).sin() * 3.0);
        let inputs = Inputs {
            torque: DVector::from_fn(n, |i, _| 0.1 * i as f64 - 0.4),
            pivot_acceleration: Vector2::new(1.5, -2.0),
        };
        let (mut a, mut b) = (Jacobians::zeros(&model), Jacobians::zeros(&model));
        let (rods, g) = (model.rods.constants(), 9.81);
        assert!(solve_and_differentiate(rods, g, &q, &qd, &inputs, &mut a, Parts::All));
        // SAFETY: the CPU has AVX2, checked above.
        assert!(unsafe { solve_and_differentiate_avx2(rods, g, &q, &qd, &inputs, &mut b, Parts::All) });
        assert_eq!(a, b);
    }

    #[test]
    fn wrong_sizes_are_errors() {
        let fast = PlanarTension::new(Chain::<Dyn>::uniform(2, 1.0, 1.0, 9.81).unwrap());
        let mut out = DVector::zeros(3);
        let err = fast.accelerations(&DVector::zeros(2), &DVector::zeros(2), &fast.zero_inputs(), &mut out);
        assert_eq!(err, Err(crate::error::Error::LengthMismatch { what: "out", expected: 2, got: 3 }));
    }
}
