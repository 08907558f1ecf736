//! `pendulum sweep` on small chains (6 links, tens of seconds simulated): a row per point
//! and kind, the node counts and tip radii of the same points run by `pendulum simulate`,
//! `--scaled` speeds, the ramp-down chain, `--from sweep.json` and `--jobs` changing
//! nothing, Ctrl-C keeping the finished points, and bad inputs refused in one line.

mod common;

use std::path::{Path, PathBuf};

use common::{Table, run_in, scratch, stderr};

/// The chain of every test: 6 links of 0.1 m and 0.1 kg (L = 0.6 m, √(g/L) = 4.04 rad/s,
/// critical speeds 4.7, 10.9 rad/s), damped so the first mode decays at ≈ 0.3 1/s.
const CHAIN: [&str; 8] = ["--n", "6", "--lengths", "0.1", "--masses", "0.1", "--damping", "0.01"];

/// Every field of a sweep.csv but the wall-clock time, row by row.
fn without_wall_time(table: &Table) -> Vec<Vec<String>> {
    let wall = table.index("wall_s");
    table
        .rows
        .iter()
        .map(|r| r.iter().enumerate().filter(|(j, _)| *j != wall).map(|(_, v)| v.clone()).collect())
        .collect()
}

/// Runs `pendulum sweep args… --out NAME` in `dir`; asserts success, returns the directory.
fn sweep_in(dir: &Path, name: &str, args: &[&str]) -> PathBuf {
    let mut all = vec!["sweep"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--out", name]);
    let out = run_in(dir, &all);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    dir.join(name)
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn a_row_per_point_and_kind_with_the_node_counts_of_simulate() {
    let dir = scratch("sweep-rows");
    let mut args = CHAIN.to_vec();
    args.extend(["--omega", "0.5:2.2:3", "--scaled", "--duration", "40", "--ramp-time", "12"]);
    let out = sweep_in(&dir, "s", &args);
    let csv = Table::read(&out.join("sweep.csv"));
    let kinds = csv.text("kind");
    assert_eq!(
        kinds,
        [
            "sudden",
            "sudden",
            "sudden",
            "ramp-up",
            "ramp-up",
            "ramp-up",
            "ramp-down",
            "ramp-down",
            "ramp-down"
        ]
    );
    assert!(csv.text("status").iter().all(|s| s == "completed"), "{:?}", csv.text("status"));
    // --scaled: the speeds in units of √(g/L), L = 0.6 m; ramp-down in decreasing ω.
    let scale = (9.81_f64 / 0.6).sqrt();
    let (omega, scaled) = (csv.column("omega_rad_s"), csv.column("omega_over_sqrt_g_over_L"));
    let expected = [0.5, 1.35, 2.2, 0.5, 1.35, 2.2, 2.2, 1.35, 0.5];
    for ((w, s), e) in omega.iter().zip(&scaled).zip(expected) {
        assert!((s - e).abs() < 1e-12 && (w - e * scale).abs() < 1e-12, "{w} rad/s, {s}");
    }
    // Below the first critical speed (4.7 rad/s) 1 node; above it the small two-node
    // response, also ramping down from it at 1.35 √(g/L); 1 node again below ω_1.
    assert_eq!(csv.column("nodes"), [1.0, 2.0, 2.0, 1.0, 2.0, 2.0, 2.0, 2.0, 1.0]);
    assert_eq!(csv.column("nodes"), csv.column("nearest_nodes"));
    // The first ramp-down point is the ramp-up run at the top speed.
    let rows = without_wall_time(&csv);
    assert_eq!(rows[5][1..], rows[6][1..]);
    // The same points run by `pendulum simulate`: the same trajectory, the same report.
    let json = json(&out.join("sweep.json"));
    let step = json["config"]["step"].as_f64().unwrap().to_string();
    let (nodes, tips, drifts) = (csv.column("nodes"), csv.column("tip_radius_m"), csv.column("drift_m"));
    for i in [0, 2, 4] {
        let w = omega[i].to_string();
        let name = format!("run{i}");
        let mut run = vec!["simulate", "--dim", "3", "--drive", "circle", "--radius", "0.02", "--omega", &w];
        run.extend_from_slice(&CHAIN);
        run.extend(["--integrator", "rk4", "--step", &step, "--end", "40", "--initial", "hanging"]);
        // The sweep feeds the shape tracker every 4 steps (its FEED_EVERY).
        run.extend(["--every", "4"]);
        run.extend(["--no-plots", "--quiet", "--out", &name]);
        if kinds[i] == "ramp-up" {
            run.extend(["--ramp-time", "12"]);
        }
        let done = run_in(&dir, &run);
        assert!(done.status.success(), "{}", stderr(&done));
        let shape = self::json(&dir.join(&name).join("shape.json"));
        assert_eq!(shape["nodes"].as_f64().unwrap(), nodes[i], "point {i}");
        let tip = shape["tip_radius"].as_f64().unwrap();
        assert!((tip - tips[i]).abs() <= 1e-12 * tip, "point {i}: {tip} against {}", tips[i]);
        let drift = shape["drift"].as_f64().unwrap();
        assert!(
            (drift - drifts[i]).abs() <= 1e-9 * drift.max(1e-12),
            "point {i}: {drift} against {}",
            drifts[i]
        );
    }
    // Every point's energy balance closes (issue 34: said per point, a warning if off).
    let scale = json["points"][0]["result"]["balance"]["scale"].as_f64().unwrap();
    for residual in csv.column("balance_residual_j") {
        assert!(residual.is_finite() && residual < 1e-6 * scale, "{residual} J of {scale} J");
    }
    // The files: sweep.json has every point's result, sweep.png is a picture.
    assert_eq!(json["status"], "completed");
    assert_eq!(json["points"].as_array().unwrap().len(), 9);
    assert_eq!(json["config"]["scaled"], true);
    assert!(std::fs::read(out.join("sweep.png")).unwrap().starts_with(b"\x89PNG"));
}

#[test]
fn from_sweep_json_and_any_number_of_jobs_give_the_same_numbers() {
    let dir = scratch("sweep-repeat");
    let mut args = CHAIN.to_vec();
    args.extend(["--omega", "3,6,12,9", "--duration", "20", "--kind", "sudden,ramp-down", "--jobs", "1"]);
    let one = sweep_in(&dir, "one", &args);
    *args.last_mut().unwrap() = "2";
    let two = sweep_in(&dir, "two", &args);
    let from = sweep_in(&dir, "from", &["--from", "one/sweep.json", "--jobs", "2"]);
    let reference = Table::read(&one.join("sweep.csv"));
    assert_eq!(reference.rows.len(), 8);
    assert_eq!(reference.text("kind")[4..], ["ramp-down"; 4]);
    assert_eq!(reference.column("omega_rad_s")[4..], [12.0, 9.0, 6.0, 3.0]);
    for other in [&two, &from] {
        assert_eq!(without_wall_time(&Table::read(&other.join("sweep.csv"))), without_wall_time(&reference));
        assert_eq!(json(&other.join("sweep.json"))["config"], json(&one.join("sweep.json"))["config"]);
    }
}

#[cfg(unix)]
#[test]
fn ctrl_c_keeps_the_finished_points_and_marks_the_others() {
    use std::time::{Duration, Instant};
    let dir = scratch("sweep-interrupt");
    let mut args = vec!["sweep"];
    args.extend_from_slice(&CHAIN);
    args.extend([
        "--omega",
        "1:10:40",
        "--kind",
        "sudden",
        "--duration",
        "3000",
        "--jobs",
        "1",
        "--out",
        "s",
    ]);
    let child = common::pendulum()
        .args(&args)
        .current_dir(&dir)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let completed = || {
        std::fs::read_to_string(dir.join("s/sweep.json"))
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .map_or(0, |j| {
                j["points"].as_array().unwrap().iter().filter(|p| p["status"] == "completed").count()
            })
    };
    while completed() == 0 {
        assert!(start.elapsed() < Duration::from_secs(60), "no point finished");
        std::thread::sleep(Duration::from_millis(20));
    }
    let pid = child.id().to_string();
    let killed = std::process::Command::new("sh").args(["-c", &format!("kill -INT {pid}")]).status().unwrap();
    assert!(killed.success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
    let last = stderr(&out).lines().last().unwrap_or_default().to_string();
    assert!(last.starts_with("error: interrupted: ") && last.contains(" of 40 points finished"), "{last}");
    let csv = Table::read(&dir.join("s/sweep.csv"));
    assert_eq!(csv.rows.len(), 40);
    let status = csv.text("status");
    let done = status.iter().filter(|s| *s == "completed").count();
    assert!((1..40).contains(&done), "{status:?}");
    assert!(
        status.iter().all(|s| ["completed", "interrupted", "not-run"].contains(&s.as_str())),
        "{status:?}"
    );
    for (s, nodes) in status.iter().zip(csv.text("nodes")) {
        assert_eq!(s == "completed", !nodes.is_empty(), "{s}: '{nodes}'");
    }
    let json = json(&dir.join("s/sweep.json"));
    assert_eq!(json["status"], "interrupted");
    assert!(std::fs::read(dir.join("s/sweep.png")).unwrap().starts_with(b"\x89PNG"));
}

#[test]
fn bad_inputs_are_refused_in_one_line_naming_the_value() {
    let dir = scratch("sweep-bad");
    let ok = ["--n", "2"];
    let simulated = run_in(&dir, &["simulate", "--end", "0.01", "--no-plots", "--quiet", "--out", "run"]);
    assert!(simulated.status.success());
    std::fs::write(dir.join("other.json"), "{\"program\": \"pendulum\", \"command\": \"sweep\"}").unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["--omega", ""], "--omega: '' lists no speed"),
        (&["--omega", ","], "--omega: ',' lists no speed"),
        (&["--omega", "1,-2"], "--omega: '1,-2' has a negative entry -2 (speeds are ≥ 0 rad/s)"),
        (&["--omega", "-1", "--scaled"], "--omega: '-1' has a negative entry -1 (speeds are ≥ 0 √(g/L))"),
        (&["--omega", "1,inf"], "--omega: '1,inf' has a non-finite entry inf"),
        (&["--omega", "NaN"], "--omega: 'NaN' has a non-finite entry NaN"),
        (&["--omega", "1,x"], "--omega: '1,x' has a bad entry 'x' (not a number)"),
        (&["--omega", "1:2"], "--omega: '1:2' is not a range A:B:N"),
        (&["--omega", "1:2:3:4"], "--omega: '1:2:3:4' is not a range A:B:N"),
        (&["--omega", "1:2:0"], "--omega: '1:2:0' asks for 0 points (N must be at least 1)"),
        (&["--omega", "1:2:-3"], "--omega: '1:2:-3' asks for -3 points"),
        (&["--omega", "1:2:x"], "--omega: '1:2:x' has a bad number of points 'x'"),
        (&["--omega", "-1:2:3"], "--omega: '-1:2:3' has a negative start -1"),
        (&["--omega", "1:inf:3"], "--omega: '1:inf:3' has a non-finite end inf"),
        (&["--omega", "2", "--jobs", "0"], "--jobs must be at least 1, got 0"),
        (&["--omega", "2", "--ramp-time", "0"], "--ramp-time must be finite and positive, got 0"),
        (&["--omega", "2", "--ramp-time", "-5"], "--ramp-time must be finite and positive, got -5"),
        (&["--omega", "2", "--ramp-time", "2"], "--ramp-time 2 s must be shorter than --duration 1 s"),
        (
            &["--omega", "2", "--kind", "sudden", "--ramp-time", "0.5"],
            "--ramp-time applies to the kinds ramp-up",
        ),
        (&["--omega", "2", "--duration", "0"], "--duration must be finite and positive, got 0"),
        (&["--omega", "2", "--duration", "-3"], "--duration must be finite and positive, got -3"),
        (&["--omega", "2", "--duration", "inf"], "--duration must be finite and positive, got inf"),
        (&["--omega", "2", "--dim", "2"], "--dim 2: not an option of pendulum sweep: sweeps are 3D"),
        (&["--omega", "2", "--radius", "0"], "--radius must be finite and positive"),
        (&["--omega", "2", "--step", "0"], "--step must be finite and positive, got 0"),
        (&["--omega", "2", "--kind", "sideways"], "invalid value 'sideways' for '--kind"),
        (&["--omega", "2", "--gravity", "0"], "--gravity must be finite and positive for a sweep"),
        (&[], "--omega"),
        (
            &["--from", "run/run.json"],
            "is not a sweep.json of pendulum sweep: a run.json of pendulum simulate",
        ),
        (&["--from", "run/trajectory.csv"], "is not a sweep.json of pendulum sweep: not JSON"),
        (&["--from", "other.json"], "is not a sweep.json of pendulum sweep: missing field"),
        (&["--from", "missing.json"], "--from: cannot read missing.json"),
        (&["--from", "other.json", "--omega", "2"], "cannot be used with"),
    ];
    for (extra, message) in cases {
        let mut args = vec!["sweep"];
        if !extra.contains(&"--from") {
            args.extend_from_slice(&ok);
            if !extra.contains(&"--duration") {
                args.extend(["--duration", "1"]);
            }
        }
        args.extend_from_slice(extra);
        args.extend(["--out", "never"]);
        let out = run_in(&dir, &args);
        let text = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {text}");
        assert_eq!(text.lines().count(), 1, "{extra:?}: {text}");
        assert!(text.contains(message), "{extra:?}: expected '{message}' in {text}");
    }
    assert!(!dir.join("never").exists(), "a refused sweep wrote files");
}
