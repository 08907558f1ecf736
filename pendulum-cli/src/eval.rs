//! `pendulum eval`: one model at one state, every term of `M q̈ + c + k + d = Q` and the
//! energies, as JSON on standard output.

use nalgebra::{DMatrix, DVector, DefaultAllocator, DimName, Dyn, OVector};
use pendulum_core::{Inputs, Model, ModelAlloc};
use serde::Serialize;

use crate::args::{EvalArgs, ModelKind};
use crate::error::{CliError, CliResult};
use crate::spec::{expand, parse_list, per_link};
use pendulum_experiment::assemble::{planar_model, spatial_model};

/// What `pendulum eval` prints.
#[derive(Debug, Serialize)]
pub struct Evaluation {
    /// `"planar"` or `"spatial"`.
    pub model: ModelKind,
    /// Number of links n.
    pub links: usize,
    /// Masses, kg.
    pub masses: Vec<f64>,
    /// Lengths, m.
    pub lengths: Vec<f64>,
    /// Gravity, m/s².
    pub gravity: f64,
    /// Damping λ_i, N·m·s.
    pub damping: Vec<f64>,
    /// Coordinates q, rad.
    pub q: Vec<f64>,
    /// Rates q̇, rad/s.
    pub qd: Vec<f64>,
    /// Torques σ, N·m.
    pub torque: Vec<f64>,
    /// Pivot acceleration p̈, m/s².
    pub pivot_acceleration: Vec<f64>,
    /// Mass matrix M(q), kg·m², row-major.
    pub mass_matrix: Vec<Vec<f64>>,
    /// Velocity terms c(q, q̇), N·m.
    pub velocity_terms: Vec<f64>,
    /// Gravity terms k(q) = ∂U/∂q, N·m.
    pub gravity_terms: Vec<f64>,
    /// Pivot terms d(q, p̈), N·m.
    pub pivot_terms: Vec<f64>,
    /// Generalized forces Q(q, q̇, σ), N·m.
    pub generalized_forces: Vec<f64>,
    /// Accelerations q̈ = M⁻¹(Q − c − k − d), rad/s².
    pub accelerations: Vec<f64>,
    /// Kinetic energy T (pivot at rest), J.
    pub kinetic_energy: f64,
    /// Potential energy U, J.
    pub potential_energy: f64,
}

/// Runs `pendulum eval`: prints the [`Evaluation`] as pretty JSON.
pub fn eval(args: &EvalArgs) -> CliResult<()> {
    let evaluation = evaluate(args)?;
    let text = serde_json::to_string_pretty(&evaluation).map_err(|e| CliError::failed(e.to_string()))?;
    println!("{text}");
    Ok(())
}

/// A chain and one state of it, as `pendulum eval` and `pendulum linearize` take them.
pub struct StateInput {
    /// The chain (masses, lengths, gravity, damping).
    pub chain: pendulum_core::Chain<Dyn>,
    /// Coordinates q, rad (dof entries).
    pub q: Vec<f64>,
    /// Rates q̇, rad/s.
    pub qd: Vec<f64>,
    /// Torques σ, N·m.
    pub torque: Vec<f64>,
    /// Pivot acceleration p̈, m/s².
    pub pivot: Vec<f64>,
}

/// Reads the chain and the state of `args`, checking every length (one-line usage errors).
pub fn parse_state(args: &EvalArgs) -> CliResult<StateInput> {
    let masses = per_link("--masses", &args.masses)?;
    let lengths = per_link("--lengths", &args.lengths)?;
    let q = parse_list("--q", &args.q)?;
    let per_link_count = match args.model {
        ModelKind::Planar => q.len(),
        ModelKind::Spatial => q.len() / 2,
    };
    let n = match args.n {
        Some(0) => return Err(CliError::invalid("--n: a chain needs at least 1 link, got 0")),
        Some(n) => n,
        None => [masses.len(), lengths.len(), per_link_count].into_iter().find(|&l| l > 1).unwrap_or(1),
    };
    let masses = expand("--masses", masses, n)?;
    let lengths = expand("--lengths", lengths, n)?;
    let damping = expand("--damping", per_link("--damping", &args.damping)?, n)?;
    let chain = pendulum_core::Chain::<Dyn>::new(&masses, &lengths, args.gravity)?.with_damping(&damping)?;
    let (dof, space) = match args.model {
        ModelKind::Planar => (n, 2),
        ModelKind::Spatial => (2 * n, 3),
    };
    let vector = |what: &str, given: &Option<String>, len: usize| -> CliResult<Vec<f64>> {
        let v = match given {
            Some(s) => parse_list(what, s)?,
            None => vec![0.0; len],
        };
        if v.len() != len {
            return Err(CliError::invalid(format!("{what}: got {} values, expected {len}", v.len())));
        }
        Ok(v)
    };
    if q.len() != dof {
        let layout = if args.model == ModelKind::Planar { "θ_1..θ_n" } else { "θ_1..θ_n, φ_1..φ_n" };
        return Err(CliError::invalid(format!(
            "--q: got {} values, expected {dof} ({layout}) for n = {n}",
            q.len()
        )));
    }
    let qd = vector("--qd", &args.qd, dof)?;
    let torque = vector("--torque", &args.torque, dof)?;
    let pivot = vector("--pivot-acceleration", &args.pivot_acceleration, space)?;
    Ok(StateInput { chain, q, qd, torque, pivot })
}

/// `q`, `q̇` and the inputs as a model's vectors.
pub fn model_state<M: Model<Dof = Dyn>>(
    q: &[f64],
    qd: &[f64],
    torque: &[f64],
    pivot: &[f64],
) -> (DVector<f64>, DVector<f64>, Inputs<Dyn, M::Space>)
where
    DefaultAllocator: ModelAlloc<M::Links, Dyn, M::Space>,
{
    let inputs = Inputs {
        torque: DVector::from_column_slice(torque),
        pivot_acceleration: OVector::<f64, M::Space>::from_iterator_generic(
            M::Space::name(),
            nalgebra::U1,
            pivot.iter().copied(),
        ),
    };
    (DVector::from_column_slice(q), DVector::from_column_slice(qd), inputs)
}

/// Evaluates the model the arguments describe.
pub fn evaluate(args: &EvalArgs) -> CliResult<Evaluation> {
    let StateInput { chain, q, qd, torque, pivot } = parse_state(args)?;
    let per_link = |v: &nalgebra::DVector<f64>| v.as_slice().to_vec();
    let (n, masses, lengths, damping) =
        (chain.links(), per_link(chain.masses()), per_link(chain.lengths()), per_link(chain.damping()));
    let terms = match args.model {
        ModelKind::Planar => terms(&planar_model(chain), &q, &qd, &torque, &pivot)?,
        ModelKind::Spatial => terms(&spatial_model(chain), &q, &qd, &torque, &pivot)?,
    };
    Ok(Evaluation {
        model: args.model,
        links: n,
        masses,
        lengths,
        gravity: args.gravity,
        damping,
        q,
        qd,
        torque,
        pivot_acceleration: pivot,
        mass_matrix: terms.mass_matrix,
        velocity_terms: terms.velocity_terms,
        gravity_terms: terms.gravity_terms,
        pivot_terms: terms.pivot_terms,
        generalized_forces: terms.generalized_forces,
        accelerations: terms.accelerations,
        kinetic_energy: terms.kinetic_energy,
        potential_energy: terms.potential_energy,
    })
}

/// The model's terms at one state.
struct Terms {
    mass_matrix: Vec<Vec<f64>>,
    velocity_terms: Vec<f64>,
    gravity_terms: Vec<f64>,
    pivot_terms: Vec<f64>,
    generalized_forces: Vec<f64>,
    accelerations: Vec<f64>,
    kinetic_energy: f64,
    potential_energy: f64,
}

fn terms<M: Model<Links = Dyn, Dof = Dyn>>(
    model: &M,
    q: &[f64],
    qd: &[f64],
    torque: &[f64],
    pivot: &[f64],
) -> CliResult<Terms>
where
    DefaultAllocator: ModelAlloc<Dyn, Dyn, M::Space>,
{
    let dof = q.len();
    let (q, qd, inputs) = model_state::<M>(q, qd, torque, pivot);
    // The accelerations first: they check finiteness and the configuration.
    let mut accelerations = DVector::zeros(dof);
    model.accelerations(&q, &qd, &inputs, &mut accelerations)?;
    let mut mass = DMatrix::zeros(dof, dof);
    model.mass_matrix(&q, &mut mass);
    let mut out = DVector::zeros(dof);
    let mut term = |f: &dyn Fn(&mut DVector<f64>)| {
        f(&mut out);
        out.as_slice().to_vec()
    };
    let velocity_terms = term(&|o| model.velocity_terms(&q, &qd, o));
    let gravity_terms = term(&|o| model.gravity_terms(&q, o));
    let pivot_terms = term(&|o| model.pivot_terms(&q, &inputs.pivot_acceleration, o));
    let generalized_forces = term(&|o| model.generalized_forces(&q, &qd, &inputs.torque, o));
    Ok(Terms {
        mass_matrix: mass.row_iter().map(|r| r.iter().copied().collect()).collect(),
        velocity_terms,
        gravity_terms,
        pivot_terms,
        generalized_forces,
        accelerations: accelerations.as_slice().to_vec(),
        kinetic_energy: model.kinetic_energy(&q, &qd),
        potential_energy: model.potential_energy(&q),
    })
}
