//! A run's values in the user's words, written once for every front end: the chain a
//! command analyses, a growth rate near round-off.

/// The range of `values` with its unit: `0.01 m` when all are equal, else `0.5–1 m`.
fn range(values: &[f64], unit: &str) -> String {
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if lo == hi { format!("{lo} {unit}") } else { format!("{lo}–{hi} {unit}") }
}

/// The chain in one line, for every command's header: `3 links of 1 m, 1 kg (L = 3 m,
/// M = 3 kg), g = 9.81 m/s², damping 3e-4 N·m·s` (ranges where the links differ; no
/// damping said when there is none).
pub fn chain_words(masses: &[f64], lengths: &[f64], gravity: f64, damping: &[f64]) -> String {
    let n = masses.len();
    let (length, mass) = (lengths.iter().sum::<f64>(), masses.iter().sum::<f64>());
    let links = if n == 1 { "1 link".to_string() } else { format!("{n} links") };
    let each = if lengths.iter().all(|&l| l == lengths[0]) && masses.iter().all(|&m| m == masses[0]) {
        format!("{links} of {}, {}", range(lengths, "m"), range(masses, "kg"))
    } else {
        format!("{links}, lengths {}, masses {}", range(lengths, "m"), range(masses, "kg"))
    };
    let damped = if damping.iter().any(|&d| d != 0.0) {
        format!(", damping {}", range(damping, "N·m·s"))
    } else {
        String::new()
    };
    format!("{each} (L = {} m, M = {} kg), g = {gravity} m/s²{damped}", round(length), round(mass))
}

/// `x` without the round-off of a sum, to be written for a reader (12 significant
/// digits: a chain of 100 links of 0.01 m is 1 m long, not 1.0000000000000007 m).
pub fn round(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let scale = 10f64.powi(11 - x.abs().log10().floor() as i32);
    (x * scale).round() / scale
}

/// `x` to six significant digits, in the shortest form (`1`, `0.02`, `0.00056237`): for
/// titles and tables, where `1.0000000000000002 m` would be noise.
pub fn short(x: f64) -> String {
    format!("{x:.5e}").parse::<f64>().map_or_else(|_| x.to_string(), |v| v.to_string())
}

/// A growth rate `rate` (1/s) in words: `0 within round-off, |rate| ≤ 6.0e-6 1/s` when
/// its magnitude is at most `bound` (the spectrum's round-off, 1/s), else `-5.57e-2 1/s`.
pub fn growth_words(rate: f64, bound: f64) -> String {
    // NaN falls through to the number: said, never hidden.
    if rate.abs() <= bound {
        format!("0 within round-off, |rate| ≤ {bound:.1e} 1/s")
    } else {
        format!("{rate:.2e} 1/s")
    }
}

#[cfg(test)]
mod tests {
    use super::{chain_words, growth_words};

    #[test]
    fn a_chain_is_said_in_one_line() {
        assert_eq!(
            chain_words(&[0.01; 100], &[0.01; 100], 9.81, &[3e-4; 100]),
            "100 links of 0.01 m, 0.01 kg (L = 1 m, M = 1 kg), g = 9.81 m/s², damping 0.0003 N·m·s"
        );
        assert_eq!(
            chain_words(&[1.0, 2.0, 3.0], &[0.5; 3], 9.81, &[0.0; 3]),
            "3 links, lengths 0.5 m, masses 1–3 kg (L = 1.5 m, M = 6 kg), g = 9.81 m/s²"
        );
        assert_eq!(
            chain_words(&[1.0], &[0.2], 0.0, &[0.0]),
            "1 link of 0.2 m, 1 kg (L = 0.2 m, M = 1 kg), g = 0 m/s²"
        );
    }

    #[test]
    fn rates_within_round_off_are_zero_and_say_the_bound() {
        // Issue 34: +9.97e-16 1/s was printed as a rate.
        assert_eq!(growth_words(9.97e-16, 6e-6), "0 within round-off, |rate| ≤ 6.0e-6 1/s");
        assert_eq!(growth_words(-6e-6, 6e-6), "0 within round-off, |rate| ≤ 6.0e-6 1/s");
        assert_eq!(growth_words(-5.57e-2, 6e-6), "-5.57e-2 1/s");
        assert_eq!(growth_words(3.1e-3, 6e-6), "3.10e-3 1/s");
        assert_eq!(growth_words(f64::NAN, 6e-6), "NaN 1/s");
    }
}
