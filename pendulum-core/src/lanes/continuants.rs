//! The range in which the tension solve trusts its continuants `P_i`, in each precision,
//! as bit patterns and as numbers, and the rule by which a solve keeps the smallest and
//! largest of them ([`Lane::widen`](super::Lane::widen)) to check that range once.

/// The continuants `P_i` of the fast down pass must stay in `[2⁻⁸⁰⁰, 2⁸⁰⁰]` (as bit
/// patterns: `low ≤ bits(P_i) ≤ low + span`), far from overflow and from the subnormals
/// where they would lose digits; otherwise the pivots are redone by
/// `rods::Rods::eliminate_by_pivots`. Negative, zero, infinite and NaN values fall outside too.
pub const CONTINUANT_RANGE: (u64, u64) = {
    let low = (1023 - 800) << 52; // 2⁻⁸⁰⁰
    let high = (1023 + 800) << 52; // 2⁸⁰⁰
    (low, high - low)
};

/// `2⁻⁸⁰` and `2⁸⁰` as `f32` bit patterns: the continuants' range in single precision, wide
/// enough for the chains of a few dozen links of grams and centimetres in SI units and far
/// enough from `f32`'s overflow (`2¹²⁸`) for the products the solve forms with them.
pub(crate) const CONTINUANT_RANGE_32: (u32, u32) = {
    let low = (127 - 80) << 23;
    let high = (127 + 80) << 23;
    (low, high - low)
};

/// [`CONTINUANT_RANGE`]'s ends as numbers: `2⁻⁸⁰⁰` and `2⁸⁰⁰`.
pub(crate) const CONTINUANT_ENDS: [f64; 2] =
    [f64::from_bits(CONTINUANT_RANGE.0), f64::from_bits(CONTINUANT_RANGE.0 + CONTINUANT_RANGE.1)];

/// [`CONTINUANT_RANGE_32`]'s ends as numbers: `2⁻⁸⁰` and `2⁸⁰`.
pub(crate) const CONTINUANT_ENDS_32: [f32; 2] =
    [f32::from_bits(CONTINUANT_RANGE_32.0), f32::from_bits(CONTINUANT_RANGE_32.0 + CONTINUANT_RANGE_32.1)];

/// `[lowest, highest]` widened to take in `x` by the rule of x86's `minpd` and `maxpd`
/// (`lowest < x ? lowest : x`): a NaN `x` is taken in. The one rule of every lane type's
/// [`Lane::widen`](super::Lane::widen) (the register types by those instructions).
#[inline(always)]
pub(crate) fn widened<T: PartialOrd + Copy>(x: T, [lowest, highest]: [T; 2]) -> [T; 2] {
    [if lowest < x { lowest } else { x }, if highest > x { highest } else { x }]
}

/// Whether `[lowest, highest]` is NaN or reaches outside `[low, high]`.
#[inline(always)]
pub(crate) fn outside_ends<T: PartialOrd>([lowest, highest]: [T; 2], [low, high]: [T; 2]) -> bool {
    !(lowest >= low && highest <= high)
}

/// [`widened`] lane by lane.
#[inline(always)]
pub(crate) fn widened_lanes<T: PartialOrd + Copy, const W: usize>(
    x: [T; W],
    [mut lowest, mut highest]: [[T; W]; 2],
) -> [[T; W]; 2] {
    for ((lowest, highest), x) in lowest.iter_mut().zip(&mut highest).zip(x) {
        [*lowest, *highest] = widened(x, [*lowest, *highest]);
    }
    [lowest, highest]
}

/// [`outside_ends`] lane by lane, as flags `1` and `0`.
#[inline(always)]
pub(crate) fn outside_lanes<T: PartialOrd + Copy, M: From<bool> + Copy + Default, const W: usize>(
    [lowest, highest]: [[T; W]; 2],
    ends: [T; 2],
) -> [M; W] {
    let mut out = [M::default(); W];
    for ((o, lowest), highest) in out.iter_mut().zip(lowest).zip(highest) {
        *o = M::from(outside_ends([lowest, highest], ends));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::{Lane, Lanes, Lanes32};

    /// A sequence of continuants as the recurrence can make them: any values (the range's
    /// ends and their neighbours, ±0, subnormals, ±∞, negatives), until a NaN, then NaN.
    fn sequence<T: Copy>(picks: &[usize], values: &[T], nan: T) -> Vec<T> {
        let nan_at = picks.iter().position(|&p| p == values.len());
        let sequence = picks.iter().map(|&p| values.get(p).copied().unwrap_or(nan));
        match nan_at {
            Some(at) => sequence.take(at).chain(std::iter::repeat_n(nan, picks.len() - at)).collect(),
            None => sequence.collect(),
        }
    }

    #[test]
    fn a_range_of_continuants_flags_what_a_check_of_each_would() {
        let [low, high] = CONTINUANT_ENDS;
        let values64 = [
            1.0,
            1.5,
            low,
            high,
            low.next_down(),
            high.next_up(),
            0.0,
            -0.0,
            1e-310,
            -1.0,
            -high,
            f64::INFINITY,
            f64::NEG_INFINITY,
            3e200,
            2e-230,
            f64::MAX,
            f64::MIN_POSITIVE,
        ];
        let [low32, high32] = CONTINUANT_ENDS_32;
        let values32 = [
            1.0f32,
            low32,
            high32,
            low32.next_down(),
            high32.next_up(),
            0.0,
            -0.0,
            1e-40,
            -1.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            3e20,
            2e-23,
        ];
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut pick = |below: usize| {
            // xorshift64: a fixed, reproducible stream of picks.
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % below as u64) as usize
        };
        for length in [0, 1, 2, 3, 5, 9, 20] {
            for _ in 0..400 {
                // Index `len` is the NaN; most values picked from the first few (in range).
                let mut picks = || -> Vec<usize> {
                    (0..length)
                        .map(|_| if pick(3) == 0 { pick(values64.len() + 1) } else { pick(4) })
                        .collect()
                };
                let (picks, others) = (picks(), picks());
                let each = sequence(&picks, &values64, f64::NAN);
                let range = each.iter().fold([f64::INFINITY, f64::NEG_INFINITY], |r, &x| x.widen(r));
                let checked = each.iter().any(|&x| x.continuant_outside());
                assert_eq!(f64::range_outside(range), checked, "{each:?}");
                // Two sequences in four lanes, alternating.
                let other = sequence(&others, &values64, f64::NAN);
                let lanes: Vec<Lanes<4>> =
                    each.iter().zip(&other).map(|(&a, &b)| Lanes([a, b, b, a])).collect();
                let start = [Lanes([f64::INFINITY; 4]), Lanes([f64::NEG_INFINITY; 4])];
                let range = lanes.iter().fold(start, |r, &x| x.widen(r));
                let checked =
                    lanes.iter().fold(Lanes::<4>::none(), |m, &x| Lanes::or(m, x.continuant_outside()));
                assert_eq!(Lanes::range_outside(range), checked, "{lanes:?}");
                let picks32: Vec<usize> = picks.iter().map(|&p| p.min(values32.len())).collect();
                let each32 = sequence(&picks32, &values32, f32::NAN);
                let lanes32: Vec<Lanes32<1>> = each32.iter().map(|&x| Lanes32([x])).collect();
                let start = [Lanes32([f32::INFINITY]), Lanes32([f32::NEG_INFINITY])];
                let range = lanes32.iter().fold(start, |r, &x| x.widen(r));
                let checked =
                    lanes32.iter().fold(Lanes32::<1>::none(), |m, &x| Lanes32::or(m, x.continuant_outside()));
                assert_eq!(Lanes32::range_outside(range), checked, "{each32:?}");
            }
        }
    }
}
