//! What the equations say about a chain beyond one trajectory: its normal modes about the
//! hanging rest (`modes`, with Bernoulli's continuum frequencies from the zeros of J0,
//! `bessel`, and the equal-link chain's exact ones from the zeros of L_n, `laguerre`), the undamped steady shapes turning rigidly about the vertical
//! as branches over the speed ω (`steady_branches`) and the heavy string they approach
//! (`continuum`, Kolodner's) and their stability (`stability`),
//! and the relative equilibria of the full 3D chain on a circling pivot, damping included,
//! with their spectrum (`relative_equilibrium`); the shape a whirled chain takes, seen in
//! the frame turning with its pivot, whether it settled and the damped steady shape nearest
//! it (`shape`); the state-space linearisation about a steady state from the models'
//! analytic derivatives (`state_space`) and the LQR gain for it (`lqr`). Shared linear
//! algebra: quasiseparable matrices (O(n) LU, solves and inertia, `quasiseparable`), the
//! turning-frame linearisation in that form (`turning_pencil`) and shift-and-invert
//! Arnoldi (`arnoldi`).

pub(crate) mod arnoldi;
pub(crate) mod bessel;
pub(crate) mod continuum;
pub(crate) mod laguerre;
pub(crate) mod lqr;
pub(crate) mod modes;
pub(crate) mod quasiseparable;
pub(crate) mod relative_equilibrium;
pub(crate) mod shape;
pub(crate) mod stability;
pub(crate) mod state_space;
pub(crate) mod steady_branches;
pub(crate) mod turning_pencil;

pub use bessel::bessel_j0_zero;
pub use continuum::{RotatingString, StringShape};
pub use laguerre::laguerre_zeros;
pub use lqr::{Lqr, lqr};
pub use modes::{
    NormalModes, bernoulli_frequency, equal_link_frequencies, fastest_decay_bound, fastest_frequency_bound,
    normal_modes, sign_changes,
};
pub use relative_equilibrium::{
    RelativeEquilibrium, relative_equilibrium, relative_spectrum, relative_spectrum_near_origin,
};
pub use shape::{
    NearestSteady, Settling, ShapeOptions, ShapeReport, ShapeTracker, WhirlShape, co_rotating_positions,
    nearest_steady, shape_report, whirl_shape,
};
pub use stability::{Linearisation, Stability, Verdict, linearise, stability, stability_dense};
pub use state_space::{STEADY_TOLERANCE, StateSpace, linearize};
pub use steady_branches::{Branch, BranchEnd, ContinuationOptions, SteadyRotation, SteadyShape};
