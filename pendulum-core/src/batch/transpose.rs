//! The batch's two layouts: arrays chain by chain (`B` rows of `m`, as numpy holds them) and
//! lanes link by link (`m` groups of `W` chains). [`gather`] and [`scatter`] turn one into
//! the other in tiles of `W × W` numbers, transposed in registers (AVX2 shuffles for four
//! `f64` or eight `f32` lanes, when the CPU has AVX2; a plain loop otherwise). A copy: every
//! number arrives unchanged.

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

use super::has_avx2;

/// A number the batch transposes: with AVX2 shuffles where its width has them.
pub(crate) trait Transpose: Copy {
    /// `out[i][k] = rows[k][i]` with AVX2 shuffles, when the CPU has AVX2 and `W` is this
    /// number's width in one register; whether it did.
    #[inline(always)]
    fn transpose_simd<const W: usize>(_rows: &[&[Self; W]; W], _out: &mut [&mut [Self; W]; W]) -> bool {
        false
    }
}

impl Transpose for f64 {
    #[inline(always)]
    fn transpose_simd<const W: usize>(rows: &[&[f64; W]; W], out: &mut [&mut [f64; W]; W]) -> bool {
        #[cfg(target_arch = "x86_64")]
        if W == 4 && has_avx2() {
            // SAFETY: the CPU has AVX2; W = 4, so the pointers address four numbers each.
            unsafe { transpose_4x4(rows.map(|r| r.as_ptr()), out.each_mut().map(|o| o.as_mut_ptr())) };
            return true;
        }
        false
    }
}

impl Transpose for f32 {
    #[inline(always)]
    fn transpose_simd<const W: usize>(rows: &[&[f32; W]; W], out: &mut [&mut [f32; W]; W]) -> bool {
        #[cfg(target_arch = "x86_64")]
        if W == 8 && has_avx2() {
            // SAFETY: the CPU has AVX2; W = 8, so the pointers address eight numbers each.
            unsafe { transpose_8x8(rows.map(|r| r.as_ptr()), out.each_mut().map(|o| o.as_mut_ptr())) };
            return true;
        }
        false
    }
}

/// `out[i][k] = rows[k][i]`: a `W × W` tile transposed.
#[inline(always)]
fn transpose<T: Transpose, const W: usize>(rows: [&[T; W]; W], mut out: [&mut [T; W]; W]) {
    if T::transpose_simd(&rows, &mut out) {
        return;
    }
    for (k, row) in rows.iter().enumerate() {
        for (i, &v) in row.iter().enumerate() {
            out[i][k] = v;
        }
    }
}

/// `out[i][k] = rows[k][i]` for 4 × 4 `f64`: unpack pairs, then swap 128-bit halves.
///
/// # Safety
/// The CPU has AVX2; each pointer addresses `W` numbers (`rows` readable, `out` writable,
/// not overlapping `rows`), with `W` the length of the arrays.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn transpose_4x4<const W: usize>(rows: [*const f64; W], out: [*mut f64; W]) {
    // SAFETY: the caller's contract (W = 4 and the pointers valid for four numbers).
    unsafe {
        let load = |k: usize| _mm256_loadu_pd(rows[k]);
        let r = [load(0), load(1), load(2), load(3)];
        let (t0, t1) = (_mm256_unpacklo_pd(r[0], r[1]), _mm256_unpackhi_pd(r[0], r[1]));
        let (t2, t3) = (_mm256_unpacklo_pd(r[2], r[3]), _mm256_unpackhi_pd(r[2], r[3]));
        _mm256_storeu_pd(out[0], _mm256_permute2f128_pd::<0x20>(t0, t2));
        _mm256_storeu_pd(out[1], _mm256_permute2f128_pd::<0x20>(t1, t3));
        _mm256_storeu_pd(out[2], _mm256_permute2f128_pd::<0x31>(t0, t2));
        _mm256_storeu_pd(out[3], _mm256_permute2f128_pd::<0x31>(t1, t3));
    }
}

/// `out[i][k] = rows[k][i]` for 8 × 8 `f32`: unpack pairs, shuffle quads, swap 128-bit
/// halves.
///
/// # Safety
/// As [`transpose_4x4`], with eight numbers per pointer.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn transpose_8x8<const W: usize>(rows: [*const f32; W], out: [*mut f32; W]) {
    // SAFETY: the caller's contract (W = 8 and the pointers valid for eight numbers).
    unsafe {
        // No `array::from_fn` here: it was not inlined into this AVX2 function.
        let load = |k: usize| _mm256_loadu_ps(rows[k]);
        let r = [load(0), load(1), load(2), load(3), load(4), load(5), load(6), load(7)];
        let unpack = |a: usize| [_mm256_unpacklo_ps(r[a], r[a + 1]), _mm256_unpackhi_ps(r[a], r[a + 1])];
        let ([t0, t1], [t2, t3], [t4, t5], [t6, t7]) = (unpack(0), unpack(2), unpack(4), unpack(6));
        let quads = |a, b| [_mm256_shuffle_ps::<0x44>(a, b), _mm256_shuffle_ps::<0xEE>(a, b)];
        let ([u0, u1], [u2, u3], [u4, u5], [u6, u7]) =
            (quads(t0, t2), quads(t1, t3), quads(t4, t6), quads(t5, t7));
        let u = [u0, u1, u2, u3, u4, u5, u6, u7];
        for i in 0..4 {
            _mm256_storeu_ps(out[i], _mm256_permute2f128_ps::<0x20>(u[i], u[4 + i]));
            _mm256_storeu_ps(out[4 + i], _mm256_permute2f128_ps::<0x31>(u[i], u[4 + i]));
        }
    }
}

/// The block's chains turned link-major: `out[W·j + k] = v[m·rows[k] + j]` for the `m`
/// numbers `j` of each row `rows[k]` of `v` (`m` per row).
#[inline(always)]
pub(crate) fn gather<T: Transpose, const W: usize>(v: &[T], rows: [usize; W], m: usize, out: &mut [T]) {
    let rows: [&[T]; W] = rows.map(|r| &v[m * r..m * (r + 1)]);
    let mut tiles = out[..W * m].chunks_exact_mut(W * W);
    for (t, tile) in tiles.by_ref().enumerate() {
        transpose(rows.map(|row| as_array(&row[W * t..])), split(tile));
    }
    let done = m / W * W;
    for (j, out) in tiles.into_remainder().chunks_exact_mut(W).enumerate() {
        for (k, o) in out.iter_mut().enumerate() {
            *o = rows[k][done + j];
        }
    }
}

/// [`gather`] undone: row `k` of `out` (rows of `m`, at most `W` of them: a block's) gets
/// lane `k` of the `m` groups of `W` in `lanes`.
#[inline(always)]
pub(crate) fn scatter<T: Transpose, const W: usize>(lanes: &[T], m: usize, out: &mut [T]) {
    let lanes = &lanes[..W * m];
    if out.len() != W * m {
        for (k, row) in out.chunks_exact_mut(m).enumerate() {
            for (j, o) in row.iter_mut().enumerate() {
                *o = lanes[W * j + k];
            }
        }
        return;
    }
    let mut rows: [&mut [T]; W] = split_rows(out, m);
    let mut tiles = lanes.chunks_exact(W * W);
    for (t, tile) in tiles.by_ref().enumerate() {
        let tile: [&[T; W]; W] = std::array::from_fn(|i| as_array(&tile[W * i..]));
        let out = rows.each_mut().map(|row| as_array_mut(&mut row[W * t..]));
        transpose(tile, out);
    }
    let done = m / W * W;
    for (j, lanes) in tiles.remainder().chunks_exact(W).enumerate() {
        for (row, &v) in rows.iter_mut().zip(lanes) {
            row[done + j] = v;
        }
    }
}

/// The first `W` numbers of `v`.
#[inline(always)]
fn as_array<T, const W: usize>(v: &[T]) -> &[T; W] {
    v[..W].try_into().expect("W numbers")
}

/// The first `W` numbers of `v`, mutably.
#[inline(always)]
fn as_array_mut<T, const W: usize>(v: &mut [T]) -> &mut [T; W] {
    (&mut v[..W]).try_into().expect("W numbers")
}

/// A tile of `W·W` numbers as its `W` groups of `W`.
#[inline(always)]
fn split<T, const W: usize>(tile: &mut [T]) -> [&mut [T; W]; W] {
    split_rows(tile, W).map(as_array_mut)
}

/// `v` as `W` rows of `m` (it holds `W·m` numbers).
#[inline(always)]
fn split_rows<T, const W: usize>(v: &mut [T], m: usize) -> [&mut [T]; W] {
    let mut rest = v;
    std::array::from_fn(|_| {
        let (row, tail) = std::mem::take(&mut rest).split_at_mut(m);
        rest = tail;
        row
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every layout change is a copy, for both widths and precisions, whole tiles and a
    /// remainder, a full block and a short last one.
    fn round_trip<T: Transpose + From<u16> + PartialEq + std::fmt::Debug, const W: usize>() {
        for m in [1, W - 1, W, 2 * W + 3] {
            let chains = W + 2;
            let v: Vec<T> = (0..chains * m).map(|i| T::from(i as u16)).collect();
            let rows: [usize; W] = std::array::from_fn(|k| (k * 3 + 1) % chains);
            let mut lanes = vec![T::from(0); W * m];
            gather(&v, rows, m, &mut lanes);
            for j in 0..m {
                for k in 0..W {
                    assert_eq!(lanes[W * j + k], v[m * rows[k] + j], "m {m} j {j} k {k}");
                }
            }
            for short in [W, W - 1] {
                let mut out = vec![T::from(0); short * m];
                scatter::<T, W>(&lanes, m, &mut out);
                for k in 0..short {
                    assert_eq!(&out[k * m..(k + 1) * m], &v[m * rows[k]..m * (rows[k] + 1)], "m {m} k {k}");
                }
            }
        }
    }

    #[test]
    fn gather_and_scatter_copy_every_number_to_its_place() {
        round_trip::<f64, 4>();
        round_trip::<f32, 8>();
        round_trip::<f64, 2>();
        round_trip::<f32, 4>();
    }
}
