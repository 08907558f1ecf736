//! The expansions committed under `pendulum-macros/expanded/`, formatted, and the test that
//! keeps them current.

use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};

use super::expand;
use crate::parse::Input;

/// Expansions committed under `pendulum-macros/expanded/` so reviewers read diffs of
/// real generated code: each algorithm at one small and one larger size.
const EXPANSIONS: [(&str, &str); 4] = [
    ("planar3.rs", "pub struct Planar3 { kind: planar, links: 3, algorithm: dense }"),
    ("planar12.rs", "pub struct Planar12 { kind: planar, links: 12, algorithm: tension }"),
    ("spatial2.rs", "pub struct Spatial2 { kind: spatial, links: 2, algorithm: dense }"),
    ("spatial3.rs", "pub struct Spatial3 { kind: spatial, links: 3, algorithm: tension }"),
];

fn rustfmt(code: &str) -> String {
    let rustfmt = std::env::var("RUSTFMT").unwrap_or_else(|_| "rustfmt".into());
    let mut child = Command::new(&rustfmt)
        .args(["--edition", "2024", "--config", "max_width=110,use_small_heuristics=Max"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot run `{rustfmt}` to format the expansions: {e}"));
    child.stdin.take().unwrap().write_all(code.as_bytes()).unwrap();
    let output = child.wait_with_output().unwrap();
    assert!(output.status.success(), "rustfmt failed on the expansion");
    String::from_utf8(output.stdout).unwrap()
}

/// Writes the expansions (`write`) or checks that the committed ones are current.
fn generate(write: bool) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("expanded");
    for (file, item) in EXPANSIONS {
        let input: Input = syn::parse_str(item).unwrap();
        let header = format!(
            "// The expansion of `pendulum_macros::model! {{ {item} }}`, formatted.\n\
             // Written by `UPDATE_EXPANSIONS=1 cargo test -p pendulum-macros --lib`; do not edit.\n\n"
        );
        let text = header + &rustfmt(&expand(&input).to_string());
        let path = dir.join(file);
        if write {
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(&path, text).unwrap();
        } else {
            let committed = std::fs::read_to_string(&path).unwrap_or_default();
            assert!(
                committed == text,
                "{} is stale: run `UPDATE_EXPANSIONS=1 cargo test -p pendulum-macros --lib` \
                 and review the diff",
                path.display()
            );
        }
    }
}

#[test]
fn committed_expansions_are_current() {
    generate(std::env::var_os("UPDATE_EXPANSIONS").is_some());
}
