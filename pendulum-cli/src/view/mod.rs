//! `pendulum view RUN_DIR`: a run as one self-contained web page (data and scripts inline,
//! nothing fetched: `pendulum_experiment::page`) with an orbit camera, playback, a time
//! slider and the energy ledger, served on localhost or written to a file (`--export`).

mod live;
mod serve;

use std::path::PathBuf;

use axum::Router;
use axum::response::Html;
use axum::routing::get;
use clap::Args;
use pendulum_experiment::page;

use crate::error::{CliResult, io_failed};

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
    #[arg(long, value_name = "N", default_value_t = page::DEFAULT_FRAMES, conflicts_with = "live")]
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
    let (page, scene) = page::page(dir, args.frames)?;
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
