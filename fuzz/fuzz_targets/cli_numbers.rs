//! The number readers: a comma list typed on the command line (`pendulum-cli/src/spec.rs`,
//! included by path: the CLI is a binary crate) and a number file (the run library's
//! `read_numbers`). Either the numbers, all finite, or a usage error naming the option;
//! never a panic.
#![no_main]

#[allow(dead_code, unused_imports)]
#[path = "../../pendulum-cli/src/error.rs"]
mod error;
#[allow(dead_code)]
#[path = "../../pendulum-cli/src/spec.rs"]
mod spec;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        match spec::parse_list("--masses", text) {
            Ok(values) => assert!(values.iter().all(|v| v.is_finite())),
            Err(e) => assert!(e.to_string().starts_with("--masses: "), "{e}"),
        }
        if let Ok(values) = spec::parse_list("--masses", text) {
            for n in [1, 3] {
                let _ = spec::expand("--masses", values.clone(), n);
            }
        }
    }
    let dir = std::env::temp_dir().join(format!("pendulum-fuzz-numbers-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let path = dir.join("numbers.txt");
    std::fs::write(&path, data).expect("scratch file");
    match pendulum_experiment::read_numbers("--lengths", &path) {
        Ok(values) => assert!(!values.is_empty() && values.iter().all(|v| v.is_finite())),
        Err(e) => assert!(e.to_string().starts_with("--lengths: "), "{e}"),
    }
});
