//! The run loop every front end shares: integrate a built [`AnySimulation`] over its
//! configuration's time span, hand every sample to the [`Sink`]s (files, an in-memory
//! [`Recorder`](crate::record::Recorder), a socket), follow a whirled chain's shape, and return
//! a [`Report`]: how the run ended, what the integrator did, the final state and the
//! shape answer.

use std::ops::ControlFlow;

use pendulum_core::ShapeReport;
use pendulum_core::integrate::State;
use pendulum_core::trajectory;

use crate::assemble::{AnySimulation, Method, Motion, Sample, Simulation};
use crate::balance::RunBalance;
use crate::description::{Dimension, RunConfig};
use crate::error::Result;
use crate::file::{IntegratorWork, Outcome};
use crate::final_state::FinalState;
use crate::whirl::Whirl;

/// Where the samples of a run go.
pub trait Sink {
    /// Takes one sample; `h0` is the inertial-frame energy of the first sample, J. An
    /// error stops the run (the run returns it).
    fn sample(&mut self, sample: &Sample, h0: f64) -> Result<()>;
}

/// What the samples of a run hold, for the sinks to name their columns.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Space dimension.
    pub dim: Dimension,
    /// Number of links.
    pub links: usize,
    /// Names of the state columns (coordinates, then rates): 2D `theta1…, dtheta1…`; 3D
    /// `u1_x…, w1_x…`.
    pub state_columns: Vec<String>,
}

impl Layout {
    /// The columns of `trajectory.csv`: `t`, the state columns, the pivot and every mass
    /// (x, y in 2D; x, y, z in 3D).
    pub fn trajectory_header(&self) -> Vec<String> {
        let axes = &["x", "y", "z"][..self.dim.space()];
        let mut header = vec!["t".to_string()];
        header.extend(self.state_columns.iter().cloned());
        header.extend(axes.iter().map(|a| format!("pivot_{a}")));
        for i in 1..=self.links {
            header.extend(axes.iter().map(|a| format!("{a}{i}")));
        }
        header
    }
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// It reached its end time.
    Completed,
    /// The observer asked it to stop (Ctrl-C).
    Interrupted,
    /// A step failed.
    Failed,
}

impl Status {
    /// `completed`, `interrupted` or `failed`, as run.json says it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Completed => "completed",
            Self::Interrupted => "interrupted",
            Self::Failed => "failed",
        }
    }
}

/// What a run did and found.
#[derive(Debug, Clone)]
pub struct Report {
    /// How it ended.
    pub status: Status,
    /// The failed step's error, when it failed.
    pub error: Option<pendulum_core::Error>,
    /// The time reached, s.
    pub t: f64,
    /// Steps taken (a failed run: the failed step's number).
    pub steps: u64,
    /// Samples handed to the sinks.
    pub samples: u64,
    /// What the integrator did.
    pub work: IntegratorWork,
    /// The state the run ended in, exactly.
    pub final_state: FinalState,
    /// The energy balance over the samples.
    pub balance: RunBalance,
    /// A whirled chain (3D, pivot circling the vertical) that completed its run: the
    /// shape it took, or why the analysis failed. `None` for other runs.
    pub shape: Option<Result<ShapeReport>>,
}

impl Report {
    /// What the reader should know about a run that ended: an energy balance that is off.
    /// (A failed run says why it failed instead.)
    pub fn warnings(&self) -> Vec<String> {
        match self.status {
            Status::Failed => Vec::new(),
            _ => self.balance.warning().into_iter().collect(),
        }
    }

    /// run.json's `outcome`.
    pub fn outcome(&self) -> Outcome {
        Outcome {
            status: self.status.name().into(),
            t: self.t,
            steps: self.steps,
            samples: self.samples,
            error: self.error.as_ref().map(ToString::to_string),
            work: Some(self.work.clone()),
            balance: Some(self.balance),
            warnings: self.warnings(),
        }
    }
}

impl AnySimulation {
    /// The columns of this simulation's samples.
    pub fn layout(&self, config: &RunConfig) -> Layout {
        let state_columns = match self {
            Self::Planar(s) => s.state_columns(),
            Self::Spatial(s) => s.state_columns(),
        };
        Layout { dim: config.dim, links: config.links(), state_columns }
    }

    /// Runs `config` (the configuration this simulation was built from) from t = 0 to
    /// its end: every `every`-th step (and the last) a sample to each sink in turn; after
    /// every step `observe(t)`, which may stop the run (`ControlFlow::Break`: the report says
    /// [`Status::Interrupted`]). A failed step, or a sample whose energy is not finite
    /// ([`pendulum_core::Error::BlewUp`]), ends the run with [`Status::Failed`] and the
    /// samples so far; a sink's error or a failure of the shape analysis ends it with
    /// that error.
    pub fn run(
        &self,
        config: &RunConfig,
        sinks: &mut [&mut dyn Sink],
        observe: &mut dyn FnMut(f64) -> ControlFlow<()>,
    ) -> Result<Report> {
        match self {
            Self::Planar(s) => run(s, config, sinks, observe),
            Self::Spatial(s) => run(s, config, sinks, observe),
        }
    }
}

/// [`AnySimulation::run`] for one kind of motion.
fn run<P: Motion>(
    simulation: &Simulation<P>,
    config: &RunConfig,
    sinks: &mut [&mut dyn Sink],
    observe: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<Report> {
    let system = simulation.system();
    let mut solver = simulation.integrator(Method::of(config))?;
    let mut state = State::new(0.0, simulation.initial_state());
    let whirl = Whirl::of(config)?;
    let mut tracker = whirl.as_ref().map(Whirl::tracker).transpose()?;
    let mut stop_error = None;
    let mut blew_up = None;
    let mut initial_energy = None;
    let mut balance = RunBalance::new(config);
    let mut samples: u64 = 0;
    // Every step comes back here, so that `observe` (progress, Ctrl-C) hears of each one
    // however sparse the samples; every `every`-th and the last are sampled.
    config.check()?;
    let (last_step, _) = trajectory::plan(0.0, config.end, config.step)?;
    let mut step: u64 = 0;
    let result = trajectory::run(&mut *solver, system, &mut state, config.end, config.step, 1, |t, x| {
        let sampled = step.is_multiple_of(config.every as u64) || step == last_step;
        step += 1;
        // A run stopped between samples ends with a sample of where it stopped.
        let stopped = !sampled && observe(t).is_break();
        if !sampled && !stopped {
            return ControlFlow::Continue(());
        }
        let sample = simulation.sample(t, x);
        let h0 = *initial_energy.get_or_insert(sample.energy);
        balance.push(&sample, h0);
        for sink in sinks.iter_mut() {
            if let Err(e) = sink.sample(&sample, h0) {
                stop_error = Some(e);
                return ControlFlow::Break(());
            }
        }
        if let Some(tracker) = &mut tracker
            && let Err(e) = tracker.push(t, &sample.state)
        {
            stop_error = Some(e);
            return ControlFlow::Break(());
        }
        samples += 1;
        if !sample.energy.is_finite() {
            blew_up = Some(pendulum_core::Error::BlewUp { t, energy: sample.energy });
            return ControlFlow::Break(());
        }
        if stopped { ControlFlow::Break(()) } else { observe(t) }
    });
    if let Some(e) = stop_error {
        return Err(e);
    }
    let (status, error, steps) = match result {
        Ok(s) if blew_up.is_some() => (Status::Failed, blew_up, s.steps),
        Ok(s) if s.stopped_early => (Status::Interrupted, None, s.steps),
        Ok(s) => (Status::Completed, None, s.steps),
        Err(e) => {
            let steps = match &e {
                pendulum_core::Error::StepFailed { step, .. } => *step,
                _ => 0,
            };
            (Status::Failed, Some(e), steps)
        }
    };
    let motion = &state.x().as_slice()[..system.motion_len()];
    let phase = whirl.as_ref().map(|w| w.phase(state.t()));
    let final_state = FinalState::new(config.dim, config.links(), state.t(), motion, phase);
    Ok(Report {
        status,
        error,
        t: state.t(),
        steps,
        samples,
        work: solver.stats().into(),
        final_state,
        balance,
        // A run cut on request ends at once (the nearest steady shape costs a dense
        // spectrum, about a second at 200 links); a failed run has no shape to report.
        shape: tracker.as_ref().filter(|_| status == Status::Completed).map(|t| t.report()),
    })
}
