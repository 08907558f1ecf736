//! The zeros `j_{0,k}` of the Bessel function J0, for Bernoulli's hanging-chain frequencies
//! `ω_k = (j_{0,k} / 2) √(g/L)` (a uniform chain of length L, in the continuum limit).

/// The first ten positive zeros of the Bessel function J0 (Abramowitz & Stegun, table 9.5).
const J0_ZEROS: [f64; 10] = [
    2.404825557695773,
    5.520078110286311,
    8.653727912911013,
    11.79153443901428,
    14.93091770848779,
    18.07106396791092,
    21.21163662987926,
    24.3524715307493,
    27.49347913204025,
    30.63460646843198,
];

/// The k-th positive zero of the Bessel function J0 (k ≥ 1): tabulated for k ≤ 10, beyond
/// by McMahon's expansion `j ≈ β + 1/(8β) − 124/(3 (8β)³) + 120928/(15 (8β)⁵)`,
/// `β = (k − ¼)π` (relative error below 1e-9 there).
pub fn bessel_j0_zero(k: usize) -> f64 {
    if let Some(&j) = J0_ZEROS.get(k.wrapping_sub(1)) {
        return j;
    }
    let beta = (k as f64 - 0.25) * std::f64::consts::PI;
    let b8 = 8.0 * beta;
    beta + 1.0 / b8 - 124.0 / (3.0 * b8.powi(3)) + 120928.0 / (15.0 * b8.powi(5))
}

#[cfg(test)]
mod tests {
    #[test]
    fn mcmahon_continues_the_table() {
        // At k = 10 the expansion already agrees with the table; beyond it takes over.
        let beta = 9.75 * std::f64::consts::PI;
        let b8 = 8.0 * beta;
        let mcmahon = beta + 1.0 / b8 - 124.0 / (3.0 * b8.powi(3)) + 120928.0 / (15.0 * b8.powi(5));
        assert!((mcmahon - super::bessel_j0_zero(10)).abs() < 1e-9 * mcmahon);
        // j_{0,11} = 33.77582021357357.
        assert!((super::bessel_j0_zero(11) - 33.77582021357357).abs() < 1e-9 * 33.8);
    }
}
