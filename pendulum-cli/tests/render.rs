//! `pendulum render` and the animation `simulate` writes: the GIF decodes with the size,
//! frame count and delays asked for; the chain is drawn where trajectory.csv puts it, at
//! one scale on both axes, in a viewport that fits the motion; the co-rotating view of a
//! steady whirl stands still; the rotation axis is where the circle's centre is; a fast
//! drive gets slow motion; bad inputs get one-line errors and exit status 2.

mod common;

use std::path::Path;

use common::{Csv, run_in, scratch, stderr};

/// A decoded GIF: size, the frames as full RGBA pictures (each drawn over the one
/// before, as every viewer does for frames that keep), and their delays (10 ms units).
struct Gif {
    width: usize,
    height: usize,
    frames: Vec<Vec<u8>>,
    delays: Vec<u16>,
}

fn decode(path: &Path) -> Gif {
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut decoder = options.read_info(file).unwrap();
    let (width, height) = (decoder.width() as usize, decoder.height() as usize);
    let mut canvas = vec![255u8; 4 * width * height];
    let (mut frames, mut delays) = (Vec::new(), Vec::new());
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        assert!(matches!(frame.dispose, gif::DisposalMethod::Keep | gif::DisposalMethod::Any));
        let (left, top, w) = (frame.left as usize, frame.top as usize, frame.width as usize);
        for (i, px) in frame.buffer.chunks_exact(4).enumerate() {
            if px[3] != 0 {
                let at = 4 * ((top + i / w) * width + left + i % w);
                canvas[at..at + 4].copy_from_slice(px);
            }
        }
        frames.push(canvas.clone());
        delays.push(frame.delay);
    }
    Gif { width, height, frames, delays }
}

/// Centroid (px) of the pixels `pick` selects, with their count.
fn centroid(width: usize, rgba: &[u8], pick: impl Fn(&[u8]) -> bool) -> Option<(f64, f64)> {
    let (mut sx, mut sy, mut count) = (0.0, 0.0, 0.0);
    for (i, px) in rgba.chunks_exact(4).enumerate() {
        if pick(px) {
            sx += (i % width) as f64;
            sy += (i / width) as f64;
            count += 1.0;
        }
    }
    (count > 5.0).then(|| (sx / count, sy / count))
}

/// The mass dots (blue).
fn mass(px: &[u8]) -> bool {
    px[2] > 180 && px[0] < 80 && px[1] < 100
}

/// The pivot's square (red).
fn pivot(px: &[u8]) -> bool {
    px[0] > 180 && px[1] < 80 && px[2] < 80
}

fn ok(dir: &Path, args: &[&str]) -> String {
    let out = run_in(dir, args);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    stderr(&out)
}

#[test]
fn the_chain_is_drawn_where_the_trajectory_puts_it_at_one_scale() {
    let dir = scratch("render-2d");
    // One link of 1 m released from horizontal, 101 samples 10 ms apart.
    let run = ["simulate", "--n", "1", "--lengths", "1", "--initial", "horizontal", "--end", "1"];
    ok(&dir, &[&run[..], &["--step", "0.01", "--every", "1", "--no-plots", "--out", "run"]].concat());
    let said = ok(&dir, &["render", "run", "--frames", "21", "--speed", "1", "--size", "300"]);
    assert!(
        said.contains("run/chain.gif: 21 frames of 300×300 px, t = 0.00–1.00 s every 0.05 s, real time"),
        "{said}"
    );
    let gif = decode(&dir.join("run/chain.gif"));
    assert_eq!((gif.width, gif.height, gif.frames.len()), (300, 300, 21));
    assert!(gif.delays.iter().all(|&d| d == 5), "{:?}", gif.delays);
    let tr = Csv::read(&dir.join("run/trajectory.csv"));
    let (x, y) = (tr.column("x1"), tr.column("y1"));
    // The fixed pivot is one pixel (a, b); the mass sits at (a + s x, b − s y).
    let (a, b) = centroid(gif.width, &gif.frames[0], pivot).expect("a pivot");
    let drawn: Vec<(f64, f64)> =
        gif.frames.iter().map(|f| centroid(gif.width, f, mass).expect("a mass in every frame")).collect();
    let (mut num, mut den) = (0.0, 0.0);
    for (k, &(px, py)) in drawn.iter().enumerate() {
        let (xm, ym) = (x[5 * k], y[5 * k]);
        num += (px - a) * xm + (b - py) * ym;
        den += xm * xm + ym * ym;
    }
    let s = num / den;
    for (k, &(px, py)) in drawn.iter().enumerate() {
        let (ex, ey) = (a + s * x[5 * k], b - s * y[5 * k]);
        assert!(
            (px - ex).abs() < 2.0 && (py - ey).abs() < 2.0,
            "frame {k}: ({px}, {py}), expected ({ex}, {ey})"
        );
        let p = centroid(gif.width, &gif.frames[k], pivot).unwrap();
        assert!((p.0 - a).abs() < 0.5 && (p.1 - b).abs() < 0.5, "the pivot moved in frame {k}");
    }
    // The motion (x from 1 m to about −0.9 m) fills most of the plot's width.
    let spread =
        x.iter().fold(f64::NEG_INFINITY, |m, &v| m.max(v)) - x.iter().fold(f64::INFINITY, |m, &v| m.min(v));
    assert!(s * spread > 180.0, "{s} px/m");
    // The tip's trail is drawn (orange) in the last frame.
    let last = gif.frames.last().unwrap();
    let trail =
        last.chunks_exact(4).filter(|p| p[0] > 230 && (120..=220).contains(&p[1]) && p[2] < 150).count();
    assert!(trail > 50, "{trail} trail pixels");
}

/// The angle α from the vertical of a single link (length l) whirling rigidly with its
/// pivot on a circle of radius R at ω below resonance: tan α = ω² (R + l sin α) / g.
fn steady_angle(l: f64, r: f64, omega: f64, g: f64) -> f64 {
    let mut alpha = 0.0_f64;
    for _ in 0..200 {
        alpha = (omega * omega * (r + l * alpha.sin()) / g).atan();
    }
    alpha
}

#[test]
fn the_co_rotating_view_of_a_steady_whirl_stands_still_beside_its_axis() {
    let dir = scratch("render-whirl");
    let (l, r, omega) = (0.5, 0.1, 3.0);
    let alpha = steady_angle(l, r, omega, 9.81);
    std::fs::write(dir.join("steady.txt"), format!("{alpha:e} 0 0 {omega:e}\n")).unwrap();
    let args = [
        "simulate",
        "--dim",
        "3",
        "--n",
        "1",
        "--lengths",
        "0.5",
        "--initial",
        "steady.txt",
        "--drive",
        "circle",
    ];
    let more =
        ["--radius", "0.1", "--omega", "3", "--end", "2.5", "--step", "0.002", "--every", "5", "--no-plots"];
    ok(&dir, &[&args[..], &more[..], &["--out", "run"]].concat());
    // 251 samples 10 ms apart: 26 frames 0.1 s apart.
    ok(
        &dir,
        &["render", "run", "--view", "co-rotating", "--size", "300", "--frames", "26", "--out", "co.gif"],
    );
    ok(&dir, &["render", "run", "--view", "side", "--size", "300", "--frames", "26", "--out", "side.gif"]);
    let co = decode(&dir.join("co.gif"));
    let side = decode(&dir.join("side.gif"));
    assert_eq!((co.frames.len(), side.frames.len()), (26, 26));
    let spread = |gif: &Gif, pick: fn(&[u8]) -> bool| {
        let points: Vec<(f64, f64)> =
            gif.frames.iter().map(|f| centroid(gif.width, f, pick).unwrap()).collect();
        let range = |c: fn(&(f64, f64)) -> f64| {
            let v: Vec<f64> = points.iter().map(c).collect();
            v.iter().fold(f64::NEG_INFINITY, |m, &x| m.max(x))
                - v.iter().fold(f64::INFINITY, |m, &x| m.min(x))
        };
        (range(|p| p.0), range(|p| p.1), points[0])
    };
    let (dx, dy, m) = spread(&co, mass);
    assert!(dx < 1.5 && dy < 1.5, "the mass moves by ({dx}, {dy}) px in the co-rotating view");
    let (px, py, p) = spread(&co, pivot);
    assert!(px < 1.5 && py < 1.5, "the pivot moves by ({px}, {py}) px in the co-rotating view");
    let (side_dx, _, _) = spread(&side, mass);
    assert!(side_dx > 60.0, "the mass crosses the side view: {side_dx} px");
    // Consecutive co-rotating frames differ in the title only, but for a few pixels.
    let title = 40 * co.width * 4; // the top 40 rows
    for k in 1..co.frames.len() {
        let (a, b) = (&co.frames[k - 1][title..], &co.frames[k][title..]);
        let changed = a.chunks_exact(4).zip(b.chunks_exact(4)).filter(|(p, q)| p != q).count();
        assert!(changed < 200, "frame {k}: {changed} pixels changed below the title");
    }
    // The rotation axis (a grey dashed vertical) is at x' = 0: the pivot is R from it
    // and the mass R + l sin α, at the same scale.
    let first = &co.frames[0];
    let mut columns = vec![0usize; co.width];
    for (i, q) in first.chunks_exact(4).enumerate() {
        if q[..3] == [90, 90, 90] {
            columns[i % co.width] += 1;
        }
    }
    let axis = (0..co.width).max_by_key(|&c| columns[c]).unwrap() as f64;
    assert!(columns[axis as usize] > 50, "no axis drawn");
    let ratio = (p.0 - axis) / (m.0 - axis);
    let expected = r / (r + l * alpha.sin());
    assert!(
        (ratio - expected).abs() < 0.03,
        "pivot/mass distance from the axis {ratio}, expected {expected}"
    );
}

#[test]
fn the_top_view_zooms_onto_a_small_motion() {
    let dir = scratch("render-top");
    // A hanging chain barely swung by a 2 cm circle: seen from above, a few cm across.
    let args = [
        "simulate",
        "--dim",
        "3",
        "--n",
        "3",
        "--lengths",
        "0.2",
        "--initial",
        "hanging",
        "--drive",
        "circle",
    ];
    let more =
        ["--radius", "0.02", "--omega", "4", "--end", "2", "--step", "0.002", "--no-plots", "--out", "run"];
    ok(&dir, &[&args[..], &more[..]].concat());
    ok(&dir, &["render", "run", "--view", "top", "--size", "300", "--frames", "40"]);
    let gif = decode(&dir.join("run/chain.gif"));
    let centres: Vec<(f64, f64)> =
        gif.frames.iter().map(|f| centroid(gif.width, f, pivot).unwrap()).collect();
    let xs: Vec<f64> = centres.iter().map(|c| c.0).collect();
    let across =
        xs.iter().fold(f64::NEG_INFINITY, |m, &v| m.max(v)) - xs.iter().fold(f64::INFINITY, |m, &v| m.min(v));
    // The pivot's 4 cm circle spans a good part of the 236 px plot (the old viewport, ±0.67 m
    // at 300 px: 9 px).
    assert!(across > 45.0, "the pivot's circle is {across} px across");
}

#[test]
fn simulate_draws_its_gif_with_the_renderer_and_a_fast_drive_in_slow_motion() {
    let dir = scratch("render-simulate");
    // Kapitza-like: drive period 31.4 ms, samples 1 ms apart; P/8 = 3.9 ms gives 3 samples.
    let args = ["simulate", "--n", "1", "--lengths", "0.2", "--initial", "tilted:2.9", "--drive", "harmonic"];
    let more = ["--amplitude", "0.02", "--omega", "200", "--step", "0.0005", "--every", "2", "--end", "0.5"];
    let said = ok(&dir, &[&args[..], &more[..], &["--frames", "40", "--out", "run"]].concat());
    assert!(
        said.contains(
            "run/chain.gif: 40 frames of 600×600 px, t = 0.383–0.500 s every 0.003 s, 0.15× (slow motion)"
        ),
        "{said}"
    );
    assert!(said.contains("note: 10.5 frames per drive period"), "{said}");
    let gif = decode(&dir.join("run/chain.gif"));
    assert_eq!((gif.width, gif.frames.len()), (600, 40));
    assert!(gif.delays.iter().all(|&d| d == 2), "20 ms, the shortest delay browsers honour");
    // `render` with no options draws the same GIF, byte for byte.
    let drawn = std::fs::read(dir.join("run/chain.gif")).unwrap();
    ok(&dir, &["render", "run", "--quiet"]);
    assert!(std::fs::read(dir.join("run/chain.gif")).unwrap() == drawn, "render differs from simulate");
    // From --from, the first frames of the window instead of the last.
    let said = ok(&dir, &["render", "run", "--from", "0.1", "--out", "early.gif"]);
    assert!(said.contains("t = 0.100–0.217 s every 0.003 s"), "{said}");
    assert!(!dir.join("early.gif.partial").exists());
}

/// Runs `args` in `dir`; returns the exit code and the last line of stderr.
fn fails(dir: &Path, args: &[&str]) -> (Option<i32>, String) {
    let out = run_in(dir, args);
    let message = stderr(&out);
    assert!(!message.contains("panicked"), "{message}");
    assert_eq!(message.trim_end().lines().count(), 1, "one line: {message}");
    (out.status.code(), message.trim_end().to_owned())
}

fn usage(dir: &Path, args: &[&str], expected: &str) {
    let (code, message) = fails(dir, args);
    assert_eq!(code, Some(2), "{args:?}: {message}");
    assert_eq!(message, expected, "{args:?}");
}

#[test]
fn bad_inputs_get_one_line_and_exit_status_2() {
    let dir = scratch("render-bad");
    ok(
        &dir,
        &[
            "simulate",
            "--n",
            "2",
            "--end",
            "0.2",
            "--step",
            "0.01",
            "--every",
            "1",
            "--no-plots",
            "--out",
            "run",
        ],
    );
    let csv = std::fs::read_to_string(dir.join("run/trajectory.csv")).unwrap();
    let copy = |name: &str, trajectory: Option<&str>| {
        std::fs::create_dir_all(dir.join(name)).unwrap();
        std::fs::copy(dir.join("run/run.json"), dir.join(name).join("run.json")).unwrap();
        if let Some(text) = trajectory {
            std::fs::write(dir.join(name).join("trajectory.csv"), text).unwrap();
        }
    };
    std::fs::create_dir_all(dir.join("empty")).unwrap();
    usage(
        &dir,
        &["render", "empty"],
        "error: empty holds no run: no run.json (a run given --out DIR writes one)",
    );
    usage(
        &dir,
        &["render", "nowhere"],
        "error: nowhere is not a run directory (what a run given --out DIR writes)",
    );
    copy("half", None);
    usage(&dir, &["render", "half"], "error: half holds no run: no trajectory.csv beside its run.json");
    // Cut in the middle of line 6, and line 4 missing its last two fields.
    let lines: Vec<&str> = csv.lines().collect();
    copy("cut", Some(&format!("{}\n{}", lines[..5].join("\n"), &lines[5][..20])));
    usage(&dir, &["render", "cut"], "error: cut/trajectory.csv line 6: the line is cut short (no line end)");
    let short = lines[3].rsplitn(3, ',').last().unwrap();
    copy("short", Some(&format!("{}\n{short}\n{}\n", lines[..3].join("\n"), lines[4..].join("\n"))));
    usage(
        &dir,
        &["render", "short"],
        "error: short/trajectory.csv line 4: 9 fields, expected 11 (is the file cut short?)",
    );
    let mut fields: Vec<&str> = lines[2].split(',').collect();
    fields[7] = "abc";
    let bad = fields.join(",");
    copy("bad", Some(&format!("{}\n{bad}\n{}\n", lines[..2].join("\n"), lines[3..].join("\n"))));
    usage(
        &dir,
        &["render", "bad"],
        "error: bad/trajectory.csv line 3, column x1: 'abc' is not a finite number",
    );
    copy("headless", Some(""));
    usage(&dir, &["render", "headless"], "error: headless/trajectory.csv is empty (no header line)");
    copy("nothing", Some(&format!("{}\n", lines[0])));
    usage(&dir, &["render", "nothing"], "error: nothing/trajectory.csv holds no samples");

    usage(&dir, &["render", "run", "--from", "2", "--to", "1"], "error: --from 2 s must be before --to 1 s");
    usage(
        &dir,
        &["render", "run", "--from", "0.1", "--to", "0.1"],
        "error: --from 0.1 s must be before --to 0.1 s",
    );
    usage(
        &dir,
        &["render", "run", "--from", "5"],
        "error: --from 5 s is after the last sample of run/trajectory.csv (t = 0.2 s)",
    );
    usage(&dir, &["render", "run", "--from", "NaN"], "error: --from must be a finite time in s, got NaN");
    for (speed, shown) in [("0", "0"), ("-1", "-1"), ("NaN", "NaN"), ("inf", "inf")] {
        let expected = format!("error: --speed must be finite and positive, got {shown}");
        usage(&dir, &["render", "run", "--speed", speed], &expected);
    }
    for size in ["100", "5000", "-600"] {
        usage(
            &dir,
            &["render", "run", "--size", size],
            &format!("error: --size must be 240 to 2400 px, got {size}"),
        );
    }
    usage(&dir, &["render", "run", "--frames", "1"], "error: --frames must be 2 to 5000, got 1");
    usage(
        &dir,
        &["render", "run", "--view", "co-rotating"],
        "error: --view co-rotating: this is a 2D run; the co-rotating view needs a 3D run whose pivot \
         circles the vertical axis",
    );
    // 3D runs whose pivot does not circle: fixed, and shaken sideways.
    ok(&dir, &["simulate", "--dim", "3", "--n", "1", "--end", "0.1", "--no-plots", "--out", "fixed"]);
    usage(
        &dir,
        &["render", "fixed", "--view", "co-rotating"],
        "error: --view co-rotating: the pivot of fixed/trajectory.csv does not circle the vertical axis: \
         it is on the axis at t = 0 s",
    );
    let shaken =
        ["--drive", "harmonic", "--direction", "1,0,0", "--phase", "0.3", "--no-plots", "--out", "shaken"];
    ok(&dir, &[&["simulate", "--dim", "3", "--n", "1", "--end", "0.5"][..], &shaken[..]].concat());
    let (code, message) = fails(&dir, &["render", "shaken", "--view", "co-rotating"]);
    assert_eq!(code, Some(2));
    assert!(
        message.starts_with(
            "error: --view co-rotating: the pivot of shaken/trajectory.csv does not circle the vertical axis: \
             its azimuth jumps by 3.142 rad at t = "
        ),
        "{message}"
    );
    for name in ["run", "fixed", "shaken", "cut", "bad"] {
        assert!(!dir.join(name).join("chain.gif").exists(), "{name}: a failed render wrote a GIF");
        assert!(!dir.join(name).join("chain.gif.partial").exists(), "{name}: a partial GIF was left");
    }
}
