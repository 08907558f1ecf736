//! The evaluation: the tensions `T`, the mass accelerations and the direction
//! accelerations `ü_i` of a chain's rods at one state, by one down pass (the elimination
//! of `A T = b`, module docs of [`rods`](super)) and one up pass, O(n).

use super::*;
use crate::lanes::{Lanes, Lanes32};

impl Rods {
    /// The constants of a chain with these masses (kg) and lengths (m), both positive, and
    /// damping coefficients `λ_i` (N·m·s).
    pub fn new(masses: &[f64], lengths: &[f64], damping: &[f64]) -> Self {
        Self {
            inverse_mass: masses.iter().map(|m| 1.0 / m).collect(),
            inverse_length: lengths.iter().map(|l| 1.0 / l).collect(),
            length: lengths.iter().copied().collect(),
            drag: damping.iter().zip(lengths).map(|(d, l)| d / l).collect(),
        }
    }

    /// Number of rods.
    pub fn len(&self) -> usize {
        self.length.len()
    }
}

impl Rods {
    /// The constants of `W` chains with the same number of rods, chain `k` in lane `k`.
    pub fn interleave<const W: usize>(chains: [&Rods; W]) -> Rods<Lanes<W>> {
        Self::side_by_side(chains, Lanes)
    }

    /// [`interleave`](Self::interleave) rounded to single precision.
    pub fn interleave_f32<const W: usize>(chains: [&Rods; W]) -> Rods<Lanes32<W>> {
        Self::side_by_side(chains, Lanes32::rounded)
    }

    /// Each constant of `chains`, lane `k` holding `chains[k]`'s, made a lane type by `lanes`.
    fn side_by_side<const W: usize, V: Lane>(chains: [&Rods; W], lanes: impl Fn([f64; W]) -> V) -> Rods<V> {
        let n = chains[0].len();
        let each = |of: fn(&Rods) -> &[f64]| -> Aligned<V> {
            (0..n).map(|i| lanes(chains.map(|c| of(c)[i]))).collect()
        };
        Rods {
            inverse_mass: each(|c| &c.inverse_mass),
            inverse_length: each(|c| &c.inverse_length),
            length: each(|c| &c.length),
            drag: each(|c| &c.drag),
        }
    }
}

impl<V: Lane> Rods<V> {
    /// The per-rod constants as one view.
    pub fn constants(&self) -> RodConstants<'_, V> {
        RodConstants {
            inverse_mass: &self.inverse_mass,
            length: &self.length,
            inverse_length: &self.inverse_length,
            drag: &self.drag,
        }
    }

    /// `1 / l_i` (1/m) per rod.
    pub fn inverse_length(&self) -> &[V] {
        &self.inverse_length
    }

    /// `λ_i / l_i` (N·s) per rod: damping `λ_i θ̇_i` (or `λ_i w_i`) acts on rod `i` as the
    /// force pair `−(λ_i / l_i) θ̇_i n_i` (or `−(λ_i / l_i) w_i`).
    pub fn drag(&self) -> &[V] {
        &self.drag
    }

    /// The tension solve (module docs): a down pass and an up pass over the chain.
    ///
    /// `load.load(i)` gives rod `i`'s [`Load`] (called for rods `i` and `i + 1` at row `i`,
    /// so twice per rod: reading a load where it is needed, rather than carrying it from row
    /// to row, spares the registers spills, in lanes and for one chain alike; a closure
    /// serves, and the lanes' kernels pass types with inlined methods, [`Loads`]);
    /// `emit(i, ü_i, u_i, T_i)` receives rod `i`'s direction acceleration (1/s²), its
    /// direction and its tension (N), once per rod in order `n−1, …, 0`. Gravity `g⃗` and
    /// the pivot acceleration `p̈` in m/s². Work O(n), one division per rod (off the serial
    /// chains), and one buffer row of `2S + 3` numbers per rod, so long chains stay in cache.
    #[inline(always)]
    pub fn solve<const S: usize>(
        &self,
        gravity: [V; S],
        pivot_acceleration: [V; S],
        rows: &mut Rows<S, V>,
        load: impl Loads<S, V>,
        emit: impl FnMut(usize, [V; S], &[V; S], V),
    ) {
        let rows = &mut rows.0[..self.length.len()];
        let outside = self.eliminate(gravity, pivot_acceleration, rows, load);
        if V::any(outside) {
            self.eliminate_by_pivots(rows, outside);
        }
        self.substitute(pivot_acceleration, rows, emit);
    }

    /// The down pass: free accelerations, right-hand sides and the elimination by
    /// continuants (module docs), rescaled by a power of two every [`Lane::RESCALE_ROWS`] rows. Returns the
    /// lanes where a continuant left [`CONTINUANT_RANGE`]; their rows then hold `b_i` and the
    /// directions but not yet valid `f_i` and `h_i`.
    #[inline(always)]
    fn eliminate<const S: usize>(
        &self,
        gravity: [V; S],
        pivot_acceleration: [V; S],
        rows: &mut [Row<S, V>],
        mut load: impl Loads<S, V>,
    ) -> V::Mask {
        let n = rows.len();
        let zero = V::splat(0.0);
        let mut free_above = pivot_acceleration;
        let mut inverse_mass_above = zero;
        let mut u_above = [zero; S];
        let mut continuants = Continuants::new();
        // 1/D_{i−1}, e_{i−1}.
        let (mut inverse_pivot_above, mut eliminated_above) = (zero, zero);
        for (i, row) in rows.iter_mut().enumerate() {
            let here = load.load(i);
            // Below the last rod, no load (no `Option`: copied through one, a load of lanes
            // fell apart into scalars).
            let pair_below = if i + 1 < n { load.load(i + 1).pair } else { [zero; S] };
            let im = self.inverse_mass[i];
            let u = here.direction;
            let mut a = gravity;
            let mut rhs = self.length[i] * here.rate_squared;
            for k in 0..S {
                a[k] += (here.pair[k] - pair_below[k]) * im;
                rhs += u[k] * (a[k] - free_above[k]);
            }
            let (diagonal, off) = entries(im, inverse_mass_above, &u_above, &u);
            let inverse_pivot = continuants.inverse_pivot(i, diagonal, off);
            let factor = off * inverse_pivot_above;
            let eliminated = rhs - factor * eliminated_above;
            *row = Row { direction: u, free: a, factor, scaled: eliminated * inverse_pivot, rhs };
            free_above = a;
            inverse_mass_above = im;
            u_above = u;
            (inverse_pivot_above, eliminated_above) = (inverse_pivot, eliminated);
        }
        continuants.outside()
    }

    /// The elimination by pivots, `D_i = A_ii − c_i² / D_{i−1}`, for the rows left by
    /// [`eliminate`](Self::eliminate) when its continuants left their range: the same `f_i`
    /// and `h_i` (to round-off) with a division on the serial chain, slower but needing no
    /// rescaling. Only the lanes flagged in `lanes` are rewritten.
    #[cold]
    #[inline(never)]
    fn eliminate_by_pivots<const S: usize>(&self, rows: &mut [Row<S, V>], lanes: V::Mask) {
        let zero = V::splat(0.0);
        let mut inverse_mass_above = zero;
        let mut u_above = [zero; S];
        let (mut inverse_pivot_above, mut eliminated_above) = (zero, zero);
        for (i, row) in rows.iter_mut().enumerate() {
            let (im, u) = (self.inverse_mass[i], row.direction);
            let (diagonal, off) = entries(im, inverse_mass_above, &u_above, &u);
            let factor = off * inverse_pivot_above;
            let inverse_pivot = V::splat(1.0) / (diagonal - factor * off);
            let eliminated = row.rhs - factor * eliminated_above;
            row.factor = V::select(lanes, factor, row.factor);
            row.scaled = V::select(lanes, eliminated * inverse_pivot, row.scaled);
            inverse_mass_above = im;
            u_above = u;
            (inverse_pivot_above, eliminated_above) = (inverse_pivot, eliminated);
        }
    }

    /// The up pass: tensions `T_i = h_i − f_{i+1} T_{i+1}`, mass accelerations and
    /// `ü_i = (a_i − a_{i−1}) / l_i`, handed to `emit` from the free end up.
    #[inline(always)]
    fn substitute<const S: usize>(
        &self,
        pivot_acceleration: [V; S],
        rows: &[Row<S, V>],
        mut emit: impl FnMut(usize, [V; S], &[V; S], V),
    ) {
        let n = rows.len();
        let zero = V::splat(0.0);
        let mut tension_below = zero;
        let mut factor_below = zero;
        let mut u_below = [zero; S];
        let mut a_below = [zero; S];
        for i in (0..n).rev() {
            let row = &rows[i];
            // The serial chain: one multiply and one subtraction per rod.
            let t = row.scaled - factor_below * tension_below;
            let im = self.inverse_mass[i];
            let mut a = row.free;
            for k in 0..S {
                a[k] += (tension_below * u_below[k] - t * row.direction[k]) * im;
            }
            if i + 1 < n {
                let il = self.inverse_length[i + 1];
                let mut udd = [zero; S];
                for k in 0..S {
                    udd[k] = (a_below[k] - a[k]) * il;
                }
                emit(i + 1, udd, &u_below, tension_below);
            }
            tension_below = t;
            factor_below = row.factor;
            u_below = row.direction;
            a_below = a;
        }
        let il = self.inverse_length[0];
        let mut udd = [zero; S];
        for k in 0..S {
            udd[k] = (a_below[k] - pivot_acceleration[k]) * il;
        }
        emit(0, udd, &u_below, tension_below);
    }
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;

    /// Solves for `n` rods with the given directions, rates and pairs; returns (ü, T).
    fn solve<const S: usize>(rods: &Rods, gravity: [f64; S], loads: &[Load<S>]) -> Solution<S> {
        solve_as(rods, gravity, loads, Route::Solve).0
    }

    /// Direction accelerations `ü_i` (1/s²) and tensions `T_i` (N) of one solve.
    type Solution<const S: usize> = (Vec<[f64; S]>, Vec<f64>);

    /// Which elimination [`solve_as`] runs.
    #[derive(Clone, Copy, PartialEq)]
    enum Route {
        /// [`Rods::solve`] as the models call it.
        Solve,
        /// [`Rods::eliminate_by_pivots`] whatever the continuants did.
        Pivots,
    }

    /// Solves by `route`; returns (ü, T), whether the continuants stayed in range, and the
    /// backward error of the tensions: `max_i |(A T − b)_i| / max_i (|A| |T| + |b|)_i`.
    fn solve_as<const S: usize>(
        rods: &Rods,
        gravity: [f64; S],
        loads: &[Load<S>],
        route: Route,
    ) -> (Solution<S>, bool, f64) {
        let n = loads.len();
        let (mut udd, mut tension) = (vec![[0.0; S]; n], vec![0.0; n]);
        let pivot = [0.0; S];
        let emit = |i: usize, a: [f64; S], _: &[f64; S], t: f64| {
            udd[i] = a;
            tension[i] = t;
        };
        let (in_range, rows) = with_scratch::<S, _>(n, |s| {
            let rows = &mut s.rows.0[..n];
            let in_range = !rods.eliminate(gravity, pivot, rows, |i| loads[i]);
            if !in_range || route == Route::Pivots {
                rods.eliminate_by_pivots(rows, true);
            }
            rods.substitute(pivot, rows, emit);
            (in_range, rows.to_vec())
        });
        let (mut residual, mut size) = (0.0f64, 0.0f64);
        for i in 0..n {
            let u = &rows[i].direction;
            let above =
                if i > 0 { (rods.inverse_mass[i - 1], rows[i - 1].direction) } else { (0.0, [0.0; S]) };
            let (diagonal, off) = entries(rods.inverse_mass[i], above.0, &above.1, u);
            let mut terms = [diagonal * tension[i], -rows[i].rhs, 0.0, 0.0];
            if i > 0 {
                terms[2] = off * tension[i - 1];
            }
            if i + 1 < n {
                let (_, off_below) =
                    entries(rods.inverse_mass[i + 1], rods.inverse_mass[i], u, &rows[i + 1].direction);
                terms[3] = off_below * tension[i + 1];
            }
            residual = residual.max(terms.iter().sum::<f64>().abs());
            size = size.max(terms.iter().map(|t| t.abs()).sum());
        }
        ((udd, tension), in_range, residual / size)
    }

    /// `10^x` with `x` uniform in `[lo, hi]`.
    fn decades(r: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
        10f64.powf(lo + (hi - lo) * r.random::<f64>())
    }

    /// A planar chain of `n` rods with masses and lengths log-uniform over `decades`
    /// (powers of ten), random angles, rates and damping-like pairs.
    fn random_chain(n: usize, decades_range: (f64, f64), seed: u64) -> (Rods, Vec<Load<2>>) {
        let mut r = ChaCha8Rng::seed_from_u64(seed);
        let masses: Vec<f64> = (0..n).map(|_| decades(&mut r, decades_range.0, decades_range.1)).collect();
        let lengths: Vec<f64> = (0..n).map(|_| decades(&mut r, decades_range.0, decades_range.1)).collect();
        let loads = (0..n)
            .map(|_| {
                let (s, c) = r.random_range(0.0..6.0f64).sin_cos();
                let rate = r.random_range(-2.0..2.0);
                let pull = r.random_range(-1.0..1.0);
                Load { direction: [s, -c], rate_squared: rate * rate, pair: [pull * c, pull * s] }
            })
            .collect();
        (Rods::new(&masses, &lengths, &vec![0.0; n]), loads)
    }

    /// Largest difference of `a` from `b`, relative to the largest `|b_i|`.
    fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
        let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale
    }

    /// Solves `loads` by the continuants (which must stay in range) and by the pivots;
    /// asserts both tension vectors have a backward error below 4 ε and differ by no more
    /// than `forward` (relative to the largest tension).
    fn continuants_against_pivots(rods: &Rods, loads: &[Load<2>], forward: f64) {
        let ((_, tension), in_range, error) = solve_as(rods, [0.0, -9.81], loads, Route::Solve);
        assert!(in_range, "the continuants left their range");
        let ((_, tension_p), _, error_p) = solve_as(rods, [0.0, -9.81], loads, Route::Pivots);
        let difference = relative_difference(&tension, &tension_p);
        assert!(
            error < 4.0 * f64::EPSILON && error_p < 4.0 * f64::EPSILON && difference < forward,
            "backward errors {error:.1e} (continuants), {error_p:.1e} (pivots); difference {difference:.1e}"
        );
    }

    #[test]
    fn continuants_match_pivots_on_a_long_chain_over_twelve_decades() {
        // n = 4096: 256 rescalings; masses and lengths from 1e-6 to 1e6.
        let (rods, loads) = random_chain(4096, (-6.0, 6.0), 7);
        continuants_against_pivots(&rods, &loads, 1e-12);
    }

    #[test]
    fn continuants_match_pivots_at_alternating_extreme_masses() {
        // Masses alternating 1e-6 and 1e6 kg: the pivots swing by twelve decades per rod.
        // The system is ill-conditioned here, so the two routes, both backward stable, may
        // differ by its condition number times ε.
        for seed in 1..4 {
            let (_, loads) = random_chain(4096, (0.0, 0.0), seed);
            let masses: Vec<f64> = (0..4096).map(|i| if i % 2 == 0 { 1e-6 } else { 1e6 }).collect();
            let lengths: Vec<f64> = (0..4096).map(|i| if i % 3 == 0 { 1e6 } else { 1e-6 }).collect();
            continuants_against_pivots(&Rods::new(&masses, &lengths, &[0.0; 4096]), &loads, 1e-6);
        }
    }

    #[test]
    fn continuants_match_pivots_on_a_straight_heavy_to_light_chain() {
        // Aligned rods, masses falling from 1e6 to 1e-6 kg: the pivots become as small
        // as the tridiagonal system lets them.
        let n = 4096;
        let masses: Vec<f64> = (0..n).map(|i| 10f64.powf(6.0 - 12.0 * i as f64 / (n - 1) as f64)).collect();
        let straight = Load { direction: [0.0, -1.0], rate_squared: 1.0, pair: [0.0; 2] };
        continuants_against_pivots(
            &Rods::new(&masses, &vec![1.0; n], &vec![0.0; n]),
            &vec![straight; n],
            1e-12,
        );
    }

    #[test]
    fn continuants_out_of_range_fall_back_to_pivots() {
        // Masses of 1e-150 kg make pivots near 2⁵⁰⁰: the continuants leave their range
        // within two rods, and the pivots still give the weight below each rod.
        let masses = [1e-150, 3e-150, 2e-150, 1e-150];
        let rods = Rods::new(&masses, &[1.0, 0.5, 2.0, 1.0], &[0.0; 4]);
        let hanging = Load { direction: [0.0, -1.0], rate_squared: 0.0, pair: [0.0; 2] };
        let ((_, tension), in_range, _) = solve_as(&rods, [0.0, -9.81], &[hanging; 4], Route::Solve);
        assert!(!in_range);
        for (i, t) in tension.iter().enumerate() {
            let weight = 9.81 * masses[i..].iter().sum::<f64>();
            assert!((t - weight).abs() < 1e-14 * weight, "rod {i}: {t:e} vs {weight:e}");
        }
    }

    #[test]
    fn in_lanes_only_the_lanes_out_of_range_fall_back_and_each_lane_is_its_chain() {
        // Four chains of 40 rods side by side; lane 2 has masses of 1e-150 kg, whose
        // continuants leave their range (redone by pivots), the others stay on the
        // continuants. Every lane must equal its chain's scalar solve bit for bit.
        let mut chains: Vec<(Rods, Vec<Load<2>>)> =
            (0..4).map(|k| random_chain(40, (-1.0, 1.0), 30 + k)).collect();
        let tiny: Vec<f64> = (0..40).map(|i| 1e-150 * (1.0 + (i % 3) as f64)).collect();
        chains[2].0 = Rods::new(&tiny, &[0.5; 40], &[0.0; 40]);
        let mut scalar = Vec::new();
        for (k, (rods, loads)) in chains.iter().enumerate() {
            let (solution, in_range, _) = solve_as(rods, [0.0, -9.81], loads, Route::Solve);
            assert_eq!(in_range, k != 2, "chain {k}");
            scalar.push(solution);
        }
        let lanes = Rods::interleave([&chains[0].0, &chains[1].0, &chains[2].0, &chains[3].0]);
        let load = |i: usize| {
            let of = |k: usize| chains[k].1[i];
            let lane = |f: &dyn Fn(Load<2>) -> f64| Lanes([f(of(0)), f(of(1)), f(of(2)), f(of(3))]);
            Load {
                direction: [lane(&|l| l.direction[0]), lane(&|l| l.direction[1])],
                rate_squared: lane(&|l| l.rate_squared),
                pair: [lane(&|l| l.pair[0]), lane(&|l| l.pair[1])],
            }
        };
        let (mut udd, mut tension) = (vec![[Lanes([0.0; 4]); 2]; 40], vec![Lanes([0.0; 4]); 40]);
        let mut rows = Rows::with_len(40);
        let g = Lanes([-9.81; 4]);
        let zero = Lanes([0.0; 4]);
        lanes.solve([zero, g], [zero; 2], &mut rows, load, |i, a, _, t| {
            udd[i] = a;
            tension[i] = t;
        });
        for (k, (scalar_udd, scalar_tension)) in scalar.iter().enumerate() {
            for i in 0..40 {
                assert_eq!(tension[i].0[k].to_bits(), scalar_tension[i].to_bits(), "lane {k}, rod {i}");
                for c in 0..2 {
                    assert_eq!(udd[i][c].0[k].to_bits(), scalar_udd[i][c].to_bits(), "lane {k}, rod {i}");
                }
            }
        }
    }

    #[test]
    fn in_single_precision_lanes_the_continuants_stay_in_range_and_only_tiny_masses_fall_back() {
        // Eight chains of 40 rods in f32 lanes; lane 5 has masses of 1e-9 kg (pivots near
        // 2³¹ kg⁻¹, past what 4 rows between rescalings keep inside 2^±80), the others
        // masses of 3 to 30 g (pivots up to 2¹⁰ kg⁻¹: inside with a rescaling every 4 rows,
        // not every 16 as in f64). Only lane 5 falls back to the elimination by pivots, and
        // every lane is its chain's f64 solve to single precision.
        let mut chains: Vec<(Rods, Vec<Load<2>>)> =
            (0..8).map(|k| random_chain(40, (-2.5, -1.5), 50 + k)).collect();
        let tiny: Vec<f64> = (0..40).map(|i| 1e-9 * (1.0 + (i % 3) as f64)).collect();
        chains[5].0 = Rods::new(&tiny, &[0.5; 40], &[0.0; 40]);
        let lanes = Rods::interleave_f32(std::array::from_fn::<_, 8, _>(|k| &chains[k].0));
        let load = |i: usize| {
            let lane = |f: &dyn Fn(Load<2>) -> f64| Lanes32::from_fn(|k| f(chains[k].1[i]) as f32);
            Load {
                direction: [lane(&|l| l.direction[0]), lane(&|l| l.direction[1])],
                rate_squared: lane(&|l| l.rate_squared),
                pair: [lane(&|l| l.pair[0]), lane(&|l| l.pair[1])],
            }
        };
        let (zero, g) = (Lanes32::<8>::splat(0.0), Lanes32::<8>::splat(-9.81));
        let mut rows = Rows::with_len(40);
        let outside = lanes.eliminate([zero, g], [zero; 2], &mut rows.0[..40], load);
        assert_eq!(outside, [0, 0, 0, 0, 0, 1, 0, 0]);
        let mut tension = vec![zero; 40];
        lanes.solve([zero, g], [zero; 2], &mut rows, load, |i, _, _, t| tension[i] = t);
        for (k, (rods, loads)) in chains.iter().enumerate() {
            let ((_, scalar), _, _) = solve_as(rods, [0.0, -9.81], loads, Route::Solve);
            let scale = scalar.iter().fold(0.0f64, |m, t| m.max(t.abs()));
            for (i, t) in scalar.iter().enumerate() {
                let error = (f64::from(tension[i].0[k]) - t).abs() / scale;
                assert!(error < 1e-5, "lane {k}, rod {i}: {error:e}");
            }
        }
    }

    /// The worst relative residual of Newton's law for every mass and of the rigidity of
    /// every rod, for the solution `(ü, T)` of `loads` with the pivot at rest — written
    /// from the module docs' mechanics, apart from the tridiagonal system (`entries`)
    /// the solve uses:
    /// `m_i a_i = m_i g⃗ + F_i − F_{i+1} + T_{i+1} u_{i+1} − T_i u_i`, `a_i = a_{i−1} + l_i ü_i`,
    /// `u_i · ü_i = −|u̇_i|²`.
    fn mechanics_residual<const S: usize>(
        rods: &Rods,
        gravity: [f64; S],
        loads: &[Load<S>],
        solution: &Solution<S>,
    ) -> (f64, f64) {
        let (udd, tension) = solution;
        let n = loads.len();
        // a_i, and Σ_{j≤i} l_j |ü_j|: the scale of its round-off.
        let (mut a, mut a_scale) = ([0.0; S], [0.0; S]);
        let (mut newton, mut rigid) = (0.0f64, 0.0f64);
        for i in 0..n {
            let m = 1.0 / rods.inverse_mass[i];
            let u = loads[i].direction;
            for k in 0..S {
                a[k] += rods.length[i] * udd[i][k];
                a_scale[k] += rods.length[i] * udd[i][k].abs();
            }
            for k in 0..S {
                let mut terms = vec![m * gravity[k], loads[i].pair[k], -tension[i] * u[k], -m * a[k]];
                if i + 1 < n {
                    terms.push(-loads[i + 1].pair[k]);
                    terms.push(tension[i + 1] * loads[i + 1].direction[k]);
                }
                let size: f64 = terms.iter().map(|t| t.abs()).sum::<f64>() + m * a_scale[k];
                newton = newton.max(terms.iter().sum::<f64>().abs() / size);
            }
            let along = dot(&u, &udd[i]);
            rigid = rigid.max(
                (along + loads[i].rate_squared).abs()
                    / (dot(&udd[i], &udd[i]).sqrt() + loads[i].rate_squared),
            );
        }
        (newton, rigid)
    }

    #[test]
    fn solutions_obey_newtons_law_and_keep_the_rods_rigid() {
        // Planar chains over twelve and two decades, by both eliminations, and a 3D chain.
        for (n, range, seed) in [(64, (-6.0, 6.0), 11), (1000, (-1.0, 1.0), 12)] {
            let (rods, loads) = random_chain(n, range, seed);
            for route in [Route::Solve, Route::Pivots] {
                let (solution, _, _) = solve_as(&rods, [0.0, -9.81], &loads, route);
                let (newton, rigid) = mechanics_residual(&rods, [0.0, -9.81], &loads, &solution);
                assert!(newton < 1e-12 && rigid < 1e-12, "n = {n}: Newton {newton:e}, rigidity {rigid:e}");
            }
        }
        let mut r = ChaCha8Rng::seed_from_u64(13);
        let n = 200;
        let masses: Vec<f64> = (0..n).map(|_| decades(&mut r, -1.0, 1.0)).collect();
        let lengths: Vec<f64> = (0..n).map(|_| decades(&mut r, -1.0, 1.0)).collect();
        let loads: Vec<Load<3>> = (0..n)
            .map(|_| {
                let (st, ct) = r.random_range(0.0..3.0f64).sin_cos();
                let (sp, cp) = r.random_range(0.0..6.0f64).sin_cos();
                let pair = [r.random_range(-1.0..1.0), r.random_range(-1.0..1.0), r.random_range(-1.0..1.0)];
                Load { direction: [st * cp, st * sp, -ct], rate_squared: r.random_range(0.0..4.0), pair }
            })
            .collect();
        let rods = Rods::new(&masses, &lengths, &vec![0.0; n]);
        let solution = solve(&rods, [0.0, 0.0, -9.81], &loads);
        let (newton, rigid) = mechanics_residual(&rods, [0.0, 0.0, -9.81], &loads, &solution);
        assert!(newton < 1e-12 && rigid < 1e-12, "3D: Newton {newton:e}, rigidity {rigid:e}");
    }

    #[test]
    fn normalizer_is_the_power_of_two_into_one_to_two() {
        for x in [1.0, 1.5, 3.0, 0.75, 2f64.powi(700), 1.9 * 2f64.powi(-700), f64::MIN_POSITIVE] {
            let y = x * x.normalizer();
            assert!((1.0..2.0).contains(&y), "{x:e} → {y}");
        }
    }

    #[test]
    fn hanging_chain_carries_the_weight_below_each_rod() {
        let rods = Rods::new(&[1.0, 2.0, 0.5], &[1.0, 0.5, 2.0], &[0.0; 3]);
        let g = 9.81;
        let hanging = Load { direction: [0.0, -1.0], rate_squared: 0.0, pair: [0.0; 2] };
        let (udd, tension) = solve(&rods, [0.0, -g], &[hanging; 3]);
        for (t, e) in tension.iter().zip([3.5 * g, 2.5 * g, 0.5 * g]) {
            assert!((t - e).abs() < 1e-12 * e, "{t} vs {e}");
        }
        assert!(udd.iter().flatten().all(|a| a.abs() < 1e-12));
    }

    #[test]
    fn spinning_single_rod_pulls_with_the_centripetal_force() {
        // One mass m on a rod l turning at ω without gravity: T = m l ω², ü = −ω² u.
        let (m, l, w) = (2.0, 0.5, 3.0);
        let rods = Rods::new(&[m], &[l], &[0.0]);
        let load = Load { direction: [1.0, 0.0, 0.0], rate_squared: w * w, pair: [0.0; 3] };
        let (udd, tension) = solve(&rods, [0.0; 3], &[load]);
        assert!((tension[0] - m * l * w * w).abs() < 1e-12);
        assert!((udd[0][0] + w * w).abs() < 1e-12);
    }
}
