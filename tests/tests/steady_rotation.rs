//! A uniform chain spun about the vertical leaves it in its k-node shape at Kolodner's
//! critical speeds, those of the heavy rotating string: `ω_k = (j_{0,k} / 2) sqrt(g / L)`;
//! at each n exactly at `√((g/l) x_k)`, `x_k` the zeros of the Laguerre polynomial L_n.

use nalgebra::Dyn;
use pendulum_core::{
    BranchEnd, Chain, ContinuationOptions, SteadyRotation, equal_link_frequencies, stability, stability_dense,
};

const J0_ZEROS: [f64; 3] = [2.404825557695773, 5.520078110286311, 8.653727912911013];

#[test]
fn bifurcation_speeds_match_kolodner_at_100_links() {
    let (length, g) = (1.5, 9.81);
    let n = 100;
    let chain = Chain::<Dyn>::uniform(n, 0.01, length / n as f64, g).unwrap();
    let problem = SteadyRotation::new(&chain, 0.0).unwrap();
    let speeds = problem.bifurcation_speeds(3).unwrap();
    for k in 0..3 {
        let kolodner = 0.5 * J0_ZEROS[k] * (g / length).sqrt();
        let err = (speeds[k] - kolodner) / kolodner;
        println!(
            "k = {}: ω = {:.6} rad/s, Kolodner {:.6} rad/s, error {:+.3e}",
            k + 1,
            speeds[k],
            kolodner,
            err
        );
        assert!(err.abs() < 0.01, "k = {}: error {err}", k + 1);
        // Exactly, at this n: the equal-link chain's ω_k = √((g/l) x_k), x_k the zeros
        // of L_n (the linearised shape equations are the normal-mode eigenproblem).
        // The 1 % bound would pass a tail mass off by one; this would not.
        let exact = equal_link_frequencies(n, g, length / n as f64)[k];
        assert!(
            (speeds[k] - exact).abs() < 1e-10 * exact,
            "k = {}: {} against Laguerre {exact}",
            k + 1,
            speeds[k]
        );
    }
}

#[test]
fn branches_leave_the_vertical_with_k_nodes_and_grow() {
    let n = 30;
    let chain = Chain::<Dyn>::uniform(n, 1.0 / n as f64, 1.0 / n as f64, 9.81).unwrap();
    let problem = SteadyRotation::new(&chain, 0.0).unwrap();
    let speeds = problem.bifurcation_speeds(3).unwrap();
    let opts = ContinuationOptions::default();
    let branches: Vec<_> = (1..=3).map(|k| problem.branch(k, 1.6 * speeds[2], &opts).unwrap()).collect();
    for (branch, k) in branches.iter().zip(1..) {
        // The whole way to the speed asked for, not a branch of one vertical point.
        assert_eq!(branch.end, BranchEnd::ReachedOmega, "k = {k}");
        let pts = &branch.points[1..];
        assert!(pts.len() >= 10, "k = {k}: {} points", pts.len());
        assert!(pts.last().unwrap().omega >= 1.6 * speeds[2], "k = {k}");
        assert!(
            pts.last().unwrap().amplitude() > 0.1,
            "k = {k}: amplitude {}",
            pts.last().unwrap().amplitude()
        );
        assert!(pts.iter().all(|s| s.nodes() == k && s.omega > speeds[k - 1]), "k = {k}");
        // Amplitude grows with speed along the branch (no fold for the free chain).
        assert!(
            pts.windows(2).all(|w| w[1].omega > w[0].omega && w[1].amplitude() > w[0].amplitude()),
            "k = {k}"
        );
    }
    // Only the one-node branch is stable; the others have directions of descent of the
    // amended potential.
    for (branch, k) in branches.iter().zip(1..) {
        let st = stability(&problem, branch.points.last().unwrap(), None).unwrap();
        if k == 1 {
            assert!(st.spectrally_stable && st.index == 0, "k = 1: {st:?}");
        } else {
            assert!(st.index > 0, "k = {k}: index {}", st.index);
        }
    }
}

/// The spatial (θ, φ) model state of a steady shape at t = 0: polar angle `|θ_i|`,
/// azimuth 0 or π by the sign of `θ_i`, rates `(0, ω)`.
fn spatial_state(
    theta: &nalgebra::DVector<f64>,
    omega: f64,
) -> (nalgebra::DVector<f64>, nalgebra::DVector<f64>) {
    let n = theta.len();
    let q = nalgebra::DVector::from_fn(2 * n, |i, _| {
        if i < n {
            theta[i].abs()
        } else if theta[i - n] < 0.0 {
            std::f64::consts::PI
        } else {
            0.0
        }
    });
    let qd = nalgebra::DVector::from_fn(2 * n, |i, _| if i < n { 0.0 } else { omega });
    (q, qd)
}

fn irregular_chain() -> Chain<Dyn> {
    Chain::<Dyn>::new(&[0.3, 1.1, 0.5, 0.8, 0.4], &[0.25, 0.15, 0.3, 0.2, 0.1], 9.81).unwrap()
}

#[test]
fn steady_shapes_rotate_rigidly_in_the_spatial_model() {
    // The verified spatial model, in the inertial frame, must give zero accelerations for
    // a steady shape spinning at ω (θ̈ = 0, φ̈ = 0), free and forced.
    use pendulum_core::{Inputs, Model, Spatial};
    let chain = irregular_chain();
    let model = Spatial::new(chain.clone());
    for (radius, k) in [(0.0, 1), (0.0, 2), (0.0, 3), (0.01, 2), (0.03, 1)] {
        let free = SteadyRotation::new(&chain, 0.0).unwrap();
        let omega = 1.3 * free.bifurcation_speeds(3).unwrap()[2];
        let branch = free.branch(k, omega, &ContinuationOptions::default()).unwrap();
        let guess = &branch.points.last().unwrap().theta;
        let problem = SteadyRotation::new(&chain, radius).unwrap();
        let shape = problem.solve(omega, guess).unwrap();
        assert_eq!(shape.nodes(), k);
        let (q, qd) = spatial_state(&shape.theta, omega);
        let mut inputs: Inputs<Dyn, nalgebra::U3> = model.zero_inputs();
        // The pivot on its circle at t = 0, at (R, 0, 0): p̈ = −ω² R e_x.
        inputs.pivot_acceleration[0] = -omega * omega * radius;
        let mut acc = nalgebra::DVector::zeros(10);
        model.accelerations(&q, &qd, &inputs, &mut acc).unwrap();
        assert!(acc.amax() < 1e-9 * omega * omega, "R = {radius}, k = {k}: accelerations {acc}");
    }
}

#[test]
fn rotating_frame_spectrum_matches_the_spatial_model_jacobian() {
    // The spatial equations depend on the azimuths only through their differences, so
    // about a rigidly rotating shape their Jacobian is constant in time and its
    // eigenvalues are the rotating-frame linearisation's (different coordinates, same
    // spectrum). Jacobian by central differences of the spatial accelerations.
    use pendulum_core::{Model, Spatial};
    let chain = irregular_chain();
    let model = Spatial::new(chain.clone());
    let problem = SteadyRotation::new(&chain, 0.0).unwrap();
    let omega = 1.3 * problem.bifurcation_speeds(3).unwrap()[2];
    for k in 1..=3 {
        let shape = problem.branch(k, omega, &ContinuationOptions::default()).unwrap().points.pop().unwrap();
        let ours = stability_dense(&problem, &shape, None).unwrap();
        let (q, qd) = spatial_state(&shape.theta, shape.omega);
        let x0 = nalgebra::DVector::from_iterator(20, q.iter().chain(qd.iter()).copied());
        let inputs = model.zero_inputs();
        let rhs = |x: &nalgebra::DVector<f64>| {
            let (q, qd) = (x.rows(0, 10).into_owned(), x.rows(10, 10).into_owned());
            let mut acc = nalgebra::DVector::zeros(10);
            model.accelerations(&q, &qd, &inputs, &mut acc).unwrap();
            nalgebra::DVector::from_iterator(20, qd.iter().chain(acc.iter()).copied())
        };
        let h = 1e-6;
        let mut jac = nalgebra::DMatrix::zeros(20, 20);
        for j in 0..20 {
            let (mut xp, mut xm) = (x0.clone(), x0.clone());
            xp[j] += h;
            xm[j] -= h;
            jac.set_column(j, &((rhs(&xp) - rhs(&xm)) / (2.0 * h)));
        }
        let theirs: Vec<_> = jac.complex_eigenvalues().iter().copied().collect();
        let scale = ours.eigenvalues.last().unwrap().norm();
        // Every eigenvalue away from the symmetry's zero pair has a partner within FD error.
        let away: Vec<_> = ours.eigenvalues.iter().filter(|z| z.norm() > 1e-3 * scale).collect();
        assert!(away.len() >= 18, "k = {k}: only {} eigenvalues compared", away.len());
        for z in away {
            let d = theirs.iter().map(|w| (w - z).norm()).fold(f64::INFINITY, f64::min);
            assert!(d < 1e-5 * scale, "k = {k}: eigenvalue {z} has no spatial partner (nearest {d:e})");
        }
        let st = if ours.spectrally_stable { "spectrally stable" } else { "unstable" };
        println!(
            "k = {k}, ω = {:.4}: growth {:.3e}, index {}, {st}",
            shape.omega, ours.growth_rate, ours.index
        );
    }
}
