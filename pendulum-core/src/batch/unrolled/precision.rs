//! The two number types a batch of generated models evaluates in: `f64`, bit for bit the
//! models, and `f32`, with its own sine kernel ([`trig32`](crate::kinematics::trig32)).

use crate::batch::WIDTH;
use crate::batch::transpose::Transpose;
use crate::kinematics::trig::sin_cos_split;
use crate::kinematics::trig32::sin_cos_split_f32;
use crate::lanes::{Lane, Lanes, Lanes32};

/// Lanes a generated kernel runs in, in precision `P`: [`BLOCKS`](Self::BLOCKS) blocks of
/// [`WIDTH`] chains side by side. One block: `P`'s arrays of lanes themselves, or a register
/// loaded from them; two: one register of eight lanes (`Avx8` for `f64`, `AvxF32` for
/// `f32`).
pub(crate) trait KernelLanes<P: Precision>: Lane {
    /// Blocks one value holds: 1 or 2.
    const BLOCKS: usize;
    /// The lanes of `blocks[0]`, then those of `blocks[1]` when [`BLOCKS`](Self::BLOCKS) is 2.
    fn join(blocks: [P::Lanes; 2]) -> Self;
    /// The blocks' lanes back, as [`join`](Self::join) took them (the one block twice when
    /// [`BLOCKS`](Self::BLOCKS) is 1).
    fn split(self) -> [P::Lanes; 2];
}

/// A lane type of one block of precision `P`, converted from and to `P`'s lanes.
macro_rules! one_block {
    ($p:ty: $($v:ty),+) => {$(
        impl KernelLanes<$p> for $v {
            const BLOCKS: usize = 1;
            #[inline(always)]
            fn join(blocks: [<$p as Precision>::Lanes; 2]) -> Self {
                blocks[0].into()
            }
            #[inline(always)]
            fn split(self) -> [<$p as Precision>::Lanes; 2] {
                let block = self.into();
                [block, block]
            }
        }
    )+};
}

one_block!(f64: Lanes<WIDTH>);
one_block!(f32: Lanes32<WIDTH>);
#[cfg(target_arch = "x86_64")]
one_block!(f64: crate::lanes::Avx4);

/// A lane type of two blocks of precision `P`, by its own `join` and `split`.
macro_rules! two_blocks {
    ($p:ty: $v:ty) => {
        impl KernelLanes<$p> for $v {
            const BLOCKS: usize = 2;
            #[inline(always)]
            fn join(blocks: [<$p as Precision>::Lanes; 2]) -> Self {
                <$v>::join(blocks)
            }
            #[inline(always)]
            fn split(self) -> [<$p as Precision>::Lanes; 2] {
                <$v>::split(self)
            }
        }
    };
}

#[cfg(target_arch = "x86_64")]
two_blocks!(f64: crate::lanes::Avx8);
#[cfg(target_arch = "x86_64")]
two_blocks!(f32: crate::lanes::AvxF32);

/// Lane `i` of `blocks[0]` and `blocks[1]` (see [`KernelLanes::join`]) for each `i`: a loop,
/// not `array::map`, whose closure was compiled apart from the AVX2 kernel (without its
/// target features, the conversions not inlined).
#[inline(always)]
pub(crate) fn join<P: Precision, V: KernelLanes<P>, const N: usize>(blocks: [&[P::Lanes; N]; 2]) -> [V; N] {
    let mut out = [V::splat(0.0); N];
    for i in 0..N {
        out[i] = V::join([blocks[0][i], blocks[1][i]]);
    }
    out
}

/// A number type of the batch's arrays and its [`WIDTH`] lanes.
pub(crate) trait Precision: Transpose + Send + Sync + Into<f64> + 'static {
    /// [`WIDTH`] numbers, one per chain of a block.
    type Lanes: KernelLanes<Self> + Send + Sync;
    /// The lanes the kernel computes in when the CPU has AVX2: one register each
    /// ([`Avx4`](crate::lanes::Avx4), one block, for `f64`; [`AvxF32`](crate::lanes::AvxF32),
    /// two blocks, for `f32`).
    #[cfg(target_arch = "x86_64")]
    type Registers: KernelLanes<Self>;
    /// The lanes the kernel computes in when the CPU has AVX-512 VL: two blocks in one
    /// register, [`Avx8`](crate::lanes::Avx8) for `f64`, [`AvxF32`](crate::lanes::AvxF32)
    /// for `f32`.
    #[cfg(target_arch = "x86_64")]
    type Wide: KernelLanes<Self>;
    /// Not a number.
    const NAN: Self;
    /// `f(k)` in lane `k`.
    fn lanes(f: impl Fn(usize) -> Self) -> Self::Lanes;
    /// `x` rounded to this precision.
    fn rounded(x: f64) -> Self;
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
    #[cfg(target_arch = "x86_64")]
    type Wide = crate::lanes::Avx8;
    const NAN: Self = f64::NAN;

    #[inline(always)]
    fn rounded(x: f64) -> Self {
        x
    }

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
    type Registers = crate::lanes::AvxF32;
    #[cfg(target_arch = "x86_64")]
    type Wide = crate::lanes::AvxF32;
    const NAN: Self = f32::NAN;

    #[inline(always)]
    fn rounded(x: f64) -> Self {
        x as f32
    }

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
