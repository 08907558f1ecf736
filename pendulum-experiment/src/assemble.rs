//! The one place a description becomes core values: which model simulates which chain,
//! the drive of a [`DriveConfig`], the integrator of a [`Method`], and the [`Simulation`]
//! the run loop sees (a motion with its energy ledger, its initial state, and what one
//! sample of it means: [`Motion`], trajectory columns and positions). The CLI's commands,
//! the live page and the sweep build their chains here.

use nalgebra::{DVector, DefaultAllocator, Dim, DimName, Dyn, OVector, U1, U2, U3};
use pendulum_core::energy::Powered;
use pendulum_core::integrate::{
    Constrained, DormandPrince, GaussFixedPoint, GaussLegendre, GaussOptions, Integrator, OntoConstraints,
    Projected, Rk4, System, Unprojected,
};
use pendulum_core::kinematics::Chart;
use pendulum_core::{
    Accounted, Chain, Circle, ConstantTorque, Directions, Drive, Driven, FirstOrder, Fixed, Harmonic, Ledger,
    Model, ModelAlloc, PlanarTension, RampedCircle, RodMidpoint, Sampled, Spatial, Turning,
};

use crate::description::{
    DEFAULT_TOLERANCE, Dimension, DriveConfig, IntegratorKind, RunConfig, StageSolver, check_components,
    circle_in_2d, midpoint_in_2d,
};
use crate::error::{Error, Result};

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

/// Most sweeps of the fixed-point stage solve per step.
const FIXED_POINT_SWEEPS: usize = 100;

/// How a run integrates: the integrator, the Gauss–Legendre stage solve, dp54's tolerance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Method {
    /// The integrator.
    pub kind: IntegratorKind,
    /// The Gauss–Legendre stage solve.
    pub solver: StageSolver,
    /// dp54's tolerance.
    pub tolerance: f64,
}

impl Method {
    /// The method `kind` with the default stage solve (fixed point) and tolerance.
    pub fn of_kind(kind: IntegratorKind) -> Self {
        Self { kind, solver: StageSolver::FixedPoint, tolerance: DEFAULT_TOLERANCE }
    }

    /// The method of a configuration.
    pub fn of(config: &RunConfig) -> Self {
        Self {
            kind: config.integrator,
            solver: config.solver,
            tolerance: config.tolerance.unwrap_or(DEFAULT_TOLERANCE),
        }
    }
}

/// The integrator of a method for an unconstrained system. Errors: a kind the system does
/// not have ([`IntegratorKind::Midpoint`] is for chains in unit directions).
fn plain_integrator<'a, S: System<Dim = Dyn> + 'a>(
    method: Method,
    system: &S,
) -> Result<Box<dyn Integrator<S> + Send + 'a>> {
    let options = GaussOptions::default();
    Ok(match (method.kind, method.solver) {
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
        (IntegratorKind::Dp54, _) => Box::new(DormandPrince::new(system, method.tolerance, Unprojected)?),
        (IntegratorKind::Midpoint, _) => {
            return Err(midpoint_in_2d());
        }
    })
}

/// [`plain_integrator`] followed by the system's projection after every step.
fn projected_integrator<'a, S: Constrained<Dim = Dyn> + 'a>(
    method: Method,
    system: &S,
) -> Result<Box<dyn Integrator<S> + Send + 'a>> {
    Ok(match method.kind {
        // Projected after every internal step, not only at the end of each step.
        IntegratorKind::Dp54 => Box::new(DormandPrince::new(system, method.tolerance, OntoConstraints)?),
        _ => Box::new(Projected::new(plain_integrator(method, system)?)),
    })
}

/// A chain's motion as `pendulum simulate` runs it: what the core's ledger needs
/// ([`Powered`]) and what a run's files show of it.
pub trait Motion: Powered + Sized {
    /// Names of the trajectory's state columns (coordinates, then rates).
    fn state_columns(&self) -> Vec<String>;
    /// Pivot position at time `t` (m), z = 0 in 2D.
    fn pivot(&self, t: f64) -> [f64; 3];
    /// Mass positions in the inertial frame (m) of the motion's state `x` at time `t`.
    fn masses(&self, t: f64, x: &[f64]) -> Vec<[f64; 3]>;
    /// The integrator of this kind for the system (with a projection onto the
    /// constraints where the motion has them).
    fn integrator<'a>(
        system: &'a Accounted<Self>,
        method: Method,
    ) -> Result<Box<dyn Integrator<Accounted<Self>> + 'a>>;
}

/// A model in angles with a boxed pivot drive and constant torques.
type AngleMotion<M> =
    FirstOrder<M, Driven<Box<dyn Drive<<M as Model>::Space>>, ConstantTorque<<M as Model>::Dof>>>;

impl<M: Model<Links = Dyn, Dof = Dyn>> Motion for AngleMotion<M>
where
    DefaultAllocator: ModelAlloc<Dyn, Dyn, M::Space>,
{
    fn state_columns(&self) -> Vec<String> {
        let n = self.model().chain().links();
        let mut columns = Vec::new();
        for prefix in ["", "d"] {
            for name in M::Chart::COORDINATES {
                columns.extend((1..=n).map(|i| format!("{prefix}{name}{i}")));
            }
        }
        columns
    }

    fn pivot(&self, t: f64) -> [f64; 3] {
        to3(&self.inputs().drive().position(t))
    }

    fn masses(&self, t: f64, x: &[f64]) -> Vec<[f64; 3]> {
        let chain = self.model().chain();
        let q = &x[..self.model().dof().value()];
        let pivot = self.inputs().drive().position(t);
        M::Chart::positions(chain.lengths().as_slice(), q, &pivot).iter().map(to3).collect()
    }

    fn integrator<'a>(
        system: &'a Accounted<Self>,
        method: Method,
    ) -> Result<Box<dyn Integrator<Accounted<Self>> + 'a>> {
        Ok(plain_integrator(method, system)?)
    }
}

impl<S: DimName> Motion for Directions<S, Box<dyn Drive<S>>>
where
    DefaultAllocator: nalgebra::allocator::Allocator<S>,
{
    fn state_columns(&self) -> Vec<String> {
        let axes = ["x", "y", "z"];
        let mut columns = Vec::new();
        for name in ["u", "w"] {
            for i in 1..=self.links() {
                columns.extend(axes[..S::DIM].iter().map(|a| format!("{name}{i}_{a}")));
            }
        }
        columns
    }

    fn pivot(&self, t: f64) -> [f64; 3] {
        to3(&self.drive().position(t))
    }

    fn masses(&self, t: f64, x: &[f64]) -> Vec<[f64; 3]> {
        self.positions(t, &DVector::from_column_slice(x)).iter().map(to3).collect()
    }

    fn integrator<'a>(
        system: &'a Accounted<Self>,
        method: Method,
    ) -> Result<Box<dyn Integrator<Accounted<Self>> + 'a>> {
        Ok(directions_integrator(method, system)?)
    }
}

/// The integrator of a method for a chain in unit link directions, with its ledger or
/// without: `midpoint` the implicit midpoint rule on the rods ([`RodMidpoint`], exact on
/// them by construction: a projection of the rates would change the energy outside the
/// ledger), any other kind followed by the projection onto the rods.
pub fn directions_integrator<'a, S>(method: Method, system: &S) -> Result<Box<dyn Integrator<S> + Send + 'a>>
where
    S: Constrained<Dim = Dyn> + 'a,
    RodMidpoint: Integrator<S>,
{
    match method.kind {
        IntegratorKind::Midpoint => Ok(Box::new(RodMidpoint::new())),
        _ => projected_integrator(method, system),
    }
}

/// A 3D chain in unit link directions whose pivot circles the vertical ([`Turning`]): the
/// model of a whirl's shape analysis and of a sweep's points.
pub fn whirl_model(chain: Chain<Dyn>, drive: Box<dyn Turning>) -> Directions<U3, Box<dyn Turning>> {
    Directions::<U3>::new(chain).with_drive(drive)
}

/// A chain set up to run: its motion with the energy ledger ([`Accounted`]) and the state
/// at t = 0.
pub struct Simulation<P> {
    system: Accounted<P>,
    x0: DVector<f64>,
}

impl<P: Motion> Simulation<P> {
    /// The motion from its state `motion` at t = 0, with an empty ledger.
    fn new(motion: P, start: &[f64]) -> Result<Self> {
        let system = Accounted::of(motion);
        let x0 = system.start(start)?;
        Ok(Self { system, x0 })
    }

    /// The first-order system integrated.
    pub fn system(&self) -> &Accounted<P> {
        &self.system
    }

    /// The state at t = 0.
    pub fn initial_state(&self) -> DVector<f64> {
        self.x0.clone()
    }

    /// Names of the trajectory's state columns (coordinates, then rates).
    pub fn state_columns(&self) -> Vec<String> {
        self.system.motion_system().state_columns()
    }

    /// Reads a sample out of the state `x` at time `t`.
    pub fn sample(&self, t: f64, x: &DVector<f64>) -> Sample {
        let motion = &x.as_slice()[..self.system.motion_len()];
        let chain = self.system.motion_system();
        Sample {
            t,
            state: motion.to_vec(),
            pivot: chain.pivot(t),
            masses: chain.masses(t, motion),
            energy: self.system.energy(t, x),
            ledger: self.system.ledger(x),
        }
    }

    /// The integrator of this method for the system.
    pub fn integrator(&self, method: Method) -> Result<Box<dyn Integrator<Accounted<P>> + '_>> {
        P::integrator(&self.system, method)
    }
}

/// A vector of the model's space as (x, y, z), z = 0 for a planar vector.
fn to3<S: DimName>(v: &OVector<f64, S>) -> [f64; 3]
where
    DefaultAllocator: nalgebra::allocator::Allocator<S>,
{
    [v[0], v[1], if S::dim() > 2 { v[2] } else { 0.0 }]
}

/// The chain of a configuration, validated by the core.
pub fn chain(config: &RunConfig) -> Result<Chain<Dyn>> {
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

/// The spaces a run's chain lives in, with what only one of them has.
pub trait RunSpace: DimName
where
    DefaultAllocator: nalgebra::allocator::Allocator<Self>,
{
    /// The circle drive, steady or ramped, in this space (3D only).
    fn circle(config: &DriveConfig) -> Result<Box<dyn Drive<Self>>>;
}

impl RunSpace for U2 {
    fn circle(_: &DriveConfig) -> Result<Box<dyn Drive<U2>>> {
        Err(circle_in_2d())
    }
}

impl RunSpace for U3 {
    fn circle(config: &DriveConfig) -> Result<Box<dyn Drive<U3>>> {
        match turning_drive(config)? {
            // Upcast: the same box, not a box of a box (the drive is called at every step).
            Some(turning) => Ok(turning),
            None => Err(Error::invalid("not a circle drive")),
        }
    }
}

/// The drive of a configuration as a [`Turning`] one (the pivot circling the vertical
/// axis: circle, steady or ramped), or `None` for other drives.
pub fn turning_drive(config: &DriveConfig) -> Result<Option<Box<dyn Turning>>> {
    Ok(match *config {
        DriveConfig::Circle { radius, omega } => Some(Box::new(Circle::new(radius, omega)?)),
        DriveConfig::RampedCircle { radius, initial_omega, omega, duration } => {
            Some(Box::new(RampedCircle::new(radius, initial_omega, omega, duration)?))
        }
        DriveConfig::Fixed | DriveConfig::Harmonic { .. } | DriveConfig::Sampled { .. } => None,
    })
}

/// The spline of a sampled drive in `S` (`at_rest`: zero velocity at the first and last
/// sample, else the natural spline); errors name the bad sample.
pub fn sampled_path<S: DimName>(times: &[f64], positions: &[Vec<f64>], at_rest: bool) -> Result<Sampled<S>>
where
    DefaultAllocator: nalgebra::allocator::Allocator<S>,
{
    check_components(positions, S::DIM)?;
    let path: Vec<OVector<f64, S>> = positions.iter().map(|p| OVector::from_column_slice(p)).collect();
    let path = if at_rest {
        Sampled::with_end_velocities(times.to_vec(), path, OVector::zeros(), OVector::zeros())
    } else {
        Sampled::new(times.to_vec(), path)
    };
    Ok(path?)
}

/// Checks a run's drive in `dim` as the core builds it (finite parameters, a direction of
/// positive length, a valid spline, the circle in 3D only); errors name the bad value.
pub fn check_drive(dim: Dimension, config: &DriveConfig) -> Result<()> {
    match dim {
        Dimension::Two => drive::<U2>(config).map(|_| ()),
        Dimension::Three => drive::<U3>(config).map(|_| ()),
    }
}

/// The pivot drive of a configuration.
fn drive<S: RunSpace>(config: &DriveConfig) -> Result<Box<dyn Drive<S>>>
where
    DefaultAllocator: nalgebra::allocator::Allocator<S>,
{
    Ok(match config {
        DriveConfig::Fixed => Box::new(Fixed),
        DriveConfig::Harmonic { direction, amplitude, omega, phase } => {
            let d = OVector::<f64, S>::from_iterator(direction.iter().copied());
            Box::new(Harmonic::new(d, *amplitude, *omega, *phase)?)
        }
        DriveConfig::Circle { .. } | DriveConfig::RampedCircle { .. } => S::circle(config)?,
        DriveConfig::Sampled { times, positions, at_rest, .. } => {
            Box::new(sampled_path::<S>(times, positions, *at_rest)?)
        }
    })
}

/// The simulation of a configuration, one of the supported kinds.
pub enum AnySimulation {
    /// 2D, angles.
    Planar(Simulation<AngleMotion<PlanarTension<Dyn>>>),
    /// 3D, unit link directions.
    Spatial(Simulation<Directions<U3, Box<dyn Drive<U3>>>>),
}

/// Builds the simulation a configuration describes; errors name the bad parameter.
///
/// 2D chains run in angles (the one place to change it: [`planar_model`]); 3D chains in
/// unit link directions, free of the spherical angles' singularity, started from
/// spherical angles `q = (θ, φ)` and rates `q̇` (any angles, a hanging chain included).
pub fn build(config: &RunConfig) -> Result<AnySimulation> {
    let chain = chain(config)?;
    let (q, qd) = (&config.initial.coordinates, &config.initial.rates);
    Ok(match config.dim {
        Dimension::Two => {
            let model = planar_model(chain);
            let dof = model.dof().value();
            let torque = if config.torque.is_empty() {
                DVector::zeros(dof)
            } else {
                DVector::from_column_slice(&config.torque)
            };
            let start: Vec<f64> = q.iter().chain(qd).copied().collect();
            let motion =
                FirstOrder::with_inputs(model, Driven::new(drive(&config.drive)?, ConstantTorque(torque)));
            AnySimulation::Planar(Simulation::new(motion, &start)?)
        }
        Dimension::Three => {
            let directions = Directions::<U3>::new(chain).with_drive(drive(&config.drive)?);
            let start = match &config.initial.directions {
                // A previous run's final state, exactly.
                Some(x) => {
                    let x = DVector::from_column_slice(x);
                    directions.check_state(&x)?;
                    x
                }
                None => directions.from_spherical(q, qd)?,
            };
            AnySimulation::Spatial(Simulation::new(directions, start.as_slice())?)
        }
    })
}
