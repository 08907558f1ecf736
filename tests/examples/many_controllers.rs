//! One controller, many plants: an LQR designed on the nominal inverted triple pendulum,
//! applied to 1024 copies whose masses and lengths are each drawn within ±10% of nominal
//! (a Monte Carlo of the controller's robustness to model error), every copy started
//! within 0.05 rad of upright and 0.1 rad/s of rest. The copies are the generated model
//! (`model!`, `algorithm: tension`) stepped together by `UnrolledBatch::integrate_rk4`
//! (and, apart, by `integrate_rk4_f32`), the control `σ = −K (x − x_up)` computed every
//! 10 ms and held as joint torques over ten RK4 steps of 1 ms: 6 s of control, 6 × 10⁶
//! chain-steps per precision.
//!
//! ```text
//! cargo run --release -p pendulum-tests --example many_controllers
//! ```
//!
//! writes `docs/many-controllers.svg`. Left: each copy's distance from upright at rest
//! against time (64 copies drawn, the worst and the median of all 1024 in bold), with the
//! nominal closed loop's slowest rate as a dashed line. Right: each copy's decay rate
//! measured over the last two seconds against its sampled linear loop's, `x_{j+1} − x_up =
//! (Φ_k − Γ_k K)(x_j − x_up)` from the copy's own start (its own masses and lengths, the
//! nominal gain, the torques held over each period): on the diagonal when each run does
//! what the linear theory says of its plant. Prints how many copies fell without control,
//! the worst copy, the rates' disagreement with that theory, and how many copies already
//! decay at their slowest closed-loop eigenvalue.

use std::{error::Error, f64::consts::PI, path::PathBuf, time::Instant};

use nalgebra::{Const, DMatrix, DVector, Dyn, SVector};
use pendulum_core::batch::UnrolledBatch;
use pendulum_core::integrate::State;
use pendulum_core::{Chain, Model, PlanarTension, STEADY_TOLERANCE, linearize, lqr};
use pendulum_tests::control;
use plotters::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pendulum_macros::model! { struct Triple { kind: planar, links: 3, algorithm: tension } }

const N: usize = 3;
const COPIES: usize = 1024;
/// The control period (s), the RK4 steps in it, and the periods run.
const PERIOD: f64 = 0.01;
const STEPS: usize = 10;
const PERIODS: usize = 600;
/// The run's length (s).
const T_END: f64 = PERIODS as f64 * PERIOD;
/// Nominal masses (kg), lengths (m) and joint damping (N·m·s).
const MASSES: [f64; N] = [0.5, 0.4, 0.3];
const LENGTHS: [f64; N] = [0.4, 0.35, 0.3];
const DAMPING: f64 = 1e-3;

/// The chain with masses and lengths scaled by `scale` (first the masses, then the lengths).
fn chain<D: nalgebra::Dim>(scale: &[f64; 2 * N]) -> Result<Chain<D>, Box<dyn Error>>
where
    nalgebra::DefaultAllocator: nalgebra::allocator::Allocator<D>,
{
    let masses: Vec<f64> = (0..N).map(|i| MASSES[i] * scale[i]).collect();
    let lengths: Vec<f64> = (0..N).map(|i| LENGTHS[i] * scale[N + i]).collect();
    Ok(Chain::new(&masses, &lengths, 9.81)?.with_damping(&[DAMPING; N])?)
}

/// The chain's `(A, B_σ)` linearised upright at rest.
fn upright(chain: Chain<Dyn>) -> Result<(DMatrix<f64>, DMatrix<f64>), Box<dyn Error>> {
    let model = PlanarTension::new(chain);
    let linear = linearize(
        &model,
        &DVector::from_element(N, PI),
        &DVector::zeros(N),
        &model.zero_inputs(),
        STEADY_TOLERANCE,
    )?;
    Ok((linear.a, linear.b_torque))
}

/// Copy `k`'s decay rate (1/s) over the last two seconds of `distances`.
fn measured_rate(distances: &[Vec<f64>], k: usize) -> f64 {
    let last = distances.len() - 1;
    let two_seconds = (2.0 / PERIOD) as usize;
    (distances[last][k] / distances[last - two_seconds][k]).ln() / 2.0
}

fn main() -> Result<(), Box<dyn Error>> {
    let _ = plotters::style::register_font(
        "sans-serif",
        plotters::style::FontStyle::Normal,
        epaint_default_fonts::UBUNTU_LIGHT,
    );
    // The design: LQR with Q = I, R = I on the nominal chain.
    let (a, b) = upright(chain(&[1.0; 2 * N])?)?;
    let design = lqr(&a, &b, &DMatrix::identity(2 * N, 2 * N), &DMatrix::identity(N, N))?;
    let (gain, nominal) = (design.gain, design.closed_loop[0].re);

    // The copies: scales within ±10%, starts near upright.
    let mut r = ChaCha8Rng::seed_from_u64(7);
    let scales: Vec<[f64; 2 * N]> =
        (0..COPIES).map(|_| std::array::from_fn(|_| r.random_range(0.9..1.1))).collect();
    let start: Vec<f64> = (0..COPIES * 2 * N)
        .map(|i| if i % (2 * N) < N { PI + r.random_range(-0.05..0.05) } else { r.random_range(-0.1..0.1) })
        .collect();
    let models = scales
        .iter()
        .map(|s| Ok(Triple::new(chain::<Const<N>>(s)?)))
        .collect::<Result<Vec<_>, Box<dyn Error>>>()?;
    let batch = UnrolledBatch::new(models)?;
    let h = PERIOD / STEPS as f64;

    // Each copy's own closed loop under the nominal gain: the slowest rate of
    // `A_k − B_k K`, and its sampled loop's linear theory, `x_{j+1} − x_up = (Φ − Γ K)(x_j − x_up)`
    // (the torques held over each period), run from the copy's own start: its distance's
    // rate over the last two seconds, faster modes included.
    let window = [T_END - 2.0, T_END].map(|t| (t / PERIOD).round() as u32);
    let theory = scales
        .iter()
        .zip(start.chunks(2 * N))
        .map(|(s, x)| {
            let (a, b) = upright(chain(s)?)?;
            let slowest = (&a - &b * &gain)
                .complex_eigenvalues()
                .iter()
                .map(|e| e.re)
                .fold(f64::NEG_INFINITY, f64::max);
            let map = control::sampled_loop(&a, &b, &gain, PERIOD);
            let [early, late] = window.map(|j| (map.pow(j) * control::from_up(x, N)).norm());
            Ok([slowest, (late / early).ln() / 2.0])
        })
        .collect::<Result<Vec<[f64; 2]>, Box<dyn Error>>>()?;

    // Without control they fall.
    let mut falling: Vec<State<Const<{ 2 * N }>>> =
        start.chunks(2 * N).map(|x| State::new(0.0, SVector::from_column_slice(x))).collect();
    let failures = batch.integrate_rk4(&mut falling, None, None, h, 200 * STEPS)?;
    let fallen = falling.iter().filter(|s| control::from_upright(s.x().as_slice(), N) > 1.0).count();
    println!(
        "without control: {fallen} of {COPIES} copies more than 1 (rad, rad/s) from upright after 2 s ({} failed)",
        failures.len()
    );

    // With it, in f64 (the states kept, compensations and all) and in f32.
    let clock = Instant::now();
    let mut states: Vec<State<Const<{ 2 * N }>>> =
        start.chunks(2 * N).map(|x| State::new(0.0, SVector::from_column_slice(x))).collect();
    let f64_run = control::controlled(&gain, (start.clone(), N), PERIODS, |rows, torque| {
        let failures = batch.integrate_rk4(&mut states, Some(torque), None, h, STEPS)?;
        assert!(failures.is_empty(), "{failures:?}");
        *rows = states.iter().flat_map(|s| s.x().iter().copied()).collect();
        Ok(())
    })?;
    let f64_time = clock.elapsed();
    let clock = Instant::now();
    let (mut x, mut carry): (Vec<f32>, Vec<f32>) =
        (start.iter().map(|&v| v as f32).collect(), vec![0.0; start.len()]);
    let f32_run = control::controlled(&gain, (start.clone(), N), PERIODS, |rows, torque| {
        let torque: Vec<f32> = torque.iter().map(|&t| t as f32).collect();
        let failures = batch.integrate_rk4_f32((&mut x, &mut carry), Some(&torque), None, h, STEPS)?;
        assert!(failures.is_empty(), "{failures:?}");
        *rows = x.iter().map(|&v| f64::from(v)).collect();
        Ok(())
    })?;
    let f32_time = clock.elapsed();
    println!(
        "6 s of control of {COPIES} copies (every core, control and bookkeeping included): f64 {:.0} ms, f32 {:.0} ms",
        f64_time.as_secs_f64() * 1e3,
        f32_time.as_secs_f64() * 1e3
    );

    let worst = |run: &[Vec<f64>], i: usize| run[i].iter().copied().fold(0.0, f64::max);
    let median = |run: &[Vec<f64>], i: usize| {
        let mut d = run[i].clone();
        d.sort_by(f64::total_cmp);
        d[COPIES / 2]
    };
    // |measured − theory| / |theory| of each copy's rate: its own run's linear theory, and
    // the slowest eigenvalue of its closed loop.
    let off = |run: &[Vec<f64>], which: usize| -> Vec<f64> {
        let mut off: Vec<f64> =
            (0..COPIES).map(|k| (measured_rate(run, k) / theory[k][which] - 1.0).abs()).collect();
        off.sort_by(f64::total_cmp);
        off
    };
    for (name, run) in [("f64", &f64_run), ("f32", &f32_run)] {
        let (linear, slowest) = (off(run, 1), off(run, 0));
        println!(
            "{name}: worst copy {:.2e} at the start, {:.2e} after 6 s; rates over 4–6 s against each run's linear \
             theory: median {:.1e}, worst {:.1e} off; within 2% of the slowest eigenvalue: {} of {COPIES}",
            worst(run, 0),
            worst(run, PERIODS),
            linear[COPIES / 2],
            linear[COPIES - 1],
            slowest.iter().filter(|&&o| o < 0.02).count()
        );
    }
    let (slow, fast) =
        theory.iter().fold((0.0f64, f64::NEG_INFINITY), |(lo, hi), &[p, _]| (lo.min(p), hi.max(p)));
    println!("slowest closed-loop rates {slow:.3} … {fast:.3} 1/s (nominal {nominal:.3} 1/s)");

    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs/many-controllers.svg");
    let root = SVGBackend::new(&path, (1100, 480)).into_drawing_area();
    root.fill(&WHITE)?;
    let (left, right) = root.split_horizontally(600);
    let t = |i: usize| i as f64 * PERIOD;
    let low = f64_run[PERIODS].iter().copied().fold(f64::INFINITY, f64::min) / 2.0;
    let high = worst(&f64_run, 0) * 3.0;
    let mut chart = ChartBuilder::on(&left)
        .caption(
            format!("{COPIES} inverted triple pendulums (±10% masses, lengths), one LQR"),
            ("sans-serif", 17),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..PERIODS as f64 * PERIOD, (low..high).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("t, s")
        .y_desc("distance from upright at rest")
        .y_label_formatter(&|d| format!("{d:.0e}"))
        .draw()?;
    let blue = RGBColor(31, 119, 180);
    for k in (0..COPIES).step_by(COPIES / 64) {
        let every_other = (0..=PERIODS).step_by(2).map(|i| (t(i), f64_run[i][k]));
        chart.draw_series(LineSeries::new(every_other, blue.mix(0.25)))?;
    }
    let black = BLACK.stroke_width(2);
    chart
        .draw_series(LineSeries::new((0..=PERIODS).map(|i| (t(i), worst(&f64_run, i))), black))?
        .label("worst copy (f64)")
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], black));
    let red = RGBColor(214, 39, 40).stroke_width(2);
    chart
        .draw_series(DashedLineSeries::new((0..=PERIODS).map(|i| (t(i), worst(&f32_run, i))), 6, 6, red))?
        .label("worst copy (f32, dashed)")
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], red));
    let median_style = blue.stroke_width(2);
    chart
        .draw_series(LineSeries::new((0..=PERIODS).map(|i| (t(i), median(&f64_run, i))), median_style))?
        .label("median copy (f64)")
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], median_style));
    let (t0, d0) = (2.0, worst(&f64_run, (2.0 / PERIOD) as usize));
    let dashed = BLACK.mix(0.6).stroke_width(1);
    chart
        .draw_series(DashedLineSeries::new(
            [(t0, d0), (t(PERIODS), d0 * (nominal * (t(PERIODS) - t0)).exp())],
            5,
            4,
            dashed,
        ))?
        .label(format!("e^(σt), nominal σ = {nominal:.3} 1/s"))
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], dashed));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK.mix(0.4))
        .draw()?;

    let measured: Vec<f64> = (0..COPIES).map(|k| measured_rate(&f64_run, k)).collect();
    let (lo, hi) = theory
        .iter()
        .map(|[_, linear]| *linear)
        .chain(measured.iter().copied())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), r| (lo.min(r), hi.max(r)));
    let range = (lo - 0.05 * (hi - lo))..(hi + 0.05 * (hi - lo));
    let mut rates = ChartBuilder::on(&right)
        .caption("each copy's decay rate over 4–6 s: run against its linear theory", ("sans-serif", 17))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(range.clone(), range.clone())?;
    rates
        .configure_mesh()
        .x_desc("rate of the copy's sampled linear loop, 1/s")
        .y_desc("rate of the nonlinear run, 1/s")
        .draw()?;
    rates
        .draw_series(LineSeries::new([(range.start, range.start), (range.end, range.end)], BLACK.mix(0.5)))?;
    let orange = RGBColor(255, 127, 14);
    for (name, run, colour, size) in [("f64", &f64_run, blue, 4), ("f32", &f32_run, orange, 2)] {
        rates
            .draw_series(
                (0..COPIES)
                    .map(|k| (theory[k][1], measured_rate(run, k)))
                    .filter(|(_, y)| range.contains(y))
                    .map(|point| Circle::new(point, size, colour.filled())),
            )?
            .label(name)
            .legend(move |(x, y)| Circle::new((x + 10, y), size, colour.filled()));
    }
    rates
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK.mix(0.4))
        .draw()?;
    root.present()?;
    println!("wrote docs/many-controllers.svg");
    Ok(())
}
