//! The CLI's run.json reader (`RunFile::read` in `pendulum-cli/src/config.rs`, included by
//! path with the modules it uses: the CLI is a binary crate) on arbitrary file contents:
//! a checked configuration or a usage error naming the file, never a panic.
#![no_main]

#[allow(dead_code)]
#[path = "../../pendulum-cli/src/args.rs"]
mod args;
#[allow(dead_code)]
#[path = "../../pendulum-cli/src/chain_args.rs"]
mod chain_args;
#[allow(dead_code)]
#[path = "../../pendulum-cli/src/config.rs"]
mod config;
#[allow(dead_code)]
#[path = "../../pendulum-cli/src/error.rs"]
mod error;
#[allow(dead_code)]
#[path = "../../pendulum-cli/src/final_state.rs"]
mod final_state;
#[allow(dead_code)]
#[path = "../../pendulum-cli/src/json_file.rs"]
mod json_file;
#[allow(dead_code)]
#[path = "../../pendulum-cli/src/spec.rs"]
mod spec;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("pendulum-fuzz-run-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let path = dir.join("run.json");
    std::fs::write(&path, data).expect("scratch file");
    match config::RunFile::read(&path) {
        Ok(file) => {
            // `check` leaves the values to the chain's own validation (as the CLI does
            // next): building the chain gives the chain or an error, never a panic.
            // (A first version asserted success here; the fuzzer found masses [0, 1],
            // which the CLI rejects at this point: "mass of link 1 must be finite and
            // positive, got 0", exit 2.)
            let c = &file.config;
            let chain = pendulum_core::Chain::<nalgebra::Dyn>::new(&c.masses, &c.lengths, c.gravity)
                .and_then(|chain| chain.with_damping(&c.damping));
            if let Err(e) = chain {
                assert!(!e.to_string().is_empty());
            }
        }
        Err(e) => assert!(e.to_string().starts_with("--from: "), "{e}"),
    }
});
