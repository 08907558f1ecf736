//! Fixtures of the control tests and examples: planar chains held upright (θ = π) by a
//! linear state feedback `σ = −K (x − x_up)` computed every period and held as joint
//! torques over it, and that sampled loop's linear theory.

use std::error::Error;
use std::f64::consts::PI;

use nalgebra::{DMatrix, DVector};

/// A state `x = (θ, θ̇)` of `n` links less upright at rest: `(θ − π, θ̇)`.
pub fn from_up(x: &[f64], n: usize) -> DVector<f64> {
    DVector::from_fn(2 * n, |i, _| if i < n { x[i] - PI } else { x[i] })
}

/// Distance of a state `x = (θ, θ̇)` of `n` links from upright at rest, `|x − x_up|`.
pub fn from_upright(x: &[f64], n: usize) -> f64 {
    from_up(x, n).norm()
}

/// `σ = −K (x − x_up)` of every state of `rows` (`2n` each), rows of `n` (N·m).
pub fn torques_of(gain: &DMatrix<f64>, rows: &[f64], n: usize) -> Vec<f64> {
    rows.chunks(2 * n).flat_map(|x| (-gain * from_up(x, n)).iter().copied().collect::<Vec<_>>()).collect()
}

/// Each state's distance from upright at the start and after each of `periods` periods of
/// control by `gain` from the states `rows` (`2n` each): `period(rows, torques)` runs one
/// period with the torques held and leaves the new states in `rows`.
pub fn controlled(
    gain: &DMatrix<f64>,
    (mut rows, n): (Vec<f64>, usize),
    periods: usize,
    mut period: impl FnMut(&mut Vec<f64>, &[f64]) -> Result<(), Box<dyn Error>>,
) -> Result<Vec<Vec<f64>>, Box<dyn Error>> {
    let distances = |rows: &[f64]| rows.chunks(2 * n).map(|x| from_upright(x, n)).collect::<Vec<_>>();
    let mut out = vec![distances(&rows)];
    for _ in 0..periods {
        let torque = torques_of(gain, &rows, n);
        period(&mut rows, &torque)?;
        out.push(distances(&rows));
    }
    Ok(out)
}

/// The sampled loop's map over one period `T` (s) of `ẋ = A x + B σ` with
/// `σ = −K x` held over it: `Φ − Γ K`, `Φ = e^{A T}`, `Γ = ∫_0^T e^{A s} ds B`, from the top
/// rows of `exp([[A, B], [0, 0]] T)`.
pub fn sampled_loop(a: &DMatrix<f64>, b: &DMatrix<f64>, gain: &DMatrix<f64>, period: f64) -> DMatrix<f64> {
    let (states, inputs) = b.shape();
    let mut augmented = DMatrix::zeros(states + inputs, states + inputs);
    augmented.view_mut((0, 0), (states, states)).copy_from(&(a * period));
    augmented.view_mut((0, states), (states, inputs)).copy_from(&(b * period));
    let exp = augmented.exp();
    exp.view((0, 0), (states, states)) - exp.view((0, states), (states, inputs)) * gain
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A double integrator `ẍ = σ` under `σ = −k x` held over `T`: `x_1 = x_0 (1 − k T²/2)`,
    /// `ẋ_1 = −k T x_0`.
    #[test]
    fn the_sampled_loop_of_a_double_integrator_is_its_exact_zero_order_hold() {
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        let b = DMatrix::from_row_slice(2, 1, &[0.0, 1.0]);
        let (k, t) = (3.0, 0.1);
        let map = sampled_loop(&a, &b, &DMatrix::from_row_slice(1, 2, &[k, 0.0]), t);
        let expected = DMatrix::from_row_slice(2, 2, &[1.0 - k * t * t / 2.0, t, -k * t, 1.0]);
        assert!((map - expected).amax() < 1e-14);
    }
}
