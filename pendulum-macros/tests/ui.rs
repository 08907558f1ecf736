//! Compile errors for bad `model!` input point at the offending token (one mistake per
//! file in `tests/ui`, the file named after it), a batch of a model that has no batched
//! form says how to get one, and good input compiles cleanly
//! (`tests/ui_pass`). Regenerate the expected `.stderr` files with
//! `TRYBUILD=overwrite cargo test -p pendulum-macros --test ui` and read the diff.

#[test]
fn ui() {
    let cases = trybuild::TestCases::new();
    cases.compile_fail("tests/ui/*.rs");
    cases.pass("tests/ui_pass/*.rs");
}
