//! The spatial equations as printed (section 1.2, eqs 30–48), each against the reference.

use super::state::{State, tail_masses};
use super::tally::{Recorder, ij};
use crate::expr::Scaled;

/// The spatial state in the document's symbols.
struct Spatial {
    n: usize,
    th: Vec<Scaled>,
    ph: Vec<Scaled>,
    thd: Vec<Scaled>,
    phd: Vec<Scaled>,
    l: Vec<Scaled>,
    m: Vec<Scaled>,
    mt: Vec<Scaled>,
    g: Scaled,
}

impl Spatial {
    fn new(st: &State) -> Spatial {
        let n = st.case.links;
        let x = |v: &[f64]| v.iter().map(|&v| Scaled::exact(v)).collect::<Vec<_>>();
        Spatial {
            n,
            th: x(&st.point.q[..n]),
            ph: x(&st.point.q[n..]),
            thd: x(&st.point.qd[..n]),
            phd: x(&st.point.qd[n..]),
            l: x(&st.params.lengths),
            m: x(&st.params.masses),
            mt: tail_masses(&st.params.masses),
            g: Scaled::exact(st.params.gravity),
        }
    }

    /// `l_i l_j M_max(i,j)`.
    fn w(&self, i: usize, j: usize) -> Scaled {
        self.l[i] * self.l[j] * self.mt[i.max(j)]
    }

    fn sp(&self, i: usize, j: usize) -> Scaled {
        (self.ph[i] - self.ph[j]).sin()
    }

    fn cp(&self, i: usize, j: usize) -> Scaled {
        (self.ph[i] - self.ph[j]).cos()
    }

    fn st(&self, i: usize) -> Scaled {
        self.th[i].sin()
    }

    fn ct(&self, i: usize) -> Scaled {
        self.th[i].cos()
    }
}

pub(super) fn check(rec: &mut Recorder, st: &State) {
    let p = Spatial::new(st);
    let n = p.n;
    let site = st.site();
    let (thd, phd, l, mt, g) = (&p.thd, &p.phd, &p.l, &p.mt, p.g);

    // The reference's B (2n × 2n; columns θ̇_j², then φ̇_j²) and C (2n × n; column
    // θ̇_jφ̇_j), by unit rates and polarization: −c = B[θ̇²;φ̇²] − C[θ̇φ̇].
    let unit_th: Vec<Vec<Scaled>> = (0..n).map(|j| st.velocity_terms_unit(j, None)).collect();
    let unit_ph: Vec<Vec<Scaled>> = (0..n).map(|j| st.velocity_terms_unit(n + j, None)).collect();
    let pair: Vec<Vec<Scaled>> = (0..n).map(|j| st.velocity_terms_unit(j, Some(n + j))).collect();
    let b_ref = |r: usize, col: usize| if col < n { -unit_th[col][r] } else { -unit_ph[col - n][r] };
    let c_ref = |r: usize, j: usize| pair[j][r] - unit_th[j][r] - unit_ph[j][r];

    // Eq 30 (form) and eq 41 (the printed θ φ̇ vector with the true blocks).
    for r in 0..2 * n {
        let quadratic: Scaled =
            (0..n).map(|j| b_ref(r, j) * thd[j].sq() + b_ref(r, n + j) * phd[j].sq()).sum();
        let true_cross: Scaled = (0..n).map(|j| c_ref(r, j) * thd[j] * phd[j]).sum();
        let printed_cross: Scaled = (0..n).map(|j| c_ref(r, j) * p.th[j] * phd[j]).sum();
        let reference = -st.velocity(r);
        let entry = || format!("row {}", r + 1);
        rec.p("30").record(site, entry, quadratic - true_cross, reference);
        rec.p("41").record(site, entry, quadratic - printed_cross, reference);
        rec.c("41").record(site, entry, quadratic - true_cross, reference);
    }

    // Eqs 31–39: every block entry-wise.
    for i in 0..n {
        for j in 0..n {
            let w = p.w(i, j);
            let a11 = w * (p.cp(i, j) * p.ct(i) * p.ct(j) + p.st(i) * p.st(j));
            let a12 = w * p.sp(i, j) * p.ct(i) * p.st(j);
            let a21 = -(w * p.sp(i, j) * p.st(i) * p.ct(j));
            let a22 = w * p.cp(i, j) * p.st(i) * p.st(j);
            rec.p("31").record(site, || ij("A11", i, j), a11, st.mass(i, j));
            rec.p("32").record(site, || ij("A12", i, j), a12, st.mass(i, n + j));
            rec.p("33").record(site, || ij("A21", i, j), a21, st.mass(n + i, j));
            rec.p("34").record(site, || ij("A22", i, j), a22, st.mass(n + i, n + j));

            let b11 = w * (p.cp(i, j) * p.ct(i) * p.st(j) - p.st(i) * p.ct(j));
            let b12 = w * p.cp(i, j) * p.ct(i) * p.st(j);
            let b2x = -(w * p.sp(i, j) * p.st(i) * p.st(j));
            rec.p("35").record(site, || ij("B11", i, j), b11, b_ref(i, j));
            rec.p("36").record(site, || ij("B12", i, j), b12, b_ref(i, n + j));
            rec.p("37").record(site, || ij("B21", i, j), b2x, b_ref(n + i, j));
            rec.p("37").record(site, || ij("B22", i, j), b2x, b_ref(n + i, n + j));

            let c1 = w * p.sp(i, j) * p.ct(i) * p.ct(j);
            let c2 = w * p.cp(i, j) * p.st(i) * p.ct(j);
            rec.p("38").record(site, || ij("C1", i, j), c1, c_ref(i, j));
            rec.c("38").record(site, || ij("C1", i, j), 2.0 * c1, c_ref(i, j));
            rec.p("39").record(site, || ij("C2", i, j), c2, c_ref(n + i, j));
            rec.c("39").record(site, || ij("C2", i, j), 2.0 * c2, c_ref(n + i, j));
        }
    }

    // Eq 40: [g; 0] = k.
    for i in 0..n {
        rec.p("40").record(site, || format!("g[{}]", i + 1), l[i] * g * mt[i] * p.st(i), st.gravity(i));
        rec.p("40").record(site, || format!("0 (φ row {})", i + 1), Scaled::zero(), st.gravity(n + i));
    }

    // Eqs 42 and 43: N = 1 written out.
    if n == 1 {
        let (l1, m1, s, c) = (l[0], mt[0], p.st(0), p.ct(0));
        let (wt, wp) = (thd[0], phd[0]);
        let a42 = [[l1.sq() * m1, Scaled::zero()], [Scaled::zero(), l1.sq() * m1 * s.sq()]];
        for (i, row) in a42.into_iter().enumerate() {
            for (j, entry) in row.into_iter().enumerate() {
                rec.p("42").record(site, || ij("A", i, j), entry, st.mass(i, j));
            }
        }
        let rhs_th = l1.sq() * m1 * c * s * wp.sq() - l1 * g * m1 * s;
        let rhs_ph = -(l1.sq() * m1 * wt * wp * s * c);
        let rhs_ph_corrected = -(2.0 * (l1.sq() * m1 * wt * wp * s * c));
        let reference = |r: usize| -(st.velocity(r) + st.gravity(r));
        rec.p("42").record(site, || "rhs θ_1".into(), rhs_th, reference(0));
        rec.p("42").record(site, || "rhs φ_1".into(), rhs_ph, reference(1));
        rec.c("42").record(site, || "rhs θ_1".into(), rhs_th, reference(0));
        rec.c("42").record(site, || "rhs φ_1".into(), rhs_ph_corrected, reference(1));

        if let Some(acc) = st.free_accelerations() {
            let theta = wp.sq() * c * s - g / l1 * s;
            let phi = wt * wp * (c / s);
            let phi_corrected = -(2.0 * (wt * wp * (c / s)));
            rec.p("43").record(site, || "θ̈_1".into(), theta, acc[0]);
            rec.p("43").record(site, || "φ̈_1".into(), phi, acc[1]);
            rec.c("43").record(site, || "θ̈_1".into(), theta, acc[0]);
            rec.c("43").record(site, || "φ̈_1".into(), phi_corrected, acc[1]);
        }
    }

    // Eq 47: v_i² (1-based i ↔ 0-based i here), checked through T = ½ Σ m_i v_i².
    let v2 = |i: usize| -> Scaled {
        let own: Scaled = (0..=i).map(|j| l[j].sq() * (phd[j].sq() * p.st(j).sq() + thd[j].sq())).sum();
        let mut cross = Scaled::zero();
        for j in 0..=i {
            for k in (0..=i).filter(|&k| k != j) {
                cross = cross
                    + l[j] * l[k] * thd[j] * thd[k] * (p.cp(j, k) * p.ct(j) * p.ct(k) + p.st(j) * p.st(k))
                    + l[j] * l[k] * phd[j] * phd[k] * p.cp(j, k) * p.st(j) * p.st(k)
                    + 2.0 * (l[j] * l[k] * thd[j] * phd[k] * p.sp(j, k) * p.ct(j) * p.st(k));
            }
        }
        own + cross
    };
    let t47: Scaled = (0..n).map(|i| p.m[i] * v2(i)).sum();
    rec.p("47").record(site, || "T".into(), 0.5 * t47, st.kinetic());

    // Eq 48: T.
    let own: Scaled = (0..n).map(|i| l[i].sq() * mt[i] * (phd[i].sq() * p.st(i).sq() + thd[i].sq())).sum();
    let mut t48 = 0.5 * own;
    for i in 0..n {
        for j in i + 1..n {
            t48 = t48
                + l[i]
                    * l[j]
                    * mt[j]
                    * thd[i]
                    * thd[j]
                    * (p.cp(i, j) * p.ct(i) * p.ct(j) + p.st(i) * p.st(j))
                + l[i] * l[j] * mt[j] * phd[i] * phd[j] * p.cp(i, j) * p.st(i) * p.st(j);
        }
        for j in (0..n).filter(|&j| j != i) {
            t48 = t48 + p.w(i, j) * thd[i] * phd[j] * p.sp(i, j) * p.ct(i) * p.st(j);
        }
    }
    rec.p("48").record(site, || "T".into(), t48, st.kinetic());

    // "U is the same as eq 12" (the remark after eq 48).
    let u12: Scaled = -(0..n).map(|i| mt[i] * g * l[i] * p.ct(i)).sum::<Scaled>();
    rec.p("12").record(site, || "U".into(), u12, st.potential());
}
