//! `pendulum view`: one self-contained page, exported or served, checked in a headless Chromium when
//! there is one (`.ci/run` installs it and sets `PENDULUM_BROWSER_TEST=require`, so CI
//! cannot skip it).

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{run_in, scratch, stderr};

/// A short whirl of 8 links run with the defaults (midpoint, h = T/20 = 0.0625 s: 97
/// samples), and its exported page.
fn exported(name: &str) -> (PathBuf, PathBuf) {
    let dir = scratch(name);
    let args = [
        "simulate",
        "--dim",
        "3",
        "--n",
        "8",
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
        "6",
        "--no-plots",
        "--quiet",
        "--out",
        "run",
    ];
    let out = run_in(&dir, &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = run_in(&dir, &["view", "run", "--export", "page.html"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("page.html: 97 frames of 97 samples (every 1)"), "{}", stderr(&out));
    (dir.clone(), dir.join("page.html"))
}

#[test]
fn the_page_holds_everything_and_fetches_nothing() {
    let (_, page) = exported("view-page");
    let text = std::fs::read_to_string(&page).unwrap();
    assert!(!text.contains("http://") && !text.contains("https://"), "the page names a URL");
    assert!(!text.contains("<script src") && !text.contains("<link"), "the page loads a file");
    assert!(text.contains("const SCENE = {\"dim\":3,\"links\":8,"), "the data is inline");
    assert!(text.contains("function selftest()"), "the viewer is inline");
    assert!(text.len() < 2_000_000, "{} bytes", text.len());
}

#[test]
fn bad_inputs_are_one_line_errors() {
    let dir = scratch("view-bad");
    std::fs::create_dir_all(dir.join("empty")).unwrap();
    let out = run_in(&dir, &["view", "empty", "--export", "p.html"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("holds no run: no run.json"), "{}", stderr(&out));
    let out = run_in(&dir, &["view", "empty", "--port", "0"]);
    assert_eq!(out.status.code(), Some(2), "no server for a directory without a run");
    // A missing directory: the message is view's, not render's (a regression).
    let out = run_in(&dir, &["view", "nowhere", "--export", "p.html"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr(&out).trim(),
        "error: nowhere is not a run directory (what a run given --out DIR writes)"
    );
    // A trajectory cut in the middle of a line.
    let (run_dir, _) = exported("view-truncated");
    let csv = run_dir.join("run/trajectory.csv");
    let text = std::fs::read_to_string(&csv).unwrap();
    std::fs::write(&csv, &text[..text.len() - 40]).unwrap();
    let out = run_in(&run_dir, &["view", "run", "--export", "p.html"]);
    assert_eq!(out.status.code(), Some(2));
    let message = stderr(&out);
    assert!(
        message.contains("the line is cut short (no line end)") && message.lines().count() == 1,
        "{message}"
    );
    let out = run_in(&run_dir, &["view", "run", "--export", "p.html", "--frames", "1"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(stderr(&out).trim(), "error: --frames must be at least 2, got 1");
}

fn browser(page: &Path, fragment: &str, extra: &[&str]) -> Option<std::process::Output> {
    let program = common::chromium()?;
    let url = format!("file://{}#{fragment}", page.canonicalize().unwrap().display());
    let out = Command::new(program)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--window-size=1200,800",
            "--virtual-time-budget=4000",
        ])
        .args(extra)
        .arg(url)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    Some(out)
}

/// In the browser: the chain is drawn where the positions say (every mass's pixel has
/// the mass colour), and the slider shows the sample it is moved to, with its time.
#[test]
fn in_the_browser_the_slider_shows_the_right_sample_and_the_chain_is_where_it_should_be() {
    let (_, page) = exported("view-browser");
    let Some(out) = browser(&page, "selftest", &["--dump-dom"]) else { return };
    let dom = String::from_utf8_lossy(&out.stdout);
    let start = dom.find("<pre id=\"selftest\">").expect("the self-test ran") + "<pre id=\"selftest\">".len();
    let json: serde_json::Value =
        serde_json::from_str(&dom[start..start + dom[start..].find('<').unwrap()]).unwrap();
    assert_eq!(json["frames"], 97);
    let checks = json["checks"].as_array().unwrap();
    assert_eq!(checks.len(), 3);
    for (check, (asked, time)) in checks.iter().zip([(0, 0.0), (48, 3.0), (96, 6.0)]) {
        assert_eq!(check["asked"], asked, "{check}");
        assert_eq!(check["shown"], asked, "{check}");
        assert!((check["time"].as_f64().unwrap() - time).abs() < 1e-5, "{check}");
        let label = check["label"].as_str().unwrap();
        assert_eq!(label, format!("t = {time:.3} s ({}/97)", asked + 1));
        assert_eq!(check["masses_on_mass_pixels"], 8, "every mass drawn where it is: {check}");
        assert!(check["inked"].as_u64().unwrap() > 500, "{check}");
    }
    // The screenshot is not blank.
    let shot = page.with_file_name("page.png");
    let arg = format!("--screenshot={}", shot.display());
    browser(&page, "t=48", &[&arg]).unwrap();
    // The canvas of sample 48 shows its masses where the trajectory puts them, projected
    // here independently of the page's script; the screenshot shows the masses (8 discs
    // of radius 6 px).
    let picture = &json["picture"];
    assert_eq!(picture["sample"], 48);
    let csv = common::Csv::read(&page.with_file_name("run").join("trajectory.csv"));
    let column = |name: String| csv.header.iter().position(|h| *h == name).unwrap();
    let masses: Vec<[f64; 3]> =
        (1..=8).map(|i| ["x", "y", "z"].map(|a| csv.rows[48][column(format!("{a}{i}"))])).collect();
    common::assert_drawn_at(picture, &masses);
    let drawn = common::Screenshot::read(&shot, (1200, 800)).count(common::MASS_COLOUR);
    assert!(drawn > 400, "{drawn} pixels in the mass colour");
}

/// `GET /` from the server at `address` (`127.0.0.1:PORT`): the response's body.
fn get(address: &str) -> String {
    use std::io::{Read, Write};
    let mut stream = std::net::TcpStream::connect(address).unwrap();
    stream.write_all(b"GET / HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n").unwrap();
    let mut response = String::new();
    stream.read_to_string(&mut response).unwrap();
    assert!(response.starts_with("HTTP/1.1 200 OK"), "{}", &response[..80.min(response.len())]);
    response.split_once("\r\n\r\n").unwrap().1.to_string()
}

/// The served page is the exported one; a client that hangs up does not stop the server;
/// Ctrl-C stops it (exit 0); a port in use is a one-line usage error naming it.
#[cfg(unix)]
#[test]
fn the_server_serves_the_page_until_ctrl_c_and_refuses_a_port_in_use() {
    use std::io::{BufRead, BufReader};
    let (dir, page) = exported("view-serve");
    let mut child = common::pendulum()
        .args(["view", "run", "--port", "0"])
        .current_dir(&dir)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    let line = lines.next().unwrap().unwrap();
    let address = line.split("http://").nth(1).and_then(|s| s.split('/').next()).expect(&line).to_string();
    assert!(line.ends_with("/ (Ctrl-C stops)"), "{line}");
    // A client that connects and hangs up at once.
    drop(std::net::TcpStream::connect(&address).unwrap());
    assert_eq!(get(&address), std::fs::read_to_string(&page).unwrap());
    assert_eq!(get(&address), std::fs::read_to_string(&page).unwrap(), "still serving");
    // The port is taken: a second server on it is refused.
    let port = address.rsplit(':').next().unwrap();
    let out = run_in(&dir, &["view", "run", "--port", port]);
    assert_eq!(out.status.code(), Some(2));
    let message = stderr(&out);
    assert!(
        message.starts_with(&format!("error: --port {port}: cannot listen on 127.0.0.1:{port}: ")),
        "{message}"
    );
    assert_eq!(message.lines().count(), 1, "{message}");
    let killed = Command::new("sh").args(["-c", &format!("kill -INT {}", child.id())]).status().unwrap();
    assert!(killed.success());
    let sent = std::time::Instant::now();
    assert!(child.wait().unwrap().success());
    // Within a second of Ctrl-C (issue 34).
    assert!(sent.elapsed() < std::time::Duration::from_secs(1), "{:?}", sent.elapsed());
    assert_eq!(lines.next().unwrap().unwrap(), "pendulum: stopped");
}

/// A whirl's page opens at its end, where the answer is, and says it plainly: counts that
/// agree with their nouns, numbers that do not wrap (issue 34).
#[test]
fn a_whirls_page_opens_at_its_answer_and_says_it_plainly() {
    let dir = scratch("view-whirl-answer");
    let run = [&["simulate", "--no-plots"][..], &common::WHIRL_20, &["--end", "60", "--out", "run"]].concat();
    let out = run_in(&dir, &run);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = run_in(&dir, &["view", "run", "--export", "page.html"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let Some(out) = browser(&dir.join("page.html"), "", &["--dump-dom"]) else { return };
    let dom = String::from_utf8_lossy(&out.stdout);
    let text = |id: &str| {
        let start = dom.find(&format!("id=\"{id}\">")).expect(id) + id.len() + 6;
        dom[start..start + dom[start..].find('<').unwrap()].to_string()
    };
    let samples = common::Csv::read(&dir.join("run/trajectory.csv")).rows.len();
    assert!(text("time").ends_with(&format!("({samples}/{samples})")), "opens at the end: {}", text("time"));
    let shape = text("shape");
    assert!(shape.starts_with("2 nodes (1 axis crossing; the pivot counts)\ntip radius 0.0"), "{shape}");
    assert!(!shape.contains("e-"), "a plain hyphen lets a number wrap: {shape}");
}
