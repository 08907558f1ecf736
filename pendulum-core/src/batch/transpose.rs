//! The batch's two layouts: arrays chain by chain (`B` rows of `m`, as numpy holds them) and
//! lanes link by link (`m` groups of `W` chains). [`gather`] and [`scatter`] turn one into
//! the other in tiles of `W × W` numbers, transposed in registers (AVX2 shuffles for four
//! or eight `f64` or eight `f32` lanes, when the CPU has AVX2; a plain loop otherwise). A copy: every
//! number arrives unchanged.
//!
//! The tiles are addressed by pointers set in plain loops: arrays of slices built with
//! `array::map` were a function call per tile, not inlined (`perf`: a tenth of a 3D call).

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

use crate::lanes::has_avx2;

/// A number the batch transposes: with AVX2 shuffles where its width has them.
pub(crate) trait Transpose: Copy {
    /// Whether [`transpose_simd`](Self::transpose_simd) serves `W × W` tiles on this CPU.
    #[inline(always)]
    fn has_simd<const W: usize>() -> bool {
        false
    }

    /// `dst[i][k] = src[k][i]` for a `W × W` tile, with AVX2 shuffles.
    ///
    /// # Safety
    /// [`has_simd::<W>`](Self::has_simd) is true; each `src[k]` is readable and each
    /// `dst[i]` writable for `W` numbers, and they do not overlap.
    #[inline(always)]
    unsafe fn transpose_simd<const W: usize>(_src: [*const Self; W], _dst: [*mut Self; W]) {
        unreachable!("no SIMD transpose for this width")
    }
}

impl Transpose for f64 {
    #[inline(always)]
    fn has_simd<const W: usize>() -> bool {
        cfg!(target_arch = "x86_64") && (W == 4 || W == 8) && has_avx2()
    }

    #[inline(always)]
    #[cfg_attr(not(target_arch = "x86_64"), allow(unused_variables))]
    unsafe fn transpose_simd<const W: usize>(src: [*const f64; W], dst: [*mut f64; W]) {
        // SAFETY: the caller's contract: AVX2, W = 4 or 8, valid pointers. An 8 × 8 tile
        // is four 4 × 4 ones: quarter (a, b) of `src` goes to quarter (b, a) of `dst`.
        #[cfg(target_arch = "x86_64")]
        unsafe {
            if W == 4 {
                return transpose_4x4(src, dst);
            }
            for a in [0, 4] {
                for b in [0, 4] {
                    let rows = [src[a].add(b), src[a + 1].add(b), src[a + 2].add(b), src[a + 3].add(b)];
                    let out = [dst[b].add(a), dst[b + 1].add(a), dst[b + 2].add(a), dst[b + 3].add(a)];
                    transpose_4x4(rows, out);
                }
            }
        };
    }
}

impl Transpose for f32 {
    #[inline(always)]
    fn has_simd<const W: usize>() -> bool {
        cfg!(target_arch = "x86_64") && W == 8 && has_avx2()
    }

    #[inline(always)]
    #[cfg_attr(not(target_arch = "x86_64"), allow(unused_variables))]
    unsafe fn transpose_simd<const W: usize>(src: [*const f32; W], dst: [*mut f32; W]) {
        // SAFETY: the caller's contract: AVX2, W = 8, valid pointers.
        #[cfg(target_arch = "x86_64")]
        unsafe {
            transpose_8x8(src, dst)
        };
    }
}

/// `dst[i][k] = src[k][i]`: a `W × W` tile transposed, with AVX2 when `simd`.
///
/// # Safety
/// As [`Transpose::transpose_simd`], with `simd` only if `T::has_simd::<W>()`.
#[inline(always)]
unsafe fn transpose<T: Transpose, const W: usize>(simd: bool, src: [*const T; W], dst: [*mut T; W]) {
    // SAFETY: the caller's contract.
    unsafe {
        if simd {
            return T::transpose_simd(src, dst);
        }
        for (k, &row) in src.iter().enumerate() {
            for (i, &out) in dst.iter().enumerate() {
                *out.add(k) = *row.add(i);
            }
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
    let mut starts = [v.as_ptr(); W];
    for (start, &r) in starts.iter_mut().zip(&rows) {
        *start = v[m * r..m * (r + 1)].as_ptr();
    }
    // SAFETY: each start is a row of `m` numbers of `v`, which `out` (borrowed mutably)
    // does not overlap.
    unsafe { gather_from(starts, m, out) };
}

/// [`gather`] from `W` rows anywhere: `out[W·j + k] = rows[k][j]` for `j < m`.
#[inline(always)]
pub(crate) fn gather_rows<T: Transpose, const W: usize>(rows: [&[T]; W], m: usize, out: &mut [T]) {
    let mut starts = [out.as_ptr(); W];
    for (start, row) in starts.iter_mut().zip(&rows) {
        *start = row[..m].as_ptr();
    }
    // SAFETY: each start is a row of `m` numbers, apart from `out` (borrowed mutably).
    unsafe { gather_from(starts, m, out) };
}

/// `out[W·j + k] = *starts[k].add(j)` for `j < m`, in `W × W` tiles.
///
/// # Safety
/// Each `starts[k]` is readable for `m` numbers, none of which are in `out`.
#[inline(always)]
unsafe fn gather_from<T: Transpose, const W: usize>(starts: [*const T; W], m: usize, out: &mut [T]) {
    let out = &mut out[..W * m];
    let (simd, tiles) = (T::has_simd::<W>(), m / W);
    for t in 0..tiles {
        let mut src = starts;
        let mut dst = [out.as_mut_ptr(); W];
        for (i, (s, d)) in src.iter_mut().zip(&mut dst).enumerate() {
            // SAFETY: `W·(t + 1) ≤ m`, so `s` stays in its row of `m` and `d` in `out`'s `W·m`.
            unsafe {
                *s = s.add(W * t);
                *d = d.add(W * W * t + W * i);
            }
        }
        // SAFETY: `src` reads W numbers of W rows, `dst` writes the tile `W·W·t..W·W·(t + 1)`
        // of `out`, apart from them (the caller's contract); `simd` as checked.
        unsafe { transpose(simd, src, dst) };
    }
    for j in W * tiles..m {
        for (k, start) in starts.iter().enumerate() {
            // SAFETY: `j < m` (the caller's contract).
            out[W * j + k] = unsafe { *start.add(j) };
        }
    }
}

/// [`gather`] undone: row `k` of `out` (rows of `m`, at most `W` of them: a block's) gets
/// lane `k` of the `m` groups of `W` in `lanes`.
#[inline(always)]
pub(crate) fn scatter<T: Transpose, const W: usize>(lanes: &[T], m: usize, out: &mut [T]) {
    if out.len() != W * m {
        let lanes = &lanes[..W * m];
        for (k, row) in out.chunks_exact_mut(m).enumerate() {
            for (j, o) in row.iter_mut().enumerate() {
                *o = lanes[W * j + k];
            }
        }
        return;
    }
    let mut starts = [out.as_mut_ptr(); W];
    for (k, start) in starts.iter_mut().enumerate() {
        // SAFETY: `out` holds `W` rows of `m`.
        *start = unsafe { start.add(m * k) };
    }
    // SAFETY: the `W` rows of `out`, each of `m` numbers, apart from `lanes` (`out` is
    // borrowed mutably).
    unsafe { scatter_into(lanes, m, starts) };
}

/// Row `i` of an `n × n` matrix per lane into the matrices of `out` (at most `W` of them:
/// a block's, `n²` numbers each, row by row as numpy holds a `(B, n, n)` array): numbers
/// `i·n … i·n + n − 1` of matrix `k` get lane `k` of the `n` groups of `W` in `lanes`.
#[inline(always)]
pub(crate) fn scatter_matrix_row<T: Transpose, const W: usize>(
    lanes: &[T],
    n: usize,
    i: usize,
    out: &mut [T],
) {
    if out.len() != W * n * n {
        for (k, matrix) in out.chunks_exact_mut(n * n).enumerate() {
            for (j, o) in matrix[i * n..(i + 1) * n].iter_mut().enumerate() {
                *o = lanes[W * j + k];
            }
        }
        return;
    }
    let mut starts = [out.as_mut_ptr(); W];
    for (k, start) in starts.iter_mut().enumerate() {
        // SAFETY: `out` holds `W` matrices of `n²`, and `i < n`.
        *start = unsafe { start.add(n * n * k + n * i) };
    }
    // SAFETY: row `i` of each of the `W` matrices of `out`, `n` numbers each, apart from
    // each other and from `lanes` (`out` is borrowed mutably).
    unsafe { scatter_into(lanes, n, starts) };
}

/// [`scatter`] into `W` rows anywhere: `rows[k][j] = lanes[W·j + k]` for `j < m`.
#[inline(always)]
pub(crate) fn scatter_rows<T: Transpose, const W: usize>(lanes: &[T], m: usize, mut rows: [&mut [T]; W]) {
    let mut starts = [std::ptr::null_mut(); W];
    for (start, row) in starts.iter_mut().zip(&mut rows) {
        *start = row[..m].as_mut_ptr();
    }
    // SAFETY: each start is a row of `m` numbers, borrowed mutably (apart from `lanes` and
    // from each other).
    unsafe { scatter_into(lanes, m, starts) };
}

/// [`scatter_rows`] into the rows given, `None` for a lane left out: by the tiles for a
/// whole set of `W`, number by number otherwise.
#[inline(always)]
pub(crate) fn scatter_some_rows<T: Transpose, const W: usize>(
    lanes: &[T],
    m: usize,
    rows: [Option<&mut [T]>; W],
) {
    if rows.iter().all(Option::is_some) {
        scatter_rows(lanes, m, rows.map(|row| row.expect("every row")));
        return;
    }
    for (k, row) in rows.into_iter().enumerate() {
        for (j, o) in row.into_iter().flat_map(|row| &mut row[..m]).enumerate() {
            *o = lanes[W * j + k];
        }
    }
}

/// `*starts[k].add(j) = lanes[W·j + k]` for `j < m`, in `W × W` tiles.
///
/// # Safety
/// Each `starts[k]` is writable for `m` numbers, apart from each other and from `lanes`.
#[inline(always)]
unsafe fn scatter_into<T: Transpose, const W: usize>(lanes: &[T], m: usize, starts: [*mut T; W]) {
    let lanes = &lanes[..W * m];
    let (simd, tiles) = (T::has_simd::<W>(), m / W);
    for t in 0..tiles {
        let mut src = [lanes.as_ptr(); W];
        let mut dst = starts;
        for (k, (s, d)) in src.iter_mut().zip(&mut dst).enumerate() {
            // SAFETY: `W·(t + 1) ≤ m`: `s` stays in `lanes`' `W·m`, `d` in row `k`'s `m`.
            unsafe {
                *s = s.add(W * W * t + W * k);
                *d = d.add(W * t);
            }
        }
        // SAFETY: `src` reads the tile `W·W·t..W·W·(t + 1)` of `lanes`, `dst` writes W numbers
        // of each of the W rows (the caller's contract).
        unsafe { transpose(simd, src, dst) };
    }
    for j in W * tiles..m {
        for (k, start) in starts.iter().enumerate() {
            // SAFETY: `j < m` (the caller's contract).
            unsafe { *start.add(j) = lanes[W * j + k] };
        }
    }
}

/// `dst[a·n + b] = src[b·n + a]`: an `n × n` matrix stored column by column (nalgebra's
/// order) into `dst` row by row (numpy's), in 4 × 4 tiles transposed with AVX2 where the CPU
/// has it (the whole loop compiled for it, so that each tile is inlined), the edges number
/// by number.
pub(crate) fn transpose_square(src: &[f64], n: usize, dst: &mut [f64]) {
    assert!(src.len() >= n * n && dst.len() >= n * n, "two matrices of {n} × {n}");
    #[cfg(target_arch = "x86_64")]
    if has_avx2() {
        // SAFETY: the CPU has AVX2, checked just above.
        return unsafe { transpose_square_avx2(src, n, dst) };
    }
    transpose_square_tiles(false, src, n, dst)
}

/// [`transpose_square_tiles`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn transpose_square_avx2(src: &[f64], n: usize, dst: &mut [f64]) {
    transpose_square_tiles(true, src, n, dst)
}

/// The body of [`transpose_square`], with AVX2 shuffles when `simd`: tile `(r, c)` has
/// columns `c..c + 4` of `src` from row `r`, and goes to rows `r..r + 4` of `dst` from
/// column `c`.
#[inline(always)]
fn transpose_square_tiles(simd: bool, src: &[f64], n: usize, dst: &mut [f64]) {
    const W: usize = 4;
    let (src, dst) = (&src[..n * n], &mut dst[..n * n]);
    let whole = n - n % W;
    for r in (0..whole).step_by(W) {
        for c in (0..whole).step_by(W) {
            let mut from = [src.as_ptr(); W];
            let mut to = [dst.as_mut_ptr(); W];
            for k in 0..W {
                // SAFETY: `r + 3` and `c + 3` are below `n`: both stay in their n² numbers.
                unsafe {
                    from[k] = from[k].add((c + k) * n + r);
                    to[k] = to[k].add((r + k) * n + c);
                }
            }
            // SAFETY: each pointer addresses four numbers of its matrix; `src` and `dst` are
            // apart (`dst` borrowed mutably); `simd` only where the caller checked AVX2.
            unsafe { transpose(simd, from, to) };
        }
    }
    for a in 0..n {
        let from = if a < whole { whole } else { 0 };
        for b in from..n {
            dst[a * n + b] = src[b * n + a];
        }
    }
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
            // Into rows anywhere: all of them, or some (the others untouched).
            for skip in [None, Some(1)] {
                let mut out = vec![T::from(999); W * m];
                let mut chunks = out.chunks_exact_mut(m);
                let some: [Option<&mut [T]>; W] =
                    std::array::from_fn(|k| chunks.next().filter(|_| Some(k) != skip));
                scatter_some_rows(&lanes, m, some);
                for (k, row) in out.chunks_exact(m).enumerate() {
                    let expected: Vec<T> = match Some(k) == skip {
                        true => vec![T::from(999); m],
                        false => v[m * rows[k]..m * (rows[k] + 1)].to_vec(),
                    };
                    assert_eq!(row, &expected[..], "m {m} k {k} skip {skip:?}");
                }
            }
        }
    }

    #[test]
    fn gather_and_scatter_copy_every_number_to_its_place() {
        round_trip::<f64, 4>();
        round_trip::<f64, 8>();
        round_trip::<f32, 8>();
        round_trip::<f64, 2>();
        round_trip::<f32, 4>();
    }

    #[test]
    fn a_square_matrix_turns_from_columns_to_rows() {
        for n in [1, 3, 4, 5, 8, 11, 20] {
            let src: Vec<f64> = (0..n * n).map(|i| i as f64).collect();
            let mut dst = vec![f64::NAN; n * n];
            transpose_square(&src, n, &mut dst);
            for a in 0..n {
                for b in 0..n {
                    assert_eq!(dst[a * n + b], src[b * n + a], "n {n}: ({a}, {b})");
                }
            }
        }
    }
}
