//! atlas.png, the map of the chain's choice: a panel per kind of start (side by side),
//! each point of the grid a cell coloured by the node count the chain ended with (pale
//! with a dot: it had not settled; grey: failed or not run), black lines between cells of
//! different node counts (the boundaries of the basins), and, on an ω axis, the critical
//! speeds of the chain on a fixed pivot (dashed: where the shapes of 1, 2, 3 … nodes are
//! born as R → 0) and the folds of the steady branches on the pivot's circle (the lowest ω
//! of each forced branch at each R: right of its line, its shapes exist).

use std::path::Path;

use pendulum_experiment::atlas::{AtlasConfig, AtlasKind, AtlasPoint, Axis, Derived, Fold, Parameter, folds};
use pendulum_experiment::steady::round_up;
use pendulum_experiment::words::{chain_words, short};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use rayon::prelude::*;

use super::csv::axis_name;
use crate::error::CliResult;
use crate::plot::{drawing_failed, fonts};
use crate::steady::plots::{colour, faint};

/// Width of a panel, px.
const PANEL: u32 = 640;
/// Width of the key, px.
const KEY: u32 = 250;
/// Height of the picture and of its title block, px.
const HEIGHT: u32 = 720;
const TITLE: u32 = 74;
/// Failed or not run.
const MISSING: RGBColor = RGBColor(190, 190, 190);

/// Draws atlas.png (module docs). With an ω axis, the steady branches are followed at
/// every radius of the grid (in parallel) for their folds; if that fails the picture is
/// drawn without them (with a note).
pub fn draw(path: &Path, config: &AtlasConfig, derived: &Derived, points: &[AtlasPoint]) -> CliResult<()> {
    fonts();
    let folds = match branch_folds(config) {
        Ok(folds) => folds,
        Err(e) => {
            eprintln!("pendulum: note: atlas.png without the steady branches' folds ({e})");
            Vec::new()
        }
    };
    render(path, config, derived, points, &folds).map_err(|e| drawing_failed(path, e))
}

/// The folds of the steady branches at every radius of the grid (`(R, folds)`), where ω
/// is an axis; none otherwise.
fn branch_folds(config: &AtlasConfig) -> pendulum_experiment::Result<Vec<(f64, Vec<Fold>)>> {
    let Some(omega) = config.axis(Parameter::Omega) else { return Ok(Vec::new()) };
    let radii = match (config.radius, config.axis(Parameter::Radius)) {
        (Some(r), _) => vec![r],
        (None, Some(axis)) => axis.values.clone(),
        (None, None) => return Ok(Vec::new()),
    };
    let top = omega.values.iter().copied().fold(0.0, f64::max);
    let omega_max = round_up(1.05 * top.max(config.reference_speed()));
    let chain = config.chain()?;
    radii.par_iter().map(|&r| Ok((r, folds(&chain, r, omega_max)?))).collect()
}

/// The values of an axis as plotted (ω in units of √(g/L) when given so).
fn plotted(config: &AtlasConfig, axis: &Axis) -> Vec<f64> {
    let unit =
        if axis.parameter == Parameter::Omega && config.scaled { config.reference_speed() } else { 1.0 };
    axis.values.iter().map(|v| v / unit).collect()
}

/// The cells' edges along an axis: midway between values, half a spacing beyond the ends.
fn edges(values: &[f64]) -> Vec<f64> {
    let n = values.len();
    let mut e = Vec::with_capacity(n + 1);
    e.push(values[0] - 0.5 * (values[1] - values[0]));
    e.extend(values.windows(2).map(|w| 0.5 * (w[0] + w[1])));
    e.push(values[n - 1] + 0.5 * (values[n - 1] - values[n - 2]));
    e
}

/// What a cell shows: the node count (if the point has a result) and whether it settled.
fn class(p: &AtlasPoint) -> Option<(usize, bool)> {
    p.result.as_ref().map(|r| (r.nodes, r.settled))
}

fn kind_caption(config: &AtlasConfig, kind: AtlasKind) -> String {
    match kind {
        AtlasKind::Sudden => "sudden start: the pivot circles at ω from t = 0".into(),
        AtlasKind::RampUp => match config.ramp_time {
            Some(t) => format!("ramp up: ω reached linearly from rest over {} s", short(t)),
            None => "ramp up: ω reached linearly from rest over the ramp time".into(),
        },
    }
}

fn render(
    path: &Path,
    config: &AtlasConfig,
    derived: &Derived,
    points: &[AtlasPoint],
    folds: &[(f64, Vec<Fold>)],
) -> Result<(), String> {
    let fail = |e: &dyn std::fmt::Display| e.to_string();
    let kinds = config.kinds.len();
    let width = PANEL * kinds as u32 + KEY;
    let root = BitMapBackend::new(path, (width, HEIGHT)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let (title, body) = root.split_vertically(TITLE);
    let (panels, key) = body.split_horizontally(PANEL * kinds as u32);

    let done = points.iter().filter(|p| p.result.is_some()).count();
    let heading = format!(
        "Which shape from rest? The node count after {} s of whirling, over {} and {}{}",
        short(config.duration),
        config.x.parameter.symbol(),
        config.y.parameter.symbol(),
        if done < points.len() {
            format!(" ({} of {} points unfinished)", points.len() - done, points.len())
        } else {
            String::new()
        }
    );
    let mut fixed = Vec::new();
    if let Some(r) = config.radius {
        fixed.push(format!("R = {} m", short(r)));
    }
    if let Some(w) = config.omega {
        fixed.push(format!("ω = {} rad/s", short(w)));
    }
    let sub = format!(
        "{}; {}RK4 h = {} s, from hanging at rest",
        chain_words(
            &config.masses,
            &config.lengths,
            config.gravity,
            config.damping.as_deref().unwrap_or(&vec![0.0; config.links()])
        ),
        fixed.iter().map(|f| format!("{f}, ")).collect::<String>(),
        short(config.step)
    );
    let centred =
        |size| TextStyle::from(("sans-serif", size).into_font()).pos(Pos::new(HPos::Center, VPos::Top));
    title.draw_text(&heading, &centred(21), (width as i32 / 2, 10)).map_err(|e| fail(&e))?;
    title.draw_text(&sub, &centred(14), (width as i32 / 2, 44)).map_err(|e| fail(&e))?;

    let (xs, ys) = (plotted(config, &config.x), plotted(config, &config.y));
    let (ex, ey) = (edges(&xs), edges(&ys));
    let (nx, ny) = (xs.len(), ys.len());
    let omega_unit = if config.scaled { config.reference_speed() } else { 1.0 };
    let critical: Vec<f64> = derived.critical_speeds.iter().map(|w| w / omega_unit).collect();
    let mut counts: Vec<usize> = points.iter().filter_map(|p| p.result.as_ref().map(|r| r.nodes)).collect();
    counts.sort_unstable();
    counts.dedup();

    for (k, (area, kind)) in panels.split_evenly((1, kinds)).iter().zip(&config.kinds).enumerate() {
        let cell = |ix: usize, iy: usize| &points[k * nx * ny + iy * nx + ix];
        let mut chart = ChartBuilder::on(area)
            .caption(kind_caption(config, *kind), ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(46)
            .y_label_area_size(70)
            .build_cartesian_2d(ex[0]..ex[nx], ey[0]..ey[ny])
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(axis_name(config, config.x.parameter))
            .y_desc(axis_name(config, config.y.parameter))
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 15))
            .draw()
            .map_err(|e| fail(&e))?;
        // The cells.
        for iy in 0..ny {
            for ix in 0..nx {
                let (fill, dot) = match class(cell(ix, iy)) {
                    Some((nodes, true)) => (colour(Some(nodes)), false),
                    Some((nodes, false)) => (faint(colour(Some(nodes))), true),
                    None => (MISSING, false),
                };
                let corners = [(ex[ix], ey[iy]), (ex[ix + 1], ey[iy + 1])];
                chart.draw_series([Rectangle::new(corners, fill.filled())]).map_err(|e| fail(&e))?;
                if dot {
                    chart
                        .draw_series([Circle::new((xs[ix], ys[iy]), 2, BLACK.filled())])
                        .map_err(|e| fail(&e))?;
                }
            }
        }
        // The boundaries between basins: cell edges between different node counts.
        let nodes = |ix: usize, iy: usize| class(cell(ix, iy)).map(|(n, _)| n);
        let line = BLACK.stroke_width(2);
        for iy in 0..ny {
            for ix in 0..nx {
                if ix + 1 < nx && nodes(ix, iy) != nodes(ix + 1, iy) {
                    let segment = [(ex[ix + 1], ey[iy]), (ex[ix + 1], ey[iy + 1])];
                    chart.draw_series([PathElement::new(segment, line)]).map_err(|e| fail(&e))?;
                }
                if iy + 1 < ny && nodes(ix, iy) != nodes(ix, iy + 1) {
                    let segment = [(ex[ix], ey[iy + 1]), (ex[ix + 1], ey[iy + 1])];
                    chart.draw_series([PathElement::new(segment, line)]).map_err(|e| fail(&e))?;
                }
            }
        }
        // The folds of the steady branches: a line per branch through its lowest ω at each
        // radius (a vertical line where R is fixed), in the colour of its node count there.
        let omega_on_x = config.x.parameter == Parameter::Omega;
        let radius_axis = config.axis(Parameter::Radius).is_some();
        let place = |w: f64, r: f64, end: usize| -> (f64, f64) {
            let w = w / omega_unit;
            match (omega_on_x, radius_axis) {
                (true, true) => (w, r),
                (false, true) => (r, w),
                (true, false) => (w, if end == 0 { ey[0] } else { ey[ny] }),
                (false, false) => (if end == 0 { ex[0] } else { ex[nx] }, w),
            }
        };
        let inside = |(x, y): (f64, f64)| x >= ex[0] && x <= ex[nx] && y >= ey[0] && y <= ey[ny];
        let branches: std::collections::BTreeSet<usize> =
            folds.iter().flat_map(|(_, f)| f.iter().map(|f| f.branch)).collect();
        for b in branches {
            let mut line: Vec<(f64, f64)> = Vec::new();
            let mut shade = BLACK;
            for (r, f) in folds {
                if let Some(f) = f.iter().find(|f| f.branch == b) {
                    shade = colour(f.nodes);
                    let ends: &[usize] = if radius_axis { &[0] } else { &[0, 1] };
                    line.extend(ends.iter().map(|&e| place(f.omega, *r, e)).filter(|p| inside(*p)));
                }
            }
            chart
                .draw_series([PathElement::new(line.clone(), WHITE.stroke_width(5))])
                .map_err(|e| fail(&e))?;
            chart
                .draw_series([PathElement::new(line.clone(), shade.stroke_width(2))])
                .map_err(|e| fail(&e))?;
            if radius_axis {
                chart
                    .draw_series(line.iter().map(|&p| Circle::new(p, 3, WHITE.filled())))
                    .map_err(|e| fail(&e))?;
                chart
                    .draw_series(line.iter().map(|&p| Circle::new(p, 3, shade.stroke_width(1))))
                    .map_err(|e| fail(&e))?;
            }
        }
        // The critical speeds on an ω axis.
        let dashed = BLACK.mix(0.8).stroke_width(2);
        for (i, &w) in critical.iter().enumerate() {
            let label = format!("ω{}", i + 1);
            let text = ("sans-serif", 16).into_font().color(&BLACK);
            if config.x.parameter == Parameter::Omega && w > ex[0] && w < ex[nx] {
                chart
                    .draw_series(DashedLineSeries::new([(w, ey[0]), (w, ey[ny])], 6, 4, dashed))
                    .map_err(|e| fail(&e))?;
                let below_top = ey[ny] - 0.015 * (ey[ny] - ey[0]);
                chart.draw_series([Text::new(label, (w, below_top), text)]).map_err(|e| fail(&e))?;
            } else if config.y.parameter == Parameter::Omega && w > ey[0] && w < ey[ny] {
                chart
                    .draw_series(DashedLineSeries::new([(ex[0], w), (ex[nx], w)], 6, 4, dashed))
                    .map_err(|e| fail(&e))?;
                chart.draw_series([Text::new(label, (ex[0], w), text)]).map_err(|e| fail(&e))?;
            }
        }
    }

    // The key.
    let mut entries: Vec<(Swatch, String)> = counts
        .iter()
        .map(|&n| {
            (Swatch::Cell(colour(Some(n)), false), format!("{n} node{}", if n == 1 { "" } else { "s" }))
        })
        .collect();
    let unsettled = points.iter().filter_map(|p| p.result.as_ref()).find(|r| !r.settled);
    if let Some(r) = unsettled {
        entries.push((Swatch::Cell(faint(colour(Some(r.nodes))), true), "pale, dotted: not settled".into()));
    }
    if done < points.len() {
        entries.push((Swatch::Cell(MISSING, false), "failed or not run".into()));
    }
    entries.push((Swatch::Line, "boundary between basins".into()));
    if [&config.x, &config.y].iter().any(|a| a.parameter == Parameter::Omega) && !critical.is_empty() {
        entries.push((Swatch::Dashed, "critical speed ωk (small R):".into()));
        entries.push((Swatch::None, "the k-node shape is born".into()));
    }
    if folds.iter().any(|(_, f)| !f.is_empty()) {
        entries.push((Swatch::Fold, "fold of a steady branch: its".into()));
        entries.push((Swatch::None, "shapes exist at higher ω".into()));
        entries.push((Swatch::None, "(colour: their node count)".into()));
    }
    entries.push((Swatch::None, "nodes = axis crossings + 1".into()));
    entries.push((Swatch::None, "(the pivot counted)".into()));
    entries.push((Swatch::None, format!("{} points, {} s each", points.len(), short(config.duration))));
    let text = TextStyle::from(("sans-serif", 14).into_font());
    for (i, (swatch, label)) in entries.iter().enumerate() {
        let y = 40 + 26 * i as i32;
        let line = BLACK.stroke_width(2);
        match *swatch {
            Swatch::Cell(fill, dot) => {
                key.draw(&Rectangle::new([(12, y - 2), (34, y + 14)], fill.filled()))
                    .map_err(|e| fail(&e))?;
                if dot {
                    key.draw(&Circle::new((23, y + 6), 2, BLACK.filled())).map_err(|e| fail(&e))?;
                }
            }
            Swatch::Line => {
                key.draw(&PathElement::new([(12, y + 6), (34, y + 6)], line)).map_err(|e| fail(&e))?
            }
            Swatch::Dashed => {
                for x in [12, 26] {
                    key.draw(&PathElement::new([(x, y + 6), (x + 8, y + 6)], line)).map_err(|e| fail(&e))?;
                }
            }
            Swatch::Fold => {
                key.draw(&PathElement::new([(12, y + 6), (34, y + 6)], WHITE.stroke_width(5)))
                    .map_err(|e| fail(&e))?;
                key.draw(&PathElement::new([(12, y + 6), (34, y + 6)], colour(Some(2)).stroke_width(2)))
                    .map_err(|e| fail(&e))?;
                key.draw(&Circle::new((23, y + 6), 3, WHITE.filled())).map_err(|e| fail(&e))?;
                key.draw(&Circle::new((23, y + 6), 3, colour(Some(2)).stroke_width(1)))
                    .map_err(|e| fail(&e))?;
            }
            Swatch::None => {}
        }
        key.draw_text(label, &text, (46, y - 1)).map_err(|e| fail(&e))?;
    }
    root.present().map_err(|e| fail(&e))
}

/// What stands left of a label in the key.
enum Swatch {
    /// A cell's colour, with the dot of an unsettled point.
    Cell(RGBColor, bool),
    Line,
    Dashed,
    Fold,
    None,
}
