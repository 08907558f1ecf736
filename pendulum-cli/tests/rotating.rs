//! `pendulum modes` and `pendulum steady` against closed forms: the simple and conical
//! pendulum, node counts, Bernoulli's hanging-chain frequencies.

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
fn a_single_link_turns_as_the_conical_pendulum() {
    let dir = scratch("steady-conical");
    let out = run_in(&dir, &["steady", "--n", "1", "--lengths", "0.5", "--omega-max", "12", "--out", "s"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let csv = Csv::read(&dir.join("s/branches.csv"));
    let (omega, theta) = (csv.column("omega"), csv.column("theta1"));
    assert!((omega[0] - (9.81_f64 / 0.5).sqrt()).abs() < 1e-9, "critical speed {}", omega[0]);
    assert!(omega.last().unwrap() >= &12.0 && omega.len() > 5);
    for (w, t) in omega.iter().zip(&theta).skip(1) {
        // cos θ = g / (l ω²) on the branch.
        assert!((t.cos() - 9.81 / (0.5 * w * w)).abs() < 1e-9, "ω = {w}: θ = {t}");
    }
    for file in ["branches.png", "shapes.png"] {
        assert!(dir.join("s").join(file).exists(), "{file}");
    }
}

#[test]
fn branch_k_of_a_fixed_pivot_chain_has_k_nodes_and_a_forced_branch_exists() {
    let dir = scratch("steady-branches");
    let out = run_in(&dir, &["steady", "--n", "4", "--lengths", "0.25", "--out", "s"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let csv = Csv::read(&dir.join("s/branches.csv"));
    let (branch, nodes, omega) = (csv.column("branch"), csv.column("nodes"), csv.column("omega"));
    for k in 1..=3 {
        let on: Vec<usize> = (0..branch.len()).filter(|&i| branch[i] == k as f64).collect();
        assert!(on.len() > 3, "branch {k} has {} points", on.len());
        // Past the bifurcation point (the vertical itself) the shape has k nodes.
        assert!(on[1..].iter().all(|&i| nodes[i] == k as f64), "branch {k}");
        assert!(on.windows(2).all(|w| omega[w[1]] >= omega[w[0]] - 1e-9), "branch {k} folds back");
    }
    let out = run_in(&dir, &["steady", "--n", "4", "--lengths", "0.25", "--radius", "0.05", "--out", "f"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let forced = Csv::read(&dir.join("f/branches.csv"));
    assert!(forced.rows.len() > 5);
    assert!(forced.column("x1").iter().all(|x| *x != 0.0), "the forced chain never hangs on the axis");
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

#[test]
fn a_link_on_a_circling_pivot_has_the_forced_conical_branches_with_a_fold() {
    let dir = scratch("steady-forced-one");
    let args =
        ["steady", "--n", "1", "--lengths", "0.5", "--radius", "0.1", "--omega-max", "10", "--out", "s"];
    let out = run_in(&dir, &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let csv = Csv::read(&dir.join("s/branches.csv"));
    let (branch, omega, theta, x) =
        (csv.column("branch"), csv.column("omega"), csv.column("theta1"), csv.column("x1"));
    let count = branch.iter().fold(0.0_f64, |a, b| a.max(*b)) as usize;
    assert!(count >= 2, "the branch from slow rotation and the folded one, got {count}");
    for i in 0..branch.len() {
        // The rod carries weight and centrifugal force: g sin θ = ω² cos θ x, x = R + l sin θ.
        assert!((x[i] - 0.1 - 0.5 * theta[i].sin()).abs() < 1e-12);
        let residual = 9.81 * theta[i].sin() - omega[i].powi(2) * theta[i].cos() * x[i];
        assert!(residual.abs() < 1e-8 * (9.81 + omega[i].powi(2)), "row {i}: {residual}");
    }
    // The folded branch turns back in ω: its speeds go down, then up again.
    let second: Vec<f64> = (0..branch.len()).filter(|&i| branch[i] == 2.0).map(|i| omega[i]).collect();
    let lowest = second.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(lowest > 0.0 && lowest < second[0] && lowest < *second.last().unwrap(), "no fold: {second:?}");
}
