//! A run as asked for ([`Request`]): the chain, drive and start given, the integrator,
//! step and sampling optional ("choose for me"); [`Request::resolve`] checks it, makes
//! the choices ([`choose`]: from the chain's fastest mode, its slowest and the drive) and
//! returns the complete [`RunConfig`]. Also the step a failed run is advised to try
//! ([`suggested_step`]).

use nalgebra::{DefaultAllocator, DimName, Dyn, U2, U3, allocator::Allocator};
use pendulum_core::{Chain, Drive, fastest_frequency_bound};

use crate::assemble::{check_drive, sampled_path};
use crate::description::{
    DEFAULT_TOLERANCE, Dimension, DriveConfig, IntegratorKind, RunConfig, StageSolver, View, check_end,
    check_step,
};
use crate::error::{Error, Result};
use crate::initial::{InitialSpec, initial_state};
use crate::spelling::{opt, opt_is};

/// Everything a run needs except what the library may choose: give `integrator`, `step`
/// and `every` to fix them, leave them `None` to have them chosen from the chain and the
/// drive (the choice and its reason are recorded in [`RunConfig::chosen`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    /// Space dimension.
    pub dim: Dimension,
    /// Masses `m_i`, kg, one per link.
    pub masses: Vec<f64>,
    /// Rod lengths `l_i`, m, one per link.
    pub lengths: Vec<f64>,
    /// Gravity `g`, m/s² (along −y in 2D, −z in 3D).
    pub gravity: f64,
    /// Damping `λ_i`, N·m·s, one per link.
    pub damping: Vec<f64>,
    /// Constant torques `σ_i` on the angles, N·m, one per link (2D only; `None`: zero).
    pub torque: Option<Vec<f64>>,
    /// The pivot's motion.
    pub drive: DriveConfig,
    /// How the chain starts.
    pub initial: InitialSpec,
    /// 3D only: the initial azimuthal rate `φ̇` of every link, rad/s (a conical swing).
    pub spin: Option<f64>,
    /// The integrator (`None`: chosen).
    pub integrator: Option<IntegratorKind>,
    /// The Gauss–Legendre stage solve.
    pub solver: StageSolver,
    /// dp54's relative tolerance (`None`: [`DEFAULT_TOLERANCE`]; others: must be `None`).
    pub tolerance: Option<f64>,
    /// The step, s (`None`: chosen).
    pub step: Option<f64>,
    /// End time, s (the run starts at 0).
    pub end: f64,
    /// A sample every this many steps (`None`: about 500 samples).
    pub every: Option<usize>,
    /// The animation's plane (3D).
    pub view: View,
    /// Most frames of the animation.
    pub frames: usize,
}

impl Request {
    /// The complete configuration: the initial state resolved (a spec, a file, a previous
    /// run's final state), the integrator, step and sampling chosen where not given, every
    /// value checked. Errors name the bad value.
    pub fn resolve(mut self) -> Result<RunConfig> {
        let n = self.masses.len();
        if self.spin.is_some() && self.dim == Dimension::Two {
            return Err(Error::invalid(format!(
                "{} (initial azimuthal rate) applies to {} only",
                opt("spin"),
                opt_is("dim", 3)
            )));
        }
        let torque = match (self.torque.take(), self.dim) {
            (None, Dimension::Two) => vec![0.0; n],
            (None, Dimension::Three) => Vec::new(),
            (Some(t), Dimension::Two) => t,
            (Some(_), Dimension::Three) => {
                return Err(Error::invalid(format!(
                    "{}: constant torques are available in 2D only ({})",
                    opt("torque"),
                    opt_is("dim", 2)
                )));
            }
        };
        let initial = initial_state(&self.initial, self.dim, n, self.spin.unwrap_or(0.0))?;
        if let Some(h) = self.step {
            check_step(h)?;
        }
        check_end(self.end)?;
        // The drive's own checks (finite parameters, ...) now, not when the run starts:
        // `choose` takes its speed for the step (the chain it checks itself).
        check_drive(self.dim, &self.drive)?;
        let choice = choose(&self)?;
        let config = RunConfig {
            dim: self.dim,
            masses: self.masses,
            lengths: self.lengths,
            gravity: self.gravity,
            damping: self.damping,
            torque,
            drive: self.drive,
            integrator: choice.integrator,
            solver: self.solver,
            step: choice.step,
            tolerance: match (choice.integrator, self.tolerance) {
                (IntegratorKind::Dp54, t) => Some(t.unwrap_or(DEFAULT_TOLERANCE)),
                (_, None) => None,
                (_, Some(_)) => {
                    return Err(Error::invalid(format!(
                        "{} applies to {} only",
                        opt("tolerance"),
                        opt_is("integrator", "dp54")
                    )));
                }
            },
            end: self.end,
            every: choice.every,
            initial,
            view: self.view,
            frames: self.frames,
            chosen: choice.reason,
        };
        config.check()?;
        Ok(config)
    }
}

/// What a run was given or chose: the integrator, step and sampling, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Choice {
    /// The integrator.
    pub integrator: IntegratorKind,
    /// The step, s.
    pub step: f64,
    /// A sample every `every` steps.
    pub every: usize,
    /// Why, in words, for what was chosen (`None` when everything was given).
    pub reason: Option<String>,
}

/// Samples a run writes when `--every` is not given (about; at least one per step).
const TARGET_SAMPLES: f64 = 500.0;

/// Steps of the implicit midpoint rule per period of the faster of the drive and the
/// chain's slowest swing.
const MIDPOINT_STEPS_PER_PERIOD: f64 = 20.0;

/// The default step of the Gauss–Legendre and RK4 integrators where the chain allows it, s.
const EXPLICIT_DEFAULT_STEP: f64 = 0.005;

/// Fills in what the request leaves open:
/// - integrator: `midpoint` for a 3D chain that is driven or damped (implicit, stable
///   past the chain's fastest mode, which such a run need not resolve; the ledger closes
///   exactly), `gl2` otherwise (conservative runs, where its energy behaviour matters, and
///   2D runs, in angles);
/// - step: for `midpoint` a twentieth of the period of the faster of the drive and the
///   chain's slowest swing `√(g/L)`; for `dp54` the sample interval of about 500 samples
///   (it adapts its own steps inside); for the others `min(0.005 s, 0.5/ω_fastest, T_drive/40)`
///   ([`suggested_step`]);
/// - every: about 500 samples over the run, fewer where trajectory.csv would pass
///   [`TRAJECTORY_BUDGET`] (an error where even two samples would).
///
/// Errors: the chain's own (masses, lengths, gravity, damping), which the choices assume.
pub fn choose(config: &Request) -> Result<Choice> {
    let mut reasons = Vec::new();
    let driven = !matches!(config.drive, DriveConfig::Fixed);
    let damped = config.damping.iter().any(|l| *l != 0.0);
    let chain =
        Chain::<Dyn>::new(&config.masses, &config.lengths, config.gravity)?.with_damping(&config.damping)?;
    let fastest = fastest_mode(&chain, &config.drive);
    let chosen_integrator = config.integrator.unwrap_or_else(|| {
        let kind = if config.dim == Dimension::Three && (driven || damped) {
            IntegratorKind::Midpoint
        } else {
            IntegratorKind::Gl2
        };
        reasons.push(match kind {
            IntegratorKind::Midpoint => format!(
                "integrator midpoint: a {} 3D chain, stepped implicitly over its fastest mode \
                 (about {fastest:.3e} rad/s; an explicit step would need h < {:.1e} s), the ledger exact",
                if driven { "driven" } else { "damped" },
                2.8 / fastest.max(f64::MIN_POSITIVE)
            ),
            _ => "integrator gl2: Gauss–Legendre, order 4, for its energy behaviour (not driven, \
                  not damped, or 2D)"
                .into(),
        });
        kind
    });
    let drive = drive_frequency(&config.drive);
    let chosen_step = config.step.unwrap_or_else(|| {
        let (h, why) = match chosen_integrator {
            IntegratorKind::Midpoint => {
                let slowest = slowest_swing(&config.lengths, config.gravity);
                let (omega, what) = match drive {
                    Some(w) if w > slowest => (w, drive_period_words(&config.drive, w)),
                    _ => (slowest, format!("the chain's slowest swing (√(g/L) = {slowest:.3} rad/s)")),
                };
                if omega > 0.0 {
                    (std::f64::consts::TAU / omega / MIDPOINT_STEPS_PER_PERIOD, format!("1/20 of {what}"))
                } else {
                    (config.end / 1000.0, "a thousandth of the run (no gravity, no drive)".into())
                }
            }
            IntegratorKind::Dp54 => (
                config.end / TARGET_SAMPLES,
                "the sample interval, about 500 samples (dp54 sizes its own steps within it)".into(),
            ),
            _ => {
                let h = suggested_step(fastest, drive).min(EXPLICIT_DEFAULT_STEP);
                (h, format!("min(0.005 s, 0.5/ω_fastest, T_drive/40), ω_fastest ≈ {fastest:.3e} rad/s"))
            }
        };
        let h = h.min(config.end);
        reasons.push(format!("step {h:.4e} s: {why}"));
        h
    });
    let chosen_every = match config.every {
        Some(k) => k,
        None => {
            let (k, why) = default_every(config, chosen_step)?;
            reasons.push(why);
            k
        }
    };
    Ok(Choice {
        integrator: chosen_integrator,
        step: chosen_step,
        every: chosen_every,
        reason: (!reasons.is_empty()).then(|| reasons.join("; ")),
    })
}

/// The size trajectory.csv may take with the default sampling, bytes.
pub const TRAJECTORY_BUDGET: f64 = 100e6;

/// Bytes of one number in the CSV files, about: the shortest form that reads back exactly
/// (up to 17 digits, a sign, a point, an exponent) and its comma.
const BYTES_PER_NUMBER: f64 = 20.0;

/// About the bytes of one row of trajectory.csv for `links` links: the time, the state
/// (2D: angles and rates; 3D: directions and angular velocities), the pivot and every mass.
pub fn sample_bytes(dim: Dimension, links: usize) -> f64 {
    let n = links as f64;
    let space = dim.space() as f64;
    let state = match dim {
        Dimension::Two => 2.0 * n,
        Dimension::Three => 6.0 * n,
    };
    (1.0 + state + space * (n + 1.0)) * BYTES_PER_NUMBER
}

/// The default sampling: about 500 samples, fewer where they would take more than
/// [`TRAJECTORY_BUDGET`]; returns `every` and why. A chain so large that the first and the
/// last state alone pass the budget is an error that says what to give instead.
fn default_every(config: &Request, step: f64) -> Result<(usize, String)> {
    // An absurd step is refused by the configuration's check, with its message.
    let steps = pendulum_core::trajectory::plan(0.0, config.end, step)
        .map_or((config.end / step).ceil(), |(n, _)| n as f64)
        .max(1.0);
    let k = (config.end / (step * TARGET_SAMPLES)).floor().max(1.0);
    let row = sample_bytes(config.dim, config.masses.len());
    // Samples at t = 0, every k steps, and at the end.
    let samples = (steps / k).floor() + 1.0 + if steps % k == 0.0 { 0.0 } else { 1.0 };
    if samples * row <= TRAJECTORY_BUDGET {
        return Ok((k as usize, format!("every {k} steps: about {TARGET_SAMPLES} samples")));
    }
    let fit = (TRAJECTORY_BUDGET / row).floor();
    let mb = |bytes: f64| bytes / 1e6;
    if fit < 2.0 {
        return Err(Error::invalid(format!(
            "a chain of {} links: one sample of trajectory.csv takes about {:.0} MB, and the default \
             sampling keeps the file under {:.0} MB, too little for the first and the last state: give \
             {} to write those two (about {:.0} MB)",
            config.masses.len(),
            mb(row),
            mb(TRAJECTORY_BUDGET),
            opt_is("every", steps),
            mb(2.0 * row),
        )));
    }
    let k = (steps / (fit - 1.0)).ceil();
    let kept = (steps / k).floor() + 1.0 + if steps % k == 0.0 { 0.0 } else { 1.0 };
    let why = format!(
        "every {k} steps: {kept} samples, fewer than the usual {TARGET_SAMPLES} to keep trajectory.csv \
         under {:.0} MB (about {:.1} MB a sample)",
        mb(TRAJECTORY_BUDGET),
        mb(row)
    );
    Ok((k as usize, why))
}

/// The slowest swing of the chain as one pendulum of its whole length, `√(g/L)` (rad/s),
/// with `L = Σ l_i`: the first mode of a uniform chain is 1.2 times that.
fn slowest_swing(lengths: &[f64], gravity: f64) -> f64 {
    let length: f64 = lengths.iter().sum();
    (gravity.max(0.0) / length).sqrt()
}

/// The chain's fastest angular frequency (rad/s), [`fastest_frequency_bound`] with the
/// drive's largest acceleration added to gravity.
pub fn fastest_mode(chain: &Chain<Dyn>, drive: &DriveConfig) -> f64 {
    let accel = match drive {
        DriveConfig::Fixed => 0.0,
        DriveConfig::Harmonic { amplitude, omega, .. } => amplitude.abs() * omega * omega,
        DriveConfig::Circle { radius, omega } => radius * omega * omega,
        DriveConfig::RampedCircle { radius, initial_omega, omega, .. } => {
            radius * initial_omega.abs().max(omega.abs()).powi(2)
        }
        DriveConfig::Sampled { times, positions, at_rest, .. } => match positions.first().map(Vec::len) {
            Some(2) => largest_sampled_acceleration::<U2>(times, positions, *at_rest),
            _ => largest_sampled_acceleration::<U3>(times, positions, *at_rest),
        },
    };
    fastest_frequency_bound(chain, chain.gravity() + accel)
}

/// The largest `|p̈|` (m/s²) of a sampled path in `S`: at one of its samples, `p̈` being
/// linear between them (0 for a path that does not build: its run reports why).
fn largest_sampled_acceleration<S: DimName>(times: &[f64], positions: &[Vec<f64>], at_rest: bool) -> f64
where
    DefaultAllocator: Allocator<S>,
{
    sampled_path::<S>(times, positions, at_rest)
        .map_or(0.0, |path| times.iter().map(|&t| path.acceleration(t).norm()).fold(0.0, f64::max))
}

/// The drive's angular frequency (rad/s), if it has one. A sampled path's is that of a
/// period of ten of its closest samples, so that the steps chosen from it resolve every
/// piece of its spline (the explicit steps at a quarter of the spacing, the midpoint's at
/// half of it).
pub fn drive_frequency(drive: &DriveConfig) -> Option<f64> {
    match drive {
        DriveConfig::Fixed => None,
        DriveConfig::Harmonic { omega, .. } | DriveConfig::Circle { omega, .. } => Some(omega.abs()),
        DriveConfig::RampedCircle { initial_omega, omega, .. } => Some(initial_omega.abs().max(omega.abs())),
        DriveConfig::Sampled { times, .. } => {
            let closest = times.windows(2).map(|w| w[1] - w[0]).fold(f64::INFINITY, f64::min);
            (closest.is_finite() && closest > 0.0).then(|| std::f64::consts::TAU / (10.0 * closest))
        }
    }
}

/// The drive's period in words for the step's reason: its angular frequency `w` (rad/s),
/// or for a sampled path the ten samples [`drive_frequency`] takes as its period.
fn drive_period_words(drive: &DriveConfig, w: f64) -> String {
    match drive {
        DriveConfig::Sampled { .. } => {
            format!(
                "ten of the drive's samples (their closest {:.4e} s apart)",
                std::f64::consts::TAU / w / 10.0
            )
        }
        _ => format!("the drive's period ({w} rad/s)"),
    }
}

/// A step that resolves both: `h = 0.5 / ω_fastest`, at most a fortieth of the drive period.
pub fn suggested_step(fastest: f64, drive: Option<f64>) -> f64 {
    let mut h = 0.5 / fastest.max(f64::MIN_POSITIVE);
    if let Some(w) = drive.filter(|w| *w > 0.0) {
        h = h.min(std::f64::consts::TAU / w / 40.0);
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` links of 1/n m and 1/n kg (a 1 m chain), hanging, 300 s, nothing chosen yet.
    fn config(dim: Dimension, n: usize, drive: DriveConfig, damping: f64) -> Request {
        let link = 1.0 / n as f64;
        Request {
            dim,
            masses: vec![link; n],
            lengths: vec![link; n],
            gravity: 9.81,
            damping: vec![damping; n],
            torque: None,
            drive,
            initial: InitialSpec::Hanging,
            spin: None,
            integrator: None,
            solver: StageSolver::FixedPoint,
            tolerance: None,
            step: None,
            end: 300.0,
            every: None,
            view: View::Xz,
            frames: 150,
        }
    }

    /// [`config`] with the integrator, step and sampling given.
    fn given(
        mut r: Request,
        integrator: Option<IntegratorKind>,
        step: Option<f64>,
        every: Option<usize>,
    ) -> Request {
        (r.integrator, r.step, r.every) = (integrator, step, every);
        r
    }

    const WHIRL: DriveConfig = DriveConfig::Circle { radius: 0.02, omega: 6.0 };

    #[test]
    fn a_request_is_refused_for_its_chain_or_drive_before_anything_is_chosen() {
        // An infinite drive speed once made the chosen step 0, and the error named the step.
        let fast =
            config(Dimension::Three, 3, DriveConfig::Circle { radius: 0.02, omega: f64::INFINITY }, 0.0);
        assert_eq!(
            fast.resolve().unwrap_err().to_string(),
            "drive angular frequency must be finite, got inf"
        );
        let flat =
            DriveConfig::Harmonic { direction: vec![0.0, 0.0], amplitude: 0.1, omega: 1.0, phase: 0.0 };
        let e = config(Dimension::Two, 3, flat, 0.0).resolve().unwrap_err().to_string();
        assert_eq!(e, "drive direction norm must be finite and positive, got 0");
        let mut weightless = config(Dimension::Two, 3, DriveConfig::Fixed, 0.0);
        weightless.gravity = f64::NAN;
        let e = weightless.resolve().unwrap_err().to_string();
        assert!(e.contains("gravity") && e.contains("NaN"), "{e}");
        let circle_2d = config(Dimension::Two, 3, WHIRL, 0.0).resolve().unwrap_err();
        assert_eq!(
            circle_2d.message(crate::Front::Python),
            "drive=\"circle\" moves the pivot on a horizontal circle: 3D only (dim=3)"
        );
    }

    #[test]
    fn a_driven_3d_chain_gets_the_midpoint_step_at_a_twentieth_of_the_drive_period() {
        let c = choose(&config(Dimension::Three, 100, WHIRL, 3e-4)).unwrap();
        assert_eq!(c.integrator, IntegratorKind::Midpoint);
        assert!((c.step - std::f64::consts::TAU / 6.0 / 20.0).abs() < 1e-15, "{}", c.step);
        assert_eq!(c.every, 11, "300 s / (0.0524 s × 500)");
        let reason = c.reason.unwrap();
        assert!(reason.starts_with("integrator midpoint: a driven 3D chain"), "{reason}");
        assert!(reason.contains("about 6.474e2 rad/s"), "{reason}");
    }

    #[test]
    fn a_damped_undriven_3d_chain_steps_by_its_slowest_swing() {
        let c = choose(&config(Dimension::Three, 10, DriveConfig::Fixed, 1e-3)).unwrap();
        assert_eq!(c.integrator, IntegratorKind::Midpoint);
        let period = std::f64::consts::TAU / 9.81_f64.sqrt();
        assert!((c.step - period / 20.0).abs() < 1e-15, "{}", c.step);
        assert!(c.reason.unwrap().contains("a damped 3D chain"));
    }

    #[test]
    fn conservative_and_planar_runs_keep_gauss_legendre_below_the_fastest_mode() {
        // A free 3D chain of 100 links: gl2 at 0.5/ω_fastest, far below 0.005 s.
        let free = config(Dimension::Three, 100, DriveConfig::Fixed, 0.0);
        let c = choose(&free).unwrap();
        assert_eq!(c.integrator, IntegratorKind::Gl2);
        let chain = Chain::<Dyn>::new(&free.masses, &free.lengths, free.gravity).unwrap();
        assert!((c.step - 0.5 / fastest_mode(&chain, &free.drive)).abs() < 1e-15);
        // A driven damped planar triple pendulum: gl2 at 0.005 s (its modes are slow).
        let drive =
            DriveConfig::Harmonic { direction: vec![0.0, 1.0], amplitude: 0.01, omega: 2.0, phase: 0.0 };
        let c = choose(&config(Dimension::Two, 3, drive, 0.01)).unwrap();
        assert_eq!((c.integrator, c.step), (IntegratorKind::Gl2, EXPLICIT_DEFAULT_STEP));
    }

    #[test]
    fn dp54_samples_its_adaptive_steps_about_500_times() {
        let c =
            choose(&given(config(Dimension::Three, 10, WHIRL, 0.0), Some(IntegratorKind::Dp54), None, None))
                .unwrap();
        assert_eq!((c.step, c.every), (300.0 / 500.0, 1));
        assert!(c.reason.unwrap().starts_with("step 6.0000e-1 s: the sample interval"));
    }

    #[test]
    fn the_default_sampling_keeps_the_trajectory_within_its_budget() {
        // 20,000 links in 3D, 1 s at 1 ms: 1001 samples of 3.6 MB would be 3.6 GB.
        let mut big =
            given(config(Dimension::Three, 20_000, WHIRL, 0.0), Some(IntegratorKind::Rk4), Some(1e-3), None);
        big.end = 1.0;
        let row = sample_bytes(Dimension::Three, 20_000);
        assert!((row - (1.0 + 9.0 * 20_000.0 + 3.0) * 20.0).abs() < 1e-6);
        let c = choose(&big).unwrap();
        let samples = 1000 / c.every + 1 + usize::from(1000 % c.every != 0);
        assert!(samples as f64 * row <= TRAJECTORY_BUDGET, "{samples} samples of {row} bytes");
        assert!(
            (samples + 1) as f64 * row > TRAJECTORY_BUDGET / 2.0,
            "thinned no more than needed: {samples}"
        );
        let reason = c.reason.unwrap();
        assert!(reason.contains(&format!("{samples} samples, fewer than the usual 500")), "{reason}");
        // A million links in 2D: two samples alone pass the budget (issue 34: the run wrote
        // 1.76 GB in a minute). An error that says what to give.
        let mut huge =
            given(config(Dimension::Two, 1_000_000, DriveConfig::Fixed, 0.0), None, Some(5e-5), None);
        huge.end = 0.01;
        let e = choose(&huge).unwrap_err().to_string();
        assert!(
            e.starts_with("a chain of 1000000 links: one sample of trajectory.csv takes about 80 MB"),
            "{e}"
        );
        assert!(e.ends_with("give --every 200 to write those two (about 160 MB)"), "{e}");
    }

    #[test]
    fn what_is_given_is_kept_and_not_explained() {
        let request =
            given(config(Dimension::Three, 10, WHIRL, 0.0), Some(IntegratorKind::Rk4), Some(1e-3), Some(7));
        let c = choose(&request).unwrap();
        assert_eq!(c, Choice { integrator: IntegratorKind::Rk4, step: 1e-3, every: 7, reason: None });
    }
}
