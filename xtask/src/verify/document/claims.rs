//! The printed equations checked, in document order: each one's number and what it
//! claims, and what checking it found.

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

pub(super) struct Check {
    pub(super) equation: &'static str,
    pub(super) claim: &'static str,
}

/// Every checked equation, in document order.
pub(super) const CHECKS: &[Check] = &[
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

pub(super) fn check_index(equation: &str) -> usize {
    CHECKS.iter().position(|c| c.equation == equation).unwrap_or_else(|| panic!("unknown check {equation}"))
}
