//! Numbers that are one `f64` or `W` of them side by side: the scalar type of the tension
//! solve, so that one algorithm serves a single chain (`f64`) and `W` chains at once in SIMD
//! lanes ([`Lanes`]), or `W` chains in single precision ([`Lanes32`]; not bit for bit
//! anything, its accuracy is measured in `docs/ensembles.md`).
//!
//! [`Lanes`] does every operation lane by lane, the same IEEE operation in each, with no
//! fused multiply-add: a lane's result is bit for bit what `f64` gives for that lane alone.
//! Compiled for AVX2 (the batch detects it at run time, as the sine kernel does) four lanes
//! are one instruction; on the baseline x86-64 target two; elsewhere whatever the target
//! has.

use std::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};

mod aligned;
mod continuants;
#[cfg(target_arch = "x86_64")]
mod registers;
mod subnormals;

pub(crate) use aligned::Aligned;
pub use continuants::CONTINUANT_RANGE;
pub(crate) use continuants::{CONTINUANT_ENDS, CONTINUANT_ENDS_32, CONTINUANT_RANGE_32};
use continuants::{outside_ends, outside_lanes, widened, widened_lanes};
#[cfg(target_arch = "x86_64")]
pub(crate) use registers::{Avx4, Avx8, AvxF32};
pub(crate) use subnormals::FlushSubnormals;

/// Whether the lanes can run as AVX2 registers on this CPU (checked once, then cached by
/// std).
#[inline(always)]
pub(crate) fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    return std::arch::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    return false;
}

/// Whether the CPU has AVX-512 (its foundation, `avx512f`; checked once, then cached by
/// std): the sine kernels then run eight `f64` (sixteen `f32`) angles per instruction,
/// and the planar batch eight chains.
#[inline(always)]
pub(crate) fn has_avx512() -> bool {
    #[cfg(target_arch = "x86_64")]
    return std::arch::is_x86_feature_detected!("avx512f");
    #[cfg(not(target_arch = "x86_64"))]
    return false;
}

/// Whether the CPU has AVX-512's foundation and its instructions on 256-bit registers
/// (`avx512vl`): code on four-`f64`-lane registers compiled for it gets 32 vector
/// registers instead of 16 (the generated models' batch, whose long kernels spill).
#[inline(always)]
pub(crate) fn has_avx512vl() -> bool {
    #[cfg(target_arch = "x86_64")]
    return has_avx512() && std::arch::is_x86_feature_detected!("avx512vl");
    #[cfg(not(target_arch = "x86_64"))]
    return false;
}

/// Ends the body of a loop over rows of lanes (one link's, one state entry's): a compiler
/// fence, which emits no instruction but keeps LLVM's loop vectorizer from running the
/// loop across rows, one lane per gather. It did so with eight `f64` lanes under AVX-512,
/// and the eight-lane planar batch took 1.4× the four-lane one's time at n = 100
/// (`docs/ensembles.md`); with the fence each operation on a row's lanes is one
/// instruction.
#[inline(always)]
pub(crate) fn one_row_at_a_time() {
    std::sync::atomic::compiler_fence(std::sync::atomic::Ordering::SeqCst);
}

/// The arithmetic the tension solve needs, lane by lane (numbers, owning nothing: a batch
/// keeps rooms of them between calls).
pub trait Lane:
    Copy
    + 'static
    + std::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
{
    /// One flag per lane.
    type Mask: Copy + std::fmt::Debug;
    /// Lanes.
    const WIDTH: usize;
    /// Rows of a tension solve between two rescalings of its continuants (`rods`'
    /// `Continuants`). Each row multiplies a continuant by its pivot `D_i`: 16 rows of
    /// pivots between 2⁻⁴⁸ and 2⁴⁸ keep it inside [`CONTINUANT_RANGE`] in double precision,
    /// 4 rows of pivots between 2⁻¹⁹ and 2¹⁹ (1/kg) inside `[2⁻⁸⁰, 2⁸⁰]` in single (after
    /// each rescaling the continuant is in `[1, 2)`).
    const RESCALE_ROWS: usize = 16;

    /// Every lane `x`.
    fn splat(x: f64) -> Self;
    /// The square root, correctly rounded, lane by lane.
    fn sqrt(self) -> Self;
    /// `|x|` (the sign bit cleared), lane by lane.
    fn abs(self) -> Self;
    /// The flags of the lanes whose bit pattern `b` has `b − low > span` (wrapping): with
    /// `(low, span)` = [`CONTINUANT_RANGE`], the lanes outside `[2⁻⁸⁰⁰, 2⁸⁰⁰]` (negative,
    /// zero, infinite and NaN included).
    fn outside(self, low: u64, span: u64) -> Self::Mask;
    /// No lane flagged.
    fn none() -> Self::Mask;
    /// The flags of either.
    fn or(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// Whether any lane is flagged.
    fn any(mask: Self::Mask) -> bool;
    /// Whether every lane is flagged.
    fn all(mask: Self::Mask) -> bool;
    /// `a` in the flagged lanes, `b` in the others.
    fn select(mask: Self::Mask, a: Self, b: Self) -> Self;
    /// `2^−e` for `x = f·2^e` with `1 ≤ f < 2`, lane by lane: the exact power of two that
    /// brings a positive normal `x` into `[1, 2)`.
    fn normalizer(self) -> Self;
    /// The lanes whose continuant `self` is outside the range where the tension solve trusts
    /// it: [`CONTINUANT_RANGE`] in double precision,
    /// `[2⁻⁸⁰, 2⁸⁰]` in single ([`Lanes32`]).
    #[inline(always)]
    fn continuant_outside(self) -> Self::Mask {
        let (low, span) = CONTINUANT_RANGE;
        self.outside(low, span)
    }
    /// `[lowest, highest]` widened to take in `self`, lane by lane, by the rule of x86's
    /// `minpd` and `maxpd` (`lowest < x ? lowest : x`, one instruction each): a NaN `self`
    /// is taken in.
    fn widen(self, range: [Self; 2]) -> [Self; 2];
    /// The lanes whose range from [`widen`](Self::widen) (started at `[+∞, −∞]`) is NaN
    /// or reaches outside the continuants' range of their precision: those with a value
    /// that [`continuant_outside`](Self::continuant_outside) flags, when a NaN value is
    /// followed by NaN only (as in the continuants' recurrence).
    fn range_outside(range: [Self; 2]) -> Self::Mask;
}

/// The comparisons and the flags' logic that control flow in lanes needs (a lane that
/// converged or failed is masked while the others go on), on lanes held as arrays.
pub trait Masked: Lane {
    /// The flags of both.
    fn and(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// The flags of `a` that are not in `b`.
    fn and_not(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// `other` where it is larger, else `self`, lane by lane: `f64::max` for a `self` that
    /// is not NaN (a NaN `other` loses). A compare and a select, which stay in vector
    /// registers (`f64::max` on arrays of eight lanes was computed one lane at a time).
    fn max(self, other: Self) -> Self;
    /// The lanes that are infinite or NaN.
    fn not_finite(self) -> Self::Mask;
    /// The lanes that are `±0`.
    fn is_zero(self) -> Self::Mask;
    /// The lanes with `self ≤ bound` (never a NaN lane).
    fn at_most(self, bound: Self) -> Self::Mask;
    /// The lanes with `self > bound` (never a NaN lane).
    fn above(self, bound: Self) -> Self::Mask;
}

impl Lane for f64 {
    type Mask = bool;
    const WIDTH: usize = 1;

    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn outside(self, low: u64, span: u64) -> bool {
        self.to_bits().wrapping_sub(low) > span
    }
    #[inline(always)]
    fn none() -> bool {
        false
    }
    #[inline(always)]
    fn or(a: bool, b: bool) -> bool {
        a | b
    }
    #[inline(always)]
    fn any(mask: bool) -> bool {
        mask
    }
    #[inline(always)]
    fn all(mask: bool) -> bool {
        mask
    }
    #[inline(always)]
    fn select(mask: bool, a: Self, b: Self) -> Self {
        if mask { a } else { b }
    }
    #[inline(always)]
    fn normalizer(self) -> Self {
        let biased = (self.to_bits() >> 52) & 0x7ff;
        f64::from_bits(((2046 - biased as i64) as u64 & 0x7ff) << 52)
    }
    #[inline(always)]
    fn widen(self, range: [Self; 2]) -> [Self; 2] {
        widened(self, range)
    }
    #[inline(always)]
    fn range_outside(range: [Self; 2]) -> bool {
        outside_ends(range, CONTINUANT_ENDS)
    }
}

impl Masked for f64 {
    #[inline(always)]
    fn and(a: bool, b: bool) -> bool {
        a & b
    }
    #[inline(always)]
    fn and_not(a: bool, b: bool) -> bool {
        a & !b
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        if other > self { other } else { self }
    }
    #[inline(always)]
    fn not_finite(self) -> bool {
        !self.is_finite()
    }
    #[inline(always)]
    fn is_zero(self) -> bool {
        self == 0.0
    }
    #[inline(always)]
    fn at_most(self, bound: Self) -> bool {
        self <= bound
    }
    #[inline(always)]
    fn above(self, bound: Self) -> bool {
        self > bound
    }
}

/// `W` numbers, one per chain of a batch, operated on lane by lane.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(transparent)]
pub struct Lanes<const W: usize>(pub [f64; W]);

/// `W` single-precision numbers, one per chain of a batch, operated on lane by lane.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(transparent)]
pub struct Lanes32<const W: usize>(pub [f32; W]);

impl<const W: usize> Lanes32<W> {
    /// `v` rounded to single precision, lane by lane.
    #[inline(always)]
    pub fn rounded(v: [f64; W]) -> Self {
        Self(v.map(|x| x as f32))
    }
}

impl<const W: usize> Lanes<W> {
    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [f64; W] {
        self.0
    }
}

/// The constructors, views and arithmetic of a lane type `$lanes` over `[$t; W]`. Loops into
/// arrays rather than `array::map` and `array::from_fn`: those left most of a generated
/// kernel's single-precision lanes scalar.
macro_rules! lane_array {
    ($lanes:ident, $t:ty) => {
        impl<const W: usize> $lanes<W> {
            /// `f(lane)` for each lane.
            #[inline(always)]
            pub fn map(self, f: impl Fn($t) -> $t) -> Self {
                let mut out = self.0;
                for x in &mut out {
                    *x = f(*x);
                }
                Self(out)
            }

            /// `f(k)` in lane `k`.
            #[inline(always)]
            pub fn from_fn(f: impl Fn(usize) -> $t) -> Self {
                let mut out = [0.0; W];
                for (k, x) in out.iter_mut().enumerate() {
                    *x = f(k);
                }
                Self(out)
            }

            /// The lanes of `v` one after another: `v[i].0[k]` at `W·i + k`.
            #[inline(always)]
            pub fn flatten(v: &[Self]) -> &[$t] {
                // SAFETY: the type is `repr(transparent)` over `[$t; W]`, so a slice of `m` of
                // them is `W·m` contiguous numbers with the same alignment.
                unsafe { std::slice::from_raw_parts(v.as_ptr().cast(), W * v.len()) }
            }

            /// [`flatten`](Self::flatten), mutably.
            #[inline(always)]
            pub fn flatten_mut(v: &mut [Self]) -> &mut [$t] {
                // SAFETY: as in `flatten`; the borrow of `v` is moved into the result.
                unsafe { std::slice::from_raw_parts_mut(v.as_mut_ptr().cast(), W * v.len()) }
            }
        }

        impl<const W: usize> Neg for $lanes<W> {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                self.map(|x| -x)
            }
        }

        lane_op!($lanes, Add, add, AddAssign, add_assign, +);
        lane_op!($lanes, Sub, sub, SubAssign, sub_assign, -);
        lane_op!($lanes, Mul, mul, MulAssign, mul_assign, *);
        lane_op!($lanes, Div, div, DivAssign, div_assign, /);
    };
}

macro_rules! lane_op {
    ($lanes:ident, $trait:ident, $method:ident, $assign:ident, $assign_method:ident, $op:tt) => {
        impl<const W: usize> $trait for $lanes<W> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, other: Self) -> Self {
                let mut out = self.0;
                for k in 0..W {
                    out[k] = self.0[k] $op other.0[k];
                }
                Self(out)
            }
        }
        impl<const W: usize> $assign for $lanes<W> {
            #[inline(always)]
            fn $assign_method(&mut self, other: Self) {
                *self = *self $op other;
            }
        }
    };
}

lane_array!(Lanes, f64);
lane_array!(Lanes32, f32);

/// The comparisons and masks of [`Lane`] for a lane array type of `$t` with masks
/// `[$m; W]` (1 in a flagged lane).
macro_rules! lane_masks {
    ($t:ty, $m:ty) => {
        #[inline(always)]
        fn and(a: [$m; W], b: [$m; W]) -> [$m; W] {
            let mut out = a;
            for k in 0..W {
                out[k] &= b[k];
            }
            out
        }
        #[inline(always)]
        fn and_not(a: [$m; W], b: [$m; W]) -> [$m; W] {
            let mut out = a;
            for k in 0..W {
                out[k] &= !b[k];
            }
            out
        }
        #[inline(always)]
        fn max(self, other: Self) -> Self {
            let mut out = self.0;
            for k in 0..W {
                if other.0[k] > out[k] {
                    out[k] = other.0[k];
                }
            }
            Self(out)
        }
        #[inline(always)]
        fn not_finite(self) -> [$m; W] {
            let mut out = [0; W];
            for k in 0..W {
                out[k] = <$m>::from(!self.0[k].is_finite());
            }
            out
        }
        #[inline(always)]
        fn is_zero(self) -> [$m; W] {
            let mut out = [0; W];
            for k in 0..W {
                out[k] = <$m>::from(self.0[k] == 0.0);
            }
            out
        }
        #[inline(always)]
        fn at_most(self, bound: Self) -> [$m; W] {
            let mut out = [0; W];
            for k in 0..W {
                out[k] = <$m>::from(self.0[k] <= bound.0[k]);
            }
            out
        }
        #[inline(always)]
        fn above(self, bound: Self) -> [$m; W] {
            let mut out = [0; W];
            for k in 0..W {
                out[k] = <$m>::from(self.0[k] > bound.0[k]);
            }
            out
        }
    };
}

/// The flags of either mask, lane by lane.
#[inline(always)]
fn or_masks<M: Copy + std::ops::BitOrAssign, const W: usize>(a: [M; W], b: [M; W]) -> [M; W] {
    let mut out = a;
    for k in 0..W {
        out[k] |= b[k];
    }
    out
}

/// Whether any lane of `mask` is flagged (non-zero).
#[inline(always)]
fn any_mask<M: Copy + Default + PartialEq + std::ops::BitOr<Output = M>, const W: usize>(
    mask: [M; W],
) -> bool {
    mask.iter().fold(M::default(), |any, &m| any | m) != M::default()
}

/// `a` in the flagged lanes, `b` in the others.
#[inline(always)]
fn select_lanes<M: Copy + Default + PartialEq, T: Copy, const W: usize>(
    mask: [M; W],
    a: [T; W],
    b: [T; W],
) -> [T; W] {
    let mut out = b;
    for k in 0..W {
        if mask[k] != M::default() {
            out[k] = a[k];
        }
    }
    out
}

impl<const W: usize> Lane for Lanes32<W> {
    type Mask = [u32; W];
    const WIDTH: usize = W;
    const RESCALE_ROWS: usize = 4;

    #[inline(always)]
    fn splat(x: f64) -> Self {
        Self([x as f32; W])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(f32::sqrt)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        self.map(f32::abs)
    }
    /// `(low, span)` as `f64` bit patterns: each lane widened to `f64` (exact) and checked.
    #[inline(always)]
    fn outside(self, low: u64, span: u64) -> [u32; W] {
        let mut out = [0; W];
        for (o, x) in out.iter_mut().zip(self.0) {
            *o = f64::from(x).outside(low, span) as u32;
        }
        out
    }
    #[inline(always)]
    fn none() -> [u32; W] {
        [0; W]
    }
    #[inline(always)]
    fn or(a: [u32; W], b: [u32; W]) -> [u32; W] {
        or_masks(a, b)
    }
    #[inline(always)]
    fn any(mask: [u32; W]) -> bool {
        any_mask(mask)
    }
    #[inline(always)]
    fn all(mask: [u32; W]) -> bool {
        mask.iter().all(|&m| m != 0)
    }
    #[inline(always)]
    fn select(mask: [u32; W], a: Self, b: Self) -> Self {
        Self(select_lanes(mask, a.0, b.0))
    }
    #[inline(always)]
    fn normalizer(self) -> Self {
        self.map(|x| {
            let biased = (x.to_bits() >> 23) & 0xff;
            f32::from_bits(((254 - biased as i32) as u32 & 0xff) << 23)
        })
    }
    #[inline(always)]
    fn continuant_outside(self) -> [u32; W] {
        let (low, span) = CONTINUANT_RANGE_32;
        let mut out = [0; W];
        for (o, x) in out.iter_mut().zip(self.0) {
            *o = (x.to_bits().wrapping_sub(low) > span) as u32;
        }
        out
    }
    #[inline(always)]
    fn widen(self, [lowest, highest]: [Self; 2]) -> [Self; 2] {
        widened_lanes(self.0, [lowest.0, highest.0]).map(Self)
    }
    #[inline(always)]
    fn range_outside([lowest, highest]: [Self; 2]) -> [u32; W] {
        outside_lanes([lowest.0, highest.0], CONTINUANT_ENDS_32)
    }
}

impl<const W: usize> Lane for Lanes<W> {
    /// 1 in the flagged lanes, 0 in the others (integers, so that the flags stay in a
    /// vector register).
    type Mask = [u64; W];
    const WIDTH: usize = W;

    #[inline(always)]
    fn splat(x: f64) -> Self {
        Self([x; W])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(f64::sqrt)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        self.map(f64::abs)
    }
    #[inline(always)]
    fn outside(self, low: u64, span: u64) -> [u64; W] {
        let mut out = [0; W];
        for (o, x) in out.iter_mut().zip(self.0) {
            *o = x.outside(low, span) as u64;
        }
        out
    }
    #[inline(always)]
    fn none() -> [u64; W] {
        [0; W]
    }
    #[inline(always)]
    fn or(a: [u64; W], b: [u64; W]) -> [u64; W] {
        or_masks(a, b)
    }
    #[inline(always)]
    fn any(mask: [u64; W]) -> bool {
        any_mask(mask)
    }
    #[inline(always)]
    fn all(mask: [u64; W]) -> bool {
        mask.iter().all(|&m| m != 0)
    }
    #[inline(always)]
    fn select(mask: [u64; W], a: Self, b: Self) -> Self {
        Self(select_lanes(mask, a.0, b.0))
    }
    #[inline(always)]
    fn normalizer(self) -> Self {
        self.map(f64::normalizer)
    }
    #[inline(always)]
    fn widen(self, [lowest, highest]: [Self; 2]) -> [Self; 2] {
        widened_lanes(self.0, [lowest.0, highest.0]).map(Self)
    }
    #[inline(always)]
    fn range_outside([lowest, highest]: [Self; 2]) -> [u64; W] {
        outside_lanes([lowest.0, highest.0], CONTINUANT_ENDS)
    }
}

impl<const W: usize> Masked for Lanes32<W> {
    lane_masks!(f32, u32);
}

impl<const W: usize> Masked for Lanes<W> {
    lane_masks!(f64, u64);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_do_what_each_f64_does() {
        let a = Lanes([1.5, -2.0, 3e-300, 7.0]);
        let b = Lanes([0.1, 3.0, 1e300, -0.0]);
        for k in 0..4 {
            assert_eq!((a + b).0[k], a.0[k] + b.0[k]);
            assert_eq!((a - b).0[k], a.0[k] - b.0[k]);
            assert_eq!((a * b).0[k], a.0[k] * b.0[k]);
            assert_eq!((a / b).0[k].to_bits(), (a.0[k] / b.0[k]).to_bits());
            assert_eq!(a.normalizer().0[k], a.0[k].normalizer());
            assert_eq!(b.abs().0[k].to_bits(), b.0[k].abs().to_bits());
        }
        let mask =
            Lanes([1.0, 0.0, f64::NAN, 2f64.powi(900)]).outside(CONTINUANT_RANGE.0, CONTINUANT_RANGE.1);
        assert_eq!(mask, [0, 1, 1, 1]);
        assert!(Lanes::<4>::any(mask) && !Lanes::<4>::any(Lanes::<4>::none()));
        assert!(!Lanes::<4>::all(mask) && Lanes::<4>::all([1, 1, 1, 1]));
        assert_eq!(Lanes::select(mask, a, b).0[..2], [0.1f64, -2.0][..]);
    }

    #[test]
    fn the_normalizer_brings_a_number_into_one_to_two() {
        for x in [1.0, 1.999, 3.0, 1e-200, 7e250, 2f64.powi(-800)] {
            let y = x * x.normalizer();
            assert!((1.0..2.0).contains(&y), "{x} → {y}");
        }
    }
}
