//! Writing the run's JSON files (run.json, final.json and the front ends' own) so that a
//! reader never sees half a file, and reading a command's file back for `--from`.

use std::io::Write;
use std::path::Path;

use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::error::{Error, Result, io_failed};
use crate::spelling::opt;

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

/// Reads `path`, given to `--from`, as the `NAME.json` of `pendulum COMMAND` (its
/// `"program"` and `"command"` fields say so) and converts it to `T`. Errors name the file
/// and what it is instead: unreadable, not JSON, another program's or command's (a
/// run.json of `pendulum simulate` is recognised by its `config.dim`), or the fields `T`
/// misses.
pub fn read_command_file<T: DeserializeOwned>(path: &Path, command: &str) -> Result<T> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::invalid(format!("{}: cannot read {}: {e}", opt("from"), path.display())))?;
    let article = if command.starts_with(['a', 'e', 'i', 'o', 'u']) { "an" } else { "a" };
    let not_it = |why: String| {
        Error::invalid(format!(
            "{}: {} is not {article} {command}.json of pendulum {command}: {why}",
            opt("from"),
            path.display()
        ))
    };
    let value: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| not_it(format!("not JSON ({e})")))?;
    let field = |name: &str| value.get(name).and_then(|v| v.as_str()).map(str::to_owned);
    match (field("program"), field("command")) {
        (Some(p), _) if p != "pendulum" => return Err(not_it(format!("written by '{p}'"))),
        (Some(_), Some(c)) if c != command => return Err(not_it(format!("written by pendulum {c}"))),
        (Some(_), None) if value.get("config").is_some_and(|c| c.get("dim").is_some()) => {
            return Err(not_it(
                "a run.json of pendulum simulate (repeat it with pendulum simulate --from)".into(),
            ));
        }
        (None, _) | (Some(_), None) => return Err(not_it(format!("no \"command\": \"{command}\" in it"))),
        _ => {}
    }
    serde_json::from_value(value).map_err(|e| not_it(e.to_string()))
}
