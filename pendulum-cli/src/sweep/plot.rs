//! sweep.png, the picture of the chain's choice: above, the free end's signed distance
//! from the axis that each run ended with against ω, over the steady branch diagram of
//! `pendulum steady --radius R` (drawn by its own code: colour = node count, line =
//! undamped stability); below, the node count each kind of start ended with against ω.
//! Marker shape = kind (● sudden, ▲ ramp up, ▼ ramp down), fill = node count (hollow:
//! not settled); the lower panel joins each kind's points in its own colour, so a
//! difference between the up and down sweeps (hysteresis) shows as two lines.

use std::path::Path;

use pendulum_core::SteadyRotation;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::error::CliResult;
use crate::plot::{drawing_failed, fonts};
use crate::steady::plots::{colour, draw_family, draw_key, family_key, reach};
use crate::steady::round_up;
use pendulum_experiment::steady::{Family, follow};
use pendulum_experiment::sweep::{Outcome, Point, SweepConfig, SweepKind};
use pendulum_experiment::words::short;

const WIDTH: u32 = 1320;
const HEIGHT: u32 = 1000;
/// Height of the title block, px.
const TITLE: u32 = 74;
/// Width of the plots (the key to their right), px.
const PLOTS: u32 = 980;
/// Height of the upper panel, px.
const UPPER: u32 = 590;

/// The colour of a kind's line in the lower panel and its key.
fn kind_colour(kind: SweepKind) -> RGBColor {
    match kind {
        SweepKind::Sudden => RGBColor(40, 40, 40),
        SweepKind::RampUp => RGBColor(0, 150, 150),
        SweepKind::RampDown => RGBColor(200, 0, 130),
    }
}

/// The horizontal offset of a kind's markers in the upper panel, px: the kinds of one ω
/// side by side, not on top of each other.
fn side(kind: SweepKind) -> i32 {
    match kind {
        SweepKind::Sudden => -6,
        SweepKind::RampUp => 0,
        SweepKind::RampDown => 6,
    }
}

/// What a kind is, in the key.
fn kind_label(kind: SweepKind, config: &SweepConfig) -> String {
    let ramp = config.ramp_time.unwrap_or(0.0);
    match kind {
        SweepKind::Sudden => "sudden start at ω".into(),
        SweepKind::RampUp => format!("ramp up from rest, {ramp} s"),
        SweepKind::RampDown => format!("ramp down from the previous ω, {ramp} s"),
    }
}

/// Draws the marker of `kind` at pixel `(x, y)`: filled with `fill` and edged black, or
/// hollow (edged in `fill`) for a run that did not settle.
fn marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    kind: SweepKind,
    (x, y): (i32, i32),
    fill: RGBColor,
    settled: bool,
) -> Result<(), String> {
    let fail = |e: &dyn std::fmt::Display| e.to_string();
    let (face, edge) =
        if settled { (fill.filled(), BLACK.stroke_width(1)) } else { (WHITE.filled(), fill.stroke_width(2)) };
    let shape: Vec<(i32, i32)> = match kind {
        SweepKind::Sudden => {
            area.draw(&Circle::new((x, y), 6, face)).map_err(|e| fail(&e))?;
            return area.draw(&Circle::new((x, y), 6, edge)).map_err(|e| fail(&e));
        }
        SweepKind::RampUp => vec![(x, y - 8), (x - 7, y + 5), (x + 7, y + 5)],
        SweepKind::RampDown => vec![(x, y + 8), (x - 7, y - 5), (x + 7, y - 5)],
    };
    area.draw(&Polygon::new(shape.clone(), face)).map_err(|e| fail(&e))?;
    let mut outline = shape.clone();
    outline.push(shape[0]);
    area.draw(&PathElement::new(outline, edge)).map_err(|e| fail(&e))
}

/// Draws sweep.png (module docs) for the finished points of `points`. The steady branches
/// are followed up to a little above the largest ω; if that fails the picture is drawn
/// without them (with a note).
pub fn draw(path: &Path, config: &SweepConfig, points: &[Point]) -> CliResult<()> {
    fonts();
    let top = config.omegas.iter().copied().fold(0.0, f64::max);
    let omega_max = round_up(if top > 0.0 { 1.05 * top } else { config.reference_speed() });
    let family = config.chain().and_then(|chain| {
        let problem = SteadyRotation::new(&chain, config.radius)?;
        let free = SteadyRotation::new(&chain, 0.0)?;
        follow(&problem, &free, omega_max, None, &|_| true)
    });
    let family = match family {
        Ok(f) => Some(f),
        Err(e) => {
            eprintln!("pendulum: note: sweep.png without the steady branches ({e})");
            None
        }
    };
    render(path, config, points, family.as_ref(), omega_max).map_err(|e| drawing_failed(path, e))
}

fn render(
    path: &Path,
    config: &SweepConfig,
    points: &[Point],
    family: Option<&Family>,
    omega_max: f64,
) -> Result<(), String> {
    let fail = |e: &dyn std::fmt::Display| e.to_string();
    let root = BitMapBackend::new(path, (WIDTH, HEIGHT)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let (title, body) = root.split_vertically(TITLE);
    let (plots, key) = body.split_horizontally(PLOTS);
    let (upper, lower) = plots.split_vertically(UPPER);
    let scale = config.reference_speed();
    let done: Vec<(&Point, &Outcome)> =
        points.iter().filter_map(|p| p.result.as_ref().map(|r| (p, r))).collect();

    // Title: the question, then the parameters.
    let unfinished = points.len() - done.len();
    let heading = format!(
        "Which shape does the chain choose? Nodes and tip radius after {} s of whirling, against ω{}",
        config.duration,
        if unfinished > 0 {
            format!(" ({unfinished} of {} points unfinished)", points.len())
        } else {
            String::new()
        }
    );
    let damping = if config.damping.iter().all(|&d| d == config.damping[0]) {
        format!("λ = {} N·m·s per link", short(config.damping[0]))
    } else {
        "λ_i as given".into()
    };
    let sub = format!(
        "n = {}, L = {} m, M = {} kg, R = {} m, {damping}, g = {} m/s²; RK4 h = {} s; from hanging at rest \
         (ramp down: from the previous point's end)",
        config.links(),
        short(config.length()),
        short(config.masses.iter().sum::<f64>()),
        short(config.radius),
        short(config.gravity),
        short(config.step),
    );
    let centred =
        |size| TextStyle::from(("sans-serif", size).into_font()).pos(Pos::new(HPos::Center, VPos::Top));
    title.draw_text(&heading, &centred(22), (WIDTH as i32 / 2, 10)).map_err(|e| fail(&e))?;
    title.draw_text(&sub, &centred(15), (WIDTH as i32 / 2, 42)).map_err(|e| fail(&e))?;

    // Upper panel: the branch diagram and where each run ended.
    let tips = done.iter().map(|(_, r)| r.tip_signed.abs()).fold(0.0, f64::max);
    let half = family.map_or(config.radius, |f| reach(f, config.radius)).max(tips).max(1e-3) * 1.12;
    let x_end = 1.02 * omega_max;
    let mut chart = ChartBuilder::on(&upper)
        .margin(12)
        .margin_right(20)
        .top_x_label_area_size(44)
        .x_label_area_size(46)
        .y_label_area_size(74)
        .build_cartesian_2d(0.0..x_end, -half..half)
        .map_err(|e| fail(&e))?
        .set_secondary_coord(0.0..x_end / scale, -half..half);
    chart
        .configure_mesh()
        .x_desc("drive speed ω (rad/s)")
        .y_desc("free end's distance from the axis (m), + on the pivot's side")
        .light_line_style(WHITE.mix(0.0))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .draw()
        .map_err(|e| fail(&e))?;
    chart
        .configure_secondary_axes()
        .x_desc(format!("ω / √(g/L)   (√(g/L) = {scale:.4} rad/s, L the chain's length)"))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .draw()
        .map_err(|e| fail(&e))?;
    let critical: &[f64] = family.map_or(&[], |f| &f.critical);
    let dotted = BLACK.mix(0.35).stroke_width(1);
    for &w in critical {
        chart
            .draw_series(DashedLineSeries::new([(w, -half), (w, half)], 2, 4, dotted))
            .map_err(|e| fail(&e))?;
    }
    let counts = match family {
        Some(f) => draw_family(&mut chart, f, config.radius)?,
        None => Vec::new(),
    };
    let area = chart.plotting_area().strip_coord_spec();
    let (dx, dy) = chart.plotting_area().get_base_pixel();
    let to_pixel = |w: f64, v: f64| {
        let (x, y) = chart.backend_coord(&(w, v));
        (x - dx, y - dy)
    };
    // The kinds of one ω side by side; settled runs on top of unsettled ones, so the
    // hollow markers do not hide them.
    for pass in [false, true] {
        for (p, r) in done.iter().filter(|(_, r)| r.settled == pass) {
            let (x, y) = to_pixel(p.omega, r.tip_signed);
            marker(&area, p.kind, (x + side(p.kind), y), colour(Some(r.nodes)), r.settled)?;
        }
    }

    // Lower panel: the node count each kind ended with.
    let most = done.iter().map(|(_, r)| r.nodes).max().unwrap_or(1).max(2);
    let y_range = 0.4..most as f64 + 0.6;
    let mut nodes_chart = ChartBuilder::on(&lower)
        .margin(12)
        .margin_right(20)
        .x_label_area_size(46)
        .y_label_area_size(74)
        .build_cartesian_2d(0.0..x_end, y_range.clone())
        .map_err(|e| fail(&e))?;
    nodes_chart
        .configure_mesh()
        .x_desc("drive speed ω (rad/s)")
        .y_desc("nodes the chain chose")
        .y_labels(most + 1)
        .y_label_formatter(&|v| {
            if (v - v.round()).abs() < 1e-9 && *v >= 1.0 { format!("{v:.0}") } else { String::new() }
        })
        .light_line_style(WHITE.mix(0.0))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .draw()
        .map_err(|e| fail(&e))?;
    for &w in critical {
        nodes_chart
            .draw_series(DashedLineSeries::new([(w, y_range.start), (w, y_range.end)], 2, 4, dotted))
            .map_err(|e| fail(&e))?;
    }
    let offset = |kind: SweepKind| match kind {
        SweepKind::Sudden => 0.0,
        SweepKind::RampUp => 0.12,
        SweepKind::RampDown => -0.12,
    };
    for &kind in &config.kinds {
        let mut line: Vec<(f64, f64)> = done
            .iter()
            .filter(|(p, _)| p.kind == kind)
            .map(|(p, r)| (p.omega, r.nodes as f64 + offset(kind)))
            .collect();
        line.sort_by(|a, b| a.0.total_cmp(&b.0));
        nodes_chart
            .draw_series(LineSeries::new(line, kind_colour(kind).stroke_width(2)))
            .map_err(|e| fail(&e))?;
    }
    let area = nodes_chart.plotting_area().strip_coord_spec();
    let (dx, dy) = nodes_chart.plotting_area().get_base_pixel();
    for (p, r) in &done {
        let (x, y) = nodes_chart.backend_coord(&(p.omega, r.nodes as f64 + offset(p.kind)));
        marker(&area, p.kind, (x - dx, y - dy), colour(Some(r.nodes)), r.settled)?;
    }
    for (k, &w) in critical.iter().enumerate() {
        let (x, y) = nodes_chart.backend_coord(&(w, y_range.end));
        let style = TextStyle::from(("sans-serif", 13).into_font()).pos(Pos::new(HPos::Left, VPos::Top));
        area.draw_text(&format!("ω{}", k + 1), &style, (x - dx + 4, y - dy + 4)).map_err(|e| fail(&e))?;
    }

    // The key.
    let text = TextStyle::from(("sans-serif", 14).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    let bold = TextStyle::from(("sans-serif", 15).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    let mut y = 40;
    key.draw_text(&format!("the chain after {} s (markers)", config.duration), &bold, (14, y))
        .map_err(|e| fail(&e))?;
    for &kind in &config.kinds {
        y += 22;
        key.draw(&PathElement::new(vec![(14, y), (40, y)], kind_colour(kind).stroke_width(2)))
            .map_err(|e| fail(&e))?;
        marker(&key, kind, (27, y), RGBColor(150, 150, 150), true)?;
        key.draw_text(&kind_label(kind, config), &text, (48, y)).map_err(|e| fail(&e))?;
    }
    y += 22;
    key.draw_text("fill: node count (as the lines)", &text, (14, y)).map_err(|e| fail(&e))?;
    y += 22;
    marker(&key, SweepKind::Sudden, (27, y), colour(Some(1)), false)?;
    key.draw_text("hollow: not settled", &text, (48, y)).map_err(|e| fail(&e))?;
    y += 22;
    key.draw_text("above: the kinds of one ω side by side", &text, (14, y)).map_err(|e| fail(&e))?;
    y += 22;
    key.draw_text("below: a line per kind, offset", &text, (14, y)).map_err(|e| fail(&e))?;
    y += 22;
    key.draw(&PathElement::new(vec![(14, y), (40, y)], dotted)).map_err(|e| fail(&e))?;
    key.draw_text("critical speeds ω_k (fixed pivot)", &text, (48, y)).map_err(|e| fail(&e))?;
    y += 44;
    key.draw_text("undamped steady shapes (lines),", &bold, (14, y)).map_err(|e| fail(&e))?;
    y += 20;
    key.draw_text(&format!("as pendulum steady --radius {}", short(config.radius)), &text, (14, y))
        .map_err(|e| fail(&e))?;
    if family.is_some() {
        draw_key(&key, y + 22, &family_key(counts, config.radius))?;
    } else {
        key.draw_text("(not found)", &text, (14, y + 22)).map_err(|e| fail(&e))?;
    }
    root.present().map_err(|e| fail(&e))
}
