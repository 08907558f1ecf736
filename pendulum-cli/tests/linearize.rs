//! `pendulum linearize`: the inverted double and triple pendulum on a cart (the pivot's
//! horizontal acceleration the only input) balanced by the LQR gain the command prints,
//! on the nonlinear generated models; and its one-line usage errors.

mod common;

use std::f64::consts::PI;

use nalgebra::{SVector, Vector2};
use pendulum_core::{Chain, Inputs, Model};
use serde_json::Value;

use common::{pendulum, stderr};

pendulum_macros::model! {
    struct Double { kind: planar, links: 2 }
    struct Triple { kind: planar, links: 3 }
}

/// `pendulum linearize ARGS` as JSON.
fn linearize(args: &[&str]) -> Value {
    let out = pendulum().arg("linearize").args(args).output().unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn matrix(v: &Value) -> Vec<Vec<f64>> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|r| r.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect())
        .collect()
}

/// Runs the closed loop `p̈_x = −K (x − x_up)` on `model` for 10 s from every link 0.1 rad
/// past upright (RK4, h = 1 ms); the largest and the final `max_i |θ_i − π|`.
fn balance<M, const N: usize>(model: &M, gain: &[f64]) -> (f64, f64)
where
    M: Model<Dof = nalgebra::Const<N>, Space = nalgebra::U2, Links = nalgebra::Const<N>>,
{
    let up = SVector::<f64, N>::repeat(PI);
    let field = |q: &SVector<f64, N>, qd: &SVector<f64, N>| {
        let u: f64 = -(0..N).map(|i| gain[i] * (q[i] - PI) + gain[N + i] * qd[i]).sum::<f64>();
        let inputs = Inputs { torque: SVector::zeros(), pivot_acceleration: Vector2::new(u, 0.0) };
        let mut qdd = SVector::zeros();
        model.accelerations(q, qd, &inputs, &mut qdd).unwrap();
        qdd
    };
    let (mut q, mut qd) = (up.add_scalar(0.1), SVector::<f64, N>::zeros());
    let h = 1e-3;
    let mut worst = 0.0f64;
    for _ in 0..10_000 {
        let k1 = (qd, field(&q, &qd));
        let k2 = (qd + k1.1 * (h / 2.0), field(&(q + k1.0 * (h / 2.0)), &(qd + k1.1 * (h / 2.0))));
        let k3 = (qd + k2.1 * (h / 2.0), field(&(q + k2.0 * (h / 2.0)), &(qd + k2.1 * (h / 2.0))));
        let k4 = (qd + k3.1 * h, field(&(q + k3.0 * h), &(qd + k3.1 * h)));
        q += (k1.0 + k2.0 * 2.0 + k3.0 * 2.0 + k4.0) * (h / 6.0);
        qd += (k1.1 + k2.1 * 2.0 + k3.1 * 2.0 + k4.1) * (h / 6.0);
        worst = worst.max((q - up).amax());
    }
    (worst, (q - up).amax())
}

#[test]
fn the_lqr_gain_of_linearize_balances_the_inverted_double_and_triple_pendulum_on_a_cart() {
    for n in [2usize, 3] {
        let q = vec![PI.to_string(); n].join(",");
        let lengths = if n == 2 { "0.5,0.4" } else { "0.5,0.4,0.3" };
        let out = linearize(&["--q", &q, "--masses", "1", "--lengths", lengths, "--lqr", "pivot-x"]);
        // Upright is an equilibrium and unstable: n growing modes.
        assert!(out["residual"].as_f64().unwrap() < 1e-12, "{out}");
        assert!(!out["stable"].as_bool().unwrap());
        let growing = out["eigenvalues"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|e| e["re"].as_f64().unwrap() > 1e-6)
            .count();
        assert_eq!(growing, n, "{}", out["eigenvalues"]);
        let lqr = &out["lqr"];
        assert!(
            lqr["closed_loop_eigenvalues"]
                .as_array()
                .unwrap()
                .iter()
                .all(|e| e["re"].as_f64().unwrap() < 0.0)
        );
        let gain = matrix(&lqr["gain"]).remove(0);
        assert_eq!(gain.len(), 2 * n);
        let lengths: Vec<f64> = lengths.split(',').map(|l| l.parse().unwrap()).collect();
        let masses = vec![1.0; n];
        let (worst, last) = if n == 2 {
            balance(&Double::new(Chain::new(&masses, &lengths, 9.81).unwrap()), &gain)
        } else {
            balance(&Triple::new(Chain::new(&masses, &lengths, 9.81).unwrap()), &gain)
        };
        println!("n = {n}: at most {worst:.3} rad from upright, {last:.1e} rad after 10 s");
        assert!(worst < 0.2, "n = {n}: {worst} rad from upright");
        assert!(last < 1e-3, "n = {n}: still {last} rad from upright after 10 s");
    }
}

#[test]
fn bad_inputs_are_one_line_usage_errors() {
    let cases: [(&[&str], &str); 6] = [
        (&["--q", "3.1,3.1"], "not an equilibrium or a steady rotation: qdd[0]"),
        (&["--q", "3.1,NaN"], "NaN"),
        (&["--q", "0,0", "--qd", "0"], "--qd: got 1 values, expected 2"),
        (&["--q", "0", "--n", "2"], "--q: got 1 values, expected 2"),
        (&["--q", "0,0", "--lqr", "pivot-z"], "pivot-z"),
        (&["--q", "0,0", "--lqr-r", "-1"], "--lqr-r must be finite and positive"),
    ];
    for (args, expected) in cases {
        let out = pendulum().arg("linearize").args(args).output().unwrap();
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(expected), "{args:?}: {err}");
    }
    // --force linearises anyway: A along the trajectory through the state.
    let out = linearize(&["--q", "3.1,3.1", "--force"]);
    assert!(out["residual"].as_f64().unwrap() > 0.1);
}
