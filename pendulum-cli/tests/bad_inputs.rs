//! Bad inputs beyond `errors.rs`: non-finite and overflowing numbers, bad initial-state
//! files, a 3D start at the spherical singularity (fine here: 3D runs in unit
//! directions), and a valid but extreme chain that fails at run time. The messages are
//! recorded in `docs/reliability.md`.

mod common;

use common::{run_in, scratch, stderr};

/// Runs `args` in a fresh directory holding the initial-state files; returns the exit
/// code and the one-line message.
fn run(name: &str, args: &[&str]) -> (Option<i32>, String) {
    let dir = scratch(&format!("bad-{name}"));
    std::fs::write(dir.join("nan.txt"), "0.1 NaN 0 0\n").unwrap();
    std::fs::write(dir.join("short.txt"), "0.1 0.2 0\n").unwrap();
    std::fs::write(dir.join("down.txt"), "0 0 0 0 0 0 0 0\n").unwrap();
    let out = run_in(&dir, args);
    let message = stderr(&out);
    assert!(!message.contains("panicked"), "{message}");
    (out.status.code(), message.trim_end().lines().last().unwrap_or("").to_owned())
}

fn usage(name: &str, args: &[&str], message: &str) {
    let (code, got) = run(name, args);
    assert_eq!(code, Some(2), "{args:?}: {got}");
    assert_eq!(got, message, "{args:?}");
}

#[test]
fn non_finite_and_overflowing_numbers() {
    usage(
        "inf-mass",
        &["simulate", "--masses", "inf", "--out", "run"],
        "error: --masses: 'inf' has a non-finite entry inf",
    );
    usage(
        "nan-step",
        &["simulate", "--step", "NaN", "--out", "run"],
        "error: --step must be finite and positive, got NaN",
    );
    usage(
        "nan-end",
        &["simulate", "--end", "NaN", "--out", "run"],
        "error: --end must be finite and positive, got NaN",
    );
    usage(
        "inf-end",
        &["simulate", "--end", "inf", "--out", "run"],
        "error: --end must be finite and positive, got inf",
    );
    // 1e400 parses to +inf, caught by the chain's own check.
    usage(
        "overflow-g",
        &["simulate", "--gravity", "1e400", "--out", "run"],
        "error: gravity g must be finite and non-negative, got inf",
    );
}

#[test]
fn bad_initial_state_files() {
    usage(
        "nan-initial",
        &["simulate", "--n", "2", "--initial", "nan.txt", "--out", "run"],
        "error: --initial: nan.txt line 1: 'NaN' is not a finite number",
    );
    usage(
        "short-initial",
        &["simulate", "--n", "2", "--initial", "short.txt", "--out", "run"],
        "error: --initial: short.txt holds 3 numbers, expected 4 (θ_1..θ_n then θ̇_1..θ̇_n) for n = 2",
    );
}

#[test]
fn a_3d_start_hanging_straight_down_runs() {
    // θ = 0 is singular for the spherical angles but not for the unit directions the
    // CLI integrates in 3D.
    let (code, got) = run(
        "down",
        &[
            "simulate",
            "--dim",
            "3",
            "--n",
            "2",
            "--initial",
            "down.txt",
            "--end",
            "0.05",
            "--out",
            "run",
            "--no-plots",
        ],
    );
    assert_eq!(code, Some(0), "{got}");
}

#[test]
fn an_extreme_chain_fails_at_run_time_with_a_message() {
    // Valid parameters (every length positive) whose numbers leave f64's range (1/l² overflows).
    let (code, got) =
        run("tiny", &["simulate", "--lengths", "1e-300", "--step", "0.005", "--out", "run", "--no-plots"]);
    assert_eq!(code, Some(1), "{got}");
    assert_eq!(
        got,
        "error: the run stopped at t = 0 s: step 0 of the run, from t = 0 s, failed: the accelerations are not \
         finite at this state (its numbers leave the range of f64); files hold what was computed"
    );
}

#[test]
fn integrator_options_that_do_not_fit_are_usage_errors() {
    let cases: [(&[&str], &str); 4] = [
        (&["--tolerance", "1e-8"], "error: --tolerance applies to --integrator dp54 only"),
        (
            &["--integrator", "dp54", "--tolerance", "0"],
            "error: --tolerance must be within 1e-14 … 0.1, got 0",
        ),
        (
            &["--integrator", "dp54", "--tolerance", "NaN"],
            "error: --tolerance must be within 1e-14 … 0.1, got NaN",
        ),
        (
            &["--integrator", "midpoint"],
            "error: --integrator midpoint steps chains in unit directions: 3D only (--dim 3)",
        ),
    ];
    for (i, (extra, message)) in cases.iter().enumerate() {
        let mut args = vec!["simulate", "--out", "run", "--no-plots"];
        args.extend_from_slice(extra);
        let (code, got) = run(&format!("integrator-{i}"), &args);
        assert_eq!(code, Some(2), "{got}");
        assert_eq!(got, *message);
    }
}

#[test]
fn a_step_chosen_too_small_for_the_run_is_a_usage_error_naming_it() {
    let (code, got) = run("tiny-auto", &["simulate", "--lengths", "1e-300", "--out", "run", "--no-plots"]);
    assert_eq!(code, Some(2), "{got}");
    assert!(got.starts_with("error: --end 10 with --step 5.04818777346"), "{got}");
    assert!(
        got.ends_with(
            " (chosen for the chain's fastest mode; name one with --step) needs 1.9809088823063011e152 steps; \
             more than 1e8 is refused"
        ),
        "{got}"
    );
}

#[test]
fn a_run_json_with_a_zero_mass_is_rejected_by_the_chain_check() {
    // Found by the cli_run_json fuzz target: `RunFile::read` checks list lengths and run
    // times, the chain's own validation the values; the user sees the latter, with the
    // file it came from.
    let dir = scratch("bad-zero-mass");
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/corpus/cli_run_json/zero_mass"),
    )
    .unwrap();
    std::fs::write(dir.join("zero.json"), text).unwrap();
    let out = run_in(&dir, &["simulate", "--from", "zero.json", "--out", "run", "--no-plots"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr(&out).trim_end(),
        "error: --from zero.json: mass of link 1 must be finite and positive, got 0"
    );
}
