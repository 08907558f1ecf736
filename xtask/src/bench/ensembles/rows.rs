//! What the report compares: each row a single-chain benchmark and the batch's that do the
//! same work (`pendulum-core/benches/ensembles.rs`' ids), and the targets.

use super::measured::{Measured, Timing};

/// The report's sections, in order: [`Row::section`] indexes them.
pub const SECTIONS: [&str; 6] = [
    "Accelerations, 64 chains a call",
    "One call of 1024 chains of 100 links (per chain against the single call of 64)",
    "The 3D whirl, n = 100: projected RK4 steps of 1 ms, and the implicit rod midpoint",
    "Planar RK4 runs, 100 steps of 0.1 ms a call",
    "Generated models (`model!`)",
    "Jacobians `∂q̈/∂q`, `∂q̈/∂q̇`, 64 chains a call",
];

/// One line of the report: the single-chain benchmark and the batch's doing the same work
/// (full criterion ids).
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Index into [`SECTIONS`].
    pub section: usize,
    /// What the line times.
    pub label: String,
    /// The single-chain call, chain after chain.
    pub single: String,
    /// The batch on one thread.
    pub batch: String,
    /// The batch on two threads.
    pub two_threads: Option<String>,
    /// The batch in `f32` on one thread.
    pub f32: Option<String>,
}

/// The rows of `family` (`<group>/<kind>/`) at `n`: `single`, `batch_1_threads`,
/// `batch_2_threads` and, with `f32`, `batch_f32_1_thread`.
fn family(section: usize, label: String, family: &str, n: usize, f32: bool) -> Row {
    Row {
        section,
        label,
        single: format!("{family}/single/{n}"),
        batch: format!("{family}/batch_1_threads/{n}"),
        two_threads: Some(format!("{family}/batch_2_threads/{n}")),
        f32: f32.then(|| format!("{family}/batch_f32_1_thread/{n}")),
    }
}

/// Every row, section by section.
pub fn rows() -> Vec<Row> {
    let mut rows = Vec::new();
    for (kind, name) in [("planar", "planar (tension)"), ("spatial", "3D (directions)")] {
        for n in [8, 20, 100] {
            rows.push(family(0, format!("{name}, n = {n}"), &format!("accelerations/{kind}"), n, true));
        }
        rows.push(Row {
            section: 0,
            label: format!("{name}, n = 100, four lanes a register"),
            single: format!("accelerations/{kind}/single/100"),
            batch: format!("accelerations/{kind}/batch_1_threads_four_lanes/100"),
            two_threads: Some(format!("accelerations/{kind}/batch_2_threads_four_lanes/100")),
            f32: None,
        });
    }
    for (kind, name) in [("planar", "planar (tension)"), ("spatial", "3D (directions)")] {
        rows.push(Row {
            section: 1,
            label: name.to_string(),
            single: format!("accelerations/{kind}/single/100"),
            batch: format!("accelerations/{kind}/batch_1_threads_1024_chains/100"),
            two_threads: Some(format!("accelerations/{kind}/batch_2_threads_1024_chains/100")),
            f32: None,
        });
    }
    rows.push(Row {
        section: 2,
        label: "RK4, one step a call".into(),
        single: "rk4/whirl_100/single".into(),
        batch: "rk4/whirl_100/batch_1_threads".into(),
        two_threads: Some("rk4/whirl_100/batch_2_threads".into()),
        f32: None,
    });
    rows.push(Row {
        section: 2,
        label: "RK4, 100 steps a call".into(),
        single: "rk4/whirl_100/single".into(),
        batch: "rk4/whirl_100/batch_1_threads_100_steps".into(),
        two_threads: Some("rk4/whirl_100/batch_2_threads_100_steps".into()),
        f32: Some("rk4/whirl_100/batch_f32_1_thread_100_steps".into()),
    });
    for (label, suffix) in
        [("rod midpoint, 10 steps of 1 ms a call", ""), ("the same, steps of 50 ms", "_of_50ms")]
    {
        rows.push(Row {
            section: 2,
            label: label.into(),
            single: format!("rk4/whirl_100/rod_midpoint_single_10_steps{suffix}"),
            batch: format!("rk4/whirl_100/rod_midpoint_batch_1_threads_10_steps{suffix}"),
            two_threads: Some(format!("rk4/whirl_100/rod_midpoint_batch_2_threads_10_steps{suffix}")),
            f32: Some(format!("rk4/whirl_100/rod_midpoint_batch_f32_1_thread_10_steps{suffix}")),
        });
    }
    for n in [20, 100] {
        rows.push(family(3, format!("free, n = {n}"), "rk4/planar_100_steps", n, true));
    }
    rows.push(Row {
        section: 3,
        label: "each pivot shaken, n = 20".into(),
        single: "rk4/planar_100_steps/single_driven/20".into(),
        batch: "rk4/planar_100_steps/batch_1_threads_driven/20".into(),
        two_threads: None,
        f32: Some("rk4/planar_100_steps/batch_f32_1_thread_driven/20".into()),
    });
    for n in [4, 8, 16] {
        rows.push(family(4, format!("planar accelerations, n = {n}"), "generated/planar", n, true));
    }
    for n in [4, 8] {
        rows.push(Row {
            section: 4,
            label: format!("planar accelerations, n = {n}, four lanes a register"),
            single: format!("generated/planar/single/{n}"),
            batch: format!("generated/planar/batch_1_threads_four_lanes/{n}"),
            two_threads: None,
            f32: None,
        });
    }
    for n in [4, 8] {
        rows.push(family(4, format!("spatial accelerations, n = {n}"), "generated/spatial", n, true));
    }
    for n in [4, 8] {
        rows.push(family(
            4,
            format!("planar RK4, 100 steps a call, n = {n}"),
            "generated/rk4_100_steps",
            n,
            true,
        ));
    }
    rows.push(Row {
        section: 4,
        label: "spatial RK4, 100 steps a call, n = 4".into(),
        single: "generated/rk4_100_steps/spatial_single/4".into(),
        batch: "generated/rk4_100_steps/spatial_batch_1_threads/4".into(),
        two_threads: Some("generated/rk4_100_steps/spatial_batch_2_threads/4".into()),
        f32: Some("generated/rk4_100_steps/spatial_batch_f32_1_thread/4".into()),
    });
    rows.push(Row {
        section: 4,
        label: "spatial RK4 whirled, 100 steps a call, n = 4".into(),
        single: "generated/rk4_100_steps/spatial_whirled_single/4".into(),
        batch: "generated/rk4_100_steps/spatial_whirled_batch_1_threads/4".into(),
        two_threads: None,
        f32: Some("generated/rk4_100_steps/spatial_whirled_batch_f32_1_thread/4".into()),
    });
    // Against the loop of single calls, then against the same loop keeping every result in
    // the `(B, ·, ·)` arrays the batch writes (`single_kept`).
    for (kind, name) in [("planar", "planar"), ("spatial", "3D (directions)")] {
        for n in [8, 20, 100] {
            let row = family(5, format!("{name}, n = {n}"), &format!("jacobians/{kind}"), n, true);
            let kept = Row {
                label: format!("{name}, n = {n}, against the loop keeping every result"),
                single: format!("jacobians/{kind}/single_kept/{n}"),
                ..row.clone()
            };
            rows.extend([row, kept]);
        }
    }
    rows
}

/// MuJoCo's `rollout`, RK4 on a 100-link chain, one thread: ns a step (the figure,
/// measured beside this project's benchmarks when the issue was written; not rerun here).
pub const MUJOCO_ROLLOUT_NS: f64 = 302_000.0;

/// One of the targets, measured: a ratio from the medians and one from the fastest
/// samples, against its bound (`≥`).
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// The target as the issue states it.
    pub target: &'static str,
    /// What was measured.
    pub what: String,
    /// The ratio from the medians, if both benchmarks ran.
    pub median: Option<f64>,
    /// The ratio from the fastest samples.
    pub fastest: Option<f64>,
    /// The bound the ratio must reach.
    pub bound: f64,
}

impl Check {
    /// `Some(true)` when the medians' ratio reaches the bound, `None` when it did not run.
    pub fn met(&self) -> Option<bool> {
        self.median.map(|r| r >= self.bound)
    }
}

/// `of(a) ÷ of(b)` from the medians and from the fastest samples.
fn ratio(m: &Measured, a: &str, b: &str) -> (Option<f64>, Option<f64>) {
    let of = |f: fn(Timing) -> f64| Some(f(m.get(a)?) / f(m.get(b)?));
    (of(|t| t.median), of(|t| t.fastest))
}

/// The targets, each checked in `measured`.
pub fn checks(measured: &Measured) -> Vec<Check> {
    let mut out = Vec::new();
    let mut check = |target, what: String, (median, fastest), bound| {
        out.push(Check { target, what, median, fastest, bound });
    };
    const ACCELERATIONS: &str = "batched accelerations ≥ 3× the single call per chain (f64)";
    for (kind, name) in [("planar", "planar"), ("spatial", "3D")] {
        for n in [8, 20, 100] {
            let ids = [
                format!("accelerations/{kind}/single/{n}"),
                format!("accelerations/{kind}/batch_1_threads/{n}"),
            ];
            check(ACCELERATIONS, format!("{name}, n = {n}"), ratio(measured, &ids[0], &ids[1]), 3.0);
        }
    }
    const THREADS: &str = "two threads ≥ 1.8× one thread, batch of ≥ 64 chains";
    for (kind, name) in [("planar", "planar"), ("spatial", "3D")] {
        for (what, suffix) in [("one call of 1024 chains", "_1024_chains"), ("one call of 64 chains", "")] {
            let [one, two] = [1, 2].map(|t| format!("accelerations/{kind}/batch_{t}_threads{suffix}/100"));
            check(
                THREADS,
                format!("{name} accelerations, {what}, n = 100"),
                ratio(measured, &one, &two),
                1.8,
            );
        }
    }
    let runs = [
        ("whirl RK4, 100 steps a call", "rk4/whirl_100/batch_{t}_threads_100_steps"),
        ("planar RK4 runs, n = 100", "rk4/planar_100_steps/batch_{t}_threads/100"),
        ("generated planar RK4 runs, n = 8", "generated/rk4_100_steps/batch_{t}_threads/8"),
    ];
    for (what, pattern) in runs {
        let [one, two] = [1, 2].map(|t| pattern.replace("{t}", &t.to_string()));
        check(THREADS, what.to_string(), ratio(measured, &one, &two), 1.8);
    }
    const WHIRL: &str = "batched RK4 step of the 3D whirl (n = 100) ≥ 3× the single step";
    let single = "rk4/whirl_100/single";
    check(WHIRL, "one step a call".into(), ratio(measured, single, "rk4/whirl_100/batch_1_threads"), 3.0);
    let runs = "rk4/whirl_100/batch_1_threads_100_steps";
    check(WHIRL, "100 steps a call".into(), ratio(measured, single, runs), 3.0);
    let mujoco = measured.get(runs).map(|t| (MUJOCO_ROLLOUT_NS / t.median, MUJOCO_ROLLOUT_NS / t.fastest));
    check(
        "per chain-step ≥ 50× MuJoCo's `rollout` RK4 of a 100-link chain, one thread (302 µs)",
        "whirl RK4, 100 steps a call".into(),
        (mujoco.map(|m| m.0), mujoco.map(|m| m.1)),
        50.0,
    );
    for n in [4, 8] {
        let ids = [format!("generated/planar/single/{n}"), format!("generated/planar/batch_1_threads/{n}")];
        let what = format!("accelerations, N = {n}");
        check(
            "generated planar N = 4 and N = 8: batched ≥ 3× single per chain",
            what,
            ratio(measured, &ids[0], &ids[1]),
            3.0,
        );
    }
    out
}

/// What the report names but `measured` lacks: each row's benchmark ids that did not run,
/// and each check that could not be taken. Empty for an unfiltered run of a bench that
/// still has every benchmark the report names (a renamed one would otherwise be a silent
/// `–`).
pub fn missing(measured: &Measured) -> Vec<String> {
    let mut out: Vec<String> = rows()
        .iter()
        .flat_map(|r| [Some(&r.single), Some(&r.batch), r.two_threads.as_ref(), r.f32.as_ref()])
        .flatten()
        .filter(|id| measured.get(id).is_none())
        .cloned()
        .collect();
    out.sort();
    out.dedup();
    out.extend(
        checks(measured).into_iter().filter(|c| c.median.is_none()).map(|c| format!("check: {}", c.what)),
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_names_the_rows_ids_and_the_checks_that_did_not_run() {
        let mut m = Measured::default();
        let t = Timing { median: 1.0, fastest: 1.0 };
        for r in rows() {
            for id in [Some(r.single), Some(r.batch), r.two_threads, r.f32].into_iter().flatten() {
                m.insert(&id, t);
            }
        }
        // Every row's ids, and the checks' (which are rows' ids too) complete the run.
        assert_eq!(missing(&m), Vec::<String>::new());
        let mut short = Measured::default();
        for r in rows().into_iter().filter(|r| r.label != "planar (tension), n = 8") {
            for id in [Some(r.single), Some(r.batch), r.two_threads, r.f32].into_iter().flatten() {
                short.insert(&id, t);
            }
        }
        assert_eq!(
            missing(&short),
            [
                "accelerations/planar/batch_1_threads/8",
                "accelerations/planar/batch_2_threads/8",
                "accelerations/planar/batch_f32_1_thread/8",
                "accelerations/planar/single/8",
                "check: planar, n = 8",
            ]
        );
    }

    #[test]
    fn ids_name_rows_of_their_own_section_and_are_unique() {
        let rows = rows();
        assert!(rows.iter().all(|r| r.section < SECTIONS.len()));
        // Sections in order, so that the report's headings come once each.
        assert!(rows.windows(2).all(|w| w[0].section <= w[1].section));
        let mut labels: Vec<_> = rows.iter().map(|r| (r.section, &r.label)).collect();
        labels.sort();
        labels.dedup();
        assert_eq!(labels.len(), rows.len(), "a label repeated in a section");
        assert!(rows.iter().all(|r| r.single.contains("single") && !r.batch.contains("single")));
    }

    #[test]
    fn checks_divide_single_by_batch_and_compare_with_the_bound() {
        let mut m = Measured::default();
        m.insert("accelerations/planar/single/8", Timing { median: 90.0, fastest: 80.0 });
        m.insert("accelerations/planar/batch_1_threads/8", Timing { median: 30.0, fastest: 25.0 });
        m.insert("accelerations/planar/single/20", Timing { median: 100.0, fastest: 100.0 });
        m.insert("accelerations/planar/batch_1_threads/20", Timing { median: 40.0, fastest: 30.0 });
        m.insert("rk4/whirl_100/batch_1_threads_100_steps", Timing { median: 1000.0, fastest: 2000.0 });
        let checks = checks(&m);
        let find = |what: &str| checks.iter().find(|c| c.what == what).unwrap();
        assert_eq!((find("planar, n = 8").median, find("planar, n = 8").met()), (Some(3.0), Some(true)));
        assert_eq!(find("planar, n = 8").fastest, Some(3.2));
        // 2.5× from the medians misses, though the fastest samples read 3.33×.
        assert_eq!(find("planar, n = 20").met(), Some(false));
        assert_eq!(find("planar, n = 100").met(), None);
        let mujoco = checks.iter().find(|c| c.bound == 50.0).unwrap();
        assert_eq!((mujoco.median, mujoco.fastest), (Some(302.0), Some(151.0)));
    }
}
