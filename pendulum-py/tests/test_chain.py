"""Chain and its models on numpy arrays: against an independent numpy computation of the
double pendulum, against the models' own identities, batched and one state at a time, and
with bad input."""

import math
import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import pendulum

G = 9.81


def double_pendulum(m1, m2, l1, l2, g, th1, th2, w1, w2):
    """θ̈ of the textbook double pendulum (angles from the downward vertical), solved from
    its 2×2 mass matrix with numpy: an independent derivation of the planar equations."""
    d = th1 - th2
    mass = np.array([[(m1 + m2) * l1**2, m2 * l1 * l2 * math.cos(d)], [m2 * l1 * l2 * math.cos(d), m2 * l2**2]])
    force = np.array(
        [
            -m2 * l1 * l2 * w2**2 * math.sin(d) - (m1 + m2) * g * l1 * math.sin(th1),
            m2 * l1 * l2 * w1**2 * math.sin(d) - m2 * g * l2 * math.sin(th2),
        ]
    )
    return np.linalg.solve(mass, force)


positive = st.floats(0.1, 3.0)
angle = st.floats(-3.0, 3.0)
rate = st.floats(-5.0, 5.0)


@settings(max_examples=200, deadline=None)
@given(positive, positive, positive, positive, angle, angle, rate, rate)
def test_the_double_pendulum_agrees_with_an_independent_numpy_derivation(m1, m2, l1, l2, a, b, wa, wb):
    chain = pendulum.Chain([m1, m2], [l1, l2], gravity=G)
    qdd = chain.accelerations([a, b], [wa, wb])
    expected = double_pendulum(m1, m2, l1, l2, G, a, b, wa, wb)
    assert np.allclose(qdd, expected, rtol=1e-9, atol=1e-9), (qdd, expected)


@settings(max_examples=50, deadline=None)
@given(st.integers(1, 12), st.integers(0, 2**32 - 1))
def test_the_equation_of_motion_holds_with_the_terms_it_returns(n, seed):
    rng = np.random.default_rng(seed)
    chain = pendulum.Chain(rng.uniform(0.1, 2.0, n), rng.uniform(0.1, 1.0, n), damping=rng.uniform(0, 0.1, n))
    for model, dof, space in [("planar", n, 2), ("spatial", 2 * n, 3)]:
        q = rng.uniform(0.3, 2.8, dof) if model == "spatial" else rng.uniform(-3, 3, dof)
        qd, torque, pivot = rng.normal(size=dof), rng.normal(size=dof), rng.normal(size=space)
        t = chain.terms(q, qd, torque, pivot, model=model)
        m = t["mass_matrix"]
        assert np.allclose(m, m.T, atol=1e-12)
        lhs = m @ t["accelerations"] + t["velocity_terms"] + t["gravity_terms"] + t["pivot_terms"]
        assert np.allclose(lhs, t["generalized_forces"], atol=1e-9 * (1 + np.abs(lhs).max()))
        kinetic, potential = chain.energy(q, qd, model=model)
        assert math.isclose(float(kinetic), t["kinetic_energy"], rel_tol=1e-12)
        assert math.isclose(float(potential), t["potential_energy"], rel_tol=1e-12, abs_tol=1e-12)
        assert math.isclose(t["kinetic_energy"], 0.5 * qd @ m @ qd, rel_tol=1e-9)


def test_a_batch_along_leading_axes_is_the_states_one_at_a_time():
    rng = np.random.default_rng(1)
    chain = pendulum.Chain([0.1] * 8, [0.1] * 8, damping=0.01)
    q, qd = rng.uniform(-2, 2, (3, 5, 8)), rng.normal(size=(3, 5, 8))
    # Many states go through the batch of chains (four or eight per SIMD register): still the
    # states one at a time, bit for bit, torques on some and none on others.
    torque = rng.normal(size=(3, 5, 8))
    torque[1] = 0.0
    batch = chain.accelerations(q, qd, torque)
    assert batch.shape == (3, 5, 8)
    for i in range(3):
        for j in range(5):
            assert np.array_equal(batch[i, j], chain.accelerations(q[i, j], qd[i, j], torque[i, j]))
    qdd, dq, dqd = chain.jacobians(q, qd)
    assert (qdd.shape, dq.shape, dqd.shape) == ((3, 5, 8), (3, 5, 8, 8), (3, 5, 8, 8))
    # The Jacobians go through the batch too (in SIMD lanes): each state's own, bit for bit,
    # and q̈ is `accelerations`' q̈.
    pivot = rng.normal(size=(3, 5, 2))
    qdd, dq, dqd = chain.jacobians(q, qd, torque, pivot_acceleration=pivot)
    assert np.array_equal(qdd, chain.accelerations(q, qd, torque, pivot_acceleration=pivot))
    for i in range(3):
        for j in range(5):
            one = chain.jacobians(q[i, j], qd[i, j], torque[i, j], pivot_acceleration=pivot[i, j])
            for many, alone in zip((qdd, dq, dqd), one):
                assert np.array_equal(many[i, j], alone)
    # Pivots accelerating, and the same error for a bad state.
    pivot = rng.normal(size=(3, 5, 2))
    batch = chain.accelerations(q, qd, pivot_acceleration=pivot)
    for i in range(3):
        for j in range(5):
            one = chain.accelerations(q[i, j], qd[i, j], pivot_acceleration=pivot[i, j])
            assert np.array_equal(batch[i, j], one)
    q[2, 1, 3] = np.nan
    with pytest.raises(ValueError) as many:
        chain.accelerations(q, qd)
    with pytest.raises(ValueError) as one:
        chain.accelerations(q[2, 1], qd[2, 1])
    assert str(many.value) == str(one.value) == "q: NaN is not finite"


def test_single_precision_is_the_double_precision_batch_to_its_documented_error():
    # precision="float32": eight states per SIMD register in f32, within 1e-5 of the largest
    # acceleration of each state (docs/ensembles.md), shaped like q, float32.
    rng = np.random.default_rng(11)
    n = 12
    chain = pendulum.Chain(rng.uniform(0.01, 0.1, n), rng.uniform(0.01, 0.1, n), damping=rng.uniform(1e-4, 1e-3, n))
    q, qd = rng.uniform(-3, 3, (4, 25, n)), rng.uniform(-5, 5, (4, 25, n))
    pivot = rng.uniform(-30, 30, (4, 25, 2))
    double = chain.accelerations(q, qd, pivot_acceleration=pivot)
    single = chain.accelerations(q, qd, pivot_acceleration=pivot, precision="float32")
    assert single.dtype == np.float32 and single.shape == double.shape == (4, 25, n)
    error = np.max(np.abs(single - double), axis=-1) / np.max(np.abs(double), axis=-1)
    assert 0 < error.max() < 1e-5
    one = chain.accelerations(q[1, 2], qd[1, 2], pivot_acceleration=pivot[1, 2], precision="float32")
    assert one.dtype == np.float32 and np.array_equal(one, single[1, 2])
    # A (B, n) table, float32 or float64, is read in one pass: the same numbers.
    table = chain.accelerations(q[0], qd[0], precision="float32")
    narrow = chain.accelerations(q[0].astype(np.float32), qd[0].astype(np.float32), precision="float32")
    general = chain.accelerations(q[0], qd[0], pivot_acceleration=np.zeros(2), precision="float32")
    assert table.dtype == np.float32 and np.array_equal(table, narrow) and np.array_equal(table, general)
    # Joint torques too, as float64 takes them.
    torque = rng.uniform(-1e-3, 1e-3, (4, 25, n))
    double = chain.accelerations(q, qd, torque, pivot_acceleration=pivot)
    single = chain.accelerations(q, qd, torque, pivot_acceleration=pivot, precision="float32")
    error = np.max(np.abs(single - double), axis=-1) / np.max(np.abs(double), axis=-1)
    assert 0 < error.max() < 1e-5
    one = chain.accelerations(q[3, 7], qd[3, 7], torque[3, 7], pivot_acceleration=pivot[3, 7], precision="float32")
    assert np.array_equal(one, single[3, 7])
    for call, message in [
        (lambda: chain.accelerations(q, qd, precision="float16"), "precision: 'float16' is neither"),
        (lambda: chain.accelerations(np.zeros(2 * n), precision="float32", model="spatial"), "model='planar' only"),
        (lambda: chain.accelerations(q[0], qd[0], np.ones((3, n)), precision="float32"), "torque"),
        (lambda: chain.accelerations(q[0], qd[0] * 1e20, precision="float32"), "not finite in single precision"),
        (lambda: chain.accelerations(q[0] * 1e40, precision="float32"), "not finite in single precision"),
        (lambda: chain.accelerations(np.full((3, n), np.inf, np.float32), precision="float32"), "q: inf is not finite"),
    ]:
        with pytest.raises(ValueError, match=message):
            call()


def test_a_contiguous_table_of_planar_states_is_read_in_place_with_the_same_numbers():
    # A (B, n) C-contiguous float64 table without torques or pivot acceleration is read
    # where numpy holds it; any other layout takes the general path: the same numbers.
    rng = np.random.default_rng(3)
    chain = pendulum.Chain(rng.uniform(0.1, 1, 6), rng.uniform(0.1, 1, 6), damping=0.02)
    q, qd = rng.uniform(-3, 3, (37, 6)), rng.normal(size=(37, 6))
    fast = chain.accelerations(q, qd)
    assert fast.shape == (37, 6) and fast.flags["C_CONTIGUOUS"]
    for k in range(37):
        assert np.array_equal(fast[k], chain.accelerations(q[k], qd[k]))
    assert np.array_equal(chain.accelerations(np.asfortranarray(q), qd), fast)
    assert np.array_equal(chain.accelerations(q, np.asfortranarray(qd)), fast)
    assert np.array_equal(chain.accelerations(q[None], qd[None])[0], fast)
    # Fortran order on the general path too (it once read such arrays in memory order).
    torque = np.ones(6)
    assert np.array_equal(chain.accelerations(np.asfortranarray(q[None]), qd[None], torque)[0],
                          chain.accelerations(q, qd, torque))
    assert np.array_equal(chain.accelerations(q), chain.accelerations(q, np.zeros_like(q)))
    assert np.array_equal(chain.accelerations(q.tolist(), qd.tolist()), fast)
    q[20, 2] = np.inf
    with pytest.raises(ValueError, match="q: inf is not finite"):
        chain.accelerations(q, qd)
    with pytest.raises(ValueError, match="the last axis has 5 entries, expected 6"):
        chain.accelerations(q[:, :5], qd[:, :5])


def test_single_precision_jacobians_are_the_double_precision_ones_to_their_documented_error():
    # precision="float32": the planar batch's Jacobians in f32 lanes, within a few parts per
    # million of each state's largest entry (docs/ensembles.md), float32, shaped like q.
    rng = np.random.default_rng(12)
    n = 10
    chain = pendulum.Chain(rng.uniform(0.01, 0.1, n), rng.uniform(0.01, 0.1, n), damping=rng.uniform(1e-4, 1e-3, n))
    q, qd, pivot = rng.uniform(-3, 3, (4, 25, n)), rng.uniform(-5, 5, (4, 25, n)), rng.uniform(-30, 30, (4, 25, 2))
    torque = rng.uniform(-1e-3, 1e-3, (4, 25, n))
    for tau in (None, torque):
        doubles = chain.jacobians(q, qd, tau, pivot_acceleration=pivot)
        singles = chain.jacobians(q, qd, tau, pivot_acceleration=pivot, precision="float32")
        for double, single, axes in zip(doubles, singles, [(-1,), (-2, -1), (-2, -1)]):
            assert single.dtype == np.float32 and single.shape == double.shape
            scale = np.abs(double).max(axis=axes, keepdims=True)
            assert (np.abs(single - double) / scale).max() < 2e-5
        tau_one = None if tau is None else tau[1, 2]
        one = chain.jacobians(q[1, 2], qd[1, 2], tau_one, pivot_acceleration=pivot[1, 2], precision="float32")
        for many, alone in zip(singles, one):
            assert np.array_equal(many[1, 2], alone)
    with pytest.raises(ValueError, match="serve model='planar' and 'directions' only"):
        chain.jacobians(q[..., :n], precision="float32", model="spatial")
    with pytest.raises(ValueError, match="float16"):
        chain.jacobians(q, precision="float16")


def test_the_analytic_jacobians_are_the_slopes_of_the_accelerations():
    rng = np.random.default_rng(2)
    chain = pendulum.Chain(rng.uniform(0.2, 1, 5), rng.uniform(0.2, 1, 5), damping=0.05)
    q, qd = rng.uniform(-2, 2, 5), rng.normal(size=5)
    _, dq, dqd = chain.jacobians(q, qd)
    eps = 1e-6
    for k in range(5):
        e = np.zeros(5)
        e[k] = eps
        fd_q = (chain.accelerations(q + e, qd) - chain.accelerations(q - e, qd)) / (2 * eps)
        fd_qd = (chain.accelerations(q, qd + e) - chain.accelerations(q, qd - e)) / (2 * eps)
        assert np.allclose(dq[:, k], fd_q, rtol=1e-6, atol=1e-6)
        assert np.allclose(dqd[:, k], fd_qd, rtol=1e-6, atol=1e-6)


def test_one_link_is_the_simple_pendulum():
    chain = pendulum.Chain(2.0, 0.5)
    assert math.isclose(float(chain.accelerations([0.3])[0]), -G / 0.5 * math.sin(0.3), rel_tol=1e-14)
    frequencies, shapes = chain.modes()
    assert math.isclose(frequencies[0], math.sqrt(G / 0.5), rel_tol=1e-12)
    assert shapes.shape == (1, 1)
    lin = chain.linearize([0.0])
    assert np.allclose(sorted(lin["eigenvalues"].imag), [-math.sqrt(G / 0.5), math.sqrt(G / 0.5)])
    upright = chain.linearize([math.pi])
    assert math.isclose(upright["eigenvalues"][0].real, math.sqrt(G / 0.5), rel_tol=1e-9)


def test_chains_pickle_and_compare():
    chain = pendulum.Chain([1.0, 2.0], [0.5, 0.25], gravity=3.7, damping=[0.1, 0.0])
    again = pickle.loads(pickle.dumps(chain))
    assert again == chain and again.n == 2 and again.gravity == 3.7
    assert np.array_equal(again.damping, [0.1, 0.0])
    assert "n=2" in repr(chain)


def rk4_step(chain, q, qd, h):
    """One classical RK4 step of the free planar chain written with numpy around
    ``Chain.accelerations``, in the order of ``x + a k`` and ``h/6 (k1 + 2 (k2 + k3) + k4)``."""
    x = np.concatenate([q, qd], axis=-1)
    n = chain.n

    def f(x):
        return np.concatenate([x[..., n:], chain.accelerations(x[..., :n], x[..., n:])], axis=-1)

    k1 = f(x)
    k2 = f(0.5 * h * k1 + x)
    k3 = f(0.5 * h * k2 + x)
    k4 = f(h * k3 + x)
    x = x + h / 6.0 * (k1 + 2.0 * (k2 + k3) + k4)
    return x[..., :n], x[..., n:]


def test_integrate_steps_many_states_each_as_rk4_around_the_model_would():
    rng = np.random.default_rng(8)
    chain = pendulum.Chain(rng.uniform(0.1, 1.0, 7), rng.uniform(0.1, 1.0, 7), damping=0.01)
    q, qd = rng.uniform(-2, 2, (3, 5, 7)), rng.uniform(-1, 1, (3, 5, 7))
    q1, qd1 = chain.integrate(q, qd, h=1e-3)
    assert q1.shape == qd1.shape == (3, 5, 7)
    # Bit for bit: a numpy RK4 step around the model, and each state alone.
    expected = rk4_step(chain, q, qd, 1e-3)
    np.testing.assert_array_equal(q1, expected[0])
    np.testing.assert_array_equal(qd1, expected[1])
    alone = chain.integrate(q[1, 2], qd[1, 2], h=1e-3, steps=40)
    many = chain.integrate(q, qd, h=1e-3, steps=40)
    np.testing.assert_array_equal(many[0][1, 2], alone[0])
    np.testing.assert_array_equal(many[1][1, 2], alone[1])
    # Without rates: from rest.
    np.testing.assert_array_equal(chain.integrate(q, h=1e-3)[0], chain.integrate(q, np.zeros_like(q), h=1e-3)[0])


def test_integrate_holds_torques_and_pivot_accelerations_over_the_call():
    rng = np.random.default_rng(9)
    chain = pendulum.Chain(rng.uniform(0.1, 1.0, 5), rng.uniform(0.1, 1.0, 5), damping=0.02)
    q, qd = rng.uniform(-2, 2, (6, 5)), rng.uniform(-1, 1, (6, 5))
    torque, pivot = rng.normal(size=(6, 5)), rng.normal(size=(6, 2))
    torque[2] = 0.0

    def f(x):
        n = chain.n
        return np.concatenate([x[:, n:], chain.accelerations(x[:, :n], x[:, n:], torque, pivot)], axis=-1)

    x = np.concatenate([q, qd], axis=-1)
    h = 2e-3
    k1 = f(x)
    k2 = f(0.5 * h * k1 + x)
    k3 = f(0.5 * h * k2 + x)
    k4 = f(h * k3 + x)
    x = x + h / 6.0 * (k1 + 2.0 * (k2 + k3) + k4)
    q1, qd1 = chain.integrate(q, qd, torque, pivot, h=h)
    np.testing.assert_array_equal(q1, x[:, :5])
    np.testing.assert_array_equal(qd1, x[:, 5:])
    # One link: a torque m g l sin θ0 holds it at θ0; a pivot accelerating sideways at a
    # holds it at rest at tan θ = −a/g. Both stay put.
    one = pendulum.Chain(0.3, 0.5)
    held, _ = one.integrate([0.7], [0.0], [0.3 * G * 0.5 * math.sin(0.7)], h=1e-3, steps=1000)
    assert abs(held[0] - 0.7) < 1e-12
    lag = math.atan(-2.0 / G)
    tilted, _ = one.integrate([lag], [0.0], pivot_acceleration=[2.0, 0.0], h=1e-3, steps=1000)
    assert abs(tilted[0] - lag) < 1e-12


def test_integrate_in_single_precision_is_the_double_precision_run_to_its_documented_error():
    rng = np.random.default_rng(12)
    chain = pendulum.Chain(rng.uniform(0.01, 0.02, 8), rng.uniform(0.01, 0.02, 8), damping=3e-4)
    q, qd = rng.uniform(-1, 1, (300, 8)), rng.uniform(-1, 1, (300, 8))
    torque = rng.normal(scale=1e-4, size=(300, 8))
    q64, qd64 = chain.integrate(q, qd, torque, h=1e-4, steps=200)
    q32, qd32 = chain.integrate(q, qd, torque, h=1e-4, steps=200, precision="float32")
    assert q32.dtype == qd32.dtype == np.float32 and q32.shape == (300, 8)
    scale = np.maximum(np.abs(q64).max(axis=-1), np.abs(qd64).max(axis=-1))[:, None]
    error = max(np.abs(q32 - q64).max(), (np.abs(qd32 - qd64) / scale).max())
    assert error < 5e-6, error
    # 300 states × 200 steps run in chunks, one state alone in one: the same numbers (the
    # rounding compensation goes from chunk to chunk).
    alone = chain.integrate(q[17], qd[17], torque[17], h=1e-4, steps=200, precision="float32")
    assert np.array_equal(alone[0], q32[17]) and np.array_equal(alone[1], qd32[17])
    with pytest.raises(ValueError, match="single precision"):
        chain.integrate(q, qd, np.full(8, 1e39), h=1e-4, precision="float32")


def lqr_gain(a, b):
    """The LQR gain for Q = I, R = I from the stable invariant subspace of the Hamiltonian
    matrix (numpy only): u = −K x."""
    n = a.shape[0]
    hamiltonian = np.block([[a, -b @ b.T], [-np.eye(n), -a.T]])
    values, vectors = np.linalg.eig(hamiltonian)
    stable = vectors[:, values.real < 0]
    riccati = np.real(stable[n:] @ np.linalg.inv(stable[:n]))
    return b.T @ riccati


def test_a_controller_holds_many_inverted_double_pendulums_upright_through_integrate():
    # docs/python.md's control loop: torques held over each 10 ms, 64 copies per call.
    chain = pendulum.Chain([0.5, 0.4], [0.4, 0.35], damping=1e-3)
    up = np.full(2, np.pi)
    linear = chain.linearize(up)
    gain = lqr_gain(linear["A"], linear["B_torque"])
    slowest = np.linalg.eigvals(linear["A"] - linear["B_torque"] @ gain).real.max()
    assert slowest < 0
    rng = np.random.default_rng(0)
    q, qd = up + rng.uniform(-0.05, 0.05, (64, 2)), rng.uniform(-0.1, 0.1, (64, 2))
    fallen, _ = chain.integrate(q, qd, h=1e-3, steps=2000)
    assert np.all(np.abs(fallen - up).max(axis=-1) > 0.5)
    for _ in range(500):
        torque = -np.concatenate([q - up, qd], axis=-1) @ gain.T
        q, qd = chain.integrate(q, qd, torque, h=1e-3, steps=10)
    distance = np.abs(np.concatenate([q - up, qd], axis=-1)).max()
    assert distance < 0.5 * math.exp(slowest * 5.0), (distance, slowest)


def test_integrate_keeps_the_energy_of_an_undamped_chain_and_the_period_of_a_small_swing():
    chain = pendulum.Chain([0.3, 0.2, 0.5], [0.4, 0.3, 0.2])
    q, qd = np.array([1.0, -0.5, 2.0]), np.array([0.0, 1.0, -1.0])
    q1, qd1 = chain.integrate(q, qd, h=1e-4, steps=20_000)
    before, after = sum(chain.energy(q, qd)), sum(chain.energy(q1, qd1))
    assert abs(after - before) < 1e-9 * abs(before)
    # One link, 1e-4 rad: after one period 2π √(l/g) it is back where it started.
    one = pendulum.Chain(1.0, 0.5)
    period = 2 * math.pi * math.sqrt(0.5 / G)
    steps = 10_000
    q1, qd1 = one.integrate([1e-4], [0.0], h=period / steps, steps=steps)
    assert abs(q1[0] - 1e-4) < 1e-11 and abs(qd1[0]) < 1e-10


def test_a_trajectory_samples_the_run_that_integrate_ends_with():
    rng = np.random.default_rng(5)
    chain = pendulum.Chain(rng.uniform(0.1, 1.0, 4), rng.uniform(0.1, 1.0, 4), damping=0.01)
    q, qd = rng.uniform(-2, 2, (3, 2, 4)), rng.uniform(-1, 1, (3, 2, 4))
    for precision in ["float64", "float32"]:
        t, qs, qds = chain.trajectory(q, qd, h=1e-3, steps=250, every=100, precision=precision)
        np.testing.assert_array_equal(t, [0.0, 0.1, 0.2, 0.25])
        assert qs.shape == qds.shape == (4, 3, 2, 4)
        np.testing.assert_array_equal(qs[0], q.astype(qs.dtype))
        end = chain.integrate(q, qd, h=1e-3, steps=250, precision=precision)
        np.testing.assert_array_equal(qs[-1], end[0])
        np.testing.assert_array_equal(qds[-1], end[1])
        # A sample is the run up to it.
        middle = chain.integrate(q, qd, h=1e-3, steps=200, precision=precision)
        np.testing.assert_array_equal(qs[2], middle[0])
    # A small swing of one link: θ₀ cos ωt at every sample.
    one = pendulum.Chain(1.0, 0.5)
    omega = math.sqrt(G / 0.5)
    t, qs, _ = one.trajectory([1e-4], h=1e-3, steps=3000, every=10)
    np.testing.assert_allclose(qs[:, 0], 1e-4 * np.cos(omega * t), rtol=0, atol=1e-11)
    with pytest.raises(ValueError, match="every: 0 is not a number of steps"):
        one.trajectory([0.1], h=1e-3, steps=10, every=0)


def test_a_state_that_blows_up_in_integrate_is_named():
    chain = pendulum.Chain(0.01, [0.01] * 4)
    qd = np.zeros((2, 3, 4))
    qd[1, 0] = 1e150
    message = r"integrate: state \(1, 0\): the step from t = 0 s with h = 0.001 s produced a non-finite state"
    with pytest.raises(RuntimeError, match=message):
        chain.integrate(np.full((2, 3, 4), 0.4), qd, h=1e-3, steps=10)


def test_a_failing_state_of_many_is_named_by_its_index():
    # Each route of accelerations and Jacobians over many states: the error names the
    # state as numpy indexes it; a call on one state gives the error alone.
    chain = pendulum.Chain([1.0] * 4, 0.25)
    q = np.random.default_rng(5).uniform(0.2, 1.0, (5, 8))
    q[2, 1] = 0.0                                                 # link 2 of state 2 vertical
    singular = r"^state 2: link 2 sits at the spherical-angle singularity"
    with pytest.raises(ValueError, match=singular):
        chain.accelerations(q, model="spatial")
    with pytest.raises(ValueError, match=singular):
        chain.jacobians(q, model="spatial")
    with pytest.raises(ValueError, match=r"^state \(1, 0\): link 2 sits"):
        chain.accelerations(q[[1, 3, 4, 2, 0, 1]].reshape(2, 3, 8), model="spatial")
    with pytest.raises(ValueError, match=r"^link 2 sits"):
        chain.accelerations(q[2], model="spatial")
    # Planar states, through the batch of chains: q̇ = 1e200 overflows one state's solve.
    q, qd = np.full((6, 4), 0.3), np.zeros((6, 4))
    qd[3] = 1e200
    for call in [
        lambda: chain.accelerations(q, qd),                        # in place
        lambda: chain.accelerations(q, qd, np.zeros(4)),           # with torques
        lambda: chain.jacobians(q, qd),
    ]:
        with pytest.raises(ValueError, match=r"^state 3: "):
            call()
    qd30 = np.where(qd > 0, 1e30, 0.0)                             # finite in float32, not its square
    for call in [
        lambda: chain.accelerations(q, qd, precision="float32"),     # past float32's range
        lambda: chain.accelerations(q, qd, np.zeros(4), precision="float32"),
        lambda: chain.jacobians(q, qd, precision="float32"),
        lambda: chain.accelerations(q, qd30, precision="float32"),   # a float64 table
        lambda: chain.accelerations(q.astype(np.float32), qd30.astype(np.float32), precision="float32"),
        lambda: chain.jacobians(q, qd30, precision="float32"),
    ]:
        with pytest.raises(ValueError, match=r"^state 3: the accelerations are not finite in single precision"):
            call()
    # Directions.
    u, w = np.tile([0.0, 0.0, -1.0], (5, 4)), np.zeros((5, 12))
    w[4] = 1e200
    w32 = np.where(w > 0, 1e30, 0.0)                               # finite in float32, not its square
    for call in [
        lambda: chain.accelerations(u, w, model="directions"),      # in place
        lambda: chain.accelerations(u, w, None, np.zeros((5, 3)), model="directions"),
        lambda: chain.jacobians(u, w, model="directions"),
        lambda: chain.accelerations(u, w32, model="directions", precision="float32"),
        lambda: chain.jacobians(u, w32, model="directions", precision="float32"),
    ]:
        with pytest.raises(ValueError, match=r"^state 4: "):
            call()
    # A rod not of unit length: its link counted from 1, as the core's errors count them.
    stretched = np.tile([0.0, 0.0, -1.0], (2, 3, 4))
    stretched[1, 0, 3:6] *= 2.0
    with pytest.raises(ValueError, match=r"^q: link 2 of state \(1, 0\) has \|u\| = 2"):
        chain.accelerations(stretched, model="directions")


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: pendulum.Chain([1.0, -1.0], 0.5), "mass of link 2 must be finite and positive, got -1"),
        (lambda: pendulum.Chain(1.0, [0.5, 0.5, 0.5], damping=[0.1, 0.2]), "damping: got 2 values for 3 links"),
        (lambda: pendulum.Chain(1.0, [0.5, 0.5]).accelerations([0.1, 0.2, 0.3]), "q: the last axis has 3 entries, expected 2"),
        (lambda: pendulum.Chain(1.0, [0.5, 0.5]).accelerations([0.1, float("nan")]), "q: NaN is not finite"),
        (lambda: pendulum.Chain(1.0, 0.5).accelerations(0.3), "q: a scalar"),
        (lambda: pendulum.Chain(1.0, 0.5).accelerations([0.3], model="cartesian"), "model: 'cartesian'"),
        (lambda: pendulum.Chain(1.0, 0.5).accelerations(np.zeros((4, 1)), np.zeros((3, 1))), "qd: the leading shape"),
        (lambda: pendulum.Chain(1.0, 0.5).accelerations([0.0, 0.0], model="spatial"), "spherical-angle singularity"),
        (lambda: pendulum.Chain(1.0, 0.5).linearize([0.3]), "not an equilibrium"),
        (lambda: pendulum.Chain(1.0, 0.5).accelerations(["a"]), "q: not an array of numbers"),
        (lambda: pendulum.Chain(1.0, 0.5).integrate([0.3], h=0.0), "h: 0 is not a positive time step"),
        (lambda: pendulum.Chain(1.0, 0.5).integrate([0.3], h=1e-3, steps=-2), "steps: -2 is not a number of steps"),
        (lambda: pendulum.Chain(1.0, 0.5).integrate([0.3], h=1e-3, precision="half"), "precision: 'half' is neither"),
        (lambda: pendulum.Chain(1.0, 0.5).integrate([0.3], h=float("nan")), "h: NaN is not a positive time step"),
        (lambda: pendulum.Chain(1.0, 0.5).integrate([0.3, 0.1], h=1e-3, model="spatial"), "integrate: serves model='planar' and model='directions'"),
        (lambda: pendulum.Chain(1.0, [0.5, 0.5]).integrate([0.1, float("inf")], h=1e-3), "q: inf is not finite"),
    ],
)
def test_bad_input_is_a_value_error_naming_the_value(call, message):
    with pytest.raises(ValueError, match=message) as e:
        call()
    assert "\n" not in str(e.value)
