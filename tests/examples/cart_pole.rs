//! The inverted double and triple pendulum on a cart, balanced by LQR: the chains
//! linearised about upright by their analytic derivatives (`pendulum_core::linearize`,
//! what `pendulum linearize` prints), the gain for the pivot's horizontal acceleration
//! (`pendulum_core::lqr`, Q = I, R = 1, as `pendulum linearize --lqr pivot-x`), and the
//! nonlinear generated models run in closed loop for 10 s from every link 0.1 rad past
//! upright (RK4, h = 1 ms).
//!
//! ```text
//! cargo run --release -p pendulum-tests --example cart_pole
//! ```
//!
//! writes `docs/cart-pole.svg`: each link's angle from upright and the cart's acceleration
//! against time. `pendulum-cli/tests/linearize.rs` runs the same loop with the gain from the
//! command and asserts the chain stays within 0.2 rad of upright.

use std::{error::Error, f64::consts::PI, path::PathBuf};

use nalgebra::{DMatrix, SVector, Vector2};
use pendulum_core::{Chain, Derivatives, Inputs, Model, STEADY_TOLERANCE, linearize, lqr};
use plotters::prelude::*;

pendulum_macros::model! {
    struct Double { kind: planar, links: 2 }
    struct Triple { kind: planar, links: 3 }
}

/// One run: time, angles from upright per link, cart acceleration.
type Run = Vec<(f64, Vec<f64>, f64)>;

fn balance<M, const N: usize>(model: &M) -> Result<Run, Box<dyn Error>>
where
    M: Derivatives + Model<Dof = nalgebra::Const<N>, Space = nalgebra::U2, Links = nalgebra::Const<N>>,
{
    let up = SVector::<f64, N>::repeat(PI);
    let space = linearize(model, &up, &SVector::zeros(), &model.zero_inputs(), STEADY_TOLERANCE)?;
    let b = space.b_pivot.columns(0, 1).into_owned();
    let design = lqr(&space.a, &b, &DMatrix::identity(2 * N, 2 * N), &DMatrix::identity(1, 1))?;
    let gain: Vec<f64> = design.gain.iter().copied().collect();
    let control = |q: &SVector<f64, N>, qd: &SVector<f64, N>| -> f64 {
        -(0..N).map(|i| gain[i] * (q[i] - PI) + gain[N + i] * qd[i]).sum::<f64>()
    };
    let field = |q: &SVector<f64, N>, qd: &SVector<f64, N>| {
        let inputs =
            Inputs { torque: SVector::zeros(), pivot_acceleration: Vector2::new(control(q, qd), 0.0) };
        let mut qdd = SVector::zeros();
        model.accelerations(q, qd, &inputs, &mut qdd).map(|()| qdd)
    };
    let (mut q, mut qd) = (up.add_scalar(0.1), SVector::<f64, N>::zeros());
    let h = 1e-3;
    let mut run = Vec::new();
    for step in 0..=10_000 {
        if step % 10 == 0 {
            run.push((step as f64 * h, (q - up).iter().copied().collect::<Vec<f64>>(), control(&q, &qd)));
        }
        let k1 = (qd, field(&q, &qd)?);
        let k2 = (qd + k1.1 * (h / 2.0), field(&(q + k1.0 * (h / 2.0)), &(qd + k1.1 * (h / 2.0)))?);
        let k3 = (qd + k2.1 * (h / 2.0), field(&(q + k2.0 * (h / 2.0)), &(qd + k2.1 * (h / 2.0)))?);
        let k4 = (qd + k3.1 * h, field(&(q + k3.0 * h), &(qd + k3.1 * h))?);
        q += (k1.0 + k2.0 * 2.0 + k3.0 * 2.0 + k4.0) * (h / 6.0);
        qd += (k1.1 + k2.1 * 2.0 + k3.1 * 2.0 + k4.1) * (h / 6.0);
    }
    let worst = run.iter().flat_map(|(_, d, _)| d.iter().map(|x| x.abs())).fold(0.0, f64::max);
    println!(
        "n = {N}: gain {gain:.3?}; growth rate open loop {:.3} 1/s; at most {worst:.3} rad from upright",
        space.growth_rate()
    );
    Ok(run)
}

fn main() -> Result<(), Box<dyn Error>> {
    let _ = plotters::style::register_font(
        "sans-serif",
        plotters::style::FontStyle::Normal,
        epaint_default_fonts::UBUNTU_LIGHT,
    );
    let double = balance(&Double::new(Chain::new(&[1.0, 1.0], &[0.5, 0.4], 9.81)?))?;
    let triple = balance(&Triple::new(Chain::new(&[1.0, 1.0, 1.0], &[0.5, 0.4, 0.3], 9.81)?))?;
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs/cart-pole.svg");
    let root = SVGBackend::new(&path, (960, 640)).into_drawing_area();
    root.fill(&WHITE)?;
    let panels = root.split_evenly((2, 2));
    let colours = [RGBColor(31, 119, 180), RGBColor(214, 39, 40), RGBColor(44, 160, 44)];
    for (column, (name, run)) in [("double", &double), ("triple", &triple)].into_iter().enumerate() {
        let mut angles = ChartBuilder::on(&panels[column])
            .caption(format!("inverted {name} pendulum on a cart: angles"), ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(55)
            .build_cartesian_2d(0.0..10.0, -0.25..0.25)?;
        angles.configure_mesh().x_desc("t, s").y_desc("θ_i − π, rad").draw()?;
        for i in 0..run[0].1.len() {
            let c = colours[i];
            angles
                .draw_series(LineSeries::new(run.iter().map(|(t, d, _)| (*t, d[i])), c.stroke_width(2)))?
                .label(format!("link {}", i + 1))
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], c.stroke_width(2)));
        }
        for bound in [-0.2, 0.2] {
            angles.draw_series(DashedLineSeries::new(
                [(0.0, bound), (10.0, bound)],
                4,
                4,
                BLACK.mix(0.4).stroke_width(1),
            ))?;
        }
        angles
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK.mix(0.4))
            .draw()?;
        let top = run.iter().map(|(_, _, u)| u.abs()).fold(0.0, f64::max) * 1.1;
        let mut cart = ChartBuilder::on(&panels[2 + column])
            .caption(format!("{name}: the cart's acceleration (the only input)"), ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(55)
            .build_cartesian_2d(0.0..10.0, -top..top)?;
        cart.configure_mesh().x_desc("t, s").y_desc("p̈_x, m/s²").draw()?;
        cart.draw_series(LineSeries::new(run.iter().map(|(t, _, u)| (*t, *u)), BLACK.stroke_width(2)))?;
    }
    root.present()?;
    println!("wrote docs/cart-pole.svg");
    Ok(())
}
