//! Helpers shared by the integration tests: run the `pendulum` binary, fresh scratch
//! directories, CSV reading.

#![allow(dead_code)] // Each test file uses its own subset.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The binary under test.
pub fn pendulum() -> Command {
    Command::new(env!("CARGO_BIN_EXE_pendulum"))
}

/// The sweep section's 20-link chain (L = 1 m, M = 1 kg, λ = 3e-4 N·m·s), hanging, whirled
/// on a 2 cm circle at 6 rad/s; `--end` is the test's.
pub const WHIRL_20: [&str; 18] = [
    "--dim",
    "3",
    "--n",
    "20",
    "--lengths",
    "0.05",
    "--masses",
    "0.05",
    "--damping",
    "3e-4",
    "--initial",
    "hanging",
    "--drive",
    "circle",
    "--radius",
    "0.02",
    "--omega",
    "6",
];

/// Runs `pendulum args...` in `dir`.
pub fn run_in(dir: &Path, args: &[&str]) -> Output {
    pendulum().args(args).current_dir(dir).output().expect("the pendulum binary runs")
}

/// Runs `pendulum args...` in `dir`, failing the test if it has not ended within
/// `seconds` (the process is killed, so a hang fails instead of stalling the suite).
pub fn run_within(dir: &Path, args: &[&str], seconds: u64) -> Output {
    use std::process::Stdio;
    use std::time::{Duration, Instant};
    let mut child = pendulum()
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the pendulum binary runs");
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(seconds) {
            let _ = child.kill();
            let out = child.wait_with_output().unwrap();
            panic!("pendulum {} did not end within {seconds} s; stderr: {}", args.join(" "), stderr(&out));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// Sends SIGINT (Ctrl-C) to `child` once `ready()` holds, and returns its output and the
/// time it took to end after the signal. Fails the test if `ready` does not hold within
/// 60 s.
#[cfg(unix)]
pub fn interrupt_when(
    child: std::process::Child,
    mut ready: impl FnMut() -> bool,
) -> (Output, std::time::Duration) {
    use std::time::{Duration, Instant};
    let start = Instant::now();
    while !ready() {
        assert!(start.elapsed() < Duration::from_secs(60), "the phase to interrupt never came");
        std::thread::sleep(Duration::from_millis(10));
    }
    // The shell's kill builtin: present wherever `sh` is.
    let killed = Command::new("sh").args(["-c", &format!("kill -INT {}", child.id())]).status().unwrap();
    assert!(killed.success());
    let sent = Instant::now();
    let out = child.wait_with_output().unwrap();
    (out, sent.elapsed())
}

/// A fresh, empty scratch directory named for the test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("pendulum-cli").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Standard error as text.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A CSV file: its header and numeric rows; panics (failing the test) on a malformed
/// row, so every test that reads a CSV also checks it is complete.
pub struct Csv {
    pub header: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Csv {
    pub fn read(path: &Path) -> Self {
        let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(text.ends_with('\n'), "{} does not end with a newline", path.display());
        let mut lines = text.lines();
        let header: Vec<String> = lines.next().expect("a header").split(',').map(String::from).collect();
        let rows: Vec<Vec<f64>> = lines
            .enumerate()
            .map(|(i, line)| {
                let row: Vec<f64> = line
                    .split(',')
                    .map(|v| {
                        v.parse().unwrap_or_else(|_| panic!("{} row {i}: bad value {v}", path.display()))
                    })
                    .collect();
                assert_eq!(row.len(), header.len(), "{} row {i} has {} fields", path.display(), row.len());
                row
            })
            .collect();
        Self { header, rows }
    }

    /// The column named `name`.
    pub fn column(&self, name: &str) -> Vec<f64> {
        let j = self.header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name}"));
        self.rows.iter().map(|r| r[j]).collect()
    }
}

/// The parsed run.json of a run directory.
pub fn run_json(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("run.json")).unwrap()).unwrap()
}

/// A CSV file with text columns (sweep.csv, branches.csv, shapes.csv): header and fields;
/// panics (failing the test) on a ragged row or a missing final newline.
pub struct Table {
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    pub fn read(path: &Path) -> Self {
        let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(text.ends_with('\n'), "{} does not end with a newline", path.display());
        let mut lines = text.lines();
        let header: Vec<String> = lines.next().expect("a header").split(',').map(String::from).collect();
        let rows: Vec<Vec<String>> = lines.map(|l| l.split(',').map(String::from).collect()).collect();
        for (i, row) in rows.iter().enumerate() {
            assert_eq!(row.len(), header.len(), "{} row {i}", path.display());
        }
        Self { header, rows }
    }

    /// The index of column `name`.
    pub fn index(&self, name: &str) -> usize {
        self.header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name}"))
    }

    /// Column `name` as text.
    pub fn text(&self, name: &str) -> Vec<String> {
        let j = self.index(name);
        self.rows.iter().map(|r| r[j].clone()).collect()
    }

    /// Column `name` as numbers.
    pub fn column(&self, name: &str) -> Vec<f64> {
        self.text(name)
            .iter()
            .map(|v| v.parse().unwrap_or_else(|_| panic!("{name}: bad number '{v}'")))
            .collect()
    }
}

/// The colour the pages draw masses in (`MASS` in pendulum-experiment/src/page/draw.js).
pub const MASS_COLOUR: [u8; 3] = [20, 50, 150];

/// The headless browser, if there is one: `$PENDULUM_CHROMIUM`, else `chromium`,
/// `chromium-browser` or `google-chrome` on the path. None (the browser checks are
/// skipped) only when `PENDULUM_BROWSER_TEST` is not `require`.
pub fn chromium() -> Option<String> {
    let found = std::env::var("PENDULUM_CHROMIUM").ok().or_else(|| {
        ["chromium", "chromium-browser", "google-chrome"]
            .into_iter()
            .find(|name| Command::new(name).arg("--version").output().is_ok_and(|o| o.status.success()))
            .map(String::from)
    });
    if found.is_none() {
        assert!(
            std::env::var("PENDULUM_BROWSER_TEST").as_deref() != Ok("require"),
            "PENDULUM_BROWSER_TEST=require but no chromium found"
        );
        eprintln!("no chromium: the browser checks are skipped");
    }
    found
}

/// A PNG screenshot's pixels, RGB.
pub struct Screenshot {
    pub width: usize,
    pub height: usize,
    rgb: Vec<[u8; 3]>,
}

impl Screenshot {
    /// Reads the PNG at `path`, checking its size.
    pub fn read(path: &Path, size: (u32, u32)) -> Self {
        let shot = Self::decode(&std::fs::read(path).unwrap());
        assert_eq!((shot.width as u32, shot.height as u32), size, "{}", path.display());
        shot
    }

    /// Decodes a PNG.
    pub fn decode(bytes: &[u8]) -> Self {
        let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        let mut reader = decoder.read_info().unwrap();
        let mut pixels = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut pixels).unwrap();
        let channels = info.color_type.samples();
        let rgb = pixels[..info.buffer_size()].chunks(channels).map(|p| [p[0], p[1], p[2]]).collect();
        Self { width: info.width as usize, height: info.height as usize, rgb }
    }

    /// Whether the pixel is within 40 of `rgb` in each channel.
    fn is(&self, x: usize, y: usize, rgb: [u8; 3]) -> bool {
        self.rgb[y * self.width + x].iter().zip(rgb).all(|(&v, c)| v.abs_diff(c) < 40)
    }

    /// The pixels of the colour `rgb` (within 40 in each channel).
    pub fn count(&self, rgb: [u8; 3]) -> usize {
        (0..self.height)
            .flat_map(|y| (0..self.width).map(move |x| (x, y)))
            .filter(|&(x, y)| self.is(x, y, rgb))
            .count()
    }

    /// Whether a pixel within one of `(x, y)` has the colour `rgb`.
    pub fn near(&self, x: f64, y: f64, rgb: [u8; 3]) -> bool {
        let (x, y) = (x.round() as i64, y.round() as i64);
        (-1..=1).flat_map(|dy| (-1..=1).map(move |dx| (x + dx, y + dy))).any(|(x, y)| {
            (0..self.width as i64).contains(&x)
                && (0..self.height as i64).contains(&y)
                && self.is(x as usize, y as usize, rgb)
        })
    }
}

/// Checks a page's self-test `picture` (its camera and the canvas as a PNG data URL,
/// `picture()` in pendulum-experiment/src/page/draw.js): every point of `masses` (m, z up),
/// projected here as the page's orthographic camera does (turned by yaw about the
/// vertical, tilted by pitch, about its centre), lands within a pixel of the mass colour.
pub fn assert_drawn_at(picture: &serde_json::Value, masses: &[[f64; 3]]) {
    use base64::Engine;
    let number = |key: &str| picture[key].as_f64().unwrap_or_else(|| panic!("no {key} in the picture"));
    let (yaw, pitch, scale) = (number("yaw"), number("pitch"), number("scale"));
    let centre: Vec<f64> = (0..3).map(|k| picture["centre"][k].as_f64().unwrap()).collect();
    let data =
        picture["image"].as_str().unwrap().strip_prefix("data:image/png;base64,").expect("a PNG data URL");
    let image = Screenshot::decode(&base64::engine::general_purpose::STANDARD.decode(data).unwrap());
    assert_eq!((image.width as f64, image.height as f64), (number("width"), number("height")));
    for (i, p) in masses.iter().enumerate() {
        let q = [p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]];
        let across = yaw.cos() * q[0] - yaw.sin() * q[1];
        let depth = yaw.sin() * q[0] + yaw.cos() * q[1];
        let up = pitch.cos() * q[2] + pitch.sin() * depth;
        let (x, y) = (image.width as f64 / 2.0 + scale * across, image.height as f64 / 2.0 - scale * up);
        assert!(image.near(x, y, MASS_COLOUR), "mass {} at {p:?} is not drawn at ({x:.1}, {y:.1})", i + 1);
    }
}
