//! The command line: `pendulum simulate | eval | linearize | modes | steady | render | sweep | atlas | view`, the
//! top of the CLI (it names every command's options; nothing imports it but `main`).

use clap::{Parser, Subcommand};

use crate::args::{EvalArgs, LinearizeArgs, ModesArgs, SimulateArgs, SteadyArgs};
use crate::atlas::AtlasArgs;
use crate::render::RenderArgs;
use crate::sweep::SweepArgs;
use crate::view::ViewArgs;

/// Swing N-link pendulums: chains of point masses on massless rigid rods hung from a
/// pivot that may be fixed or driven, in 2D or 3D.
///
/// SI units throughout, angles in radians. 2D: θ_i from the downward vertical, gravity
/// along −y. 3D: θ_i from −z, φ_i azimuth from +x, gravity along −z.
#[derive(Debug, Parser)]
#[command(name = "pendulum", version, propagate_version = true)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Integrate a chain in time; write trajectory.csv, energy.csv, run.json, energy.png
    /// and chain.gif into the output directory.
    ///
    /// trajectory.csv: t, the state (2D: θ_i then θ̇_i; 3D: unit link directions u_i then
    /// their rates w_i = u̇_i), the pivot and every mass (x, y[, z]), every k steps.
    /// energy.csv: t, energy (inertial frame), drive_work, torque_work, damped,
    /// balance_residual = energy − energy(0) − (drive_work + torque_work − damped).
    /// run.json: every parameter and the version (repeat with --from). Ctrl-C stops the
    /// run and writes valid files for what was computed.
    ///
    /// Without options: a small demo (a triple pendulum released from tilted:1.0 for
    /// 10 s) written to ./pendulum-run.
    Simulate(Box<SimulateArgs>),
    /// Evaluate one model at one state and print its terms as JSON: mass matrix M,
    /// velocity terms c, gravity terms k, pivot terms d, generalized forces Q, the
    /// accelerations q̈ = M⁻¹(Q − c − k − d), kinetic energy T and potential energy U
    /// (equation M q̈ + c + k + d = Q, the sympy reference's form). Planar accelerations
    /// come from the O(n) rod-tension solve, spatial ones from the spherical-angle model
    /// (singular where a link points straight down or up).
    Eval(EvalArgs),
    /// Linearise the chain about a steady state (an equilibrium, e.g. hanging or
    /// inverted, or a steady rotation: q̈ = 0) and print, as JSON, A (state x = (q, q̇)),
    /// B for the torques and for the pivot acceleration, and the eigenvalues of A, from
    /// the models' analytic derivatives (no finite differences). --lqr INPUT adds the LQR
    /// gain for one input (e.g. pivot-x: a cart). A state that is not steady is refused
    /// unless --force.
    Linearize(LinearizeArgs),
    /// Normal modes of the chain hanging at rest: a table of angular frequencies, periods
    /// and node counts (with Bernoulli's continuum frequencies for a uniform chain), and
    /// modes.csv and modes.png (the mode shapes) in the output directory.
    Modes(ModesArgs),
    /// Steady rotation about the vertical: the branches of shapes that turn rigidly at
    /// angular speed ω, up to exactly --omega-max (fixed pivot: leaving the vertical at
    /// the critical speeds; --radius R: a pivot on a circle), and every steady shape at
    /// the speeds of --omega with its node count, tip radius and stability: tables,
    /// branches.csv, shapes.csv, the branch diagram branches.png and shapes.png.
    ///
    /// Nodes = axis crossings + 1 (the pivot counted). Stability, of the 3D equations in
    /// the turning frame: stable (index 0, a minimum of the amended potential),
    /// gyroscopic (spectrally stable with an even index > 0: held by Coriolis forces,
    /// destroyed by damping in the turning frame) or unstable (growth rate: the largest
    /// real part of the eigenvalues, 1/s).
    Steady(SteadyArgs),
    /// Draw a run's animation again from its run.json and trajectory.csv, without
    /// simulating: another view (side, top, or co-rotating with a pivot that circles the
    /// vertical axis), time window, playback speed, size or frame count. Writes
    /// RUN_DIR/chain.gif (or --out FILE): axes in m, a scale bar, the rotation axis of a
    /// circling pivot and the tip's trail, in a viewport that fits the motion.
    Render(RenderArgs),
    /// Which shape a whirled 3D chain chooses: for every speed ω of --omega (a list or
    /// A:B:N) and every --kind of start (sudden, ramp-up, ramp-down), run the chain from
    /// hanging at rest (ramp-down: from the previous point's end) with its pivot on a
    /// horizontal circle of --radius R, RK4 + projection, and report the shape it ends in:
    /// nodes, axis crossings, tip radius, settled, the nearest damped steady shape and its
    /// stability. Points run in parallel (--jobs).
    ///
    /// Writes sweep.csv (a row per point and kind), sweep.json (every parameter and the
    /// results so far: repeat with --from) and sweep.png (the node count and tip radius
    /// chosen against ω over the steady branch diagram of `pendulum steady --radius R`),
    /// and prints a table. Ctrl-C stops: finished points are kept, the files stay valid.
    Sweep(Box<SweepArgs>),
    /// Which shape a whirled 3D chain at rest ends in over a grid of two parameters: two of
    /// --omega, --radius, --damping and --ramp-time given as A:B:N (or lists) are the axes,
    /// the others fixed; each point is the run of `pendulum sweep` (sudden or ramp-up start)
    /// with its parameters. Points run as batches of chains on all cores (--jobs).
    ///
    /// Writes atlas.csv (a row per point and kind), atlas.json (every parameter and the
    /// results so far: Ctrl-C keeps finished points, --from resumes) and atlas.png (the map
    /// coloured by node count, unsettled points marked, the basins' boundaries and the
    /// critical speeds drawn, one panel per kind), and prints the map in characters.
    Atlas(Box<AtlasArgs>),
    /// A run in the browser: served on http://127.0.0.1:PORT/ until Ctrl-C, or exported
    /// as one self-contained HTML file (--export FILE: data and scripts inline, nothing
    /// fetched; opens offline). The page shows the chain under an orbit
    /// camera (drag to turn, wheel to zoom; 2D runs in their plane), play/pause, one
    /// sample back and on, a time slider, playback speed, the frame co-rotating with a
    /// circling pivot, the tip's trail, the rotation axis and a scale bar, the energy
    /// ledger under a cursor at the shown time, the run's parameters and its shape
    /// summary. Long runs are thinned to --frames samples.
    ///
    /// --live: no run; the server simulates a 3D chain in real time for each page (the
    /// README's whirl unless --n, --masses, --lengths, --damping, --radius, --omega say
    /// otherwise) and streams it over a WebSocket. Drag the pivot with the mouse (it
    /// follows the pointer in the screen's plane; its acceleration enters the equations
    /// like any drive), set the circling speed, radius and damping while it runs.
    View(ViewArgs),
}
