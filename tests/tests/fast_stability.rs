//! The structured stability route (`stability`: the index of `H` from `O(n)` pivots, the
//! eigenvalues nearest the origin by shift-and-invert Arnoldi until they account for the
//! index) gives the verdicts, indices and growth rates of the dense one
//! (`stability_dense`, all `4n` eigenvalues), along whole branches: at the critical speeds
//! where they leave the vertical, through the unstable stretches of the two- and
//! three-node branches, round the folds of the forced branches, damped and undamped.

use nalgebra::{DVector, Dyn};
use pendulum_core::{Chain, ContinuationOptions, SteadyRotation, SteadyShape, stability, stability_dense};

/// Compares the two routes at `shape`; returns whether the verdict was unstable.
fn agree(problem: &SteadyRotation, shape: &SteadyShape, damping: Option<&[f64]>, what: &str) -> bool {
    let fast = stability(problem, shape, damping).unwrap();
    let dense = stability_dense(problem, shape, damping).unwrap();
    let at = format!("{what} at ω = {} rad/s (damped: {})", shape.omega, damping.is_some());
    assert_eq!(fast.index, dense.index, "index {at}");
    assert_eq!(
        fast.verdict().label(),
        dense.verdict().label(),
        "verdict {at}: {fast:?} / {:?}",
        dense.growth_rate
    );
    let unstable = !dense.spectrally_stable;
    if unstable || damping.is_some() {
        // Growth rates (and damped decay rates) to 1e-8 1/s; round-off otherwise.
        assert!(
            (fast.growth_rate - dense.growth_rate).abs() < 1e-8,
            "growth {at}: {} against {}",
            fast.growth_rate,
            dense.growth_rate
        );
    }
    assert!(
        fast.eigenvalues.len() >= 8.min(4 * problem.links()),
        "{at}: {} eigenvalues",
        fast.eigenvalues.len()
    );
    unstable
}

fn chains() -> Vec<(&'static str, Chain<Dyn>)> {
    let masses: Vec<f64> = (0..20).map(|i| 0.05 + 0.02 * ((i * 7) % 5) as f64).collect();
    let lengths: Vec<f64> = (0..20).map(|i| 0.04 + 0.01 * ((i * 3) % 4) as f64).collect();
    vec![
        ("uniform 12", Chain::<Dyn>::uniform(12, 1.0 / 12.0, 1.0 / 12.0, 9.81).unwrap()),
        ("uneven 20", Chain::<Dyn>::new(&masses, &lengths, 9.81).unwrap()),
        ("uniform 60", Chain::<Dyn>::uniform(60, 1.0 / 60.0, 1.0 / 60.0, 9.81).unwrap()),
    ]
}

#[test]
fn fixed_pivot_branches_and_the_vertical_get_the_dense_verdicts() {
    let options = ContinuationOptions::default();
    for (name, chain) in chains() {
        let n = chain.links();
        let problem = SteadyRotation::new(&chain, 0.0).unwrap();
        let critical = problem.bifurcation_speeds(3).unwrap();
        let top = 1.3 * critical[2];
        let stride = if n > 30 { 3 } else { 1 };
        let mut unstable = 0;
        let mut points = 0;
        for k in 1..=3 {
            let branch = problem.branch(k, top, &options).unwrap();
            for shape in branch.points.iter().step_by(stride) {
                unstable += usize::from(agree(&problem, shape, None, &format!("{name}, branch {k}")));
                points += 1;
            }
            // Damped (turning-frame damping on every link): only index 0 stays stable.
            let damping = vec![0.01; n];
            for shape in branch.points.iter().step_by(8 * stride) {
                agree(&problem, shape, Some(&damping), &format!("{name}, branch {k}"));
            }
        }
        // The vertical just below, at and just above each critical speed.
        for &w in &critical {
            for omega in [w * (1.0 - 1e-6), w, w * (1.0 + 1e-6)] {
                agree(&problem, &problem.shape(omega, DVector::zeros(n)), None, &format!("{name}, vertical"));
            }
        }
        println!("{name}: {points} shapes, {unstable} unstable, the same verdicts");
        assert!(unstable > 0, "{name}: no unstable stretch was tested");
    }
}

#[test]
fn forced_branches_round_their_folds_with_the_dense_verdicts() {
    let options = ContinuationOptions::default();
    for (name, chain) in chains().into_iter().take(2) {
        let n = chain.links();
        let problem = SteadyRotation::new(&chain, 0.03).unwrap();
        let free = SteadyRotation::new(&chain, 0.0).unwrap();
        let top = 1.2 * free.bifurcation_speeds(2).unwrap()[1];
        let rest = problem.solve(0.0, &DVector::zeros(n)).unwrap();
        let mut branches = vec![problem.continue_from(&rest, true, top, &options).unwrap()];
        // The branches through the free chain's one- and two-node shapes on either side
        // of the axis, followed down in ω: those not connected to rest fold back up.
        for k in 1..=2 {
            let shape = free.branch(k, top, &options).unwrap().points.last().unwrap().clone();
            for sign in [1.0, -1.0] {
                if let Ok(start) = problem.solve(0.99 * top, &(&shape.theta * sign)) {
                    branches.push(problem.continue_from(&start, false, top, &options).unwrap());
                }
            }
        }
        let mut unstable = 0;
        let mut folds = 0;
        for branch in &branches {
            for (i, shape) in branch.points.iter().enumerate() {
                unstable += usize::from(agree(&problem, shape, None, &format!("{name}, forced")));
                if i > 0 && i + 1 < branch.points.len() {
                    let (a, b) = (branch.points[i - 1].omega, branch.points[i + 1].omega);
                    folds += usize::from((shape.omega - a) * (b - shape.omega) < 0.0);
                }
            }
        }
        println!(
            "{name}, forced: {} shapes, {folds} at folds, {unstable} unstable",
            branches.iter().map(|b| b.points.len()).sum::<usize>()
        );
        assert!(folds > 0 && unstable > 0, "{name}: folds {folds}, unstable {unstable}");
    }
}

#[test]
fn a_whirls_nearest_shape_gets_the_growth_rate_of_the_whole_damped_spectrum() {
    // The 3D chain in unit directions on a circling pivot, with and without its own
    // damping: the eigenvalues near the origin hold the growth rate of all 4n, on the
    // forced branches' stable and unstable shapes alike.
    use nalgebra::U3;
    use pendulum_core::{
        Circle, Directions, relative_equilibrium, relative_spectrum, relative_spectrum_near_origin,
    };
    let n = 30;
    let radius = 0.02;
    let base = Chain::<Dyn>::uniform(n, 1.0 / n as f64, 1.0 / n as f64, 9.81).unwrap();
    let problem = SteadyRotation::new(&base, radius).unwrap();
    let free = SteadyRotation::new(&base, 0.0).unwrap();
    let options = ContinuationOptions::default();
    let (mut compared, mut unstable, mut truncated) = (0, 0, 0);
    for omega in [2.5, 5.0, 9.0, 14.0] {
        let mut shapes = vec![];
        let rest = problem.solve(0.0, &DVector::zeros(n)).unwrap();
        let from_rest = problem.continue_from(&rest, true, omega, &options).unwrap();
        shapes.extend(problem.solutions_at(std::slice::from_ref(&from_rest), omega));
        for k in 1..=free.unstable_directions_at_vertical(omega).min(2) {
            let last = free.branch(k, omega, &options).unwrap().points.last().unwrap().clone();
            for sign in [1.0, -1.0] {
                if let Ok(shape) = problem.solve(omega, &(&last.theta * sign)) {
                    shapes.push(shape);
                }
            }
        }
        for shape in &shapes {
            for damping in [0.0, 3e-4] {
                let chain = base.clone().with_damping(&vec![damping / n as f64; n]).unwrap();
                let model = Directions::<U3>::new(chain).with_drive(Circle::new(radius, omega).unwrap());
                let guess: Vec<(f64, f64)> = shape.theta.iter().map(|&t| (t, 0.0)).collect();
                let Ok(eq) = relative_equilibrium(&model, &guess) else { continue };
                let all = relative_spectrum(&model, &eq).unwrap();
                let near = relative_spectrum_near_origin(&model, &eq).unwrap();
                let growth =
                    |z: &[nalgebra::Complex<f64>]| z.iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max);
                let (g_near, g_all) = (growth(&near), growth(&all));
                assert!(
                    (g_near - g_all).abs() < 1e-8,
                    "ω = {omega}, λ = {damping}: {g_near} against {g_all}"
                );
                compared += 1;
                unstable += usize::from(g_all > 1e-6);
                truncated += usize::from(near.len() < all.len());
            }
        }
    }
    println!("{compared} relative equilibria, {unstable} unstable, {truncated} from part of the spectrum");
    assert!(compared >= 12 && unstable >= 3 && truncated == compared, "{compared} {unstable} {truncated}");
}
