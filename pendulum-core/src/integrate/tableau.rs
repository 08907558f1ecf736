//! Butcher tableaux of the Gauss–Legendre methods with s = 1, 2, 3 stages, exact to the last bit.

use nalgebra::{U1, U2, U3};

/// A Butcher tableau of at most three stages: `c_i = Σ_j a_ij`, weights `b_i`, order `order`.
///
/// Entries beyond `stages` are zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tableau {
    /// Number of stages `s`.
    pub stages: usize,
    /// Classical order of the method.
    pub order: usize,
    /// Coefficient matrix `a_ij` (row `i` gives stage `i`).
    pub a: [[f64; 3]; 3],
    /// Weights `b_i`.
    pub b: [f64; 3],
    /// Nodes `c_i`.
    pub c: [f64; 3],
}

/// The implicit midpoint rule: Gauss–Legendre with one stage, order 2.
///
/// `c = ½`, `a = ½`, `b = 1` (all exact in binary).
pub const GAUSS_1: Tableau = Tableau {
    stages: 1,
    order: 2,
    a: [[0.5, 0.0, 0.0], [0.0; 3], [0.0; 3]],
    b: [1.0, 0.0, 0.0],
    c: [0.5, 0.0, 0.0],
};

/// Gauss–Legendre with two stages, order 4 (the seed document's eqs 53–59).
///
/// `c = ½ ∓ √3/6`, `a = [[¼, ¼ − √3/6], [¼ + √3/6, ¼]]`, `b = (½, ½)`.
///
/// The document's coefficients (eqs 56–59: `a11 = 1/4`, `a12 = 1/4 − √3/6`,
/// `a21 = 1/4 + √3/6`, `a22 = 1/4`) and its update rule (eq 55:
/// `x(t+h) = x(t) + h (k1 + k2)/2`) match this standard tableau, with the nodes in
/// increasing order `c1 = ½ − √3/6 < c2 = ½ + √3/6` (the row sums of `a`). The document's
/// system (eq 51) is autonomous, so it never needs `c`; a time-dependent drive does, and
/// stage `i` is evaluated at `t + c_i h`.
///
/// Each literal is the f64 nearest to the exact value (checked by the unit tests against
/// 25-digit decimals and a double-double evaluation).
pub const GAUSS_2: Tableau = Tableau {
    stages: 2,
    order: 4,
    a: [[0.25, -0.03867513459481288, 0.0], [0.5386751345948129, 0.25, 0.0], [0.0; 3]],
    b: [0.5, 0.5, 0.0],
    c: [0.2113248654051871, 0.7886751345948129, 0.0],
};

/// Gauss–Legendre with three stages, order 6.
///
/// `c = (½ − √15/10, ½, ½ + √15/10)`, `b = (5/18, 4/9, 5/18)`,
/// ```text
/// a = [ 5/36           2/9 − √15/15   5/36 − √15/30 ]
///     [ 5/36 + √15/24  2/9            5/36 − √15/24 ]
///     [ 5/36 + √15/30  2/9 + √15/15   5/36          ]
/// ```
/// (Hairer, Nørsett & Wanner, *Solving ODEs I*, table II.7.4). Each literal is the f64
/// nearest to the exact value.
pub const GAUSS_3: Tableau = Tableau {
    stages: 3,
    order: 6,
    a: [
        [0.1388888888888889, -0.0359766675249389, 0.009789444015308325],
        [0.30026319498086457, 0.2222222222222222, -0.022485417203086815],
        [0.26798833376246944, 0.48042111196938336, 0.1388888888888889],
    ],
    b: [0.2777777777777778, 0.4444444444444444, 0.2777777777777778],
    c: [0.11270166537925831, 0.5, 0.8872983346207417],
};

/// The number of stages of a Gauss–Legendre method as a nalgebra dimension (`U1`, `U2`,
/// `U3`), tied to its tableau. The stage matrices of
/// [`GaussLegendre`](super::GaussLegendre) are `dim × s`, its Newton matrix
/// `(s·dim) × (s·dim)`, all sized at compile time for fixed-size systems.
pub trait GaussStages: nalgebra::DimName {
    /// The method's tableau.
    const TABLEAU: Tableau;
}

impl GaussStages for U1 {
    const TABLEAU: Tableau = GAUSS_1;
}

impl GaussStages for U2 {
    const TABLEAU: Tableau = GAUSS_2;
}

impl GaussStages for U3 {
    const TABLEAU: Tableau = GAUSS_3;
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: [Tableau; 3] = [GAUSS_1, GAUSS_2, GAUSS_3];

    /// Order conditions of quadrature, `B(2s)`: `Σ b_i c_i^{k−1} = 1/k` for `k = 1..2s`,
    /// and the simplifying assumption `C(s)`: `Σ_j a_ij c_j^{k−1} = c_i^k / k` for
    /// `k = 1..s`. Together they give order `2s`.
    #[test]
    fn tableaux_satisfy_b_2s_and_c_s() {
        for t in ALL {
            let s = t.stages;
            assert_eq!(t.order, 2 * s);
            for k in 1..=2 * s {
                let sum: f64 = (0..s).map(|i| t.b[i] * t.c[i].powi(k as i32 - 1)).sum();
                assert!((sum - 1.0 / k as f64).abs() < 3e-16, "B({k}) for s = {s}: {sum}");
            }
            for i in 0..s {
                for k in 1..=s {
                    let sum: f64 = (0..s).map(|j| t.a[i][j] * t.c[j].powi(k as i32 - 1)).sum();
                    let exact = t.c[i].powi(k as i32) / k as f64;
                    assert!((sum - exact).abs() < 3e-16, "C({k}) row {i} for s = {s}: {sum} vs {exact}");
                }
            }
            // Also D(s): Σ_i b_i c_i^{k−1} a_ij = b_j (1 − c_j^k) / k.
            for j in 0..s {
                for k in 1..=s {
                    let sum: f64 = (0..s).map(|i| t.b[i] * t.c[i].powi(k as i32 - 1) * t.a[i][j]).sum();
                    let exact = t.b[j] * (1.0 - t.c[j].powi(k as i32)) / k as f64;
                    assert!((sum - exact).abs() < 3e-16, "D({k}) column {j} for s = {s}");
                }
            }
        }
    }

    /// Every literal parses identically from a 25-significant-digit decimal of the exact
    /// value (Rust's float parsing rounds correctly), computed with Python's `decimal` at
    /// 40 digits: `Decimal(15).sqrt()` etc.
    #[test]
    fn literals_are_the_correctly_rounded_decimals() {
        let cases: [(f64, &str); 17] = [
            (GAUSS_2.c[0], "2.1132486540518711774542561e-1"),
            (GAUSS_2.c[1], "7.8867513459481288225457439e-1"),
            (GAUSS_2.a[0][1], "-3.8675134594812882254574390e-2"),
            (GAUSS_2.a[1][0], "5.3867513459481288225457439e-1"),
            (GAUSS_3.c[0], "1.1270166537925831148207346e-1"),
            (GAUSS_3.c[2], "8.8729833462074168851792654e-1"),
            (GAUSS_3.a[0][0], "1.3888888888888888888888889e-1"),
            (GAUSS_3.a[2][2], "1.3888888888888888888888889e-1"),
            (GAUSS_3.a[1][1], "2.2222222222222222222222222e-1"),
            (GAUSS_3.b[0], "2.7777777777777777777777778e-1"),
            (GAUSS_3.b[1], "4.4444444444444444444444444e-1"),
            (GAUSS_3.a[0][1], "-3.5976667524938903456395471e-2"),
            (GAUSS_3.a[0][2], "9.7894440153083260495800422e-3"),
            (GAUSS_3.a[1][0], "3.0026319498086459243802495e-1"),
            (GAUSS_3.a[1][2], "-2.2485417203086814660247169e-2"),
            (GAUSS_3.a[2][0], "2.6798833376246945172819774e-1"),
            (GAUSS_3.a[2][1], "4.8042111196938334790083992e-1"),
        ];
        for (literal, decimal) in cases {
            assert_eq!(literal.to_bits(), decimal.parse::<f64>().unwrap().to_bits(), "{decimal}");
        }
        assert_eq!(GAUSS_3.b[2], GAUSS_3.b[0]);
        assert_eq!(GAUSS_3.c[1], 0.5);
        assert_eq!(GAUSS_2.a[0][0], 0.25);
        assert_eq!(GAUSS_2.a[1][1], 0.25);
    }

    /// A double-double number `hi + lo` (about 106 bits), just enough arithmetic to
    /// evaluate the closed forms independently of any decimal table.
    #[derive(Clone, Copy, Debug)]
    struct Dd(f64, f64);

    impl Dd {
        fn from_ratio(p: f64, q: f64) -> Dd {
            Dd(p, 0.0).div(q)
        }
        fn two_sum(a: f64, b: f64) -> Dd {
            let s = a + b;
            let v = s - a;
            Dd(s, (a - (s - v)) + (b - v))
        }
        fn add(self, o: Dd) -> Dd {
            let s = Dd::two_sum(self.0, o.0);
            Dd::two_sum(s.0, s.1 + self.1 + o.1)
        }
        fn neg(self) -> Dd {
            Dd(-self.0, -self.1)
        }
        fn div(self, q: f64) -> Dd {
            let hi = self.0 / q;
            // Remainder self − hi·q, exact in its leading part thanks to the FMA.
            let r = (-hi).mul_add(q, self.0) + self.1;
            Dd::two_sum(hi, r / q)
        }
        /// `√n` for a small integer `n`: one Newton step from the f64 root doubles the
        /// precision.
        fn sqrt(n: f64) -> Dd {
            let r = n.sqrt();
            let residual = (-r).mul_add(r, n);
            Dd::two_sum(r, residual / (2.0 * r))
        }
        /// The f64 nearest to `hi + lo`, asserting that the value is not so close to a
        /// rounding boundary that double-double precision cannot decide.
        fn rounded(self) -> f64 {
            let Dd(hi, lo) = Dd::two_sum(self.0, self.1);
            let half_ulp = (hi.abs().next_up() - hi.abs()) / 2.0;
            assert!((lo.abs() - half_ulp).abs() > 1e-28 * hi.abs(), "too close to a tie: {hi} {lo}");
            hi
        }
    }

    #[test]
    fn literals_match_double_double_closed_forms() {
        let r3 = Dd::sqrt(3.0);
        let r15 = Dd::sqrt(15.0);
        let half = Dd(0.5, 0.0);
        let quarter = Dd(0.25, 0.0);
        let f5_36 = Dd::from_ratio(5.0, 36.0);
        let f2_9 = Dd::from_ratio(2.0, 9.0);
        let cases: [(f64, Dd); 17] = [
            (GAUSS_2.c[0], half.add(r3.div(6.0).neg())),
            (GAUSS_2.c[1], half.add(r3.div(6.0))),
            (GAUSS_2.a[0][1], quarter.add(r3.div(6.0).neg())),
            (GAUSS_2.a[1][0], quarter.add(r3.div(6.0))),
            (GAUSS_3.c[0], half.add(r15.div(10.0).neg())),
            (GAUSS_3.c[2], half.add(r15.div(10.0))),
            (GAUSS_3.b[0], Dd::from_ratio(5.0, 18.0)),
            (GAUSS_3.b[1], Dd::from_ratio(4.0, 9.0)),
            (GAUSS_3.a[0][0], f5_36),
            (GAUSS_3.a[1][1], f2_9),
            (GAUSS_3.a[0][1], f2_9.add(r15.div(15.0).neg())),
            (GAUSS_3.a[0][2], f5_36.add(r15.div(30.0).neg())),
            (GAUSS_3.a[1][0], f5_36.add(r15.div(24.0))),
            (GAUSS_3.a[1][2], f5_36.add(r15.div(24.0).neg())),
            (GAUSS_3.a[2][0], f5_36.add(r15.div(30.0))),
            (GAUSS_3.a[2][1], f2_9.add(r15.div(15.0))),
            (GAUSS_3.a[2][2], f5_36),
        ];
        for (i, (literal, exact)) in cases.into_iter().enumerate() {
            assert_eq!(literal.to_bits(), exact.rounded().to_bits(), "case {i}: {literal} vs {exact:?}");
        }
    }

    /// The row sums of `a` are the nodes, to round-off (`C(1)` again, stated as the
    /// definition the document relies on).
    #[test]
    fn row_sums_are_the_nodes() {
        for t in ALL {
            for i in 0..t.stages {
                let sum: f64 = t.a[i].iter().sum();
                assert!((sum - t.c[i]).abs() <= 2.0 * f64::EPSILON, "{sum} vs {}", t.c[i]);
            }
        }
    }
}
