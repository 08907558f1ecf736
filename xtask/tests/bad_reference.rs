//! Bad reference files: a truncated file, an unknown symbol, a mass matrix of the wrong
//! size. Each gives an error naming the file, the case and the entry; none panics. (The
//! loader's other checks are unit tests in `xtask/src/case.rs`; the loader is also a
//! fuzz target, `fuzz/fuzz_targets/reference_case.rs`.)

use std::path::PathBuf;

use serde_json::{Value, json};
use xtask::case::Case;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pendulum-bad-reference-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn original() -> String {
    std::fs::read_to_string(xtask::cases_dir().join("planar_n2.json")).unwrap()
}

/// Loads `text` as `planar_n2.json` and returns the full error chain.
fn load_error(name: &str, text: &str) -> String {
    let path = scratch(name).join("planar_n2.json");
    std::fs::write(&path, text).unwrap();
    let message = format!("{:#}", Case::load(&path).unwrap_err());
    println!("{name}: {message}");
    assert!(message.contains("planar_n2.json"), "{message}");
    message
}

#[test]
fn a_truncated_file_is_invalid_json() {
    let text = original();
    assert!(Case::load(&xtask::cases_dir().join("planar_n2.json")).is_ok());
    for fraction in [0.0, 0.1, 0.5, 0.9, 0.999] {
        let cut = (text.len() as f64 * fraction) as usize;
        let message = load_error(&format!("truncated-{cut}"), &text[..cut]);
        assert!(message.contains(": invalid JSON: EOF while parsing"), "{message}");
    }
}

fn edited(edit: impl FnOnce(&mut Value)) -> String {
    let mut json: Value = serde_json::from_str(&original()).unwrap();
    edit(&mut json);
    json.to_string()
}

#[test]
fn an_unknown_symbol_is_named_with_its_entry() {
    let text = edited(|v| v["mass_matrix"][1][0] = json!(["*", "m2", "zeta"]));
    let message = load_error("unknown-symbol", &text);
    assert!(
        message.ends_with("planar_n2.json: case planar_n2: mass_matrix[1][0]: unknown symbol \"zeta\""),
        "{message}"
    );
}

#[test]
fn a_wrong_matrix_size_is_named() {
    let text = edited(|v| v["mass_matrix"] = json!([[1, 0, 0], [0, 1, 0], [0, 0, 1]]));
    let message = load_error("rows", &text);
    assert!(
        message.ends_with("planar_n2.json: case planar_n2: mass_matrix: has 3 entries, expected 2"),
        "{message}"
    );
    let text = edited(|v| v["mass_matrix"][1] = json!([1]));
    let message = load_error("columns", &text);
    assert!(
        message.ends_with("planar_n2.json: case planar_n2: mass_matrix[1]: has 1 entries, expected 2"),
        "{message}"
    );
}
