//! Lanes held in one x86-64 vector register: [`Avx4`], four `f64` lanes in an AVX register,
//! and [`Sse4`], four `f32` lanes in an SSE register. They are the lane types of the
//! generated models' batch kernel on a CPU with AVX2.
//!
//! [`Lanes<4>`](super::Lanes) and [`Lanes32<4>`](super::Lanes32) leave it to LLVM's SLP
//! vectorizer to turn each array of four into one register; in a long straight-line kernel
//! (a generated model's, all its links' numbers live at once) it gave up on half of them,
//! leaving them scalar or spilled. Here every operation is one intrinsic, the same IEEE
//! operation in each lane with no fused multiply-add, so a lane's result is still bit for
//! bit what `f64` (`f32`) gives.
//!
//! An [`Avx4`] must only exist in code compiled for AVX2 and run on a CPU that has it (the
//! batch checks at run time, then enters a `#[target_feature(enable = "avx2")]` function):
//! its methods are `#[inline(always)]` intrinsics, inlined into that function. The types are
//! private to the crate for that reason. ([`Sse4`] needs only SSE2, which every x86-64 CPU
//! has.)

use std::arch::x86_64::*;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub, SubAssign};

use super::{CONTINUANT_RANGE, CONTINUANT_RANGE_32, Lane, Lanes, Lanes32};

/// Four `f64` lanes, one AVX register (see the module's docs for where one may exist).
#[derive(Debug, Clone, Copy)]
#[repr(transparent)]
pub(crate) struct Avx4(__m256d);

/// Four `f32` lanes, one SSE register.
#[derive(Debug, Clone, Copy)]
#[repr(transparent)]
pub(crate) struct Sse4(__m128);

/// A register type's loads and stores from its lane array, arithmetic and negation, one
/// intrinsic each.
macro_rules! register_lanes {
    ($name:ident, $array:ident, $t:ty, $load:ident, $store:ident, $add:ident, $sub:ident,
     $mul:ident, $div:ident, $xor:ident, $set1:ident) => {
        impl From<$array<4>> for $name {
            #[inline(always)]
            fn from(v: $array<4>) -> Self {
                // SAFETY: an `Avx4` is only made on a CPU with AVX (module docs), an `Sse4`
                // on any x86-64; the load is unaligned and reads the four numbers of `v`.
                Self(unsafe { $load(v.0.as_ptr()) })
            }
        }

        impl From<$name> for $array<4> {
            #[inline(always)]
            fn from(v: $name) -> Self {
                let mut out: [$t; 4] = [0.0; 4];
                // SAFETY: as in `from`; the store writes the four numbers of `out`.
                unsafe { $store(out.as_mut_ptr(), v.0) };
                $array(out)
            }
        }

        register_lanes!(@op $name, Add, add, $add);
        register_lanes!(@op $name, Sub, sub, $sub);
        register_lanes!(@op $name, Mul, mul, $mul);
        register_lanes!(@op $name, Div, div, $div);

        impl AddAssign for $name {
            #[inline(always)]
            fn add_assign(&mut self, other: Self) {
                *self = *self + other;
            }
        }

        impl SubAssign for $name {
            #[inline(always)]
            fn sub_assign(&mut self, other: Self) {
                *self = *self - other;
            }
        }

        impl Neg for $name {
            type Output = Self;
            /// The sign bit flipped, as `-x` does.
            #[inline(always)]
            fn neg(self) -> Self {
                // SAFETY: as in `from`.
                Self(unsafe { $xor(self.0, $set1(-0.0)) })
            }
        }
    };
    (@op $name:ident, $trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for $name {
            type Output = Self;
            #[inline(always)]
            fn $method(self, other: Self) -> Self {
                // SAFETY: as in `from`.
                Self(unsafe { $intrinsic(self.0, other.0) })
            }
        }
    };
}

register_lanes!(
    Avx4,
    Lanes,
    f64,
    _mm256_loadu_pd,
    _mm256_storeu_pd,
    _mm256_add_pd,
    _mm256_sub_pd,
    _mm256_mul_pd,
    _mm256_div_pd,
    _mm256_xor_pd,
    _mm256_set1_pd
);
register_lanes!(
    Sse4,
    Lanes32,
    f32,
    _mm_loadu_ps,
    _mm_storeu_ps,
    _mm_add_ps,
    _mm_sub_ps,
    _mm_mul_ps,
    _mm_div_ps,
    _mm_xor_ps,
    _mm_set1_ps
);

impl Lane for Avx4 {
    /// All ones in the flagged lanes, zeros in the others.
    type Mask = __m256i;
    const WIDTH: usize = 4;

    // SAFETY (every method): an `Avx4` exists only in code compiled for AVX2 on a CPU that
    // has it (module docs).
    #[inline(always)]
    fn splat(x: f64) -> Self {
        Self(unsafe { _mm256_set1_pd(x) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(unsafe { _mm256_sqrt_pd(self.0) })
    }
    /// `b − low > span` as unsigned 64-bit integers: both sides with their top bit flipped,
    /// then AVX2's signed comparison.
    #[inline(always)]
    fn outside(self, low: u64, span: u64) -> __m256i {
        unsafe {
            let top = _mm256_set1_epi64x(i64::MIN);
            let offset = _mm256_sub_epi64(_mm256_castpd_si256(self.0), _mm256_set1_epi64x(low as i64));
            _mm256_cmpgt_epi64(_mm256_xor_si256(offset, top), _mm256_set1_epi64x((span ^ (1 << 63)) as i64))
        }
    }
    #[inline(always)]
    fn none() -> __m256i {
        unsafe { _mm256_setzero_si256() }
    }
    #[inline(always)]
    fn or(a: __m256i, b: __m256i) -> __m256i {
        unsafe { _mm256_or_si256(a, b) }
    }
    #[inline(always)]
    fn any(mask: __m256i) -> bool {
        unsafe { _mm256_testz_si256(mask, mask) == 0 }
    }
    #[inline(always)]
    fn all(mask: __m256i) -> bool {
        unsafe { _mm256_movemask_pd(_mm256_castsi256_pd(mask)) == 0xf }
    }
    #[inline(always)]
    fn select(mask: __m256i, a: Self, b: Self) -> Self {
        Self(unsafe { _mm256_blendv_pd(b.0, a.0, _mm256_castsi256_pd(mask)) })
    }
    /// `f64`'s [`normalizer`](Lane::normalizer) on the lanes' bit patterns.
    #[inline(always)]
    fn normalizer(self) -> Self {
        unsafe {
            let exponent = _mm256_set1_epi64x(0x7ff);
            let biased = _mm256_and_si256(_mm256_srli_epi64::<52>(_mm256_castpd_si256(self.0)), exponent);
            let inverse = _mm256_and_si256(_mm256_sub_epi64(_mm256_set1_epi64x(2046), biased), exponent);
            Self(_mm256_castsi256_pd(_mm256_slli_epi64::<52>(inverse)))
        }
    }
    #[inline(always)]
    fn continuant_outside(self) -> __m256i {
        let (low, span) = CONTINUANT_RANGE;
        self.outside(low, span)
    }
}

impl Lane for Sse4 {
    /// All ones in the flagged lanes, zeros in the others.
    type Mask = __m128i;
    const WIDTH: usize = 4;
    const RESCALE_ROWS: usize = 4;

    // SAFETY (every method): SSE2 is part of every x86-64 CPU.
    #[inline(always)]
    fn splat(x: f64) -> Self {
        Self(unsafe { _mm_set1_ps(x as f32) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(unsafe { _mm_sqrt_ps(self.0) })
    }
    /// As [`Lanes32`]'s: each lane widened to `f64` (exact) and checked (out of the hot path).
    #[inline(always)]
    fn outside(self, low: u64, span: u64) -> __m128i {
        let flags = Lanes32::from(self).outside(low, span).map(|f| -(f as i32));
        unsafe { _mm_loadu_si128(flags.as_ptr().cast()) }
    }
    #[inline(always)]
    fn none() -> __m128i {
        unsafe { _mm_setzero_si128() }
    }
    #[inline(always)]
    fn or(a: __m128i, b: __m128i) -> __m128i {
        unsafe { _mm_or_si128(a, b) }
    }
    #[inline(always)]
    fn any(mask: __m128i) -> bool {
        unsafe { _mm_movemask_epi8(mask) != 0 }
    }
    #[inline(always)]
    fn all(mask: __m128i) -> bool {
        unsafe { _mm_movemask_ps(_mm_castsi128_ps(mask)) == 0xf }
    }
    #[inline(always)]
    fn select(mask: __m128i, a: Self, b: Self) -> Self {
        let mask = unsafe { _mm_castsi128_ps(mask) };
        Self(unsafe { _mm_or_ps(_mm_and_ps(mask, a.0), _mm_andnot_ps(mask, b.0)) })
    }
    /// `f32`'s normalizer (as [`Lanes32`]'s) on the lanes' bit patterns.
    #[inline(always)]
    fn normalizer(self) -> Self {
        unsafe {
            let exponent = _mm_set1_epi32(0xff);
            let biased = _mm_and_si128(_mm_srli_epi32::<23>(_mm_castps_si128(self.0)), exponent);
            let inverse = _mm_and_si128(_mm_sub_epi32(_mm_set1_epi32(254), biased), exponent);
            Self(_mm_castsi128_ps(_mm_slli_epi32::<23>(inverse)))
        }
    }
    /// `b − low > span` on the lanes' `f32` bit patterns, with [`CONTINUANT_RANGE_32`]: both
    /// sides with their top bit flipped, then SSE2's signed comparison.
    #[inline(always)]
    fn continuant_outside(self) -> __m128i {
        let (low, span) = CONTINUANT_RANGE_32;
        unsafe {
            let top = _mm_set1_epi32(i32::MIN);
            let offset = _mm_sub_epi32(_mm_castps_si128(self.0), _mm_set1_epi32(low as i32));
            _mm_cmpgt_epi32(_mm_xor_si128(offset, top), _mm_set1_epi32((span ^ (1 << 31)) as i32))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each operation of `Avx4`, lane by lane, against `f64`'s, compiled for AVX2.
    #[target_feature(enable = "avx2")]
    fn compare(a: [f64; 4], b: [f64; 4]) {
        let (x, y) = (Avx4::from(Lanes(a)), Avx4::from(Lanes(b)));
        let bits = |v: Avx4| Lanes::from(v).0.map(f64::to_bits);
        let each = |f: fn(f64, f64) -> f64| std::array::from_fn::<u64, 4, _>(|k| f(a[k], b[k]).to_bits());
        assert_eq!(bits(x + y), each(|a, b| a + b));
        assert_eq!(bits(x - y), each(|a, b| a - b));
        assert_eq!(bits(x * y), each(|a, b| a * b));
        assert_eq!(bits(x / y), each(|a, b| a / b));
        assert_eq!(bits(-x), each(|a, _| -a));
        assert_eq!(bits(x.sqrt()), each(|a, _| a.sqrt()));
        assert_eq!(bits(x.normalizer()), each(|a, _| a.normalizer()));
        let (low, span) = CONTINUANT_RANGE;
        let flags = |m: __m256i| {
            let mut out = [0u64; 4];
            // SAFETY: writes the four lanes of `out`.
            unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), m) };
            out.map(|f| f != 0)
        };
        let outside = flags(x.continuant_outside());
        assert_eq!(outside, a.map(|v| v.outside(low, span)));
        assert_eq!(Avx4::any(x.continuant_outside()), outside.contains(&true));
        assert_eq!(Avx4::all(x.continuant_outside()), !outside.contains(&false));
        assert!(Avx4::all(Avx4::splat(f64::NAN).continuant_outside()));
        assert!(!Avx4::any(Avx4::none()));
        let chosen = Lanes::from(Avx4::select(x.continuant_outside(), x, y)).0;
        for k in 0..4 {
            assert_eq!(chosen[k].to_bits(), if outside[k] { a[k] } else { b[k] }.to_bits());
        }
    }

    /// Each operation of `Sse4`, lane by lane, against `Lanes32`'s (which do each `f32`'s).
    fn compare_f32(a: [f32; 4], b: [f32; 4]) {
        let (x, y) = (Sse4::from(Lanes32(a)), Sse4::from(Lanes32(b)));
        let (u, v) = (Lanes32(a), Lanes32(b));
        let bits = |w: Lanes32<4>| w.0.map(f32::to_bits);
        let sse = |w: Sse4| bits(Lanes32::from(w));
        assert_eq!(sse(x + y), bits(u + v));
        assert_eq!(sse(x - y), bits(u - v));
        assert_eq!(sse(x * y), bits(u * v));
        assert_eq!(sse(x / y), bits(u / v));
        assert_eq!(sse(-x), bits(-u));
        assert_eq!(sse(x.sqrt()), bits(u.sqrt()));
        assert_eq!(sse(x.normalizer()), bits(u.normalizer()));
        assert_eq!(sse(Sse4::splat(0.1)), bits(Lanes32::splat(0.1)));
        let flags = |m: __m128i| {
            let mut out = [0u32; 4];
            // SAFETY: writes the four lanes of `out`.
            unsafe { _mm_storeu_si128(out.as_mut_ptr().cast(), m) };
            out.map(|f| f != 0)
        };
        let expected = u.continuant_outside().map(|f| f != 0);
        assert_eq!(flags(x.continuant_outside()), expected);
        let (low, span) = CONTINUANT_RANGE;
        assert_eq!(flags(x.outside(low, span)), u.outside(low, span).map(|f| f != 0));
        assert_eq!(Sse4::any(x.continuant_outside()), expected.contains(&true));
        assert_eq!(Sse4::all(x.continuant_outside()), !expected.contains(&false));
        assert!(Sse4::all(Sse4::splat(f64::NAN).continuant_outside()));
        assert!(!Sse4::any(Sse4::none()));
        let chosen = Lanes32::from(Sse4::select(x.continuant_outside(), x, y)).0;
        for k in 0..4 {
            assert_eq!(chosen[k].to_bits(), if expected[k] { a[k] } else { b[k] }.to_bits());
        }
    }

    #[test]
    fn sse_lanes_do_what_each_f32_does() {
        let cases = [
            ([1.5, -2.0, 3e-30, 7.0], [0.1, 3.0, 1e30, -0.0]),
            ([f32::NAN, 0.0, -1.0, 2f32.powi(90)], [1.0, 0.0, f32::INFINITY, 3.0]),
            ([2f32.powi(-80), 2f32.powi(80), 1e-40, -0.0], [2.0, 0.5, 1e-40, f32::MIN_POSITIVE]),
        ];
        for (a, b) in cases {
            compare_f32(a, b);
        }
    }

    #[test]
    fn avx_lanes_do_what_each_f64_does() {
        if !super::super::has_avx2() {
            return;
        }
        let cases = [
            ([1.5, -2.0, 3e-300, 7.0], [0.1, 3.0, 1e300, -0.0]),
            ([f64::NAN, 0.0, -1.0, 2f64.powi(900)], [1.0, 0.0, f64::INFINITY, 3.0]),
            ([2f64.powi(-800), 2f64.powi(800), 1e-310, -0.0], [2.0, 0.5, 1e-310, f64::MIN_POSITIVE]),
        ];
        for (a, b) in cases {
            // SAFETY: the CPU has AVX2, checked above.
            unsafe { compare(a, b) };
        }
    }
}
