//! `sin θ` and `cos θ` in single precision for a whole array of angles: the sines of the
//! batch's `f32` lanes (`pendulum_core::batch::UnrolledBatch::accelerations_f32`).
//!
//! Cephes' `sinf`/`cosf` (S. L. Moshier), branch-free so that the compiler runs eight
//! angles per AVX2 instruction: θ (rad) reduced by π/4 in three pieces,
//! ```text
//! j = 2 ⌈⌊|θ| · 4/π⌋ / 2⌉,   r = ((|θ| − j D₁) − j D₂) − j D₃,   |r| ≤ π/4
//! sin r ≈ r + r z (S₀ + z (S₁ + z S₂)),   cos r ≈ 1 − z/2 + z² (C₀ + z (C₁ + z C₂)),   z = r²
//! ```
//! (`D₁ + D₂ + D₃ = π/4`, `D₁` and `D₂` short enough that `j D₁`, `j D₂` are exact), then
//! the quadrant `j/2 mod 4` picks `±sin r` or `±cos r`. Within 2 × 10⁻⁷ of the exact
//! values for `|θ| ≤ 8192` (module tests); beyond, and for non-finite θ, `f64::sin_cos`
//! rounded to `f32`.

use super::trig::split_with;

/// Beyond this `|θ|` (rad) the reduction loses digits: `f64::sin_cos` instead.
const LIMIT: f32 = 8192.0;

/// The AVX-512 loop runs 32 angles a turn and the rest one by one: below 32 angles it is
/// slower than the AVX2 loop (the generated models' `f32` batch at n = 4, sixteen angles a
/// block, lost 17% with it), from 32 on faster (`docs/ensembles.md`).
const AVX512_FROM: usize = 32;

const FOUR_OVER_PI: f32 = 1.273_239_5;
// π/4 = D1 + D2 + D3 (Cephes' DP1, DP2, DP3).
const D1: f32 = 0.785_156_25;
const D2: f32 = 2.418_756_5e-4;
const D3: f32 = 3.774_895e-8;
// sin r ≈ r + r z (S0 + z (S1 + z S2)), Cephes' sinf.
const S0: f32 = -1.666_665_5e-1;
const S1: f32 = 8.332_161e-3;
const S2: f32 = -1.951_529_6e-4;
// cos r ≈ 1 − z/2 + z² (C0 + z (C1 + z C2)), Cephes' cosf.
const C0: f32 = 4.166_664_6e-2;
const C1: f32 = -1.388_731_6e-3;
const C2: f32 = 2.443_315_7e-5;

/// Whether the kernel serves `θ`: `|θ| ≤ LIMIT` (false for NaN).
#[inline(always)]
fn in_range(theta: f32) -> bool {
    theta.abs() <= LIMIT
}

/// `(sin θ, cos θ)` for `|θ| ≤ LIMIT`; meaningless outside.
#[inline(always)]
fn sin_cos_reduced(theta: f32) -> (f32, f32) {
    // Clamped, so that the conversion below is in range: the angles past LIMIT (NaN
    // included) are redone by the caller. A saturating `as i32` instead was left scalar
    // by the compiler, a third of the batch's time.
    let x = theta.abs().min(LIMIT);
    // ⌊x 4/π⌋ rounded up to even: the nearest multiple of π/2 in units of π/4.
    // SAFETY: 0 ≤ x·4/π ≤ 10431 (x ≤ LIMIT, and never NaN after `min`): finite and within i32.
    let j = unsafe { (x * FOUR_OVER_PI).to_int_unchecked::<i32>() }.wrapping_add(1) & !1;
    let y = j as f32;
    let r = ((x - y * D1) - y * D2) - y * D3;
    let z = r * r;
    let sin_r = r + r * z * (S0 + z * (S1 + z * S2));
    let cos_r = 1.0 - 0.5 * z + z * z * (C0 + z * (C1 + z * C2));
    // x = r + (j/2) π/2: quadrant q = j/2 mod 4.
    let q = (j >> 1) as u32;
    let swap = 0u32.wrapping_sub(q & 1);
    let (sin_r, cos_r) = (sin_r.to_bits(), cos_r.to_bits());
    let (sin, cos) = ((sin_r & !swap) | (cos_r & swap), (cos_r & !swap) | (sin_r & swap));
    // sin: + + − − by quadrant, times the sign of θ; cos: + − − +.
    let sin_sign = ((q & 2) << 30) ^ (theta.to_bits() & 0x8000_0000);
    let cos_sign = ((q + 1) & 2) << 30;
    (f32::from_bits(sin ^ sin_sign), f32::from_bits(cos ^ cos_sign))
}

/// `sin[i]`, `cos[i]` of `angles[i]` (rad), every angle. With AVX-512 and at least
/// [`AVX512_FROM`] angles in its own function (sixteen angles an instruction), else
/// inlined, so that it runs with its caller's target features; the same operations, the
/// same bits.
#[inline(always)]
pub(crate) fn sin_cos_split_f32(angles: &[f32], sin: &mut [f32], cos: &mut [f32]) {
    #[cfg(target_arch = "x86_64")]
    if angles.len() >= AVX512_FROM && crate::lanes::has_avx512() {
        // SAFETY: the CPU has AVX-512, checked just above.
        return unsafe { split_avx512(angles, sin, cos) };
    }
    split(angles, sin, cos)
}

/// [`split`] compiled for AVX-512.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn split_avx512(angles: &[f32], sin: &mut [f32], cos: &mut [f32]) {
    split(angles, sin, cos)
}

/// The body of [`sin_cos_split_f32`], for whatever target features its caller has.
#[inline(always)]
fn split(angles: &[f32], sin: &mut [f32], cos: &mut [f32]) {
    split_with(angles, sin, cos, sin_cos_reduced, in_range, |theta| {
        let (sin, cos) = f64::from(theta).sin_cos();
        (sin as f32, cos as f32)
    })
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;

    /// The worst `|f32 − exact|` over `angles`, against `f64::sin_cos` of the same `f32`.
    fn worst(angles: &[f32]) -> f64 {
        let (mut sin, mut cos) = (vec![0.0; angles.len()], vec![0.0; angles.len()]);
        sin_cos_split_f32(angles, &mut sin, &mut cos);
        let mut worst: f64 = 0.0;
        for ((&theta, &s), &c) in angles.iter().zip(&sin).zip(&cos) {
            let (es, ec) = f64::from(theta).sin_cos();
            worst = worst.max((f64::from(s) - es).abs()).max((f64::from(c) - ec).abs());
        }
        worst
    }

    #[test]
    fn single_precision_sines_are_within_two_tenths_of_a_millionth() {
        let mut r = ChaCha8Rng::seed_from_u64(32);
        let random: Vec<f32> = (0..100_000).map(|_| r.random_range(-8192.0..8192.0)).collect();
        assert!(worst(&random) < 2e-7, "{}", worst(&random));
        let small: Vec<f32> = (0..100_000).map(|_| r.random_range(-4.0..4.0)).collect();
        assert!(worst(&small) < 2e-7, "{}", worst(&small));
        // Near every multiple of π/4 up to 100 rad, where the quadrant changes.
        let edges: Vec<f32> = (-128..128)
            .flat_map(|k| {
                let x = (f64::from(k) * std::f64::consts::FRAC_PI_4) as f32;
                [x, f32::from_bits(x.to_bits() + 1), f32::from_bits(x.to_bits().wrapping_sub(1))]
            })
            .collect();
        assert!(worst(&edges) < 2e-7, "{}", worst(&edges));
    }

    #[test]
    fn every_instruction_set_gives_the_same_bits() {
        let mut r = ChaCha8Rng::seed_from_u64(33);
        let angles: Vec<f32> = (0..10_007).map(|_| r.random_range(-9000.0..9000.0)).collect();
        for len in (0..40).chain([10_007]) {
            let angles = &angles[..len];
            let run = |f: &dyn Fn(&mut [f32], &mut [f32])| {
                let (mut sin, mut cos) = (vec![0.0f32; len], vec![0.0f32; len]);
                f(&mut sin, &mut cos);
                sin.iter().chain(&cos).map(|x| x.to_bits()).collect::<Vec<_>>()
            };
            let baseline = run(&|s, c| split(angles, s, c));
            assert_eq!(run(&|s, c| sin_cos_split_f32(angles, s, c)), baseline, "{len} angles");
            #[cfg(target_arch = "x86_64")]
            if crate::lanes::has_avx512() {
                // SAFETY: the CPU has AVX-512.
                assert_eq!(run(&|s, c| unsafe { split_avx512(angles, s, c) }), baseline, "{len} angles");
            }
        }
    }

    #[test]
    fn beyond_the_range_and_non_finite_angles_go_to_std() {
        let angles = [1e6f32, -3e9, f32::NAN, f32::INFINITY, 0.5];
        let (mut sin, mut cos) = ([0.0; 5], [0.0; 5]);
        sin_cos_split_f32(&angles, &mut sin, &mut cos);
        assert_eq!(sin[0], 1e6f64.sin() as f32);
        assert_eq!(cos[1], (-3e9f64).cos() as f32);
        assert!(sin[2].is_nan() && cos[3].is_nan());
        assert!((sin[4] - 0.5f32.sin()).abs() < 1e-7);
    }
}
