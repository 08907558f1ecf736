//! What the runs in lanes share: a block's states ([`State`]: time, state and their
//! rounding compensations) into lanes and back out, the lanes whose numbers are not
//! finite, and the rows of a single-precision block that may start.

use nalgebra::Dyn;

use super::transpose::{gather_rows, scatter_some_rows};
use super::{Failure, WIDTH_F32, non_finite};
use crate::integrate::State;
#[cfg(target_arch = "x86_64")]
use crate::lanes::has_avx2;
use crate::lanes::{Lane, Lanes, Lanes32, Masked, one_row_at_a_time};

/// What [`into_lanes`] found in a block's states.
#[derive(Debug, Clone, Copy)]
pub(super) struct Arrival<const W: usize> {
    /// The lanes whose state has an entry that is not finite (flag `1`), found in lanes
    /// where the numbers arrive (before the search for the entry, chain by chain in code
    /// without AVX2, was a twelfth of a one-step call).
    pub suspect: [u64; W],
    /// Whether every compensation of the states was `+0.0` (then the lanes' were not
    /// transposed but cleared).
    pub uncompensated: bool,
}

/// The states `states` (`m` numbers each) into lanes: the times and their compensations
/// into `t`, the states into `x`, their compensations into `carry`, which is written only
/// where a state brings one or `carry_zero` is false (it says every entry of `carry` is
/// `+0.0` already). Compiled for AVX2 where the CPU has it, so that the tiles' transposes
/// are inlined (called tile by tile from code without AVX2, getting a whirl's states into
/// lanes and back was a quarter of a one-step call).
pub(super) fn into_lanes<const W: usize>(
    states: [&State<Dyn>; W],
    m: usize,
    t: &mut [Lanes<W>; 2],
    x: &mut [Lanes<W>],
    (carry, carry_zero): (&mut [Lanes<W>], bool),
) -> Arrival<W> {
    #[cfg(target_arch = "x86_64")]
    if has_avx2() {
        // SAFETY: the CPU has AVX2, checked just above.
        return unsafe { into_lanes_avx2(states, m, t, x, (carry, carry_zero)) };
    }
    fill_lanes(states, m, t, x, (carry, carry_zero))
}

/// [`fill_lanes`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn into_lanes_avx2<const W: usize>(
    states: [&State<Dyn>; W],
    m: usize,
    t: &mut [Lanes<W>; 2],
    x: &mut [Lanes<W>],
    carry: (&mut [Lanes<W>], bool),
) -> Arrival<W> {
    fill_lanes(states, m, t, x, carry)
}

/// The body of [`into_lanes`].
#[inline(always)]
fn fill_lanes<const W: usize>(
    states: [&State<Dyn>; W],
    m: usize,
    t: &mut [Lanes<W>; 2],
    x: &mut [Lanes<W>],
    (carry, carry_zero): (&mut [Lanes<W>], bool),
) -> Arrival<W> {
    let parts = states.map(State::parts);
    *t = [Lanes::from_fn(|k| parts[k].0), Lanes::from_fn(|k| parts[k].1)];
    gather_rows(parts.map(|p| p.2), m, Lanes::flatten_mut(x));
    // Projected steps clear the compensation: a run of them arrives with none, most often.
    // The states know it (reading the compensations to be sure was a twentieth of a
    // one-step call).
    let uncompensated = states.iter().all(|state| state.is_cleared());
    if !uncompensated {
        gather_rows(parts.map(|p| p.3), m, Lanes::flatten_mut(carry));
    } else if !carry_zero {
        carry[..m].fill(Lanes([0.0; W]));
    }
    Arrival { suspect: non_finite_lanes(&x[..m]), uncompensated }
}

/// The block's states (up to `W`, lane `k` for the `k`-th) that `ran` (flag `1`) out
/// of the lanes [`into_lanes`] filled (by the tiles' transposes for a whole block: one
/// number at a time, this was a quarter of a one-step call); with no lanes of
/// compensations (`None`), the states keep their own. Compiled for AVX2 where the CPU has
/// it, as [`into_lanes`].
pub(super) fn out_of_lanes<'a, const W: usize>(
    states: impl IntoIterator<Item = &'a mut State<Dyn>>,
    ran: [u64; W],
    m: usize,
    lanes: (&[Lanes<W>; 2], &[Lanes<W>], Option<&[Lanes<W>]>),
) {
    let mut xs: [Option<&mut [f64]>; W] = std::array::from_fn(|_| None);
    let mut carries: [Option<&mut [f64]>; W] = std::array::from_fn(|_| None);
    let (t, _, _) = lanes;
    for (k, state) in states.into_iter().enumerate().filter(|(k, _)| ran[*k] != 0) {
        let (time, time_carry, x, carry) = match lanes.2 {
            Some(_) => {
                let (time, time_carry, x, carry) = state.parts_mut();
                (time, time_carry, x, Some(carry))
            }
            None => {
                let (time, time_carry, x) = state.time_and_x_mut();
                (time, time_carry, x, None)
            }
        };
        (*time, *time_carry) = (t[0].0[k], t[1].0[k]);
        (xs[k], carries[k]) = (Some(x), carry);
    }
    #[cfg(target_arch = "x86_64")]
    if has_avx2() {
        // SAFETY: the CPU has AVX2, checked just above.
        return unsafe { empty_lanes_avx2(m, lanes, xs, carries) };
    }
    empty_lanes(m, lanes, xs, carries)
}

/// [`empty_lanes`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn empty_lanes_avx2<const W: usize>(
    m: usize,
    lanes: (&[Lanes<W>; 2], &[Lanes<W>], Option<&[Lanes<W>]>),
    xs: [Option<&mut [f64]>; W],
    carries: [Option<&mut [f64]>; W],
) {
    empty_lanes(m, lanes, xs, carries)
}

/// The states and their compensations (when given) out of the lanes into the rows given
/// (`None`: a lane left out).
#[inline(always)]
fn empty_lanes<const W: usize>(
    m: usize,
    (_, x, carry): (&[Lanes<W>; 2], &[Lanes<W>], Option<&[Lanes<W>]>),
    xs: [Option<&mut [f64]>; W],
    carries: [Option<&mut [f64]>; W],
) {
    scatter_some_rows(Lanes::flatten(x), m, xs);
    if let Some(carry) = carry {
        scatter_some_rows(Lanes::flatten(carry), m, carries);
    }
}

/// The lanes in which some entry of `v` is not finite (flag `1`).
#[inline(always)]
pub(super) fn non_finite_lanes<const W: usize>(v: &[Lanes<W>]) -> [u64; W] {
    non_finite_sum(v).not_finite()
}

/// [`non_finite_lanes`] of `v`, given `sum`, the lanes' sums of `v`'s entries formed as they
/// were written: a finite sum means every entry of its lane is finite (an infinite or NaN
/// entry leaves the sum infinite or NaN), so `v` is read again only where a sum is not
/// finite (which finite entries can make by overflowing). A pass over a block's results
/// of its own was a twentieth of a 3D evaluation at n = 100 (the planar batch and the
/// `f32` ones, in AVX2's 16 registers, keep their pass: the sums made them 6–9% and 1.6×
/// slower).
#[inline(always)]
pub(super) fn finite_unless_flagged<const W: usize>(sum: Lanes<W>, v: &[Lanes<W>]) -> [u64; W] {
    if Lanes::any(sum.not_finite()) { non_finite_lanes(v) } else { [0; W] }
}

/// `y − y`: `0` for a finite `y`, NaN otherwise (lane by lane); summed, NaN where any
/// term was not finite.
#[inline(always)]
#[allow(clippy::eq_op)] // `y − y` on purpose: 0 or NaN.
pub(super) fn nan_unless_finite<V: Lane>(y: V) -> V {
    y - y
}

/// [`non_finite_lanes`] in single precision.
#[inline(always)]
pub(super) fn non_finite_lanes_f32<const W: usize>(v: &[Lanes32<W>]) -> [u32; W] {
    non_finite_sum(v).not_finite()
}

/// Lane by lane, NaN where some entry of `v` is not finite and `0` elsewhere: `y − y` is `0`
/// for a finite `y` and NaN otherwise, summed in four independent sums (one sum waited on
/// each addition; a per-lane loop of flags was vectorised across entries and transposed
/// back, with spills).
#[inline(always)]
pub(super) fn non_finite_sum<V: Lane>(v: &[V]) -> V {
    let mut sums = [V::splat(0.0); 4];
    let mut quads = v.chunks_exact(4);
    for quad in quads.by_ref() {
        for (sum, y) in sums.iter_mut().zip(quad) {
            *sum += nan_unless_finite(*y);
        }
        one_row_at_a_time();
    }
    for (sum, y) in sums.iter_mut().zip(quads.remainder()) {
        *sum += nan_unless_finite(*y);
    }
    (sums[0] + sums[1]) + (sums[2] + sums[3])
}

/// A single-precision block's rows of `x` (`m` numbers each, row `k` chain `chains[k]`)
/// before its first step: the failures of those with an entry that is not finite (named by
/// it), and the lanes of the others, which start (flag `1`).
pub(super) fn finite_rows(
    x: &[f32],
    m: usize,
    chains: [usize; WIDTH_F32],
) -> (Vec<Failure>, [u32; WIDTH_F32]) {
    let mut failures = Vec::new();
    let mut alive = [0u32; WIDTH_F32];
    for (k, row) in x.chunks_exact(m).enumerate() {
        match non_finite("x", row) {
            Some(error) => failures.push(Failure { chain: chains[k], error }),
            None => alive[k] = 1,
        }
    }
    (failures, alive)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lane_is_flagged_for_an_entry_not_finite_and_not_for_a_sum_that_overflowed() {
        // Lane 0: finite entries whose sum overflows; lane 1: an infinity; lane 2: a NaN;
        // lane 3: finite entries that sum to a finite number.
        let v = [Lanes([f64::MAX, f64::INFINITY, 1.0, 2.0]), Lanes([f64::MAX, -1.0, f64::NAN, -2.0])];
        let sum = v.iter().fold(Lanes([0.0; 4]), |s, &x| s + x);
        assert_eq!(finite_unless_flagged(sum, &v), [0, 1, 1, 0]);
        assert_eq!(finite_unless_flagged(sum, &v), non_finite_lanes(&v));
        let finite = [Lanes([1.0, -1.0, 0.5, 2.0]); 3];
        let sum = finite.iter().fold(Lanes([0.0; 4]), |s, &x| s + x);
        assert_eq!(finite_unless_flagged(sum, &finite), [0; 4]);
    }
}
