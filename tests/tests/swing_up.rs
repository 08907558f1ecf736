//! A driven, damped 3D chain started hanging at rest settles onto a relative equilibrium:
//! the shape `relative_equilibrium` finds from the Directions model's own equations, with
//! the node count of the nearest undamped steady shape.

use nalgebra::{DVector, Dyn, U3, Vector3};
use pendulum_core::integrate::{Integrator, Projected, Rk4, State};
use pendulum_core::{Chain, Circle, Directions, SteadyRotation, relative_equilibrium, relative_spectrum};

#[test]
fn driven_damped_chain_settles_onto_the_relative_equilibrium() {
    let (n, radius) = (4, 0.02);
    let plain = Chain::<Dyn>::uniform(n, 0.25, 0.25, 9.81).unwrap();
    let critical = SteadyRotation::new(&plain, 0.0).unwrap().bifurcation_speeds(2).unwrap();
    // Between the first two critical speeds, heavily enough damped to settle in 60 s.
    let omega = 0.5 * (critical[0] + critical[1]);
    let chain = plain.clone().with_damping(&[0.1; 4]).unwrap();
    let model = Directions::<U3>::new(chain).with_drive(Circle::new(radius, omega).unwrap());
    let mut state = State::new(0.0, model.hanging());
    let mut solver = Projected::new(Rk4::new(&model));
    for _ in 0..30_000 {
        solver.step(&model, &mut state, 2e-3).unwrap();
    }
    // Rotating-frame positions and link angles (θ in the pivot's plane, ψ out of it).
    let (s, c) = (omega * state.t()).sin_cos();
    let rotating: Vec<Vector3<f64>> = model
        .positions(state.t(), state.x())
        .into_iter()
        .map(|r| Vector3::new(c * r.x + s * r.y, -s * r.x + c * r.y, r.z))
        .collect();
    let mut previous = Vector3::new(radius, 0.0, 0.0);
    let guess: Vec<(f64, f64)> = rotating
        .iter()
        .map(|r| {
            let u = (r - previous) / 0.25;
            previous = *r;
            (u.x.atan2(-u.z), u.y.asin())
        })
        .collect();
    let eq = relative_equilibrium(&model, &guess).unwrap();
    let mut r = Vector3::new(radius, 0.0, 0.0);
    let distance = (0..n)
        .map(|i| {
            r += 0.25 * eq.state.fixed_rows::<3>(3 * i).into_owned();
            (r - rotating[i]).norm()
        })
        .fold(0.0, f64::max);
    println!("ω = {omega:.4} rad/s: distance {distance:.2e} m, angles {:?}", eq.angles);
    assert!(distance < 1e-5, "distance to the relative equilibrium {distance} m");
    let growth =
        relative_spectrum(&model, &eq).unwrap().iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max);
    println!("growth rate {growth:.3e} 1/s");
    assert!(growth < 0.0, "the equilibrium it settled on has growth rate {growth}");
    // Its in-plane shape is close to an undamped forced steady shape with the same nodes.
    let forced = SteadyRotation::new(&plain, radius).unwrap();
    let steady = forced.solve(omega, &DVector::from_iterator(n, guess.iter().map(|g| g.0))).unwrap();
    let nodes = 1 + pendulum_core::sign_changes(&rotating.iter().map(|r| r.x).collect::<Vec<_>>());
    assert_eq!(nodes, steady.nodes());
}
