//! `pendulum linearize`: the chain linearised about a steady state (an equilibrium or a
//! steady rotation) from the models' analytic derivatives, as JSON: `A`, `B` for the
//! torques and for the pivot acceleration, the eigenvalues of `A`, and optionally the LQR
//! gain for one input.

use nalgebra::{DMatrix, DefaultAllocator, Dyn, allocator::Allocator};
use pendulum_core::{Derivatives, Error, Model, ModelAlloc, Planar, Spatial, StateSpace, linearize, lqr};
use serde::Serialize;

use crate::args::{LinearizeArgs, LqrInput, ModelKind};
use crate::error::{CliError, CliResult};
use crate::eval::{StateInput, model_state, parse_state};

/// One eigenvalue, 1/s.
#[derive(Debug, Serialize)]
pub struct Eigenvalue {
    /// Real part: the growth (> 0) or decay (< 0) rate.
    pub re: f64,
    /// Imaginary part: the angular frequency, rad/s.
    pub im: f64,
}

/// The LQR design in the output.
#[derive(Debug, Serialize)]
pub struct Gain {
    /// Which input: `"torque"` (all torques) or `"pivot-x"`, `"pivot-y"`, `"pivot-z"`.
    pub input: String,
    /// State weight `Q = q I` and input weight `R = r I`.
    pub q_weight: f64,
    /// Input weight.
    pub r_weight: f64,
    /// `K` (inputs × states, row-major): the control is `u = −K (x − x₀)`.
    pub gain: Vec<Vec<f64>>,
    /// Eigenvalues of `A − B K`, 1/s.
    pub closed_loop_eigenvalues: Vec<Eigenvalue>,
}

/// What `pendulum linearize` prints.
#[derive(Debug, Serialize)]
pub struct Linearization {
    /// `"planar"` or `"spatial"`.
    pub model: ModelKind,
    /// Number of links.
    pub links: usize,
    /// The state `x₀ = (q, q̇)` linearised about.
    pub q: Vec<f64>,
    /// Rates, rad/s.
    pub qd: Vec<f64>,
    /// `max |q̈|` there, rad/s² (0 at an exact equilibrium).
    pub residual: f64,
    /// `A = [[0, I], [∂q̈/∂q, ∂q̈/∂q̇]]`, row-major, state `x = (q, q̇)`.
    pub a: Vec<Vec<f64>>,
    /// `B_σ = [[0], [M⁻¹]]`: one column per torque.
    pub b_torque: Vec<Vec<f64>>,
    /// `B_p = [[0], [∂q̈/∂p̈]]`: one column per pivot-acceleration component.
    pub b_pivot: Vec<Vec<f64>>,
    /// Eigenvalues of `A` by decreasing real part, 1/s.
    pub eigenvalues: Vec<Eigenvalue>,
    /// Whether every eigenvalue has a real part ≤ 1e-9 (no growing mode).
    pub stable: bool,
    /// The LQR gain, with `--lqr`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lqr: Option<Gain>,
}

fn rows(m: &DMatrix<f64>) -> Vec<Vec<f64>> {
    m.row_iter().map(|r| r.iter().copied().collect()).collect()
}

fn eigenvalues(values: impl IntoIterator<Item = nalgebra::Complex<f64>>) -> Vec<Eigenvalue> {
    values.into_iter().map(|e| Eigenvalue { re: e.re, im: e.im }).collect()
}

/// Runs `pendulum linearize`: prints the [`Linearization`] as pretty JSON.
pub fn run(args: &LinearizeArgs) -> CliResult<()> {
    let out = linearization(args)?;
    let text = serde_json::to_string_pretty(&out).map_err(|e| CliError::failed(e.to_string()))?;
    println!("{text}");
    Ok(())
}

/// The linearisation the arguments ask for.
pub fn linearization(args: &LinearizeArgs) -> CliResult<Linearization> {
    let positive = |x: f64| x > 0.0 && x.is_finite();
    if !positive(args.tolerance) {
        return Err(CliError::invalid(format!(
            "--tolerance must be finite and positive, got {}",
            args.tolerance
        )));
    }
    for (what, w) in [("--lqr-q", args.lqr_q), ("--lqr-r", args.lqr_r)] {
        if !positive(w) {
            return Err(CliError::invalid(format!("{what} must be finite and positive, got {w}")));
        }
    }
    let state = parse_state(&args.state)?;
    let tolerance = if args.force { f64::INFINITY } else { args.tolerance };
    let space = match args.state.model {
        ModelKind::Planar => state_space(&Planar::new(state.chain.clone()), &state, tolerance)?,
        ModelKind::Spatial => state_space(&Spatial::new(state.chain.clone()), &state, tolerance)?,
    };
    let gain = args.lqr.map(|input| design(&space, input, args)).transpose()?;
    let stable = space.growth_rate() <= 1e-9;
    Ok(Linearization {
        model: args.state.model,
        links: state.chain.links(),
        q: state.q,
        qd: state.qd,
        residual: space.residual,
        a: rows(&space.a),
        b_torque: rows(&space.b_torque),
        b_pivot: rows(&space.b_pivot),
        eigenvalues: eigenvalues(space.eigenvalues.iter().copied()),
        stable,
        lqr: gain,
    })
}

fn state_space<M: Derivatives + Model<Links = Dyn, Dof = Dyn>>(
    model: &M,
    state: &StateInput,
    tolerance: f64,
) -> CliResult<StateSpace>
where
    DefaultAllocator: ModelAlloc<Dyn, Dyn, M::Space> + Allocator<Dyn, M::Space>,
{
    let (q, qd, inputs) = model_state::<M>(&state.q, &state.qd, &state.torque, &state.pivot);
    linearize(model, &q, &qd, &inputs, tolerance).map_err(|e| match e {
        Error::NotSteady { .. } => {
            CliError::invalid(format!("{e}; pass --force to linearise there anyway (or --tolerance)"))
        }
        e => e.into(),
    })
}

/// The LQR gain for one input of `space`.
fn design(space: &StateSpace, input: LqrInput, args: &LinearizeArgs) -> CliResult<Gain> {
    let b = match input {
        LqrInput::Torque => space.b_torque.clone(),
        LqrInput::PivotX | LqrInput::PivotY | LqrInput::PivotZ => {
            let k = input as usize - LqrInput::PivotX as usize;
            if k >= space.b_pivot.ncols() {
                return Err(CliError::invalid("--lqr pivot-z: a planar pivot moves in x and y only"));
            }
            space.b_pivot.columns(k, 1).into_owned()
        }
    };
    let (n, m) = (space.a.nrows(), b.ncols());
    let q = DMatrix::identity(n, n) * args.lqr_q;
    let r = DMatrix::identity(m, m) * args.lqr_r;
    let design = lqr(&space.a, &b, &q, &r).map_err(|e| CliError::invalid(e.to_string()))?;
    Ok(Gain {
        input: input.name().to_owned(),
        q_weight: args.lqr_q,
        r_weight: args.lqr_r,
        gain: rows(&design.gain),
        closed_loop_eigenvalues: eigenvalues(design.closed_loop.iter().copied()),
    })
}
