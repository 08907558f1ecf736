//! `sin θ` and `cos θ` of a whole array of angles at once, for the O(n) planar model: a
//! branch-free polynomial kernel that the compiler vectorises, and `f64::sin_cos` outside
//! `|θ| ≤ 8192` rad.
//!
//! One libm `sincos` call costs about as much as the whole tension solve of a link, and
//! no compiler vectorises it. The loop below runs two angles per instruction with the
//! baseline x86-64 target (SSE2), four on CPUs with AVX2 and eight with AVX-512 (detected
//! at run time). All
//! do the same IEEE operations in the same order (no fused multiply-add), so the results
//! are bit for bit the same on every machine. The kernel is fdlibm's (`k_sin.c`,
//! `k_cos.c`: error below 1 ulp on `[−π/4, π/4]` given the tail `r_t` of the reduced
//! argument), after a Cody–Waite reduction (θ in rad):
//! ```text
//! k = round(θ · 2/π),   r + r_t = θ − k (C₁ + C₂ + C₃)        (|k| < 2¹³)
//! C₁, C₂: π/2 in two pieces of 40 bits (k C₁, k C₂ exact),  C₃: the next 53 bits
//! sin θ = ±sin r or ±cos r,  cos θ = ±cos r or ±sin r          (by k mod 4)
//! ```
//! `θ − k C₁` is exact (Sterbenz), `− k C₂` is added by an error-free two-sum, and
//! `|π/2 − C₁ − C₂ − C₃| < 2⁻¹⁴²`: `r + r_t` is off by less than 2⁻¹²⁹, below 2⁻⁶⁸ |r| even
//! at the smallest `|r|` among the doubles with `k ≠ 0`, `|θ| ≤ 8192` (2⁻⁶⁰·⁵, at
//! θ ≈ 45.553; for `k = 0`, `r = θ` exactly). Tested against std at random angles, at the
//! doubles nearest every multiple of π/2 in range and at their neighbours: at most 1 ulp
//! apart (module tests). The one difference in kind: `sin(−0)` is `+0`.

#[cfg(target_arch = "x86_64")]
use crate::lanes::{has_avx2, has_avx512};

/// Beyond this `|θ|` (rad), and for non-finite `θ`, [`sin_cos_into`] calls `f64::sin_cos`.
pub(crate) const LIMIT: f64 = 8192.0;

/// `1.5 · 2⁵²`: adding it rounds to an integer, kept in the low bits of the sum.
const SHIFTER: f64 = 6755399441055744.0;
/// π/2 = C₁ + C₂ + C₃ + O(2⁻¹⁴²); C₁ and C₂ have 40 significant bits.
const PIO2_1: f64 = 1.5707963267941523;
const PIO2_2: f64 = 7.443547480488527e-13;
const PIO2_3: f64 = -1.9034889620193266e-25;

// fdlibm k_sin.c (the same doubles, shortest decimals):
// sin r ≈ r + S1 r³ + … + S6 r¹³ on [−π/4, π/4].
const S1: f64 = -0.16666666666666632;
const S2: f64 = 0.00833333333332249;
const S3: f64 = -0.0001984126982985795;
const S4: f64 = 2.7557313707070068e-06;
const S5: f64 = -2.5050760253406863e-08;
const S6: f64 = 1.58969099521155e-10;
// fdlibm k_cos.c (the same doubles, shortest decimals):
// cos r ≈ 1 − r²/2 + C1 r⁴ + … + C6 r¹⁴ on [−π/4, π/4].
const C1: f64 = 0.0416666666666666;
const C2: f64 = -0.001388888888887411;
const C3: f64 = 2.480158728947673e-05;
const C4: f64 = -2.7557314351390663e-07;
const C5: f64 = 2.087572321298175e-09;
const C6: f64 = -1.1359647557788195e-11;

/// Whether the kernel serves `θ`: `|θ| ≤ LIMIT` (false for NaN).
#[inline(always)]
fn in_range(theta: f64) -> bool {
    theta.abs() <= LIMIT
}

/// `(sin θ, cos θ)` for `|θ| ≤ LIMIT` (module docs); meaningless outside.
#[inline(always)]
fn sin_cos_reduced(theta: f64) -> (f64, f64) {
    let shifted = theta * std::f64::consts::FRAC_2_PI + SHIFTER;
    let quadrant = shifted.to_bits(); // k + 2⁵¹ in the low bits: k mod 4 in the last two
    let k = shifted - SHIFTER;
    let r1 = theta - k * PIO2_1;
    let w2 = k * PIO2_2;
    // Two-sum: hi + lo = r1 − w2 exactly.
    let hi = r1 - w2;
    let b = hi - r1;
    let lo = (r1 - (hi - b)) + (-w2 - b) - k * PIO2_3;
    let r = hi + lo;
    let tail = (hi - r) + lo;
    let z = r * r;
    // k_sin(r, tail)
    let v = z * r;
    let p = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
    let sin = r - ((z * (0.5 * tail - v * p) - tail) - v * S1);
    // k_cos(r, tail)
    let q = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    let half = 0.5 * z;
    let w = 1.0 - half;
    let cos = w + (((1.0 - w) - half) + (z * q - r * tail));
    // Odd k swaps sine and cosine; the signs follow the quadrant.
    let swap = 0u64.wrapping_sub(quadrant & 1);
    let (sin, cos) = (sin.to_bits(), cos.to_bits());
    let (sin, cos) = ((sin & !swap) | (cos & swap), (cos & !swap) | (sin & swap));
    (f64::from_bits(sin ^ ((quadrant & 2) << 62)), f64::from_bits(cos ^ (((quadrant + 1) & 2) << 62)))
}

/// `out[i] = [sin θ_i, cos θ_i]` for every angle (rad) in `angles` (`out` at least as long).
///
/// Vectorised polynomial kernel for `|θ_i| ≤ LIMIT` (module docs), `f64::sin_cos` for the
/// others (NaN for a non-finite angle, as std).
pub fn sin_cos_into(angles: &[f64], out: &mut [[f64; 2]]) {
    #[cfg(target_arch = "x86_64")]
    if has_avx512() {
        // SAFETY: the CPU has AVX-512, checked just above.
        return unsafe { sin_cos_avx512(angles, out) };
    }
    #[cfg(target_arch = "x86_64")]
    if has_avx2() {
        // SAFETY: the CPU has AVX2, checked just above.
        return unsafe { sin_cos_avx2(angles, out) };
    }
    sin_cos_loop(angles, out)
}

/// [`sin_cos_loop`] compiled for AVX-512: eight lanes, the same operations.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn sin_cos_avx512(angles: &[f64], out: &mut [[f64; 2]]) {
    sin_cos_loop(angles, out)
}

/// [`sin_cos_loop`] compiled for AVX2: four lanes instead of two, the same operations.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn sin_cos_avx2(angles: &[f64], out: &mut [[f64; 2]]) {
    sin_cos_loop(angles, out)
}

/// The body of [`sin_cos_into`], vectorised for whatever target features its caller has.
#[inline(always)]
fn sin_cos_loop(angles: &[f64], out: &mut [[f64; 2]]) {
    let out = &mut out[..angles.len()];
    let mut outside = false;
    for (o, &theta) in out.iter_mut().zip(angles) {
        let (sin, cos) = sin_cos_reduced(theta);
        *o = [sin, cos];
        outside |= !in_range(theta);
    }
    if outside {
        for (o, &theta) in out.iter_mut().zip(angles) {
            if !in_range(theta) {
                let (sin, cos) = theta.sin_cos();
                *o = [sin, cos];
            }
        }
    }
}

/// [`sin_cos_into`]'s values, bit for bit, into two arrays (`sin[i]`, `cos[i]` of
/// `angles[i]`): the layout of the batch's lanes. With AVX-512 in its own function, else
/// inlined, so that it runs with its caller's target features.
#[inline(always)]
pub(crate) fn sin_cos_split(angles: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if has_avx512() {
        // SAFETY: the CPU has AVX-512, checked just above.
        return unsafe { split_avx512(angles, sin, cos) };
    }
    split(angles, sin, cos)
}

/// [`split`] compiled for AVX-512.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn split_avx512(angles: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    split(angles, sin, cos)
}

/// The body of [`sin_cos_split`], for whatever target features its caller has.
#[inline(always)]
fn split(angles: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    split_with(angles, sin, cos, sin_cos_reduced, in_range, f64::sin_cos)
}

/// The two passes of a sine kernel over `angles` into `sin` and `cos`: `reduced(θ)` for
/// every angle (branch-free, vectorised), then `outside(θ)` for the angles not
/// `in_range`, should there be any. Inlined, so that it runs with its caller's target
/// features.
#[inline(always)]
pub(crate) fn split_with<T: Copy>(
    angles: &[T],
    sin: &mut [T],
    cos: &mut [T],
    reduced: impl Fn(T) -> (T, T),
    in_range: impl Fn(T) -> bool,
    outside: impl Fn(T) -> (T, T),
) {
    let (sin, cos) = (&mut sin[..angles.len()], &mut cos[..angles.len()]);
    let mut any_outside = false;
    for ((s, c), &theta) in sin.iter_mut().zip(cos.iter_mut()).zip(angles) {
        (*s, *c) = reduced(theta);
        any_outside |= !in_range(theta);
    }
    if any_outside {
        for ((s, c), &theta) in sin.iter_mut().zip(cos.iter_mut()).zip(angles) {
            if !in_range(theta) {
                (*s, *c) = outside(theta);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;

    /// Distance in units in the last place (`±0` equal; NaN against NaN is 0).
    fn ulps(a: f64, b: f64) -> u64 {
        if a.is_nan() && b.is_nan() {
            return 0;
        }
        let ordered = |x: f64| {
            let bits = x.to_bits() as i64;
            if bits < 0 { i64::MIN - bits } else { bits }
        };
        ordered(a).abs_diff(ordered(b))
    }

    /// The worst distance from std over `angles`, and where.
    fn worst(angles: &[f64]) -> (u64, f64) {
        let mut out = vec![[0.0; 2]; angles.len()];
        sin_cos_into(angles, &mut out);
        let mut worst = (0, 0.0);
        for (&theta, &[sin, cos]) in angles.iter().zip(&out) {
            let (s, c) = theta.sin_cos();
            let d = ulps(sin, s).max(ulps(cos, c));
            if d > worst.0 {
                worst = (d, theta);
            }
        }
        worst
    }

    /// `n` numbers uniform in [0, 1) from a seeded generator.
    fn stream(seed: u64, n: usize) -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n).map(|_| rng.random()).collect()
    }

    #[test]
    fn within_one_ulp_of_std_at_random_angles_of_every_scale() {
        // Uniform on [−8192, 8192] and log-uniform magnitudes from 1e-300 to 8192.
        let u = stream(1, 400_000);
        let mut angles: Vec<f64> = u[..200_000].iter().map(|x| LIMIT * (2.0 * x - 1.0)).collect();
        angles.extend(u[200_000..].iter().enumerate().map(|(i, x)| {
            let m = 10f64.powf(-300.0 + 303.9 * x);
            if i % 2 == 0 { m } else { -m }
        }));
        let (d, at) = worst(&angles);
        assert!(d <= 1, "{d} ulp at {at:e}");
    }

    #[test]
    fn within_one_ulp_of_std_next_to_every_multiple_of_half_pi() {
        // The doubles nearest k π/2 (and ten neighbours each side), where the reduced
        // argument is smallest and the reduction is tested hardest.
        let mut angles = Vec::new();
        let top = (LIMIT / std::f64::consts::FRAC_PI_2) as i64;
        for k in -top..=top {
            let near = k as f64 * std::f64::consts::FRAC_PI_2;
            let mut x = near;
            for _ in 0..10 {
                x = x.next_down();
            }
            for _ in 0..21 {
                angles.push(x);
                x = x.next_up();
            }
        }
        let (d, at) = worst(&angles);
        assert!(d <= 1, "{d} ulp at {at:e}");
    }

    #[test]
    fn every_instruction_set_gives_the_same_bits() {
        // The baseline loop, the AVX2 and the AVX-512 loops (those the CPU has) and the
        // split form must agree to the bit, on every length (the vector loops' tails).
        let u = stream(3, 100_003);
        let angles: Vec<f64> = u.iter().map(|x| 1.1 * LIMIT * (2.0 * x - 1.0)).collect();
        let bits = |v: &[[f64; 2]]| v.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
        for len in (0..40).chain([100_003]) {
            let angles = &angles[..len];
            let mut baseline = vec![[0.0; 2]; len];
            sin_cos_loop(angles, &mut baseline);
            let mut loops: Vec<Vec<[f64; 2]>> = Vec::new();
            let mut run = |f: &dyn Fn(&mut [[f64; 2]])| {
                let mut out = vec![[0.0; 2]; len];
                f(&mut out);
                loops.push(out);
            };
            run(&|out| sin_cos_into(angles, out));
            run(&|out| {
                let (mut sin, mut cos) = (vec![0.0; len], vec![0.0; len]);
                sin_cos_split(angles, &mut sin, &mut cos);
                out.iter_mut().zip(sin.iter().zip(&cos)).for_each(|(o, (&s, &c))| *o = [s, c]);
            });
            #[cfg(target_arch = "x86_64")]
            if has_avx2() {
                // SAFETY: the CPU has AVX2.
                run(&|out| unsafe { sin_cos_avx2(angles, out) });
            }
            #[cfg(target_arch = "x86_64")]
            if has_avx512() {
                // SAFETY: the CPU has AVX-512.
                run(&|out| unsafe { sin_cos_avx512(angles, out) });
            }
            for out in &loops {
                assert_eq!(bits(out), bits(&baseline), "{len} angles");
            }
        }
    }

    #[test]
    fn std_beyond_the_limit_and_for_non_finite_angles() {
        let angles = [
            LIMIT,
            -LIMIT,
            LIMIT.next_up(),
            -LIMIT.next_up(),
            1e5,
            -3e9,
            1e300,
            f64::MAX,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            0.5,
        ];
        let mut out = vec![[0.0; 2]; angles.len()];
        sin_cos_into(&angles, &mut out);
        for (&theta, &[sin, cos]) in angles.iter().zip(&out) {
            let (s, c) = theta.sin_cos();
            if theta.abs() > LIMIT {
                assert_eq!((sin.to_bits(), cos.to_bits()), (s.to_bits(), c.to_bits()), "{theta:e}");
            } else if theta.is_nan() {
                assert!(sin.is_nan() && cos.is_nan());
            } else {
                assert!(ulps(sin, s) <= 1 && ulps(cos, c) <= 1, "{theta:e}");
            }
        }
    }
}
