//! A uniform chain spun about the vertical leaves it in its k-node shape at Kolodner's
//! critical speeds, those of the heavy rotating string: `ω_k = (j_{0,k} / 2) sqrt(g / L)`.

use nalgebra::Dyn;
use pendulum_core::{Chain, ContinuationOptions, SteadyRotation, stability};

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
        println!("k = {}: ω = {:.6} rad/s, Kolodner {:.6} rad/s, error {:+.3e}", k + 1, speeds[k], kolodner, err);
        assert!(err.abs() < 0.01, "k = {}: error {err}", k + 1);
    }
}

#[test]
fn branches_leave_the_vertical_with_k_nodes_and_grow() {
    let n = 30;
    let chain = Chain::<Dyn>::uniform(n, 1.0 / n as f64, 1.0 / n as f64, 9.81).unwrap();
    let problem = SteadyRotation::new(&chain, 0.0).unwrap();
    let speeds = problem.bifurcation_speeds(3).unwrap();
    let opts = ContinuationOptions::default();
    for k in 1..=3 {
        let branch = problem.branch(k, 1.6 * speeds[2], &opts).unwrap();
        let pts = &branch.points[1..];
        assert!(pts.iter().all(|s| s.nodes() == k && s.omega > speeds[k - 1]), "k = {k}");
        // Amplitude grows with speed along the branch (no fold for the free chain).
        assert!(pts.windows(2).all(|w| w[1].omega > w[0].omega && w[1].amplitude() > w[0].amplitude()), "k = {k}");
    }
    // Only the one-node branch is stable; the others have directions of descent of the
    // amended potential.
    let top = problem.branch(1, 1.6 * speeds[2], &opts).unwrap();
    let st = stability(&problem, top.points.last().unwrap(), None).unwrap();
    assert!(st.spectrally_stable && st.index == 0);
}
