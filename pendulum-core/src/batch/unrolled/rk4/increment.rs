//! The increment of one RK4 step as [`Rk4`](crate::integrate::Rk4) rounds it, for lanes
//! of chains or for one chain.

use crate::integrate::rk4_weighted;
use crate::lanes::Lane;

/// `q̈(q, q̇)` for [`increment`]: a type of its own rather than a closure, for the lanes'
/// kernel must be inlined into its caller to run with the caller's target features, and a
/// closure called four times was compiled as a function of its own, without them (SSE2 in
/// the AVX2 run, half its time).
pub(super) trait Accelerations<V, const N: usize, const G: usize> {
    /// `q̈` (rad/s²) of `G` arrays of coordinates `q` (rad) and rates `qd` (rad/s).
    fn at(&mut self, q: &[[V; N]; G], qd: &[[V; N]; G]) -> [[V; N]; G];
}

/// Any closure `q̈(q, q̇)` (out of the hot path: a closure is compiled apart).
impl<V, const N: usize, const G: usize, F: FnMut(&[[V; N]; G], &[[V; N]; G]) -> [[V; N]; G]>
    Accelerations<V, N, G> for F
{
    fn at(&mut self, q: &[[V; N]; G], qd: &[[V; N]; G]) -> [[V; N]; G] {
        self(q, qd)
    }
}

/// The increment `h (k1 + 2 k2 + 2 k3 + k4) / 6` of one step of
/// [`Rk4`](crate::integrate::Rk4) from `(θ, θ̇)`, for the first-order system
/// `(θ, θ̇)' = (θ̇, θ̈)` with `θ̈ = accelerations(θ, θ̇)`, rounded as `Rk4` rounds it: lane by
/// lane (`V = Lanes`) or for one chain (`V = f64`), for `G` blocks at once.
#[inline(always)]
pub(super) fn increment<V: Lane, const N: usize, const G: usize>(
    q: &[[V; N]; G],
    qd: &[[V; N]; G],
    h: f64,
    mut accelerations: impl Accelerations<V, N, G>,
) -> ([[V; N]; G], [[V; N]; G]) {
    let (half, whole, sixth) = (V::splat(0.5 * h), V::splat(h), V::splat(h / 6.0));
    // k_s = (θ̇_s, θ̈_s), the stages of `Rk4::stages`.
    let a1 = accelerations.at(q, qd);
    let (q2, qd2) = (axpy(q, half, qd), axpy(qd, half, &a1));
    let a2 = accelerations.at(&q2, &qd2);
    let (q3, qd3) = (axpy(q, half, &qd2), axpy(qd, half, &a2));
    let a3 = accelerations.at(&q3, &qd3);
    let (q4, qd4) = (axpy(q, whole, &qd3), axpy(qd, whole, &a3));
    let a4 = accelerations.at(&q4, &qd4);
    (weighted_sum(sixth, [qd, &qd2, &qd3, &qd4]), weighted_sum(sixth, [&a1, &a2, &a3, &a4]))
}

/// `y = x + a k` as `Rk4`'s `axpy` rounds it, for `G` blocks. A function, not a closure
/// in [`increment`]: called six times, a closure was compiled apart, without the kernel's
/// target features (each lane operation a call, 0.23× the run).
#[inline(always)]
fn axpy<V: Lane, const N: usize, const G: usize>(x: &[[V; N]; G], a: V, k: &[[V; N]; G]) -> [[V; N]; G] {
    let mut y = *x;
    for (y, k) in y.iter_mut().zip(k) {
        for (y, &k) in y.iter_mut().zip(k) {
            *y = a * k + *y;
        }
    }
    y
}

/// `(h/6) (k1 + 2 (k2 + k3) + k4)` as `Rk4` rounds it ([`rk4_weighted`]), for `G` blocks
/// (`sixth` = h/6).
#[inline(always)]
fn weighted_sum<V: Lane, const N: usize, const G: usize>(
    sixth: V,
    [k1, k2, k3, k4]: [&[[V; N]; G]; 4],
) -> [[V; N]; G] {
    let mut out = *k1;
    for j in 0..G {
        for i in 0..N {
            out[j][i] = rk4_weighted(sixth, [k1[j][i], k2[j][i], k3[j][i], k4[j][i]]);
        }
    }
    out
}
