//! The two number types a batch of generated models evaluates in: `f64`, bit for bit the
//! models, and `f32`, with its own sine kernel ([`trig32`](crate::kinematics::trig32)).

use crate::batch::WIDTH;
use crate::batch::transpose::Transpose;
use crate::kinematics::{trig::sin_cos_split, trig32::sin_cos_split_f32};
use crate::lanes::{Lane, Lanes, Lanes32};

/// A number type of the batch's arrays and its [`WIDTH`] lanes.
pub(crate) trait Precision: Transpose + Send + Sync + Into<f64> + 'static {
    /// [`WIDTH`] numbers, one per chain of a block.
    type Lanes: Lane + Send + Sync;
    /// The same lanes as the kernel computes in them when the CPU has AVX2: one register
    /// each ([`Avx4`](crate::lanes::Avx4) for `f64`, [`Sse4`](crate::lanes::Sse4) for `f32`), converted from and to [`Lanes`](Self::Lanes).
    #[cfg(target_arch = "x86_64")]
    type Registers: Lane + From<Self::Lanes> + Into<Self::Lanes>;
    /// Not a number.
    const NAN: Self;
    /// `f(k)` in lane `k`.
    fn lanes(f: impl Fn(usize) -> Self) -> Self::Lanes;
    /// The lanes of `v` one after another (`v[i]`'s lane `k` at `WIDTH·i + k`).
    fn flatten(v: &[Self::Lanes]) -> &[Self];
    /// [`flatten`](Self::flatten), mutably.
    fn flatten_mut(v: &mut [Self::Lanes]) -> &mut [Self];
    /// `[sin θ_i, cos θ_i]` of every lane of every angle, by this precision's sine kernel
    /// (inlined, so that it runs with its caller's target features).
    fn sin_cos<const N: usize>(angles: &[Self::Lanes; N]) -> [[Self::Lanes; 2]; N];
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
    fn sin_cos<const N: usize>(angles: &[Self::Lanes; N]) -> [[Self::Lanes; 2]; N] {
        let (mut sin, mut cos) = ([Lanes::splat(0.0); N], [Lanes::splat(0.0); N]);
        sin_cos_split(Lanes::flatten(angles), Lanes::flatten_mut(&mut sin), Lanes::flatten_mut(&mut cos));
        std::array::from_fn(|i| [sin[i], cos[i]])
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
    fn sin_cos<const N: usize>(angles: &[Self::Lanes; N]) -> [[Self::Lanes; 2]; N] {
        let (mut sin, mut cos) = ([Lanes32::splat(0.0); N], [Lanes32::splat(0.0); N]);
        sin_cos_split_f32(
            Lanes32::flatten(angles),
            Lanes32::flatten_mut(&mut sin),
            Lanes32::flatten_mut(&mut cos),
        );
        std::array::from_fn(|i| [sin[i], cos[i]])
    }
}
