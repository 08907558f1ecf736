//! The committed reference cases (`reference/cases/*.json`), built into the library, so
//! that a program without the repository (the Python package) checks claims against the
//! same sympy derivation `cargo xtask verify` reads from the files.

use std::sync::OnceLock;

use anyhow::Result;

use crate::case::Case;

macro_rules! cases {
    ($($name:literal),* $(,)?) => {
        [$(($name, include_str!(concat!("../../reference/cases/", $name, ".json")))),*]
    };
}

/// Every committed case: its name and its file's text.
const FILES: [(&str, &str); 13] = cases!(
    "planar_n1",
    "planar_n2",
    "planar_n3",
    "planar_n4",
    "planar_n5",
    "planar_n6",
    "planar_n7",
    "planar_n8",
    "spatial_n1",
    "spatial_n2",
    "spatial_n3",
    "spatial_n4",
    "spatial_n5",
);

/// The committed cases, planar by n then spatial by n (parsed once).
pub fn cases() -> Result<&'static [Case]> {
    static CASES: OnceLock<std::result::Result<Vec<Case>, String>> = OnceLock::new();
    let parsed = CASES.get_or_init(|| {
        FILES
            .iter()
            .map(|(name, text)| Case::parse(text, &format!("{name}.json (built in)"), name))
            .collect::<Result<Vec<_>>>()
            .map_err(|e| format!("{e:#}"))
    });
    parsed.as_deref().map_err(|e| anyhow::anyhow!("{e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_built_in_cases_are_the_committed_files() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../reference/cases");
        let files = crate::case::load_all(&dir).unwrap();
        let built_in = cases().unwrap();
        assert_eq!(built_in.len(), files.len(), "a case file is missing from FILES");
        for (a, b) in built_in.iter().zip(&files) {
            assert_eq!((a.kind, a.links, &a.name), (b.kind, b.links, &b.name));
        }
    }
}
