//! The one error type of the crate: every variant names the bad value and where it is.

/// Everything that can go wrong when building a chain or evaluating a model.
///
/// Link numbers (`link`) are 1-based, as in the seed document (link 1 hangs from the
/// pivot); indices into vectors (`index`) are 0-based, as in Rust.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A chain was asked for with no links.
    #[error("a chain needs at least one link, got 0")]
    NoLinks,
    /// A vector has the wrong number of entries.
    #[error("{what} has {got} entries, expected {expected}")]
    LengthMismatch {
        /// Which vector (`"masses"`, `"q"`, `"torque"`, ...).
        what: &'static str,
        /// The length the chain or model needs.
        expected: usize,
        /// The length that was given.
        got: usize,
    },
    /// A mass is zero, negative, infinite or NaN.
    #[error("mass of link {link} must be finite and positive, got {}", num(.value))]
    InvalidMass {
        /// 1-based link number.
        link: usize,
        /// The offending value, kg.
        value: f64,
    },
    /// A length is zero, negative, infinite or NaN.
    #[error("length of link {link} must be finite and positive, got {}", num(.value))]
    InvalidLength {
        /// 1-based link number.
        link: usize,
        /// The offending value, m.
        value: f64,
    },
    /// Gravity is negative, infinite or NaN.
    #[error("gravity g must be finite and non-negative, got {}", num(.value))]
    InvalidGravity {
        /// The offending value, m/s².
        value: f64,
    },
    /// A damping coefficient is negative, infinite or NaN.
    #[error("damping of link {link} must be finite and non-negative, got {}", num(.value))]
    InvalidDamping {
        /// 1-based link number.
        link: usize,
        /// The offending value, N·m·s.
        value: f64,
    },
    /// The chains of a batch must have the same number of links (and there must be one).
    #[error("chain {chain} of the batch has {links} links, chain 0 has {expected}")]
    BatchMismatch {
        /// 0-based index of the chain in the batch.
        chain: usize,
        /// Its links.
        links: usize,
        /// Chain 0's links.
        expected: usize,
    },
    /// A batch needs at least one chain.
    #[error("a batch needs at least one chain, got 0")]
    EmptyBatch,
    /// A state or input entry is infinite or NaN.
    #[error("{what}[{index}] must be finite, got {}", num(.value))]
    NonFinite {
        /// Which vector (`"q"`, `"qd"`, `"torque"`, `"pivot_acceleration"`).
        what: &'static str,
        /// 0-based index into that vector.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A link of a spatial (θ, φ) model points straight down or up, where φ is undefined
    /// and the mass matrix is singular.
    #[error("link {link} sits at the spherical-angle singularity: theta = {} rad \
         (|sin theta| = {sin_theta:e} < {tolerance:e}); the (theta, phi) coordinates cannot \
         give its phi acceleration there", num(.theta))]
    SingularAngle {
        /// 1-based link number.
        link: usize,
        /// The link's polar angle θ, rad.
        theta: f64,
        /// |sin θ|.
        sin_theta: f64,
        /// The threshold below which |sin θ| counts as singular.
        tolerance: f64,
    },
    /// The mass matrix failed to factor as symmetric positive definite (only possible
    /// through round-off in extreme parameter ranges).
    #[error("the mass matrix is not numerically positive definite at this state")]
    NotPositiveDefinite,
    /// The O(n) tension solve (`PlanarTension`, `Directions`, the batches, `model!`'s
    /// `algorithm: tension`) gave non-finite accelerations from finite inputs: the state's
    /// or the chain's numbers (a rate, a length, a mass ratio) leave `f64`'s range.
    #[error("the accelerations are not finite at this state (its numbers leave the range of f64)")]
    NonFiniteAccelerations,
    /// A single-precision evaluation gave a non-finite result from finite inputs: the
    /// chain's numbers leave `f32`'s range (or its tension solve's) where `f64`'s do not.
    #[error("the accelerations are not finite in single precision at this state (use f64)")]
    SinglePrecisionOverflow,
    /// The implicit stage equations of an integrator step did not converge: the
    /// iterations (Newton, simplified then full, or fixed-point sweeps) diverged, stalled
    /// above round-off, or ran out. The state is left as it was before the step.
    #[error("the stage equations of the step from t = {} s with h = {} s did not converge \
         after {iterations} iterations; try a smaller step", num(.t), num(.h))]
    StageSolveFailed {
        /// Time at the start of the step, s.
        t: f64,
        /// The step size, s.
        h: f64,
        /// Iterations spent on the step, over all attempts.
        iterations: usize,
    },
    /// An integrator step produced an infinite or NaN state. The state is left as it was
    /// before the step.
    #[error("the step from t = {} s with h = {} s produced a non-finite state", num(.t), num(.h))]
    NonFiniteState {
        /// Time at the start of the step, s.
        t: f64,
        /// The step size, s.
        h: f64,
    },
    /// An error-controlled integrator could not meet its tolerance: its internal step
    /// shrank below 1e-12 of the step asked for, or it took a million internal steps. The
    /// state is left as it was before the step.
    #[error("the error-controlled step from t = {} s could not meet the tolerance {}: its internal \
         step shrank to {} s (a stiff chain: try --integrator midpoint, or a looser --tolerance)",
         num(.t), num(.tolerance), num(.h))]
    StepSizeCollapsed {
        /// Time where it gave up, s.
        t: f64,
        /// The internal step it had come down to, s.
        h: f64,
        /// The tolerance.
        tolerance: f64,
    },
    /// A tolerance of an error-controlled integrator outside `[1e-14, 0.1]` or NaN.
    #[error("tolerance must be within 1e-14 … 0.1, got {}", num(.tolerance))]
    InvalidTolerance {
        /// The offending value.
        tolerance: f64,
    },
    /// An integrator was asked for a step of size zero, infinite or NaN.
    #[error("step size h must be finite and non-zero, got {}", num(.h))]
    InvalidStepSize {
        /// The offending value, s.
        h: f64,
    },
    /// A pivot drive parameter is out of range (non-finite, negative amplitude or radius,
    /// zero direction).
    #[error("drive {what} must be {requirement}, got {}", num(.value))]
    InvalidDrive {
        /// Which parameter (`"amplitude"`, `"angular frequency"`, `"phase"`, `"radius"`,
        /// `"direction norm"`).
        what: &'static str,
        /// What it must be (`"finite"`, `"finite and non-negative"`, ...).
        requirement: &'static str,
        /// The offending value (for a direction, its Euclidean norm).
        value: f64,
    },
    /// A sampled pivot path ([`Sampled`](crate::drive::Sampled)) needs two samples at least.
    #[error("a sampled drive needs at least 2 samples, got {got}")]
    TooFewSamples {
        /// The number of samples given.
        got: usize,
    },
    /// A sample time of a sampled pivot path is not after the one before it.
    #[error("times[{index}] must be after times[{}] = {}, got {}", .index - 1, num(.previous), num(.value))]
    UnorderedTimes {
        /// 0-based index of the sample.
        index: usize,
        /// Its time, s.
        value: f64,
        /// The time before it, s.
        previous: f64,
    },
    /// A trajectory run was asked for with a bad end time or sampling.
    #[error("trajectory {what} must be {requirement}, got {}", num(.value))]
    InvalidRun {
        /// Which parameter (`"end time"`, `"step size"`, `"sampling interval"`).
        what: &'static str,
        /// What it must be.
        requirement: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A step of a trajectory run failed; `source` is the integrator's or the system's
    /// error. The state is left at time `t`, the start of the failed step.
    #[error("step {step} of the run, from t = {} s, failed: {source}", num(.t))]
    StepFailed {
        /// Time at the start of the failed step, s.
        t: f64,
        /// 0-based number of the failed step in the run.
        step: u64,
        /// What went wrong.
        source: Box<Error>,
    },
    /// A run's state is still finite but its energy is not: the run has blown up (a step
    /// too long for the chain, as a rule). The run stops at the sample that shows it.
    #[error("the energy reached {} J at t = {} s: the run blew up", num(.energy), num(.t))]
    BlewUp {
        /// Time of the sample, s.
        t: f64,
        /// The sample's energy, J.
        energy: f64,
    },
    /// A steady-rotation or normal-mode request has a parameter out of range.
    #[error("steady rotation: {what} must be {requirement}, got {}", num(.value))]
    InvalidSteady {
        /// Which parameter (`"angular speed"`, `"pivot radius"`, `"gravity"`, `"mode"`, ...).
        what: &'static str,
        /// What it must be.
        requirement: &'static str,
        /// The offending value.
        value: f64,
    },
    /// Newton's method on the steady-rotation shape equations did not converge.
    #[error("the steady-rotation shape equations at omega = {} rad/s did not converge after \
         {iterations} Newton iterations (residual {residual:e})", num(.omega))]
    SteadyNotConverged {
        /// The angular speed, rad/s.
        omega: f64,
        /// Newton iterations spent.
        iterations: usize,
        /// The residual norm reached, N·m.
        residual: f64,
    },
    /// A linearisation was asked for at a state that is not steady: `q̈ ≠ 0`.
    #[error("the state is not an equilibrium or a steady rotation: qdd[{index}] = {} rad/s², \
         above the tolerance {}", num(.value), num(.tolerance))]
    NotSteady {
        /// 0-based coordinate index of the largest acceleration.
        index: usize,
        /// That acceleration, rad/s².
        value: f64,
        /// The tolerance it exceeds, rad/s².
        tolerance: f64,
    },
    /// The algebraic Riccati equation of an LQR design has no stabilising solution.
    #[error("LQR: {reason}")]
    Riccati {
        /// Why (not stabilisable, a weight not positive definite, ...).
        reason: String,
    },
}

/// A value for an error message: plain decimals (`-1`, `0.5`, `NaN`, `inf`) in the
/// usual range, scientific notation (`1e-300`, `2.5e20`) for the very small and very large,
/// which plain `{}` would print as hundreds of digits.
fn num(value: &f64) -> String {
    let magnitude = value.abs();
    if magnitude != 0.0 && magnitude.is_finite() && !(1e-5..1e16).contains(&magnitude) {
        format!("{value:e}")
    } else {
        format!("{value}")
    }
}

/// The crate's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extreme_values_are_printed_in_scientific_notation() {
        let e = Error::InvalidRun { what: "step size", requirement: "not absurdly small", value: 1e-300 };
        assert_eq!(e.to_string(), "trajectory step size must be not absurdly small, got 1e-300");
        let e = Error::InvalidGravity { value: -2.5e20 };
        assert_eq!(e.to_string(), "gravity g must be finite and non-negative, got -2.5e20");
        let e = Error::InvalidMass { link: 2, value: -1.0 };
        assert_eq!(e.to_string(), "mass of link 2 must be finite and positive, got -1");
        let e = Error::InvalidStepSize { h: f64::NAN };
        assert_eq!(e.to_string(), "step size h must be finite and non-zero, got NaN");
    }
}
