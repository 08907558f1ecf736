//! Small oscillations of a uniform hanging chain approach Bernoulli's heavy string:
//! `ω_k = (j_{0,k} / 2) sqrt(g / L)`, `j_{0,k}` the zeros of the Bessel function J0; at
//! each n they are exactly `√((g/l) x_k)`, `x_k` the zeros of the Laguerre polynomial L_n.

use nalgebra::{DMatrix, Dyn};
use pendulum_core::{Chain, equal_link_frequencies, normal_modes};

/// The first three zeros of J0.
const J0_ZEROS: [f64; 3] = [2.404825557695773, 5.520078110286311, 8.653727912911013];

/// Relative errors of the first three frequencies of a uniform n-link chain of length
/// `length` against Bernoulli's.
fn errors(n: usize, length: f64, g: f64) -> [f64; 3] {
    let chain = Chain::<Dyn>::uniform(n, 1.0 / n as f64, length / n as f64, g).unwrap();
    let modes = normal_modes(&chain);
    std::array::from_fn(|k| {
        let bernoulli = 0.5 * J0_ZEROS[k] * (g / length).sqrt();
        (modes.frequencies[k] - bernoulli) / bernoulli
    })
}

#[test]
fn uniform_chain_converges_to_bernoulli_frequencies() {
    let (length, g) = (2.0, 9.81);
    println!("| n | ω1 error | ω2 error | ω3 error |");
    println!("|---|---|---|---|");
    let mut previous = [f64::INFINITY; 3];
    for n in [10, 25, 50, 100, 200] {
        let e = errors(n, length, g);
        println!("| {n} | {:+.3e} | {:+.3e} | {:+.3e} |", e[0], e[1], e[2]);
        for k in 0..3 {
            assert!(e[k].abs() < previous[k].abs(), "n = {n}, mode {}: error {} did not shrink", k + 1, e[k]);
            if n >= 100 {
                assert!(e[k].abs() < 0.01, "n = {n}, mode {}: error {} above 1%", k + 1, e[k]);
            }
        }
        previous = e;
    }
}

/// Worst relative difference of `frequencies` from the equal-link chain's exact ones.
fn laguerre_error(frequencies: &[f64], n: usize, link: f64, g: f64) -> f64 {
    let exact = equal_link_frequencies(n, g, link);
    frequencies.iter().zip(&exact).map(|(w, e)| ((w - e) / e).abs()).fold(0.0, f64::max)
}

#[test]
fn uniform_chain_has_the_laguerre_frequencies_exactly() {
    // Every mode of every n, not only the first three in the limit.
    let (length, g) = (2.0, 9.81);
    for n in [1, 2, 3, 10, 25, 50, 100, 200] {
        let chain = Chain::<Dyn>::uniform(n, 1.0 / n as f64, length / n as f64, g).unwrap();
        let frequencies = normal_modes(&chain).frequencies;
        let error = laguerre_error(frequencies.as_slice(), n, length / n as f64, g);
        println!("n = {n}: worst relative error against √((g/l) x_k) {error:.1e}");
        assert!(error < 1e-10, "n = {n}: {error:e}");
    }
}

#[test]
fn an_off_by_one_tail_mass_passes_bernoulli_but_not_laguerre() {
    // The eigenproblem K v = ω² W v of a uniform 100-link chain built with tail masses
    // counted one link too far (M_i = (n − i + 2) m instead of (n − i + 1) m): it
    // converges to Bernoulli's frequencies as well, so the 1 % bound lets it through; the
    // exact frequencies at the same n do not.
    let (n, length, g) = (100, 2.0, 9.81);
    let l = length / n as f64;
    let tail = |i: usize| (n - i + 1) as f64; // 0-based: n − (i + 1) + 2
    let w = DMatrix::from_fn(n, n, |i, j| tail(i.max(j)) * l * l);
    let k = DMatrix::from_fn(n, n, |i, j| if i == j { g * tail(i) * l } else { 0.0 });
    // W = C Cᵀ: the eigenvalues of C⁻¹ K C⁻ᵀ.
    let c = w.cholesky().unwrap().l();
    let c_inv = c.clone().try_inverse().unwrap();
    let mut squares: Vec<f64> =
        (&c_inv * &k * c_inv.transpose()).symmetric_eigenvalues().iter().copied().collect();
    squares.sort_by(f64::total_cmp);
    let frequencies: Vec<f64> = squares.iter().map(|s| s.sqrt()).collect();
    for (kk, zero) in J0_ZEROS.iter().enumerate() {
        let bernoulli = 0.5 * zero * (g / length).sqrt();
        let error = (frequencies[kk] - bernoulli) / bernoulli;
        assert!(error.abs() < 0.01, "mode {}: Bernoulli error {error:e}", kk + 1);
    }
    let error = laguerre_error(&frequencies, n, l, g);
    println!("off-by-one tail mass at n = {n}: worst error against Laguerre {error:.1e}");
    assert!(error > 1e-3, "{error:e}");
}

#[test]
fn fixed_size_chain_gives_the_same_modes() {
    let dynamic = Chain::<Dyn>::uniform(5, 0.2, 0.3, 9.81).unwrap();
    let fixed = Chain::<nalgebra::Const<5>>::uniform(5, 0.2, 0.3, 9.81).unwrap();
    let (a, b) = (normal_modes(&dynamic), normal_modes(&fixed));
    for k in 0..5 {
        assert!((a.frequencies[k] - b.frequencies[k]).abs() <= 1e-13 * a.frequencies[k]);
    }
}
