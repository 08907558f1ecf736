//! The tangents of [`Directions`]' tension solve: `δü` along a change `δx = (δu, δw)` of
//! the state in O(n) (a Jacobian-vector product), and the full Jacobian of the
//! first-order system `x' = (w, ü)` in O(n²), one tangent per column.
//!
//! Rod `i`'s load is `u_i`, `|u̇_i|² = w_i·w_i` and the damping's pair `−(λ_i/l_i) w_i`, so
//! `δ` moves it by `δu_i`, `2 w_i·δw_i` and `−(λ_i/l_i) δw_i`; the rest is the tangent of
//! the solve (`rods` module). The full Jacobian takes every column at once
//! (`rods::green`): each column's load change sits on one rod.

use nalgebra::{DMatrix, DVector, DefaultAllocator, DimName, allocator::Allocator};

use super::Directions;
use super::rate_load;
use crate::drive::Drive;
use crate::error::{Error, Result};
use crate::lanes::Lane;
use crate::rods::{Column, Linearised, LoadTangent, TangentRow, unit};

impl<S: DimName, Dr: Drive<S>> Directions<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    /// The solve at `(t, x)` kept for its tangents, in `C = S::DIM` dimensions.
    fn linearised<const C: usize>(&self, t: f64, x: &[f64]) -> Linearised<C> {
        let n = self.links();
        let drag = self.rods.drag();
        let mut gravity = [0.0; C];
        gravity[C - 1] = -self.chain.gravity();
        let p = self.drive.acceleration(t);
        let pivot: [f64; C] = std::array::from_fn(|k| p[k]);
        let (directions, rates) = x.split_at(C * n);
        let (directions, rates) = (directions.as_chunks::<C>().0, rates.as_chunks::<C>().0);
        Linearised::new(&self.rods, gravity, pivot, |i| rate_load(directions[i], rates[i], drag[i]))
    }

    /// `δü = (∂ü/∂u) δu + (∂ü/∂w) δw` (1/s²) at `(t, x)` along `dx = (δu, δw)`, written
    /// into `out` (`S·n` entries): one O(n) linearised solve and one tangent pass.
    ///
    /// Errors: [`Error::LengthMismatch`] / [`Error::NonFinite`] for a bad state, direction
    /// or buffer (the direction's entries checked only when the result is not finite).
    pub fn jvp(&self, t: f64, x: &DVector<f64>, dx: &DVector<f64>, out: &mut [f64]) -> Result<()> {
        self.check_state(x)?;
        let n = self.links();
        if dx.len() != self.state_len() {
            return Err(Error::LengthMismatch { what: "dx", expected: self.state_len(), got: dx.len() });
        }
        if out.len() != S::DIM * n {
            return Err(Error::LengthMismatch { what: "out", expected: S::DIM * n, got: out.len() });
        }
        match S::DIM {
            2 => self.jvp_in::<2>(t, x.as_slice(), dx.as_slice(), out),
            _ => self.jvp_in::<3>(t, x.as_slice(), dx.as_slice(), out),
        }
        if !crate::model::all_finite(out) {
            crate::model::check_vector("dx", dx.as_slice(), self.state_len())?;
        }
        Ok(())
    }

    /// [`jvp`](Self::jvp) in `C = S::DIM` dimensions: rod `i`'s load moves by `δu_i`,
    /// `2 w_i·δw_i` and `−(λ_i/l_i) δw_i` (module docs).
    fn jvp_in<const C: usize>(&self, t: f64, x: &[f64], dx: &[f64], out: &mut [f64]) {
        let n = self.links();
        let solve = self.linearised::<C>(t, x);
        let drag = self.rods.drag();
        let rates = x[C * n..].as_chunks::<C>().0;
        let (du, dw) = dx.split_at(C * n);
        let (du, dw) = (du.as_chunks::<C>().0, dw.as_chunks::<C>().0);
        let mut rows: Vec<TangentRow<C>> = (0..n)
            .map(|i| {
                let (w, dwi) = (&rates[i], &dw[i]);
                let mut load = LoadTangent { direction: du[i], rate_squared: 0.0, pair: [0.0; C] };
                for ((pair, w), dw) in load.pair.iter_mut().zip(w).zip(dwi) {
                    load.rate_squared += 2.0 * w * dw;
                    *pair = -drag[i] * dw;
                }
                TangentRow::new(load)
            })
            .collect();
        solve.tangent(&self.rods, [0.0; C], &mut rows, out.as_chunks_mut::<C>().0);
    }

    /// The Jacobian `∂x'/∂x = [[0, I], [∂ü/∂u, ∂ü/∂w]]` of the first-order system at
    /// `(t, x)`: one linearised solve, one O(n) solve per row of `ü`, and three
    /// multiply-adds per entry (`rods::green`), O(n²) in all.
    pub fn analytic_jacobian(&self, t: f64, x: &DVector<f64>, out: &mut DMatrix<f64>) -> Result<()> {
        self.check_state(x)?;
        let len = self.state_len();
        if out.shape() != (len, len) {
            return Err(Error::LengthMismatch { what: "jacobian", expected: len * len, got: out.len() });
        }
        let half = len / 2;
        let mut lower = vec![0.0; half * len];
        self.lower_jacobian_of_valid(t, x.as_slice(), &mut lower);
        // On the slice: nalgebra's `fill` went entry by entry, half of the call at n = 20.
        out.as_mut_slice().fill(0.0);
        for i in 0..half {
            out[(i, half + i)] = 1.0;
        }
        // Column by column (column-major): the lower half of each of `out`'s is one of `lower`'s.
        let columns = out.as_mut_slice().chunks_exact_mut(len);
        for (column, lower) in columns.zip(lower.chunks_exact(half)) {
            column[half..].copy_from_slice(lower);
        }
        Ok(())
    }

    /// The lower blocks of [`analytic_jacobian`](Self::analytic_jacobian), `[∂ü/∂u, ∂ü/∂w]`
    /// (`S·n` rows, `2·S·n` columns), column-major into `lower`, at a state already checked.
    pub(crate) fn lower_jacobian_of_valid(&self, t: f64, x: &[f64], lower: &mut [f64]) {
        match S::DIM {
            2 => self.lower_jacobian_in::<2>(t, x, lower),
            _ => self.lower_jacobian_in::<3>(t, x, lower),
        }
    }

    fn lower_jacobian_in<const C: usize>(&self, t: f64, x: &[f64], lower: &mut [f64]) {
        let n = self.links();
        let half = C * n;
        let solve = self.linearised::<C>(t, x);
        let drag = self.rods.drag();
        let rates = &x[half..];
        let rows: Vec<(usize, [f64; C])> = (0..half).map(|r| (r / C, unit(r % C))).collect();
        let columns: Vec<_> = (0..2 * half).map(|b| state_column(b, n, rates, drag)).collect();
        let green = solve.green(&self.rods, &rows);
        solve.columns(&self.rods, &rows, &green, &columns, lower);
    }
}

/// Column `b` of `∂ü/∂x` as a load change of chains of `n` rods at rates `w` (`C·n`
/// numbers) with drags `λ_i/l_i` (module docs): for `b < C·n` the direction `u_i` (`i =
/// b / C`) moving along axis `k = b mod C`, beyond it the rate `w_i` (`b − C·n`), which
/// moves `|u̇_i|²` by `2 w_ik` and the pair by `−λ_i/l_i` along `k`. In lanes `V` too.
#[inline(always)]
pub(crate) fn state_column<const C: usize, V: Lane>(
    b: usize,
    n: usize,
    rates: &[V],
    drag: &[V],
) -> Column<C, V> {
    let zero = V::splat(0.0);
    let (rod, k) = ((b % (C * n)) / C, b % C);
    let load = if b < C * n {
        LoadTangent { direction: unit(k), rate_squared: zero, pair: [zero; C] }
    } else {
        let mut pair = [zero; C];
        pair[k] = -drag[rod];
        LoadTangent { direction: [zero; C], rate_squared: V::splat(2.0) * rates[b - C * n], pair }
    };
    Column { rod, load }
}

#[cfg(test)]
mod tests {
    use nalgebra::{U2, U3};

    use super::*;
    use crate::chain::Chain;
    use crate::drive::Circle;
    use crate::integrate::central_difference_jacobian;

    /// The analytic Jacobian against central differences, and the JVP against it.
    macro_rules! agrees {
        ($model:expr, $x:expr) => {{
            let (model, x) = (&$model, &$x);
            let len = model.state_len();
            let (mut analytic, mut numeric) = (DMatrix::zeros(len, len), DMatrix::zeros(len, len));
            model.analytic_jacobian(0.7, x, &mut analytic).unwrap();
            central_difference_jacobian(model, 0.7, x, &mut numeric).unwrap();
            assert!((&analytic - &numeric).amax() < 1e-6 * numeric.amax(), "{analytic} {numeric}");
            let dx = DVector::from_fn(len, |i, _| ((i as f64) * 0.9).cos());
            let mut jvp = vec![0.0; len / 2];
            model.jvp(0.7, x, &dx, &mut jvp).unwrap();
            let product = analytic.rows(len / 2, len / 2) * &dx;
            assert!((DVector::from_vec(jvp) - product).amax() < 1e-9 * analytic.amax());
        }};
    }

    #[test]
    fn planar_and_spatial_tangents_agree_with_central_differences() {
        let chain = Chain::new(&[1.0, 0.5, 2.0, 0.7], &[0.7, 1.2, 0.4, 0.9], 9.81)
            .unwrap()
            .with_damping(&[0.1, 0.2, 0.3, 0.05])
            .unwrap();
        let planar = Directions::<U2>::new(chain.clone());
        let x = planar.from_angles(&[0.4, -1.3, 2.2, 0.9], &[1.5, -0.7, 2.1, 0.3]).unwrap();
        agrees!(planar, x);
        let spatial = Directions::<U3>::new(chain).with_drive(Circle::new(0.1, 3.0).unwrap());
        let x = spatial
            .from_spherical(
                &[0.9, 1.7, 2.3, 0.5, 0.2, -1.0, 2.8, 0.3],
                &[1.5, -0.7, 2.1, 0.4, 1.2, -0.9, 0.3, 0.8],
            )
            .unwrap();
        agrees!(spatial, x);
    }

    /// Masses of 1e-150 kg take the linearised solve's continuants out of their range; the
    /// classical pivots then give the JVP of the same chain at 1 kg (no damping: the motion
    /// does not depend on the masses' scale).
    #[test]
    fn the_linearised_solve_falls_back_to_pivots_for_extreme_masses() {
        let (masses, lengths) = ([1.0, 3.0, 2.0, 1.0], [1.0, 0.5, 2.0, 1.0]);
        let tiny: Vec<f64> = masses.iter().map(|m| m * 1e-150).collect();
        let model = |m: &[f64]| {
            Directions::<U3>::new(Chain::new(m, &lengths, 9.81).unwrap())
                .with_drive(Circle::new(0.1, 3.0).unwrap())
        };
        let (normal, extreme) = (model(&masses), model(&tiny));
        let x = normal
            .from_spherical(
                &[0.9, 1.7, 2.3, 0.5, 0.2, -1.0, 2.8, 0.3],
                &[1.5, -0.7, 2.1, 0.4, 1.2, -0.9, 0.3, 0.8],
            )
            .unwrap();
        let dx = DVector::from_fn(x.len(), |i, _| ((i as f64) * 0.9).cos());
        let (mut a, mut b) = (vec![0.0; 12], vec![0.0; 12]);
        normal.jvp(0.7, &x, &dx, &mut a).unwrap();
        extreme.jvp(0.7, &x, &dx, &mut b).unwrap();
        let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(a.iter().zip(&b).all(|(p, q)| (p - q).abs() < 1e-12 * scale), "{a:?} {b:?}");
    }

    #[test]
    fn a_bad_direction_is_an_error() {
        let model = Directions::<U2>::new(Chain::uniform(3, 1.0, 1.0, 9.81).unwrap());
        let x = model.from_angles(&[0.4, -1.3, 2.2], &[1.5, -0.7, 2.1]).unwrap();
        let mut out = vec![0.0; 6];
        let mut dx = DVector::from_element(x.len(), 0.5);
        dx[7] = f64::NAN;
        let err = model.jvp(0.0, &x, &dx, &mut out).unwrap_err();
        assert!(matches!(err, Error::NonFinite { what: "dx", index: 7, .. }), "{err:?}");
        let short = DVector::from_element(x.len() - 1, 0.5);
        let err = model.jvp(0.0, &x, &short, &mut out).unwrap_err();
        assert_eq!(err, Error::LengthMismatch { what: "dx", expected: 12, got: 11 });
    }
}
