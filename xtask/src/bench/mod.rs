//! `cargo xtask bench`: runs the criterion benchmarks (`pendulum-core/benches/models.rs`)
//! into a fresh directory, reads the medians and fastest samples back and writes
//! `docs/bench.md` (tables, targets, machine, date) and `docs/bench.svg` (log–log plot).
//! `--ensembles` does the same for the batches (`pendulum-core/benches/ensembles.rs`):
//! `docs/ensembles-speed.md` and `docs/ensembles-speed.svg` ([`ensembles`]).
//! `--quick` is a smoke run, and a run filtered by criterion arguments is partial: both
//! write their report under the target directory instead of `docs/`.

pub mod ensembles;
mod plot;
mod report;
mod results;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Instant, SystemTime, UNIX_EPOCH};

use anyhow::{Context, Result, bail};

pub use report::{RunInfo, Targets};
pub use results::{Results, Statistic};

/// Options of `cargo xtask bench`.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct Options {
    /// Smoke run (under a minute once built): few sizes, short warm-up and measurement;
    /// the report goes to `<target>/xtask-bench/<bench>/quick/`, not `docs/`.
    #[arg(long)]
    pub quick: bool,
    /// Do not run the benchmarks: rewrite the report from the last run's estimates.
    #[arg(long)]
    pub report_only: bool,
    /// The batches against the single-chain calls instead (`pendulum-core/benches/ensembles.rs`,
    /// about four minutes a run; `--quick` is no shorter, as its groups set their own
    /// times): `docs/ensembles-speed.md` and `docs/ensembles-speed.svg`.
    #[arg(long)]
    pub ensembles: bool,
    /// With `--ensembles`: this many whole runs, one after another, each ratio taken
    /// within a run and the report giving each run's (a shared machine's ratios move by
    /// 10–20% from run to run).
    #[arg(long, default_value_t = 1, requires = "ensembles", value_parser = clap::value_parser!(u32).range(1..=20))]
    pub runs: u32,
    /// Extra arguments for criterion, e.g. a filter such as `planar_accelerations`
    /// (a filtered run's report goes under the target directory, not `docs/`).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    pub args: Vec<String>,
}

/// Criterion settings: (warm-up s, measurement s, samples, bootstrap resamples).
const FULL: (f64, f64, usize, usize) = (0.3, 0.7, 40, 20_000);
/// See [`FULL`].
const QUICK: (f64, f64, usize, usize) = (0.02, 0.05, 10, 1_000);

/// The command of a complete run, as recorded in its report.
const FULL_COMMAND: &str = "cargo xtask bench";
/// The command of a complete run of the ensembles' benchmarks.
const ENSEMBLES_COMMAND: &str = "cargo xtask bench --ensembles";

/// Runs the benchmarks and writes the report and plot.
pub fn run(options: &Options) -> Result<()> {
    if options.ensembles {
        return run_ensembles(options);
    }
    let mode = if options.quick { "quick" } else { "full" };
    let scratch = target_dir()?.join("xtask-bench").join("models").join(mode);
    let criterion = scratch.join("criterion");
    let info = run_once(options, ("models", FULL_COMMAND), &scratch)?;
    // Only a complete full run (no criterion filter) goes to docs/.
    let complete = !options.quick && info.command == FULL_COMMAND;
    let out_dir = if complete { crate::workspace_root().join("docs") } else { scratch.clone() };
    let results = Results::load(&criterion, Statistic::Median)?;
    let fastest = Results::load(&criterion, Statistic::Fastest)?;
    let md_path = out_dir.join("bench.md");
    let notes = existing_notes(&crate::workspace_root().join("docs").join("bench.md"));
    std::fs::write(&md_path, report::markdown(&results, &fastest, &info, &notes))
        .with_context(|| format!("writing {}", md_path.display()))?;
    let svg_path = out_dir.join("bench.svg");
    std::fs::write(&svg_path, plot::svg(&fastest)?)
        .with_context(|| format!("writing {}", svg_path.display()))?;
    println!("\n{}", report::targets_markdown(&Targets::of(&results), &Targets::of(&fastest)));
    println!("{} benchmarks; wrote {} and {}", results.len(), md_path.display(), svg_path.display());
    Ok(())
}

/// The run's facts, from running the benchmarks `name` into `scratch/criterion` (and
/// saving them in `scratch/run.json`), or with `--report-only` from that file.
fn run_once(options: &Options, (name, full): (&str, &str), scratch: &Path) -> Result<RunInfo> {
    let info_path = scratch.join("run.json");
    if options.report_only {
        return read_info(&info_path);
    }
    let info = bench(options, (name, full), &scratch.join("criterion"))?;
    std::fs::write(&info_path, serde_json::to_string_pretty(&info)?)
        .with_context(|| format!("writing {}", info_path.display()))?;
    Ok(info)
}

/// `cargo xtask bench --ensembles`: `--runs` runs of the ensembles' benchmarks, then
/// `ensembles-speed.md` and `.svg` (in `docs/` for a complete full run) and the issue's
/// checks printed, each run's.
fn run_ensembles(options: &Options) -> Result<()> {
    let mode = if options.quick { "quick" } else { "full" };
    let scratch = target_dir()?.join("xtask-bench").join("ensembles").join(mode);
    let full = match options.runs {
        1 => ENSEMBLES_COMMAND.to_string(),
        k => format!("{ENSEMBLES_COMMAND} --runs {k}"),
    };
    let mut runs = Vec::new();
    for k in 1..=options.runs {
        let dir = scratch.join(format!("run-{k}"));
        let info = run_once(options, ("ensembles", &full), &dir)?;
        runs.push((info, ensembles::Measured::load(&dir.join("criterion"))?));
    }
    // An unfiltered run has every benchmark the report names, or the report is out of date.
    if options.args.is_empty() {
        for (k, (_, m)) in runs.iter().enumerate() {
            let missing = ensembles::missing(m);
            if !missing.is_empty() {
                bail!("run {}: the report names benchmarks that did not run: {}", k + 1, missing.join(", "));
            }
        }
    }
    let complete = !options.quick && runs.iter().all(|(info, _)| info.command == full);
    let out_dir = if complete { crate::workspace_root().join("docs") } else { scratch.clone() };
    let md_path = out_dir.join("ensembles-speed.md");
    std::fs::write(&md_path, ensembles::markdown(&runs))
        .with_context(|| format!("writing {}", md_path.display()))?;
    let svg_path = out_dir.join("ensembles-speed.svg");
    let measured: Vec<&ensembles::Measured> = runs.iter().map(|(_, m)| m).collect();
    std::fs::write(&svg_path, ensembles::svg(&measured)?)
        .with_context(|| format!("writing {}", svg_path.display()))?;
    for (k, m) in measured.iter().enumerate() {
        println!("run {}:", k + 1);
        for check in ensembles::checks(m) {
            let met = match check.met() {
                Some(true) => "met",
                Some(false) => "MISSED",
                None => "not run",
            };
            let ratio = check.median.map_or("–".into(), |r| format!("{r:.2}×"));
            println!("{met:>7}  {ratio:>8} (≥ {}×)  {}: {}", check.bound, check.target, check.what);
        }
    }
    println!("{} runs; wrote {} and {}", runs.len(), md_path.display(), svg_path.display());
    Ok(())
}

/// The checked-out commit, short, with `+changes` when the tree differs from it (from
/// `git`; `unknown` without it).
fn commit() -> String {
    let git = |args: &[&str]| {
        Command::new("git")
            .current_dir(crate::workspace_root())
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    let Some(hash) = git(&["rev-parse", "--short", "HEAD"]) else { return "unknown".into() };
    match git(&["status", "--porcelain", "--untracked-files=no"]) {
        Some(changes) if !changes.is_empty() => format!("{hash}+changes"),
        _ => hash,
    }
}

/// Runs `cargo bench --workspace --bench <name>` (pendulum-core's, the workspace's one
/// bench of that name) with criterion's output in `criterion` (emptied first, so the
/// report never mixes runs); `full` is how the report names a complete run.
fn bench(options: &Options, (name, full): (&str, &str), criterion: &Path) -> Result<RunInfo> {
    if criterion.exists() {
        std::fs::remove_dir_all(criterion).with_context(|| format!("emptying {}", criterion.display()))?;
    }
    std::fs::create_dir_all(criterion).with_context(|| format!("creating {}", criterion.display()))?;
    let (warm_up, measurement, samples, resamples) = if options.quick { QUICK } else { FULL };
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    // `--workspace` unifies features as `cargo bench --workspace --no-run` (CI) does, so the
    // binary CI compiled is reused rather than built again.
    let build = ["bench", "--workspace", "--bench", name];
    let status = Command::new(&cargo)
        .current_dir(crate::workspace_root())
        .args(build)
        .arg("--no-run")
        .status()
        .context("building the benchmarks")?;
    if !status.success() {
        bail!("cargo bench --no-run failed ({status})");
    }
    let mut command = Command::new(cargo);
    command
        .current_dir(crate::workspace_root())
        .args(build)
        .arg("--")
        .args(["--warm-up-time", &warm_up.to_string(), "--measurement-time", &measurement.to_string()])
        .args(["--sample-size", &samples.to_string(), "--nresamples", &resamples.to_string()])
        .args(&options.args)
        .env("CRITERION_HOME", criterion)
        .env("PENDULUM_BENCH_QUICK", if options.quick { "1" } else { "0" });
    let date = utc_now();
    let load_before = load_average();
    let start = Instant::now();
    let status = command.status().context("running cargo bench")?;
    let seconds = start.elapsed().as_secs_f64();
    if !status.success() {
        bail!("cargo bench failed ({status})");
    }
    let mut invocation = String::from(full);
    if options.quick {
        invocation += " --quick";
    }
    for a in &options.args {
        invocation += &format!(" {a}");
    }
    Ok(RunInfo {
        command: invocation,
        date,
        machine: machine(),
        settings: format!(
            "{warm_up} s warm-up, {measurement} s measurement, {samples} samples and {resamples} \
             bootstrap resamples per benchmark"
        ),
        load: (load_before, load_average()),
        seconds,
        commit: commit(),
    })
}

/// The cargo target directory (honours `CARGO_TARGET_DIR` and cargo config), from
/// `cargo metadata`.
fn target_dir() -> Result<PathBuf> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let output = Command::new(cargo)
        .current_dir(crate::workspace_root())
        .args(["metadata", "--format-version", "1", "--no-deps", "--offline"])
        .output()
        .context("running cargo metadata")?;
    if !output.status.success() {
        bail!("cargo metadata failed: {}", String::from_utf8_lossy(&output.stderr));
    }
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).context("parsing cargo metadata")?;
    let dir = json["target_directory"].as_str().context("cargo metadata: no target_directory")?;
    Ok(PathBuf::from(dir))
}

/// The hand-written notes of the committed report: from [`report::NOTES_MARKER`] to
/// the end, or the marker alone if there are none.
fn existing_notes(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    match text.find(report::NOTES_MARKER) {
        Some(i) => text[i..].to_string(),
        None => format!("{}\n", report::NOTES_MARKER),
    }
}

/// `"<cpu model>, <n> logical cores"` from `/proc/cpuinfo` (Linux) and the standard
/// library's count.
fn machine() -> String {
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    format!("{model}, {cores} logical cores")
}

/// The 1, 5 and 15 minute load averages from `/proc/loadavg`, or `"unknown"`.
fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|| "unknown".into())
}

/// The current UTC time as `YYYY-MM-DD HH:MM UTC`.
fn utc_now() -> String {
    let secs = SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_secs());
    utc(secs)
}

/// `secs` since the Unix epoch as `YYYY-MM-DD HH:MM UTC` (proleptic Gregorian calendar;
/// the days-to-civil conversion of H. Hinnant's `chrono` algorithms).
fn utc(secs: u64) -> String {
    let days = (secs / 86_400) as i64;
    let (hour, minute) = ((secs % 86_400) / 3600, (secs % 3600) / 60);
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02} {hour:02}:{minute:02} UTC")
}

/// The [`RunInfo`] saved by the last run (for `--report-only`).
fn read_info(path: &Path) -> Result<RunInfo> {
    let text = std::fs::read_to_string(path).with_context(|| {
        format!("reading {} (run the benchmarks first, without --report-only)", path.display())
    })?;
    serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_dates() {
        assert_eq!(utc(0), "1970-01-01 00:00 UTC");
        // 2000-02-29 12:34 (leap day of a century leap year).
        assert_eq!(utc(951_827_640), "2000-02-29 12:34 UTC");
        assert_eq!(utc(1_795_320_000), "2026-11-22 04:00 UTC");
    }

    #[test]
    fn notes_are_kept_from_the_marker_on() {
        let dir = std::env::temp_dir().join(format!("xtask-bench-notes-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("bench.md");
        std::fs::write(&path, format!("# generated\n| table |\n{}\nwhy it is slow\n", report::NOTES_MARKER))
            .unwrap();
        let notes = existing_notes(&path);
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(notes, format!("{}\nwhy it is slow\n", report::NOTES_MARKER));
        assert_eq!(existing_notes(&dir.join("missing.md")), format!("{}\n", report::NOTES_MARKER));
    }
}
