//! Writing the command's JSON files (run.json, final.json, shape.json, sweep.json) so that
//! a reader never sees half a file.

use std::io::Write;
use std::path::Path;

use serde::Serialize;

use crate::error::{CliError, CliResult, io_failed};

/// Writes `value` as pretty JSON atomically: to `NAME.json.tmp` beside `path`, flushed and
/// synced, then renamed over `path`, so a reader sees the old or the new file, never half.
pub fn write_json_atomic<T: Serialize + ?Sized>(path: &Path, value: &T) -> CliResult<()> {
    let tmp = path.with_extension("json.tmp");
    let text = serde_json::to_string_pretty(value).map_err(|e| CliError::failed(e.to_string()))?;
    let mut f = std::fs::File::create(&tmp).map_err(|e| io_failed("create", &tmp, e))?;
    f.write_all(text.as_bytes())
        .and_then(|()| f.write_all(b"\n"))
        .map_err(|e| io_failed("write", &tmp, e))?;
    f.sync_all().map_err(|e| io_failed("sync", &tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| io_failed("rename into", path, e))
}

/// A warning on stderr when `path`, read to repeat a run, was written by another version
/// of the program (`version`): the results may differ.
pub fn warn_other_version(path: &Path, version: &str) {
    if version != env!("CARGO_PKG_VERSION") {
        eprintln!(
            "pendulum: warning: {} was written by pendulum {version}, this is {}; results may differ",
            path.display(),
            env!("CARGO_PKG_VERSION")
        );
    }
}
