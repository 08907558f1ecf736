//! Branch diagrams of the rotating chain: steady shapes with k = 1, 2, 3 nodes, their
//! amplitude against the angular speed, and their stability.
//!
//! ```text
//! cargo run --release -p pendulum-tests --example rotating_chain
//! ```
//!
//! writes `docs/rotating-branches.svg` (free pivot), `docs/rotating-forced.svg` (pivot on
//! a circle of radius R = 0.02 L) and their data in `docs/data/rotating-*.csv`, and prints
//! the critical speeds and the stable stretches of each branch. Line styles: thick solid =
//! stable with any small damping (index 0), thin solid = spectrally stable only
//! (gyroscopically stabilised; damping destabilises it), dashed = unstable; colour = the
//! shape's node count.

use std::{error::Error, fmt::Write as _, fs, path::PathBuf};

use nalgebra::{DVector, Dyn};
use pendulum_core::{Branch, Chain, ContinuationOptions, SteadyRotation, SteadyShape, stability};
use plotters::prelude::*;

/// Links of the chain (uniform, total length 1 m, total mass 1 kg, g = 9.81 m/s²).
const LINKS: usize = 30;
const LENGTH: f64 = 1.0;
const GRAVITY: f64 = 9.81;
/// Pivot circle radius of the forced diagram, as a fraction of the length.
const FORCED_RADIUS: f64 = 0.02;
/// The diagrams run up to this multiple of the third critical speed.
const SPAN: f64 = 1.6;

/// Stability class of one steady shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Class {
    /// Index 0: stable with or without small damping.
    Stable,
    /// Spectrally stable, index > 0: gyroscopically stabilised, destabilised by damping.
    Gyroscopic,
    /// An eigenvalue with positive real part.
    Unstable,
}

impl Class {
    fn name(self) -> &'static str {
        match self {
            Class::Stable => "stable",
            Class::Gyroscopic => "gyroscopic",
            Class::Unstable => "unstable",
        }
    }
}

struct Point {
    omega: f64,
    amplitude: f64,
    nodes: usize,
    growth: f64,
    /// |Im| of the eigenvalue with the largest real part, rad/s.
    growth_frequency: f64,
    index: usize,
    class: Class,
}

/// The largest displacement from the axis with its sign (the side of the axis it is on).
fn signed_amplitude(s: &SteadyShape) -> f64 {
    s.displacements.iter().copied().fold(0.0, |a: f64, x| if x.abs() > a.abs() { x } else { a })
}

fn classify(problem: &SteadyRotation, branch: &Branch, signed: bool) -> Result<Vec<Point>, Box<dyn Error>> {
    branch
        .points
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let st = stability(problem, s, None)?;
            let class = match (st.spectrally_stable, st.index) {
                (true, 0) => Class::Stable,
                (true, _) => Class::Gyroscopic,
                (false, _) => Class::Unstable,
            };
            let worst =
                st.eigenvalues.iter().max_by(|a, b| a.re.total_cmp(&b.re)).map_or(0.0, |z| z.im.abs());
            let amplitude = if signed { signed_amplitude(s) } else { s.amplitude() };
            // A bifurcation point (on the vertical) takes the node count of its branch.
            let shown = if s.amplitude() == 0.0 { branch.points.get(i + 1).unwrap_or(s) } else { s };
            Ok(Point {
                omega: s.omega,
                amplitude,
                nodes: shown.nodes(),
                growth: st.growth_rate,
                growth_frequency: worst,
                index: st.index,
                class,
            })
        })
        .collect()
}

/// A stretch of a branch: class, node count, points (ω / sqrt(g/L), amplitude / L).
type Run = (Class, usize, Vec<(f64, f64)>);

/// Runs of consecutive points of one class and node count (each run shares its end
/// point with the next).
fn runs(points: &[Point]) -> Vec<Run> {
    let mut out: Vec<Run> = Vec::new();
    let scale = (GRAVITY / LENGTH).sqrt();
    for p in points {
        let xy = (p.omega / scale, p.amplitude / LENGTH);
        match out.last_mut() {
            Some((class, nodes, run)) if *class == p.class && *nodes == p.nodes => run.push(xy),
            Some((_, _, run)) => {
                let last = *run.last().expect("runs are never empty");
                out.push((p.class, p.nodes, vec![last, xy]));
            }
            None => out.push((p.class, p.nodes, vec![xy])),
        }
    }
    out
}

/// A summary of the stretches of one branch: "stable 1.23–4.56; unstable 4.56–7.89".
fn stretches(points: &[Point]) -> String {
    let mut s = String::new();
    for (class, nodes, run) in runs(points) {
        let (a, b) = (run.first().expect("non-empty").0, run.last().expect("non-empty").0);
        let _ = write!(s, "{} ({nodes} nodes) {:.3}–{:.3}; ", class.name(), a.min(b), a.max(b));
    }
    s.trim_end_matches("; ").to_string()
}

fn csv(rows: &[(String, &[Point])]) -> String {
    let mut out = String::from(
        "branch,omega_rad_s,amplitude_m,nodes,growth_rate_1_s,growth_frequency_rad_s,index,class\n",
    );
    for (name, points) in rows {
        for p in points.iter() {
            let _ = writeln!(
                out,
                "{name},{:.9},{:.9},{},{:.3e},{:.4},{},{}",
                p.omega,
                p.amplitude,
                p.nodes,
                p.growth,
                p.growth_frequency,
                p.index,
                p.class.name()
            );
        }
    }
    out
}

fn colour(k: usize) -> RGBColor {
    [
        RGBColor(0, 90, 181),
        RGBColor(220, 50, 32),
        RGBColor(0, 140, 70),
        RGBColor(120, 80, 160),
        RGBColor(230, 150, 0),
    ][(k + 4) % 5]
}

fn plot(
    path: &PathBuf,
    title: &str,
    y_label: &str,
    y_range: std::ops::Range<f64>,
    branches: &[&[Point]],
    critical: &[f64],
) -> Result<(), Box<dyn Error>> {
    let scale = (GRAVITY / LENGTH).sqrt();
    let x_max = SPAN * critical[2] / scale;
    let root = SVGBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..x_max, y_range.clone())?;
    chart
        .configure_mesh()
        .x_desc("angular speed ω / sqrt(g/L)")
        .y_desc(y_label)
        .light_line_style(WHITE.mix(0.0))
        .draw()?;
    for &w in critical {
        let x = w / scale;
        chart.draw_series(DashedLineSeries::new(
            [(x, y_range.start), (x, y_range.end)],
            3,
            5,
            BLACK.mix(0.3).stroke_width(1),
        ))?;
    }
    let mut labelled = [false; 8];
    for points in branches {
        for (class, nodes, run) in runs(points) {
            let c = colour(nodes);
            let series = match class {
                Class::Stable => chart.draw_series(LineSeries::new(run, c.stroke_width(3)))?,
                Class::Gyroscopic => chart.draw_series(LineSeries::new(run, c.stroke_width(1)))?,
                Class::Unstable => chart.draw_series(DashedLineSeries::new(run, 6, 4, c.stroke_width(2)))?,
            };
            if nodes < labelled.len() && !labelled[nodes] {
                labelled[nodes] = true;
                series
                    .label(format!("{nodes} node{}", if nodes == 1 { "" } else { "s" }))
                    .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], c.stroke_width(3)));
            }
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK.mix(0.4))
        .position(SeriesLabelPosition::UpperLeft)
        .draw()?;
    root.present()?;
    Ok(())
}

fn main() -> Result<(), Box<dyn Error>> {
    // Labels are laid out with the embedded Ubuntu Light (plotters' ab_glyph backend).
    let _ = plotters::style::register_font(
        "sans-serif",
        plotters::style::FontStyle::Normal,
        epaint_default_fonts::UBUNTU_LIGHT,
    );
    let docs = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs");
    fs::create_dir_all(docs.join("data"))?;
    let chain = Chain::<Dyn>::uniform(LINKS, 1.0 / LINKS as f64, LENGTH / LINKS as f64, GRAVITY)?;
    let opts = ContinuationOptions::default();
    let scale = (GRAVITY / LENGTH).sqrt();

    // Free pivot: the branches leaving the vertical.
    let free = SteadyRotation::new(&chain, 0.0)?;
    let critical = free.bifurcation_speeds(3)?;
    let omega_max = SPAN * critical[2];
    println!("uniform chain, n = {LINKS}, L = {LENGTH} m, g = {GRAVITY} m/s², sqrt(g/L) = {scale:.6} rad/s");
    let mut free_branches = Vec::new();
    for k in 1..=3 {
        let branch = free.branch(k, omega_max, &opts)?;
        let points = classify(&free, &branch, false)?;
        println!(
            "k = {k}: leaves the vertical at ω = {:.6} rad/s = {:.6} sqrt(g/L); {} points, end {:?}",
            critical[k - 1],
            critical[k - 1] / scale,
            points.len(),
            branch.end
        );
        println!("        in units of sqrt(g/L): {}", stretches(&points));
        free_branches.push((k, points, branch.points.last().expect("branches have points").clone()));
    }
    let rows: Vec<(String, &[Point])> =
        free_branches.iter().map(|(k, p, _)| (format!("free k={k}"), p.as_slice())).collect();
    fs::write(docs.join("data/rotating-branches.csv"), csv(&rows))?;
    plot(
        &docs.join("rotating-branches.svg"),
        &format!("Steady rotation of a uniform {LINKS}-link chain (free pivot)"),
        "amplitude max|x_i| / L",
        0.0..1.0,
        &free_branches.iter().map(|(_, p, _)| p.as_slice()).collect::<Vec<_>>(),
        &critical,
    )?;

    // Forced: pivot on a circle of radius R. From rest upwards, and from each free
    // branch's end shape (both signs) downwards; the forced branches fold.
    let radius = FORCED_RADIUS * LENGTH;
    let forced = SteadyRotation::new(&chain, radius)?;
    let mut forced_branches: Vec<(String, Vec<Point>)> = Vec::new();
    let from_rest =
        forced.continue_from(&forced.solve(0.0, &DVector::zeros(LINKS))?, true, omega_max, &opts)?;
    let points = classify(&forced, &from_rest, true)?;
    println!("forced R = {radius} m, from rest: {} points, end {:?}", points.len(), from_rest.end);
    println!("        in units of sqrt(g/L): {}", stretches(&points));
    forced_branches.push(("forced from rest".into(), points));
    for (k, _, last) in &free_branches {
        for sign in [1.0, -1.0] {
            let start = forced.solve(0.99 * omega_max, &(&last.theta * sign))?;
            let branch = forced.continue_from(&start, false, omega_max, &opts)?;
            let points = classify(&forced, &branch, true)?;
            let name = format!("forced from free k={k} sign {sign:+}");
            println!("{name}: {} points, end {:?}", points.len(), branch.end);
            println!("        in units of sqrt(g/L): {}", stretches(&points));
            forced_branches.push((name, points));
        }
    }
    let rows: Vec<(String, &[Point])> =
        forced_branches.iter().map(|(n, p)| (n.clone(), p.as_slice())).collect();
    fs::write(docs.join("data/rotating-forced.csv"), csv(&rows))?;
    let forced_plot: Vec<&[Point]> = forced_branches.iter().map(|(_, p)| p.as_slice()).collect();
    plot(
        &docs.join("rotating-forced.svg"),
        &format!("Steady rotation with the pivot on a circle, R = {FORCED_RADIUS} L"),
        "signed amplitude x / L (pivot side +)",
        -1.0..1.0,
        &forced_plot,
        &critical,
    )?;
    println!("wrote docs/rotating-branches.svg, docs/rotating-forced.svg, docs/data/rotating-*.csv");
    Ok(())
}
