//! `pendulum steady`: the chain turning steadily about the vertical (the branches of
//! shapes as a table and branches.csv, the branch diagram and the shapes as plots).

use std::io::Write;
use std::path::Path;

use nalgebra::{DVector, Dyn};
use pendulum_core::{Branch, BranchEnd, Chain, ContinuationOptions, SteadyRotation, SteadyShape};
use plotters::prelude::*;

use crate::args::SteadyArgs;
use crate::chain_args::chain_of;
use crate::error::{CliError, CliResult, io_failed};
use crate::plot::{drawing_failed, fonts};

/// Runs `pendulum steady`.
pub fn steady(args: &SteadyArgs) -> CliResult<()> {
    let chain = chain_of(&args.chain)?;
    let n = chain.links();
    let problem = SteadyRotation::new(&chain, args.radius)?;
    let reference = problem.reference_speed();
    let options = ContinuationOptions::default();
    let mut branches: Vec<(String, Option<f64>, Branch)> = Vec::new();
    let omega_max;
    if args.radius == 0.0 {
        let count = args.branches.unwrap_or(n.min(3));
        if count == 0 || count > n {
            return Err(CliError::usage(format!("--branches must be between 1 and n = {n}, got {count}")));
        }
        let speeds = problem.bifurcation_speeds(count)?;
        omega_max = args.omega_max.unwrap_or(1.5 * speeds[count - 1]);
        check_omega_max(omega_max)?;
        for (k, &speed) in speeds.iter().enumerate() {
            if speed >= omega_max {
                continue;
            }
            let branch = problem.branch(k + 1, omega_max, &options)?;
            branches.push((format!("{} node{}", k + 1, if k == 0 { "" } else { "s" }), Some(speed), branch));
        }
    } else {
        if args.branches.is_some() {
            return Err(CliError::usage("--branches applies to a fixed pivot (--radius 0) only"));
        }
        omega_max = args.omega_max.unwrap_or(3.0 * reference);
        check_omega_max(omega_max)?;
        // The forced branch from slow rotation: near the vertical, pushed out by the pivot.
        let start = problem.solve(0.05 * reference, &DVector::zeros(n))?;
        let branch = problem.continue_from(&start, true, omega_max, &options)?;
        branches.push(("forced".into(), None, branch));
        // The branches not connected to slow rotation (they fold back): from the free
        // chain's shapes at omega_max, on either side of the axis, followed downward.
        let free = SteadyRotation::new(&chain, 0.0)?;
        let count = n.min(3);
        for k in 1..=count {
            let Ok(free_branch) = free.branch(k, omega_max, &options) else { continue };
            let Some(shape) = free_branch.points.last() else { continue };
            for sign in [1.0, -1.0] {
                let Ok(start) = problem.solve(omega_max, &(&shape.theta * sign)) else { continue };
                let known = branches.iter().any(|(_, _, b)| {
                    b.points.iter().any(|p| {
                        (p.omega - start.omega).abs() < 1e-6 * omega_max
                            && (&p.theta - &start.theta).amax() < 1e-6
                    }) || b.points.windows(2).any(|w| near_segment(&w[0], &w[1], &start))
                });
                if known {
                    continue;
                }
                if let Ok(branch) = problem.continue_from(&start, false, omega_max, &options) {
                    branches.push((format!("forced {}", branches.len() + 1), None, branch));
                }
            }
        }
    }
    std::fs::create_dir_all(&args.out).map_err(|e| {
        CliError::usage(format!("--out: cannot create the directory {}: {e}", args.out.display()))
    })?;
    write_branches(&args.out.join("branches.csv"), &branches, n)?;
    print_branches(&branches, reference);
    plot_branches(&args.out.join("branches.png"), &branches, omega_max, args.radius)?;
    plot_shapes(&args.out.join("shapes.png"), &problem, &chain, &branches, omega_max)?;
    eprintln!(
        "pendulum: {} branch{} up to ω = {omega_max:.4} rad/s; files in {} (branches.csv, branches.png, shapes.png)",
        branches.len(),
        if branches.len() == 1 { "" } else { "es" },
        args.out.display()
    );
    Ok(())
}

/// `shape` lies on the branch segment between `a` and `b` (same ω range, angles within
/// 0.02 rad of the linear interpolation: continuation steps are coarse, distinct branches
/// are much farther apart).
fn near_segment(a: &SteadyShape, b: &SteadyShape, shape: &SteadyShape) -> bool {
    let (lo, hi) = if a.omega <= b.omega { (a, b) } else { (b, a) };
    if !(lo.omega <= shape.omega && shape.omega <= hi.omega) || hi.omega == lo.omega {
        return false;
    }
    let s = (shape.omega - lo.omega) / (hi.omega - lo.omega);
    let interpolated = &lo.theta * (1.0 - s) + &hi.theta * s;
    (&interpolated - &shape.theta).amax() < 0.02
}

fn check_omega_max(omega_max: f64) -> CliResult<()> {
    if omega_max.is_finite() && omega_max > 0.0 {
        Ok(())
    } else {
        Err(CliError::usage(format!("--omega-max must be finite and positive, got {omega_max}")))
    }
}

fn end_reason(end: BranchEnd) -> &'static str {
    match end {
        BranchEnd::ReachedOmega => "reached --omega-max",
        BranchEnd::ReachedZeroOmega => "returned to ω = 0",
        BranchEnd::StepTooSmall => "continuation step became too small",
        BranchEnd::MaxPoints => "point limit reached",
    }
}

fn print_branches(branches: &[(String, Option<f64>, Branch)], reference: f64) {
    println!("reference speed sqrt(g/L) = {reference:.6} rad/s");
    println!("branch     leaves vertical at (rad/s)   points   last ω (rad/s)   last amplitude (m)   end");
    for (name, speed, branch) in branches {
        let last = branch.points.last();
        let speed = speed.map_or("-".to_string(), |s| format!("{s:.6}"));
        println!(
            "{name:<10} {speed:>27}   {:>6}   {:>14.6}   {:>18.6}   {}",
            branch.points.len(),
            last.map_or(f64::NAN, |p| p.omega),
            last.map_or(f64::NAN, SteadyShape::amplitude),
            end_reason(branch.end)
        );
    }
}

fn write_branches(path: &Path, branches: &[(String, Option<f64>, Branch)], n: usize) -> CliResult<()> {
    let file = std::fs::File::create(path).map_err(|e| io_failed("create", path, e))?;
    let mut csv = std::io::BufWriter::new(file);
    let write_err = |e| io_failed("write", path, e);
    let mut header = vec!["branch".to_string(), "omega".into(), "amplitude".into(), "nodes".into()];
    header.extend((1..=n).map(|i| format!("theta{i}")));
    header.extend((1..=n).map(|i| format!("x{i}")));
    writeln!(csv, "{}", header.join(",")).map_err(write_err)?;
    for (b, (_, _, branch)) in branches.iter().enumerate() {
        for p in &branch.points {
            let values = [(b + 1) as f64, p.omega, p.amplitude(), p.nodes() as f64]
                .into_iter()
                .chain(p.theta.iter().copied())
                .chain(p.displacements.iter().copied());
            let row: Vec<String> = values.map(|v| format!("{v:?}")).collect();
            writeln!(csv, "{}", row.join(",")).map_err(write_err)?;
        }
    }
    csv.flush().map_err(write_err)
}

const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(140, 86, 75),
];

/// The branch diagram: the signed distance of the free end from the axis, `x_n` (m),
/// against `ω` (rad/s); the vertical (`x_n = 0`) in grey for a fixed pivot.
fn plot_branches(
    path: &Path,
    branches: &[(String, Option<f64>, Branch)],
    omega_max: f64,
    radius: f64,
) -> CliResult<()> {
    fonts();
    let fail = |e: &dyn std::fmt::Display| drawing_failed(path, e);
    let root = BitMapBackend::new(path, (640, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let tip = |p: &SteadyShape| *p.displacements.last().unwrap_or(&0.0);
    let reach = branches
        .iter()
        .flat_map(|(_, _, b)| b.points.iter().map(|p| tip(p).abs()))
        .fold(radius.abs(), f64::max)
        .max(1e-3);
    let mut chart = ChartBuilder::on(&root)
        .caption("steady rotation: free end's distance from the axis", ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..omega_max, -1.1 * reach..1.1 * reach)
        .map_err(|e| fail(&e))?;
    chart
        .configure_mesh()
        .x_desc("ω (rad/s)")
        .y_desc("x_n (m)")
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| fail(&e))?;
    if radius == 0.0 {
        chart
            .draw_series(LineSeries::new(
                [(0.0, 0.0), (omega_max, 0.0)],
                RGBColor(150, 150, 150).stroke_width(2),
            ))
            .map_err(|e| fail(&e))?
            .label("vertical")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RGBColor(150, 150, 150)));
    }
    for (i, (name, _, branch)) in branches.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        let points: Vec<(f64, f64)> = branch.points.iter().map(|p| (p.omega, tip(p))).collect();
        chart
            .draw_series(LineSeries::new(points.iter().copied(), color.stroke_width(2)))
            .map_err(|e| fail(&e))?
            .label(name.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
        if radius == 0.0 {
            // The mirror branch (θ → −θ) is a solution too.
            chart
                .draw_series(LineSeries::new(
                    points.iter().map(|&(w, x)| (w, -x)),
                    color.mix(0.4).stroke_width(1),
                ))
                .map_err(|e| fail(&e))?;
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 13))
        .draw()
        .map_err(|e| fail(&e))?;
    root.present().map_err(|e| fail(&e))
}

/// The shape of each branch at the largest speed it reached (or `omega_max`): masses at
/// `(x_i, z_i)`, `z_i = −Σ_{j≤i} l_j cos θ_j`, in the turning plane.
fn plot_shapes(
    path: &Path,
    problem: &SteadyRotation,
    chain: &Chain<Dyn>,
    branches: &[(String, Option<f64>, Branch)],
    omega_max: f64,
) -> CliResult<()> {
    fonts();
    let fail = |e: &dyn std::fmt::Display| drawing_failed(path, e);
    let root = BitMapBackend::new(path, (480, 480)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let total: f64 = chain.lengths().iter().sum();
    let r = 1.1 * (total + problem.radius());
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("shapes at the last ω of each branch (≤ {omega_max:.3} rad/s)"), ("sans-serif", 15))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(40)
        .build_cartesian_2d(-r..r, -r..0.2 * r)
        .map_err(|e| fail(&e))?;
    chart.configure_mesh().x_desc("x (m)").y_desc("z (m)").draw().map_err(|e| fail(&e))?;
    chart
        .draw_series(LineSeries::new([(0.0, 0.2 * r), (0.0, -r)], RGBColor(180, 180, 180)))
        .map_err(|e| fail(&e))?;
    for (i, (name, _, branch)) in branches.iter().enumerate() {
        let Some(shape) = branch.points.last() else { continue };
        let color = PALETTE[i % PALETTE.len()];
        let mut z = 0.0;
        let mut points = vec![(problem.radius(), 0.0)];
        for (l, (theta, x)) in chain.lengths().iter().zip(shape.theta.iter().zip(&shape.displacements)) {
            z -= l * theta.cos();
            points.push((*x, z));
        }
        chart
            .draw_series(LineSeries::new(points.iter().copied(), color.stroke_width(2)))
            .map_err(|e| fail(&e))?
            .label(format!("{name}, ω = {:.3}", shape.omega))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
        chart
            .draw_series(points[1..].iter().map(|&p| Circle::new(p, 3, color.filled())))
            .map_err(|e| fail(&e))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| fail(&e))?;
    root.present().map_err(|e| fail(&e))
}
