//! Relative equilibria of the 3D chain in unit link directions with its pivot on a circle,
//! damping included: the steady shapes a driven, damped chain settles into, and their
//! spectrum, computed from the [`Directions`] model's own accelerations.
//!
//! With the pivot on `p(t) = R (cos ωt, sin ωt, 0)` ([`Circle`]), gravity along −z and the
//! chain's damping `D = ½ Σ λ_i |u̇_i|²` (inertial rates), the equations are equivariant
//! under turning about z by `ωt`. In the frame turning with the pivot, with
//! `ũ_i = Rot(−ωt) u_i`, `w̃_i = Rot(−ωt) w_i` (inertial rates, rotated), the system is
//! autonomous:
//!
//! ```text
//! dũ_i/dt = w̃_i − Ω × ũ_i,     dw̃_i/dt = a_i(0, ũ, w̃) − Ω × w̃_i,     Ω = ω e_z,
//! ```
//!
//! `a_i(0, ·)` the model's accelerations at `t = 0` (pivot at `(R, 0, 0)`). A relative
//! equilibrium has `w̃_i = Ω × ũ_i` and `a_i = Ω × (Ω × ũ_i)`; only the two components of
//! the latter tangent to the unit sphere are unknown (the rod tension fixes the radial one),
//! so with `ũ_i = (cos ψ_i sin θ_i, sin ψ_i, −cos ψ_i cos θ_i)` Newton solves `2n`
//! equations in `(θ_i, ψ_i)` with a central-difference Jacobian. Without damping the
//! solutions are the planar shapes of [`crate::SteadyRotation`] (`ψ = 0`); with damping
//! they lag out of the plane.
//!
//! The spectrum is that of the autonomous system's Jacobian restricted to the tangent
//! space of the constraint manifold (`|u_i| = 1`, `u_i · w_i = 0`, invariant under the
//! flow): `4n` eigenvalues from the model's analytic tangents ([`Directions::jvp`]) along
//! a basis of that space.

use nalgebra::{Complex, DMatrix, DVector, U3, Vector3};

use crate::analysis::arnoldi::Arnoldi;

use crate::drive::Circle;
use crate::error::{Error, Result};
use crate::kinematics::tilt::{direction, tangents};
use crate::models::directions::Directions;

/// A relative equilibrium of a driven chain, in the frame turning with the pivot at
/// `t = 0` (pivot at `(R, 0, 0)`).
#[derive(Debug, Clone, PartialEq)]
pub struct RelativeEquilibrium {
    /// In-plane angles `θ_i` and out-of-plane angles `ψ_i` of the links, rad.
    pub angles: Vec<(f64, f64)>,
    /// The model state `x = (u, w)` at `t = 0`: `w_i = Ω × u_i`.
    pub state: DVector<f64>,
}

fn omega_of(model: &Directions<U3, Circle>) -> Vector3<f64> {
    Vector3::new(0.0, 0.0, model.drive().angular_frequency())
}

/// The state `(u, Ω × u)` of the shape with angles `(θ_i, ψ_i)`.
fn rigid_state(model: &Directions<U3, Circle>, angles: &[(f64, f64)]) -> DVector<f64> {
    let n = angles.len();
    let omega = omega_of(model);
    let mut x = DVector::zeros(6 * n);
    for (i, &(t, p)) in angles.iter().enumerate() {
        let u = direction(t, p);
        let w = omega.cross(&u);
        x.fixed_rows_mut::<3>(3 * i).copy_from(&u);
        x.fixed_rows_mut::<3>(3 * (n + i)).copy_from(&w);
    }
    x
}

/// The autonomous rotating-frame vector field `G(x̃)` (module docs).
fn field(model: &Directions<U3, Circle>, x: &DVector<f64>) -> Result<DVector<f64>> {
    let n = model.links();
    let omega = omega_of(model);
    let mut acc = vec![0.0; 3 * n];
    model.accelerations(0.0, x, &mut acc, None)?;
    let mut g = DVector::zeros(6 * n);
    for i in 0..n {
        let u = x.fixed_rows::<3>(3 * i).into_owned();
        let w = x.fixed_rows::<3>(3 * (n + i)).into_owned();
        let a = Vector3::new(acc[3 * i], acc[3 * i + 1], acc[3 * i + 2]);
        g.fixed_rows_mut::<3>(3 * i).copy_from(&(w - omega.cross(&u)));
        g.fixed_rows_mut::<3>(3 * (n + i)).copy_from(&(a - omega.cross(&w)));
    }
    Ok(g)
}

/// The `2n` tangential equilibrium residuals `t_k · (a_i − Ω × (Ω × u_i))`, 1/s².
fn residual(model: &Directions<U3, Circle>, angles: &[(f64, f64)]) -> Result<DVector<f64>> {
    let n = angles.len();
    let x = rigid_state(model, angles);
    let g = field(model, &x)?;
    let mut r = DVector::zeros(2 * n);
    for (i, &(t, p)) in angles.iter().enumerate() {
        let (t1, t2) = tangents(t, p);
        let dw = g.fixed_rows::<3>(3 * (n + i)).into_owned();
        r[2 * i] = t1.dot(&dw);
        r[2 * i + 1] = t2.dot(&dw);
    }
    Ok(r)
}

/// The relative equilibrium of `model` nearest `guess` (angles `(θ_i, ψ_i)`, rad) by
/// Newton's method with a central-difference Jacobian (steps limited to 0.3 rad, at most 60);
/// once the steps are below 1e-2 rad the Jacobian is kept while each step at least halves
/// the residual (the chord method).
///
/// Errors: [`Error::LengthMismatch`] when `guess` does not have one pair per link,
/// [`Error::NonFinite`] for a non-finite guess, [`Error::SteadyNotConverged`] when Newton
/// fails (e.g. `R = 0` without damping: the shape can turn freely about the axis and the
/// Jacobian is singular).
pub fn relative_equilibrium(
    model: &Directions<U3, Circle>,
    guess: &[(f64, f64)],
) -> Result<RelativeEquilibrium> {
    let n = model.links();
    if guess.len() != n {
        return Err(Error::LengthMismatch { what: "guess", expected: n, got: guess.len() });
    }
    if let Some((index, v)) =
        guess.iter().flat_map(|&(a, b)| [a, b]).enumerate().find(|(_, v)| !v.is_finite())
    {
        return Err(Error::NonFinite { what: "guess", index, value: v });
    }
    let omega = model.drive().angular_frequency();
    let mut angles = guess.to_vec();
    let h = 1e-7;
    // Newton while the steps are large (the path to the solution, and so the solution
    // found, as with a new Jacobian every step); then the chord method: the Jacobian is
    // kept while each step at least halves the residual (near the solution one
    // factorisation serves every step).
    let mut factor: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>> = None;
    let (mut previous, mut last_step) = (f64::INFINITY, f64::INFINITY);
    for it in 1..=ITERATIONS {
        let r = residual(model, &angles)?;
        let norm = r.norm();
        if factor.is_none() || norm > 0.5 * previous || last_step > CHORD_BELOW {
            let mut jac = DMatrix::zeros(2 * n, 2 * n);
            for j in 0..2 * n {
                let shift = |s: f64| {
                    let mut a = angles.clone();
                    if j % 2 == 0 {
                        a[j / 2].0 += s
                    } else {
                        a[j / 2].1 += s
                    }
                    a
                };
                let col = (residual(model, &shift(h))? - residual(model, &shift(-h))?) / (2.0 * h);
                jac.set_column(j, &col);
            }
            factor = Some(jac.lu());
        }
        previous = norm;
        let fail = || Error::SteadyNotConverged { omega, iterations: it, residual: norm };
        let mut step = factor.as_ref().and_then(|f| f.solve(&(-&r))).ok_or_else(fail)?;
        let size = step.amax();
        if !size.is_finite() {
            return Err(fail());
        }
        if size > 0.3 {
            step *= 0.3 / size;
        }
        last_step = size;
        for (i, a) in angles.iter_mut().enumerate() {
            a.0 += step[2 * i];
            a.1 += step[2 * i + 1];
        }
        if size < 1e-11 {
            let state = rigid_state(model, &angles);
            return Ok(RelativeEquilibrium { angles, state });
        }
    }
    Err(Error::SteadyNotConverged {
        omega,
        iterations: ITERATIONS,
        residual: residual(model, &angles)?.norm(),
    })
}

/// Newton (chord) steps before [`relative_equilibrium`] gives up.
const ITERATIONS: usize = 60;

/// The largest step (rad) after which [`relative_equilibrium`] keeps its Jacobian.
const CHORD_BELOW: f64 = 1e-2;

/// The linearisation about `eq` in the turning frame on the constraint manifold, `4n × 4n`,
/// in the tangent coordinates of each link `i`: `4i + k` the position along `t_k`
/// (`δu = t_k`, `δw = −(t_k·w) u`), `4i + 2 + k` the velocity along `t_k` (`δw = t_k`),
/// from `4n` analytic tangents of the model ([`Directions::jvp`]). `J` maps the tangent
/// space to itself and the `t_k` are orthonormal and normal to `u`, so a coordinate of
/// `J b` is the dot product of `t_k` with its `u`- or `w`-part: `O(n²)` in all.
fn reduced(model: &Directions<U3, Circle>, eq: &RelativeEquilibrium) -> Result<DMatrix<f64>> {
    let n = model.links();
    let x0 = &eq.state;
    let omega = omega_of(model);
    let frames: Vec<(Vector3<f64>, Vector3<f64>)> = eq.angles.iter().map(|&(t, p)| tangents(t, p)).collect();
    let mut reduced = DMatrix::zeros(4 * n, 4 * n);
    let mut b = DVector::zeros(6 * n);
    let mut da = vec![0.0; 3 * n];
    for (i, (t1, t2)) in frames.iter().enumerate() {
        let u = x0.fixed_rows::<3>(3 * i).into_owned();
        let w = x0.fixed_rows::<3>(3 * (n + i)).into_owned();
        for (k, tk) in [t1, t2].into_iter().enumerate() {
            for velocity in [false, true] {
                b.as_mut_slice().fill(0.0);
                if velocity {
                    b.fixed_rows_mut::<3>(3 * (n + i)).copy_from(tk);
                } else {
                    b.fixed_rows_mut::<3>(3 * i).copy_from(tk);
                    b.fixed_rows_mut::<3>(3 * (n + i)).copy_from(&(-(tk.dot(&w)) * u));
                }
                model.jvp(0.0, x0, &b, &mut da)?;
                let c = 4 * i + k + if velocity { 2 } else { 0 };
                for (j, (s1, s2)) in frames.iter().enumerate() {
                    let du = b.fixed_rows::<3>(3 * j).into_owned();
                    let dw = b.fixed_rows::<3>(3 * (n + j)).into_owned();
                    let a = Vector3::new(da[3 * j], da[3 * j + 1], da[3 * j + 2]);
                    let (gu, gw) = (dw - omega.cross(&du), a - omega.cross(&dw));
                    reduced[(4 * j, c)] = s1.dot(&gu);
                    reduced[(4 * j + 1, c)] = s2.dot(&gu);
                    reduced[(4 * j + 2, c)] = s1.dot(&gw);
                    reduced[(4 * j + 3, c)] = s2.dot(&gw);
                }
            }
        }
    }
    Ok(reduced)
}

/// The `4n` eigenvalues (1/s) of the linearisation about `eq` in the turning frame, on the
/// constraint manifold (module docs), from the model's analytic tangents
/// ([`Directions::jvp`]), by a dense eigensolve (`O(n³)`; [`relative_spectrum_near_origin`]
/// finds those that can grow in `O(n²)`).
///
/// Errors: those of the model's accelerations.
pub fn relative_spectrum(
    model: &Directions<U3, Circle>,
    eq: &RelativeEquilibrium,
) -> Result<Vec<Complex<f64>>> {
    Ok(reduced(model, eq)?.complex_eigenvalues().iter().copied().collect())
}

/// The eigenvalues of [`relative_spectrum`] within `1.5 |ω| + ½ sqrt(g/L)` of the origin
/// (at least 16, sorted by modulus): those that can grow.
///
/// Without damping an eigenvalue with `Re λ > 0` has `|λ|² = −p*Hp / p*Mp ≤ ω²` when every
/// rod pulls (`H ⪰ E − ω² M` with `E` the rod tensions times lengths), and light damping
/// moves eigenvalues little; the margin covers it. They come from shift-and-invert Arnoldi
/// near the origin: the position coordinates' rows of the linearisation are `J = [A B; C D]`
/// with `A`, `B` one `2 × 2` block per link, so `(J − σ)⁻¹` needs one dense `2n × 2n` LU of
/// the Schur complement `C − (D − σ) B⁻¹(A − σ)` (`O(n³)` with a small constant, against
/// `4n × 4n` Schur iterations) and `O(n²)` per step.
///
/// Errors: those of the model's accelerations; [`Error::NotPositiveDefinite`] when no shift
/// gives an invertible complement.
pub fn relative_spectrum_near_origin(
    model: &Directions<U3, Circle>,
    eq: &RelativeEquilibrium,
) -> Result<Vec<Complex<f64>>> {
    const CONVERGED: f64 = 1e-10;
    let n = model.links();
    let j = reduced(model, eq)?;
    let chain = model.chain();
    let reference = (chain.gravity().abs() / chain.lengths().iter().sum::<f64>()).sqrt();
    let omega = model.drive().angular_frequency().abs();
    let radius = 1.5 * omega + 0.5 * reference;
    let (pos, vel) = (|i: usize| 4 * i, |i: usize| 4 * i + 2);
    let block = |r: usize, c: usize| {
        nalgebra::Matrix2::new(j[(r, c)], j[(r, c + 1)], j[(r + 1, c)], j[(r + 1, c + 1)])
    };
    let mut sigma = 1e-2 * reference.max(omega);
    let mut solver = None;
    for _ in 0..6 {
        // K_i = B_i⁻¹ (A_i − σ), S = C − (D − σ) K (in position / velocity halves).
        let inverses: Option<Vec<nalgebra::Matrix2<f64>>> =
            (0..n).map(|i| block(pos(i), vel(i)).try_inverse()).collect();
        let Some(inverses) = inverses else { return Err(Error::NotPositiveDefinite) };
        let k: Vec<nalgebra::Matrix2<f64>> = (0..n)
            .map(|i| inverses[i] * (block(pos(i), pos(i)) - nalgebra::Matrix2::identity() * sigma))
            .collect();
        let d_minus = |r: usize, c: usize| {
            j[(vel(r / 2) + r % 2, vel(c / 2) + c % 2)] - if r == c { sigma } else { 0.0 }
        };
        let schur = DMatrix::from_fn(2 * n, 2 * n, |r, c| {
            let (link, col) = (c / 2, c % 2);
            let dk: f64 = (0..2).map(|m| d_minus(r, 2 * link + m) * k[link][(m, col)]).sum();
            j[(vel(r / 2) + r % 2, pos(link) + col)] - dk
        });
        let lu = schur.lu();
        if lu.is_invertible() {
            solver = Some((lu, inverses, k));
            break;
        }
        sigma *= 1.618;
    }
    let Some((lu, inverses, k)) = solver else { return Err(Error::NotPositiveDefinite) };
    let d_minus = DMatrix::from_fn(2 * n, 2 * n, |r, c| {
        j[(vel(r / 2) + r % 2, vel(c / 2) + c % 2)] - if r == c { sigma } else { 0.0 }
    });
    let mut apply = |b: &[f64], out: &mut [f64]| {
        // y_i = B_i⁻¹ b1_i, r = b2 − (D − σ) y, p = S⁻¹ r, v_i = y_i − K_i p_i.
        let y = DVector::from_fn(2 * n, |r, _| {
            let i = r / 2;
            inverses[i][(r % 2, 0)] * b[pos(i)] + inverses[i][(r % 2, 1)] * b[pos(i) + 1]
        });
        let b2 = DVector::from_fn(2 * n, |r, _| b[vel(r / 2) + r % 2]);
        let p = lu.solve(&(b2 - &d_minus * &y)).unwrap_or_else(|| DVector::from_element(2 * n, f64::NAN));
        for i in 0..n {
            for m in 0..2 {
                out[pos(i) + m] = p[2 * i + m];
                out[vel(i) + m] = y[2 * i + m] - k[i][(m, 0)] * p[2 * i] - k[i][(m, 1)] * p[2 * i + 1];
            }
        }
    };
    let dim = 4 * n;
    let mut arnoldi = Arnoldi::new(dim);
    let mut steps = 32.min(dim);
    let shift = Complex::new(sigma, 0.0);
    loop {
        arnoldi.extend(steps - arnoldi.steps(), &mut apply);
        if arnoldi.broken() {
            return relative_spectrum(model, eq);
        }
        let complete = arnoldi.complete();
        let ritz = arnoldi.ritz(CONVERGED, |_| complete);
        let mut found: Vec<Complex<f64>> = ritz
            .iter()
            .take_while(|r| complete || r.residual <= CONVERGED)
            .map(|r| shift + r.value.inv())
            .collect();
        found.sort_by(|a, b| a.norm().total_cmp(&b.norm()));
        let beyond = found.last().is_some_and(|z| z.norm() > radius);
        if complete || (beyond && found.len() >= 16.min(dim)) {
            return Ok(found);
        }
        steps = (steps + 16 + steps / 2).min(dim);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::stability::stability_dense;
    use crate::analysis::steady_branches::SteadyRotation;
    use crate::chain::Chain;
    use nalgebra::Dyn;

    fn chain() -> Chain<Dyn> {
        Chain::<Dyn>::new(&[0.3, 1.1, 0.5, 0.8], &[0.25, 0.15, 0.3, 0.2], 9.81).unwrap()
    }

    #[test]
    fn undamped_equilibria_are_the_planar_steady_shapes_with_the_same_spectrum() {
        let (radius, omega) = (0.03, 9.0);
        let problem = SteadyRotation::new(&chain(), radius).unwrap();
        let shape = problem.solve(omega, &DVector::from_element(4, 0.9)).unwrap();
        let model = Directions::<U3>::new(chain()).with_drive(Circle::new(radius, omega).unwrap());
        let guess: Vec<(f64, f64)> = shape.theta.iter().map(|&t| (t + 0.05, 0.02)).collect();
        let eq = relative_equilibrium(&model, &guess).unwrap();
        for (i, &(t, p)) in eq.angles.iter().enumerate() {
            assert!((t - shape.theta[i]).abs() < 1e-9 && p.abs() < 1e-9, "link {i}: ({t}, {p})");
        }
        // The Directions model's spectrum and the analytic rotating-frame one agree to
        // round-off.
        let ours = stability_dense(&problem, &shape, None).unwrap().eigenvalues;
        let theirs = relative_spectrum(&model, &eq).unwrap();
        let scale = ours.last().unwrap().norm();
        let mut worst = 0.0f64;
        for z in &ours {
            let d = theirs.iter().map(|w| (w - z).norm()).fold(f64::INFINITY, f64::min);
            // The central differences the spectrum used before needed a bound of 1e-5.
            assert!(d < 1e-11 * scale, "eigenvalue {z}: nearest {d:e}");
            worst = worst.max(d / scale);
        }
        // The figure of docs/derivatives.md: `cargo test -p pendulum-core --lib
        // relative_equilibrium -- --nocapture`.
        println!("relative_spectrum against stability: {worst:.1e} of the spectrum's scale");
    }

    #[test]
    fn damping_makes_the_shape_lag_and_decay() {
        let (radius, omega) = (0.03, 9.0);
        let c = chain().with_damping(&[0.002; 4]).unwrap();
        let model = Directions::<U3>::new(c).with_drive(Circle::new(radius, omega).unwrap());
        let problem = SteadyRotation::new(&chain(), radius).unwrap();
        let shape = problem.solve(omega, &DVector::from_element(4, 0.9)).unwrap();
        let guess: Vec<(f64, f64)> = shape.theta.iter().map(|&t| (t, 0.0)).collect();
        let eq = relative_equilibrium(&model, &guess).unwrap();
        // Drag against the rotation (+y direction of motion at x > 0) tilts links to −y
        // (u_y = sin ψ < 0), by a small angle, and leaves the in-plane shape near the
        // undamped one.
        println!("out-of-plane tilts ψ_i: {:?}", eq.angles.iter().map(|a| a.1).collect::<Vec<_>>());
        assert!(eq.angles.iter().all(|&(_, p)| p < 0.0 && p > -0.1), "{:?}", eq.angles);
        for (&(t, _), undamped) in eq.angles.iter().zip(shape.theta.iter()) {
            assert!((t - undamped).abs() < 0.05, "θ {t} against undamped {undamped}");
        }
        let spectrum = relative_spectrum(&model, &eq).unwrap();
        let growth = spectrum.iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max);
        // The in-phase one-node shape stays stable: every mode now decays.
        assert!(growth < 0.0, "growth {growth}");
    }

    #[test]
    fn the_eigenvalues_near_the_origin_are_those_of_the_whole_spectrum_and_hold_the_growth() {
        // Damped and undamped, the stable in-phase shape and the saddle against the pivot
        // (a real growing eigenvalue), slow and fast: the near-origin route finds the
        // dense spectrum's eigenvalues within its radius and the same growth rate.
        let mut checked = 0;
        for (damping, omega, side) in
            [(0.0, 9.0, 0.9), (0.002, 9.0, 0.9), (0.002, 9.0, -1.0), (0.01, 4.0, 0.5), (0.0, 12.0, -1.0)]
        {
            let radius = 0.03;
            let c = chain().with_damping(&[damping; 4]).unwrap();
            let model = Directions::<U3>::new(c).with_drive(Circle::new(radius, omega).unwrap());
            let problem = SteadyRotation::new(&chain(), radius).unwrap();
            let Ok(shape) = problem.solve(omega, &DVector::from_element(4, side)) else { continue };
            let guess: Vec<(f64, f64)> = shape.theta.iter().map(|&t| (t, 0.0)).collect();
            let eq = relative_equilibrium(&model, &guess).unwrap();
            let all = relative_spectrum(&model, &eq).unwrap();
            let near = relative_spectrum_near_origin(&model, &eq).unwrap();
            let growth = |z: &[Complex<f64>]| z.iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max);
            let scale = all.iter().map(|z| z.norm()).fold(0.0, f64::max);
            for z in &near {
                let d = all.iter().map(|w| (w - z).norm()).fold(f64::INFINITY, f64::min);
                assert!(d < 1e-9 * scale, "{z}: nearest {d:e}");
            }
            assert!(
                (growth(&near) - growth(&all)).abs() < 1e-8,
                "λ = {damping}, ω = {omega}: {} {}",
                growth(&near),
                growth(&all)
            );
            println!(
                "λ = {damping}, ω = {omega}, side {side}: growth {:.4e} ({} of {} eigenvalues)",
                growth(&near),
                near.len(),
                all.len()
            );
            checked += 1;
        }
        assert!(checked >= 4, "{checked}");
    }

    #[test]
    fn bad_guess_is_named() {
        let model = Directions::<U3>::new(chain()).with_drive(Circle::new(0.01, 3.0).unwrap());
        assert!(matches!(
            relative_equilibrium(&model, &[(0.0, 0.0)]),
            Err(Error::LengthMismatch { what: "guess", expected: 4, got: 1 })
        ));
        assert!(matches!(
            relative_equilibrium(&model, &[(0.0, f64::NAN), (0.0, 0.0), (0.0, 0.0), (0.0, 0.0)]),
            Err(Error::NonFinite { what: "guess", index: 1, .. })
        ));
    }
}
