//! The tables of `pendulum steady` on stdout: the branches, with their node counts and
//! stretches of stability, and every steady shape at the listed speeds.

use pendulum_core::{BranchEnd, SteadyRotation, Verdict};

use super::branches::{Family, Labelled};
use super::{Judged, nodes_name, rate};
use pendulum_experiment::steady::AtSpeed;

const NODES_NOTE: &str = "nodes = axis crossings + 1, the pivot counted";

/// The branch table: number, name, node count(s), critical speed, points, how it ended,
/// and its stretches of stability in continuation order.
pub fn branches(family: &Family, problem: &SteadyRotation, omega_max: f64) {
    println!("reference speed sqrt(g/L) = {:.6} rad/s", problem.reference_speed());
    if !family.critical.is_empty() {
        let list: Vec<String> = family.critical.iter().map(|w| format!("{w:.6}")).collect();
        println!("critical speeds of the chain on a fixed pivot (rad/s): {}", list.join(", "));
    }
    println!(
        "branches up to ω = {omega_max} rad/s ({NODES_NOTE}; stretches in continuation order, ω in rad/s)"
    );
    println!(
        "{:>3}  {:<18}  {:>5}  {:>26}  {:>6}  {:<19}  stability along the branch",
        "#", "branch", "nodes", "leaves vertical at (rad/s)", "points", "end"
    );
    if !family.vertical.is_empty() {
        let stretches: Vec<String> =
            family.vertical.iter().map(|(a, b, j)| format!("{} {a:.3}→{b:.3}", run_label(j))).collect();
        println!(
            "{:>3}  {:<18}  {:>5}  {:>26}  {:>6}  {:<19}  {}",
            0,
            "vertical",
            "-",
            "-",
            "-",
            "-",
            stretches.join("; ")
        );
    }
    for (b, labelled) in family.branches.iter().enumerate() {
        let counts = node_counts(labelled);
        let nodes = match (counts.first(), counts.last()) {
            (Some(lo), Some(hi)) if lo != hi => format!("{lo}–{hi}"),
            (Some(k), _) => k.to_string(),
            _ => "-".into(),
        };
        let critical = labelled.critical.map_or("-".to_string(), |s| format!("{s:.6}"));
        println!(
            "{:>3}  {:<18}  {nodes:>5}  {critical:>26}  {:>6}  {:<19}  {}",
            b + 1,
            labelled.name,
            labelled.branch.points.len(),
            end_reason(labelled.branch.end),
            stretches(labelled, counts.len() > 1)
        );
    }
}

/// The distinct node counts along a branch, ascending.
fn node_counts(labelled: &Labelled) -> Vec<usize> {
    let mut counts: Vec<usize> = labelled.nodes.iter().flatten().copied().collect();
    counts.sort_unstable();
    counts.dedup();
    counts
}

fn end_reason(end: BranchEnd) -> &'static str {
    match end {
        BranchEnd::ReachedOmega => "reached --omega-max",
        BranchEnd::ReachedZeroOmega => "returned to ω = 0",
        BranchEnd::StepTooSmall => "step became too small",
        BranchEnd::MaxPoints => "point limit reached",
    }
}

/// `stable`, `gyroscopic (index 2)`, `unstable (index 1)`.
fn run_label(j: &Judged) -> String {
    match j.verdict {
        Verdict::Stable => "stable".into(),
        Verdict::Gyroscopic { index } => format!("gyroscopic (index {index})"),
        Verdict::Unstable { .. } => format!("unstable (index {})", j.index),
    }
}

/// The runs of equal verdict, index and (if `with_nodes`) node count along the branch,
/// each from its first point's ω to the next run's first point's ω; unstable runs with
/// their largest growth rate.
pub fn stretches(labelled: &Labelled, with_nodes: bool) -> String {
    let points = &labelled.branch.points;
    let key = |i: usize| {
        let i = labelled.shown(i);
        (run_label(&labelled.judged[i]), if with_nodes { labelled.nodes[i] } else { None })
    };
    let mut out: Vec<String> = Vec::new();
    let mut start = 0;
    for i in 1..=points.len() {
        if i < points.len() && key(i) == key(start) {
            continue;
        }
        let (label, nodes) = key(start);
        let end = points[i.min(points.len() - 1)].omega;
        let growth = (start..i)
            .filter_map(|k| labelled.judged[labelled.shown(k)].verdict.growth_rate())
            .fold(f64::NEG_INFINITY, f64::max);
        let mut text = match nodes {
            Some(k) => format!("{}: {label}", nodes_name(k)),
            None => label,
        };
        if growth.is_finite() {
            text.insert_str(text.len() - 1, &format!(", growth up to {} 1/s", rate(growth)));
        }
        out.push(format!("{text} {:.3}→{end:.3}", points[start].omega));
        start = i;
    }
    out.join("; ")
}

/// The shape table: speed, branch, nodes, tip radius (and side of the axis for a circling
/// pivot), verdict, index, growth rate; with damping the damped verdict, growth rate and
/// (circling pivot) the damped shape's shift.
pub fn shapes(found: &[AtSpeed], radius: f64, damped: bool) {
    let forced = radius != 0.0;
    println!();
    println!("steady shapes ({NODES_NOTE}; tip radius = |x_n|, the free end's distance from the axis)");
    let mut header = format!(
        "{:<10}  {:>3}  {:<18}  {:>5}  {:>14}",
        "ω (rad/s)", "#", "branch", "nodes", "tip radius (m)"
    );
    if forced {
        header.push_str(&format!("  {:<8}", "tip side"));
    }
    header.push_str(&format!("  {:<10}  {:>5}  {:>12}", "stability", "index", "growth (1/s)"));
    if damped {
        header.push_str(&format!("  {:<10}  {:>19}", "damped", "damped growth (1/s)"));
        if forced {
            header.push_str(&format!("  {:>16}", "damped shift (m)"));
        }
    }
    println!("{header}");
    for f in found {
        let nodes = f.nodes.map_or("-".to_string(), |k| k.to_string());
        let mut line = format!(
            "{:<10}  {:>3}  {:<18}  {nodes:>5}  {:>14.6}",
            f.shape.omega.to_string(),
            f.branch,
            f.name,
            f.tip_radius()
        );
        if forced {
            let tip = f.shape.displacements.last().copied().unwrap_or(0.0);
            line.push_str(&format!("  {:<8}", if tip >= 0.0 { "pivot's" } else { "opposite" }));
        }
        let growth = f.judged.verdict.growth_rate().map_or("-".to_string(), rate);
        line.push_str(&format!("  {:<10}  {:>5}  {growth:>12}", f.judged.verdict.label(), f.judged.index));
        if damped {
            match &f.damped {
                Some(d) => {
                    line.push_str(&format!("  {:<10}  {:>19}", d.verdict.label(), rate(d.growth_rate)));
                    if forced {
                        line.push_str(&format!("  {:>16.2e}", d.shift));
                    }
                }
                None => line.push_str(&format!("  {:<10}  {:>19}", "not found", "-")),
            }
        }
        println!("{}", line.trim_end());
    }
}
