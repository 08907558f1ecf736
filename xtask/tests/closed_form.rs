//! The closed-form double pendulum (`xtask/src/closed_form.rs`, eq 50 corrected) against
//! the generic model, and its parameter checks. Here rather than in a test module of that
//! file, which `pendulum-core/benches/models.rs` also compiles.

use nalgebra::{DVector, Dyn};
use pendulum_core::{Chain, Model, Planar};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use xtask::closed_form::DoublePendulum;

/// Eq 50 (corrected) agrees with the generic `Planar<Dyn>` to round-off at random
/// states; each component's error is measured against its round-off scale, the sum
/// of the magnitudes of the numerator's terms over the denominator.
#[test]
fn matches_the_generic_model_to_round_off() {
    let mut rng = ChaCha8Rng::seed_from_u64(50);
    for _ in 0..500 {
        let [m1, m2, l1, l2]: [f64; 4] = std::array::from_fn(|_| 10f64.powf(rng.random_range(-1.0..1.0)));
        let g = rng.random_range(0.0..20.0);
        let q = [rng.random_range(-3.2..3.2), rng.random_range(-3.2..3.2)];
        let qd = [rng.random_range(-10.0..10.0), rng.random_range(-10.0..10.0)];
        let closed = DoublePendulum::new(m1, m2, l1, l2, g).unwrap().accelerations(q, qd);

        let generic = Planar::new(Chain::<Dyn>::new(&[m1, m2], &[l1, l2], g).unwrap());
        let mut a = DVector::zeros(2);
        generic
            .accelerations(
                &DVector::from_row_slice(&q),
                &DVector::from_row_slice(&qd),
                &generic.zero_inputs(),
                &mut a,
            )
            .unwrap();

        let (m, l, g) = (m2 / (m1 + m2), l2 / l1, g / l1);
        let c = (q[0] - q[1]).cos();
        let den = 1.0 - m * c * c;
        let terms = m * l * qd[1] * qd[1] + g + m * (qd[0] * qd[0] + g);
        let scale = [terms / den, terms / (l * den)];
        for i in 0..2 {
            let error = (closed[i] - a[i]).abs() / scale[i];
            assert!(
                error < 1e-12,
                "θ̈{}: closed {} vs generic {} (relative to scale {error:e})",
                i + 1,
                closed[i],
                a[i]
            );
        }
    }
}

#[test]
fn bad_parameters_are_errors_naming_the_value() {
    let err = DoublePendulum::new(1.0, -2.0, 1.0, 1.0, 9.81).unwrap_err();
    assert!(err.to_string().contains("m2 = -2"), "{err}");
    let err = DoublePendulum::new(1.0, 2.0, 1.0, 1.0, f64::NAN).unwrap_err();
    assert!(err.to_string().contains("g = NaN"), "{err}");
}
