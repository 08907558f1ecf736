//! `pendulum eval` agrees with the sympy reference (`reference/cases/*.json`) for planar
//! n = 3 and spatial n = 2 at a generic state with every parameter non-trivial.
//!
//! The expected numbers are computed here from the committed reference expressions by a
//! small evaluator of their JSON grammar (`reference/README.md`, "Expression grammar"),
//! independent of xtask's; the expected accelerations solve `M q̈ = Q − c − k − d` with
//! the reference's terms.

mod common;

use std::collections::HashMap;

use nalgebra::{DMatrix, DVector};
use serde_json::Value;

use common::{run_in, scratch, stderr};

/// Evaluates a reference expression: integers, symbols, `+`, `*`, `^` (integer power),
/// `/` (rational constant), `sin`, `cos`.
fn evaluate(e: &Value, env: &HashMap<String, f64>) -> f64 {
    match e {
        Value::Number(k) => k.as_i64().expect("integer constant") as f64,
        Value::String(name) => *env.get(name).unwrap_or_else(|| panic!("unbound symbol {name}")),
        Value::Array(items) => {
            let op = items[0].as_str().expect("operator");
            let args = &items[1..];
            match op {
                "+" => args.iter().map(|a| evaluate(a, env)).sum(),
                "*" => args.iter().map(|a| evaluate(a, env)).product(),
                "^" => evaluate(&args[0], env).powi(args[1].as_i64().expect("integer power") as i32),
                "/" => args[0].as_i64().unwrap() as f64 / args[1].as_i64().unwrap() as f64,
                "sin" => evaluate(&args[0], env).sin(),
                "cos" => evaluate(&args[0], env).cos(),
                other => panic!("unknown operator {other}"),
            }
        }
        other => panic!("not an expression: {other}"),
    }
}

/// One state of one case: every symbol's value, and the same values as CLI arguments.
struct Point {
    masses: Vec<f64>,
    lengths: Vec<f64>,
    gravity: f64,
    damping: Vec<f64>,
    q: Vec<f64>,
    qd: Vec<f64>,
    torque: Vec<f64>,
    pivot: Vec<f64>,
}

fn list(v: &[f64]) -> String {
    v.iter().map(|x| format!("{x:?}")).collect::<Vec<_>>().join(",")
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

fn check_against_reference(case: &str, model: &str, p: &Point) {
    let path = format!("{}/../reference/cases/{case}.json", env!("CARGO_MANIFEST_DIR"));
    let reference: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let symbols = &reference["symbols"];
    let mut env = HashMap::new();
    let mut bind = |key: &str, values: &[f64]| {
        let names = symbols[key].as_array().unwrap();
        assert_eq!(names.len(), values.len(), "{key}");
        for (name, v) in names.iter().zip(values) {
            env.insert(name.as_str().unwrap().to_string(), *v);
        }
    };
    bind("coordinates", &p.q);
    bind("rates", &p.qd);
    bind("masses", &p.masses);
    bind("lengths", &p.lengths);
    bind("damping", &p.damping);
    bind("torques", &p.torque);
    bind("pivot_acceleration", &p.pivot);
    env.insert(symbols["gravity"].as_str().unwrap().to_string(), p.gravity);

    let dir = scratch(&format!("eval-{case}"));
    let args = [
        "eval",
        "--model",
        model,
        "--masses",
        &list(&p.masses),
        "--lengths",
        &list(&p.lengths),
        "--gravity",
        &format!("{:?}", p.gravity),
        "--damping",
        &list(&p.damping),
        "--q",
        &list(&p.q),
        "--qd",
        &list(&p.qd),
        "--torque",
        &list(&p.torque),
        "--pivot-acceleration",
        &list(&p.pivot),
    ];
    let out = run_in(&dir, &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let got: Value = serde_json::from_slice(&out.stdout).expect("eval prints JSON");

    let close = |what: &str, got: f64, want: f64, scale: f64| {
        assert!((got - want).abs() <= 1e-12 * scale, "{case} {what}: eval {got}, reference {want}");
    };
    let dof = p.q.len();
    let mut mass = DMatrix::zeros(dof, dof);
    for a in 0..dof {
        for b in 0..dof {
            let want = evaluate(&reference["mass_matrix"][a][b], &env);
            mass[(a, b)] = want;
            close(&format!("M[{a}][{b}]"), got["mass_matrix"][a][b].as_f64().unwrap(), want, 10.0);
        }
    }
    let mut rhs = DVector::zeros(dof);
    for (key, sign) in [
        ("velocity_terms", -1.0),
        ("gravity_terms", -1.0),
        ("pivot_terms", -1.0),
        ("generalized_forces", 1.0),
    ] {
        let values = floats(&got[key]);
        assert_eq!(values.len(), dof, "{key}");
        for a in 0..dof {
            let want = evaluate(&reference[key][a], &env);
            rhs[a] += sign * want;
            close(&format!("{key}[{a}]"), values[a], want, 100.0);
        }
    }
    for key in ["kinetic_energy", "potential_energy"] {
        close(key, got[key].as_f64().unwrap(), evaluate(&reference[key], &env), 100.0);
    }
    let expected = mass.lu().solve(&rhs).expect("M is invertible at this state");
    let accelerations = floats(&got["accelerations"]);
    for a in 0..dof {
        close(&format!("accelerations[{a}]"), accelerations[a], expected[a], 1e3 * (1.0 + expected.amax()));
    }
    // The state echoed back is the state evaluated.
    assert_eq!(floats(&got["q"]), p.q);
    assert_eq!(got["links"], p.masses.len());
}

#[test]
fn planar_n3_agrees_with_the_sympy_reference() {
    let p = Point {
        masses: vec![1.3, 0.7, 2.1],
        lengths: vec![0.4, 0.9, 0.6],
        gravity: 9.81,
        damping: vec![0.2, 0.1, 0.3],
        q: vec![0.3, -1.1, 2.0],
        qd: vec![0.5, -1.5, 2.2],
        torque: vec![0.4, -0.3, 0.1],
        pivot: vec![0.7, -2.0],
    };
    check_against_reference("planar_n3", "planar", &p);
}

#[test]
fn spatial_n2_agrees_with_the_sympy_reference() {
    let p = Point {
        masses: vec![1.1, 0.6],
        lengths: vec![0.8, 0.5],
        gravity: 9.81,
        damping: vec![0.15, 0.25],
        q: vec![0.7, 2.1, -0.4, 1.3],
        qd: vec![0.9, -0.6, 1.7, -2.3],
        torque: vec![0.2, -0.1, 0.3, 0.05],
        pivot: vec![0.3, -0.5, 1.2],
    };
    check_against_reference("spatial_n2", "spatial", &p);
}
