//! `pendulum simulate` driven as a user would: files written, their contents, physics
//! visible in them, repeatability from run.json, interruption.

mod common;

use common::{Csv, run_in, run_json, scratch, stderr};

#[test]
fn the_demo_runs_without_options_and_says_where_its_files_went() {
    let dir = scratch("demo");
    let out = run_in(&dir, &["simulate"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let message = stderr(&out);
    assert!(message.contains("demo"), "{message}");
    assert!(message.contains("files in pendulum-run"), "{message}");
    let run = dir.join("pendulum-run");
    for file in ["trajectory.csv", "energy.csv", "run.json", "energy.png", "chain.gif"] {
        let len = std::fs::metadata(run.join(file)).map(|m| m.len()).unwrap_or(0);
        assert!(len > 100, "{file} missing or empty");
    }
    assert!(!run.join("run.json.tmp").exists());
    let gif = std::fs::read(run.join("chain.gif")).unwrap();
    assert_eq!(&gif[..6], b"GIF89a");
    let png = std::fs::read(run.join("energy.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    let json = run_json(&run);
    assert_eq!(json["outcome"]["status"], "completed");
    assert_eq!(json["version"], env!("CARGO_PKG_VERSION"));
}

#[test]
fn a_conservative_run_keeps_its_energy_and_samples_every_k_steps() {
    let dir = scratch("conservative");
    let args =
        ["simulate", "--n", "2", "--initial", "horizontal", "--end", "2", "--step", "0.01", "--every", "5"];
    let out = run_in(&dir, &[&args[..], &["--out", "run", "--no-plots"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let trajectory = Csv::read(&dir.join("run/trajectory.csv"));
    let expected =
        ["t", "theta1", "theta2", "dtheta1", "dtheta2", "pivot_x", "pivot_y", "x1", "y1", "x2", "y2"];
    assert_eq!(trajectory.header, expected);
    // 200 steps sampled at 0, 5, ..., 200: 41 rows.
    let t = trajectory.column("t");
    assert_eq!(t.len(), 41);
    assert!((t[1] - 0.05).abs() < 1e-12 && (t[40] - 2.0).abs() < 1e-12);
    let energy = Csv::read(&dir.join("run/energy.csv"));
    let h = energy.column("energy");
    // Horizontal start at rest: H = −g (m1 + m2) l1 cos θ1 − ... = 0.
    assert!(h[0].abs() < 1e-12, "H0 = {}", h[0]);
    let drift = h.iter().map(|e| e.abs()).fold(0.0, f64::max);
    assert!(drift < 1e-6, "energy drift {drift} J");
    assert!(drift > 0.0, "the energy column should carry the integration's round-off");
    assert!(energy.column("drive_work").iter().all(|&w| w == 0.0));
    assert!(!dir.join("run/chain.gif").exists(), "--no-plots draws nothing");
}

#[test]
fn positions_in_the_trajectory_match_the_angles() {
    let dir = scratch("positions");
    let args =
        ["simulate", "--masses", "1,2,0.5", "--lengths", "0.3,0.5,0.2", "--end", "0.5", "--out", "run"];
    let out = run_in(&dir, &[&args[..], &["--no-plots", "--initial", "tilted:0.4"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let tr = Csv::read(&dir.join("run/trajectory.csv"));
    let lengths = [0.3, 0.5, 0.2];
    for row in 0..tr.rows.len() {
        let (mut x, mut y) = (0.0, 0.0);
        for (i, l) in lengths.iter().enumerate() {
            let theta = tr.column(&format!("theta{}", i + 1))[row];
            x += l * theta.sin();
            y -= l * theta.cos();
            assert!((tr.column(&format!("x{}", i + 1))[row] - x).abs() < 1e-12);
            assert!((tr.column(&format!("y{}", i + 1))[row] - y).abs() < 1e-12);
        }
    }
}

#[test]
fn a_small_swing_has_the_period_of_the_simple_pendulum() {
    // One link of l = 0.5 m from 0.05 rad: T = 2π √(l/g) (1 + θ0²/16) = 1.41857 s.
    let dir = scratch("period");
    let args = ["simulate", "--n", "1", "--initial", "tilted:0.05", "--end", "3", "--step", "0.002"];
    let out = run_in(&dir, &[&args[..], &["--every", "1", "--out", "run", "--no-plots"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let tr = Csv::read(&dir.join("run/trajectory.csv"));
    let (t, theta) = (tr.column("t"), tr.column("theta1"));
    // Downward zero crossings of θ, interpolated.
    let crossings: Vec<f64> = (1..t.len())
        .filter(|&i| theta[i - 1] > 0.0 && theta[i] <= 0.0)
        .map(|i| t[i - 1] + (t[i] - t[i - 1]) * theta[i - 1] / (theta[i - 1] - theta[i]))
        .collect();
    assert!(crossings.len() >= 2, "{crossings:?}");
    let period = crossings[1] - crossings[0];
    let expected = 2.0 * std::f64::consts::PI * (0.5_f64 / 9.81).sqrt() * (1.0 + 0.05_f64.powi(2) / 16.0);
    assert!((period - expected).abs() < 1e-4, "period {period} s, expected {expected} s");
}

#[test]
fn from_run_json_repeats_the_run_exactly() {
    let dir = scratch("repeat");
    let args = [
        "simulate",
        "--n",
        "3",
        "--masses",
        "1,0.5,2",
        "--damping",
        "0.05",
        "--torque",
        "0.1,0,-0.2",
        "--drive",
        "harmonic",
        "--direction",
        "1,1",
        "--amplitude",
        "0.02",
        "--omega",
        "15",
        "--integrator",
        "gl3",
        "--solver",
        "newton",
        "--end",
        "0.6",
        "--step",
        "0.004",
        "--every",
        "3",
        "--out",
        "first",
        "--no-plots",
    ];
    let out = run_in(&dir, &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = run_in(&dir, &["simulate", "--from", "first/run.json", "--out", "second", "--no-plots"]);
    assert!(out.status.success(), "{}", stderr(&out));
    for file in ["trajectory.csv", "energy.csv"] {
        let a = std::fs::read(dir.join("first").join(file)).unwrap();
        let b = std::fs::read(dir.join("second").join(file)).unwrap();
        assert!(a == b, "{file} differs between the run and its repetition");
    }
    let (a, b) = (run_json(&dir.join("first")), run_json(&dir.join("second")));
    assert_eq!(a["config"], b["config"]);
    // The picture may be drawn differently; the physics stays.
    let out = run_in(&dir, &["simulate", "--from", "first/run.json", "--out", "third", "--frames", "5"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(std::fs::read(dir.join("third/chain.gif")).unwrap().starts_with(b"GIF89a"));
    let c = run_json(&dir.join("third"));
    assert_eq!(c["config"]["frames"], 5);
    assert_eq!(c["config"]["masses"], a["config"]["masses"]);
    assert_eq!(a["config"]["integrator"], "gl3");
    assert_eq!(a["config"]["solver"], "newton");
    assert_eq!(a["config"]["drive"]["kind"], "harmonic");
}

#[test]
fn the_energy_ledger_closes_for_a_driven_damped_run() {
    // The program's ledger against one rebuilt here from the trajectory alone: H from the
    // angles, rates and the drive's ṗ = A ω cos(ωt) ŷ; the torque work Σ σ Δθ_i exactly
    // (constant torques); the dissipated energy ∫ Σ λ θ̇_i² dt by the trapezoidal rule.
    // What is left of H(T) − H(0) is the drive's work, which the program's must match.
    let dir = scratch("ledger");
    let (m, l, g, lambda, sigma, amplitude, omega) = (1.0, 0.5, 9.81, 0.1, 0.3, 0.05, 12.0);
    let args = [
        "simulate",
        "--n",
        "2",
        "--damping",
        "0.1",
        "--torque",
        "0.3",
        "--drive",
        "harmonic",
        "--amplitude",
        "0.05",
        "--omega",
        "12",
        "--end",
        "2",
        "--step",
        "0.002",
        "--every",
        "1",
        "--out",
        "run",
        "--no-plots",
    ];
    let out = run_in(&dir, &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let e = Csv::read(&dir.join("run/energy.csv"));
    let tr = Csv::read(&dir.join("run/trajectory.csv"));
    let (t, th1, th2, w1, w2) = (
        tr.column("t"),
        tr.column("theta1"),
        tr.column("theta2"),
        tr.column("dtheta1"),
        tr.column("dtheta2"),
    );
    assert_eq!(t.len(), 1001);
    let energy = |k: usize| {
        let pivot_y = amplitude * (omega * t[k]).sin();
        let pivot_vy = amplitude * omega * (omega * t[k]).cos();
        let (v1, y1) =
            ([l * th1[k].cos() * w1[k], pivot_vy + l * th1[k].sin() * w1[k]], pivot_y - l * th1[k].cos());
        let (v2, y2) =
            ([v1[0] + l * th2[k].cos() * w2[k], v1[1] + l * th2[k].sin() * w2[k]], y1 - l * th2[k].cos());
        0.5 * m * (v1[0] * v1[0] + v1[1] * v1[1] + v2[0] * v2[0] + v2[1] * v2[1]) + m * g * (y1 + y2)
    };
    let h = e.column("energy");
    for k in 0..t.len() {
        assert!(
            (h[k] - energy(k)).abs() < 1e-12 * (1.0 + h[k].abs()),
            "t = {}: H {} against {}",
            t[k],
            h[k],
            energy(k)
        );
    }
    let last = t.len() - 1;
    let torque_work = sigma * (th1[last] - th1[0] + th2[last] - th2[0]);
    let damping_power: Vec<f64> = (0..t.len()).map(|k| lambda * (w1[k] * w1[k] + w2[k] * w2[k])).collect();
    let damped: f64 =
        (1..t.len()).map(|k| 0.5 * (damping_power[k] + damping_power[k - 1]) * (t[k] - t[k - 1])).sum();
    let drive_work = energy(last) - energy(0) - torque_work + damped;
    let (their_drive, their_torque, their_damped) =
        (e.column("drive_work")[last], e.column("torque_work")[last], e.column("damped")[last]);
    assert!(
        drive_work.abs() > 1e-2 && torque_work.abs() > 1e-3 && damped > 1e-2,
        "{drive_work} {torque_work} {damped}"
    );
    assert!(
        (their_torque - torque_work).abs() < 1e-9 * torque_work.abs(),
        "torque work {their_torque} against {torque_work}"
    );
    // The trapezoidal rule erred by 4e-7 relative here (7.8e-7 J); bound 25× above that.
    assert!((their_damped - damped).abs() < 1e-5 * damped, "dissipated {their_damped} against {damped}");
    assert!(
        (their_drive - drive_work).abs() < 1e-5 * damped,
        "drive work {their_drive} against {drive_work} (H(T) − H(0) − W_torque + E_damped)"
    );
    println!(
        "drive work {their_drive} J against {drive_work} J rebuilt (difference {:.1e} J); dissipated {their_damped} J against {damped} J",
        their_drive - drive_work
    );
    let residual = e.column("balance_residual");
    let worst = residual.iter().map(|r| r.abs()).fold(0.0, f64::max);
    assert!(worst < 1e-8 * (1.0 + (h[last] - h[0]).abs()), "balance residual {worst} J");
}

#[test]
fn a_spatial_chain_swings_on_a_circling_pivot() {
    let dir = scratch("spatial");
    let args = [
        "simulate",
        "--dim",
        "3",
        "--n",
        "2",
        "--initial",
        "tilted:0.6",
        "--spin",
        "2",
        "--drive",
        "circle",
        "--radius",
        "0.05",
        "--omega",
        "4",
        "--end",
        "1",
        "--step",
        "0.005",
        "--view",
        "xy",
        "--frames",
        "10",
        "--out",
        "run",
    ];
    let out = run_in(&dir, &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let tr = Csv::read(&dir.join("run/trajectory.csv"));
    assert_eq!(&tr.header[1..7], ["u1_x", "u1_y", "u1_z", "u2_x", "u2_y", "u2_z"]);
    assert!(tr.header.ends_with(&["x2".into(), "y2".into(), "z2".into()]));
    let (px, py) = (tr.column("pivot_x"), tr.column("pivot_y"));
    assert!(px.iter().zip(&py).all(|(x, y)| ((x * x + y * y).sqrt() - 0.05).abs() < 1e-12));
    let residual = Csv::read(&dir.join("run/energy.csv")).column("balance_residual");
    assert!(residual.iter().all(|r| r.abs() < 1e-7), "{residual:?}");
    assert!(dir.join("run/chain.gif").exists());
}

#[test]
fn a_hanging_3d_chain_is_swung_out_by_a_circling_pivot_with_rigid_rods() {
    let dir = scratch("hanging3d");
    let args = [
        "simulate",
        "--dim",
        "3",
        "--n",
        "4",
        "--lengths",
        "0.25",
        "--initial",
        "hanging",
        "--drive",
        "circle",
        "--radius",
        "0.1",
        "--omega",
        "5",
        "--end",
        "3",
        "--step",
        "0.002",
        "--out",
        "run",
        "--no-plots",
    ];
    let out = run_in(&dir, &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let config = &run_json(&dir.join("run"))["config"];
    // Driven in 3D without --integrator: the implicit midpoint step, and run.json says why.
    assert_eq!(config["integrator"], "midpoint");
    let chosen = config["chosen"].as_str().unwrap();
    assert!(chosen.starts_with("integrator midpoint: a driven 3D chain"), "{chosen}");
    assert!(chosen.contains("every 3 steps: about 500 samples"), "{chosen}");
    let tr = Csv::read(&dir.join("run/trajectory.csv"));
    let first = &tr.rows[0];
    assert_eq!(&first[1..4], &[0.0, 0.0, -1.0], "u1 hangs straight down");
    // Rods stay rigid: consecutive masses (and pivot to mass 1) 0.25 m apart.
    let point = |prefix: &str, suffix: &str| -> [Vec<f64>; 3] {
        ["x", "y", "z"].map(|a| tr.column(&format!("{prefix}{a}{suffix}")))
    };
    let mut chain = vec![point("pivot_", "")];
    chain.extend((1..=4).map(|i| point("", &i.to_string())));
    for (i, rod) in chain.windows(2).enumerate() {
        let length =
            |row: usize| (0..3).map(|k| (rod[1][k][row] - rod[0][k][row]).powi(2)).sum::<f64>().sqrt();
        let worst = (0..tr.rows.len()).map(|row| (length(row) - 0.25).abs()).fold(0.0, f64::max);
        assert!(worst < 1e-9, "rod {} deviates from 0.25 m by {worst} m", i + 1);
    }
    let tip = &chain[4];
    let widest = tip[0].iter().zip(&tip[1]).map(|(x, y)| x.hypot(*y)).fold(0.0, f64::max);
    assert!(widest > 0.2, "the tip should be swung out, got {widest} m");
    let residual = Csv::read(&dir.join("run/energy.csv")).column("balance_residual");
    assert!(
        residual.iter().all(|r| r.abs() < 1e-8),
        "{:?}",
        residual.iter().map(|r| r.abs()).fold(0.0, f64::max)
    );
}

/// The error-controlled explicit pair and the implicit step on the same driven, damped 3D
/// run: both close the ledger, keep the rods, and land on the same chain; run.json says
/// what each integrator did.
#[test]
fn dp54_and_midpoint_agree_on_a_whirl_and_close_the_ledger() {
    let dir = scratch("dp54-midpoint");
    let base = [
        "simulate",
        "--dim",
        "3",
        "--n",
        "6",
        "--lengths",
        "0.1",
        "--masses",
        "0.1",
        "--damping",
        "1e-3",
        "--initial",
        "hanging",
        "--drive",
        "circle",
        "--radius",
        "0.05",
        "--omega",
        "5",
        "--end",
        "4",
        "--no-plots",
        "--quiet",
    ];
    let mut tips = Vec::new();
    for (name, extra) in [
        ("dp", &["--integrator", "dp54", "--tolerance", "1e-10", "--step", "0.01"][..]),
        ("mid", &["--integrator", "midpoint", "--step", "0.0005"][..]),
    ] {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        args.extend(["--out", name]);
        let out = run_in(&dir, &args);
        assert!(out.status.success(), "{}", stderr(&out));
        let residual = Csv::read(&dir.join(name).join("energy.csv")).column("balance_residual");
        let worst = residual.iter().map(|r| r.abs()).fold(0.0, f64::max);
        assert!(worst < 1e-9, "{name}: {worst:e}");
        let work = &run_json(&dir.join(name))["outcome"]["work"];
        assert!(work["rhs_evaluations"].as_u64().unwrap() > 0, "{work}");
        if name == "dp" {
            assert!(work["steps"].as_u64().unwrap() > 400, "adaptive steps inside the 400 asked for: {work}");
        } else {
            assert!(work["newton_iterations"].as_u64().unwrap() >= 8000, "{work}");
        }
        let tr = Csv::read(&dir.join(name).join("trajectory.csv"));
        let last = tr.rows.len() - 1;
        tips.push(["x6", "y6", "z6"].map(|a| tr.column(a)[last]));
    }
    let gap = (0..3).map(|k| (tips[0][k] - tips[1][k]).powi(2)).sum::<f64>().sqrt();
    // The midpoint rule's error at h = 0.5 ms is of order (hω)² ~ 1e-5 of the motion.
    assert!(gap < 1e-4, "tips {tips:?} {gap:e} m apart");
}

#[test]
fn an_initial_state_file_is_read() {
    let dir = scratch("initial-file");
    std::fs::write(dir.join("state.txt"), "# theta1 theta2\n0.1, -0.2\n# rates\n1.5 0\n").unwrap();
    let args =
        ["simulate", "--n", "2", "--initial", "state.txt", "--end", "0.01", "--out", "run", "--no-plots"];
    let out = run_in(&dir, &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let row = &Csv::read(&dir.join("run/trajectory.csv")).rows[0];
    assert_eq!(&row[..5], &[0.0, 0.1, -0.2, 1.5, 0.0]);
    std::fs::write(dir.join("short.txt"), "0.1 0.2 0.3").unwrap();
    let out = run_in(&dir, &["simulate", "--n", "2", "--initial", "short.txt", "--out", "run2"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("holds 3 numbers, expected 4"), "{}", stderr(&out));
}

#[cfg(unix)]
#[test]
fn ctrl_c_leaves_valid_files_for_what_was_computed() {
    use std::time::{Duration, Instant};
    let dir = scratch("interrupt");
    // A run far longer than the test: only the interruption can end it in time.
    let child = common::pendulum()
        .args(["simulate", "--n", "3", "--end", "100000", "--step", "0.01", "--every", "4", "--out", "run"])
        .args(["--frames", "20"])
        .current_dir(&dir)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while std::fs::metadata(dir.join("run/energy.csv")).map(|m| m.len()).unwrap_or(0) < 10_000 {
        assert!(start.elapsed() < Duration::from_secs(20), "the run never started writing");
        std::thread::sleep(Duration::from_millis(50));
    }
    let pid = child.id().to_string();
    // The shell's kill builtin: present wherever `sh` is.
    let killed = std::process::Command::new("sh").args(["-c", &format!("kill -INT {pid}")]).status().unwrap();
    assert!(killed.success());
    let out = child.wait_with_output().unwrap();
    // Exit status 130 (the convention after Ctrl-C), a message that says the run was cut.
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
    assert!(stderr(&out).contains("interrupted: the run was cut at t = "), "{}", stderr(&out));
    let run = dir.join("run");
    let json = run_json(&run);
    assert_eq!(json["outcome"]["status"], "interrupted");
    let t_end = json["outcome"]["t"].as_f64().unwrap();
    assert!(t_end > 0.0 && t_end < 100000.0);
    let trajectory = Csv::read(&run.join("trajectory.csv"));
    let energy = Csv::read(&run.join("energy.csv"));
    assert_eq!(trajectory.rows.len() as u64, json["outcome"]["samples"].as_u64().unwrap());
    assert_eq!(energy.rows.len(), trajectory.rows.len());
    assert!((trajectory.column("t").last().unwrap() - t_end).abs() < 1e-9);
    assert!(std::fs::read(run.join("chain.gif")).unwrap().starts_with(b"GIF89a"));
}

#[test]
fn a_straight_chain_of_many_links_runs_with_the_defaults() {
    // Regression: Newton's stage solve failed from exactly straight chains of > 5 links
    // (increments shrinking for ever below round-off were not taken as converged).
    for solver in ["fixed-point", "newton"] {
        let dir = scratch(&format!("straight-many-{solver}"));
        let args = ["simulate", "--n", "20", "--lengths", "0.05", "--initial", "tilted:1.0", "--end", "0.3"];
        let more = ["--step", "0.002", "--solver", solver, "--out", "run", "--no-plots"];
        let out = run_in(&dir, &[&args[..], &more[..]].concat());
        assert!(out.status.success(), "{solver}: {}", stderr(&out));
        let residual = Csv::read(&dir.join("run/energy.csv")).column("balance_residual");
        let worst = residual.iter().map(|r| r.abs()).fold(0.0, f64::max);
        assert!(worst < 1e-6, "{solver}: energy error {worst} J");
    }
}

#[test]
fn a_run_that_fails_exits_1_with_valid_files_and_says_why() {
    // A step far longer than the fastest period of 30 links of 2 cm: the stage solve fails.
    let dir = scratch("failed-run");
    let args = ["simulate", "--n", "30", "--lengths", "0.02", "--end", "1", "--step", "0.05", "--out", "run"];
    let out = run_in(&dir, &args);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let message = stderr(&out);
    // The likely cause, named, and a step to try that resolves the fastest mode: 30 links
    // of 2 cm hang with a fastest mode near 2·30·√(g/0.6) ≈ 240 rad/s.
    assert!(message.contains("likely too long for the chain's fastest mode"), "{message}");
    let suggested: f64 =
        message.split("try --step ").nth(1).unwrap().split(',').next().unwrap().parse().unwrap();
    assert!(suggested > 1e-3 && suggested < 3e-3, "{message}");
    let json = run_json(&dir.join("run"));
    assert_eq!(json["outcome"]["status"], "failed");
    assert!(json["outcome"]["error"].as_str().unwrap().contains("did not converge"));
    let trajectory = Csv::read(&dir.join("run/trajectory.csv"));
    assert_eq!(trajectory.rows.len(), 1, "the initial state only");
    assert!(std::fs::read(dir.join("run/chain.gif")).unwrap().starts_with(b"GIF89a"));
}

#[test]
fn a_run_that_blows_up_stops_there_with_valid_files_and_new_advice() {
    // Issue 34: RK4 at 80 ms on the README's 100-link whirl reaches infinite energy at
    // t = 0.24 s; the energy plot's axis search then looped for ever, deaf to Ctrl-C, and
    // the advice named the integrator already in use.
    let dir = scratch("blow-up");
    let whirl = ["--dim", "3", "--n", "100", "--masses", "0.01", "--lengths", "0.01", "--damping", "3e-4"];
    let drive = ["--initial", "hanging", "--drive", "circle", "--radius", "0.02", "--omega", "6"];
    let run = ["--integrator", "rk4", "--step", "0.08", "--every", "1", "--end", "5", "--out", "run"];
    let out = common::run_within(&dir, &[&["simulate"][..], &whirl, &drive, &run].concat(), 10);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let message = stderr(&out);
    let last = message.lines().last().unwrap();
    assert!(last.starts_with("error: the energy reached inf J at t = 0.238"), "{last}");
    assert!(last.contains("try --step 7.7e-4)"), "{last}");
    assert!(!last.contains("--integrator"), "{last}");
    let json = run_json(&dir.join("run"));
    assert_eq!(json["outcome"]["status"], "failed");
    assert!(json["outcome"]["error"].as_str().unwrap().contains("the run blew up"));
    // The samples up to the blow-up, the last one infinite; the pictures drawn.
    let energy = Csv::read(&dir.join("run/energy.csv")).column("energy");
    assert_eq!(energy.len(), 4);
    assert!(energy[..3].iter().all(|e| e.is_finite()) && energy[3] == f64::INFINITY);
    assert!(std::fs::read(dir.join("run/energy.png")).unwrap().starts_with(b"\x89PNG"));
    assert!(std::fs::read(dir.join("run/chain.gif")).unwrap().starts_with(b"GIF89a"));
    // A failed run has no shape to report.
    assert!(!dir.join("run/shape.json").exists());
}

#[test]
fn a_million_links_with_the_defaults_is_refused_at_once_with_what_to_give() {
    // Issue 34: the default sampling took every step, and trajectory.csv reached 1.76 GB
    // after 26 of 178 steps with nothing on the terminal.
    let dir = scratch("million-links");
    let out = common::run_within(&dir, &["simulate", "--n", "1000000", "--end", "0.01", "--out", "run"], 60);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let message = stderr(&out);
    assert!(message.contains("one sample of trajectory.csv takes about 80 MB"), "{message}");
    assert!(message.contains("give --every 178 to write those two (about 160 MB)"), "{message}");
    assert!(!dir.join("run").exists(), "nothing written");
}

#[cfg(unix)]
#[test]
fn a_long_run_reports_progress_within_seconds_however_sparse_its_samples() {
    use std::io::{BufRead, BufReader};
    use std::time::{Duration, Instant};
    // 100,000 links: about 0.15 s a step, and one sample at each end of 0.05 s.
    let dir = scratch("early-progress");
    let mut child = common::pendulum()
        .args(["simulate", "--n", "100000", "--end", "0.05", "--every", "1000", "--no-plots", "--out", "run"])
        .current_dir(&dir)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    // After the header line that names the chain, the first progress line.
    let first = BufReader::new(child.stderr.take().unwrap())
        .lines()
        .map(Result::unwrap)
        .find(|line| !line.starts_with("pendulum: 2D, 100000 links"))
        .unwrap();
    let took = start.elapsed();
    let _ = child.kill();
    let _ = child.wait();
    assert!(first.starts_with("pendulum: t = ") && first.contains("s to go"), "{first}");
    assert!(took < Duration::from_secs(5), "the first progress line came after {took:?}");
}

#[test]
fn a_run_whose_energy_balance_is_off_says_so_and_a_good_one_does_not() {
    // Issue 34: RK4 at 0.2 s "completed" with exit 0 and an energy-balance error of 3.8 J
    // (13 % of the triple pendulum's energy scale), said nowhere.
    let dir = scratch("balance-off");
    let out =
        run_in(&dir, &["simulate", "--integrator", "rk4", "--step", "0.2", "--end", "20", "--out", "off"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let message = stderr(&out);
    assert!(
        message.contains(
            "pendulum: warning: the energy balance is off by 3.806e0 J, 12.9 % of the run's energy scale"
        ),
        "{message}"
    );
    assert!(message.contains("max |H − H0 − W| = 3.806e0 J (12.9 % of the energy scale: off)"), "{message}");
    let outcome = &run_json(&dir.join("off"))["outcome"];
    assert!((outcome["balance"]["residual"].as_f64().unwrap() - 3.806).abs() < 1e-3);
    assert!(outcome["warnings"][0].as_str().unwrap().starts_with("the energy balance is off"));
    // The default step keeps the balance at round-off: nothing to say.
    let out = run_in(&dir, &["simulate", "--end", "20", "--out", "good"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("warning"), "{}", stderr(&out));
    let outcome = &run_json(&dir.join("good"))["outcome"];
    assert!(
        outcome["balance"]["residual"].as_f64().unwrap()
            < 1e-6 * outcome["balance"]["scale"].as_f64().unwrap()
    );
    assert!(outcome.get("warnings").is_none());
}

#[test]
fn from_with_a_chain_option_names_only_the_option_given() {
    // Issue 34: `--from X --n 5` listed some 25 options that conflict with --from.
    let dir = scratch("from-conflict");
    let out = run_in(&dir, &["simulate", "--from", "run.json", "--n", "5", "--omega=3"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr(&out).trim(),
        "error: the argument '--from <RUN_JSON>' cannot be used with --n <N>, --omega <OMEGA>"
    );
}

#[test]
fn a_pivot_on_samples_of_a_circle_whirls_the_chain_as_the_circle_does_and_repeats_without_the_file() {
    let dir = scratch("sampled");
    // The circle R = 2 cm, ω = 7 rad/s sampled at 100 Hz (about 90 samples a turn) from
    // −0.5 s to 2.5 s: the natural spline's ends (p̈ = 0 there, not the circle's) stay
    // outside the run.
    let rows: String = (-50..=250)
        .map(|k| {
            let t = k as f64 * 0.01;
            format!("{t:?}, {:?}, {:?}, 0\n", 0.02 * (7.0 * t).cos(), 0.02 * (7.0 * t).sin())
        })
        .collect();
    std::fs::write(dir.join("circle.txt"), format!("# t, x, y, z\n{rows}")).unwrap();
    let common = ["simulate", "--dim", "3", "--n", "3", "--initial", "hanging", "--end", "2", "--no-plots"];
    let fixed = ["--integrator", "rk4", "--step", "0.001", "--every", "100"];
    let sampled = ["--drive", "sampled", "--path", "circle.txt"];
    let circle = ["--drive", "circle", "--radius", "0.02", "--omega", "7"];
    for (drive, out) in [(&sampled[..], "sampled"), (&circle[..], "circle")] {
        let run = run_in(&dir, &[&common[..], &fixed[..], drive, &["--out", out]].concat());
        assert!(run.status.success(), "{}", stderr(&run));
    }
    let (a, b) =
        (Csv::read(&dir.join("sampled/trajectory.csv")), Csv::read(&dir.join("circle/trajectory.csv")));
    let worst = ["u3_x", "u3_y", "u3_z", "pivot_x", "pivot_y"]
        .iter()
        .flat_map(|c| a.column(c).into_iter().zip(b.column(c)).map(|(x, y)| (x - y).abs()))
        .fold(0.0, f64::max);
    let swung = a.column("u3_x").iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    assert!(swung > 0.05 && worst < 1e-6, "swung {swung}, off by {worst}");
    let json = run_json(&dir.join("sampled"));
    assert_eq!(json["config"]["drive"]["kind"], "sampled");
    assert_eq!(json["config"]["drive"]["times"].as_array().unwrap().len(), 301);
    // The defaults: the midpoint step, at half the samples' spacing, its ledger closed.
    let run = run_in(&dir, &[&common[..], &sampled[..], &["--out", "chosen"]].concat());
    assert!(run.status.success(), "{}", stderr(&run));
    let chosen = run_json(&dir.join("chosen"));
    assert_eq!(chosen["config"]["integrator"], "midpoint");
    assert!(
        (chosen["config"]["step"].as_f64().unwrap() - 0.005).abs() < 1e-12,
        "{}",
        chosen["config"]["step"]
    );
    let residual = Csv::read(&dir.join("chosen/energy.csv")).column("balance_residual");
    assert!(residual.iter().all(|r| r.abs() < 1e-9), "{residual:?}");
    // run.json holds the samples: the run repeats with the file gone.
    std::fs::remove_file(dir.join("circle.txt")).unwrap();
    let run = run_in(&dir, &["simulate", "--from", "sampled/run.json", "--out", "again", "--no-plots"]);
    assert!(run.status.success(), "{}", stderr(&run));
    let again = std::fs::read(dir.join("again/trajectory.csv")).unwrap();
    assert!(again == std::fs::read(dir.join("sampled/trajectory.csv")).unwrap());
    // A file that is not rows of t and the position is named.
    std::fs::write(dir.join("bad.txt"), "0 0 0\n1 0 0\n").unwrap();
    let run = run_in(&dir, &[&common[..], &["--drive", "sampled", "--path", "bad.txt"]].concat());
    assert_eq!(run.status.code(), Some(2), "{}", stderr(&run));
    assert!(stderr(&run).contains("bad.txt holds 6 numbers, not rows of 4"), "{}", stderr(&run));
}
