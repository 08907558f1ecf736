//! `pendulum simulate` of a whirled chain answers in its own terms: the node count, tip
//! radius, whether it settled and the nearest damped steady shape with its stability, on
//! stdout and in shape.json and shape.png; speed ramps; bad ramp parameters.

mod common;

use common::{run_in, scratch, stderr};

fn stdout(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A uniform 3D chain of 8 links (L = 1 m, M = 1 kg) hanging at rest, its pivot on a 2 cm
/// circle: with the damping heavy enough to settle in a minute, a sudden start between the
/// first two critical speeds (about 3.4 and 7.7 rad/s for n = 8) ends in the 1-node shape,
/// one between the second and third in the 2-node shape.
fn whirl(dir: &std::path::Path, omega: &str, extra: &[&str]) -> std::process::Output {
    let args = [
        "simulate",
        "--dim",
        "3",
        "--n",
        "8",
        "--masses",
        "0.125",
        "--lengths",
        "0.125",
        "--damping",
        "2e-2",
        "--initial",
        "hanging",
        "--drive",
        "circle",
        "--radius",
        "0.02",
        "--omega",
        omega,
        "--integrator",
        "rk4",
        "--step",
        "0.002",
        "--end",
        "60",
        "--every",
        "25",
        "--out",
        "run",
    ];
    run_in(dir, &[&args[..], extra].concat())
}

#[test]
fn a_sudden_whirl_reports_its_nodes_settled_and_the_stable_steady_shape() {
    for (omega, nodes) in [("3", 1), ("6", 2)] {
        let dir = scratch(&format!("whirl-{omega}"));
        let out = whirl(&dir, omega, &[]);
        assert!(out.status.success(), "{}", stderr(&out));
        let line = stdout(&out);
        let expected = format!("rad/s: {nodes} node");
        assert!(line.contains(&expected), "{line}");
        assert!(line.contains(", settled (drift"), "{line}");
        assert!(
            line.contains(&format!("away: {nodes} node")) && line.contains("stable (largest growth rate -"),
            "{line}"
        );

        let shape: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("run/shape.json")).unwrap()).unwrap();
        assert_eq!(shape["nodes"], nodes);
        assert_eq!(shape["axis_crossings"], nodes - 1);
        assert_eq!(shape["settled"], true);
        assert!(shape["drift"].as_f64().unwrap() <= 1e-3, "{shape}");
        assert_eq!(shape["nearest"]["found"], true);
        assert_eq!(shape["nearest"]["nodes"], nodes);
        assert_eq!(shape["nearest"]["stable"], true);
        // Settled onto the damped steady shape: within 1e-3 L of it.
        assert!(shape["nearest"]["distance"].as_f64().unwrap() < 1e-3, "{shape}");
        assert!(shape["tip_radius"].as_f64().unwrap() > 0.02, "{shape}");
        assert_eq!(shape["shape"]["radial"].as_array().unwrap().len(), 8);
        let png = std::fs::read(dir.join("run/shape.png")).unwrap();
        assert!(png.starts_with(b"\x89PNG"));
    }
}

#[test]
fn a_ramp_is_recorded_and_a_short_run_is_not_called_settled() {
    let dir = scratch("whirl-ramp");
    let args = [
        "simulate",
        "--dim",
        "3",
        "--n",
        "4",
        "--initial",
        "hanging",
        "--drive",
        "circle",
        "--radius",
        "0.02",
        "--omega",
        "5",
        "--ramp-time",
        "0.5",
        "--ramp-from",
        "1",
        "--integrator",
        "rk4",
        "--step",
        "0.002",
        "--end",
        "1",
        "--out",
        "run",
        "--no-plots",
    ];
    let out = run_in(&dir, &args);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stdout(&out).contains("not settled (the run is shorter than"), "{}", stdout(&out));
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run/run.json")).unwrap()).unwrap();
    let ramp = &run["config"]["drive"];
    assert_eq!(ramp["kind"], "rampedcircle", "{run}");
    assert_eq!(ramp["initial_omega"], 1.0);
    assert_eq!(ramp["omega"], 5.0);
    assert_eq!(ramp["duration"], 0.5);
    // The ramp's work enters the ledger like any drive's. While the speed ramps, the
    // balance closes to RK4's error; the step that ends at the ramp's end (t = 0.5 s) sees
    // the jump of p̈ = R φ̈ (the speed's kink) in its last stage, an error of first order in
    // h there, so afterwards the residual is larger, but still a small part of the work.
    let energy = common::Csv::read(&dir.join("run/energy.csv"));
    let (t, residual) = (energy.column("t"), energy.column("balance_residual"));
    let work = energy.column("drive_work").iter().map(|w| w.abs()).fold(0.0, f64::max);
    let worst = |ramp: bool| {
        t.iter()
            .zip(&residual)
            .filter(|(t, _)| (**t < 0.5 - 1e-9) == ramp)
            .map(|(_, r)| r.abs())
            .fold(0.0, f64::max)
    };
    assert!(work > 1e-2, "drive work {work} J");
    assert!(worst(true) < 1e-8 * work, "during the ramp: residual {} J, work {work} J", worst(true));
    assert!(worst(false) < 3e-4 * work, "after the ramp: residual {} J, work {work} J", worst(false));
    assert!(!dir.join("run/shape.png").exists());
}

#[test]
fn bad_ramps_are_one_line_errors() {
    let dir = scratch("whirl-bad-ramps");
    let base = ["simulate", "--dim", "3", "--n", "3", "--drive", "circle", "--end", "0.1"];
    for (extra, expected) in [
        (vec!["--ramp-time", "0"], "ramp duration must be finite and positive, got 0"),
        (vec!["--ramp-time", "-2"], "ramp duration must be finite and positive, got -2"),
        (vec!["--ramp-from", "2"], "--ramp-from needs --ramp-time"),
    ] {
        let out = run_in(&dir, &[&base[..], &extra[..]].concat());
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {}", stderr(&out));
        let message = stderr(&out);
        assert_eq!(message.lines().count(), 1, "{message}");
        assert!(message.contains(expected), "{extra:?}: {message}");
    }
    let out = run_in(&dir, &["simulate", "--drive", "harmonic", "--ramp-time", "1", "--end", "0.1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("--ramp-time and --ramp-from apply to --drive circle only"),
        "{}",
        stderr(&out)
    );
}

/// Writing a sample of a 2D chain costs O(n): four times the links take about four times
/// as long per written sample, not sixteen (the dense kinetic energy was O(n²)). Best of
/// three runs each, every step written; the bound 8 sits between linear (4) and
/// quadratic (16).
#[test]
fn a_written_2d_sample_costs_time_linear_in_n() {
    let dir = scratch("whirl-linear-samples");
    let time = |n: usize| {
        (0..3)
            .map(|_| {
                let n = n.to_string();
                let args = [
                    "simulate",
                    "--n",
                    &n,
                    "--initial",
                    "tilted:0.3",
                    "--integrator",
                    "rk4",
                    "--step",
                    "1e-6",
                    "--end",
                    "4e-6",
                    "--every",
                    "1",
                    "--no-plots",
                    "--quiet",
                    "--out",
                    "run",
                ];
                let start = std::time::Instant::now();
                let out = run_in(&dir, &args);
                assert!(out.status.success(), "{}", stderr(&out));
                start.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min)
    };
    let (small, large) = (time(25_000), time(100_000));
    assert!(
        large / small < 8.0,
        "n = 25000: {small:.3} s, n = 100000: {large:.3} s: ratio {:.1}",
        large / small
    );
}

#[test]
fn the_default_whirl_is_drawn_co_rotating_and_warns_about_nothing() {
    // Issue 34: with the defaults, 300 s of whirl at 6 rad/s got about 500 samples, 1.8
    // per drive period, and the side-view GIF warned the user to change --step.
    let dir = scratch("default-whirl-view");
    let whirl = [&["simulate"][..], &common::WHIRL_20, &["--end", "300"]].concat();
    let out = run_in(&dir, &[&whirl[..], &["--out", "run"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let message = stderr(&out);
    assert!(!message.contains("warning"), "{message}");
    assert!(
        message.contains("run/chain.gif: ") && message.contains(", co-rotating side view x'–z"),
        "{message}"
    );
    assert_eq!(common::run_json(&dir.join("run"))["config"]["view"], "co-rotating");
    // A side view asked for still warns: the samples are too far apart for it.
    let out = run_in(&dir, &[&whirl[..], &["--view", "xz", "--out", "side"]].concat());
    assert!(stderr(&out).contains("the drive may look aliased"), "{}", stderr(&out));
    // The co-rotating view needs a pivot on a circle.
    let out = run_in(&dir, &["simulate", "--dim", "3", "--view", "co-rotating", "--out", "bad"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr(&out).trim(),
        "error: --view co-rotating needs a 3D chain whose pivot circles (--dim 3 --drive circle)"
    );
}

#[test]
fn a_growth_rate_within_round_off_is_reported_as_zero_with_its_bound() {
    // Issue 34: an undamped whirl's nearest steady shape was "stable (+9.97e-16 1/s)".
    let dir = scratch("round-off-rate");
    let args = ["simulate", "--dim", "3", "--n", "3", "--initial", "hanging", "--drive", "circle"];
    let out = run_in(
        &dir,
        &[&args[..], &["--radius", "0.02", "--omega", "2", "--end", "20", "--out", "run"]].concat(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let line = stdout(&out);
    assert!(line.contains("stable (largest growth rate 0 within round-off, |rate| ≤ 2.0e-6 1/s)"), "{line}");
    let shape: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run/shape.json")).unwrap()).unwrap();
    let nearest = &shape["nearest"];
    assert!(nearest["growth_rate"].as_f64().unwrap().abs() <= nearest["growth_rate_bound"].as_f64().unwrap());
}
