//! The reference case loader (`xtask::case::Case::load`) on arbitrary file contents
//! (written to a scratch file named like a real case): a case or an error naming the
//! file, never a panic. A loaded case is evaluated at one point.
#![no_main]

use libfuzzer_sys::fuzz_target;
use xtask::case::{Case, Params, Point};

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("pendulum-fuzz-case-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let path = dir.join("planar_n1.json");
    std::fs::write(&path, data).expect("scratch file");
    match Case::load(&path) {
        Ok(case) => {
            let (n, dof, space) = (case.links, case.dof(), case.kind.space());
            let params =
                Params { masses: vec![1.0; n], lengths: vec![1.0; n], gravity: 9.81, damping: vec![0.1; n] };
            let point = Point {
                q: vec![0.3; dof],
                qd: vec![0.2; dof],
                torque: vec![0.0; dof],
                pivot_acceleration: vec![0.0; space],
            };
            let _ = case.evaluate(&params, &point);
        }
        Err(e) => assert!(format!("{e:#}").contains("planar_n1.json"), "{e:#}"),
    }
});
