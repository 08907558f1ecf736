//! The table on stdout: the sweep's parameters, then one line per point.

use std::fmt::Write as _;

use pendulum_experiment::sweep::{Point, Status, SweepConfig};
use pendulum_experiment::words::{growth_words, short};

/// The table on stdout: the sweep's parameters, then one line per point.
pub fn table(config: &SweepConfig, points: &[Point]) {
    let scale = config.reference_speed();
    let n = config.links();
    let damping = if config.damping.iter().all(|&d| d == config.damping[0]) {
        format!("λ = {} N·m·s per link", short(config.damping[0]))
    } else {
        "λ_i per link as given".into()
    };
    let ramp = config.ramp_time.map_or(String::new(), |t| format!(", ramps over {t} s"));
    let mut out = format!(
        "sweep: n = {n}, L = {} m, M = {} kg, R = {} m, {damping}; {} s per point{ramp}, RK4 + projection h = {} s; \
         √(g/L) = {scale:.6} rad/s{}\n",
        short(config.length()),
        short(config.masses.iter().sum::<f64>()),
        short(config.radius),
        config.duration,
        config.step,
        if config.scaled { " (--omega given in these units)" } else { "" }
    );
    out.push_str(
        "nodes = axis crossings + 1 (the pivot counted); tip radius = the free end's distance from the axis \
         (+ on the pivot's side); nearest = the damped steady shape nearest the final shape\n",
    );
    let _ = writeln!(
        out,
        "{:<9}  {:>10}  {:>8}  {:>5}  {:>15}  {:<19}  {:>16}  {:>7}  {:<26}  {:>8}",
        "kind",
        "ω (rad/s)",
        "ω/√(g/L)",
        "nodes",
        "tip, signed (m)",
        "settled (drift, m)",
        "nearest dist (m)",
        "nodes",
        "nearest: stability",
        "wall (s)"
    );
    for p in points {
        let head = format!("{:<9}  {:>10.4}  {:>8.3}", p.kind.name(), p.omega, p.omega_scaled);
        let Some(r) = &p.result else {
            let why = p.error.as_deref().map_or(String::new(), |e| format!(" ({e})"));
            let status = if p.status == Status::Completed { "no result" } else { p.status.name() };
            let _ = writeln!(out, "{head}  {status}{why}");
            continue;
        };
        let settled = format!("{} ({:.1e})", if r.settled { "yes" } else { "no" }, r.drift);
        let (distance, nodes, stability) = match &r.nearest {
            Some(n) => (
                format!("{:.2e}", n.distance),
                n.nodes.to_string(),
                format!(
                    "{} ({})",
                    if n.stable { "stable" } else { "unstable" },
                    growth_words(n.growth_rate, n.growth_rate_bound)
                ),
            ),
            None => ("-".into(), "-".into(), "none found".into()),
        };
        let _ = writeln!(
            out,
            "{head}  {:>5}  {:>+15.4}  {settled:<19}  {distance:>16}  {nodes:>7}  {stability:<26}  {:>8}",
            r.nodes,
            r.tip_signed,
            r.wall_seconds.map_or("-".into(), |w| format!("{w:.1}"))
        );
    }
    let chosen: Vec<String> = config
        .kinds
        .iter()
        .map(|&k| {
            let counts: Vec<String> = points
                .iter()
                .filter(|p| p.kind == k)
                .map(|p| p.result.as_ref().map_or("-".into(), |r| r.nodes.to_string()))
                .collect();
            format!("{}: {}", k.name(), counts.join(" "))
        })
        .collect();
    let _ = writeln!(out, "nodes, in the order of the rows: {}", chosen.join("; "));
    print!("{out}");
}
