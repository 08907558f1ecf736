//! The planar equations as printed (section 1.1, eqs 11–26, and the dimensionless double
//! pendulum, eqs 49–50), each against the reference.

use super::state::{State, tail_masses};
use super::tally::{Recorder, ij};
use crate::expr::Scaled;

/// The planar state in the document's symbols.
struct Planar {
    n: usize,
    th: Vec<Scaled>,
    thd: Vec<Scaled>,
    l: Vec<Scaled>,
    /// Tail masses `M_1..M_n` (eq 10), 0-based.
    mt: Vec<Scaled>,
    g: Scaled,
}

impl Planar {
    fn new(st: &State) -> Planar {
        let n = st.case.links;
        Planar {
            n,
            th: st.point.q.iter().map(|&v| Scaled::exact(v)).collect(),
            thd: st.point.qd.iter().map(|&v| Scaled::exact(v)).collect(),
            l: st.params.lengths.iter().map(|&v| Scaled::exact(v)).collect(),
            mt: tail_masses(&st.params.masses),
            g: Scaled::exact(st.params.gravity),
        }
    }

    /// `sin(θ_a − θ_b)`.
    fn s(&self, a: usize, b: usize) -> Scaled {
        (self.th[a] - self.th[b]).sin()
    }

    /// `cos(θ_a − θ_b)`.
    fn c(&self, a: usize, b: usize) -> Scaled {
        (self.th[a] - self.th[b]).cos()
    }

    /// `M_max(i,j) l_i l_j`.
    fn w(&self, i: usize, j: usize) -> Scaled {
        self.mt[i.max(j)] * self.l[i] * self.l[j]
    }
}

pub(super) fn check(rec: &mut Recorder, st: &State, qdd: &[Scaled]) {
    let p = Planar::new(st);
    let n = p.n;
    let site = st.site();
    let (th, thd, l, mt, g) = (&p.th, &p.thd, &p.l, &p.mt, p.g);

    // Eq 11: T.
    let t11: Scaled = (0..n)
        .map(|i| {
            let own = mt[i] * l[i].sq() * thd[i].sq();
            let below: Scaled = (0..i).map(|j| mt[i] * l[i] * l[j] * thd[i] * thd[j] * p.c(i, j)).sum();
            let above: Scaled = (i + 1..n).map(|j| mt[j] * l[i] * l[j] * thd[i] * thd[j] * p.c(i, j)).sum();
            own + below + above
        })
        .sum();
    rec.p("11").record(site, || "T".into(), 0.5 * t11, st.kinetic());

    // Eq 12: U.
    let u12: Scaled = -(0..n).map(|i| mt[i] * g * l[i] * th[i].cos()).sum::<Scaled>();
    rec.p("12").record(site, || "U".into(), u12, st.potential());

    // Eq 15 (its two halves summed) and eq 16, against M θ̈ + c + k at random θ̈.
    for d in 0..n {
        let reference = st.lagrange_lhs(qdd, d);
        let ddt: Scaled = mt[d] * l[d].sq() * qdd[d]
            + (0..d).map(|i| mt[d] * l[d] * l[i] * qdd[i] * p.c(d, i)).sum()
            - (0..d).map(|i| mt[d] * l[d] * l[i] * thd[i] * (thd[d] - thd[i]) * p.s(d, i)).sum()
            + (d + 1..n).map(|i| mt[i] * l[d] * l[i] * qdd[i] * p.c(d, i)).sum()
            - (d + 1..n).map(|i| mt[i] * l[d] * l[i] * thd[i] * (thd[d] - thd[i]) * p.s(d, i)).sum();
        let below: Scaled = (0..d).map(|i| mt[d] * l[d] * l[i] * thd[d] * thd[i] * p.s(d, i)).sum();
        let gravity = mt[d] * g * l[d] * th[d].sin();
        let above_printed: Scaled = (d + 1..n).map(|i| mt[i] * l[d] * l[i] * thd[i] * p.c(d, i)).sum();
        let above_corrected: Scaled =
            (d + 1..n).map(|i| mt[i] * l[d] * l[i] * thd[d] * thd[i] * p.s(d, i)).sum();
        let entry = || format!("row {}", d + 1);
        rec.p("15").record(site, entry, ddt + below + above_printed + gravity, reference);
        rec.c("15").record(site, entry, ddt + below + above_corrected + gravity, reference);

        let e16: Scaled = mt[d] * l[d].sq() * qdd[d]
            + (0..d).map(|i| mt[d] * l[d] * l[i] * qdd[i] * p.c(d, i)).sum()
            + (0..d).map(|i| mt[d] * l[d] * l[i] * thd[i].sq() * p.s(d, i)).sum()
            + (d + 1..n).map(|i| mt[i] * l[d] * l[i] * qdd[i] * p.c(d, i)).sum()
            + (d + 1..n).map(|i| mt[i] * l[d] * l[i] * thd[i].sq() * p.s(d, i)).sum()
            + mt[d] * g * l[d] * th[d].sin();
        rec.p("16").record(site, entry, e16, reference);
    }

    // Eq 17: the n = 3 equations written out.
    if n == 3 {
        let (m1, m2, m3) = (mt[0], mt[1], mt[2]);
        let (l1, l2, l3) = (l[0], l[1], l[2]);
        let (a1, a2, a3) = (qdd[0], qdd[1], qdd[2]);
        let (w1, w2, w3) = (thd[0], thd[1], thd[2]);
        let rows = [
            m1 * l1.sq() * a1
                + m1 * g * l1 * th[0].sin()
                + m2 * l1 * l2 * a2 * p.c(0, 1)
                + m3 * l1 * l3 * a3 * p.c(0, 2)
                + m2 * l1 * l2 * w2.sq() * p.s(0, 1)
                + m3 * l1 * l3 * w3.sq() * p.s(0, 2),
            m2 * l2.sq() * a2
                + m2 * g * l2 * th[1].sin()
                + m2 * l2 * l1 * a1 * p.c(1, 0)
                + m2 * l2 * l1 * w1.sq() * p.s(1, 0)
                + m3 * l2 * l3 * a3 * p.c(1, 2)
                + m3 * l2 * l3 * w3.sq() * p.s(1, 2),
            m3 * l3.sq() * a3
                + m3 * g * l3 * th[2].sin()
                + m3 * l3 * l1 * a1 * p.c(2, 0)
                + m3 * l3 * l2 * a2 * p.c(2, 1)
                + m3 * l3 * l1 * w1.sq() * p.s(2, 0)
                + m3 * l3 * l2 * w2.sq() * p.s(2, 1),
        ];
        for (d, row) in rows.into_iter().enumerate() {
            rec.p("17").record(site, || format!("row {}", d + 1), row, st.lagrange_lhs(qdd, d));
        }
    }

    // The reference's S, column j = −c at θ̇ = e_j; eq 18's form: S θ̇² = −c.
    let s_ref: Vec<Vec<Scaled>> = {
        let columns: Vec<Vec<Scaled>> = (0..n).map(|j| st.velocity_terms_unit(j, None)).collect();
        (0..n).map(|i| (0..n).map(|j| -columns[j][i]).collect()).collect()
    };
    for (i, row) in s_ref.iter().enumerate() {
        let rebuilt: Scaled = row.iter().zip(thd).map(|(&s, &w)| s * w.sq()).sum();
        rec.p("18").record(site, || format!("(Sθ̇²)[{}]", i + 1), rebuilt, -st.velocity(i));
    }

    // Eq 21: h = k.
    for i in 0..n {
        rec.p("21").record(site, || format!("h[{}]", i + 1), mt[i] * g * l[i] * th[i].sin(), st.gravity(i));
    }

    // Eqs 22, 23 and the corrected 23.
    for i in 0..n {
        for j in 0..n {
            let c22 = mt[i.max(j)] * l[i] * l[j] * p.c(i, j);
            rec.p("22").record(site, || ij("C", i, j), c22, st.mass(i, j));
            let s23 = if i >= j { mt[i] * l[i] * l[j] * p.s(i, j) } else { mt[j] * l[j] * l[i] * p.s(j, i) };
            rec.p("23").record(site, || ij("S", i, j), s23, s_ref[i][j]);
            rec.c("23").record(site, || ij("S", i, j), p.w(i, j) * p.s(j, i), s_ref[i][j]);
        }
    }

    // Eq 24: the n = 3 matrices written out.
    if n == 3 {
        let (m1, m2, m3) = (mt[0], mt[1], mt[2]);
        let (l1, l2, l3) = (l[0], l[1], l[2]);
        let zero = Scaled::zero();
        let c24 = [
            [m1 * l1.sq(), m2 * l1 * l2 * p.c(1, 0), m3 * l1 * l3 * p.c(2, 0)],
            [m2 * l2 * l1 * p.c(0, 1), m2 * l2.sq(), m3 * l2 * l3 * p.c(2, 1)],
            [m3 * l3 * l1 * p.c(0, 2), m3 * l3 * l2 * p.c(1, 2), m3 * l3.sq()],
        ];
        let s24 = [
            [zero, m2 * l1 * l2 * p.s(1, 0), m3 * l1 * l3 * p.s(2, 0)],
            [m2 * l2 * l1 * p.c(0, 1), zero, m3 * l2 * l3 * p.c(2, 1)],
            [m3 * l3 * l1 * p.c(0, 2), m3 * l3 * l2 * p.c(1, 2), zero],
        ];
        let s24_corrected = [
            [zero, m2 * l1 * l2 * p.s(1, 0), m3 * l1 * l3 * p.s(2, 0)],
            [m2 * l2 * l1 * p.s(0, 1), zero, m3 * l2 * l3 * p.s(2, 1)],
            [m3 * l3 * l1 * p.s(0, 2), m3 * l3 * l2 * p.s(1, 2), zero],
        ];
        let h24 = [m1 * g * l1 * th[0].sin(), m2 * g * l2 * th[1].sin(), m3 * g * l3 * th[2].sin()];
        for i in 0..3 {
            for j in 0..3 {
                rec.p("24 C").record(site, || ij("C", i, j), c24[i][j], st.mass(i, j));
                rec.p("24 S").record(site, || ij("S", i, j), s24[i][j], s_ref[i][j]);
                rec.c("24 S").record(site, || ij("S", i, j), s24_corrected[i][j], s_ref[i][j]);
            }
            rec.p("24 h").record(site, || format!("h[{}]", i + 1), h24[i], st.gravity(i));
        }
    }

    // Eq 26: f = σ − λθ̇ is the reference's generalized force.
    for (d, &rate) in thd.iter().enumerate() {
        let f = Scaled::exact(st.point.torque[d]) - Scaled::exact(st.params.damping[d]) * rate;
        rec.p("26").record(site, || format!("f[{}]", d + 1), f, st.force(d));
    }

    if n == 2 {
        double_pendulum(rec, st, &p);
    }
}

/// Eqs 49–50: the dimensionless double pendulum, with `l = l2/l1`, `m = m2/(m1+m2)`,
/// time unscaled and `g → g/l1` (the scaling that makes eq 49 the physical equation
/// divided by `(m1+m2) l1²`; the text's `g → g/l1/(m1+m2)` is checked as "49 g").
fn double_pendulum(rec: &mut Recorder, st: &State, p: &Planar) {
    let site = st.site();
    let (m1, m2) = (Scaled::exact(st.params.masses[0]), Scaled::exact(st.params.masses[1]));
    let (l1, l2) = (p.l[0], p.l[1]);
    let m = m2 / (m1 + m2);
    let l = l2 / l1;
    let g = p.g / l1;
    let g_text = p.g / l1 / (m1 + m2);
    let (t1, t2) = (p.th[0], p.th[1]);
    let (w1, w2) = (p.thd[0], p.thd[1]);
    let one = Scaled::exact(1.0);
    let norm = (m1 + m2) * l1.sq();

    // Eq 49, first line: the matrices, and the right-hand side (second line).
    let c49 = [[one, m * l * (t2 - t1).cos()], [m * l * (t1 - t2).cos(), m * l.sq()]];
    for (i, row) in c49.into_iter().enumerate() {
        for (j, entry) in row.into_iter().enumerate() {
            rec.p("49").record(site, || ij("C", i, j), entry, st.mass(i, j) / norm);
        }
    }
    let rhs = |g: Scaled| {
        [
            m * l * w2.sq() * (t2 - t1).sin() - g * t1.sin(),
            m * l * w1.sq() * (t1 - t2).sin() - m * g * l * t2.sin(),
        ]
    };
    let (r49, r49_text) = (rhs(g), rhs(g_text));
    for i in 0..2 {
        let reference = -(st.velocity(i) + st.gravity(i)) / norm;
        let entry = || format!("rhs[{}]", i + 1);
        rec.p("49").record(site, entry, r49[i], reference);
        rec.p("49 g").record(site, entry, r49_text[i], reference);
        rec.c("49 g").record(site, entry, r49[i], reference);
    }
    let Some(acc) = st.free_accelerations() else { return };
    // Eq 49, third line: the explicit inverse.
    let det = m * l.sq() - m.sq() * l.sq() * (t2 - t1).cos().sq();
    let inv = [[m * l.sq(), -(m * l * (t2 - t1).cos())], [-(m * l * (t1 - t2).cos()), one]];
    for i in 0..2 {
        let a = (inv[i][0] * r49[0] + inv[i][1] * r49[1]) / det;
        rec.p("49").record(site, || format!("θ̈_{}", i + 1), a, acc[i]);
    }

    // Eq 50.
    let den1 = one - m * (t2 - t1).cos().sq();
    let a1 = (m * l * w2.sq() * (t2 - t1).sin()
        - g * t1.sin()
        - m * (t2 - t1).cos() * (w1.sq() * (t1 - t2).sin() - g * t2.sin()))
        / den1;
    let den2 = l - m * l * (t2 - t1).cos().sq();
    let a2 = (w1.sq() * (t1 - t2).sin()
        - g * t1.sin()
        - (t1 - t2).cos() * (m * l * w2.sq() * (t2 - t1).sin() - g * t1.sin()))
        / den2;
    let a2_corrected = (w1.sq() * (t1 - t2).sin()
        - g * t2.sin()
        - (t1 - t2).cos() * (m * l * w2.sq() * (t2 - t1).sin() - g * t1.sin()))
        / den2;
    rec.p("50").record(site, || "θ̈_1".into(), a1, acc[0]);
    rec.p("50").record(site, || "θ̈_2".into(), a2, acc[1]);
    rec.c("50").record(site, || "θ̈_1".into(), a1, acc[0]);
    rec.c("50").record(site, || "θ̈_2".into(), a2_corrected, acc[1]);
}
