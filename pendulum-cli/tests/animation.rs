//! The animation shows the chain where the trajectory says it is: the masses' pixels in
//! frames of chain.gif sit at the projected positions of trajectory.csv.

mod common;

use common::{Csv, run_in, scratch, stderr};

/// The frames of a GIF as RGBA buffers, with the image width.
fn frames(path: &std::path::Path) -> (usize, Vec<Vec<u8>>) {
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options.read_info(std::fs::File::open(path).unwrap()).unwrap();
    let width = decoder.width() as usize;
    let height = decoder.height() as usize;
    let mut out = Vec::new();
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        // plotters writes whole frames.
        assert_eq!(
            (frame.width as usize, frame.height as usize, frame.left, frame.top),
            (width, height, 0, 0)
        );
        out.push(frame.buffer.to_vec());
    }
    (width, out)
}

/// Centroid (pixels) of the strongly blue pixels: the mass dots.
fn blue_centroid(width: usize, rgba: &[u8]) -> (f64, f64) {
    let (mut sx, mut sy, mut count) = (0.0, 0.0, 0.0);
    for (i, px) in rgba.chunks_exact(4).enumerate() {
        if px[2] > 180 && px[0] < 80 && px[1] < 80 {
            sx += (i % width) as f64;
            sy += (i / width) as f64;
            count += 1.0;
        }
    }
    assert!(count > 10.0, "no mass drawn");
    (sx / count, sy / count)
}

#[test]
fn the_mass_in_the_gif_is_where_the_trajectory_puts_it() {
    let dir = scratch("animation");
    // One link of 1 m from horizontal: it starts at (1, 0) and swings down and left.
    let args = [
        "simulate",
        "--n",
        "1",
        "--lengths",
        "1",
        "--initial",
        "horizontal",
        "--end",
        "0.6",
        "--step",
        "0.01",
    ];
    let out = run_in(&dir, &[&args[..], &["--every", "1", "--frames", "100", "--out", "run"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let (width, frames) = frames(&dir.join("run/chain.gif"));
    let tr = Csv::read(&dir.join("run/trajectory.csv"));
    assert_eq!(frames.len(), tr.rows.len(), "one frame per sample here");
    let (x, y) = (tr.column("x1"), tr.column("y1"));
    // The drawing maps [−r, r]² (r = 1.08 × reach) onto the square inside an 8-pixel margin.
    let r = 1.08;
    let span = width as f64 - 16.0;
    let to_pixel = |x: f64, y: f64| (8.0 + (x + r) / (2.0 * r) * span, 8.0 + (r - y) / (2.0 * r) * span);
    for k in [0, 20, 40, 60] {
        let (px, py) = blue_centroid(width, &frames[k]);
        let (ex, ey) = to_pixel(x[k], y[k]);
        assert!(
            (px - ex).abs() < 3.0 && (py - ey).abs() < 3.0,
            "frame {k}: drawn at ({px}, {py}), expected ({ex}, {ey})"
        );
    }
    // And the physics: released at rest from horizontal, after 0.6 s it is left of where it
    // started and below the pivot.
    assert!(x[60] < x[0] && y[60] < -0.5, "{} {}", x[60], y[60]);
}
