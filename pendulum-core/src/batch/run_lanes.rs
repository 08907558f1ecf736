//! [`RunLane`]: the lanes a batch computes in, `f64` ([`Lanes`]) or `f32` ([`F32x8`]),
//! with their precision's sine kernel and flags: what the runs, the accelerations and the
//! Jacobians of `PlanarBatch`, and the Jacobians of `DirectionsBatch`, are written against
//! once.

use super::lane_states::{non_finite_lanes, non_finite_lanes_f32};
use super::transpose::Transpose;
use super::{F32x8, WIDTH_F32};
use crate::kinematics::{trig::sin_cos_split, trig32::sin_cos_split_f32};
use crate::lanes::{Lanes, Lanes32, Masked};

/// The lanes a batch steps and differentiates in, with their precision's sine kernel: four
/// or eight `f64` lanes ([`Lanes`]) or [`F32x8`].
pub(super) trait RunLane: Masked + Send {
    /// The number type of one lane.
    type Num: Transpose + Into<f64> + Send + Sync;
    /// The lanes of `v` one after another.
    fn flatten(v: &[Self]) -> &[Self::Num];
    /// The same, to write.
    fn flatten_mut(v: &mut [Self]) -> &mut [Self::Num];
    /// `f(k)` in lane `k`.
    fn from_nums(f: impl Fn(usize) -> Self::Num) -> Self;
    /// The lanes `k` with `flag(k)`.
    fn mask(flag: impl Fn(usize) -> bool) -> Self::Mask;
    /// `sin`, `cos` of every lane of `angles` (inlined, so that it runs with its caller's
    /// target features).
    fn sin_cos(angles: &[Self], sin: &mut [Self], cos: &mut [Self]);
    /// The lanes in which some entry of `v` is not finite.
    fn non_finite(v: &[Self]) -> Self::Mask;
}

impl<const W: usize> RunLane for Lanes<W> {
    type Num = f64;
    #[inline(always)]
    fn flatten(v: &[Self]) -> &[f64] {
        Lanes::flatten(v)
    }
    #[inline(always)]
    fn flatten_mut(v: &mut [Self]) -> &mut [f64] {
        Lanes::flatten_mut(v)
    }
    #[inline(always)]
    fn from_nums(f: impl Fn(usize) -> f64) -> Self {
        Lanes::from_fn(f)
    }
    #[inline(always)]
    fn mask(flag: impl Fn(usize) -> bool) -> [u64; W] {
        std::array::from_fn(|k| u64::from(flag(k)))
    }
    #[inline(always)]
    fn sin_cos(angles: &[Self], sin: &mut [Self], cos: &mut [Self]) {
        sin_cos_split(Lanes::flatten(angles), Lanes::flatten_mut(sin), Lanes::flatten_mut(cos));
    }
    #[inline(always)]
    fn non_finite(v: &[Self]) -> [u64; W] {
        non_finite_lanes(v)
    }
}

impl RunLane for F32x8 {
    type Num = f32;
    #[inline(always)]
    fn flatten(v: &[Self]) -> &[f32] {
        Lanes32::flatten(v)
    }
    #[inline(always)]
    fn flatten_mut(v: &mut [Self]) -> &mut [f32] {
        Lanes32::flatten_mut(v)
    }
    #[inline(always)]
    fn from_nums(f: impl Fn(usize) -> f32) -> Self {
        Lanes32::from_fn(f)
    }
    #[inline(always)]
    fn mask(flag: impl Fn(usize) -> bool) -> [u32; WIDTH_F32] {
        std::array::from_fn(|k| u32::from(flag(k)))
    }
    #[inline(always)]
    fn sin_cos(angles: &[Self], sin: &mut [Self], cos: &mut [Self]) {
        sin_cos_split_f32(Lanes32::flatten(angles), Lanes32::flatten_mut(sin), Lanes32::flatten_mut(cos));
    }
    #[inline(always)]
    fn non_finite(v: &[Self]) -> [u32; WIDTH_F32] {
        non_finite_lanes_f32(v)
    }
}
