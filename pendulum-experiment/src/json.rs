//! Writing the run's JSON files (run.json, final.json and the front ends' own) so that a
//! reader never sees half a file.

use std::io::Write;
use std::path::Path;

use serde::Serialize;

use crate::error::{Error, Result, io_failed};

/// Writes `value` as pretty JSON atomically: to `NAME.json.tmp` beside `path`, flushed and
/// synced, then renamed over `path`, so a reader sees the old or the new file, never half.
pub fn write_json_atomic<T: Serialize + ?Sized>(path: &Path, value: &T) -> Result<()> {
    let tmp = path.with_extension("json.tmp");
    let text = serde_json::to_string_pretty(value).map_err(|e| Error::failed(e.to_string()))?;
    let mut f = std::fs::File::create(&tmp).map_err(|e| io_failed("create", &tmp, e))?;
    f.write_all(text.as_bytes())
        .and_then(|()| f.write_all(b"\n"))
        .map_err(|e| io_failed("write", &tmp, e))?;
    f.sync_all().map_err(|e| io_failed("sync", &tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| io_failed("rename into", path, e))
}
