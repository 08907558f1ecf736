//! `pendulum atlas` on small chains (6 links, tens of seconds simulated): a row per point
//! and kind with the node counts and tip radii of `pendulum simulate` at the same
//! parameters, the map on stdout, a damping axis, Ctrl-C then `--from` giving the files of
//! one uninterrupted run (any `--jobs`), and bad inputs refused in one line.

mod common;

use std::path::{Path, PathBuf};

use common::{Table, run_in, scratch, stderr};

/// 6 links of 0.1 m and 0.1 kg (L = 0.6 m, √(g/L) = 4.04 rad/s, critical speeds 4.7,
/// 10.9 rad/s), damped so the first mode decays at ≈ 0.3 1/s.
const CHAIN: [&str; 8] = ["--n", "6", "--lengths", "0.1", "--masses", "0.1", "--damping", "0.01"];

/// Runs `pendulum atlas args… --out NAME` in `dir`; asserts success, returns the directory
/// and stdout.
fn atlas_in(dir: &Path, name: &str, args: &[&str]) -> (PathBuf, String) {
    let mut all = vec!["atlas"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--out", name, "--quiet"]);
    let out = run_in(dir, &all);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    (dir.join(name), String::from_utf8_lossy(&out.stdout).into_owned())
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn a_row_per_point_and_kind_with_the_answer_of_simulate() {
    let dir = scratch("atlas-rows");
    let mut args = CHAIN.to_vec();
    args.extend(["--omega", "3,8,12", "--radius", "0.01,0.03", "--kind", "sudden,ramp-up"]);
    args.extend(["--duration", "20", "--ramp-time", "6"]);
    let (out, stdout) = atlas_in(&dir, "a", &args);
    let csv = Table::read(&out.join("atlas.csv"));
    assert_eq!(csv.text("kind"), [["sudden"; 6], ["ramp-up"; 6]].concat());
    assert!(csv.text("status").iter().all(|s| s == "completed"), "{:?}", csv.text("status"));
    // Kind by kind, row by row of y (R), along x (ω).
    assert_eq!(csv.column("omega_rad_s")[..6], [3.0, 8.0, 12.0, 3.0, 8.0, 12.0]);
    assert_eq!(csv.column("radius_m")[..6], [0.01, 0.01, 0.01, 0.03, 0.03, 0.03]);
    assert_eq!(csv.text("ramp_time_s")[5..7], ["", "6.0"]);
    // Below the first critical speed (4.7 rad/s) 1 node, above it a sudden start finds 2.
    let nodes = csv.column("nodes");
    assert_eq!(nodes[..2], [1.0, 2.0]);
    // The map on stdout: per kind, y from the top down, a digit per settled point.
    let lines: Vec<&str> = stdout.lines().collect();
    assert!(
        lines[1].starts_with("sudden: rows R (m) from 0.03 (top) to 0.01, columns ω (rad/s) from 3 to 12")
    );
    let row = |i: usize| lines[i].split_whitespace().last().unwrap().to_string();
    let digit = |i: usize| {
        let settled = csv.text("settled")[i] == "true";
        if settled { char::from_digit(nodes[i] as u32, 10).unwrap() } else { '*' }
    };
    assert_eq!(row(3), (0..3).map(digit).collect::<String>(), "{stdout}");
    assert_eq!(row(2), (3..6).map(digit).collect::<String>(), "{stdout}");
    // The same points run by `pendulum simulate`: the same report, bit for bit.
    let json = json(&out.join("atlas.json"));
    let step = json["config"]["step"].as_f64().unwrap().to_string();
    let (tips, omega, radius) =
        (csv.column("tip_radius_m"), csv.column("omega_rad_s"), csv.column("radius_m"));
    for i in [1, 5, 10] {
        let (w, r) = (omega[i].to_string(), radius[i].to_string());
        let name = format!("run{i}");
        let mut run = vec!["simulate", "--dim", "3", "--drive", "circle", "--radius", &r, "--omega", &w];
        run.extend_from_slice(&CHAIN);
        run.extend([
            "--integrator",
            "rk4",
            "--step",
            &step,
            "--end",
            "20",
            "--initial",
            "hanging",
            "--every",
            "4",
        ]);
        run.extend(["--no-plots", "--quiet", "--out", &name]);
        if i >= 6 {
            run.extend(["--ramp-time", "6"]);
        }
        let done = run_in(&dir, &run);
        assert!(done.status.success(), "{}", stderr(&done));
        let shape = self::json(&dir.join(&name).join("shape.json"));
        assert_eq!(shape["nodes"].as_f64().unwrap(), nodes[i], "point {i}");
        assert_eq!(shape["tip_radius"].as_f64().unwrap(), tips[i], "point {i}");
    }
    assert_eq!(json["status"], "completed");
    assert_eq!(json["points"].as_array().unwrap().len(), 12);
    assert!(json["points"][0]["result"].get("wall_seconds").is_none(), "atlas.json depends on the machine");
    assert!(std::fs::read(out.join("atlas.png")).unwrap().starts_with(b"\x89PNG"));
}

#[test]
fn a_damping_axis_runs_a_chain_per_column() {
    let dir = scratch("atlas-damping");
    let mut args = CHAIN[..6].to_vec();
    args.extend(["--damping", "0.005:0.02:3", "--omega", "3,8", "--duration", "10"]);
    let (out, _) = atlas_in(&dir, "a", &args);
    let csv = Table::read(&out.join("atlas.csv"));
    assert_eq!(csv.column("damping_n_m_s"), [0.005, 0.005, 0.0125, 0.0125, 0.02, 0.02]);
    let config = json(&out.join("atlas.json"))["config"].clone();
    assert_eq!(
        (config["x"]["parameter"].as_str(), config["y"]["parameter"].as_str()),
        (Some("omega"), Some("damping"))
    );
    // Each row is the sweep of its chain.
    let mut sweep = CHAIN[..6].to_vec();
    sweep.extend([
        "--damping",
        "0.0125",
        "--omega",
        "3,8",
        "--duration",
        "10",
        "--kind",
        "sudden",
        "--quiet",
    ]);
    let step = config["step"].as_f64().unwrap().to_string();
    sweep.extend(["--step", &step, "--out", "s"]);
    let mut all = vec!["sweep"];
    all.extend(sweep);
    let done = run_in(&dir, &all);
    assert!(done.status.success(), "{}", stderr(&done));
    let s = Table::read(&dir.join("s/sweep.csv"));
    assert_eq!(s.column("tip_radius_m"), csv.column("tip_radius_m")[2..4]);
}

#[cfg(unix)]
#[test]
fn ctrl_c_then_from_gives_the_files_of_one_uninterrupted_run() {
    let dir = scratch("atlas-resume");
    let mut args = CHAIN.to_vec();
    args.extend(["--omega", "2:14:8", "--radius", "0.01:0.04:6", "--duration", "40"]);
    let (whole, _) = atlas_in(&dir, "whole", &[args.as_slice(), &["--jobs", "2"]].concat());
    // Cut after the first round (8 points with one thread), then resumed.
    let mut cut = vec!["atlas"];
    cut.extend_from_slice(&args);
    cut.extend(["--jobs", "1", "--out", "cut"]);
    let child = common::pendulum()
        .args(&cut)
        .current_dir(&dir)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let completed = |path: &Path| {
        std::fs::read_to_string(path)
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .map_or(0, |j| {
                j["points"].as_array().unwrap().iter().filter(|p| p["status"] == "completed").count()
            })
    };
    let json_path = dir.join("cut/atlas.json");
    let (out, _) = common::interrupt_when(child, || completed(&json_path) > 0);
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
    let last = stderr(&out).lines().last().unwrap_or_default().to_string();
    assert!(
        last.starts_with("error: interrupted: ") && last.contains("resume with pendulum atlas --from"),
        "{last}"
    );
    let kept = completed(&json_path);
    assert!((1..48).contains(&kept), "{kept} of 48 points completed before Ctrl-C");
    assert_eq!(json(&json_path)["status"], "interrupted");
    let map = Table::read(&dir.join("cut/atlas.csv"));
    assert_eq!(map.text("status").iter().filter(|s| *s == "pending").count(), 48 - kept);
    // Resumed: the completed points kept, the others run; the same files as one run.
    let resumed = run_in(&dir, &["atlas", "--from", "cut/atlas.json", "--out", "cut", "--jobs", "1"]);
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    assert!(stderr(&resumed).contains(&format!("{kept} kept from --from, {} to run", 48 - kept)));
    for file in ["atlas.csv", "atlas.json", "atlas.png"] {
        let (a, b) =
            (std::fs::read(whole.join(file)).unwrap(), std::fs::read(dir.join("cut").join(file)).unwrap());
        assert!(a == b, "{file} differs after resuming");
    }
    // --again runs every point again: the same files.
    let again = run_in(&dir, &["atlas", "--from", "cut/atlas.json", "--again", "--out", "again", "--quiet"]);
    assert!(again.status.success(), "{}", stderr(&again));
    assert_eq!(
        std::fs::read(whole.join("atlas.csv")).unwrap(),
        std::fs::read(dir.join("again/atlas.csv")).unwrap()
    );
}

#[test]
fn bad_inputs_are_refused_in_one_line_naming_the_value() {
    let dir = scratch("atlas-bad");
    let swept =
        run_in(&dir, &["sweep", "--n", "2", "--omega", "2", "--duration", "1", "--quiet", "--out", "s"]);
    assert!(swept.status.success(), "{}", stderr(&swept));
    let cases: &[(&[&str], &str)] = &[
        (
            &["--omega", "1,2"],
            "an atlas needs exactly two axes (two of --omega, --radius, --damping, --ramp-time",
        ),
        (
            &["--omega", "1:2:3", "--radius", "0.01,0.02", "--damping", "0:1:2"],
            "got 3 (--omega, --radius, --damping)",
        ),
        (
            &["--omega", "1,2", "--radius", "0.01,-0.02"],
            "--radius: '0.01,-0.02' has a negative entry -0.02 (radii",
        ),
        (
            &["--omega", "1,2", "--radius", "0,0.02"],
            "--radius must be finite and positive (the pivot's circle drives the chain), got 0",
        ),
        (
            &["--omega", "1,2", "--ramp-time", "1,2"],
            "--ramp-time as an axis applies to the kind ramp-up only",
        ),
        (
            &["--omega", "1,2", "--radius", "0.01,0.02", "--ramp-time", "0.5"],
            "--ramp-time applies to the kind ramp-up only",
        ),
        (
            &["--omega", "1,2", "--radius", "0.01,0.02", "--duration", "0"],
            "--duration must be finite and positive, got 0",
        ),
        (
            &["--omega", "1,2", "--radius", "0.01,0.02", "--kind", "ramp-down"],
            "invalid value 'ramp-down' for '--kind",
        ),
        (&["--omega", "1,2", "--radius", "0.01,0.02", "--jobs", "0"], "--jobs must be at least 1, got 0"),
        (&["--from", "s/sweep.json"], "is not an atlas.json of pendulum atlas: written by pendulum sweep"),
        (&["--from", "missing.json"], "--from: cannot read missing.json"),
        (&["--again"], "--from"),
    ];
    for (extra, message) in cases {
        let mut args = vec!["atlas"];
        if !extra.contains(&"--from") {
            args.extend(["--n", "2"]);
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
    assert!(!dir.join("never").exists(), "a refused atlas wrote files");
}
