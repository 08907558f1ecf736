//! `pendulum modes`: the normal modes of the chain hanging at rest (table, modes.csv and
//! the mode shapes in modes.png).

use std::path::Path;

use nalgebra::Dyn;
use pendulum_core::{Chain, bernoulli_frequency, normal_modes, sign_changes};
use pendulum_experiment::Csv;
use plotters::prelude::*;

use crate::args::ModesArgs;
use crate::chain_args::chain_of;
use crate::error::{CliError, CliResult};
use crate::plot::{drawing_failed, fonts};

/// Runs `pendulum modes`.
pub fn modes(args: &ModesArgs) -> CliResult<()> {
    let chain = chain_of(&args.chain)?;
    let n = chain.links();
    let count = args.count.unwrap_or(n.min(6));
    if count == 0 || count > n {
        return Err(CliError::invalid(format!("--count must be between 1 and n = {n}, got {count}")));
    }
    let modes = normal_modes(&chain);
    let total: f64 = chain.lengths().iter().sum();
    let uniform = chain.masses().iter().all(|&m| m == chain.masses()[0])
        && chain.lengths().iter().all(|&l| l == chain.lengths()[0]);
    crate::args::create_out(&args.out)?;
    let mut header =
        vec!["k".to_string(), "omega".into(), "frequency_hz".into(), "period".into(), "nodes".into()];
    header.extend((1..=n).map(|i| format!("x{i}")));
    let mut csv = Csv::create(&args.out.join("modes.csv"), &header)?;
    let mut out = format!("normal modes of {}; pivot fixed\n", crate::chain_args::header(&chain, None));
    let continuum = if uniform { "   Bernoulli (continuum)" } else { "" };
    out.push_str(&format!(" k   omega (rad/s)     f (Hz)   period (s)  nodes{continuum}\n"));
    let mut shapes = Vec::new();
    for k in 0..count {
        let omega = modes.frequencies[k];
        let x = modes.displacements(&chain, k);
        let nodes = 1 + sign_changes(&x);
        let f = omega / (2.0 * std::f64::consts::PI);
        let period = if omega > 0.0 { 1.0 / f } else { f64::INFINITY };
        let mut line = format!("{:>2}  {omega:>14.6}  {f:>9.5}  {period:>11.5}  {nodes:>5}", k + 1);
        if uniform {
            let bernoulli = bernoulli_frequency(k + 1, chain.gravity(), total);
            line.push_str(&format!("   {bernoulli:>14.6}"));
        }
        out.push_str(&line);
        out.push('\n');
        csv.row([(k + 1) as f64, omega, f, period, nodes as f64].into_iter().chain(x.iter().copied()))?;
        shapes.push((k + 1, omega, x));
    }
    csv.finish()?;
    print!("{out}");
    let png = args.out.join("modes.png");
    plot_modes(&png, &chain, &shapes)?;
    eprintln!("pendulum: {count} of {n} modes; files in {} (modes.csv, modes.png)", args.out.display());
    Ok(())
}

/// Depths of the masses of a hanging chain, `z_i = −Σ_{j≤i} l_j` (m).
fn hanging_depths(chain: &Chain<Dyn>) -> Vec<f64> {
    let mut z = 0.0;
    chain
        .lengths()
        .iter()
        .map(|l| {
            z -= l;
            z
        })
        .collect()
}

/// Where the chain crosses the vertical through the pivot: the heights (m) at which the
/// displacement `x` interpolated linearly between masses (and from the pivot, `x = 0`)
/// changes sign. With the pivot, these are the mode's nodes.
fn crossings(x: &[f64], z: &[f64]) -> Vec<f64> {
    let mut out = Vec::new();
    for i in 1..x.len() {
        let (a, b) = (x[i - 1], x[i]);
        if a != 0.0 && b != 0.0 && a.signum() != b.signum() {
            out.push(z[i - 1] + (z[i] - z[i - 1]) * a / (a - b));
        }
    }
    out
}

/// One panel per mode: the chain displaced in its mode shape (horizontal displacement
/// scaled to a quarter of the chain's length: mode shapes have no size of their own), the
/// hanging chain in grey, the nodes (the pivot and the crossings of the vertical) marked;
/// heights in metres.
fn plot_modes(path: &Path, chain: &Chain<Dyn>, shapes: &[(usize, f64, Vec<f64>)]) -> CliResult<()> {
    fonts();
    let fail = |e: &dyn std::fmt::Display| drawing_failed(path, e);
    let panels = shapes.len();
    let root = BitMapBackend::new(path, (240 * panels as u32, 460)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let total: f64 = chain.lengths().iter().sum();
    let z = hanging_depths(chain);
    for (area, (k, omega, x)) in root.split_evenly((1, panels)).iter().zip(shapes) {
        let peak = x.iter().fold(0.0_f64, |a, v| a.max(v.abs())).max(f64::MIN_POSITIVE);
        let scale = 0.25 * total / peak;
        let nodes: Vec<f64> = std::iter::once(0.0).chain(crossings(x, &z)).collect();
        let mut chart = ChartBuilder::on(area)
            .caption(
                format!(
                    "mode {k}: ω = {omega:.3} rad/s, {} node{}",
                    nodes.len(),
                    if nodes.len() == 1 { "" } else { "s" }
                ),
                ("sans-serif", 14),
            )
            .margin(6)
            .x_label_area_size(34)
            .y_label_area_size(44)
            .build_cartesian_2d(-0.4 * total..0.4 * total, -1.05 * total..0.05 * total)
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(3)
            .x_label_formatter(&|_| String::new())
            .y_labels(6)
            .x_desc("displacement (peak = L/4)")
            .y_desc("height (m)")
            .light_line_style(BLACK.mix(0.04))
            .label_style(("sans-serif", 11))
            .axis_desc_style(("sans-serif", 12))
            .draw()
            .map_err(|e| fail(&e))?;
        let rest = std::iter::once((0.0, 0.0)).chain(z.iter().map(|&z| (0.0, z)));
        chart
            .draw_series(LineSeries::new(rest, RGBColor(200, 200, 200).stroke_width(1)))
            .map_err(|e| fail(&e))?;
        let points: Vec<(f64, f64)> =
            std::iter::once((0.0, 0.0)).chain(x.iter().zip(&z).map(|(x, z)| (x * scale, *z))).collect();
        chart
            .draw_series(LineSeries::new(points.iter().copied(), BLACK.stroke_width(2)))
            .map_err(|e| fail(&e))?;
        chart
            .draw_series(points[1..].iter().map(|&p| Circle::new(p, 3, BLUE.filled())))
            .map_err(|e| fail(&e))?;
        chart
            .draw_series(nodes.iter().map(|&h| Circle::new((0.0, h), 6, RED.stroke_width(2))))
            .map_err(|e| fail(&e))?;
    }
    root.present().map_err(|e| fail(&e))
}

#[cfg(test)]
mod tests {
    use super::crossings;

    #[test]
    fn nodes_are_where_the_chain_crosses_the_vertical() {
        // 1 + sign changes: the pivot and one crossing halfway between heights −1 and −2.
        assert_eq!(crossings(&[1.0, -1.0, -2.0], &[-1.0, -2.0, -3.0]), vec![-1.5]);
        assert_eq!(crossings(&[0.2, 0.6], &[-1.0, -2.0]), Vec::<f64>::new());
    }
}
