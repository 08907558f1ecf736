//! run.json files written by the last release (`pendulum simulate`, committed under
//! `tests/runs/`) load through the library's [`RunFile`], run without the CLI, and end in
//! the CLI's `final.json`, bit for bit; the recorded outcome (steps, samples, the
//! integrator's work) comes out the same too.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use pendulum_experiment::{Error, FinalState, Recorder, RunFile, Status, build};

fn runs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/runs")
}

/// Runs `NAME.run.json` and checks its final state against `NAME.final.json` as text and
/// its outcome against the recorded one.
fn repeat(name: &str) {
    let file = RunFile::read(&runs().join(format!("{name}.run.json"))).unwrap();
    let config = &file.config;
    let mut recorder = Recorder::default();
    let report =
        build(config).unwrap().run(config, &mut [&mut recorder], &mut |_| ControlFlow::Continue(())).unwrap();
    assert_eq!(report.status, Status::Completed);
    let expected = std::fs::read_to_string(runs().join(format!("{name}.final.json"))).unwrap();
    let written = serde_json::to_string_pretty(&report.final_state).unwrap() + "\n";
    assert_eq!(written, expected, "{name}: the final state differs from the CLI's final.json");
    let recorded: FinalState = serde_json::from_str(&expected).unwrap();
    for (a, b) in report
        .final_state
        .coordinates
        .iter()
        .chain(&report.final_state.rates)
        .zip(recorded.coordinates.iter().chain(&recorded.rates))
    {
        assert_eq!(a.to_bits(), b.to_bits(), "{name}: {a} vs {b}");
    }
    let outcome = file.outcome.expect("a finished run's file");
    assert_eq!((report.steps, report.samples), (outcome.steps, outcome.samples), "{name}");
    if let Some(work) = outcome.work {
        assert_eq!(report.work, work, "{name}");
    }
    assert_eq!(recorder.len() as u64, report.samples, "{name}");
    assert_eq!(recorder.times.last().copied(), Some(report.t), "{name}");
}

#[test]
fn the_demo_gauss_legendre_in_angles() {
    repeat("triple");
}

#[test]
fn a_whirl_by_rk4_with_projection_and_its_pivot_phase() {
    repeat("whirl");
}

#[test]
fn a_damped_whirl_on_the_chosen_midpoint_rule() {
    repeat("midpoint");
}

#[test]
fn dormand_prince_on_a_shaken_3d_chain() {
    repeat("dp");
}

#[test]
fn a_run_json_without_the_fields_later_releases_added_loads_and_runs() {
    let early = RunFile::read(&runs().join("triple-early.run.json")).unwrap();
    let now = RunFile::read(&runs().join("triple.run.json")).unwrap();
    assert_eq!(early.config.chosen, None);
    assert_eq!(early.outcome.as_ref().unwrap().work, None);
    assert_eq!(
        (early.config.masses.clone(), early.config.step),
        (now.config.masses.clone(), now.config.step)
    );
}

#[test]
fn a_whirl_reports_its_shape_and_a_bad_file_names_itself() {
    let file = RunFile::read(&runs().join("whirl.run.json")).unwrap();
    let report =
        build(&file.config).unwrap().run(&file.config, &mut [], &mut |_| ControlFlow::Continue(())).unwrap();
    let shape = report.shape.expect("a circling pivot").unwrap();
    assert!(shape.shape.nodes >= 1 && shape.shape.tip_radius > 0.0, "{shape:?}");
    assert!(report.final_state.pivot_phase.is_some());

    let dir = std::env::temp_dir().join(format!("pendulum-experiment-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("run.json");
    std::fs::write(&bad, "{\"program\": \"pendulum\"}").unwrap();
    let e = RunFile::read(&bad).unwrap_err();
    assert!(matches!(e, Error::Invalid(_)), "{e:?}");
    assert!(e.to_string().contains("is not a valid run.json"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_observer_stops_the_run_and_the_report_says_so() {
    let file = RunFile::read(&runs().join("triple.run.json")).unwrap();
    let mut seen = 0;
    let mut observe = |t: f64| {
        if t >= 1.011 {
            return ControlFlow::Break(());
        }
        seen += 1;
        ControlFlow::Continue(())
    };
    let config = &file.config;
    let report = build(config).unwrap().run(config, &mut [], &mut observe).unwrap();
    assert_eq!(report.status, Status::Interrupted);
    // Stopped at the first step past t = 1.011 s (step 203), between samples, and sampled there.
    assert!(report.t >= 1.011 && report.t < 1.011 + 1.001 * config.step, "{}", report.t);
    assert_eq!(seen, report.steps, "the observer hears of t = 0 and of every step before the stop");
    let every = config.every as u64;
    assert_ne!(report.steps % every, 0, "the test stops between samples");
    assert_eq!(report.samples, report.steps / every + 2, "t = 0, every {every} steps, the stop");
}
