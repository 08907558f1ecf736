//! `pendulum view RUN_DIR`: a run as one self-contained web page (data and scripts inline,
//! nothing fetched) with an orbit camera, playback, a time slider and the energy ledger
//! (`viewer.js`), served on localhost or written to a file (`--export`).

mod scene;
mod serve;

use std::path::PathBuf;

use clap::Args;

use crate::error::{CliError, CliResult, io_failed};
use crate::render::source::Run;

/// The page's HTML and style, with `/*SCENE*/` where the data goes and `/*VIEWER*/`
/// where the script goes.
const PAGE: &str = include_str!("page.html");
/// The viewer: plain JavaScript, no library, no build step.
const VIEWER: &str = include_str!("viewer.js");

/// Options of `pendulum view`.
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// The run directory: what `pendulum simulate --out DIR` wrote (run.json,
    /// trajectory.csv and energy.csv are read; shape.json when there is one).
    #[arg(value_name = "RUN_DIR")]
    pub run: PathBuf,
    /// Write the page to this file instead of serving it: one self-contained HTML file
    /// that opens offline.
    #[arg(long, value_name = "FILE")]
    pub export: Option<PathBuf>,
    /// Serve on this port of 127.0.0.1 (0: any free port; the URL is printed).
    #[arg(long, default_value_t = 8765, conflicts_with = "export")]
    pub port: u16,
    /// Most frames in the page; longer runs are thinned to every k-th sample.
    #[arg(long, value_name = "N", default_value_t = scene::DEFAULT_FRAMES)]
    pub frames: usize,
}

/// Runs `pendulum view`.
pub fn view(args: &ViewArgs) -> CliResult<()> {
    if args.frames < 2 {
        return Err(CliError::usage(format!("--frames must be at least 2, got {}", args.frames)));
    }
    let run = Run::open(&args.run)?;
    let scene = scene::Scene::read(&args.run, &run, args.frames)?;
    let json = serde_json::to_string(&scene)
        .map_err(|e| CliError::failed(format!("cannot encode the scene: {e}")))?;
    // Inside a <script> element nothing may close it.
    let json = json.replace("</", "<\\/");
    let page = PAGE.replacen("/*SCENE*/", &json, 1).replacen("/*VIEWER*/", VIEWER, 1);
    let what = format!(
        "{}: {} frames of {} samples (every {}), {:.1} MB",
        args.run.display(),
        scene.frame_count(),
        scene.samples,
        scene.every,
        page.len() as f64 / 1e6
    );
    let Some(path) = &args.export else {
        return serve::serve(page, args.port, &what);
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
