//! `cargo xtask reference [--check]`: regenerate the sympy reference in `reference/cases`, or check it is current.
//!
//! The work is done by `reference/derive.py` (python3 with sympy 1.14.0, see
//! `reference/requirements.txt`), run with `PYTHONHASHSEED=0`; its output is
//! byte-for-byte deterministic. Both modes generate into a fresh scratch directory
//! first. Without `--check` the `*.json` files of `reference/cases` are then replaced
//! (stale ones removed), so a failed run leaves the committed files untouched. With
//! `--check` the scratch files are compared with the committed ones by name and
//! bytes ([`compare_dirs`]).

use std::collections::BTreeMap;
use std::fmt;
use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{SystemTime, UNIX_EPOCH};

use anyhow::{Context, Result, bail};

/// The sympy version the committed reference was generated with.
pub const SYMPY_VERSION: &str = "1.14.0";

const INSTALL_HINT: &str = "pip install -r reference/requirements.txt";
const REGENERATE_HINT: &str = "run `cargo xtask reference` to regenerate";

/// Regenerates `reference/cases` (or, with `check`, verifies it is up to date).
pub fn run(check: bool) -> Result<()> {
    let root = crate::workspace_root();
    let cases = crate::cases_dir();
    check_python()?;

    let scratch = ScratchDir::new("pendulum-reference").context("creating a scratch directory")?;
    derive(&root, scratch.path())?;
    let generated = read_json_files(scratch.path())?;
    if generated.is_empty() {
        bail!("reference/derive.py wrote no *.json files into {}", scratch.path().display());
    }

    if check {
        let diff = compare_dirs(scratch.path(), &cases)?;
        if !diff.is_clean() {
            bail!("{} is not up to date with reference/derive.py:\n{diff}{REGENERATE_HINT}", cases.display());
        }
        eprintln!("reference: {} files in {} are up to date", generated.len(), cases.display());
    } else {
        replace_json_files(&cases, &generated)?;
        eprintln!("reference: wrote {} files to {}", generated.len(), cases.display());
    }
    Ok(())
}

/// Fails unless `python3` runs and imports sympy [`SYMPY_VERSION`].
pub(crate) fn check_python() -> Result<()> {
    let output = Command::new("python3")
        .args(["-c", "import sympy; print(sympy.__version__)"])
        .stdin(Stdio::null())
        .output()
        .with_context(|| format!("cannot run python3 (is it installed?); then `{INSTALL_HINT}`"))?;
    if !output.status.success() {
        bail!(
            "python3 cannot import sympy ({}): `{INSTALL_HINT}`",
            String::from_utf8_lossy(&output.stderr).trim().lines().last().unwrap_or("no message")
        );
    }
    let version = String::from_utf8_lossy(&output.stdout).trim().to_string();
    if version != SYMPY_VERSION {
        bail!("python3 has sympy {version}, the reference needs sympy {SYMPY_VERSION}: `{INSTALL_HINT}`");
    }
    Ok(())
}

/// Runs `python3 reference/derive.py --out OUT` from the workspace root.
fn derive(root: &Path, out: &Path) -> Result<()> {
    let script = root.join("reference").join("derive.py");
    let status = Command::new("python3")
        .arg(&script)
        .arg("--out")
        .arg(out)
        .current_dir(root)
        .env("PYTHONHASHSEED", "0")
        .stdin(Stdio::null())
        .status()
        .with_context(|| format!("running python3 {}", script.display()))?;
    if !status.success() {
        bail!("python3 {} failed ({status}); see its output above", script.display());
    }
    Ok(())
}

/// Removes every `*.json` in `dir` (creating `dir` if needed) and writes `files` there.
fn replace_json_files(dir: &Path, files: &BTreeMap<String, Vec<u8>>) -> Result<()> {
    fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    for name in read_json_files(dir)?.keys() {
        let path = dir.join(name);
        fs::remove_file(&path).with_context(|| format!("removing stale {}", path.display()))?;
    }
    for (name, bytes) in files {
        let path = dir.join(name);
        fs::write(&path, bytes).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

/// The `*.json` files directly in `dir`, by file name. A missing directory has none.
pub fn read_json_files(dir: &Path) -> Result<BTreeMap<String, Vec<u8>>> {
    let mut files = BTreeMap::new();
    let entries = match fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(err) if err.kind() == io::ErrorKind::NotFound => return Ok(files),
        Err(err) => return Err(err).with_context(|| format!("listing {}", dir.display())),
    };
    for entry in entries {
        let entry = entry.with_context(|| format!("listing {}", dir.display()))?;
        let path = entry.path();
        if path.extension().is_none_or(|ext| ext != "json") || !path.is_file() {
            continue;
        }
        let name = entry
            .file_name()
            .into_string()
            .map_err(|name| anyhow::anyhow!("non-UTF-8 file name {name:?} in {}", dir.display()))?;
        let bytes = fs::read(&path).with_context(|| format!("reading {}", path.display()))?;
        files.insert(name, bytes);
    }
    Ok(files)
}

/// How the committed reference files differ from freshly generated ones (file names, sorted).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Comparison {
    /// Present in both, with different bytes.
    pub stale: Vec<String>,
    /// Generated but not committed.
    pub missing: Vec<String>,
    /// Committed but no longer generated.
    pub extra: Vec<String>,
}

impl Comparison {
    /// True when the committed files are exactly the generated ones.
    pub fn is_clean(&self) -> bool {
        self.stale.is_empty() && self.missing.is_empty() && self.extra.is_empty()
    }
}

impl fmt::Display for Comparison {
    /// One line per differing file, e.g. `  stale:   planar_n3.json (content differs)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for name in &self.stale {
            writeln!(f, "  stale:   {name} (content differs)")?;
        }
        for name in &self.missing {
            writeln!(f, "  missing: {name} (generated, not committed)")?;
        }
        for name in &self.extra {
            writeln!(f, "  extra:   {name} (committed, no longer generated)")?;
        }
        Ok(())
    }
}

/// Compares freshly `generated` files with the `committed` ones (name → bytes).
pub fn compare(generated: &BTreeMap<String, Vec<u8>>, committed: &BTreeMap<String, Vec<u8>>) -> Comparison {
    let mut diff = Comparison::default();
    for (name, bytes) in generated {
        match committed.get(name) {
            None => diff.missing.push(name.clone()),
            Some(old) if old != bytes => diff.stale.push(name.clone()),
            Some(_) => {}
        }
    }
    diff.extra = committed.keys().filter(|name| !generated.contains_key(*name)).cloned().collect();
    diff
}

/// Compares the `*.json` files of two directories: `generated` (fresh) against `committed`.
pub fn compare_dirs(generated: &Path, committed: &Path) -> Result<Comparison> {
    Ok(compare(&read_json_files(generated)?, &read_json_files(committed)?))
}

/// A fresh, uniquely named directory under the system temp dir, removed on drop.
#[derive(Debug)]
pub struct ScratchDir {
    path: PathBuf,
}

impl ScratchDir {
    /// Creates `$TMPDIR/<prefix>-<pid>-<nanos>-<counter>`; never reuses an existing directory.
    pub fn new(prefix: &str) -> io::Result<Self> {
        static COUNTER: AtomicU32 = AtomicU32::new(0);
        let nanos = SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_nanos());
        loop {
            let count = COUNTER.fetch_add(1, Ordering::Relaxed);
            let path = std::env::temp_dir().join(format!("{prefix}-{}-{nanos}-{count}", std::process::id()));
            match fs::create_dir(&path) {
                Ok(()) => return Ok(Self { path }),
                Err(err) if err.kind() == io::ErrorKind::AlreadyExists => continue,
                Err(err) => return Err(err),
            }
        }
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for ScratchDir {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) {
        fs::write(dir.join(name), text).unwrap();
    }

    fn names(list: &[&str]) -> Vec<String> {
        list.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn identical_dirs_are_clean() {
        let a = ScratchDir::new("xtask-regen-test").unwrap();
        let b = ScratchDir::new("xtask-regen-test").unwrap();
        for dir in [a.path(), b.path()] {
            write(dir, "planar_n1.json", "{}\n");
            write(dir, "spatial_n1.json", "[1]\n");
        }
        let diff = compare_dirs(a.path(), b.path()).unwrap();
        assert!(diff.is_clean(), "{diff}");
        assert_eq!(diff.to_string(), "");
    }

    #[test]
    fn reports_stale_missing_and_extra_files() {
        let generated = ScratchDir::new("xtask-regen-test").unwrap();
        let committed = ScratchDir::new("xtask-regen-test").unwrap();
        write(generated.path(), "planar_n1.json", "{}\n");
        write(committed.path(), "planar_n1.json", "{}\n");
        write(generated.path(), "planar_n2.json", "{\"a\": 1}\n");
        write(committed.path(), "planar_n2.json", "{\"a\": 2}\n");
        write(generated.path(), "planar_n3.json", "new\n");
        write(generated.path(), "spatial_n2.json", "new\n");
        write(committed.path(), "planar_n9.json", "old\n");
        // only *.json files take part
        write(committed.path(), "notes.txt", "ignored\n");
        fs::create_dir(committed.path().join("sub.json")).unwrap();

        let diff = compare_dirs(generated.path(), committed.path()).unwrap();
        assert_eq!(
            diff,
            Comparison {
                stale: names(&["planar_n2.json"]),
                missing: names(&["planar_n3.json", "spatial_n2.json"]),
                extra: names(&["planar_n9.json"]),
            }
        );
        assert!(!diff.is_clean());
        let text = diff.to_string();
        for name in ["planar_n2.json", "planar_n3.json", "spatial_n2.json", "planar_n9.json"] {
            assert!(text.contains(name), "{text}");
        }
        assert!(!text.contains("planar_n1.json"), "{text}");
    }

    #[test]
    fn byte_level_difference_is_stale() {
        let mut generated = BTreeMap::new();
        let mut committed = BTreeMap::new();
        generated.insert("a.json".to_string(), b"{}\n".to_vec());
        committed.insert("a.json".to_string(), b"{}".to_vec());
        assert_eq!(compare(&generated, &committed).stale, names(&["a.json"]));
    }

    #[test]
    fn missing_committed_dir_means_all_missing() {
        let generated = ScratchDir::new("xtask-regen-test").unwrap();
        write(generated.path(), "planar_n1.json", "{}\n");
        let gone = generated.path().join("does-not-exist");
        let diff = compare_dirs(generated.path(), &gone).unwrap();
        assert_eq!(diff.missing, names(&["planar_n1.json"]));
        assert!(diff.stale.is_empty() && diff.extra.is_empty());
    }

    #[test]
    fn replace_removes_stale_json_and_keeps_other_files() {
        let dir = ScratchDir::new("xtask-regen-test").unwrap();
        write(dir.path(), "planar_n9.json", "old\n");
        write(dir.path(), "planar_n1.json", "old\n");
        write(dir.path(), "README.md", "keep\n");
        let mut files = BTreeMap::new();
        files.insert("planar_n1.json".to_string(), b"new\n".to_vec());
        replace_json_files(dir.path(), &files).unwrap();
        assert_eq!(read_json_files(dir.path()).unwrap(), files);
        assert_eq!(fs::read_to_string(dir.path().join("README.md")).unwrap(), "keep\n");
    }

    #[test]
    fn scratch_dirs_are_distinct_and_removed() {
        let a = ScratchDir::new("xtask-regen-test").unwrap();
        let b = ScratchDir::new("xtask-regen-test").unwrap();
        assert_ne!(a.path(), b.path());
        let path = a.path().to_path_buf();
        assert!(path.is_dir());
        drop(a);
        assert!(!path.exists());
    }
}
