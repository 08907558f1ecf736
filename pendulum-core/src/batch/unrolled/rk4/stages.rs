//! Each kind's stages in lanes: the planar models' `θ̈` and the spatial models' `(θ̈, φ̈)`
//! of a group's blocks, with the spatial models' polar check; and a failed chain's own
//! step, for its error.

use nalgebra::{SVector, Vector2};

use super::increment::increment;
use super::{StageInputs, Stages, stage_times};
use crate::batch::unrolled::precision::{KernelLanes, Precision};
use crate::batch::unrolled::spatial::near_pole;
use crate::batch::unrolled::{
    GROUP, LinkConstants, PlanarKernel, SineRoom, SpatialKernel, UnrolledBatch, UnrolledSpatialBatch,
    unit_blocks,
};
use crate::error::{Error, Result};
use crate::model::Inputs;

impl<M: PlanarKernel<N>, const N: usize> Stages<N, GROUP> for UnrolledBatch<M, N> {
    #[inline(always)]
    fn at<P: Precision, V: KernelLanes<P>>(
        c: &[LinkConstants<V, N>; GROUP],
        count: usize,
        room: &mut SineRoom<P::Lanes, N, GROUP>,
        [q, qd]: [&[[V; N]; GROUP]; 2],
        inputs: StageInputs<'_, V, N, GROUP>,
    ) -> [[V; N]; GROUP] {
        let zero = V::splat(0.0);
        let units = count.div_ceil(V::BLOCKS);
        for (u, q) in q.iter().enumerate().take(units) {
            let [a, b] = unit_blocks(u, V::BLOCKS, count);
            for (i, q) in q.iter().enumerate() {
                [room.angles[a][i], room.angles[b][i]] = q.split();
            }
        }
        room.sin_cos::<P>(count);
        let mut out = [[zero; N]; GROUP];
        for u in 0..units {
            let mut trig = [[zero; 2]; N];
            room.trig(unit_blocks(u, V::BLOCKS, count), &mut trig);
            let (torque, [x, y, _]) = inputs.map_or(([zero; N], [zero; 3]), |(t, p)| (t[u], p[u]));
            out[u] = M::kernel(&c[u], &trig, &qd[u], &torque, [x, y]);
        }
        out
    }

    #[cold]
    fn step_error(
        &self,
        chain: usize,
        (t, x): (f64, &[f64]),
        h: f64,
        torque: &[f64],
        pivot: &dyn Fn(f64) -> [f64; 3],
    ) -> Error {
        let model = &self.models[chain];
        own_step_error::<N, 1>((t, x), h, pivot, |q, qd, [x, y, _]| {
            let inputs = Inputs {
                torque: SVector::<f64, N>::from_column_slice(torque),
                pivot_acceleration: Vector2::new(x, y),
            };
            let mut out = SVector::<f64, N>::zeros();
            let (q, qd) = (SVector::<f64, N>::from(q[0]), SVector::<f64, N>::from(qd[0]));
            model.accelerations(&q, &qd, &inputs, &mut out).map(|()| [out.data.0[0]])
        })
    }
}

impl<M: SpatialKernel<N>, const N: usize> Stages<N, { 2 * GROUP }> for UnrolledSpatialBatch<M, N> {
    #[inline(always)]
    fn at<P: Precision, V: KernelLanes<P>>(
        c: &[LinkConstants<V, N>; GROUP],
        count: usize,
        room: &mut SineRoom<P::Lanes, N, { 2 * GROUP }>,
        [q, qd]: [&[[V; N]; 2 * GROUP]; 2],
        inputs: StageInputs<'_, V, N, { 2 * GROUP }>,
    ) -> [[V; N]; 2 * GROUP] {
        let zero = V::splat(0.0);
        let units = count.div_ceil(V::BLOCKS);
        for u in 0..units {
            let [a, b] = unit_blocks(u, V::BLOCKS, count);
            for coordinate in 0..2 {
                for (i, q) in q[2 * u + coordinate].iter().enumerate() {
                    [room.angles[2 * a + coordinate][i], room.angles[2 * b + coordinate][i]] = q.split();
                }
            }
        }
        room.sin_cos::<P>(2 * count);
        let mut out = [[zero; N]; 2 * GROUP];
        for u in 0..units {
            let pair = unit_blocks(u, V::BLOCKS, count);
            let mut trig = [[[zero; 2]; N]; 2];
            room.trig(pair.map(|j| 2 * j), &mut trig[0]);
            room.trig(pair.map(|j| 2 * j + 1), &mut trig[1]);
            let rates = [qd[2 * u], qd[2 * u + 1]];
            let (torque, pivot) =
                inputs.map_or(([[zero; N]; 2], [zero; 3]), |(t, p)| ([t[2 * u], t[2 * u + 1]], p[u]));
            let mut accelerations = M::kernel(&c[u], &trig, &rates, &torque, pivot);
            let near = near_pole(&trig[0]);
            if V::any(near) {
                accelerations[0][0] = V::select(near, V::splat(f64::NAN), accelerations[0][0]);
            }
            [out[2 * u], out[2 * u + 1]] = accelerations;
        }
        out
    }

    #[cold]
    fn step_error(
        &self,
        chain: usize,
        (t, x): (f64, &[f64]),
        h: f64,
        torque: &[f64],
        pivot: &dyn Fn(f64) -> [f64; 3],
    ) -> Error {
        let model = &self.models[chain];
        own_step_error::<N, 2>((t, x), h, pivot, |q, qd, p| {
            let mut out = [[0.0; N]; 2];
            let (q, qd) = (q.as_flattened(), qd.as_flattened());
            model.row_accelerations(q, qd, torque, p, out.as_flattened_mut()).map(|()| out)
        })
    }
}

/// The error of one chain's own RK4 step from `(t, x)`, `x = (q, q̇)` of `2CN` entries, its
/// accelerations `accelerations(q, q̇, p̈)` with the pivot acceleration `pivot(t)` at each
/// stage's time: the first stage's error, else a non-finite increment
/// ([`Error::NonFiniteState`]).
fn own_step_error<const N: usize, const C: usize>(
    (t, x): (f64, &[f64]),
    h: f64,
    pivot: &dyn Fn(f64) -> [f64; 3],
    mut accelerations: impl FnMut(&[[f64; N]; C], &[[f64; N]; C], [f64; 3]) -> Result<[[f64; N]; C]>,
) -> Error {
    let arrays = |x: &[f64]| -> [[f64; N]; C] {
        std::array::from_fn(|c| x[N * c..N * (c + 1)].try_into().expect("N"))
    };
    let (q, qd) = (arrays(&x[..C * N]), arrays(&x[C * N..]));
    let (times, mut stage, mut first) = (stage_times(t, h), 0, None);
    increment::<f64, N, C>(&q, &qd, h, |q: &[[f64; N]; C], qd: &[[f64; N]; C]| {
        let at = accelerations(q, qd, pivot(times[stage]));
        stage += 1;
        at.unwrap_or_else(|error| {
            first.get_or_insert(error);
            [[f64::NAN; N]; C]
        })
    });
    first.unwrap_or(Error::NonFiniteState { t, h })
}
