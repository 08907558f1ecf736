//! Ctrl-C in every phase (issue 34): while drawing the pictures, encoding a GIF, rendering
//! and in `steady`, the program exits with status 130 within a second, leaves the files it
//! had finished complete and no half-written file behind.

#![cfg(unix)]

mod common;

use std::path::Path;
use std::time::{Duration, Instant};

use common::{interrupt_when, run_json, scratch, stderr};

/// Files in `dir` whose name ends in `.partial`.
fn partial_files(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".partial"))
        .collect()
}

/// Asserts the exit status 130 within a second of the signal, and the message.
fn assert_cut(out: &std::process::Output, took: Duration) {
    assert_eq!(out.status.code(), Some(130), "{}", stderr(out));
    assert!(took < Duration::from_secs(1), "took {took:?} after Ctrl-C");
    assert!(stderr(out).contains("interrupted"), "{}", stderr(out));
}

/// A 2D run whose animation of 2,500 frames takes seconds to encode.
const LONG_GIF: [&str; 12] =
    ["--n", "20", "--end", "100", "--step", "0.01", "--every", "2", "--frames", "5000", "--out", "run"];

#[test]
fn ctrl_c_while_simulate_encodes_the_gif_exits_at_once_with_the_data_complete() {
    let dir = scratch("interrupt-encoding");
    let child = common::pendulum()
        .arg("simulate")
        .args(LONG_GIF)
        .current_dir(&dir)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let run = dir.join("run");
    let (out, took) = interrupt_when(child, || run.join("chain.gif.partial").exists());
    assert_cut(&out, took);
    // The run itself was complete, and its record says so.
    let json = run_json(&run);
    assert_eq!(json["outcome"]["status"], "completed");
    assert_eq!(json["outcome"]["samples"], 5001);
    assert_eq!(common::Csv::read(&run.join("energy.csv")).rows.len(), 5001);
    assert!(run.join("final.json").exists() && run.join("energy.png").exists());
    assert!(!run.join("chain.gif").exists());
    assert_eq!(partial_files(&run), Vec::<String>::new());
}

#[test]
fn ctrl_c_while_rendering_exits_at_once_without_a_partial_file() {
    let dir = scratch("interrupt-render");
    let made = common::run_in(&dir, &[&["simulate", "--no-plots"][..], &LONG_GIF].concat());
    assert!(made.status.success(), "{}", stderr(&made));
    let child = common::pendulum()
        .args(["render", "run", "--frames", "5000", "--out", "run/again.gif"])
        .current_dir(&dir)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let run = dir.join("run");
    let (out, took) = interrupt_when(child, || run.join("again.gif.partial").exists());
    assert_cut(&out, took);
    assert!(!run.join("again.gif").exists());
    assert_eq!(partial_files(&run), Vec::<String>::new());
}

#[test]
fn ctrl_c_in_steady_exits_at_once() {
    let dir = scratch("interrupt-steady");
    // Several seconds of continuation (O(n) a step, 1000 links, a test build).
    let child = common::pendulum()
        .args([
            "steady",
            "--n",
            "1000",
            "--lengths",
            "0.001",
            "--masses",
            "0.001",
            "--omega",
            "6",
            "--out",
            "s",
        ])
        .current_dir(&dir)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let (out, took) = interrupt_when(child, || start.elapsed() > Duration::from_millis(500));
    assert_cut(&out, took);
}
