//! [`PlanarTangents`]' full Jacobians in the links' own angles, O(n²) with a small constant.
//!
//! In the links' frames (`C_j = cos(θ_j − θ_{j−1})`, `S_j = sin(θ_j − θ_{j−1})`, the pulls
//! `f_i = σ_i/l_i − (λ_i/l_i) θ̇_i`, `A` the tension system with `A_ii = 1/m_i + 1/m_{i−1}`
//! and `A_{j,j−1} = −C_j/m_{j−1}`) the solve is `A T = b` and `θ̈ = h(θ, θ̇, σ, p̈, T)`:
//! ```text
//! b_i = l_i θ̇_i² + f_{i+1} S_{i+1}/m_i − f_{i−1} S_i/m_{i−1}  [+ u_0·(g⃗ − p̈) for i = 0]
//! θ̈_i = (f_i A_ii − f_{i+1} C_{i+1}/m_i − f_{i−1} C_i/m_{i−1}
//!         + T_{i+1} S_{i+1}/m_i − T_{i−1} S_i/m_{i−1}) / l_i   [− n_0·(p̈ − g⃗)/l_0 for i = 0]
//! ```
//! With the residual `r = b − A T` at fixed `T` and `H = ∂h/∂T` (tridiagonal, zero
//! diagonal), `∂θ̈/∂x = ∂h/∂x + G ∂r/∂x` with `G = H A⁻¹`. Every column `x` (an angle,
//! rate or torque of link `x`, or the pivot) changes `r` and `h` in rows `x − 1 … x + 1`
//! only, so after `G` (n solves with the kept factors of `A`, all outputs at once) each
//! entry costs three multiply-adds.

use super::PlanarTangents;

impl PlanarTangents<'_> {
    /// `∂θ̈/∂θ`, `∂θ̈/∂θ̇` and, if asked, `∂θ̈/∂σ` and `∂θ̈/∂p̈`, column-major (module docs).
    pub(super) fn blocks(&self, dq: &mut [f64], dqd: &mut [f64], inputs: Option<(&mut [f64], &mut [f64])>) {
        let n = self.sin_cos.len();
        if n == 0 {
            return;
        }
        let rods = self.rods;
        let (im, il, length, drag) = (rods.inverse_mass(), rods.inverse_length(), rods.length(), rods.drag());
        let (sc, f, rates) = (&self.sin_cos, &self.pulls, &self.rates);
        let t = |i: usize| self.solve.tension(i);
        // Joint j between links j − 1 and j (j = 1..n; entries 0 and n zeros): C_j, S_j and the
        // derivatives of r_{j−1}, r_j, h_{j−1}, h_j by φ_j = θ_j − θ_{j−1}.
        let mut joints = vec![Joint::default(); n + 1];
        for j in 1..n {
            let ([s0, c0], [s1, c1]) = (sc[j - 1], sc[j]);
            let (cj, sj) = (c0 * c1 + s0 * s1, s1 * c0 - c1 * s0);
            let w = im[j - 1];
            joints[j] = Joint {
                cos: cj,
                sin: sj,
                r_above: w * (f[j] * cj - sj * t(j)),
                r_below: w * (-f[j - 1] * cj - sj * t(j - 1)),
                h_above: il[j - 1] * w * (f[j] * sj + t(j) * cj),
                h_below: il[j] * w * (f[j - 1] * sj - t(j - 1) * cj),
            };
        }
        // G = H A⁻¹, column-major: column j is row j of A⁻¹ Hᵀ, the solve of every output
        // at once, each a row operation of the kept elimination.
        let mut green = vec![0.0; n * n];
        for j in 0..n {
            if j >= 1 {
                green[j * n + j - 1] = il[j - 1] * im[j - 1] * joints[j].sin;
            }
            if j + 1 < n {
                green[j * n + j + 1] = -il[j + 1] * im[j] * joints[j + 1].sin;
            }
        }
        for j in 1..n {
            let factor = self.solve.factor(j);
            let (above, here) = green.split_at_mut(j * n);
            // Rows i > j + 1 of column j − 1 are still zero.
            let end = (j + 1).min(n);
            for (g, a) in here[..end].iter_mut().zip(&above[(j - 1) * n..(j - 1) * n + end]) {
                *g -= factor * a;
            }
        }
        let last = self.solve.inverse_pivot(n - 1);
        green[(n - 1) * n..].iter_mut().for_each(|g| *g *= last);
        for j in (0..n - 1).rev() {
            let (inverse_pivot, factor) = (self.solve.inverse_pivot(j), self.solve.factor(j + 1));
            let (here, below) = green.split_at_mut((j + 1) * n);
            for (g, b) in here[j * n..].iter_mut().zip(&below[..n]) {
                *g = *g * inverse_pivot - factor * b;
            }
        }
        // Column x of the Jacobian from G's columns x − 1, x, x + 1; a coefficient outside
        // the chain is zero (the joints there are), so its column may be any.
        let mix = |out: &mut [f64], x: usize, r: [f64; 3], h: [f64; 3]| {
            let column = |j: usize| &green[j * n..(j + 1) * n];
            let (above, here, below) = (column(x.saturating_sub(1)), column(x), column((x + 1).min(n - 1)));
            for (o, ((a, g), b)) in out.iter_mut().zip(above.iter().zip(here).zip(below)) {
                *o = r[0] * a + r[1] * g + r[2] * b;
            }
            if x >= 1 {
                out[x - 1] += h[0];
            }
            out[x] += h[1];
            if x + 1 < n {
                out[x + 1] += h[2];
            }
        };
        let [px, py] = self.solve.pivot();
        let g = self.gravity;
        let [s0, c0] = sc[0];
        // By θ_x: through φ_x (+1) and φ_{x+1} (−1); link 0's u_0·(g⃗ − p̈) and −n_0·(p̈ − g⃗)/l_0.
        for x in 0..n {
            let (a, b) = (joints[x], joints[x + 1]);
            let (mut r, mut h) = (
                [a.r_above, a.r_below - b.r_above, -b.r_below],
                [a.h_above, a.h_below - b.h_above, -b.h_below],
            );
            if x == 0 {
                r[1] -= s0 * (g + py) + c0 * px;
                h[1] += il[0] * (s0 * px - c0 * (g + py));
            }
            mix(&mut dq[x * n..(x + 1) * n], x, r, h);
        }
        // By the pull f_x, then θ̇_x = −(λ_x/l_x) f_x plus 2 l_x θ̇_x in b_x, and σ_x = f_x/l_x.
        let pull = |x: usize| {
            // Joints 0 and n are zeros: the entries outside the chain vanish with them.
            let (above, below) = (joints[x], joints[x + 1]);
            let (im_above, il_above) = if x >= 1 { (im[x - 1], il[x - 1]) } else { (0.0, 0.0) };
            let il_below = il.get(x + 1).copied().unwrap_or(0.0);
            let r = [im_above * above.sin, 0.0, -im[x] * below.sin];
            let h =
                [-il_above * im_above * above.cos, il[x] * (im[x] + im_above), -il_below * im[x] * below.cos];
            (r, h)
        };
        let scale = |k: f64, v: [f64; 3]| v.map(|e| k * e);
        for x in 0..n {
            let (r, h) = pull(x);
            let mut rate = scale(-drag[x], r);
            rate[1] += 2.0 * length[x] * rates[x];
            mix(&mut dqd[x * n..(x + 1) * n], x, rate, scale(-drag[x], h));
        }
        if let Some((dtorque, dpivot)) = inputs {
            for x in 0..n {
                let (r, h) = pull(x);
                mix(&mut dtorque[x * n..(x + 1) * n], x, scale(il[x], r), scale(il[x], h));
            }
            mix(&mut dpivot[..n], 0, [0.0, -s0, 0.0], [0.0, -il[0] * c0, 0.0]);
            mix(&mut dpivot[n..2 * n], 0, [0.0, c0, 0.0], [0.0, -il[0] * s0, 0.0]);
        }
    }
}

/// One joint's terms (module docs): `C_j`, `S_j` and `∂r_{j−1}`, `∂r_j`, `∂h_{j−1}`,
/// `∂h_j` by `φ_j = θ_j − θ_{j−1}` (zero for the joints outside the chain).
#[derive(Debug, Clone, Copy, Default)]
struct Joint {
    cos: f64,
    sin: f64,
    r_above: f64,
    r_below: f64,
    h_above: f64,
    h_below: f64,
}
