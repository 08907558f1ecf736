//! The page of a recorded run: one self-contained HTML file (data and scripts inline,
//! nothing fetched) with an orbit camera, playback, a time slider, the co-rotating frame
//! and the energy ledger. `pendulum view` serves or exports it; the Python package shows
//! it in a notebook.

mod scene;

use std::path::Path;

pub use scene::{DEFAULT_FRAMES, Scene};

use crate::error::{Error, Result};
use crate::run_dir::Run;
use crate::spelling::opt;

/// The page's HTML and style, with `/*SCENE*/` where the data goes and `/*VIEWER*/`
/// where the script goes.
const PAGE: &str = include_str!("page.html");
/// Drawing the chain, shared with the live page: plain JavaScript, no library, no build
/// step.
pub const DRAW: &str = include_str!("draw.js");
/// The viewer of a recorded run.
const VIEWER: &str = include_str!("viewer.js");

/// The page of the run in `dir` with at most `frames` samples (longer runs thinned to
/// every k-th), and its scene.
pub fn page(dir: &Path, frames: usize) -> Result<(String, Scene)> {
    if frames < 2 {
        return Err(Error::invalid(format!("{} must be at least 2, got {frames}", opt("frames"))));
    }
    let run = Run::open(dir)?;
    let scene = Scene::read(dir, &run, frames)?;
    let json =
        serde_json::to_string(&scene).map_err(|e| Error::failed(format!("cannot encode the scene: {e}")))?;
    // Inside a <script> element nothing may close it.
    let json = json.replace("</", "<\\/");
    // The scene last: nothing in the run's text is read as a placeholder.
    let page =
        PAGE.replacen("/*DRAW*/", DRAW, 1).replacen("/*VIEWER*/", VIEWER, 1).replacen("/*SCENE*/", &json, 1);
    Ok((page, scene))
}
