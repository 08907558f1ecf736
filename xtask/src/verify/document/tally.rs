//! The relative error of a printed value against the reference, and the tallies that
//! turn those errors into one verdict per equation, for its printed and corrected form.

use super::claims::{CHECKS, Finding, Verdict, check_index};
use crate::expr::Scaled;

/// An equation agrees with the reference if its worst relative error is below this.
pub const AGREEMENT: f64 = 1e-10;

/// `|p − r| / (scale_p + scale_r)`; 0 if they are equal, ∞ if they differ at zero scale.
pub fn relative_error(printed: Scaled, reference: Scaled) -> f64 {
    let diff = (printed.v - reference.v).abs();
    if diff == 0.0 {
        return 0.0;
    }
    diff / (printed.s + reference.s)
}

#[derive(Clone, Debug, Default)]
pub(super) struct Tally {
    worst: f64,
    count: usize,
    first: Option<String>,
}

/// Where a comparison happens, for the report.
#[derive(Clone, Copy)]
pub(crate) struct Site<'a> {
    pub(crate) case: &'a str,
    pub(crate) state: usize,
}

impl Tally {
    pub(super) fn record(
        &mut self,
        site: Site,
        entry: impl FnOnce() -> String,
        printed: Scaled,
        reference: Scaled,
    ) {
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
pub(super) struct Recorder {
    printed: Vec<Tally>,
    corrected: Vec<Tally>,
}

impl Recorder {
    pub(super) fn new() -> Recorder {
        Recorder {
            printed: vec![Tally::default(); CHECKS.len()],
            corrected: vec![Tally::default(); CHECKS.len()],
        }
    }

    pub(super) fn p(&mut self, equation: &str) -> &mut Tally {
        &mut self.printed[check_index(equation)]
    }

    pub(super) fn c(&mut self, equation: &str) -> &mut Tally {
        &mut self.corrected[check_index(equation)]
    }

    pub(super) fn findings(self) -> Vec<Finding> {
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

/// `i, j` (0-based) as the document's 1-based `[i,j]`.
pub(super) fn ij(name: &str, i: usize, j: usize) -> String {
    format!("{name}[{},{}]", i + 1, j + 1)
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
}
