//! `pendulum view RUN_DIR`: a run as one self-contained web page (data and scripts inline,
//! nothing fetched) with an orbit camera, playback, a time slider and the energy ledger
//! (`viewer.js`), served on localhost or written to a file (`--export`).

mod live;
mod scene;
mod serve;

use std::path::PathBuf;

use axum::Router;
use axum::response::Html;
use axum::routing::get;
use clap::Args;

use crate::error::{CliError, CliResult, io_failed};
use crate::render::source::Run;

/// The page's HTML and style, with `/*SCENE*/` where the data goes and `/*VIEWER*/`
/// where the script goes.
const PAGE: &str = include_str!("page.html");
/// Drawing the chain, shared with the live page: plain JavaScript, no library, no build
/// step.
const DRAW: &str = include_str!("draw.js");
/// The viewer of a recorded run.
const VIEWER: &str = include_str!("viewer.js");

/// Options of `pendulum view`.
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// The run directory: what `pendulum simulate --out DIR` wrote (run.json,
    /// trajectory.csv and energy.csv are read; shape.json when there is one).
    #[arg(value_name = "RUN_DIR", required_unless_present = "live", conflicts_with = "live")]
    pub run: Option<PathBuf>,
    /// Write the page to this file instead of serving it: one self-contained HTML file
    /// that opens offline.
    #[arg(long, value_name = "FILE", conflicts_with = "live")]
    pub export: Option<PathBuf>,
    /// Serve on this port of 127.0.0.1 (0: any free port; the URL is printed).
    #[arg(long, default_value_t = 8765, conflicts_with = "export")]
    pub port: u16,
    /// Most frames in the page; longer runs are thinned to every k-th sample.
    #[arg(long, value_name = "N", default_value_t = scene::DEFAULT_FRAMES, conflicts_with = "live")]
    pub frames: usize,
    /// A live chain instead of a run.
    #[command(flatten)]
    pub live: live::LiveArgs,
}

/// Runs `pendulum view`.
pub fn view(args: &ViewArgs) -> CliResult<()> {
    let Some(dir) = args.run.as_ref().filter(|_| !args.live.live) else {
        return live::live(&args.live, args.port);
    };
    if args.frames < 2 {
        return Err(CliError::invalid(format!("--frames must be at least 2, got {}", args.frames)));
    }
    let run = Run::open(dir)?;
    let scene = scene::Scene::read(dir, &run, args.frames)?;
    let json = serde_json::to_string(&scene)
        .map_err(|e| CliError::failed(format!("cannot encode the scene: {e}")))?;
    // Inside a <script> element nothing may close it.
    let json = json.replace("</", "<\\/");
    // The scene last: nothing in the run's text is read as a placeholder.
    let page =
        PAGE.replacen("/*DRAW*/", DRAW, 1).replacen("/*VIEWER*/", VIEWER, 1).replacen("/*SCENE*/", &json, 1);
    let what = format!(
        "{}: {} frames of {} samples (every {}), {:.1} MB",
        dir.display(),
        scene.frame_count(),
        scene.samples,
        scene.every,
        page.len() as f64 / 1e6
    );
    let Some(path) = &args.export else {
        let app = Router::new().route("/", get(move || async move { Html(page) }));
        return serve::serve(app, args.port, &what);
    };
    std::fs::write(path, page.as_bytes()).map_err(|e| io_failed("write", path, e))?;
    eprintln!(
        "pendulum: {}: {} frames of {} samples (every {}), {:.1} MB; open it in a browser",
        path.display(),
        scene.frame_count(),
        scene.samples,
        scene.every,
        page.len() as f64 / 1e6
    );
    Ok(())
}
