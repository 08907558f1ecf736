//! A run of an N-link pendulum as data, for every front end (the `pendulum` command, its
//! sweep and live page, and the language bindings):
//!
//! - [`RunConfig`] describes an experiment completely (chain, drive, damping and
//!   torques, initial state, end, integrator, step, sampling, how to draw it); inside a
//!   [`RunFile`] it is `run.json`, versioned, and every file an earlier release wrote still
//!   loads.
//! - [`Request`] is a run as asked for, with the integrator, step and sampling optional;
//!   [`Request::resolve`] chooses them ([`choose`], from the chain's fastest mode and the
//!   drive, recording why) and checks everything.
//! - [`build`] turns a configuration into core values, the one place that picks a model
//!   for a chain and an integrator for a method ([`assemble`]).
//! - [`AnySimulation::run`] is the run loop: samples stream to [`Sink`]s
//!   ([`SampleFiles`] writes trajectory.csv and energy.csv, [`Recorder`] keeps arrays),
//!   and the [`Report`] says how the run ended, its final state and, for a whirled chain,
//!   the shape it took.
//! - [`options`] turns a front end's separate options (flags, keyword arguments) into the
//!   description's values with the shared one-line messages; [`run_dir`] reads a written
//!   run back; [`page`] makes the self-contained page of `pendulum view` and notebooks.
//! - [`steady`]: the steady shapes as `pendulum steady` and `pendulum.steady` show them
//!   (the branches up to exactly ω_max with every point's verdict, the shapes at speeds).
//!
//! The core (`pendulum-core`) stays free of serde and files: this crate sits between it
//! and the front ends, so an embedder of a fixed-N model builds neither.
//!
//! ```
//! use pendulum_experiment::{Dimension, DriveConfig, InitialSpec, Recorder, Request, StageSolver, View, build};
//!
//! let config = Request {
//!     dim: Dimension::Two,
//!     masses: vec![1.0; 3],
//!     lengths: vec![0.5; 3],
//!     gravity: 9.81,
//!     damping: vec![0.0; 3],
//!     torque: None,
//!     drive: DriveConfig::Fixed,
//!     initial: InitialSpec::Tilted(1.0),
//!     spin: None,
//!     integrator: None, // chosen: Gauss–Legendre s = 2
//!     solver: StageSolver::FixedPoint,
//!     tolerance: None,
//!     step: None,
//!     end: 2.0,
//!     every: None,
//!     view: View::Xz,
//!     frames: 150,
//! }
//! .resolve()?;
//! let mut recorder = Recorder::default();
//! let report = build(&config)?.run(&config, &mut [&mut recorder], &mut |_| std::ops::ControlFlow::Continue(()))?;
//! assert_eq!(report.status.name(), "completed");
//! let worst = recorder.balance_residual.iter().fold(0.0_f64, |m, r| m.max(r.abs()));
//! assert!(worst < 1e-6, "energy drift {worst} J");
//! # Ok::<(), pendulum_experiment::Error>(())
//! ```

pub mod assemble;
pub mod atlas;
pub mod balance;
pub mod csv;
pub mod description;
pub mod error;
pub mod file;
pub mod files;
pub mod final_state;
pub mod initial;
pub mod json;
pub mod options;
pub mod page;
pub mod points;
pub mod record;
pub mod request;
pub mod run;
pub mod run_dir;
pub mod spelling;
pub mod steady;
pub mod sweep;
pub mod whirl;
pub mod whirls;
pub mod words;

pub use assemble::{AnySimulation, Method, Sample, build, chain, directions_integrator, turning_drive};
pub use balance::{BALANCE_TOLERANCE, RunBalance};
pub use csv::Csv;
pub use description::{
    DEFAULT_TOLERANCE, Dimension, DriveConfig, InitialConfig, IntegratorKind, RunConfig, StageSolver, View,
};
pub use error::{Error, Result};
pub use file::{IntegratorWork, Outcome, RunFile, VERSION, other_version};
pub use files::SampleFiles;
pub use final_state::FinalState;
pub use initial::{InitialSpec, initial_state, read_numbers};
pub use json::write_json_atomic;
pub use options::{DriveKind, DriveOptions, PathSamples};
pub use record::Recorder;
pub use request::{Choice, Request, choose, drive_frequency, fastest_mode, suggested_step};
pub use run::{Layout, Report, Sink, Status};
pub use spelling::{Front, opt, opt_is};
pub use whirl::Whirl;
