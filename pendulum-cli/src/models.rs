//! Which core model simulates which chain (one place to switch models), and the
//! [`Simulation`] seam the run loop sees: a system, its initial state, and what one sample
//! of it means (trajectory columns, positions, energy ledger).

use nalgebra::{DVector, DefaultAllocator, DimName, Dyn, OVector, U1, U2, U3, Vector2, Vector3};
use pendulum_core::integrate::{
    Constrained, GaussFixedPoint, GaussLegendre, GaussOptions, Integrator, Projected, Rk4, System,
};
use pendulum_core::{
    Accounted, AccountedDirections, Chain, Circle, ConstantTorque, Directions, Drive, Fixed, Harmonic,
    Ledger, Model, ModelAlloc, PlanarTension, Spatial,
};

use crate::args::{IntegratorKind, StageSolver};

use crate::args::Dimension;
use crate::config::{DriveConfig, RunConfig};
use crate::error::{CliError, CliResult};

/// One sample of a run, in plain numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Time, s.
    pub t: f64,
    /// The trajectory columns after `t` ([`Simulation::state_columns`]).
    pub state: Vec<f64>,
    /// Pivot position (m), z = 0 in 2D.
    pub pivot: [f64; 3],
    /// Mass positions in the inertial frame (m), mass 1 (nearest the pivot) first.
    pub masses: Vec<[f64; 3]>,
    /// Inertial-frame energy `H_in = T + U` with the pivot's motion included, J.
    pub energy: f64,
    /// Work of drive and torques and the damped energy since t = 0, J.
    pub ledger: Ledger,
}

/// A chain set up to run: the integrators see [`system`](Simulation::system).
pub trait Simulation {
    /// The first-order system integrated.
    type Sys: System<Dim = Dyn>;
    /// The system.
    fn system(&self) -> &Self::Sys;
    /// The state at t = 0.
    fn initial_state(&self) -> DVector<f64>;
    /// Names of the trajectory's state columns (coordinates, then rates).
    fn state_columns(&self) -> Vec<String>;
    /// Reads a sample out of the state `x` at time `t`.
    fn sample(&self, t: f64, x: &DVector<f64>) -> Sample;
    /// The integrator of this kind for the system (with a projection onto the
    /// constraints where the system has them).
    fn integrator(&self, kind: IntegratorKind, solver: StageSolver) -> Box<dyn Integrator<Self::Sys> + '_>;
}

/// Most sweeps of the fixed-point stage solve per step.
const FIXED_POINT_SWEEPS: usize = 100;

/// The integrator of a kind for an unconstrained system, Gauss–Legendre stages solved by
/// `solver`.
fn plain_integrator<'a, S: System<Dim = Dyn> + 'a>(
    kind: IntegratorKind,
    solver: StageSolver,
    system: &S,
) -> Box<dyn Integrator<S> + 'a> {
    let options = GaussOptions::default();
    match (kind, solver) {
        (IntegratorKind::Gl1, StageSolver::Newton) => {
            Box::new(GaussLegendre::<Dyn, U1>::new(system, options))
        }
        (IntegratorKind::Gl2, StageSolver::Newton) => {
            Box::new(GaussLegendre::<Dyn, U2>::new(system, options))
        }
        (IntegratorKind::Gl3, StageSolver::Newton) => {
            Box::new(GaussLegendre::<Dyn, U3>::new(system, options))
        }
        (IntegratorKind::Gl1, StageSolver::FixedPoint) => {
            Box::new(GaussFixedPoint::<Dyn, U1>::new(system, FIXED_POINT_SWEEPS))
        }
        (IntegratorKind::Gl2, StageSolver::FixedPoint) => {
            Box::new(GaussFixedPoint::<Dyn, U2>::new(system, FIXED_POINT_SWEEPS))
        }
        (IntegratorKind::Gl3, StageSolver::FixedPoint) => {
            Box::new(GaussFixedPoint::<Dyn, U3>::new(system, FIXED_POINT_SWEEPS))
        }
        (IntegratorKind::Rk4, _) => Box::new(Rk4::new(system)),
    }
}

/// [`plain_integrator`] followed by the system's projection after every step.
fn projected_integrator<'a, S: Constrained<Dim = Dyn> + 'a>(
    kind: IntegratorKind,
    solver: StageSolver,
    system: &S,
) -> Box<dyn Integrator<S> + 'a> {
    Box::new(Projected::new(plain_integrator(kind, solver, system)))
}

/// An angle model with a boxed pivot drive, constant torques and the energy ledger.
type AccountedModel<M> = Accounted<M, Box<dyn Drive<<M as Model>::Space>>, ConstantTorque<<M as Model>::Dof>>;

/// A chain model in angle coordinates with its drive, torques and energy ledger
/// ([`Accounted`]): state `x = (q, q̇, W_drive, W_torque, E_damped)`.
pub struct AngleSimulation<M: Model>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    system: AccountedModel<M>,
    x0: DVector<f64>,
}

impl<M: Model<Links = Dyn, Dof = Dyn>> AngleSimulation<M>
where
    DefaultAllocator: ModelAlloc<Dyn, Dyn, M::Space>,
{
    fn new(
        model: M,
        drive: Box<dyn Drive<M::Space>>,
        torque: &[f64],
        q: &[f64],
        qd: &[f64],
    ) -> CliResult<Self> {
        let dof = model.dof();
        let torque =
            if torque.is_empty() { DVector::zeros(dof.0) } else { DVector::from_column_slice(torque) };
        let (q, qd) = (DVector::from_column_slice(q), DVector::from_column_slice(qd));
        model.check_configuration(&q).map_err(singular_start)?;
        let system = Accounted::new(model, drive, ConstantTorque(torque));
        let x0 = system.state(&q, &qd);
        Ok(Self { system, x0 })
    }
}

/// The error for a 3D start at the spherical-angle singularity.
fn singular_start(e: pendulum_core::Error) -> CliError {
    CliError::usage(format!(
        "initial state: {e}. The 3D model in spherical angles cannot start with a link \
         straight down or up; start tilted (--initial tilted:0.3) or from a file"
    ))
}

impl<M: Model<Links = Dyn, Dof = Dyn>> Simulation for AngleSimulation<M>
where
    DefaultAllocator: ModelAlloc<Dyn, Dyn, M::Space>,
{
    type Sys = AccountedModel<M>;

    fn system(&self) -> &Self::Sys {
        &self.system
    }

    fn initial_state(&self) -> DVector<f64> {
        self.x0.clone()
    }

    fn state_columns(&self) -> Vec<String> {
        let n = self.system.model().chain().links();
        let names: &[&str] = if M::Space::dim() == 2 { &["theta"] } else { &["theta", "phi"] };
        let mut columns = Vec::new();
        for prefix in ["", "d"] {
            for name in names {
                columns.extend((1..=n).map(|i| format!("{prefix}{name}{i}")));
            }
        }
        columns
    }

    fn sample(&self, t: f64, x: &DVector<f64>) -> Sample {
        let (q, _, ledger) = self.system.split(x);
        let drive = self.system.inputs().drive();
        let pivot = to3(&drive.position(t));
        let chain = self.system.model().chain();
        let masses = if M::Space::dim() == 2 {
            planar_positions(chain.lengths().as_slice(), q.as_slice(), pivot)
        } else {
            spatial_positions(chain.lengths().as_slice(), q.as_slice(), pivot)
        };
        let dof = q.len();
        Sample {
            t,
            state: x.as_slice()[..2 * dof].to_vec(),
            pivot,
            masses,
            energy: self.system.energy(t, x),
            ledger,
        }
    }

    fn integrator(&self, kind: IntegratorKind, solver: StageSolver) -> Box<dyn Integrator<Self::Sys> + '_> {
        plain_integrator(kind, solver, &self.system)
    }
}

/// A chain in unit link directions ([`Directions`], no coordinate singularity) with its
/// energy ledger ([`AccountedDirections`]).
pub struct DirectionsSimulation<S: DimName>
where
    DefaultAllocator: nalgebra::allocator::Allocator<S>,
{
    system: AccountedDirections<S, Box<dyn Drive<S>>>,
    x0: DVector<f64>,
}

impl<S: DimName> Simulation for DirectionsSimulation<S>
where
    DefaultAllocator: nalgebra::allocator::Allocator<S>,
{
    type Sys = AccountedDirections<S, Box<dyn Drive<S>>>;

    fn system(&self) -> &Self::Sys {
        &self.system
    }

    fn initial_state(&self) -> DVector<f64> {
        self.x0.clone()
    }

    fn state_columns(&self) -> Vec<String> {
        let n = self.system.chain().links();
        let axes = ["x", "y", "z"];
        let mut columns = Vec::new();
        for name in ["u", "w"] {
            for i in 1..=n {
                columns.extend(axes[..S::DIM].iter().map(|a| format!("{name}{i}_{a}")));
            }
        }
        columns
    }

    fn sample(&self, t: f64, x: &DVector<f64>) -> Sample {
        let motion = self.system.motion(x);
        let chain = self.system.chain();
        Sample {
            t,
            state: motion.as_slice().to_vec(),
            pivot: to3(&chain.drive().position(t)),
            masses: chain.positions(t, &motion).iter().map(to3).collect(),
            energy: chain.inertial_energy(t, &motion),
            ledger: self.system.ledger(x),
        }
    }

    fn integrator(&self, kind: IntegratorKind, solver: StageSolver) -> Box<dyn Integrator<Self::Sys> + '_> {
        projected_integrator(kind, solver, &self.system)
    }
}

/// A vector of the model's space as (x, y, z), z = 0 for a planar vector.
fn to3<S: DimName>(v: &OVector<f64, S>) -> [f64; 3]
where
    DefaultAllocator: nalgebra::allocator::Allocator<S>,
{
    [v[0], v[1], if S::dim() > 2 { v[2] } else { 0.0 }]
}

/// Planar mass positions `r_k = p + Σ_{j≤k} l_j (sin θ_j, −cos θ_j)` (m).
pub fn planar_positions(lengths: &[f64], theta: &[f64], pivot: [f64; 3]) -> Vec<[f64; 3]> {
    let mut r = pivot;
    lengths
        .iter()
        .zip(theta)
        .map(|(l, th)| {
            let (s, c) = th.sin_cos();
            r = [r[0] + l * s, r[1] - l * c, r[2]];
            r
        })
        .collect()
}

/// Spatial mass positions `r_k = p + Σ_{j≤k} l_j (sin θ_j cos φ_j, sin θ_j sin φ_j,
/// −cos θ_j)` (m), `q = (θ_1..θ_n, φ_1..φ_n)`.
pub fn spatial_positions(lengths: &[f64], q: &[f64], pivot: [f64; 3]) -> Vec<[f64; 3]> {
    let n = lengths.len();
    let mut r = pivot;
    (0..n)
        .map(|i| {
            let (st, ct) = q[i].sin_cos();
            let (sp, cp) = q[n + i].sin_cos();
            let l = lengths[i];
            r = [r[0] + l * st * cp, r[1] + l * st * sp, r[2] - l * ct];
            r
        })
        .collect()
}

/// The chain of a configuration, validated by the core.
pub fn chain(config: &RunConfig) -> CliResult<Chain<Dyn>> {
    Ok(Chain::<Dyn>::new(&config.masses, &config.lengths, config.gravity)?.with_damping(&config.damping)?)
}

/// The planar model in angles (the one place to change it): O(n) accelerations by the
/// rod tensions, everything else as the dense `Planar`.
pub fn planar_model(chain: Chain<Dyn>) -> PlanarTension<Dyn> {
    PlanarTension::new(chain)
}

/// The spatial model in spherical angles (`pendulum eval`): singular where a link
/// hangs straight down or up.
pub fn spatial_model(chain: Chain<Dyn>) -> Spatial<Dyn> {
    Spatial::new(chain)
}

/// The 3D chain `pendulum simulate` integrates (the one place to change it): unit link
/// directions, free of the spherical angles' singularity, started from spherical
/// angles `q = (θ, φ)` and rates `q̇` (any angles, a hanging chain included).
fn spatial_simulation(
    chain: Chain<Dyn>,
    drive: Box<dyn Drive<U3>>,
    q: &[f64],
    qd: &[f64],
) -> CliResult<DirectionsSimulation<U3>> {
    let directions = Directions::<U3>::new(chain).with_drive(drive);
    let motion = directions.from_spherical(q, qd)?;
    let system = AccountedDirections::new(directions);
    let x0 = system.state(&motion)?;
    Ok(DirectionsSimulation { system, x0 })
}

/// The planar drive of a configuration.
fn drive2(config: &DriveConfig) -> CliResult<Box<dyn Drive<U2>>> {
    Ok(match config {
        DriveConfig::Fixed => Box::new(Fixed),
        DriveConfig::Harmonic { direction, amplitude, omega, phase } => {
            let d = Vector2::from_iterator(direction.iter().copied());
            Box::new(Harmonic::new(d, *amplitude, *omega, *phase)?)
        }
        DriveConfig::Circle { .. } => {
            return Err(CliError::usage("--drive circle moves the pivot on a horizontal circle: 3D only"));
        }
    })
}

/// The spatial drive of a configuration.
fn drive3(config: &DriveConfig) -> CliResult<Box<dyn Drive<U3>>> {
    Ok(match config {
        DriveConfig::Fixed => Box::new(Fixed),
        DriveConfig::Harmonic { direction, amplitude, omega, phase } => {
            let d = Vector3::from_iterator(direction.iter().copied());
            Box::new(Harmonic::new(d, *amplitude, *omega, *phase)?)
        }
        DriveConfig::Circle { radius, omega } => Box::new(Circle::new(*radius, *omega)?),
    })
}

/// The simulation of a configuration, one of the supported kinds.
pub enum AnySimulation {
    /// 2D, angles.
    Planar(AngleSimulation<PlanarTension<Dyn>>),
    /// 3D, unit link directions.
    Spatial(DirectionsSimulation<U3>),
}

/// Builds the simulation a configuration describes; errors name the bad parameter.
pub fn build(config: &RunConfig) -> CliResult<AnySimulation> {
    let chain = chain(config)?;
    let (q, qd) = (&config.initial.coordinates, &config.initial.rates);
    Ok(match config.dim {
        Dimension::Two => AnySimulation::Planar(AngleSimulation::new(
            planar_model(chain),
            drive2(&config.drive)?,
            &config.torque,
            q,
            qd,
        )?),
        Dimension::Three => AnySimulation::Spatial(spatial_simulation(chain, drive3(&config.drive)?, q, qd)?),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_follow_the_conventions() {
        let r = planar_positions(&[1.0, 2.0], &[std::f64::consts::FRAC_PI_2, 0.0], [0.5, 0.0, 0.0]);
        assert!((r[0][0] - 1.5).abs() < 1e-15 && r[0][1].abs() < 1e-15);
        assert!((r[1][0] - 1.5).abs() < 1e-15 && (r[1][1] + 2.0).abs() < 1e-15);
        let half = std::f64::consts::FRAC_PI_2;
        let r = spatial_positions(&[1.0], &[half, half], [0.0; 3]);
        assert!(r[0][0].abs() < 1e-15 && (r[0][1] - 1.0).abs() < 1e-15 && r[0][2].abs() < 1e-15);
    }
}
