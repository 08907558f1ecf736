"""Chain's model="directions" (the 3D chain in unit link directions, through the batch of
chains): against the spherical-angle model by the chain rule, against the planar model in
a vertical plane, a pivot's acceleration as a change of gravity, batches against one state
at a time, float32 against float64, the projected RK4 run's invariants, and bad input."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import pendulum


def directions(theta, phi):
    """u_i = (sin θ cos φ, sin θ sin φ, −cos θ) and its first and second derivatives by θ and
    φ, as arrays of shape (n, 3)."""
    st_, ct, sp, cp = np.sin(theta), np.cos(theta), np.sin(phi), np.cos(phi)
    zero = np.zeros_like(theta)
    u = np.stack([st_ * cp, st_ * sp, -ct], 1)
    u_t = np.stack([ct * cp, ct * sp, st_], 1)
    u_p = np.stack([-st_ * sp, st_ * cp, zero], 1)
    u_tp = np.stack([-ct * sp, ct * cp, zero], 1)
    u_pp = np.stack([-st_ * cp, -st_ * sp, zero], 1)
    return u, u_t, u_p, -u, u_tp, u_pp


def planar_directions(theta, rate):
    """(u, u̇) of a chain in the x–z plane at angles θ from the downward vertical, flat."""
    zero = np.zeros_like(theta)
    u = np.stack([np.sin(theta), zero, -np.cos(theta)], 1)
    normal = np.stack([np.cos(theta), zero, np.sin(theta)], 1)
    return u.ravel(), (rate[:, None] * normal).ravel()


positive = st.floats(0.2, 3.0)


@settings(max_examples=100, deadline=None)
@given(
    st.lists(positive, min_size=3, max_size=3),
    st.lists(positive, min_size=3, max_size=3),
    st.floats(0.0, 0.5),
    st.integers(0, 2**32 - 1),
)
def test_directions_agree_with_the_spherical_angle_model_by_the_chain_rule(masses, lengths, damping, seed):
    # Away from the poles the spherical model is regular: ü = u_θ θ̈ + u_φ φ̈ + u_θθ θ̇² +
    # 2 u_θφ θ̇ φ̇ + u_φφ φ̇², with θ̈, φ̈ from model="spatial" (the same chain, damping and
    # pivot acceleration).
    r = np.random.default_rng(seed)
    chain = pendulum.Chain(masses, lengths, damping=damping)
    theta, phi = r.uniform(0.4, 2.7, 3), r.uniform(-3, 3, 3)
    rates = r.uniform(-2, 2, 6)
    pivot = r.uniform(-5, 5, 3)
    q = np.concatenate([theta, phi])
    qdd = chain.accelerations(q, rates, pivot_acceleration=pivot, model="spatial")
    u, u_t, u_p, u_tt, u_tp, u_pp = directions(theta, phi)
    td, pd, tdd, pdd = rates[:3, None], rates[3:, None], qdd[:3, None], qdd[3:, None]
    ud = u_t * td + u_p * pd
    expected = u_t * tdd + u_p * pdd + u_tt * td**2 + 2 * u_tp * td * pd + u_pp * pd**2
    got = chain.accelerations(u.ravel(), ud.ravel(), pivot_acceleration=pivot, model="directions")
    scale = np.max(np.abs(expected)) + 1.0
    assert np.max(np.abs(got - expected.ravel())) < 1e-9 * scale


def test_a_chain_in_a_vertical_plane_moves_as_the_planar_model_says():
    chain = pendulum.Chain([1.0, 0.5, 0.8, 0.3], [1.0, 0.7, 0.5, 0.4], damping=0.05)
    r = np.random.default_rng(4)
    theta, rate = r.uniform(-3, 3, 4), r.uniform(-3, 3, 4)
    u, ud = planar_directions(theta, rate)
    tdd = chain.accelerations(theta, rate, pivot_acceleration=[1.5, -2.0], model="planar")
    got = chain.accelerations(u, ud, pivot_acceleration=[1.5, 0.0, -2.0], model="directions").reshape(4, 3)
    normal = np.stack([np.cos(theta), np.zeros(4), np.sin(theta)], 1)
    expected = tdd[:, None] * normal - rate[:, None] ** 2 * u.reshape(4, 3)
    assert np.max(np.abs(got - expected)) < 1e-12 * np.max(np.abs(expected))


def test_a_vertical_pivot_acceleration_is_a_change_of_gravity():
    # In the pivot's frame p̈ acts as gravity g⃗ − p̈: lifting the pivot at a m/s² is gravity
    # g + a.
    masses, lengths = [0.3, 0.2, 0.4], [0.5, 0.4, 0.6]
    r = np.random.default_rng(7)
    u = r.normal(size=(3, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    w = np.cross(u, r.normal(size=(3, 3)))
    lifted = pendulum.Chain(masses, lengths, gravity=9.81).accelerations(
        u.ravel(), w.ravel(), pivot_acceleration=[0, 0, 2.5], model="directions"
    )
    heavier = pendulum.Chain(masses, lengths, gravity=12.31).accelerations(u.ravel(), w.ravel(), model="directions")
    assert np.allclose(lifted, heavier, rtol=0, atol=1e-12 * np.max(np.abs(heavier)))


def test_a_chain_hanging_at_rest_stays_there():
    chain = pendulum.Chain([0.1] * 20, 0.05)
    hanging = np.tile([0.0, 0.0, -1.0], 20)
    assert np.max(np.abs(chain.accelerations(hanging, model="directions"))) < 1e-12
    q, qd = chain.integrate(hanging, h=1e-3, steps=100, model="directions")
    assert np.max(np.abs(q - hanging)) < 1e-12 and np.max(np.abs(qd)) < 1e-10


def random_states(rng, shape, n):
    u = rng.normal(size=(*shape, n, 3))
    u /= np.linalg.norm(u, axis=-1, keepdims=True)
    w = np.cross(u, rng.normal(size=(*shape, n, 3)))
    return u.reshape(*shape, 3 * n), w.reshape(*shape, 3 * n)


def test_many_states_equal_each_state_alone_bit_for_bit():
    chain = pendulum.Chain([0.2, 0.1, 0.3, 0.2, 0.1], 0.2, damping=0.01)
    r = np.random.default_rng(11)
    u, w = random_states(r, (3, 7), 5)
    pivot = r.uniform(-3, 3, (3, 7, 3))
    many = chain.accelerations(u, w, pivot_acceleration=pivot, model="directions")
    assert many.shape == (3, 7, 15)
    for i in range(3):
        for j in range(7):
            one = chain.accelerations(u[i, j], w[i, j], pivot_acceleration=pivot[i, j], model="directions")
            assert np.array_equal(one, many[i, j])
    # One pivot row for all states is that row repeated.
    shared = chain.accelerations(u, w, pivot_acceleration=pivot[0, 0], model="directions")
    repeated = chain.accelerations(u, w, pivot_acceleration=np.broadcast_to(pivot[0, 0], pivot.shape), model="directions")
    assert np.array_equal(shared, repeated)


def test_tables_read_in_place_give_the_general_paths_numbers():
    # A C-ordered (B, 3n) table is read where numpy holds it (one model repeated, the
    # directions and rates apart): the same bits as the general path (a Fortran-ordered
    # copy, a (B, 1, 3n) array), in float64 and float32, with one pivot row for all.
    chain = pendulum.Chain([0.2, 0.1, 0.3, 0.2], 0.2, damping=0.01)
    u, w = random_states(np.random.default_rng(12), (37,), 4)
    pivot = [0.5, -1.0, 2.0]
    for precision in ["float64", "float32"]:
        table = chain.accelerations(u, w, pivot_acceleration=pivot, model="directions", precision=precision)
        fortran = chain.accelerations(
            np.asfortranarray(u), np.asfortranarray(w), pivot_acceleration=pivot, model="directions", precision=precision
        )
        lifted = chain.accelerations(u[:, None], w[:, None], pivot_acceleration=pivot, model="directions", precision=precision)
        assert table.shape == (37, 12) and np.array_equal(table, fortran) and np.array_equal(table, lifted[:, 0])
    single = chain.accelerations(u, w, model="directions", precision="float32")
    from_single = chain.accelerations(u.astype(np.float32), w.astype(np.float32), model="directions", precision="float32")
    assert from_single.dtype == np.float32 and np.array_equal(single, from_single)
    # Bad input in a table is named as the general path names it.
    bad = w.copy()
    bad[5, 7] = np.nan
    with pytest.raises(ValueError, match="qd: NaN is not finite"):
        chain.accelerations(u, bad, model="directions")
    with pytest.raises(ValueError, match="qd: NaN is not finite"):
        chain.accelerations(u, bad, model="directions", precision="float32")
    stretched = u.copy()
    stretched[9, 3:6] *= 1.5
    with pytest.raises(ValueError, match=r"link 2 of state 9 has \|u\| = 1.5"):
        chain.accelerations(stretched, w, model="directions")


def test_float32_is_within_a_few_parts_per_million_of_float64():
    chain = pendulum.Chain([0.02, 0.01, 0.03] * 4, [0.02, 0.01, 0.015] * 4, damping=1e-4)
    r = np.random.default_rng(3)
    u, w = random_states(r, (200,), 12)
    double = chain.accelerations(u, w, model="directions")
    single = chain.accelerations(u, w, model="directions", precision="float32")
    assert single.dtype == np.float32 and single.shape == double.shape
    error = np.max(np.abs(single - double), axis=1) / np.max(np.abs(double), axis=1)
    # docs/ensembles.md: below 1e-5 for spreads of masses and lengths up to 100.
    assert np.max(error) < 1e-5


def test_jacobians_match_central_differences_and_batches_match_one_state():
    # ∂ü/∂u and ∂ü/∂u̇ in the directions' own components, against central differences of
    # the accelerations (steps of 5e-7 keep every rod within the 1e-6 of unit length the
    # model takes).
    chain = pendulum.Chain([0.3, 0.2, 0.4], [0.5, 0.3, 0.4], damping=0.05)
    r = np.random.default_rng(21)
    u, w = random_states(r, (4,), 3)
    pivot = r.uniform(-3, 3, (4, 3))
    udd, du, dw = chain.jacobians(u, w, pivot_acceleration=pivot, model="directions")
    assert udd.shape == (4, 9) and du.shape == dw.shape == (4, 9, 9)
    assert np.array_equal(udd, chain.accelerations(u, w, pivot_acceleration=pivot, model="directions"))
    h = 5e-7
    worst = 0.0
    for k in range(4):
        f = lambda a, b: chain.accelerations(a, b, pivot_acceleration=pivot[k], model="directions")
        for j in range(9):
            e = np.zeros(9)
            e[j] = h
            by_u = (f(u[k] + e, w[k]) - f(u[k] - e, w[k])) / (2 * h)
            by_w = (f(u[k], w[k] + e) - f(u[k], w[k] - e)) / (2 * h)
            scale = np.max(np.abs(du[k])) + np.max(np.abs(dw[k]))
            error = max(np.max(np.abs(du[k][:, j] - by_u)), np.max(np.abs(dw[k][:, j] - by_w))) / scale
            assert error < 1e-6
            worst = max(worst, error)
        one = chain.jacobians(u[k], w[k], pivot_acceleration=pivot[k], model="directions")
        assert all(np.array_equal(a, b[k]) for a, b in zip(one, (udd, du, dw)))
    print(f"jacobians against central differences: worst {worst:.1e} of the largest entries")


def test_float32_jacobians_are_within_a_few_parts_per_million_and_each_state_is_its_own():
    # precision="float32": eight states per SIMD register in f32, within 2e-5 of each
    # state's largest entry (docs/ensembles.md), shaped like the float64 ones, float32.
    chain = pendulum.Chain([0.02, 0.01, 0.03] * 3, [0.02, 0.01, 0.015] * 3, damping=1e-4)
    r = np.random.default_rng(4)
    u, w = random_states(r, (3, 11), 9)
    pivot = r.uniform(-3, 3, (3, 11, 3))
    doubles = chain.jacobians(u, w, pivot_acceleration=pivot, model="directions")
    singles = chain.jacobians(u, w, pivot_acceleration=pivot, model="directions", precision="float32")
    for double, single, axes in zip(doubles, singles, [(-1,), (-2, -1), (-2, -1)]):
        assert single.dtype == np.float32 and single.shape == double.shape
        scale = np.abs(double).max(axis=axes, keepdims=True)
        assert (np.abs(single - double) / scale).max() < 2e-5
    one = chain.jacobians(u[2, 5], w[2, 5], pivot_acceleration=pivot[2, 5], model="directions", precision="float32")
    for many, alone in zip(singles, one):
        assert np.array_equal(many[2, 5], alone)
    with pytest.raises(ValueError, match="not finite in single precision"):
        chain.jacobians(u[0], w[0] * 1e39, model="directions", precision="float32")


def test_the_projected_run_keeps_rods_rigid_and_conserves_energy():
    chain = pendulum.Chain([0.3, 0.2, 0.25, 0.1], [0.4, 0.3, 0.35, 0.2])
    r = np.random.default_rng(5)
    u, w = random_states(r, (6,), 4)
    e0 = sum(chain.energy(u, w, model="directions"))
    q, qd = chain.integrate(u, w, h=1e-4, steps=5000, model="directions")
    e1 = sum(chain.energy(q, qd, model="directions"))
    drift = np.max(np.abs(e1 - e0) / np.abs(e0))
    print(f"energy after 5000 projected RK4 steps of 0.1 ms: {drift:.1e} relative")
    assert drift < 1e-7
    links = q.reshape(6, 4, 3)
    assert np.max(np.abs(np.linalg.norm(links, axis=-1) - 1)) < 1e-14
    assert np.max(np.abs(np.sum(links * qd.reshape(6, 4, 3), axis=-1))) < 1e-12
    # The trajectory's samples are integrate's states after as many steps, bit for bit.
    t, qs, qds = chain.trajectory(u, w, h=1e-4, steps=500, every=250, model="directions")
    assert np.allclose(t, [0.0, 0.025, 0.05]) and qs.shape == (3, 6, 12)
    q250, qd250 = chain.integrate(u, w, h=1e-4, steps=250, model="directions")
    assert np.array_equal(qs[0], u) and np.array_equal(qs[1], q250) and np.array_equal(qds[1], qd250)


def test_float32_runs_follow_float64_and_keep_rods_rigid():
    # The run of the previous test in single precision (docs/ensembles.md, "Single
    # precision"): within 1e-5 of float64 after 1000 steps, the rods of unit length and the
    # rates perpendicular to them to f32's rounding; a state alone its batch's numbers.
    chain = pendulum.Chain([0.3, 0.2, 0.25, 0.1], [0.4, 0.3, 0.35, 0.2])
    u, w = random_states(np.random.default_rng(5), (6,), 4)
    q, qd = chain.integrate(u, w, h=1e-4, steps=1000, model="directions", t0=0.2)
    q32, qd32 = chain.integrate(u.astype(np.float32), w, h=1e-4, steps=1000, model="directions", precision="float32", t0=0.2)
    assert q32.dtype == qd32.dtype == np.float32 and q32.shape == (6, 12)
    scale = np.maximum(np.abs(q).max(axis=-1), np.abs(qd).max(axis=-1))
    error = np.maximum(np.abs(q32 - q).max(axis=-1), np.abs(qd32 - qd).max(axis=-1)) / scale
    assert error.max() < 1e-5, error.max()
    links = q32.astype(np.float64).reshape(6, 4, 3)
    assert np.max(np.abs(np.linalg.norm(links, axis=-1) - 1)) < 1e-6
    alone = chain.integrate(u[4], w[4], h=1e-4, steps=1000, model="directions", precision="float32", t0=0.2)
    assert np.array_equal(alone[0], q32[4]) and np.array_equal(alone[1], qd32[4])


def test_the_rod_midpoint_keeps_a_free_chains_energy_at_a_long_step_and_each_state_is_its_own():
    # method="rod_midpoint": the implicit step, stable far past RK4's limit, keeps a free
    # undamped chain's energy to the Newton tolerance and its rods rigid exactly; many
    # states in SIMD lanes, each bit for bit itself alone, also where a state's step is
    # halved (a link turning by more than a radian).
    chain = pendulum.Chain([0.3, 0.2, 0.25, 0.1, 0.2, 0.15], [0.4, 0.3, 0.35, 0.2, 0.25, 0.3])
    r = np.random.default_rng(7)
    u, w = random_states(r, (3, 5), 6)
    w[1, 3] *= 100.0  # h |w_i| near 2 rad: its steps are halved
    e0 = sum(chain.energy(u, w, model="directions"))
    q, qd = chain.integrate(u, w, h=0.02, steps=200, model="directions", method="rod_midpoint")
    e1 = sum(chain.energy(q, qd, model="directions"))
    drift = np.max(np.abs(e1 - e0) / np.abs(e0))
    print(f"energy after 200 rod midpoint steps of 20 ms: {drift:.1e} relative")
    assert drift < 1e-10
    links = q.reshape(3, 5, 6, 3)
    assert np.max(np.abs(np.linalg.norm(links, axis=-1) - 1)) < 1e-13
    for k in [(0, 0), (1, 3), (2, 4)]:
        alone = chain.integrate(u[k], w[k], h=0.02, steps=200, model="directions", method="rod_midpoint")
        assert np.array_equal(alone[0], q[k]) and np.array_equal(alone[1], qd[k])
    # Driven, it converges to projected RK4's motion at order 2; the trajectory's samples
    # are integrate's states.
    circle = pendulum.Circle(radius=0.05, omega=4.0)
    exact, _ = chain.integrate(u[0], w[0], h=1e-4, steps=4000, model="directions", drive=circle)
    errors = []
    for steps in [400, 800]:
        t, qs, _ = chain.trajectory(u[0], w[0], h=0.4 / steps, steps=steps, every=steps // 2, model="directions", method="rod_midpoint", drive=circle)
        errors.append(np.max(np.abs(qs[2] - exact)))
    order = np.log2(errors[0] / errors[1])
    print(f"rod midpoint errors at 1 and 0.5 ms after 0.4 s: {errors[0]:.1e}, {errors[1]:.1e}; order {order:.2f}")
    assert 1.8 < order < 2.3 and errors[1] < 1e-4
    half, _ = chain.integrate(u[0], w[0], h=5e-4, steps=400, model="directions", method="rod_midpoint", drive=circle)
    assert np.allclose(t, [0.0, 0.2, 0.4]) and np.array_equal(qs[1], half)


def test_the_rod_midpoint_in_float32_follows_float64_at_long_steps():
    # precision="float32" with method="rod_midpoint": eight states per register in single
    # precision, a step the lanes cannot take whole the state's own in float64. A 20-link
    # chain whirled from hanging by 8 pivots on their own circles, 80 steps of 50 ms: it
    # follows the float64 run to the error docs/ensembles.md gives, each state bit for bit
    # itself alone, float32 back.
    n = 20
    chain = pendulum.Chain([0.1 / n] * n, [1.0 / n] * n, damping=[1e-4] * n)
    r = np.random.default_rng(11)
    circle = pendulum.Circle(radius=r.uniform(0.01, 0.03, 8), omega=r.uniform(2.0, 9.0, 8))
    u = np.tile(np.array([0.0, 0.0, -1.0] * n), (8, 1))
    w = np.zeros_like(u)
    q64, qd64 = chain.integrate(u, w, h=0.05, steps=80, model="directions", method="rod_midpoint", drive=circle)
    q32, qd32 = chain.integrate(u, w, h=0.05, steps=80, model="directions", method="rod_midpoint", drive=circle, precision="float32")
    assert q32.dtype == np.float32 and qd32.dtype == np.float32
    error = max(np.max(np.abs(q32 - q64)) / np.max(np.abs(q64)), np.max(np.abs(qd32 - qd64)) / np.max(np.abs(qd64)))
    swung = np.max(q64[:, 3 * n - 1] + 1.0)
    print(f"rod midpoint in float32, 80 steps of 50 ms, n = {n}: {error:.1e} relative; the lowest link up by {swung:.2f}")
    assert error < 2e-4 and swung > 0.1
    one = pendulum.Circle(radius=circle.radius[5], omega=circle.omega[5])
    alone = chain.integrate(u[5], w[5], h=0.05, steps=80, model="directions", method="rod_midpoint", drive=one, precision="float32")
    assert np.array_equal(alone[0], q32[5]) and np.array_equal(alone[1], qd32[5])


def test_the_rod_midpoint_refuses_what_it_does_not_serve():
    chain = pendulum.Chain([1.0, 1.0], [1.0, 1.0])
    u = np.array([0.0, 0.0, -1.0, 0.6, 0.0, -0.8])
    with pytest.raises(ValueError, match="'rod_midpoint' steps model='directions'"):
        chain.integrate([0.1, 0.2], h=0.01, method="rod_midpoint")
    with pytest.raises(ValueError, match="precision: 'float16' is neither 'float64' nor 'float32'"):
        chain.integrate(u, h=0.01, model="directions", precision="float16", method="rod_midpoint")
    with pytest.raises(ValueError, match=r"method: \"euler\" is not 'rk4' or 'rod_midpoint'"):
        chain.integrate(u, h=0.01, model="directions", method="euler")
    with pytest.raises(ValueError, match="h: 0 is not a positive time step"):
        chain.integrate(u, h=0.0, model="directions", method="rod_midpoint")


def test_bad_input_is_named():
    chain = pendulum.Chain([1.0, 1.0], [1.0, 1.0])
    u = np.array([0.0, 0.0, -1.0, 0.6, 0.0, -0.8])
    with pytest.raises(ValueError, match=r"q: link 2 of state 2 has \|u\| = 2"):
        chain.accelerations(np.stack([u, u, np.concatenate([u[:3], 2 * u[3:]])]), model="directions")
    with pytest.raises(ValueError, match="the last axis has 2 entries, expected 6"):
        chain.accelerations([0.1, 0.2], model="directions")
    with pytest.raises(ValueError, match="takes no joint torques"):
        chain.accelerations(u, torque=np.zeros(6), model="directions")
    with pytest.raises(ValueError, match="precision: 'float16' is neither 'float64' nor 'float32'"):
        chain.integrate(u, h=1e-3, model="directions", precision="float16")
    with pytest.raises(ValueError, match="not finite in single precision"):
        chain.integrate(u, np.full(6, 1e39), h=1e-3, model="directions", precision="float32", steps=0)
    with pytest.raises(ValueError, match="this call takes 'planar' or 'spatial'"):
        chain.terms(u, model="directions")
    with pytest.raises(ValueError, match="none of 'planar', 'spatial', 'directions'"):
        chain.accelerations(u, model="direction")
    with pytest.raises(ValueError, match="pivot_acceleration: the last axis has 2 entries, expected 3"):
        chain.accelerations(u, pivot_acceleration=[0.0, 1.0], model="directions")
