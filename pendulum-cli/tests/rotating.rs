//! `pendulum modes` against closed forms (the simple pendulum, node counts, Bernoulli's
//! hanging-chain frequencies) and bad arguments of `modes` and `steady`; `steady` itself
//! in `steady.rs`.

mod common;

use common::{Csv, run_in, scratch, stderr};

#[test]
fn one_link_has_the_simple_pendulum_frequency() {
    let dir = scratch("modes-one");
    let out = run_in(&dir, &["modes", "--n", "1", "--lengths", "0.4", "--out", "m"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let csv = Csv::read(&dir.join("m/modes.csv"));
    let omega = csv.column("omega")[0];
    assert!((omega - (9.81_f64 / 0.4).sqrt()).abs() < 1e-12, "{omega}");
    assert!(dir.join("m/modes.png").exists());
}

#[test]
fn a_uniform_chain_approaches_bernoulli_and_mode_k_has_k_nodes() {
    let dir = scratch("modes-uniform");
    let out = run_in(&dir, &["modes", "--n", "20", "--lengths", "0.05", "--count", "4", "--out", "m"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let table = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(table.contains("Bernoulli"), "{table}");
    let csv = Csv::read(&dir.join("m/modes.csv"));
    assert_eq!(csv.rows.len(), 4);
    // ω_k = (j_{0,k} / 2) √(g/L), L = 1 m; 20 links are within 2 % for the first four.
    let zeros = [2.404825557695773, 5.520078110286311, 8.653727912911013, 11.79153443901428];
    for (k, (omega, nodes)) in csv.column("omega").iter().zip(csv.column("nodes")).enumerate() {
        let bernoulli = 0.5 * zeros[k] * 9.81_f64.sqrt();
        assert!((omega / bernoulli - 1.0).abs() < 0.02, "mode {}: {omega} vs {bernoulli}", k + 1);
        assert!(*omega < bernoulli, "a discrete chain is slower than the continuum");
        assert_eq!(nodes as usize, k + 1);
    }
}

#[test]
fn bad_rotation_arguments_are_named() {
    let dir = scratch("rotating-errors");
    let cases: [(&[&str], &str); 6] = [
        (&["modes", "--n", "3", "--count", "5"], "--count"),
        (&["modes", "--masses", "1,-1"], "mass of link 2"),
        (&["steady", "--radius", "-1"], "radius"),
        (&["steady", "--gravity", "0"], "gravity"),
        (&["steady", "--omega-max", "-2"], "--omega-max"),
        (&["steady", "--radius", "0.1", "--branches", "2"], "--branches"),
    ];
    for (args, needle) in cases {
        let out = run_in(&dir, args);
        let message = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {message}");
        assert_eq!(message.trim_end().lines().count(), 1, "{args:?}: {message}");
        assert!(message.contains(needle), "{args:?}: {message}");
    }
}
