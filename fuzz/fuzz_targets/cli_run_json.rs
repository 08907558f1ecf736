//! The run.json reader (`pendulum_experiment::RunFile::read`, which `pendulum simulate
//! --from` and `pendulum.Run.load` use) on arbitrary file contents: a checked
//! configuration or a usage error naming the file, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("pendulum-fuzz-run-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let path = dir.join("run.json");
    std::fs::write(&path, data).expect("scratch file");
    match pendulum_experiment::RunFile::read(&path) {
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
