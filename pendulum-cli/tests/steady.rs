//! `pendulum steady` against closed forms and the core: the conical pendulum, node counts,
//! the forced branches, `--omega-max` as the exact end, the default range, every shape at
//! the `--omega` speeds (the same shapes as the continuation's, to 1e-9) with the
//! stability of `stability` / `relative_spectrum`, and bad speed lists.

mod common;

use nalgebra::{DVector, Dyn, U3};
use pendulum_core::{
    Chain, Circle, Directions, SteadyRotation, Verdict, relative_equilibrium, relative_spectrum, stability,
};

use common::{Table, run_in, scratch, stderr};

/// `theta1..n` of row `i` of a shapes or branches table.
fn theta(table: &Table, i: usize, n: usize) -> DVector<f64> {
    DVector::from_fn(n, |k, _| table.rows[i][table.index(&format!("theta{}", k + 1))].parse().unwrap())
}

/// Runs `pendulum steady args… --out s` in a fresh directory; returns it and stdout.
fn steady(name: &str, args: &[&str]) -> (std::path::PathBuf, String) {
    let dir = scratch(name);
    let mut all = vec!["steady"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--out", "s"]);
    let out = run_in(&dir, &all);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    (dir.join("s"), String::from_utf8_lossy(&out.stdout).into_owned())
}

fn uniform(n: usize, length: f64) -> Chain<Dyn> {
    Chain::<Dyn>::uniform(n, 1.0, length, 9.81).unwrap()
}

#[test]
fn a_single_link_turns_as_the_conical_pendulum() {
    let (dir, stdout) = steady("steady-conical", &["--n", "1", "--lengths", "0.5", "--omega-max", "12"]);
    // Issue 34: steady never said which chain it analysed.
    assert_eq!(
        stdout.lines().next().unwrap(),
        "steady rotation of 1 link of 0.5 m, 1 kg (L = 0.5 m, M = 1 kg), g = 9.81 m/s²; pivot fixed"
    );
    let csv = Table::read(&dir.join("branches.csv"));
    let (omega, theta) = (csv.column("omega"), csv.column("theta1"));
    assert!((omega[0] - (9.81_f64 / 0.5).sqrt()).abs() < 1e-9, "critical speed {}", omega[0]);
    assert!(*omega.last().unwrap() == 12.0 && omega.len() > 5);
    for (w, t) in omega.iter().zip(&theta).skip(1) {
        // cos θ = g / (l ω²) on the branch.
        assert!((t.cos() - 9.81 / (0.5 * w * w)).abs() < 1e-9, "ω = {w}: θ = {t}");
    }
    // The conical pendulum is stable (index 0) all along, past the bifurcation point (the
    // vertical at the critical speed, 0 nodes, where H is singular).
    let nodes = csv.column("nodes");
    assert_eq!(nodes[0], 0.0);
    assert!(csv.text("stability")[1..].iter().all(|s| s == "stable"));
    for file in ["branches.png", "shapes.png", "shapes.csv"] {
        assert!(dir.join(file).exists(), "{file}");
    }
}

#[test]
fn branch_k_of_a_fixed_pivot_chain_has_k_nodes_and_a_forced_branch_exists() {
    let (dir, table) = steady("steady-branches", &["--n", "4", "--lengths", "0.25"]);
    let csv = Table::read(&dir.join("branches.csv"));
    let (branch, nodes, omega) = (csv.column("branch"), csv.column("nodes"), csv.column("omega"));
    for k in 1..=3 {
        let on: Vec<usize> = (0..branch.len()).filter(|&i| branch[i] == k as f64).collect();
        assert!(on.len() > 3, "branch {k} has {} points", on.len());
        // The bifurcation point is the vertical (0 nodes), then the shape has k nodes.
        assert_eq!(nodes[on[0]], 0.0);
        assert!(on[1..].iter().all(|&i| nodes[i] == k as f64), "branch {k}");
        assert!(on.windows(2).all(|w| omega[w[1]] >= omega[w[0]] - 1e-9), "branch {k} folds back");
    }
    assert!(table.contains("nodes = axis crossings + 1, the pivot counted"), "{table}");
    let (forced, _) =
        steady("steady-branches-forced", &["--n", "4", "--lengths", "0.25", "--radius", "0.05"]);
    let forced = Table::read(&forced.join("branches.csv"));
    assert!(forced.rows.len() > 5);
    assert!(forced.column("x1").iter().all(|x| *x != 0.0), "the forced chain never hangs on the axis");
}

#[test]
fn a_link_on_a_circling_pivot_has_the_forced_conical_branches_with_a_fold() {
    let args = ["--n", "1", "--lengths", "0.5", "--radius", "0.1", "--omega-max", "10"];
    let (dir, _) = steady("steady-forced-one", &args);
    let csv = Table::read(&dir.join("branches.csv"));
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

#[test]
fn omega_max_is_the_exact_end_of_every_branch() {
    for (name, radius) in [("steady-exact-free", "0"), ("steady-exact-forced", "0.05")] {
        let (dir, table) = steady(name, &["--radius", radius, "--omega-max", "19.98"]);
        assert!(table.contains("branches up to ω = 19.98 rad/s"), "{table}");
        let csv = Table::read(&dir.join("branches.csv"));
        let (branch, omega) = (csv.column("branch"), csv.column("omega"));
        let count = branch.iter().fold(0.0_f64, |a, b| a.max(*b)) as usize;
        assert!(count >= 3, "{name}: {count} branches");
        for b in 1..=count {
            let on: Vec<f64> =
                (0..branch.len()).filter(|&i| branch[i] == b as f64).map(|i| omega[i]).collect();
            assert_eq!(*on.last().unwrap(), 19.98, "{name}: branch {b} ends at {}", on.last().unwrap());
            assert!(on.iter().all(|&w| w <= 19.98), "{name}: branch {b} overshoots");
        }
        // The shapes are listed at --omega-max by default, exactly there.
        let shapes = Table::read(&dir.join("shapes.csv"));
        assert!(shapes.column("omega").iter().all(|&w| w == 19.98));
    }
}

#[test]
fn the_default_range_covers_three_critical_speeds_for_either_pivot() {
    let chain = uniform(12, 0.1);
    let critical = SteadyRotation::new(&chain, 0.0).unwrap().bifurcation_speeds(4).unwrap();
    let (free, _) = steady("steady-default-free", &["--n", "12", "--lengths", "0.1"]);
    let (forced, _) = steady("steady-default-forced", &["--n", "12", "--lengths", "0.1", "--radius", "0.05"]);
    for dir in [free, forced] {
        let csv = Table::read(&dir.join("branches.csv"));
        let omega_max = csv.column("omega").iter().copied().fold(0.0, f64::max);
        assert!(omega_max > 1.2 * critical[2] && omega_max < critical[3], "{omega_max} vs {critical:?}");
        let nodes = csv.column("nodes");
        assert!(nodes.contains(&3.0) && !nodes.contains(&5.0), "{}: {nodes:?}", dir.display());
        let shapes = Table::read(&dir.join("shapes.csv"));
        let listed = shapes.column("nodes");
        assert!([1.0, 2.0, 3.0].iter().all(|k| listed.contains(k)), "{}: {listed:?}", dir.display());
    }
}

/// Where each branch of branches.csv crosses `omega`: the bracketing pairs of rows.
fn crossings(csv: &Table, omega: f64) -> Vec<(usize, usize)> {
    let (branch, w) = (csv.column("branch"), csv.column("omega"));
    (1..w.len())
        .filter(|&i| {
            branch[i] == branch[i - 1] && (w[i - 1] - omega) * (w[i] - omega) <= 0.0 && w[i] != w[i - 1]
        })
        .map(|i| (i - 1, i))
        .collect()
}

/// `steady --omega` lists the shapes of the continuation: at `--omega-max` the branches'
/// own last points, elsewhere the shape Newton finds from the bracketing points; one row
/// per crossing, the equations solved.
fn check_listed_shapes(name: &str, radius: f64) -> f64 {
    let (n, length) = (4, 0.25);
    let chain = uniform(n, length);
    let problem = SteadyRotation::new(&chain, radius).unwrap();
    let critical = SteadyRotation::new(&chain, 0.0).unwrap().bifurcation_speeds(3).unwrap();
    let speeds = [0.8 * critical[0], 1.5 * critical[0], 1.1 * critical[1], 1.2 * critical[2]];
    let list = speeds.map(|w| format!("{w:?}")).join(",");
    let r = radius.to_string();
    let last = format!("{:?}", speeds[3]);
    let args = ["--n", "4", "--lengths", "0.25", "--radius", &r, "--omega", &list, "--omega-max", &last];
    let (dir, _) = steady(name, &args);
    let branches = Table::read(&dir.join("branches.csv"));
    let shapes = Table::read(&dir.join("shapes.csv"));
    let (omega, branch) = (shapes.column("omega"), shapes.column("branch"));
    let mut worst = 0.0_f64;
    for &w in &speeds {
        let rows: Vec<usize> = (0..omega.len()).filter(|&i| omega[i] == w && branch[i] > 0.0).collect();
        let pairs = crossings(&branches, w);
        assert_eq!(
            rows.len(),
            pairs.len(),
            "{name} ω = {w}: {} shapes for {} crossings",
            rows.len(),
            pairs.len()
        );
        for &(a, b) in &pairs {
            let (wa, wb) = (branches.column("omega")[a], branches.column("omega")[b]);
            let s = if wb == wa { 1.0 } else { (w - wa) / (wb - wa) };
            let guess = theta(&branches, a, n) * (1.0 - s) + theta(&branches, b, n) * s;
            let direct = problem.solve(w, &guess).unwrap();
            // The listed shape of the same branch nearest the direct solve.
            let b_no = branches.column("branch")[a];
            let distance = rows
                .iter()
                .filter(|&&i| branch[i] == b_no)
                .map(|&i| (theta(&shapes, i, n) - &direct.theta).amax())
                .fold(f64::INFINITY, f64::min);
            assert!(distance < 1e-9, "{name} ω = {w}: branch {b_no} differs by {distance:e} rad");
            worst = worst.max(distance);
            if w == speeds[3] {
                // At --omega-max the listed shape is the branch's own last point.
                let end = theta(&branches, if branches.column("omega")[a] == w { a } else { b }, n);
                let at_end =
                    rows.iter().map(|&i| (theta(&shapes, i, n) - &end).amax()).fold(f64::INFINITY, f64::min);
                assert!(at_end < 1e-9, "{name}: {at_end:e} rad from the end of branch {b_no}");
                worst = worst.max(at_end);
            }
        }
        for &i in &rows {
            let residual = problem.residual(&theta(&shapes, i, n), w * w).norm();
            assert!(residual < 1e-10 * 9.81 * 4.0, "{name} ω = {w}: residual {residual:e}");
        }
    }
    worst
}

#[test]
fn listed_shapes_are_the_continuation_shapes() {
    let free = check_listed_shapes("steady-listed-free", 0.0);
    let forced = check_listed_shapes("steady-listed-forced", 0.05);
    println!("largest distance to the continuation: fixed pivot {free:.1e} rad, forced {forced:.1e} rad");
}

#[test]
fn listed_shapes_at_continuation_points_are_those_points() {
    // The continuation's pseudo-arclength corrector and `--omega`'s Newton at fixed ω, from
    // different starts, land on the same shape.
    let mut worst = [0.0_f64; 2];
    for (case, radius) in ["0", "0.05"].into_iter().enumerate() {
        let base = ["--n", "5", "--lengths", "0.2", "--radius", radius];
        let (dir, _) = steady(&format!("steady-points-{case}"), &base);
        let branches = Table::read(&dir.join("branches.csv"));
        let (branch, omega) = (branches.column("branch"), branches.column("omega"));
        // The middle point of every branch.
        let count = branch.iter().fold(0.0_f64, |a, b| a.max(*b)) as usize;
        let picks: Vec<usize> = (1..=count)
            .map(|b| {
                let on: Vec<usize> = (0..branch.len()).filter(|&i| branch[i] == b as f64).collect();
                on[on.len() / 2]
            })
            .collect();
        let list = picks.iter().map(|&i| format!("{:?}", omega[i])).collect::<Vec<_>>().join(",");
        let mut args = base.to_vec();
        args.extend(["--omega", &list]);
        let (again, _) = steady(&format!("steady-points-{case}-listed"), &args);
        let shapes = Table::read(&again.join("shapes.csv"));
        let (w, b) = (shapes.column("omega"), shapes.column("branch"));
        for &i in &picks {
            let distance = (0..w.len())
                .filter(|&r| w[r] == omega[i] && b[r] == branch[i])
                .map(|r| (theta(&shapes, r, 5) - theta(&branches, i, 5)).amax())
                .fold(f64::INFINITY, f64::min);
            assert!(
                distance < 1e-9,
                "R = {radius}, branch {}, ω = {}: {distance:e} rad",
                branch[i],
                omega[i]
            );
            worst[case] = worst[case].max(distance);
        }
    }
    println!(
        "largest distance to a continuation point: fixed pivot {:.1e} rad, forced {:.1e} rad",
        worst[0], worst[1]
    );
}

/// The stability columns of shapes.csv row `i`: label, index, growth rate.
fn verdict_of_row(shapes: &Table, i: usize) -> (String, usize, f64) {
    (shapes.text("stability")[i].clone(), shapes.column("index")[i] as usize, shapes.column("growth_rate")[i])
}

#[test]
fn listed_stability_is_that_of_the_core() {
    let (n, damping) = (4, 0.01);
    let chain = uniform(n, 0.25);
    let critical = SteadyRotation::new(&chain, 0.0).unwrap().bifurcation_speeds(3).unwrap();
    let speeds = [1.5 * critical[0], 1.1 * critical[1], 1.3 * critical[2]];
    let list = speeds.map(|w| format!("{w:?}")).join(",");
    let d = damping.to_string();
    for (name, radius) in [("steady-verdict-free", 0.0), ("steady-verdict-forced", 0.05)] {
        let r = radius.to_string();
        let args = ["--n", "4", "--lengths", "0.25", "--radius", &r, "--omega", &list, "--damping", &d];
        let (dir, table) = steady(name, &args);
        let problem = SteadyRotation::new(&chain, radius).unwrap();
        let shapes = Table::read(&dir.join("shapes.csv"));
        let (omega, nodes) = (shapes.column("omega"), shapes.column("nodes"));
        let mut labels = Vec::new();
        for i in 0..shapes.rows.len() {
            let shape = problem.shape(omega[i], theta(&shapes, i, n));
            let st = stability(&problem, &shape, None).unwrap();
            let (label, index, growth) = verdict_of_row(&shapes, i);
            assert_eq!(label, st.verdict().label(), "{name} row {i}");
            assert_eq!(index, st.index, "{name} row {i}");
            assert!((growth - st.growth_rate).abs() <= 1e-9 * (1.0 + st.growth_rate.abs()), "{name} row {i}");
            // Damped: turning-frame damping on a fixed pivot, the 3D relative equilibrium's
            // spectrum on a circling one.
            let damped_growth = shapes.column("damped_growth_rate")[i];
            let damped_label = &shapes.text("damped_stability")[i];
            let expected = if radius == 0.0 {
                let st = stability(&problem, &shape, Some(&[damping; 4])).unwrap();
                (st.verdict(), st.growth_rate)
            } else {
                let model = Directions::<U3>::new(chain.clone().with_damping(&[damping; 4]).unwrap())
                    .with_drive(Circle::new(radius, omega[i]).unwrap());
                let guess: Vec<(f64, f64)> = shape.theta.iter().map(|&t| (t, 0.0)).collect();
                let spectrum =
                    relative_spectrum(&model, &relative_equilibrium(&model, &guess).unwrap()).unwrap();
                let largest = spectrum.iter().map(|z| z.norm()).fold(0.0, f64::max);
                let tolerance = 1e-6 * largest.max(omega[i]).max(problem.reference_speed());
                let growth = spectrum.iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max);
                (Verdict::of_spectrum(&spectrum, None, tolerance), growth)
            };
            assert_eq!(damped_label, expected.0.label(), "{name} row {i} damped");
            assert!((damped_growth - expected.1).abs() <= 1e-9 * (1.0 + expected.1.abs()), "{name} row {i}");
            labels.push((nodes[i] as usize, label, damped_label.clone()));
        }
        // Known cases: the in-phase one-node shape is stable, damped too; every shape
        // with more nodes has descent directions (index > 0): gyroscopic or unstable.
        assert!(
            labels.iter().any(|(k, l, dl)| *k == 1 && l == "stable" && dl == "stable"),
            "{name}: {labels:?}"
        );
        assert!(
            labels.iter().filter(|(k, _, _)| *k >= 2).all(|(_, l, _)| l != "stable"),
            "{name}: {labels:?}"
        );
        assert!(labels.iter().any(|(k, _, _)| *k == 3), "{name}: {labels:?}");
        if radius == 0.0 {
            // Kelvin–Tait–Chetaev: turning-frame damping leaves only index 0 stable; the
            // vertical above ω_1 (0 nodes) is gyroscopic.
            assert!(
                labels.iter().filter(|(k, _, _)| *k != 1).all(|(_, _, dl)| dl == "unstable"),
                "{labels:?}"
            );
            assert!(
                labels.iter().filter(|(k, _, _)| *k == 0).all(|(_, l, _)| l == "gyroscopic"),
                "{labels:?}"
            );
        } else {
            // Out of phase with the pivot, the large one-node shape has one descent direction.
            assert!(labels.iter().any(|(k, l, _)| *k == 1 && l == "unstable"), "{labels:?}");
        }
        assert!(table.contains("damped growth (1/s)"), "{table}");
    }
}

#[test]
fn bad_speed_lists_are_named() {
    let dir = scratch("steady-bad-speeds");
    let cases: [(&[&str], &str); 9] = [
        (
            &["--omega", ""],
            "error: --omega: '' lists no speed (give one or more in rad/s, e.g. --omega 5,10)",
        ),
        (
            &["--omega", ","],
            "error: --omega: ',' lists no speed (give one or more in rad/s, e.g. --omega 5,10)",
        ),
        (&["--omega", "5,,6"], "error: --omega: '5,,6' has an empty entry"),
        (&["--omega", "-1"], "error: --omega: '-1' has a negative entry -1 (speeds are ≥ 0 rad/s)"),
        (&["--omega", "5,inf"], "error: --omega: '5,inf' has a non-finite entry inf"),
        (&["--omega", "NaN"], "error: --omega: 'NaN' has a non-finite entry NaN"),
        (&["--omega", "3,x"], "error: --omega: '3,x' has a bad entry 'x' (not a number)"),
        (
            &["--omega", "30", "--omega-max", "20"],
            "error: --omega: 30 rad/s is above --omega-max = 20 rad/s (the branches end there)",
        ),
        (
            &["--damping", "0.1,-1,0"],
            "error: --damping: damping of link 2 must be finite and non-negative, got -1",
        ),
    ];
    for (args, message) in cases {
        let mut all = vec!["steady"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["--out", "s"]);
        let out = run_in(&dir, &all);
        let got = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {got}");
        assert_eq!(got.trim_end(), message, "{args:?}");
        assert!(!dir.join("s").exists(), "{args:?} wrote files");
    }
}

#[test]
fn the_continuum_has_the_strings_critical_speeds_and_the_chains_shapes_within_one_over_n() {
    // The 100-link chain of the README whirl, its pivot on a 2 cm circle.
    let chain = ["--n", "100", "--masses", "0.01", "--lengths", "0.01"];
    let (dir, stdout) = steady(
        "steady-continuum",
        &[&chain[..], &["--continuum", "--radius", "0.02", "--omega", "3,5"]].concat(),
    );
    let mut lines = stdout.lines();
    assert!(lines.next().unwrap().starts_with("heavy string (Kolodner) of length L = 1 m, g = 9.81 m/s²"));
    // ω_k = (j_0k/2) √(g/L).
    assert_eq!(
        lines.next().unwrap(),
        "critical speeds ω_k = (j_0k/2)·√(g/L) (rad/s): 3.766067, 8.644696, 13.552136 (√(g/L) = 3.132092 rad/s)"
    );
    let csv = Table::read(&dir.join("continuum.csv"));
    let (omega, nodes, tips) = (csv.column("omega"), csv.column("nodes"), csv.column("tip_radius"));
    assert_eq!(omega, [3.0, 5.0, 5.0, 5.0]);
    assert_eq!(nodes, [1.0, 2.0, 2.0, 1.0]);
    // The 100-link chain's forced shapes (`steady --radius 0.02`): 0.07353, 0.06172,
    // 0.86411 m; the string's differ by about 1/n.
    for (tip, chain) in [(tips[0], 0.073534), (tips[2], 0.061716), (tips[3], 0.864108)] {
        assert!((tip - chain).abs() < 2.0 / 100.0 * chain, "{tip} against the chain's {chain}");
    }
    assert!(std::fs::read(dir.join("continuum.png")).unwrap().starts_with(b"\x89PNG"));
    assert!(std::fs::read(dir.join("convergence.png")).unwrap().starts_with(b"\x89PNG"));
    // The chain's options that do not apply to the string are refused.
    let out = run_in(&scratch("steady-continuum-bad"), &["steady", "--continuum", "--damping", "0.01"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr(&out).trim(),
        "error: --continuum: --damping and --branches apply to the chain, not to the string"
    );
}
