//! "The document as printed": a numerical check of the seed document's hand derivation.
//!
//! The seed document ("鎖を振り回したい", 中山大樹, 2018) prints the
//! equations of motion of planar and spatial N-link pendulums. Its equations are
//! *claims*; the truth is the sympy reference in `reference/cases` (positions → T, U →
//! Euler–Lagrange). This module encodes the printed equations **exactly as printed**
//! (typos included) and compares each one, in isolation, with the reference at many
//! random states: every ingredient other than the equation under test is taken from
//! the reference, so each verdict is attributable to that one equation.
//!
//! Reference conventions: `M q̈ + c + k + d = Q`, `c` the velocity terms (exactly
//! quadratic in the rates), `k = ∂U/∂q`. In the document's planar notation (eq 18)
//! `C = M`, `S θ̇² = −c`, `h = k`; in the spatial block form (eq 30)
//! `B [θ̇²; φ̇²] − C [θ̇φ̇] − [g; 0] = −c − k`. The reference's coefficient matrices
//! `S`, `B`, `C` are extracted numerically from `c` (unit rates and polarization).
//!
//! Every compared number carries an absolute round-off scale (the sum of the absolute
//! values of the terms it was computed from): one rule, [`Scaled`], tracked through the
//! printed formula here and through the reference's expressions by
//! [`Case::evaluate_with_scales`]. The relative error of an entry is
//! `|printed − reference| / (scale_printed + scale_reference)`; an equation agrees if
//! its worst relative error over all entries, cases and states is below [`AGREEMENT`].
//!
//! The verdicts are recorded in `reference/ERRATA.md` (with the corrected forms, which
//! are checked here too); [`run`] fails if the measured findings no longer match it.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{Context, bail};
use nalgebra::{DMatrix, DVector};
use rand::Rng;

use crate::case::{Case, Evaluated, Kind, Params, Point};
use crate::expr::Scaled;

/// An equation agrees with the reference if its worst relative error is below this.
pub const AGREEMENT: f64 = 1e-10;

/// Where the errata (and the machine-readable summary table) live.
pub fn errata_path() -> PathBuf {
    crate::workspace_root().join("reference").join("ERRATA.md")
}

// ---------------------------------------------------------------------------------
// Relative error
// ---------------------------------------------------------------------------------

/// `|p − r| / (scale_p + scale_r)`; 0 if they are equal, ∞ if they differ at zero scale.
pub fn relative_error(printed: Scaled, reference: Scaled) -> f64 {
    let diff = (printed.v - reference.v).abs();
    if diff == 0.0 {
        return 0.0;
    }
    diff / (printed.s + reference.s)
}

// ---------------------------------------------------------------------------------
// Findings
// ---------------------------------------------------------------------------------

/// The outcome of checking one printed equation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    Agrees,
    Disagrees,
    /// No case of the right kind and size was given.
    Untested,
}

impl Verdict {
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Agrees => "agrees",
            Verdict::Disagrees => "disagrees",
            Verdict::Untested => "untested",
        }
    }
}

/// What was measured for one printed equation.
#[derive(Clone, Debug)]
pub struct Finding {
    /// The equation number as printed (with a suffix where one printed equation holds
    /// several separately checked claims), as in the ERRATA summary table.
    pub equation: &'static str,
    pub claim: &'static str,
    pub verdict: Verdict,
    /// The worst relative error over all entries, cases and states.
    pub worst: f64,
    /// The first disagreeing entry: case, state, entry, printed and reference values.
    pub first_disagreement: Option<String>,
    /// For a disagreeing equation: the verdict and worst error of the corrected form
    /// given in ERRATA.md, evaluated the same way.
    pub corrected: Option<(Verdict, f64)>,
}

struct Check {
    equation: &'static str,
    claim: &'static str,
}

/// Every checked equation, in document order.
const CHECKS: &[Check] = &[
    Check {
        equation: "11",
        claim: "planar T = ½Σ_i(M_i l_i²θ̇_i² + Σ_{j<i} M_i… + Σ_{j>i} M_j… l_i l_j θ̇_iθ̇_j cos(θ_i−θ_j))",
    },
    Check {
        equation: "12", claim: "U = −Σ M_i g l_i cos θ_i (planar; and spatial, as said after eq 48)"
    },
    Check { equation: "15", claim: "d/dt ∂L/∂θ̇_d and −∂L/∂θ_d written out (their sum)" },
    Check {
        equation: "16",
        claim: "planar equation of motion: … + Σ W_di θ̇_i² sin(θ_d−θ_i) + M_d g l_d sin θ_d = 0",
    },
    Check { equation: "17", claim: "the n = 3 equations of motion written out" },
    Check { equation: "18", claim: "planar velocity terms are S θ̇² (squares of the rates only)" },
    Check { equation: "21", claim: "h_i = M_i g l_i sin θ_i" },
    Check { equation: "22", claim: "C_ij = M_max(i,j) l_i l_j cos(θ_i−θ_j)" },
    Check {
        equation: "23", claim: "S_ij = M_i l_i l_j sin(θ_i−θ_j) (i≥j), M_j l_j l_i sin(θ_j−θ_i) (i<j)"
    },
    Check { equation: "24 C", claim: "n = 3 mass matrix C written out" },
    Check { equation: "24 S", claim: "n = 3 matrix S written out" },
    Check { equation: "24 h", claim: "n = 3 vector h written out" },
    Check { equation: "26", claim: "generalized force f_d = σ_d − λ_d θ̇_d" },
    Check {
        equation: "30", claim: "spatial velocity terms are B[θ̇²;φ̇²] − C[θ̇φ̇] (no other products)"
    },
    Check { equation: "31", claim: "A11 = W(cos(φ_i−φ_j)cosθ_i cosθ_j + sinθ_i sinθ_j)" },
    Check { equation: "32", claim: "A12 = W sin(φ_i−φ_j) cosθ_i sinθ_j" },
    Check { equation: "33", claim: "A21 = −W sin(φ_i−φ_j) sinθ_i cosθ_j" },
    Check { equation: "34", claim: "A22 = W cos(φ_i−φ_j) sinθ_i sinθ_j" },
    Check { equation: "35", claim: "B11 = W(cos(φ_i−φ_j)cosθ_i sinθ_j − sinθ_i cosθ_j)" },
    Check { equation: "36", claim: "B12 = W cos(φ_i−φ_j) cosθ_i sinθ_j" },
    Check { equation: "37", claim: "B21 = B22 = −W sin(φ_i−φ_j) sinθ_i sinθ_j" },
    Check { equation: "38", claim: "C1 = W sin(φ_i−φ_j) cosθ_i cosθ_j" },
    Check { equation: "39", claim: "C2 = W cos(φ_i−φ_j) sinθ_i cosθ_j" },
    Check { equation: "40", claim: "g_i = l_i g M_i sin θ_i (and 0 for the φ rows)" },
    Check { equation: "41", claim: "the vector multiplying C is (θ_j φ̇_j), printed with θ not θ̇" },
    Check { equation: "42", claim: "N = 1 spatial equation in block form written out" },
    Check {
        equation: "43", claim: "N = 1: θ̈ = φ̇² cosθ sinθ − (g/l) sinθ, φ̈ = θ̇φ̇ cot θ"
    },
    Check { equation: "47", claim: "spatial v_i² (checked as T = ½Σ m_i v_i²)" },
    Check { equation: "48", claim: "spatial kinetic energy T" },
    Check { equation: "49", claim: "dimensionless double pendulum (l = l2/l1, m = m2/(m1+m2), g → g/l1)" },
    Check { equation: "49 g", claim: "the text's scaling g → g/l1/(m1+m2) in eq 49" },
    Check { equation: "50", claim: "dimensionless double pendulum accelerations θ̈_1, θ̈_2" },
];

fn check_index(equation: &str) -> usize {
    CHECKS.iter().position(|c| c.equation == equation).unwrap_or_else(|| panic!("unknown check {equation}"))
}

#[derive(Clone, Debug, Default)]
struct Tally {
    worst: f64,
    count: usize,
    first: Option<String>,
}

/// Where a comparison happens, for the report.
#[derive(Clone, Copy)]
struct Site<'a> {
    case: &'a str,
    state: usize,
}

impl Tally {
    fn record(&mut self, site: Site, entry: impl FnOnce() -> String, printed: Scaled, reference: Scaled) {
        let rel = relative_error(printed, reference);
        self.count += 1;
        if rel > self.worst || (rel.is_nan() && !self.worst.is_nan()) {
            self.worst = rel;
        }
        if (rel >= AGREEMENT || rel.is_nan()) && self.first.is_none() {
            self.first = Some(format!(
                "{} state {}: {}: printed {:.6e}, reference {:.6e}",
                site.case,
                site.state,
                entry(),
                printed.v,
                reference.v
            ));
        }
    }

    fn verdict(&self) -> Verdict {
        if self.count == 0 {
            Verdict::Untested
        } else if self.worst < AGREEMENT {
            Verdict::Agrees
        } else {
            Verdict::Disagrees
        }
    }
}

/// One tally for the printed form and one for the corrected form of every check.
struct Recorder {
    printed: Vec<Tally>,
    corrected: Vec<Tally>,
}

impl Recorder {
    fn new() -> Recorder {
        Recorder {
            printed: vec![Tally::default(); CHECKS.len()],
            corrected: vec![Tally::default(); CHECKS.len()],
        }
    }

    fn p(&mut self, equation: &str) -> &mut Tally {
        &mut self.printed[check_index(equation)]
    }

    fn c(&mut self, equation: &str) -> &mut Tally {
        &mut self.corrected[check_index(equation)]
    }

    fn findings(self) -> Vec<Finding> {
        CHECKS
            .iter()
            .zip(self.printed)
            .zip(self.corrected)
            .map(|((check, printed), corrected)| Finding {
                equation: check.equation,
                claim: check.claim,
                verdict: printed.verdict(),
                worst: printed.worst,
                first_disagreement: printed.first,
                corrected: (corrected.count > 0).then(|| (corrected.verdict(), corrected.worst)),
            })
            .collect()
    }
}

// ---------------------------------------------------------------------------------
// Reference access
// ---------------------------------------------------------------------------------

/// One random state of one case, evaluated by the reference.
struct State<'a> {
    case: &'a Case,
    index: usize,
    params: Params,
    point: Point,
    ev: Evaluated,
    sc: Evaluated,
}

impl State<'_> {
    fn site(&self) -> Site<'_> {
        Site { case: &self.case.name, state: self.index }
    }

    fn mass(&self, i: usize, j: usize) -> Scaled {
        Scaled::with_scale(self.ev.mass_matrix[(i, j)], self.sc.mass_matrix[(i, j)])
    }

    fn velocity(&self, i: usize) -> Scaled {
        Scaled::with_scale(self.ev.velocity_terms[i], self.sc.velocity_terms[i])
    }

    fn gravity(&self, i: usize) -> Scaled {
        Scaled::with_scale(self.ev.gravity_terms[i], self.sc.gravity_terms[i])
    }

    fn force(&self, i: usize) -> Scaled {
        Scaled::with_scale(self.ev.generalized_forces[i], self.sc.generalized_forces[i])
    }

    fn kinetic(&self) -> Scaled {
        Scaled::with_scale(self.ev.kinetic_energy, self.sc.kinetic_energy)
    }

    fn potential(&self) -> Scaled {
        Scaled::with_scale(self.ev.potential_energy, self.sc.potential_energy)
    }

    /// The reference's velocity terms `c` at this configuration with rates `qd`.
    fn velocity_terms_at(&self, qd: Vec<f64>) -> Vec<Scaled> {
        let point = Point {
            q: self.point.q.clone(),
            qd,
            torque: vec![0.0; self.point.torque.len()],
            pivot_acceleration: vec![0.0; self.point.pivot_acceleration.len()],
        };
        let (ev, sc) = self.case.evaluate_with_scales(&self.params, &point);
        (0..ev.velocity_terms.len())
            .map(|i| Scaled::with_scale(ev.velocity_terms[i], sc.velocity_terms[i]))
            .collect()
    }

    /// `c` with rate `j` (and optionally also rate `k`) set to one, all others zero.
    fn velocity_terms_unit(&self, j: usize, k: Option<usize>) -> Vec<Scaled> {
        let mut qd = vec![0.0; self.point.qd.len()];
        qd[j] = 1.0;
        if let Some(k) = k {
            qd[k] = 1.0;
        }
        self.velocity_terms_at(qd)
    }

    /// `(M q̈ + c + k)_d` at accelerations `qdd`.
    fn lagrange_lhs(&self, qdd: &[Scaled], d: usize) -> Scaled {
        (0..qdd.len()).map(|j| self.mass(d, j) * qdd[j]).sum::<Scaled>() + self.velocity(d) + self.gravity(d)
    }

    /// The free, undriven, undamped accelerations `M⁻¹(−c − k)`, each with the
    /// componentwise round-off bound `|M⁻¹|(s_M |q̈| + s_c + s_k)` as its scale.
    fn free_accelerations(&self) -> Option<Vec<Scaled>> {
        let mass = &self.ev.mass_matrix;
        let rhs: DVector<f64> = -(&self.ev.velocity_terms + &self.ev.gravity_terms);
        let inverse: DMatrix<f64> = mass.clone().try_inverse()?;
        let acc = &inverse * &rhs;
        let rhs_scale = self.sc.velocity_terms.abs() + self.sc.gravity_terms.abs();
        let mass_scale = self.sc.mass_matrix.abs().zip_map(&mass.abs(), f64::max);
        let scale = inverse.abs() * (mass_scale * acc.abs() + rhs_scale);
        Some((0..acc.len()).map(|i| Scaled::with_scale(acc[i], scale[i])).collect())
    }
}

// ---------------------------------------------------------------------------------
// The findings
// ---------------------------------------------------------------------------------

/// Check every printed equation against the reference `cases` at `states` random
/// states per case (the states of [`crate::sample::state`] for `seed`). Pure: reads nothing but `cases`.
pub fn findings(cases: &[Case], states: usize, seed: u64) -> Vec<Finding> {
    let mut rec = Recorder::new();
    for case in cases {
        let n = case.links;
        for index in 0..states {
            // State `index` is the one `verify` draws ([`crate::sample::state`]); the
            // accelerations for eqs 15–17 are drawn after it from the same generator.
            let (params, point, mut rng) = crate::sample::state_with_rng(seed, case.kind, n, index);
            let qdd: Vec<Scaled> =
                (0..case.dof()).map(|_| Scaled::exact(rng.random_range(-2.0..2.0))).collect();
            let (ev, sc) = case.evaluate_with_scales(&params, &point);
            let st = State { case, index, params, point, ev, sc };
            match case.kind {
                Kind::Planar => planar(&mut rec, &st, &qdd),
                Kind::Spatial => spatial(&mut rec, &st),
            }
        }
    }
    rec.findings()
}

/// `i, j` (0-based) as the document's 1-based `[i,j]`.
fn ij(name: &str, i: usize, j: usize) -> String {
    format!("{name}[{},{}]", i + 1, j + 1)
}

fn tail_masses(masses: &[f64]) -> Vec<Scaled> {
    (0..masses.len()).map(|i| masses[i..].iter().map(|&m| Scaled::exact(m)).sum()).collect()
}

// ---------------------------------------------------------------------------------
// Planar (section 1.1, eqs 11–26, and 49–50)
// ---------------------------------------------------------------------------------

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

fn planar(rec: &mut Recorder, st: &State, qdd: &[Scaled]) {
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

// ---------------------------------------------------------------------------------
// Spatial (section 1.2, eqs 30–48)
// ---------------------------------------------------------------------------------

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

fn spatial(rec: &mut Recorder, st: &State) {
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

// ---------------------------------------------------------------------------------
// Report and ERRATA
// ---------------------------------------------------------------------------------

/// The findings as a table.
pub fn render(findings: &[Finding]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "| equation | what it claims | verdict | worst rel. error | corrected form | first disagreeing entry and state |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|");
    for f in findings {
        let corrected = match f.corrected {
            Some((verdict, worst)) => format!("{} ({worst:.1e})", verdict.as_str()),
            None => "–".into(),
        };
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.1e} | {} | {} |",
            f.equation,
            f.claim,
            f.verdict.as_str(),
            f.worst,
            corrected,
            f.first_disagreement.as_deref().unwrap_or("–")
        );
    }
    out
}

/// The rows of the summary table of ERRATA.md: the first table whose header is
/// `| equation | verdict |`.
pub fn parse_summary(text: &str) -> anyhow::Result<Vec<(String, String)>> {
    let cells = |line: &str| -> Option<Vec<String>> {
        let line = line.trim();
        let inner = line.strip_prefix('|')?.strip_suffix('|')?;
        Some(inner.split('|').map(|c| c.trim().to_string()).collect())
    };
    let mut lines = text.lines();
    loop {
        let Some(line) = lines.next() else { bail!("no summary table with header `| equation | verdict |`") };
        if cells(line).is_some_and(|c| c == ["equation", "verdict"]) {
            break;
        }
    }
    match lines.next().and_then(cells) {
        Some(sep)
            if sep.len() == 2
                && sep.iter().all(|c| !c.is_empty() && c.chars().all(|ch| "-: ".contains(ch))) => {}
        _ => bail!("the summary table header is not followed by a `|---|---|` separator"),
    }
    let mut rows = Vec::new();
    for line in lines {
        let Some(row) = cells(line) else { break };
        let [equation, verdict] = <[String; 2]>::try_from(row)
            .map_err(|row| anyhow::anyhow!("summary row {line:?} has {} cells, expected 2", row.len()))?;
        rows.push((equation, verdict));
    }
    Ok(rows)
}

/// How the measured findings differ from the summary rows (empty: they match), and
/// corrected forms that do not agree. An untested equation (none of its cases given,
/// e.g. under `verify --case`) is no difference, but must still have its row.
pub fn differences(findings: &[Finding], summary: &[(String, String)]) -> Vec<String> {
    let mut out = Vec::new();
    for (k, (equation, _)) in summary.iter().enumerate() {
        if summary[..k].iter().any(|(e, _)| e == equation) {
            out.push(format!("eq {equation}: listed more than once in the ERRATA summary"));
        }
        if !findings.iter().any(|f| f.equation == equation) {
            out.push(format!("eq {equation}: in the ERRATA summary but not a checked equation"));
        }
    }
    for f in findings {
        match summary.iter().find(|(e, _)| e == f.equation) {
            None => out.push(format!(
                "eq {}: measured {} but missing from the ERRATA summary",
                f.equation,
                f.verdict.as_str()
            )),
            Some((_, recorded)) if f.verdict != Verdict::Untested && recorded != f.verdict.as_str() => out
                .push(format!(
                    "eq {}: ERRATA says {recorded}, measured {} (worst relative error {:.1e}{})",
                    f.equation,
                    f.verdict.as_str(),
                    f.worst,
                    f.first_disagreement.as_deref().map(|d| format!("; first: {d}")).unwrap_or_default()
                )),
            Some(_) => {}
        }
        if let Some((verdict, worst)) = f.corrected
            && verdict != Verdict::Agrees
        {
            out.push(format!(
                "eq {}: the corrected form in ERRATA {} (worst relative error {worst:.1e})",
                f.equation,
                verdict.as_str()
            ));
        }
    }
    out
}

/// Check the document's printed equations at `states` random states per case, print
/// the findings, and fail iff they no longer match `reference/ERRATA.md`.
/// Disagreements with the reference are findings, not failures.
pub fn run(cases: &[Case], states: usize, seed: u64) -> anyhow::Result<()> {
    let findings = findings(cases, states, seed);
    println!("The document as printed ({states} random states per case, seed {seed}):");
    print!("{}", render(&findings));
    let path = errata_path();
    let text = std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let summary = parse_summary(&text).with_context(|| format!("parsing {}", path.display()))?;
    let differences = differences(&findings, &summary);
    if !differences.is_empty() {
        bail!("the document check no longer matches {}:\n  {}", path.display(), differences.join("\n  "));
    }
    let untested: Vec<&str> =
        findings.iter().filter(|f| f.verdict == Verdict::Untested).map(|f| f.equation).collect();
    if !untested.is_empty() {
        println!("Untested (none of their cases given): eqs {}.", untested.join(", "));
    }
    println!("The findings match {}.", path.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_error_is_scaled_and_zero_safe() {
        assert_eq!(relative_error(Scaled::zero(), Scaled::zero()), 0.0);
        assert_eq!(relative_error(Scaled::exact(1.0), Scaled::zero()), 1.0);
        let a = Scaled::exact(0.3).sin() * Scaled::exact(2.0);
        assert!(relative_error(a, Scaled::with_scale(2.0 * 0.3f64.sin(), 2.0)) < 1e-15);
        assert!(relative_error(-a, Scaled::with_scale(2.0 * 0.3f64.sin(), 2.0)) > 0.1);
    }

    #[test]
    fn summary_parsing_and_differences() {
        let text = "# x\n\n| equation | verdict |\n|---|---|\n| 22 | agrees |\n| 23 | agrees |\n| 99 | agrees |\n\nmore\n";
        let rows = parse_summary(text).unwrap();
        assert_eq!(rows.len(), 3);
        let finding = |equation, verdict| Finding {
            equation,
            claim: "",
            verdict,
            worst: 0.0,
            first_disagreement: None,
            corrected: None,
        };
        let found = [
            finding("22", Verdict::Agrees),
            finding("23", Verdict::Disagrees),
            finding("24 C", Verdict::Agrees),
        ];
        let diffs = differences(&found, &rows);
        assert_eq!(diffs.len(), 3, "{diffs:#?}");
        assert!(diffs.iter().any(|d| d.starts_with("eq 23: ERRATA says agrees")));
        assert!(diffs.iter().any(|d| d.starts_with("eq 99:")));
        assert!(diffs.iter().any(|d| d.starts_with("eq 24 C:")));
        assert!(parse_summary("| equation | verdict |\n| 22 | agrees |\n").is_err());
        assert!(parse_summary("nothing here").is_err());
    }

    /// The committed reference and ERRATA.md agree with a short run.
    #[test]
    fn findings_match_errata() {
        let cases = crate::case::load_all(&crate::cases_dir()).expect("the committed reference cases load");
        let findings = findings(&cases, 6, 20181223);
        let untested: Vec<_> =
            findings.iter().filter(|f| f.verdict == Verdict::Untested).map(|f| f.equation).collect();
        assert!(untested.is_empty(), "the committed cases leave eqs {untested:?} untested");
        let text = std::fs::read_to_string(errata_path()).expect("reference/ERRATA.md exists");
        let summary = parse_summary(&text).expect("the ERRATA summary parses");
        let differences = differences(&findings, &summary);
        assert!(differences.is_empty(), "{}\n{}", render(&findings), differences.join("\n"));
    }
}
