//! `pendulum view --live`: the live page in a headless Chromium (a scripted drag of the
//! pivot moves the chain's pivot where the drag says), a page that goes away leaves the
//! server running, Ctrl-C stops it; bad options are one-line usage errors.

mod common;

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use common::{pendulum, run_in, scratch, stderr};

#[test]
fn bad_live_options_are_one_line_usage_errors() {
    let dir = scratch("live-bad");
    for (args, expected) in [
        (&["--n", "0"][..], "--n: a chain needs at least 1 link, got 0"),
        (&["--radius", "-1"], "radius"),
        (&["--omega", "NaN"], "omega NaN"),
        (&["--damping", "5"], "damping 5"),
        (&["--start", "-2"], "--start -2: must be a time in 0…3600 s"),
        (&["--lengths", "0.1,x"], "--lengths"),
    ] {
        let out = run_in(&dir, &[&["view", "--live"][..], args].concat());
        let message = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {message}");
        assert!(message.starts_with("error: ") && message.contains(expected), "{args:?}: {message}");
        assert_eq!(message.lines().count(), 1, "{message}");
    }
    // A run and --live, or a live option without --live: clap's usage errors.
    for args in [&["view", "--live", "somewhere"][..], &["view", "--n", "5"], &["view"]] {
        assert_eq!(run_in(&dir, args).status.code(), Some(2), "{args:?}");
    }
}

/// A server that is stopped when the test ends, however it ends (a server left running
/// would hold the test's output open).
struct Server(Child);

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// The server of `pendulum view --live --port 0` and the address it printed.
fn serve(args: &[&str]) -> (Server, String, mpsc::Receiver<String>) {
    let mut child =
        pendulum().args(["view", "--live", "--port", "0"]).args(args).stderr(Stdio::piped()).spawn().unwrap();
    let (send, lines) = mpsc::channel();
    let stderr = child.stderr.take().unwrap();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = send.send(line);
        }
    });
    let child = Server(child);
    let line = lines.recv_timeout(Duration::from_secs(30)).expect("the server starts");
    assert!(line.contains("live: 100 links") && line.ends_with("/ (Ctrl-C stops)"), "{line}");
    let address = line.split("http://").nth(1).and_then(|s| s.split('/').next()).expect(&line).to_string();
    (child, address, lines)
}

/// `GET /` from `address`: the status line.
fn status(address: &str) -> String {
    let mut stream = std::net::TcpStream::connect(address).unwrap();
    stream.write_all(b"GET / HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n").unwrap();
    let mut response = String::new();
    stream.read_to_string(&mut response).unwrap();
    response.lines().next().unwrap_or_default().to_string()
}

/// The live page in the browser: the 100 masses drawn in the mass colour where their
/// positions say, before and after a scripted drag of the pivot by (120, −60) px; the
/// pivot's centre then where that drag says, computed here from the page's camera
/// (yaw, pitch, pixels per metre) independently of the page's script. The page going
/// away leaves the server serving; Ctrl-C stops it.
#[cfg(unix)]
#[test]
fn in_the_browser_a_drag_moves_the_pivot_of_the_live_chain() {
    let Some(program) = common::chromium() else { return };
    let dir = scratch("live-browser");
    let (server, address, lines) = serve(&[]);
    let browser = |profile: &str| {
        let mut command = Command::new(&program);
        command
            .args(["--headless", "--no-sandbox", "--disable-gpu", "--window-size=1200,800"])
            .arg(format!("--user-data-dir={}", dir.join(profile).display()));
        command
    };
    // The self-test in real time: a page left open until it reports. (Under a virtual-time
    // budget, with the page's held request pending, the browser at times delayed the
    // page's socket messages until the hold ended: the drag reached the server 3.5 s late.)
    let mut page = browser("selftest")
        .arg(format!("http://{address}/#selftest"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let prefix = "pendulum: live page self-test: ";
    let report = std::iter::from_fn(|| lines.recv_timeout(Duration::from_secs(20)).ok())
        .find_map(|line| line.strip_prefix(prefix).map(String::from));
    let _ = page.kill();
    let _ = page.wait();
    let report = report.expect("a self-test report from the page");
    // A screenshot 4 s on (the page holds a request open that long, and the browser's
    // virtual time waits for it) shows the masses (100 discs of radius 2 px, overlapping).
    let shot = dir.join("live.png");
    let out = browser("screenshot")
        .arg("--virtual-time-budget=8000")
        .arg(format!("--screenshot={}", shot.display()))
        .arg(format!("http://{address}/#hold=4"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let drawn = common::Screenshot::read(&shot, (1200, 800)).count(common::MASS_COLOUR);
    assert!(drawn > 300, "{drawn} pixels in the mass colour");
    let test: serde_json::Value = serde_json::from_str(&report).unwrap();
    assert_eq!(test["links"], 100, "{test}");
    for drawn in [&test["drawn"], &test["drawn_after"]] {
        assert_eq!(drawn["masses_on_mass_pixels"], 100, "every mass where it is: {test}");
        assert!(drawn["inked"].as_u64().unwrap() > 1000, "{test}");
    }
    let vector = |v: &serde_json::Value| -> [f64; 3] { std::array::from_fn(|k| v[k].as_f64().unwrap()) };
    let (before, after, target) = (vector(&test["before"]), vector(&test["after"]), vector(&test["target"]));
    // The first picture: the masses of the frame the page was sent, where they are.
    let picture = &test["picture"];
    let points: Vec<[f64; 3]> = picture["points"].as_array().unwrap().iter().map(vector).collect();
    assert_eq!(points.len(), 101);
    common::assert_drawn_at(picture, &points[1..]);
    let (yaw, pitch, scale) = (
        picture["yaw"].as_f64().unwrap(),
        picture["pitch"].as_f64().unwrap(),
        picture["scale"].as_f64().unwrap(),
    );
    let (dx, dy) = (test["drag"][0].as_f64().unwrap(), test["drag"][1].as_f64().unwrap());
    // The screen's right and up in space for an orthographic camera turned by yaw about
    // the vertical and tilted by pitch.
    let right = [yaw.cos(), -yaw.sin(), 0.0];
    let up = [pitch.sin() * yaw.sin(), pitch.sin() * yaw.cos(), pitch.cos()];
    let expected: [f64; 3] = std::array::from_fn(|k| before[k] + dx / scale * right[k] - dy / scale * up[k]);
    let miss = |a: [f64; 3], b: [f64; 3]| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
    assert!(
        miss(target, expected) < 1e-6,
        "the drag asked for {target:?}, expected {expected:?} (drags {}, errors {})",
        test["drags"],
        test["errors"]
    );
    assert!(miss(after, expected) < 1e-3, "the pivot's centre went to {after:?}, expected {expected:?}");
    assert!(miss(after, before) > 0.2, "the drag moved the pivot by {:.3} m", miss(after, before));
    // The page went away; the server goes on.
    assert_eq!(status(&address), "HTTP/1.1 200 OK");
    let mut server = server;
    let killed = Command::new("sh").args(["-c", &format!("kill -INT {}", server.0.id())]).status().unwrap();
    assert!(killed.success());
    assert!(server.0.wait().unwrap().success());
    let rest: Vec<String> = lines.try_iter().collect();
    assert_eq!(rest.last().map(String::as_str), Some("pendulum: stopped"), "{rest:?}");
}
