//! A run continues from another's final state (`final.json`, `--initial RUN_DIR`): exactly
//! the state it ended in, in the coordinates it was integrated in (3D: unit directions);
//! states that do not fit the run are one-line errors.

mod common;

use common::{run_in, scratch, stderr};

fn final_state(dir: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("final.json")).unwrap()).unwrap()
}

fn numbers(v: &serde_json::Value, key: &str) -> Vec<f64> {
    v[key].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

#[test]
fn two_halves_from_the_final_state_make_the_whole_run() {
    // A 3D chain swinging from a tilted, spinning start, fixed pivot (autonomous), RK4:
    // one run of 2 s against 1 s + 1 s from the first half's final state.
    let dir = scratch("continuation-halves");
    let chain = ["simulate", "--dim", "3", "--n", "4", "--initial", "tilted:0.7", "--spin", "1.5"];
    let run = ["--integrator", "rk4", "--step", "0.002", "--no-plots", "--quiet"];
    let whole = run_in(&dir, &[&chain[..], &run[..], &["--end", "2", "--out", "whole"]].concat());
    assert!(whole.status.success(), "{}", stderr(&whole));
    let first = run_in(&dir, &[&chain[..], &run[..], &["--end", "1", "--out", "first"]].concat());
    assert!(first.status.success(), "{}", stderr(&first));
    let rest = ["--dim", "3", "--n", "4", "--initial", "first", "--end", "1", "--out", "second"];
    let second = run_in(&dir, &[&["simulate"][..], &rest[..], &run[..]].concat());
    assert!(second.status.success(), "{}", stderr(&second));

    let (a, b) = (final_state(&dir.join("whole")), final_state(&dir.join("second")));
    assert_eq!(a["representation"], "directions");
    assert_eq!(numbers(&a, "coordinates").len(), 12);
    for key in ["coordinates", "rates"] {
        let (x, y) = (numbers(&a, key), numbers(&b, key));
        let worst = x.iter().zip(&y).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
        // Only the integrator's compensated summation restarts: round-off apart.
        assert!(worst < 1e-12, "{key}: {worst}");
    }
    // The second run's run.json holds the state it started from, exactly.
    let run_json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("second/run.json")).unwrap()).unwrap();
    let start = numbers(&run_json["config"]["initial"], "directions");
    let end_of_first = final_state(&dir.join("first"));
    let expected: Vec<f64> =
        numbers(&end_of_first, "coordinates").into_iter().chain(numbers(&end_of_first, "rates")).collect();
    assert_eq!(start, expected);
}

#[test]
fn a_planar_run_continues_in_angles() {
    let dir = scratch("continuation-planar");
    let out = run_in(&dir, &["simulate", "--n", "2", "--end", "0.5", "--out", "a", "--no-plots", "--quiet"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let state = final_state(&dir.join("a"));
    assert_eq!(state["representation"], "angles");
    let out = run_in(
        &dir,
        &["simulate", "--n", "2", "--initial", "a/final.json", "--end", "0.5", "--out", "b", "--quiet"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let run_json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("b/run.json")).unwrap()).unwrap();
    assert_eq!(numbers(&run_json["config"]["initial"], "coordinates"), numbers(&state, "coordinates"));
    assert_eq!(numbers(&run_json["config"]["initial"], "rates"), numbers(&state, "rates"));
}

#[test]
fn a_state_of_another_chain_is_a_one_line_error() {
    let dir = scratch("continuation-mismatch");
    let out = run_in(
        &dir,
        &["simulate", "--dim", "3", "--n", "3", "--end", "0.1", "--out", "a", "--no-plots", "--quiet"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    for (args, expected) in [
        (
            vec!["simulate", "--dim", "3", "--n", "4", "--initial", "a"],
            "--initial a/final.json: a state of 3 links in 3D, this run has 4 links in 3D",
        ),
        (
            vec!["simulate", "--n", "3", "--initial", "a/final.json"],
            "--initial a/final.json: a state of 3 links in 3D, this run has 3 links in 2D",
        ),
        (vec!["simulate", "--n", "3", "--initial", "missing.json"], "--initial missing.json: cannot read it"),
    ] {
        let out = run_in(&dir, &args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        let message = stderr(&out);
        assert_eq!(message.lines().count(), 1, "{message}");
        assert!(message.contains(expected), "{args:?}: {message}");
    }
}

#[test]
fn a_whirl_continues_where_it_was_relative_to_its_pivot() {
    // The pivot's phase restarts at 0 in the second run; the state is turned by −φ(T) about
    // the vertical, so the shape in the turning frame carries on: 1 s + 1 s against 2 s.
    let dir = scratch("continuation-whirl");
    let chain = ["simulate", "--dim", "3", "--n", "4", "--initial", "tilted:0.3", "--drive", "circle"];
    let run = [
        "--radius",
        "0.05",
        "--omega",
        "4",
        "--integrator",
        "rk4",
        "--step",
        "0.002",
        "--no-plots",
        "--quiet",
    ];
    for (extra, out) in [(&["--end", "2"][..], "whole"), (&["--end", "1"][..], "first")] {
        let o = run_in(&dir, &[&chain[..], &run[..], extra, &["--out", out]].concat());
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let phase = final_state(&dir.join("first"))["pivot_phase"].as_f64().unwrap();
    assert!((phase - 4.0).abs() < 1e-12, "φ(1 s) = {phase}");
    let rest = [
        "simulate",
        "--dim",
        "3",
        "--n",
        "4",
        "--initial",
        "first",
        "--drive",
        "circle",
        "--end",
        "1",
        "--out",
        "second",
    ];
    let o = run_in(&dir, &[&rest[..], &run[..]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let shape = |run: &str| -> Vec<f64> {
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join(run).join("shape.json")).unwrap())
                .unwrap();
        v["shape"]["positions"].as_array().unwrap().iter().flat_map(numbers_of).collect()
    };
    let (a, b) = (shape("whole"), shape("second"));
    let worst = a.iter().zip(&b).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
    assert!(worst < 1e-10, "co-rotating positions differ by {worst} m");
}

fn numbers_of(v: &serde_json::Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}
