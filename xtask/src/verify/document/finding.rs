//! What checking one printed equation of the seed document found: a row of verify's
//! document table and of the ERRATA comparison.

pub use crate::claims::Verdict;

/// What was measured for one printed equation.
#[derive(Clone, Debug)]
pub struct Finding {
    /// The equation number as printed (with a suffix where one printed equation holds
    /// several separately checked claims), as in the ERRATA summary table.
    pub equation: String,
    /// What it claims, in words (the claim's title after `Eq N: `).
    pub claim: String,
    pub verdict: Verdict,
    /// The worst relative error over all entries, cases and states.
    pub worst: f64,
    /// The first disagreeing entry: case, state, entry, claimed and reference values.
    pub first_disagreement: Option<String>,
    /// For a disagreeing equation: the verdict and worst error of its corrected form
    /// (the one ERRATA.md gives), evaluated the same way.
    pub corrected: Option<(Verdict, f64)>,
    /// The slips the claims check found, or why there are none ("–" for an agreement).
    pub diagnosis: String,
}
