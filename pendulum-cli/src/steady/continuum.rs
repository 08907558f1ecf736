//! `pendulum steady --continuum`: Kolodner's heavy rotating string of the chain's length
//! and gravity ([`RotatingString`]) — its critical speeds, its steady shapes at the
//! `--omega` speeds (stdout, continuum.csv) and its branches, tip radius against ω up to
//! `--omega-max` (continuum.png); and how uniform chains of 10 to 1000 links of the same
//! length and mass approach it (convergence.png).

use nalgebra::Dyn;
use pendulum_core::{Chain, RotatingString, SteadyRotation, StringShape};
use pendulum_experiment::Csv;
use pendulum_experiment::csv::number;
use pendulum_experiment::words::round;
use plotters::prelude::*;

use super::{DEFAULT_MARGIN, check_omega_max, parse_speeds, plots::colour, round_up};
use crate::args::SteadyArgs;
use crate::error::{CliError, CliResult};
use crate::plot::{drawing_failed, fonts, key};

/// Speeds of the branch diagram.
const DIAGRAM_SPEEDS: usize = 240;

/// Runs `pendulum steady --continuum` for the string of `chain`'s length and gravity.
pub fn run(args: &SteadyArgs, chain: &Chain<Dyn>) -> CliResult<()> {
    if args.damping.is_some() || args.branches.is_some() {
        return Err(CliError::invalid(
            "--continuum: --damping and --branches apply to the chain, not to the string",
        ));
    }
    let length: f64 = chain.lengths().iter().sum();
    let string = RotatingString::new(length, chain.gravity(), args.radius)?;
    let critical = string.critical_speeds(3);
    let listed = args.omega.as_deref().map(parse_speeds).transpose()?;
    let omega_max = match args.omega_max {
        Some(w) => {
            check_omega_max(w)?;
            w
        }
        None => listed.iter().flatten().fold(round_up(DEFAULT_MARGIN * critical[2]), |a, &b| a.max(b)),
    };
    let speeds = listed.unwrap_or_else(|| vec![omega_max]);
    let pivot = if args.radius == 0.0 {
        "top fixed".to_string()
    } else {
        format!("top on a circle of radius {} m", args.radius)
    };
    println!(
        "heavy string (Kolodner) of length L = {} m, g = {} m/s², the continuum of the chain of {} links; {pivot}",
        round(length),
        chain.gravity(),
        chain.links()
    );
    let list: Vec<String> = critical.iter().map(|w| format!("{w:.6}")).collect();
    println!(
        "critical speeds ω_k = (j_0k/2)·√(g/L) (rad/s): {} (√(g/L) = {:.6} rad/s)",
        list.join(", "),
        (chain.gravity() / length).sqrt()
    );
    crate::args::create_out(&args.out)?;
    let mut found = Vec::new();
    for &omega in &speeds {
        found.extend(string.shapes_at(omega)?);
    }
    table(&found, args.radius);
    csv(&args.out.join("continuum.csv"), &found)?;
    let png = args.out.join("continuum.png");
    diagram(&png, &string, omega_max, &critical, args.radius, length)?;
    let mass: f64 = chain.masses().iter().sum();
    let tip_speed = speeds.iter().copied().find(|&w| w > critical[0] && args.radius == 0.0);
    let tip = match tip_speed {
        Some(w) => string.shapes_at(w)?.into_iter().find(|s| s.nodes == 1),
        None => None,
    };
    let errors = approach(length, mass, chain.gravity(), &critical, tip.as_ref())?;
    convergence(&args.out.join("convergence.png"), &errors, tip.as_ref().map(|t| t.omega), length)?;
    eprintln!(
        "pendulum: {} shape{} of the string at {} speed{}; files in {} (continuum.csv, continuum.png, convergence.png)",
        found.len(),
        if found.len() == 1 { "" } else { "s" },
        speeds.len(),
        if speeds.len() == 1 { "" } else { "s" },
        args.out.display()
    );
    Ok(())
}

/// The shapes on stdout: speed, nodes, tip radius and side.
fn table(found: &[StringShape], radius: f64) {
    println!();
    println!(
        "steady shapes of the string (nodes = axis crossings + 1, the top counted; tip radius = the free end's distance from the axis)"
    );
    println!("ω (rad/s)     nodes  tip radius (m)  tip side");
    for s in found {
        let side = if radius == 0.0 {
            "either (mirror images)"
        } else if s.tip > 0.0 {
            "pivot's"
        } else {
            "opposite"
        };
        println!("{:<12}  {:>5}  {:>14.6}  {side}", s.omega, s.nodes, s.tip_radius());
    }
}

/// continuum.csv: one row per shape (omega, nodes, signed tip, tip radius).
fn csv(path: &std::path::Path, found: &[StringShape]) -> CliResult<()> {
    let mut csv = Csv::create(path, &["omega", "nodes", "tip_signed", "tip_radius"])?;
    for s in found {
        csv.fields(&[number(s.omega), s.nodes.to_string(), number(s.tip), number(s.tip_radius())])?;
    }
    csv.finish()
}

/// continuum.png: the tip radius of every steady shape against ω (colour: node count),
/// the critical speeds marked.
fn diagram(
    path: &std::path::Path,
    string: &RotatingString,
    omega_max: f64,
    critical: &[f64],
    radius: f64,
    length: f64,
) -> CliResult<()> {
    fonts();
    let fail = |e: &dyn std::fmt::Display| drawing_failed(path, e);
    let mut points: Vec<(f64, f64, usize)> = Vec::new();
    for i in 1..=DIAGRAM_SPEEDS {
        let omega = omega_max * i as f64 / DIAGRAM_SPEEDS as f64;
        for s in string.sketch_at(omega)? {
            points.push((omega, s.tip_radius(), s.nodes));
        }
    }
    let root = BitMapBackend::new(path, (760, 520)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let top = points.iter().map(|p| p.1).fold(length, f64::max) * 1.05;
    let caption = if radius == 0.0 {
        format!("heavy string of length {} m, top fixed: tip radius of the steady shapes", round(length))
    } else {
        format!("heavy string of length {} m, top on a circle of radius {radius} m", round(length))
    };
    let mut chart = ChartBuilder::on(&root)
        .caption(caption, ("sans-serif", 17))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..omega_max, 0.0..top)
        .map_err(|e| fail(&e))?;
    chart
        .configure_mesh()
        .x_desc("ω (rad/s)")
        .y_desc("tip radius (m)")
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| fail(&e))?;
    for (k, &w) in critical.iter().enumerate().filter(|(_, w)| **w <= omega_max) {
        let grey = RGBColor(150, 150, 150);
        chart
            .draw_series(DashedLineSeries::new(vec![(w, 0.0), (w, top)], 6, 5, grey.stroke_width(1)))
            .map_err(|e| fail(&e))?;
        chart
            .draw_series(std::iter::once(Text::new(
                format!("ω_{}", k + 1),
                (w, top * 0.97),
                ("sans-serif", 13),
            )))
            .map_err(|e| fail(&e))?;
    }
    let most = points.iter().map(|p| p.2).max().unwrap_or(1);
    for nodes in 1..=most {
        let c = colour(Some(nodes));
        chart
            .draw_series(
                points.iter().filter(|p| p.2 == nodes).map(|&(w, r, _)| Circle::new((w, r), 2, c.filled())),
            )
            .map_err(|e| fail(&e))?
            .label(if nodes == 1 { "1 node".to_string() } else { format!("{nodes} nodes") })
            .legend(move |(x, y)| Circle::new((x + 8, y), 4, c.filled()));
    }
    key(&mut chart, SeriesLabelPosition::UpperLeft, path)?;
    root.present().map_err(|e| fail(&e))
}

/// Link counts of the convergence picture.
const SIZES: [usize; 7] = [10, 20, 50, 100, 200, 500, 1000];

/// One chain of the convergence picture: its link count, the relative errors of its first
/// three critical speeds against the string's, and of its one-node tip radius (if asked).
struct Approach {
    links: usize,
    speeds: [f64; 3],
    tip: Option<f64>,
}

/// The uniform chains of [`SIZES`] links with the string's length `length` (m), mass
/// `mass` (kg) and gravity: their critical speeds ([`SteadyRotation::bifurcation_speeds`],
/// O(n) per bisection step) and, for a fixed top, the tip radius of the one-node shape at
/// the speed of `tip` (Newton from the string's shape), each as `(chain − string) / string`.
fn approach(
    length: f64,
    mass: f64,
    gravity: f64,
    critical: &[f64],
    tip: Option<&StringShape>,
) -> CliResult<Vec<Approach>> {
    SIZES
        .iter()
        .map(|&n| {
            let chain = Chain::<Dyn>::uniform(n, mass / n as f64, length / n as f64, gravity)?;
            let problem = SteadyRotation::new(&chain, 0.0)?;
            let found = problem.bifurcation_speeds(3.min(n))?;
            let mut speeds = [f64::NAN; 3];
            for (k, w) in found.iter().enumerate() {
                speeds[k] = (w - critical[k]) / critical[k];
            }
            let tip = match tip {
                Some(shape) => {
                    // The string's points at the link ends, then the link angles between them.
                    let steps = shape.x.len() - 1;
                    let at = |i: usize| {
                        let k = (i * steps + n / 2) / n;
                        (shape.x[k], shape.depth[k])
                    };
                    let guess = nalgebra::DVector::from_fn(n, |i, _| {
                        let ((x0, d0), (x1, d1)) = (at(i), at(i + 1));
                        (x1 - x0).atan2(d1 - d0)
                    });
                    let found = problem.solve(shape.omega, &guess)?;
                    let radius = found.displacements.last().map_or(0.0, |x| x.abs());
                    Some((radius - shape.tip_radius()) / shape.tip_radius())
                }
                None => None,
            };
            Ok(Approach { links: n, speeds, tip })
        })
        .collect()
}

/// convergence.png: `|chain − string| / string` against the link count on log–log axes,
/// for the first three critical speeds and the one-node tip radius at `tip_speed`, with the
/// slope of `1/n`.
fn convergence(
    path: &std::path::Path,
    errors: &[Approach],
    tip_speed: Option<f64>,
    length: f64,
) -> CliResult<()> {
    fonts();
    let fail = |e: &dyn std::fmt::Display| drawing_failed(path, e);
    let root = BitMapBackend::new(path, (760, 520)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let values = errors
        .iter()
        .flat_map(|a| a.speeds.iter().copied().chain(a.tip))
        .filter(|v| v.is_finite() && *v != 0.0);
    let (lo, hi) = values.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v.abs()), hi.max(v.abs())));
    let (first, last) = (SIZES[0] as f64, SIZES[SIZES.len() - 1] as f64);
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("uniform chains of n links against the heavy string of {} m", round(length)),
            ("sans-serif", 17),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d((first * 0.8..last * 1.25).log_scale(), (lo * 0.5..hi * 2.0).log_scale())
        .map_err(|e| fail(&e))?;
    chart
        .configure_mesh()
        .x_desc("links n")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_desc("|chain − string| / string")
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| fail(&e))?;
    let mut series: Vec<(String, Vec<(f64, f64)>)> = (0..3)
        .map(|k| {
            let points = errors
                .iter()
                .filter(|a| a.speeds[k].is_finite())
                .map(|a| (a.links as f64, a.speeds[k].abs()));
            (format!("critical speed ω_{} (chain below)", k + 1), points.collect())
        })
        .collect();
    if let Some(w) = tip_speed {
        let points = errors.iter().filter_map(|a| a.tip.map(|t| (a.links as f64, t.abs())));
        series.push((format!("one-node tip radius at {} rad/s (chain outside)", round(w)), points.collect()));
    }
    for (i, (label, points)) in series.into_iter().enumerate() {
        let c = colour(Some(i + 1));
        chart
            .draw_series(LineSeries::new(points.clone(), c.stroke_width(2)))
            .map_err(|e| fail(&e))?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2)));
        chart.draw_series(points.iter().map(|&p| Circle::new(p, 3, c.filled()))).map_err(|e| fail(&e))?;
    }
    // The slope of an O(1/n) approach, between the curves: a third of the first speed's
    // error at the first n.
    if let Some(a) = errors.first().filter(|a| a.speeds[0].is_finite()) {
        let c0 = a.speeds[0].abs() * first / 3.0;
        let grey = RGBColor(150, 150, 150);
        chart
            .draw_series(DashedLineSeries::new(
                vec![(first, c0 / first), (last, c0 / last)],
                6,
                5,
                grey.stroke_width(1),
            ))
            .map_err(|e| fail(&e))?
            .label("slope 1/n")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], grey.stroke_width(1)));
    }
    key(&mut chart, SeriesLabelPosition::LowerLeft, path)?;
    root.present().map_err(|e| fail(&e))
}
