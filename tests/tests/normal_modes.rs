//! Small oscillations of a uniform hanging chain approach Bernoulli's heavy string:
//! `ω_k = (j_{0,k} / 2) sqrt(g / L)`, `j_{0,k}` the zeros of the Bessel function J0.

use nalgebra::Dyn;
use pendulum_core::{Chain, normal_modes};

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

#[test]
fn fixed_size_chain_gives_the_same_modes() {
    let dynamic = Chain::<Dyn>::uniform(5, 0.2, 0.3, 9.81).unwrap();
    let fixed = Chain::<nalgebra::Const<5>>::uniform(5, 0.2, 0.3, 9.81).unwrap();
    let (a, b) = (normal_modes(&dynamic), normal_modes(&fixed));
    for k in 0..5 {
        assert!((a.frequencies[k] - b.frequencies[k]).abs() <= 1e-13 * a.frequencies[k]);
    }
}
