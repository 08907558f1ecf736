//! Every bad argument or file: a one-line message naming the problem, exit status 2, no
//! panic, nothing left half-written.

mod common;

use common::{run_in, scratch, stderr};

/// Runs the arguments in a fresh directory and checks the error contract.
fn assert_usage_error(name: &str, args: &[&str], needle: &str) {
    let dir = scratch(&format!("error-{name}"));
    std::fs::write(dir.join("letters.txt"), "1 2 x\n").unwrap();
    std::fs::write(dir.join("empty.txt"), "# nothing\n").unwrap();
    std::fs::write(dir.join("bad.json"), "{ not json").unwrap();
    std::fs::write(dir.join("other.json"), r#"{"program":"other","version":"1","config":{}}"#).unwrap();
    let out = run_in(&dir, args);
    let message = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {message}");
    assert_eq!(message.trim_end().lines().count(), 1, "{args:?}: not one line: {message}");
    assert!(message.contains(needle), "{args:?}: {message:?} does not name '{needle}'");
    assert!(!message.contains("panicked"), "{message}");
    assert!(!dir.join("run/trajectory.csv").exists(), "{args:?} wrote a trajectory");
}

#[test]
fn bad_chain_parameters_are_named() {
    assert_usage_error("n0", &["simulate", "--n", "0", "--out", "run"], "--n");
    assert_usage_error("mass", &["simulate", "--masses", "1,-2,1", "--out", "run"], "mass of link 2");
    assert_usage_error(
        "count",
        &["simulate", "--n", "3", "--lengths", "1,2", "--out", "run"],
        "2 values for 3 links",
    );
    assert_usage_error("entry", &["simulate", "--lengths", "1,abc", "--out", "run"], "'abc'");
    assert_usage_error(
        "file",
        &["simulate", "--masses", "letters.txt", "--out", "run"],
        "letters.txt line 1",
    );
    assert_usage_error("nofile", &["simulate", "--masses", "missing.txt", "--out", "run"], "missing.txt");
    assert_usage_error("empty", &["simulate", "--lengths", "empty.txt", "--out", "run"], "holds no numbers");
    assert_usage_error("gravity", &["simulate", "--gravity", "-9.8", "--out", "run"], "gravity");
    assert_usage_error("damping", &["simulate", "--damping", "-0.1", "--out", "run"], "damping of link 1");
    assert_usage_error("nan", &["simulate", "--gravity", "NaN", "--out", "run"], "gravity");
}

#[test]
fn bad_run_parameters_are_named() {
    assert_usage_error("step", &["simulate", "--step", "0", "--out", "run"], "--step");
    assert_usage_error("end", &["simulate", "--end", "-1", "--out", "run"], "--end");
    assert_usage_error("every", &["simulate", "--every", "0", "--out", "run"], "--every");
    assert_usage_error("huge", &["simulate", "--step", "1e-9", "--end", "1000", "--out", "run"], "1e8");
    assert_usage_error("integrator", &["simulate", "--integrator", "euler", "--out", "run"], "euler");
    assert_usage_error("dim", &["simulate", "--dim", "4", "--out", "run"], "'4'");
    assert_usage_error("initial", &["simulate", "--initial", "sideways", "--out", "run"], "sideways");
    assert_usage_error("tilted", &["simulate", "--initial", "tilted:x", "--out", "run"], "tilted angle 'x'");
    assert_usage_error("unknown", &["simulate", "--speed", "3"], "--speed");
    assert_usage_error("negative-n", &["simulate", "--n", "-3", "--out", "run"], "'-3'");
    assert_usage_error("out-is-file", &["simulate", "--out", "bad.json"], "--out");
}

#[test]
fn bad_drives_and_combinations_are_named() {
    assert_usage_error("circle2d", &["simulate", "--drive", "circle", "--out", "run"], "3D only");
    assert_usage_error(
        "amplitude",
        &["simulate", "--drive", "harmonic", "--amplitude", "-1", "--out", "run"],
        "amplitude",
    );
    let args = ["simulate", "--drive", "harmonic", "--direction", "0,0", "--out", "run"];
    assert_usage_error("direction", &args, "direction norm");
    let args = ["simulate", "--drive", "harmonic", "--direction", "1,0,0", "--out", "run"];
    assert_usage_error("direction3", &args, "3 components");
    assert_usage_error(
        "radius",
        &["simulate", "--dim", "3", "--drive", "circle", "--radius", "-1", "--out", "run"],
        "radius",
    );
    assert_usage_error("torque3d", &["simulate", "--dim", "3", "--torque", "1", "--out", "run"], "2D only");
    assert_usage_error("spin2d", &["simulate", "--spin", "1", "--out", "run"], "--spin");
    assert_usage_error("from-and-n", &["simulate", "--from", "run.json", "--n", "3"], "--from");
}

#[test]
fn bad_run_files_are_named() {
    assert_usage_error(
        "from-missing",
        &["simulate", "--from", "nothere.json", "--out", "run"],
        "nothere.json",
    );
    assert_usage_error(
        "from-bad",
        &["simulate", "--from", "bad.json", "--out", "run"],
        "not a valid run.json",
    );
    assert_usage_error("from-other", &["simulate", "--from", "other.json", "--out", "run"], "other.json");
}

#[test]
fn a_doctored_run_json_is_rejected() {
    let dir = scratch("doctored");
    let out = run_in(&dir, &["simulate", "--n", "2", "--end", "0.02", "--out", "run", "--no-plots"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(dir.join("run/run.json")).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json["config"]["lengths"] = serde_json::json!([0.5]);
    std::fs::write(dir.join("doctored.json"), json.to_string()).unwrap();
    let out = run_in(&dir, &["simulate", "--from", "doctored.json", "--out", "again"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("lengths: got 1 values, expected 2"), "{}", stderr(&out));
}

#[test]
fn bad_eval_arguments_are_named() {
    assert_usage_error(
        "eval-q",
        &["eval", "--model", "planar", "--n", "3", "--q", "0.1,0.2"],
        "--q: got 2 values",
    );
    assert_usage_error("eval-noq", &["eval", "--model", "planar"], "--q");
    let args = ["eval", "--model", "spatial", "--q", "0,0.5,0,0"];
    assert_usage_error("eval-singular", &args, "singularity");
    let args = ["eval", "--model", "planar", "--q", "0.1", "--pivot-acceleration", "1,2,3"];
    assert_usage_error("eval-pivot", &args, "--pivot-acceleration: got 3 values, expected 2");
    assert_usage_error("eval-model", &["eval", "--model", "conical", "--q", "0"], "conical");
}

#[test]
fn help_lists_every_command_and_option() {
    let dir = scratch("help");
    let out = run_in(&dir, &["--help"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("simulate") && text.contains("eval"), "{text}");
    let out = run_in(&dir, &["simulate", "--help"]);
    let text = String::from_utf8_lossy(&out.stdout);
    for option in [
        "--dim",
        "--n",
        "--masses",
        "--lengths",
        "--gravity",
        "--damping",
        "--torque",
        "--drive",
        "--amplitude",
        "--omega",
        "--phase",
        "--direction",
        "--radius",
        "--integrator",
        "--step",
        "--end",
        "--initial",
        "--spin",
        "--every",
        "--out",
        "--from",
        "--view",
        "--frames",
        "--no-plots",
        "--quiet",
    ] {
        assert!(text.contains(option), "simulate --help lacks {option}");
    }
    let out = run_in(&dir, &["eval", "--help"]);
    let text = String::from_utf8_lossy(&out.stdout);
    for option in ["--model", "--q", "--qd", "--torque", "--pivot-acceleration", "--damping"] {
        assert!(text.contains(option), "eval --help lacks {option}");
    }
    let out = run_in(&dir, &[]);
    assert_eq!(out.status.code(), Some(2), "no command is a usage error");
}

/// Output cut off by its reader (`pendulum modes … | head -1`) ends the command quietly,
/// by SIGPIPE as any Unix tool, not with a panic.
#[cfg(unix)]
#[test]
fn a_closed_pipe_ends_the_output_without_a_panic() {
    use std::os::unix::process::ExitStatusExt;
    let dir = scratch("closed-pipe");
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = common::pendulum()
        .args(["modes", "--n", "12", "--lengths", "0.1", "--count", "4", "--out", "modes"])
        .current_dir(&dir)
        .stdout(writer)
        .stderr(std::process::Stdio::piped())
        .output()
        .unwrap();
    assert_eq!(out.status.signal(), Some(13), "{:?}: {}", out.status, stderr(&out));
    assert!(!stderr(&out).contains("panicked"), "{}", stderr(&out));
}
