//! The two number types a batch of generated models evaluates in: `f64`, bit for bit the
//! models, and `f32`, with its own sine kernel ([`trig32`](crate::kinematics::trig32)).

use crate::batch::WIDTH;
use crate::batch::transpose::Transpose;
use crate::kinematics::trig::sin_cos_split;
use crate::kinematics::trig32::sin_cos_split_f32;
use crate::lanes::{Lane, Lanes, Lanes32};

/// Lanes a generated kernel runs in, in precision `P`: `P`'s arrays of lanes themselves, or
/// registers loaded from them and stored back.
pub(crate) trait KernelLanes<P: Precision>: Lane + From<P::Lanes> + Into<P::Lanes> {}

impl<P: Precision, V: Lane + From<P::Lanes> + Into<P::Lanes>> KernelLanes<P> for V {}

/// Each lane group of `v` in type `V`: a loop, not `array::map`, whose closure was compiled
/// apart from the AVX2 kernel (without its target features, the conversions not inlined).
#[inline(always)]
pub(crate) fn convert<L: Copy + Into<V>, V: Lane, const N: usize>(v: &[L; N]) -> [V; N] {
    let mut out = [V::splat(0.0); N];
    for i in 0..N {
        out[i] = v[i].into();
    }
    out
}

/// A number type of the batch's arrays and its [`WIDTH`] lanes.
pub(crate) trait Precision: Transpose + Send + Sync + Into<f64> + 'static {
    /// [`WIDTH`] numbers, one per chain of a block.
    type Lanes: KernelLanes<Self> + Send + Sync;
    /// The same lanes as the kernel computes in them when the CPU has AVX2: one register
    /// each ([`Avx4`](crate::lanes::Avx4) for `f64`, [`Sse4`](crate::lanes::Sse4) for
    /// `f32`).
    #[cfg(target_arch = "x86_64")]
    type Registers: KernelLanes<Self>;
    /// Not a number.
    const NAN: Self;
    /// `f(k)` in lane `k`.
    fn lanes(f: impl Fn(usize) -> Self) -> Self::Lanes;
    /// The lanes of `v` one after another (`v[i]`'s lane `k` at `WIDTH·i + k`).
    fn flatten(v: &[Self::Lanes]) -> &[Self];
    /// [`flatten`](Self::flatten), mutably.
    fn flatten_mut(v: &mut [Self::Lanes]) -> &mut [Self];
    /// `sin[i]`, `cos[i]` of `angles[i]` (rad), by this precision's sine kernel.
    fn sin_cos_split(angles: &[Self], sin: &mut [Self], cos: &mut [Self]);
}

impl Precision for f64 {
    type Lanes = Lanes<WIDTH>;
    #[cfg(target_arch = "x86_64")]
    type Registers = crate::lanes::Avx4;
    const NAN: Self = f64::NAN;

    #[inline(always)]
    fn lanes(f: impl Fn(usize) -> Self) -> Self::Lanes {
        Lanes::from_fn(f)
    }
    #[inline(always)]
    fn flatten(v: &[Self::Lanes]) -> &[Self] {
        Lanes::flatten(v)
    }
    #[inline(always)]
    fn flatten_mut(v: &mut [Self::Lanes]) -> &mut [Self] {
        Lanes::flatten_mut(v)
    }
    #[inline(always)]
    fn sin_cos_split(angles: &[Self], sin: &mut [Self], cos: &mut [Self]) {
        sin_cos_split(angles, sin, cos)
    }
}

impl Precision for f32 {
    type Lanes = Lanes32<WIDTH>;
    #[cfg(target_arch = "x86_64")]
    type Registers = crate::lanes::Sse4;
    const NAN: Self = f32::NAN;

    #[inline(always)]
    fn lanes(f: impl Fn(usize) -> Self) -> Self::Lanes {
        Lanes32::from_fn(f)
    }
    #[inline(always)]
    fn flatten(v: &[Self::Lanes]) -> &[Self] {
        Lanes32::flatten(v)
    }
    #[inline(always)]
    fn flatten_mut(v: &mut [Self::Lanes]) -> &mut [Self] {
        Lanes32::flatten_mut(v)
    }
    #[inline(always)]
    fn sin_cos_split(angles: &[Self], sin: &mut [Self], cos: &mut [Self]) {
        sin_cos_split_f32(angles, sin, cos)
    }
}
