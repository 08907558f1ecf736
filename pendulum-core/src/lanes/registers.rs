//! Lanes held in one x86-64 vector register: [`Avx4`], four `f64` lanes in an AVX register,
//! [`Avx8`], eight in an AVX-512 register, and [`AvxF32`], eight `f32` lanes in an AVX
//! register. They are the lane types of the generated models' batch kernel on a CPU with
//! AVX2 (AVX-512 for [`Avx8`]).
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
//! its methods are `#[inline(always)]` intrinsics, inlined into that function. The same holds
//! for an [`AvxF32`], and for an [`Avx8`] and AVX-512 F. The types are private to the crate
//! for that reason.

use std::arch::x86_64::*;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub, SubAssign};

use super::{
    CONTINUANT_ENDS, CONTINUANT_ENDS_32, CONTINUANT_RANGE, CONTINUANT_RANGE_32, Lane, Lanes, Lanes32,
};

/// Four `f64` lanes, one AVX register (see the module's docs for where one may exist).
#[derive(Debug, Clone, Copy)]
#[repr(transparent)]
pub(crate) struct Avx4(__m256d);

/// Eight `f64` lanes, one AVX-512 register (see the module's docs for where one may exist).
#[derive(Debug, Clone, Copy)]
#[repr(transparent)]
pub(crate) struct Avx8(__m512d);

/// Eight `f32` lanes, one AVX register (see the module's docs for where one may exist).
#[derive(Debug, Clone, Copy)]
#[repr(transparent)]
pub(crate) struct AvxF32(__m256);

/// A register type's loads and stores from its lane array, arithmetic and negation, one
/// intrinsic each.
macro_rules! register_lanes {
    ($name:ident, $array:ident, $w:literal, $t:ty, $load:ident, $store:ident, $add:ident,
     $sub:ident, $mul:ident, $div:ident, $xor:ident, $set1:ident) => {
        impl From<$array<$w>> for $name {
            #[inline(always)]
            fn from(v: $array<$w>) -> Self {
                // SAFETY: an `Avx4` or an `AvxF32` is only made on a CPU with AVX2, an `Avx8`
                // on one with AVX-512 F (module docs); the load is unaligned and reads the
                // numbers of `v`.
                Self(unsafe { $load(v.0.as_ptr()) })
            }
        }

        impl From<$name> for $array<$w> {
            #[inline(always)]
            fn from(v: $name) -> Self {
                let mut out: [$t; $w] = [0.0; $w];
                // SAFETY: as in `from`; the store writes the numbers of `out`.
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
    4,
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
    Avx8,
    Lanes,
    8,
    f64,
    _mm512_loadu_pd,
    _mm512_storeu_pd,
    _mm512_add_pd,
    _mm512_sub_pd,
    _mm512_mul_pd,
    _mm512_div_pd,
    xor_512,
    _mm512_set1_pd
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
    #[inline(always)]
    fn abs(self) -> Self {
        Self(unsafe { _mm256_andnot_pd(_mm256_set1_pd(-0.0), self.0) })
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
    #[inline(always)]
    fn widen(self, [lowest, highest]: [Self; 2]) -> [Self; 2] {
        unsafe { [Self(_mm256_min_pd(lowest.0, self.0)), Self(_mm256_max_pd(highest.0, self.0))] }
    }
    /// Not `lowest ≥ 2⁻⁸⁰⁰` or not `highest ≤ 2⁸⁰⁰`, unordered comparisons (true for NaN).
    #[inline(always)]
    fn range_outside([lowest, highest]: [Self; 2]) -> __m256i {
        let [low, high] = CONTINUANT_ENDS;
        unsafe {
            let below = _mm256_cmp_pd::<_CMP_NGE_UQ>(lowest.0, _mm256_set1_pd(low));
            let above = _mm256_cmp_pd::<_CMP_NLE_UQ>(highest.0, _mm256_set1_pd(high));
            _mm256_castpd_si256(_mm256_or_pd(below, above))
        }
    }
}

register_lanes!(
    AvxF32,
    Lanes32,
    8,
    f32,
    _mm256_loadu_ps,
    _mm256_storeu_ps,
    _mm256_add_ps,
    _mm256_sub_ps,
    _mm256_mul_ps,
    _mm256_div_ps,
    _mm256_xor_ps,
    _mm256_set1_ps
);

/// `a` xor `b`, bit by bit (AVX-512 F has it for integers only: `_mm512_xor_pd` is DQ's).
#[inline(always)]
unsafe fn xor_512(a: __m512d, b: __m512d) -> __m512d {
    // SAFETY: the caller's (an `Avx8` exists only where AVX-512 F runs, module docs).
    unsafe { _mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(a), _mm512_castpd_si512(b))) }
}

impl Avx8 {
    /// Block `lanes[0]`'s four lanes, then `lanes[1]`'s.
    #[inline(always)]
    pub(crate) fn join(lanes: [Lanes<4>; 2]) -> Self {
        // SAFETY: as in `from`; each load reads the four numbers of one block.
        unsafe {
            let low = _mm512_castpd256_pd512(_mm256_loadu_pd(lanes[0].0.as_ptr()));
            Self(_mm512_insertf64x4::<1>(low, _mm256_loadu_pd(lanes[1].0.as_ptr())))
        }
    }

    /// The first four lanes and the last four, as [`join`](Self::join) took them.
    #[inline(always)]
    pub(crate) fn split(self) -> [Lanes<4>; 2] {
        let mut out = [Lanes([0.0; 4]); 2];
        // SAFETY: as in `from`; each store writes the four numbers of one block.
        unsafe {
            _mm256_storeu_pd(out[0].0.as_mut_ptr(), _mm512_castpd512_pd256(self.0));
            _mm256_storeu_pd(out[1].0.as_mut_ptr(), _mm512_extractf64x4_pd::<1>(self.0));
        }
        out
    }
}

impl Lane for Avx8 {
    /// One bit per lane, set in the flagged lanes.
    type Mask = __mmask8;
    const WIDTH: usize = 8;

    // SAFETY (every method): an `Avx8` exists only in code compiled for AVX-512 F on a CPU
    // that has it (module docs).
    #[inline(always)]
    fn splat(x: f64) -> Self {
        Self(unsafe { _mm512_set1_pd(x) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(unsafe { _mm512_sqrt_pd(self.0) })
    }
    /// The sign bit cleared as an integer `and` (AVX-512F; `_mm512_andnot_pd` wants DQ).
    #[inline(always)]
    fn abs(self) -> Self {
        Self(unsafe {
            _mm512_castsi512_pd(_mm512_and_si512(_mm512_castpd_si512(self.0), _mm512_set1_epi64(i64::MAX)))
        })
    }
    /// `b − low > span` as unsigned 64-bit integers (AVX-512 compares them as such).
    #[inline(always)]
    fn outside(self, low: u64, span: u64) -> __mmask8 {
        unsafe {
            let offset = _mm512_sub_epi64(_mm512_castpd_si512(self.0), _mm512_set1_epi64(low as i64));
            _mm512_cmpgt_epu64_mask(offset, _mm512_set1_epi64(span as i64))
        }
    }
    #[inline(always)]
    fn none() -> __mmask8 {
        0
    }
    #[inline(always)]
    fn or(a: __mmask8, b: __mmask8) -> __mmask8 {
        a | b
    }
    #[inline(always)]
    fn any(mask: __mmask8) -> bool {
        mask != 0
    }
    #[inline(always)]
    fn all(mask: __mmask8) -> bool {
        mask == 0xff
    }
    #[inline(always)]
    fn select(mask: __mmask8, a: Self, b: Self) -> Self {
        Self(unsafe { _mm512_mask_blend_pd(mask, b.0, a.0) })
    }
    /// `f64`'s [`normalizer`](Lane::normalizer) on the lanes' bit patterns.
    #[inline(always)]
    fn normalizer(self) -> Self {
        unsafe {
            let exponent = _mm512_set1_epi64(0x7ff);
            let biased = _mm512_and_si512(_mm512_srli_epi64::<52>(_mm512_castpd_si512(self.0)), exponent);
            let inverse = _mm512_and_si512(_mm512_sub_epi64(_mm512_set1_epi64(2046), biased), exponent);
            Self(_mm512_castsi512_pd(_mm512_slli_epi64::<52>(inverse)))
        }
    }
    #[inline(always)]
    fn widen(self, [lowest, highest]: [Self; 2]) -> [Self; 2] {
        unsafe { [Self(_mm512_min_pd(lowest.0, self.0)), Self(_mm512_max_pd(highest.0, self.0))] }
    }
    /// Not `lowest ≥ 2⁻⁸⁰⁰` or not `highest ≤ 2⁸⁰⁰`, unordered comparisons (true for NaN).
    #[inline(always)]
    fn range_outside([lowest, highest]: [Self; 2]) -> __mmask8 {
        let [low, high] = CONTINUANT_ENDS;
        unsafe {
            _mm512_cmp_pd_mask::<_CMP_NGE_UQ>(lowest.0, _mm512_set1_pd(low))
                | _mm512_cmp_pd_mask::<_CMP_NLE_UQ>(highest.0, _mm512_set1_pd(high))
        }
    }
}

impl AvxF32 {
    /// Block `lanes[0]`'s four lanes, then `lanes[1]`'s.
    #[inline(always)]
    pub(crate) fn join(lanes: [Lanes32<4>; 2]) -> Self {
        // SAFETY: as in `from`; each load reads the four numbers of one block.
        unsafe { Self(_mm256_set_m128(_mm_loadu_ps(lanes[1].0.as_ptr()), _mm_loadu_ps(lanes[0].0.as_ptr()))) }
    }

    /// The first four lanes and the last four, as [`join`](Self::join) took them.
    #[inline(always)]
    pub(crate) fn split(self) -> [Lanes32<4>; 2] {
        let mut out = [Lanes32([0.0; 4]); 2];
        // SAFETY: as in `from`; each store writes the four numbers of one block.
        unsafe {
            _mm_storeu_ps(out[0].0.as_mut_ptr(), _mm256_castps256_ps128(self.0));
            _mm_storeu_ps(out[1].0.as_mut_ptr(), _mm256_extractf128_ps::<1>(self.0));
        }
        out
    }
}

impl Lane for AvxF32 {
    /// All ones in the flagged lanes, zeros in the others.
    type Mask = __m256i;
    const WIDTH: usize = 8;
    const RESCALE_ROWS: usize = 4;

    // SAFETY (every method): an `AvxF32` exists only in code compiled for AVX2 on a CPU
    // that has it (module docs).
    #[inline(always)]
    fn splat(x: f64) -> Self {
        Self(unsafe { _mm256_set1_ps(x as f32) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(unsafe { _mm256_sqrt_ps(self.0) })
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Self(unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0) })
    }
    /// As [`Lanes32`]'s: each lane widened to `f64` (exact) and checked (out of the hot path).
    #[inline(always)]
    fn outside(self, low: u64, span: u64) -> __m256i {
        let flags = Lanes32::<8>::from(self).outside(low, span).map(|f| -(f as i32));
        unsafe { _mm256_loadu_si256(flags.as_ptr().cast()) }
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
        unsafe { _mm256_movemask_ps(_mm256_castsi256_ps(mask)) == 0xff }
    }
    #[inline(always)]
    fn select(mask: __m256i, a: Self, b: Self) -> Self {
        Self(unsafe { _mm256_blendv_ps(b.0, a.0, _mm256_castsi256_ps(mask)) })
    }
    /// `f32`'s normalizer (as [`Lanes32`]'s) on the lanes' bit patterns.
    #[inline(always)]
    fn normalizer(self) -> Self {
        unsafe {
            let exponent = _mm256_set1_epi32(0xff);
            let biased = _mm256_and_si256(_mm256_srli_epi32::<23>(_mm256_castps_si256(self.0)), exponent);
            let inverse = _mm256_and_si256(_mm256_sub_epi32(_mm256_set1_epi32(254), biased), exponent);
            Self(_mm256_castsi256_ps(_mm256_slli_epi32::<23>(inverse)))
        }
    }
    /// `b − low > span` on the lanes' `f32` bit patterns, with [`CONTINUANT_RANGE_32`]: both
    /// sides with their top bit flipped, then AVX2's signed comparison.
    #[inline(always)]
    fn continuant_outside(self) -> __m256i {
        let (low, span) = CONTINUANT_RANGE_32;
        unsafe {
            let top = _mm256_set1_epi32(i32::MIN);
            let offset = _mm256_sub_epi32(_mm256_castps_si256(self.0), _mm256_set1_epi32(low as i32));
            _mm256_cmpgt_epi32(_mm256_xor_si256(offset, top), _mm256_set1_epi32((span ^ (1 << 31)) as i32))
        }
    }
    #[inline(always)]
    fn widen(self, [lowest, highest]: [Self; 2]) -> [Self; 2] {
        unsafe { [Self(_mm256_min_ps(lowest.0, self.0)), Self(_mm256_max_ps(highest.0, self.0))] }
    }
    /// Not `lowest ≥ 2⁻⁸⁰` or not `highest ≤ 2⁸⁰`, unordered comparisons (true for NaN).
    #[inline(always)]
    fn range_outside([lowest, highest]: [Self; 2]) -> __m256i {
        let [low, high] = CONTINUANT_ENDS_32;
        unsafe {
            let below = _mm256_cmp_ps::<_CMP_NGE_UQ>(lowest.0, _mm256_set1_ps(low));
            let above = _mm256_cmp_ps::<_CMP_NLE_UQ>(highest.0, _mm256_set1_ps(high));
            _mm256_castps_si256(_mm256_or_ps(below, above))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each operation of the `f64` register lanes `V` (`W` of them), lane by lane, against
    /// `f64`'s; inlined into a caller compiled for `V`'s instructions.
    #[inline(always)]
    fn compare<V: Lane + From<Lanes<W>> + Into<Lanes<W>>, const W: usize>(a: [f64; W], b: [f64; W]) {
        let (x, y) = (V::from(Lanes(a)), V::from(Lanes(b)));
        let bits = |v: V| v.into().0.map(f64::to_bits);
        let each = |f: fn(f64, f64) -> f64| std::array::from_fn::<u64, W, _>(|k| f(a[k], b[k]).to_bits());
        assert_eq!(bits(x + y), each(|a, b| a + b));
        assert_eq!(bits(x - y), each(|a, b| a - b));
        assert_eq!(bits(x * y), each(|a, b| a * b));
        assert_eq!(bits(x / y), each(|a, b| a / b));
        assert_eq!(bits(-x), each(|a, _| -a));
        assert_eq!(bits(x.sqrt()), each(|a, _| a.sqrt()));
        assert_eq!(bits(x.abs()), each(|a, _| a.abs()));
        assert_eq!(bits(x.normalizer()), each(|a, _| a.normalizer()));
        let (low, span) = CONTINUANT_RANGE;
        let flags = |m: V::Mask| V::select(m, V::splat(1.0), V::splat(0.0)).into().0.map(|f| f == 1.0);
        let outside = flags(x.continuant_outside());
        assert_eq!(outside, a.map(|v| v.outside(low, span)));
        let [lowest, highest] = x.widen([y, y]);
        assert_eq!(bits(lowest), each(|a, b| a.widen([b, b])[0]));
        assert_eq!(bits(highest), each(|a, b| a.widen([b, b])[1]));
        let range = flags(V::range_outside([x, y]));
        assert_eq!(range, std::array::from_fn(|k| f64::range_outside([a[k], b[k]])));
        assert_eq!(V::any(x.continuant_outside()), outside.contains(&true));
        assert_eq!(V::all(x.continuant_outside()), !outside.contains(&false));
        assert!(V::all(V::splat(f64::NAN).continuant_outside()));
        assert!(!V::any(V::none()));
        assert!(!flags(V::or(V::none(), V::none())).contains(&true));
        assert_eq!(flags(V::or(x.continuant_outside(), V::none())), outside);
    }

    /// [`compare`] of [`Avx4`], compiled for AVX2.
    #[target_feature(enable = "avx2")]
    fn compare_avx4(a: [f64; 4], b: [f64; 4]) {
        compare::<Avx4, 4>(a, b)
    }

    /// [`compare`] of [`Avx8`], compiled for AVX-512 F, and its blocks joined and split.
    #[target_feature(enable = "avx2,avx512f")]
    fn compare_avx8(a: [f64; 8], b: [f64; 8]) {
        compare::<Avx8, 8>(a, b);
        let halves =
            |v: [f64; 8]| [Lanes(std::array::from_fn(|k| v[k])), Lanes(std::array::from_fn(|k| v[4 + k]))];
        let joined = Lanes::<8>::from(Avx8::join(halves(a))).0;
        assert_eq!(joined.map(f64::to_bits), a.map(f64::to_bits));
        assert_eq!(
            Avx8::from(Lanes(b)).split().map(|h| h.0.map(f64::to_bits)),
            halves(b).map(|h| h.0.map(f64::to_bits))
        );
    }

    /// Each operation of the `f32` register lanes `V` (`W` of them), lane by lane, against
    /// `Lanes32`'s (which do each `f32`'s); inlined into a caller compiled for `V`'s
    /// instructions.
    #[inline(always)]
    fn compare_f32<V: Lane + From<Lanes32<W>> + Into<Lanes32<W>>, const W: usize>(a: [f32; W], b: [f32; W]) {
        let (x, y) = (V::from(Lanes32(a)), V::from(Lanes32(b)));
        let (u, v) = (Lanes32(a), Lanes32(b));
        let bits = |w: Lanes32<W>| w.0.map(f32::to_bits);
        let reg = |w: V| bits(w.into());
        assert_eq!(reg(x + y), bits(u + v));
        assert_eq!(reg(x - y), bits(u - v));
        assert_eq!(reg(x * y), bits(u * v));
        assert_eq!(reg(x / y), bits(u / v));
        assert_eq!(reg(-x), bits(-u));
        assert_eq!(reg(x.sqrt()), bits(u.sqrt()));
        assert_eq!(reg(x.abs()), bits(u.abs()));
        assert_eq!(reg(x.normalizer()), bits(u.normalizer()));
        assert_eq!(reg(V::splat(0.1)), bits(Lanes32::splat(0.1)));
        let flags = |m: V::Mask| V::select(m, V::splat(1.0), V::splat(0.0)).into().0.map(|f| f == 1.0);
        let expected = u.continuant_outside().map(|f| f != 0);
        assert_eq!(flags(x.continuant_outside()), expected);
        let (low, span) = CONTINUANT_RANGE;
        assert_eq!(flags(x.outside(low, span)), u.outside(low, span).map(|f| f != 0));
        assert_eq!(V::any(x.continuant_outside()), expected.contains(&true));
        assert_eq!(V::all(x.continuant_outside()), !expected.contains(&false));
        assert!(V::all(V::splat(f64::NAN).continuant_outside()));
        assert!(!V::any(V::none()));
        assert_eq!(flags(V::or(x.continuant_outside(), V::none())), expected);
        let [lowest, highest] = x.widen([y, y]);
        assert_eq!(reg(lowest), bits(u.widen([v, v])[0]));
        assert_eq!(reg(highest), bits(u.widen([v, v])[1]));
        assert_eq!(flags(V::range_outside([x, y])), Lanes32::range_outside([u, v]).map(|f| f != 0));
    }

    /// [`compare_f32`] of [`AvxF32`], compiled for AVX2, and its blocks joined and split.
    #[target_feature(enable = "avx2")]
    fn compare_avx_f32(a: [f32; 8], b: [f32; 8]) {
        compare_f32::<AvxF32, 8>(a, b);
        let halves = |v: [f32; 8]| {
            [Lanes32(std::array::from_fn(|k| v[k])), Lanes32(std::array::from_fn(|k| v[4 + k]))]
        };
        assert_eq!(Lanes32::<8>::from(AvxF32::join(halves(a))).0.map(f32::to_bits), a.map(f32::to_bits));
        let split = AvxF32::from(Lanes32(b)).split().map(|h| h.0.map(f32::to_bits));
        assert_eq!(split, halves(b).map(|h| h.0.map(f32::to_bits)));
    }

    #[test]
    fn avx_lanes_do_what_each_f32_does() {
        let cases = [
            ([1.5, -2.0, 3e-30, 7.0], [0.1, 3.0, 1e30, -0.0]),
            ([f32::NAN, 0.0, -1.0, 2f32.powi(90)], [1.0, 0.0, f32::INFINITY, 3.0]),
            ([2f32.powi(-80), 2f32.powi(80), 1e-40, -0.0], [2.0, 0.5, 1e-40, f32::MIN_POSITIVE]),
        ];
        if !super::super::has_avx2() {
            return;
        }
        for (a, b) in cases {
            for (c, d) in cases {
                let eight =
                    |u: [f32; 4], v: [f32; 4]| std::array::from_fn(|k| if k < 4 { u[k] } else { v[k - 4] });
                // SAFETY: the CPU has AVX2, checked above.
                unsafe { compare_avx_f32(eight(a, c), eight(b, d)) };
            }
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
            unsafe { compare_avx4(a, b) };
        }
        if !super::super::has_avx512() {
            return;
        }
        // Each case beside each other (and itself): every lane of the eight seen in both halves.
        for (a, b) in cases {
            for (c, d) in cases {
                let eight =
                    |u: [f64; 4], v: [f64; 4]| std::array::from_fn(|k| if k < 4 { u[k] } else { v[k - 4] });
                // SAFETY: the CPU has AVX-512 F, checked above.
                unsafe { compare_avx8(eight(a, c), eight(b, d)) };
            }
        }
    }
}
