//! Long-run energy behaviour of the integrators on the chaotic double pendulum, in the
//! velocity form `x = (q, q̇)` ([`FirstOrder`]) and the canonical form `x = (q, p)`
//! ([`Canonical`]).
//!
//! Unit masses and lengths, g = 9.81 m/s², released from rest at θ = (π/2, π/2) (the
//! start has H ≈ 0, so energy errors are given relative to the scale m g l = 9.81 J).
//! Every run evaluates the energy after every step; it writes `t`, the energy error
//! `ΔH/(m g l)` at the sample and the largest `|ΔH|/(m g l)` since the previous sample
//! to `<out>/<run>.csv` (about 500 samples), and prints per run: the largest error,
//! the least-squares slope of `|ΔH|` against `t` (a secular drift shows as a slope times
//! run length comparable with the largest error), the exponent of a log-log fit of the
//! running maximum against `t` (Brouwer's law for round-off: ≤ ½; a linear drift: 1),
//! the integrator's statistics and the wall time. `<out>/summary.csv` collects the table.
//! Then ensembles of 16 runs from starts 10⁻⁹ rad apart (Gauss s = 3 and s = 2) give the
//! RMS and mean of ΔH over the members against t (`<out>/ensemble16_<run>.csv`,
//! `<out>/ensemble_summary.csv`): a random walk has RMS ∝ √t, a drift RMS ∝ t.
//!
//! ```text
//! cargo run --release -p pendulum-core --example energy_long_run -- [--out DIR] [--quick] [RUN ...]
//! ```
//! `RUN` filters runs by substring of their names (all by default; a filtered run writes
//! `summary_partial.csv`). `--quick` takes a tenth of the steps (a smoke test, written to
//! `target/energy_quick` unless `--out`); `--members K` sets the ensemble size (16);
//! `--refresh RATE` and `--no-extrapolate` change [`GaussOptions`] (a fresh Jacobian
//! every step with `--refresh 0`), to see whether the stage solve affects the energy.
//! Runs named `…_wrapped` bring the angles back to (−π, π] whenever one leaves
//! (−3π, 3π); the others let links that turn over wind up (hundreds of radians), which
//! turns out to decide whether the round-off follows Brouwer's law.
//!
//! `docs/plot_energy.py` draws `docs/energy.png` from the CSV files;
//! `docs/integrators.md` discusses the numbers.

use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use nalgebra::{Const, DimMul, SVector, U2, U3, Vector2};
use pendulum_core::integrate::{
    GaussAlloc, GaussLegendre, GaussOptions, GaussStages, Integrator, Rk4, State, Stats, System,
};
use pendulum_core::{Canonical, Chain, FirstOrder, Inputs, Planar};

type Model = Planar<Const<2>>;
type Velocity = FirstOrder<Model, Inputs<Const<2>, U2>>;
type Momentum = Canonical<Model, Inputs<Const<2>, U2>>;
type X = SVector<f64, 4>;

/// The stage-solve options of every Gauss run (default unless `--refresh`/`--no-extrapolate`).
static OPTIONS: std::sync::OnceLock<GaussOptions> = std::sync::OnceLock::new();

/// The energy scale m g l, J.
const SCALE: f64 = 9.81;
/// Samples written per run (at most).
const SAMPLES: usize = 500;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Method {
    Gauss2,
    Gauss3,
    Rk4,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Form {
    Velocity,
    Canonical,
}

struct Config {
    method: Method,
    form: Form,
    h: f64,
    steps: usize,
    /// Bring the angles back to (−π, π] whenever one leaves (−3π, 3π).
    wrap: bool,
}

impl Config {
    fn name(&self) -> String {
        let method = match self.method {
            Method::Gauss2 => "gl2",
            Method::Gauss3 => "gl3",
            Method::Rk4 => "rk4",
        };
        let form = match self.form {
            Form::Velocity => "velocity",
            Form::Canonical => "canonical",
        };
        let wrap = if self.wrap { "_wrapped" } else { "" };
        format!("{method}_{form}_h{}_n{}{wrap}", self.h, self.steps)
    }
}

/// One sample of a run.
struct Sample {
    /// Time, s.
    t: f64,
    /// Energy error ΔH/(m g l) at `t`.
    error: f64,
    /// Largest |ΔH|/(m g l) since the previous sample.
    window_max: f64,
    /// Whether this is one of the uniformly spaced samples (the others are log-spaced).
    uniform: bool,
}

/// What one run measured.
struct Outcome {
    name: String,
    config: (Method, Form, f64, usize),
    max_error: f64,
    /// Largest |ΔH|/(m g l) over t ≤ 1000 s.
    max_error_1000: f64,
    final_error: f64,
    /// Largest |θ_i| reached, rad (the angles are not wrapped: links that turn over wind up).
    max_angle: f64,
    slope: f64,
    running_max_slope: f64,
    /// Log-log exponent of the running maximum over the last two decades of the run.
    exponent_2: f64,
    /// The same over the last three decades.
    exponent_3: f64,
    /// Mean |ΔH|/(m g l) over the first and the last tenth of the run (uniform samples).
    mean_first_tenth: f64,
    mean_last_tenth: f64,
    stats: Stats,
    seconds: f64,
    samples: Vec<Sample>,
}

fn model() -> Model {
    Planar::new(Chain::<Const<2>>::uniform(2, 1.0, 1.0, 9.81).expect("valid chain"))
}

fn start() -> (Vector2<f64>, Vector2<f64>) {
    (Vector2::new(FRAC_PI_2, FRAC_PI_2), Vector2::zeros())
}

/// Steps `steps` times with step `h`, evaluating `energy` after each step.
fn run<S: System<Dim = Const<4>>, I: Integrator<S>>(
    system: &S,
    mut integrator: I,
    x0: X,
    h: f64,
    steps: usize,
    wrap: bool,
    energy: impl Fn(&X) -> f64,
) -> (Vec<Sample>, Stats, f64, f64, f64) {
    let e0 = energy(&x0);
    let mut state = State::new(0.0, x0);
    let every = steps.div_ceil(SAMPLES).max(1);
    // Also sample at 10 log-spaced steps per decade, for the log-log fits and plots.
    let mut log_steps: Vec<usize> =
        (0..).map(|k| 10f64.powf(0.1 * k as f64).round() as usize).take_while(|&n| n < steps).collect();
    log_steps.dedup();
    let mut next_log = log_steps.into_iter().peekable();
    let mut samples = Vec::with_capacity(SAMPLES + 100);
    let (mut window_max, mut max_1000, mut max_angle) = (0.0f64, 0.0f64, 0.0f64);
    let clock = Instant::now();
    for n in 1..=steps {
        integrator.step(system, &mut state, h).unwrap_or_else(|e| panic!("step {n}: {e}"));
        max_angle = max_angle.max(state.x()[0].abs()).max(state.x()[1].abs());
        if wrap && (state.x()[0].abs() > 3.0 * PI || state.x()[1].abs() > 3.0 * PI) {
            // Subtracting a multiple of fl(2π) changes the angle by ~1e-16 rad per wrap and
            // clears the compensation (`State::set`); wraps are rare (one per two turns).
            let mut x = *state.x();
            for i in 0..2 {
                x[i] -= (x[i] / TAU).round() * TAU;
            }
            state.set(state.t(), &x);
        }
        let error = (energy(state.x()) - e0) / SCALE;
        window_max = window_max.max(error.abs());
        if state.t() <= 1000.0 + 1e-9 {
            max_1000 = max_1000.max(error.abs());
        }
        let log_sample = next_log.peek() == Some(&n);
        if log_sample {
            next_log.next();
        }
        if log_sample || n % every == 0 || n == steps {
            let uniform = n % every == 0 || n == steps;
            samples.push(Sample { t: state.t(), error, window_max, uniform });
            window_max = 0.0;
        }
    }
    (samples, *integrator.stats(), clock.elapsed().as_secs_f64(), max_1000, max_angle)
}

fn gauss<S: System<Dim = Const<4>>, St: GaussStages>(system: &S) -> GaussLegendre<Const<4>, St>
where
    Const<4>: DimMul<St>,
    nalgebra::DefaultAllocator: GaussAlloc<Const<4>, St>,
{
    GaussLegendre::new(system, *OPTIONS.get().unwrap_or(&GaussOptions::default()))
}

fn run_form<S: System<Dim = Const<4>>>(
    system: &S,
    config: &Config,
    x0: X,
    energy: impl Fn(&X) -> f64,
) -> (Vec<Sample>, Stats, f64, f64, f64) {
    let (h, n, w) = (config.h, config.steps, config.wrap);
    match config.method {
        Method::Gauss2 => run(system, gauss::<S, U2>(system), x0, h, n, w, energy),
        Method::Gauss3 => run(system, gauss::<S, U3>(system), x0, h, n, w, energy),
        Method::Rk4 => run(system, Rk4::new(system), x0, h, n, w, energy),
    }
}

/// Least-squares slope of `y` against `x`.
fn slope(points: &[(f64, f64)]) -> f64 {
    let count = points.len() as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / count;
    let my = points.iter().map(|p| p.1).sum::<f64>() / count;
    let cov: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let var: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    cov / var
}

fn measure(config: &Config) -> Outcome {
    measure_from(config, 0.0)
}

/// [`measure`] from θ = (π/2 + δ, π/2 − 0.7 δ) (rad), at rest.
fn measure_from(config: &Config, delta: f64) -> Outcome {
    let (mut q, qd) = start();
    q[0] += delta;
    q[1] -= 0.7 * delta;
    let (samples, stats, seconds, max_error_1000, max_angle) = match config.form {
        Form::Velocity => {
            let system: Velocity = FirstOrder::new(model());
            let x0 = system.state(&q, &qd);
            run_form(&system, config, x0, |x| system.energy(x))
        }
        Form::Canonical => {
            let system: Momentum = Canonical::new(model());
            let x0 = system.from_velocities(&q, &qd);
            run_form(&system, config, x0, |x| system.energy(x).expect("regular state"))
        }
    };
    // Running maximum of |ΔH| at the sample times (the window maxima make it exact).
    let mut running = Vec::with_capacity(samples.len());
    let mut max = 0.0f64;
    for sample in &samples {
        max = max.max(sample.window_max);
        running.push((sample.t, max));
    }
    // Uniformly spaced samples only, so that early times are not over-weighted.
    let absolute: Vec<(f64, f64)> =
        samples.iter().filter(|s| s.uniform).map(|s| (s.t, s.error.abs())).collect();
    // Log-log exponents of the running maximum against t, over the last two and three
    // decades of the run (all samples in the range: log-spaced ones dominate early).
    let exponent = |decades: f64| {
        let t_end = running.last().map_or(0.0, |p| p.0);
        let points: Vec<(f64, f64)> = running
            .iter()
            .filter(|p| p.0 >= t_end * 10f64.powf(-decades) && p.1 > 0.0)
            .map(|&(t, m)| (t.ln(), m.ln()))
            .collect();
        if points.len() >= 2 { slope(&points) } else { f64::NAN }
    };
    let tenth = |late: bool| {
        let t_end = running.last().map_or(0.0, |p| p.0);
        let chosen: Vec<f64> = absolute
            .iter()
            .filter(|p| if late { p.0 >= 0.9 * t_end } else { p.0 <= 0.1 * t_end })
            .map(|p| p.1)
            .collect();
        chosen.iter().sum::<f64>() / chosen.len() as f64
    };
    Outcome {
        name: config.name(),
        config: (config.method, config.form, config.h, config.steps),
        max_error: max,
        max_error_1000,
        final_error: samples.last().map_or(0.0, |s| s.error),
        max_angle,
        slope: slope(&absolute),
        running_max_slope: slope(&running),
        exponent_2: exponent(2.0),
        exponent_3: exponent(3.0),
        mean_first_tenth: tenth(false),
        mean_last_tenth: tenth(true),
        stats,
        seconds,
        samples,
    }
}

/// An ensemble of `members` runs of `config` from starts `δ = k·10⁻⁹` rad apart
/// (k = 0 … members − 1): the chaos makes their round-off (and truncation) errors
/// independent samples. Per sample time: the root mean square and the mean of ΔH/(m g l)
/// over the members and the largest |ΔH| of any member. A random walk (Brouwer's law)
/// has its RMS growing like √t and a mean within a few RMS/√members of zero; a
/// systematic drift shows as RMS ∝ t with a mean of the same size.
fn ensemble(config: &Config, members: usize) -> (Vec<(f64, f64, f64, f64)>, f64) {
    let clock = Instant::now();
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get()).min(members);
    let mut outcomes: Vec<(usize, Outcome)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..workers)
            .map(|w| {
                scope.spawn(move || {
                    (w..members)
                        .step_by(workers)
                        .map(|k| (k, measure_from(config, 1e-9 * k as f64)))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("worker")).collect()
    });
    outcomes.sort_by_key(|o| o.0);
    let count = outcomes[0].1.samples.len();
    let rows = (0..count)
        .map(|j| {
            let t = outcomes[0].1.samples[j].t;
            let errors: Vec<f64> = outcomes.iter().map(|o| o.1.samples[j].error).collect();
            let rms = (errors.iter().map(|e| e * e).sum::<f64>() / members as f64).sqrt();
            let mean = errors.iter().sum::<f64>() / members as f64;
            let max = outcomes.iter().map(|o| o.1.samples[j].window_max).fold(0.0, f64::max);
            (t, rms, mean, max)
        })
        .collect();
    (rows, clock.elapsed().as_secs_f64())
}

fn ensemble_configs(quick: bool) -> Vec<Config> {
    let scale = if quick { 10 } else { 1 };
    let mut list = Vec::new();
    for (method, h) in [(Method::Gauss3, 0.001), (Method::Gauss2, 0.01)] {
        for form in [Form::Velocity, Form::Canonical] {
            list.push(Config { method, form, h, steps: 1_000_000 / scale, wrap: false });
        }
    }
    // Gauss s = 3 over the same 1000 s at h/2 and 2h: truncation error changes by 2^∓6,
    // round-off by 2^±½, which tells the two apart.
    for (h, steps) in [(0.002, 500_000), (0.0005, 2_000_000)] {
        list.push(Config {
            method: Method::Gauss3,
            form: Form::Canonical,
            h,
            steps: steps / scale,
            wrap: false,
        });
    }
    // The same with the angles wrapped.
    for form in [Form::Velocity, Form::Canonical] {
        list.push(Config { method: Method::Gauss3, form, h: 0.001, steps: 1_000_000 / scale, wrap: true });
    }
    for (h, steps) in [(0.002, 500_000), (0.0005, 2_000_000)] {
        list.push(Config {
            method: Method::Gauss3,
            form: Form::Canonical,
            h,
            steps: steps / scale,
            wrap: true,
        });
    }
    list
}

/// Log-log slope of `y` against `t` over the last `decades` decades of `points`.
fn loglog(points: &[(f64, f64)], decades: f64) -> f64 {
    let t_end = points.last().map_or(0.0, |p| p.0);
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.0 >= t_end * 10f64.powf(-decades) && p.1 > 0.0)
        .map(|&(t, y)| (t.ln(), y.ln()))
        .collect();
    if logs.len() >= 2 { slope(&logs) } else { f64::NAN }
}

fn configs(quick: bool) -> Vec<Config> {
    let scale = if quick { 10 } else { 1 };
    let mut list = Vec::new();
    let both = [Form::Velocity, Form::Canonical];
    for form in both {
        list.push(Config { method: Method::Gauss2, form, h: 0.01, steps: 1_000_000 / scale, wrap: false });
    }
    // Ten times longer: does the velocity form drift where the canonical one does not?
    for form in both {
        list.push(Config { method: Method::Gauss2, form, h: 0.01, steps: 10_000_000 / scale, wrap: false });
    }
    // The h⁴ scaling of the bound: 1000 s at three step sizes (h = 0.01 is the long run's
    // first 1000 s).
    for (h, steps) in [(0.02, 50_000), (0.005, 200_000)] {
        for form in both {
            list.push(Config { method: Method::Gauss2, form, h, steps: steps / scale, wrap: false });
        }
    }
    for wrap in [false, true] {
        for form in both {
            list.push(Config { method: Method::Gauss3, form, h: 0.001, steps: 1_000_000 / scale, wrap });
        }
    }
    for h in [0.01, 0.001] {
        for form in both {
            list.push(Config { method: Method::Rk4, form, h, steps: 1_000_000 / scale, wrap: false });
        }
    }
    list
}

fn main() {
    let mut out = None;
    let mut quick = false;
    let mut members = 16;
    let mut options = GaussOptions::default();
    let mut filters = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--out" => out = Some(PathBuf::from(args.next().expect("--out needs a directory"))),
            "--quick" => quick = true,
            "--refresh" => {
                options.jacobian_refresh_rate =
                    args.next().and_then(|m| m.parse().ok()).expect("--refresh needs a rate");
            }
            "--no-extrapolate" => options.extrapolate = false,
            "--members" => {
                members = args.next().and_then(|m| m.parse().ok()).expect("--members needs a count");
            }
            "-h" | "--help" => {
                println!(
                    "energy_long_run [--out DIR] [--quick] [--members K] [--refresh RATE] [--no-extrapolate] [RUN ...]"
                );
                return;
            }
            _ => filters.push(arg),
        }
    }
    OPTIONS.set(options).expect("set once");
    // A smoke test must not overwrite the committed data.
    let out = out.unwrap_or_else(|| PathBuf::from(if quick { "target/energy_quick" } else { "docs/data" }));
    std::fs::create_dir_all(&out).expect("create the output directory");
    let header = "run,method,form,h,steps,t_end,max_abs_dH,max_abs_dH_t1000,final_dH,slope_abs_dH_per_s,\
                  drift_over_run,slope_running_max_per_s,mean_first_tenth,mean_last_tenth,exponent_2_decades,exponent_3_decades,newton_per_step,jacobians_per_step,\
                  rhs_per_step,full_newton_steps,max_abs_angle,seconds";
    println!("{header}");
    let mut summary = format!("{header}\n");
    for config in configs(quick) {
        let name = config.name();
        if !filters.is_empty() && !filters.iter().any(|f| name.contains(f.as_str())) {
            continue;
        }
        let o = measure(&config);
        let mut csv = String::from("t,dH,window_max_abs_dH\n");
        for s in &o.samples {
            writeln!(csv, "{},{:.6e},{:.6e}", s.t, s.error, s.window_max).unwrap();
        }
        std::fs::write(out.join(format!("{}.csv", o.name)), csv).expect("write the samples");
        let (method, form, h, steps) = o.config;
        let per_step = |v: u64| v as f64 / steps as f64;
        let line = format!(
            "{},{method:?},{form:?},{h},{steps},{},{:.3e},{:.3e},{:.3e},{:.3e},{:.3e},{:.3e},{:.3e},{:.3e},{:.3},{:.3},{:.3},{:.4},{:.3},{},{:.1},{:.2}",
            o.name,
            h * steps as f64,
            o.max_error,
            o.max_error_1000,
            o.final_error,
            o.slope,
            o.slope * h * steps as f64,
            o.running_max_slope,
            o.mean_first_tenth,
            o.mean_last_tenth,
            o.exponent_2,
            o.exponent_3,
            per_step(o.stats.newton_iterations),
            per_step(o.stats.jacobian_evaluations),
            per_step(o.stats.rhs_evaluations),
            o.stats.full_newton_steps,
            o.max_angle,
            o.seconds,
        );
        println!("{line}");
        summary.push_str(&line);
        summary.push('\n');
    }
    let partial = if filters.is_empty() { "" } else { "_partial" };
    std::fs::write(out.join(format!("summary{partial}.csv")), summary).expect("write the summary");

    let header = "ensemble,members,t_end,rms_dH_end,mean_dH_end,mean_over_rms_sqrt_members,max_abs_dH,\
                  rms_exponent_2_decades,rms_exponent_3_decades,seconds";
    println!("{header}");
    let mut summary = format!("{header}\n");
    for config in ensemble_configs(quick) {
        let name = format!("ensemble{members}_{}", config.name());
        if !filters.is_empty() && !filters.iter().any(|f| name.contains(f.as_str())) {
            continue;
        }
        let (rows, seconds) = ensemble(&config, members);
        let mut csv = String::from("t,rms_dH,mean_dH,max_abs_dH\n");
        for (t, rms, mean, max) in &rows {
            writeln!(csv, "{t},{rms:.6e},{mean:.6e},{max:.6e}").unwrap();
        }
        std::fs::write(out.join(format!("{name}.csv")), csv).expect("write the ensemble");
        let rms: Vec<(f64, f64)> = rows.iter().map(|r| (r.0, r.1)).collect();
        let &(t_end, rms_end, mean_end, _) = rows.last().expect("samples");
        let max = rows.iter().map(|r| r.3).fold(0.0, f64::max);
        let line = format!(
            "{name},{members},{t_end},{rms_end:.3e},{mean_end:.3e},{:.2},{max:.3e},{:.3},{:.3},{seconds:.1}",
            mean_end / (rms_end / (members as f64).sqrt()),
            loglog(&rms, 2.0),
            loglog(&rms, 3.0),
        );
        println!("{line}");
        summary.push_str(&line);
        summary.push('\n');
    }
    std::fs::write(out.join(format!("ensemble_summary{partial}.csv")), summary).expect("write the summary");
}
