//! `docs/bench.md` from one run's [`Results`]: the done-when targets, tables of medians
//! and of ratios to the generic route and to the baseline, the machine and the date.

use std::fmt::Write;

use super::results::Results;

/// The model kinds, as in the group names `<kind>_<operation>`.
pub const KINDS: [&str; 2] = ["planar", "spatial"];

/// The timed operations (group suffix, what is timed).
pub const OPERATIONS: [(&str, &str); 5] = [
    ("accelerations", "`Model::accelerations`: input checks, `M(q)`, `Q − c − k − d`, Cholesky solve"),
    ("mass_matrix", "`Model::mass_matrix`: `M(q)` into a preallocated matrix"),
    ("forces", "`Q − c − k − d` from `generalized_forces`, `velocity_terms`, `gravity_terms`, `pivot_terms`"),
    ("gl2_step", "one Gauss–Legendre step (s = 2, h = 1 ms) of `FirstOrder<model>` from a fixed state"),
    ("energy", "`Model::energy`: `T + U`"),
];

/// The implementations in table order (benchmark function name, label).
pub const IMPLEMENTATIONS: [(&str, &str); 10] = [
    ("generated", "generated"),
    ("generated_dense", "generated, `algorithm: dense`"),
    ("generated_tension", "generated, `algorithm: tension`"),
    ("generic_fixed", "generic `Const<n>`"),
    ("generic_dyn", "generic `Dyn`"),
    ("closed_form", "closed form (eq 50)"),
    ("tension", "O(n) `PlanarTension<Dyn>`"),
    ("directions", "O(n) `Directions` rhs"),
    ("directions_angles", "O(n) `Directions` → (θ, φ) q̈"),
    ("baseline", "baseline"),
];

/// The smallest n from which `model!` generates `algorithm: tension` by default, per kind
/// (`pendulum_macros`' `Algorithm::crossover`; `default_algorithms_match_the_macro` checks
/// the generated types agree).
pub const GENERATED_CROSSOVER: [(&str, usize); 2] = [("planar", 4), ("spatial", 2)];

/// The algorithm `model!` generates by default for `n` links of `kind`: `"dense"` or
/// `"tension"`.
pub fn default_algorithm(kind: &str, n: usize) -> &'static str {
    let from = GENERATED_CROSSOVER.iter().find(|(k, _)| *k == kind).map_or(usize::MAX, |&(_, n)| n);
    if n >= from { "tension" } else { "dense" }
}

/// The routes computing the same `q̈` in the same angles as the generated models, per kind
/// (`Directions` rhs is another quantity, the first-order right-hand side in direction
/// coordinates, and is listed beside them).
pub const SAME_QUANTITY: [(&str, &[&str]); 2] = [
    ("planar", &["generic_fixed", "generic_dyn", "closed_form", "tension"]),
    ("spatial", &["generic_fixed", "generic_dyn", "directions_angles"]),
];

/// The O(n) route in the same coordinates that the generated models must beat by
/// [`ALGORITHM_TARGET`], and from which n on.
pub const LINEAR_SAME_QUANTITY: [(&str, &str, usize); 2] =
    [("planar", "tension", 8), ("spatial", "directions_angles", 1)];

/// Required speed-up of the generated models (default algorithm) over the O(n) route in
/// the same coordinates ([`LINEAR_SAME_QUANTITY`]).
pub const ALGORITHM_TARGET: f64 = 1.3;

/// The generic dense route every speed-up is measured against.
pub const GENERIC: &str = "generic_dyn";
/// The physical-limit baseline.
pub const BASELINE: &str = "baseline";
/// The O(n) routes whose crossovers the report gives: (kind, implementation).
pub const LINEAR: [(&str, &str); 3] =
    [("planar", "tension"), ("planar", "directions"), ("spatial", "directions")];

/// The line that separates the generated report from the hand-written notes, which
/// `cargo xtask bench` keeps when it rewrites `docs/bench.md`.
pub const NOTES_MARKER: &str = "<!-- hand-written notes below this line: kept by `cargo xtask bench` -->";

/// Required speed-up of generated over generic `Dyn` accelerations for n ≤ 4.
pub const SPEEDUP_TARGET: f64 = 3.0;
/// Largest allowed time of generated `Planar2` relative to the closed form.
pub const CLOSED_FORM_TARGET: f64 = 1.2;

/// How and where a run was made.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct RunInfo {
    /// The command that ran it.
    pub command: String,
    /// Date and time (UTC) at the start.
    pub date: String,
    /// CPU model and core count.
    pub machine: String,
    /// Criterion settings (warm-up, measurement, samples).
    pub settings: String,
    /// `/proc/loadavg` before and after.
    pub load: (String, String),
    /// Wall time of the benchmark run (built beforehand), s.
    pub seconds: f64,
    /// The commit benchmarked, short, `+changes` when the tree differed from it (empty in
    /// the runs recorded before it was).
    #[serde(default)]
    pub commit: String,
}

/// The label of a benchmark function name.
pub fn label(implementation: &str) -> &str {
    IMPLEMENTATIONS.iter().find(|(name, _)| *name == implementation).map_or(implementation, |(_, l)| l)
}

/// The implementations of `group` in table order (unknown names last).
fn ordered<'a>(results: &'a Results, group: &str) -> Vec<&'a str> {
    let present = results.implementations(group);
    let rank = |i: &str| IMPLEMENTATIONS.iter().position(|(name, _)| *name == i).unwrap_or(usize::MAX);
    let mut v: Vec<&str> = present.into_iter().collect();
    v.sort_by_key(|i| (rank(i), i.to_string()));
    v
}

/// A time in ns with a sensible unit and three significant figures.
pub fn time(ns: f64) -> String {
    let (value, unit) = match ns {
        t if t < 1e3 => (t, "ns"),
        t if t < 1e6 => (t / 1e3, "µs"),
        t if t < 1e9 => (t / 1e6, "ms"),
        t => (t / 1e9, "s"),
    };
    let digits = if value < 10.0 {
        2
    } else if value < 100.0 {
        1
    } else {
        0
    };
    format!("{value:.digits$} {unit}")
}

/// A ratio with two decimals below 10, one above.
pub(crate) fn ratio(r: f64) -> String {
    if r < 10.0 { format!("{r:.2}") } else { format!("{r:.1}") }
}

/// The done-when checks of issue 4, measured in one run.
#[derive(Debug, Clone, PartialEq)]
pub struct Targets {
    /// `(kind, n, generic Dyn ÷ generated)` of accelerations for n ≤ 4.
    pub speedups: Vec<(&'static str, usize, Option<f64>)>,
    /// Generated `Planar2` ÷ closed form, accelerations.
    pub closed_form: Option<f64>,
    /// `(check_inputs time at n = 2, (generated − check_inputs) ÷ closed form)`.
    pub closed_form_unchecked: Option<(f64, f64)>,
    /// Where each O(n) route of `LINEAR` overtakes the generated models.
    pub crossovers: Vec<Crossover>,
    /// The generated models' two algorithms at every measured n (issue 20).
    pub algorithms: Vec<AlgorithmRow>,
}

/// One size of one kind: the generated models' two algorithms and what they compete with.
#[derive(Debug, Clone, PartialEq)]
pub struct AlgorithmRow {
    /// Model kind.
    pub kind: &'static str,
    /// Links.
    pub n: usize,
    /// `algorithm: dense` time, ns.
    pub dense: Option<f64>,
    /// `algorithm: tension` time, ns.
    pub tension: Option<f64>,
    /// The fastest other route computing the same q̈ ([`SAME_QUANTITY`]): name and time.
    pub best_other: Option<(&'static str, f64)>,
    /// The O(n) route in the same coordinates ([`LINEAR_SAME_QUANTITY`]), ns.
    pub linear: Option<f64>,
    /// `Directions` rhs (another quantity), ns.
    pub directions: Option<f64>,
}

impl AlgorithmRow {
    /// The default algorithm's time.
    pub fn generated(&self) -> Option<f64> {
        if default_algorithm(self.kind, self.n) == "tension" { self.tension } else { self.dense }
    }
}

/// Where an O(n) route overtakes another route (accelerations).
#[derive(Debug, Clone, PartialEq)]
pub struct Crossover {
    /// Model kind (`planar`, `spatial`).
    pub kind: &'static str,
    /// The O(n) route's benchmark name.
    pub route: &'static str,
    /// `(n, O(n) time ÷ other time)` at every n where both ran.
    pub ratios: Vec<(usize, f64)>,
    /// The smallest measured n from which the O(n) route is faster at every measured n.
    pub from: Option<usize>,
}

impl Crossover {
    /// The crossover of `route` against `other` in `<kind>_accelerations`.
    pub fn of(results: &Results, kind: &'static str, route: &'static str, other: &str) -> Self {
        let group = format!("{kind}_accelerations");
        let ratios: Vec<(usize, f64)> = results
            .series(&group, route)
            .into_iter()
            .filter_map(|(n, t)| Some((n, t / results.get(&group, other, n)?)))
            .collect();
        let from = ratios.iter().rposition(|&(_, r)| r >= 1.0).map_or(0, |i| i + 1);
        Self { kind, route, from: ratios.get(from).map(|&(n, _)| n), ratios }
    }
}

impl Targets {
    /// The checks, from `results`.
    pub fn of(results: &Results) -> Self {
        let speedups = KINDS
            .into_iter()
            .flat_map(|kind| {
                let group = format!("{kind}_accelerations");
                (1..=4).map(move |n| {
                    let s = results.get(&group, GENERIC, n).zip(results.get(&group, "generated", n));
                    (kind, n, s.map(|(g, x)| g / x))
                })
            })
            .collect();
        let group = "planar_accelerations";
        let closed_form =
            results.get(group, "generated", 2).zip(results.get(group, "closed_form", 2)).map(|(g, c)| g / c);
        let closed_form_unchecked =
            results.get("planar_input_checks", "check_inputs", 2).and_then(|checks| {
                let (generated, closed) =
                    (results.get(group, "generated", 2)?, results.get(group, "closed_form", 2)?);
                Some((checks, (generated - checks) / closed))
            });
        let crossovers = LINEAR
            .into_iter()
            .map(|(kind, route)| Crossover::of(results, kind, route, "generated"))
            .collect();
        let algorithms = KINDS
            .into_iter()
            .flat_map(|kind| {
                let group = format!("{kind}_accelerations");
                let mut sizes: Vec<usize> =
                    results.series(&group, "generated_dense").into_iter().map(|(n, _)| n).collect();
                sizes.dedup();
                let others = SAME_QUANTITY.iter().find(|(k, _)| *k == kind).map_or(&[][..], |(_, o)| o);
                let linear = LINEAR_SAME_QUANTITY.iter().find(|(k, _, _)| *k == kind).map(|&(_, r, _)| r);
                sizes
                    .into_iter()
                    .map(|n| {
                        let get = |name: &str| results.get(&group, name, n);
                        let best_other = others
                            .iter()
                            .filter_map(|&o| Some((o, get(o)?)))
                            .min_by(|a, b| a.1.total_cmp(&b.1));
                        AlgorithmRow {
                            kind,
                            n,
                            dense: get("generated_dense"),
                            tension: get("generated_tension"),
                            best_other,
                            linear: linear.and_then(get),
                            directions: get("directions"),
                        }
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        Self { speedups, closed_form, closed_form_unchecked, crossovers, algorithms }
    }
}

/// The generated models' algorithms as markdown (issue 20): per kind and n, both
/// algorithms, the default, and the checks against the other routes.
fn algorithms_markdown(median: &Targets, fastest: &Targets) -> String {
    let mut out = String::new();
    if median.algorithms.is_empty() {
        return out;
    }
    let _ = writeln!(
        out,
        "**Generated models: the algorithm at each n** (`model!`'s `algorithm: dense | tension`; the default is `tension` from n = {} planar and n = {} spatial). Times are medians / fastest samples; \"best other\" is the fastest other route computing the same q̈ in the same angles ({}); the O(n) route in the same coordinates must be ≥ {ALGORITHM_TARGET}× slower than the default (planar `PlanarTension<Dyn>` from n = 8; spatial `Directions::spherical_accelerations`, which converts angles to directions and back and allocates its result). `Directions` rhs, another quantity (the first-order right-hand side in direction coordinates, no trigonometry), is listed for scale.\n",
        GENERATED_CROSSOVER[0].1,
        GENERATED_CROSSOVER[1].1,
        SAME_QUANTITY.iter().map(|(k, o)| format!("{k}: {}", o.join(", "))).collect::<Vec<_>>().join("; ")
    );
    let _ = writeln!(
        out,
        "| model | n | dense | tension | faster | default | best other | default ≤ best other | O(n) same coords ÷ default | `Directions` rhs |\n|---|---|---|---|---|---|---|---|---|---|"
    );
    let show = |t: Option<f64>| t.map_or("–".to_string(), time);
    for (m, f) in median.algorithms.iter().zip(&fastest.algorithms) {
        let faster = match (m.dense, m.tension) {
            (Some(d), Some(t)) => {
                if t < d {
                    "tension"
                } else {
                    "dense"
                }
            }
            _ => "–",
        };
        let default = default_algorithm(m.kind, m.n);
        let other = |r: &AlgorithmRow| r.best_other.map(|(_, t)| t);
        let beats = |r: &AlgorithmRow| match (r.generated(), other(r)) {
            (Some(g), Some(o)) => {
                if g <= o {
                    "yes".to_string()
                } else {
                    format!("**no** ({:.2}×)", g / o)
                }
            }
            _ => "–".to_string(),
        };
        let needed = LINEAR_SAME_QUANTITY
            .iter()
            .find(|(k, _, _)| *k == m.kind)
            .is_some_and(|&(_, _, from)| m.n >= from);
        let linear = |r: &AlgorithmRow| match (r.linear, r.generated()) {
            (Some(l), Some(g)) => {
                let v = l / g;
                if needed && v < ALGORITHM_TARGET { format!("**{}**", ratio(v)) } else { ratio(v) }
            }
            _ => "–".to_string(),
        };
        let _ = writeln!(
            out,
            "| {} | {} | {} / {} | {} / {} | {faster} | {default} | {} {} / {} | {} / {} | {} / {} | {} / {} |",
            m.kind,
            m.n,
            show(m.dense),
            show(f.dense),
            show(m.tension),
            show(f.tension),
            m.best_other.map_or("–", |(name, _)| label(name)),
            show(other(m)),
            show(other(f)),
            beats(m),
            beats(f),
            linear(m),
            linear(f),
            show(m.directions),
            show(f.directions),
        );
    }
    let _ = writeln!(out);
    out
}

/// `"met"`, or by how much a ratio `r` misses: `at_least` targets need `r ≥ target`,
/// the others `r ≤ target`.
fn verdict(r: f64, target: f64, at_least: bool) -> String {
    match (at_least, r) {
        (true, r) if r >= target => "met".into(),
        (true, r) => format!("**missed**, {:.0}% short", 100.0 * (1.0 - r / target)),
        (false, r) if r <= target => "met".into(),
        (false, r) => format!("**missed**, {:.0}% over", 100.0 * (r / target - 1.0)),
    }
}

fn both(median: Option<f64>, fastest: Option<f64>) -> String {
    let show = |r: Option<f64>| r.map_or("–".to_string(), ratio);
    format!("{} / {}", show(median), show(fastest))
}

/// The checks as markdown, from the medians and from the fastest samples of one run.
pub fn targets_markdown(median: &Targets, fastest: &Targets) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Each figure is given twice, from the medians / from the fastest samples (the two \
         statistics of the same run; see the notes on load).\n"
    );
    let _ = writeln!(
        out,
        "**Generated accelerations ≥ {SPEEDUP_TARGET}× faster than generic `Dyn` for n ≤ 4** \
         (speed-up = generic `Dyn` time ÷ generated time):\n"
    );
    let _ = writeln!(out, "| model | n | speed-up | medians | fastest samples |\n|---|---|---|---|---|");
    for (&(kind, n, m), &(_, _, f)) in median.speedups.iter().zip(&fastest.speedups) {
        let v = |r: Option<f64>| r.map_or("not measured".to_string(), |r| verdict(r, SPEEDUP_TARGET, true));
        let _ = writeln!(out, "| {kind} | {n} | {} | {} | {} |", both(m, f), v(m), v(f));
    }
    let _ = writeln!(out);
    if let (Some(m), Some(f)) = (median.closed_form, fastest.closed_form) {
        let _ = writeln!(
            out,
            "**Generated `Planar2` within {CLOSED_FORM_TARGET}× of the closed form:** generated ÷ closed \
             form = {} (medians: {}; fastest samples: {}).\n",
            both(Some(m), Some(f)),
            verdict(m, CLOSED_FORM_TARGET, false),
            verdict(f, CLOSED_FORM_TARGET, false)
        );
    } else {
        let _ = writeln!(out, "**Closed form:** not measured in this run.\n");
    }
    if let (Some((cm, _)), Some((cf, _))) = (median.closed_form_unchecked, fastest.closed_form_unchecked) {
        let _ = writeln!(
            out,
            "The generated model runs the full input check (`check_inputs`: lengths and \
             finiteness of q, q̇, σ, p̈) only on the way to an error: every non-finite input \
             makes the result non-finite or a pivot fail, and those paths name the bad entry. \
             Checking up front would cost {} / {} at n = 2, which the closed form does not pay.\n",
            time(cm),
            time(cf),
        );
    }
    for (m, f) in median.crossovers.iter().zip(&fastest.crossovers) {
        let what = format!("{} {}", m.kind, label(m.route));
        if m.ratios.is_empty() {
            let _ = writeln!(out, "**Crossover, {what}:** not measured in this run.\n");
            continue;
        }
        let from = |c: &Crossover| {
            c.from.map_or("never (slower at every measured n)".to_string(), |n| format!("n = {n}"))
        };
        let list: Vec<String> = m
            .ratios
            .iter()
            .zip(&f.ratios)
            .map(|(&(n, rm), &(_, rf))| format!("{n}: {}", both(Some(rm), Some(rf))))
            .collect();
        let _ = writeln!(
            out,
            "**Crossover, {what}:** faster than the generated models from **{}** (medians) / **{}** \
             (fastest samples) on. Its time ÷ generated time, by n: {}.\n",
            from(m),
            from(f),
            list.join(", ")
        );
    }
    out.push_str(&algorithms_markdown(median, fastest));
    out
}

/// The generated part of `docs/bench.md`, followed by `notes` (the hand-written part,
/// starting with [`NOTES_MARKER`]).
///
/// `results` holds the medians, `fastest` the fastest samples of the same run.
pub fn markdown(results: &Results, fastest: &Results, info: &RunInfo, notes: &str) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# Benchmarks: generated vs generic vs closed form vs O(n)\n");
    let _ = writeln!(
        out,
        "Generated by `{}` on {} in {:.0} s of benchmarking. Machine: {}. Load average \
         (1/5/15 min) before: {}, after: {}. Criterion {}. Times are per evaluation; the tables \
         give the median and the fastest sample of each benchmark. Every ratio below \
         comes from this one run; absolute times depend on the machine and its load.\n",
        info.command, info.date, info.seconds, info.machine, info.load.0, info.load.1, info.settings
    );
    let _ = writeln!(
        out,
        "To regenerate: `cargo xtask bench` (this file and `bench.svg`; the hand-written notes at \
         the end are kept), `cargo xtask bench --quick` (smoke run, report under the target \
         directory), `cargo xtask bench --report-only` (rewrite from the last run's estimates).\n"
    );
    let _ =
        writeln!(out, "What is timed (groups `<kind>_<operation>` in `pendulum-core/benches/models.rs`):\n");
    for (op, what) in OPERATIONS {
        let _ = writeln!(out, "- `{op}`: {what};");
    }
    let _ = writeln!(
        out,
        "- `baseline`: `dof` calls of `sin_cos` and `2·dof` stores (`dof` = n planar, 2n spatial), \
         the least any evaluation does.\n"
    );
    let _ =
        writeln!(out, "![time per evaluation vs n (fastest sample of each benchmark), log–log](bench.svg)\n");
    let _ = writeln!(out, "## Targets (issue 4)\n");
    out += &targets_markdown(&Targets::of(results), &Targets::of(fastest));
    for (kind, route) in LINEAR {
        if let Some(n) = Crossover::of(results, kind, route, GENERIC).from {
            let _ = writeln!(
                out,
                "{kind} {} is faster than the dense generic `Dyn` route from n = {n} on.\n",
                label(route)
            );
        }
    }

    for kind in KINDS {
        for (op, what) in OPERATIONS {
            let group = format!("{kind}_{op}");
            if !results.has_group(&group) {
                continue;
            }
            let _ = writeln!(out, "## {kind} {}\n\n{what}.\n", op.replace('_', " "));
            out += &times_table(results, &group, "Median time");
            out += &times_table(fastest, &group, "Fastest sample");
            let speedup = |t: f64, generic: f64| generic / t;
            let title = "Speed-up over generic `Dyn`, its time ÷ this time";
            out += &ratio_table(results, fastest, &group, GENERIC, title, speedup);
            if op == "accelerations" {
                let title = "Multiple of the baseline, this time ÷ baseline time";
                out += &ratio_table(results, fastest, &group, BASELINE, title, |t, base| t / base);
            }
        }
    }
    out += notes;
    out
}

fn header(columns: &[String]) -> String {
    format!("| n | {} |\n|---|{}\n", columns.join(" | "), "---|".repeat(columns.len()))
}

fn times_table(results: &Results, group: &str, title: &str) -> String {
    let implementations = ordered(results, group);
    let columns: Vec<String> = implementations.iter().map(|i| label(i).to_string()).collect();
    let mut out = format!("{title}:\n\n{}", header(&columns));
    for n in results.sizes(group) {
        let cells: Vec<String> =
            implementations.iter().map(|i| results.get(group, i, n).map_or("–".into(), time)).collect();
        let _ = writeln!(out, "| {n} | {} |", cells.join(" | "));
    }
    out + "\n"
}

/// A table of ratios `value(t, reference)` of each implementation against `reference`
/// (generic `Dyn` or the baseline) at each n; each cell "from medians / from fastest samples".
fn ratio_table(
    results: &Results,
    fastest: &Results,
    group: &str,
    reference: &str,
    title: &str,
    value: fn(f64, f64) -> f64,
) -> String {
    let implementations: Vec<&str> =
        ordered(results, group).into_iter().filter(|i| *i != reference && *i != BASELINE).collect();
    if implementations.is_empty() || results.series(group, reference).is_empty() {
        return String::new();
    }
    let columns: Vec<String> = implementations.iter().map(|i| label(i).to_string()).collect();
    let mut out = format!("{title} (medians / fastest samples):\n\n{}", header(&columns));
    for n in results.sizes(group) {
        let cell = |i: &str| {
            let r = |res: &Results| Some(value(res.get(group, i, n)?, res.get(group, reference, n)?));
            match (r(results), r(fastest)) {
                (None, None) => "–".to_string(),
                (m, f) => both(m, f),
            }
        };
        let cells: Vec<String> = implementations.iter().map(|i| cell(i)).collect();
        if cells.iter().any(|c| c != "–") {
            let _ = writeln!(out, "| {n} | {} |", cells.join(" | "));
        }
    }
    out + "\n"
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::verify::models;

    fn results() -> Results {
        let mut r = Results::default();
        let g = "planar_accelerations";
        for (n, generated, generic, linear) in
            [(1, 10.0, 60.0, 30.0), (2, 20.0, 100.0, 25.0), (4, 50.0, 140.0, 45.0), (8, 150.0, 400.0, 90.0)]
        {
            r.insert(g, "generated", n, generated);
            r.insert(g, GENERIC, n, generic);
            r.insert(g, "tension", n, linear);
            r.insert(g, BASELINE, n, 5.0 * n as f64);
        }
        r.insert(g, "closed_form", 2, 16.0);
        r.insert("spatial_accelerations", "generated", 1, 20.0);
        r.insert("spatial_accelerations", GENERIC, 1, 50.0);
        r
    }

    #[test]
    fn targets_report_speedups_shortfalls_and_the_crossover() {
        let t = Targets::of(&results());
        assert_eq!(t.speedups[0], ("planar", 1, Some(6.0)));
        assert_eq!(t.speedups[2], ("planar", 3, None));
        assert_eq!(t.speedups[4], ("spatial", 1, Some(2.5)));
        assert_eq!(t.closed_form, Some(1.25));
        // O(n) ÷ generated: 3, 1.25, 0.9, 0.6: faster from n = 4 on.
        assert_eq!(t.crossovers[0].from, Some(4));
        assert!(t.crossovers[1].ratios.is_empty());
        let md = targets_markdown(&t, &t);
        assert!(md.contains("| spatial | 1 | 2.50 / 2.50 | **missed**, 17% short |"), "{md}");
        assert!(md.contains("= 1.25 / 1.25 (medians: **missed**, 4% over;"), "{md}");
        assert!(
            md.contains("PlanarTension<Dyn>`:** faster than the generated models from **n = 4** (medians)"),
            "{md}"
        );
    }

    #[test]
    fn a_crossover_needs_the_route_faster_at_every_larger_n() {
        let mut r = Results::default();
        for (n, linear) in [(1, 0.5), (2, 2.0), (3, 0.5)] {
            r.insert("planar_accelerations", "generated", n, 1.0);
            r.insert("planar_accelerations", "tension", n, linear);
        }
        assert_eq!(Crossover::of(&r, "planar", "tension", "generated").from, Some(3));
        r.insert("planar_accelerations", "tension", 3, 1.5);
        assert_eq!(Crossover::of(&r, "planar", "tension", "generated").from, None);
    }

    #[test]
    fn tables_hold_medians_and_ratios() {
        let md = markdown(&results(), &results(), &RunInfo::default(), "NOTES");
        assert!(md.contains("| 2 | 20.0 ns | 100 ns | 16.0 ns | 25.0 ns | 10.0 ns |"), "{md}");
        // Speed-ups over generic Dyn: generated 5, closed form 6.25, O(n) 4.
        assert!(md.contains("| 2 | 5.00 / 5.00 | 6.25 / 6.25 | 4.00 / 4.00 |"), "{md}");
        // Multiples of the baseline (10 ns at n = 2).
        assert!(md.contains("| 2 | 2.00 / 2.00 | 10.0 / 10.0 | 1.60 / 1.60 | 2.50 / 2.50 |"), "{md}");
        assert!(md.ends_with("NOTES"));
    }

    #[test]
    fn times_get_units() {
        assert_eq!(time(7.25), "7.25 ns");
        assert_eq!(time(1234.0), "1.23 µs");
        assert_eq!(time(45_600_000.0), "45.6 ms");
    }

    #[test]
    fn default_algorithms_match_the_macro() {
        // The report's copy of the crossover against what `model!` generated.
        let planar = [
            models::Planar1::ALGORITHM,
            models::Planar2::ALGORITHM,
            models::Planar3::ALGORITHM,
            models::Planar4::ALGORITHM,
            models::Planar5::ALGORITHM,
            models::Planar6::ALGORITHM,
            models::Planar7::ALGORITHM,
            models::Planar8::ALGORITHM,
        ];
        for (n, a) in planar.into_iter().enumerate() {
            assert_eq!(a, default_algorithm("planar", n + 1), "planar n = {}", n + 1);
        }
        let spatial = [
            models::Spatial1::ALGORITHM,
            models::Spatial2::ALGORITHM,
            models::Spatial3::ALGORITHM,
            models::Spatial4::ALGORITHM,
            models::Spatial5::ALGORITHM,
        ];
        for (n, a) in spatial.into_iter().enumerate() {
            assert_eq!(a, default_algorithm("spatial", n + 1), "spatial n = {}", n + 1);
        }
        assert_eq!(
            (models::PlanarDense8::ALGORITHM, models::SpatialTension1::ALGORITHM),
            ("dense", "tension")
        );
    }
}
