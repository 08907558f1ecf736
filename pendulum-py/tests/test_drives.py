"""Runs whose pivot moves within a call (`drive=pendulum.Harmonic(...)`,
`pendulum.Circle(...)` or `pendulum.Sampled(...)`, parameters one for all or one per
state): Kapitza's inverted pendulum against its threshold and slow frequency, a whirled
rod on its steady cone, the directions against the planar model, drives per state and
each state alone bit for bit, runs split in calls, a pivot on samples of a motion against
the motion itself, and bad input."""

import pickle

import numpy as np
import pytest

import pendulum

G = 9.81


def test_kapitza_pendulum_stands_upright_above_its_threshold_at_its_slow_frequency():
    # A rod of length l shaken vertically, p = A sin(ωt) ẑ, stands upright when
    # A²ω² > 2 g l; it then sways about the top at Ω² = A²ω²/(2 l²) − g/l (Kapitza), with
    # corrections of the order of (Ω/ω)². One call, one frequency per state.
    amplitude, length, h = 0.02, 0.5, 2e-5
    chain = pendulum.Chain(1.0, length)
    omega = np.array([100.0, 300.0, 600.0])  # threshold: sqrt(2 g l) / A = 157 rad/s
    q0 = np.full((3, 1), np.pi - 0.1)
    t, q, _ = chain.trajectory(q0, h=h, steps=200_000, every=10, drive=pendulum.Harmonic(amplitude, omega))
    away = q[:, :, 0] - np.pi
    assert np.max(np.abs(away[:, 0])) > 2.0, "below the threshold the rod falls"
    for k in (1, 2):
        assert np.max(np.abs(away[:, k])) < 0.25, f"ω = {omega[k]}: the rod stands"
        # Sign changes of the sway averaged over one period of the shaking.
        window = int(round(2 * np.pi / omega[k] / (10 * h)))
        slow = np.convolve(away[:, k], np.ones(window) / window, mode="valid")
        crossings = t[np.nonzero(np.diff(np.sign(slow)))[0]]
        measured = np.pi / np.mean(np.diff(crossings))
        kapitza = np.sqrt((amplitude * omega[k]) ** 2 / (2 * length**2) - G / length)
        print(f"ω = {omega[k]}: slow sway {measured:.3f} rad/s, Kapitza {kapitza:.3f} ({measured / kapitza - 1:+.1%})")
        assert abs(measured / kapitza - 1) < 0.03, (omega[k], measured, kapitza)


def cone_angle(radius, length, omega):
    """The steady cone angle α (rad) of a rod of length l on a pivot circling at radius R
    and speed ω, its mass circling with the pivot: ω² (R + l sin α) = g tan α, by its fixed
    point (checked to have converged)."""
    alpha = 0.0
    for _ in range(500):
        alpha = np.arctan(omega**2 * (radius + length * np.sin(alpha)) / G)
    assert abs(G * np.tan(alpha) - omega**2 * (radius + length * np.sin(alpha))) < 1e-12
    return alpha


def on_the_cone(radius, length, omega):
    """The rod's state `(u, w)` on its steady cone, in the plane of the pivot's radius at
    t = 0, turning with it."""
    alpha = cone_angle(radius, length, omega)
    u = np.array([np.sin(alpha), 0.0, -np.cos(alpha)])
    return u, omega * np.cross([0.0, 0.0, 1.0], u)


def tilt(q, phase):
    """The angle (rad) of rods `q` (rows of x, y, z) from the downward vertical, measured in
    the plane of the pivot's radius at azimuth `phase` (one per row), and how far out of
    that plane they point."""
    turned = np.stack([np.cos(phase), np.sin(phase)], 1)
    along = np.einsum("ij,ij->i", q[:, :2], turned)
    across = turned[:, 0] * q[:, 1] - turned[:, 1] * q[:, 0]
    return np.arctan2(along, -q[:, 2]), across


def test_a_whirled_rod_started_on_its_steady_cone_stays_there():
    # A rod of length l on a pivot circling at radius R and speed ω stands steady at the
    # cone angle α with ω² (R + l sin α) = g tan α, its mass circling with the pivot.
    radius, length, omega = 0.1, 0.5, 6.0
    u, w = on_the_cone(radius, length, omega)
    t, q, _ = pendulum.Chain(1.0, length).trajectory(
        u, w, h=1e-3, steps=2000, every=100, model="directions", drive=pendulum.Circle(radius, omega)
    )
    angle, across = tilt(q, omega * t)
    assert np.max(np.abs(angle - cone_angle(radius, length, omega))) < 1e-6
    assert np.max(np.abs(across)) < 1e-6


def test_a_whirl_ramped_slowly_follows_its_steady_cone():
    # The rod above, undamped, from hanging at rest, the circle's speed ramped from 0 to ω
    # over T (one T per state, one call): the slower the ramp, the closer the rod stays to
    # its cone after it (adiabatic following: the sway left over falls as 1/T).
    radius, length, omega = 0.1, 0.5, 4.0
    alpha = cone_angle(radius, length, omega)
    ramp = np.array([15.0, 30.0, 60.0])
    hanging, rest = np.tile([0.0, 0.0, -1.0], (3, 1)), np.zeros((3, 3))
    h, every = 2e-3, 50
    drive = pendulum.Circle(radius, omega, ramp_time=ramp)
    t, q, _ = pendulum.Chain(1.0, length).trajectory(
        hanging, rest, h=h, steps=int(65 / h), every=every, model="directions", drive=drive
    )
    sway = []
    for k, time in enumerate(ramp):
        phase = np.where(t < time, 0.5 * omega / time * t**2, omega * time / 2 + omega * (t - time))
        angle, _ = tilt(q[:, k], phase)
        sway.append(np.max(np.abs(angle - alpha)[t > time]))
    print("sway about the cone after ramps of " + ", ".join(f"{T:.0f} s: {a:.3f} rad" for T, a in zip(ramp, sway)))
    assert sway[2] < 0.05 and 1.5 < sway[0] / sway[1] < 2.5 and 1.5 < sway[1] / sway[2] < 2.5, sway
    # A ramp from ω to ω is the steady circle, bit for bit.
    steady = pendulum.Circle(radius, omega)
    flat = pendulum.Circle(radius, omega, ramp_time=2.0, ramp_from=omega)
    u, w = np.array([0.6, 0.0, -0.8]), np.array([0.0, 1.0, 0.0])
    a = pendulum.Chain(1.0, length).integrate(u, w, h=1e-3, steps=3000, model="directions", drive=steady)
    b = pendulum.Chain(1.0, length).integrate(u, w, h=1e-3, steps=3000, model="directions", drive=flat)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


def test_a_shaken_chain_in_a_vertical_plane_moves_as_the_planar_model_says():
    # The same shaking along (1, 1) in the x–z plane, from the same state: the two models'
    # RK4 runs agree to their truncation errors.
    chain = pendulum.Chain([1.0, 0.5, 0.8], [0.4, 0.3, 0.5], damping=0.01)
    theta, rate = np.array([0.3, -0.4, 0.9]), np.array([0.5, -1.0, 0.2])
    steps, h = 2000, 2.5e-4
    planar, _ = chain.integrate(
        theta, rate, h=h, steps=steps, t0=0.3, drive=pendulum.Harmonic(0.05, 40.0, 0.5, direction=(1.0, 1.0))
    )
    zero = np.zeros(3)
    u = np.stack([np.sin(theta), zero, -np.cos(theta)], 1).ravel()
    w = (rate[:, None] * np.stack([np.cos(theta), zero, np.sin(theta)], 1)).ravel()
    drive = pendulum.Harmonic(0.05, 40.0, 0.5, direction=(1.0, 0.0, 1.0))
    q, _ = chain.integrate(u, w, h=h, steps=steps, t0=0.3, model="directions", drive=drive)
    q = q.reshape(3, 3)
    assert np.max(np.abs(np.arctan2(q[:, 0], -q[:, 2]) - planar)) < 1e-8


@pytest.mark.parametrize("model", ["planar", "directions"])
def test_drives_per_state_and_runs_in_calls_give_one_calls_numbers(model):
    chain = pendulum.Chain([0.4, 0.3, 0.2, 0.5], [0.3, 0.2, 0.4, 0.3], damping=0.02)
    r = np.random.default_rng(11)
    if model == "planar":
        q0, qd0 = r.uniform(-2, 2, (2, 3, 4)), r.uniform(-2, 2, (2, 3, 4))
        direction = (0.3, 1.0)
    else:
        u = r.normal(size=(2, 3, 4, 3))
        u /= np.linalg.norm(u, axis=-1, keepdims=True)
        q0, qd0 = u.reshape(2, 3, 12), np.cross(u, r.normal(size=u.shape)).reshape(2, 3, 12)
        direction = (0.3, 0.0, 1.0)
    drive = pendulum.Harmonic(0.03, 70.0, 0.2, direction=direction)
    kw = dict(h=1e-3, model=model, drive=drive)
    q, qd = chain.integrate(q0, qd0, steps=30, t0=0.1, **kw)
    # In two calls, the second from where the first ended: the same to round-off (a call
    # starts its states' rounding compensation afresh).
    qa, qda = chain.integrate(q0, qd0, steps=10, t0=0.1, **kw)
    qb, qdb = chain.integrate(qa, qda, steps=20, t0=0.1 + 10 * 1e-3, **kw)
    assert np.max(np.abs(qb - q)) < 1e-13 and np.max(np.abs(qdb - qd)) < 1e-12
    # Started a step late, the drive's phase differs: the time is read.
    late, _ = chain.integrate(qa, qda, steps=20, t0=0.1 + 11 * 1e-3, **kw)
    assert np.max(np.abs(late - q)) > 1e-6
    # The same parameters given once per state.
    each = pendulum.Harmonic(
        np.full((2, 3), 0.03), np.full((2, 3), 70.0), np.full((2, 3), 0.2), direction=np.tile(direction, (2, 3, 1))
    )
    qe, qde = chain.integrate(q0, qd0, steps=30, t0=0.1, h=1e-3, model=model, drive=each)
    assert np.array_equal(q, qe) and np.array_equal(qd, qde)
    # Each state alone.
    for i in range(2):
        for j in range(3):
            alone = chain.integrate(q0[i, j], qd0[i, j], steps=30, t0=0.1, **kw)
            assert np.array_equal(alone[0], q[i, j]) and np.array_equal(alone[1], qd[i, j])
    # The states differ from the pivot at rest's: the drive moved them.
    held, _ = chain.integrate(q0, qd0, steps=30, h=1e-3, model=model)
    assert np.max(np.abs(held - q)) > 1e-3


def test_a_drive_that_stands_still_is_the_pivot_at_rest_bit_for_bit():
    chain = pendulum.Chain([0.4, 0.3], [0.3, 0.2])
    q0, qd0 = np.array([[0.3, -0.2], [1.0, 2.0]]), np.array([[0.1, 0.0], [-1.0, 0.5]])
    rest = chain.integrate(q0, qd0, h=1e-3, steps=50)
    still = chain.integrate(q0, qd0, h=1e-3, steps=50, drive=pendulum.Harmonic([0.0, 0.0], 30.0))
    assert all(np.array_equal(a, b) for a, b in zip(rest, still))
    u = np.array([0.6, 0.0, -0.8, 0.0, 0.6, -0.8])
    w = np.array([0.0, 0.8, 0.0, 1.0, 0.0, 0.0])
    rest = chain.integrate(u, w, h=1e-3, steps=50, model="directions")
    still = chain.integrate(u, w, h=1e-3, steps=50, model="directions", drive=pendulum.Circle(0.0, 5.0))
    assert all(np.array_equal(a, b) for a, b in zip(rest, still))


def test_driven_runs_in_float32_follow_float64():
    # Kapitza's rod from the first test and a shaken 8-link chain: float32 within the
    # bound of docs/ensembles.md (1e-4 of the largest number of each state).
    for chain, q0, drive in [
        (pendulum.Chain(1.0, 0.5), np.full((3, 1), np.pi - 0.1), pendulum.Harmonic(0.02, [100.0, 300.0, 600.0])),
        (
            pendulum.Chain([0.1] * 8, 0.05, damping=1e-4),
            np.random.default_rng(3).uniform(-1, 1, (16, 8)),
            pendulum.Harmonic(0.005, np.linspace(50.0, 400.0, 16), direction=(0.2, 1.0)),
        ),
    ]:
        kw = dict(h=1e-4, steps=100, drive=drive, t0=0.25)
        q, qd = chain.integrate(q0, **kw)
        q32, qd32 = chain.integrate(q0.astype(np.float32), precision="float32", **kw)
        assert q32.dtype == np.float32
        scale = np.maximum(np.abs(q).max(axis=-1), np.abs(qd).max(axis=-1))
        error = np.maximum(np.abs(q32 - q).max(axis=-1), np.abs(qd32 - qd).max(axis=-1)) / scale
        assert error.max() < 1e-4, error.max()
        # Sampled, the run goes in calls, each from its own start time: the same to f32's
        # rounding.
        _, qs, _ = chain.trajectory(q0.astype(np.float32), precision="float32", every=30, **kw)
        assert np.max(np.abs(qs[-1] - q32).max(axis=-1) / scale) < 1e-6
    # The whirled rod of the second test in float32: on its cone to f32's rounding.
    radius, length, omega = 0.1, 0.5, 6.0
    u, w = on_the_cone(radius, length, omega)
    kw = dict(h=1e-3, steps=2000, every=100, model="directions", drive=pendulum.Circle(radius, omega))
    t, q, _ = pendulum.Chain(1.0, length).trajectory(u, w, precision="float32", **kw)
    angle, _ = tilt(q.astype(np.float64), omega * t)
    assert np.max(np.abs(angle - cone_angle(radius, length, omega))) < 1e-5


def test_trajectory_times_start_at_t0():
    chain = pendulum.Chain(1.0, 1.0)
    t, q, _ = chain.trajectory([0.2], h=0.01, steps=4, every=2, t0=5.0, drive=pendulum.Harmonic(0.01, 10.0))
    assert np.allclose(t, [5.0, 5.02, 5.04]) and q.shape == (3, 1)


def test_drives_print_and_pickle():
    h = pendulum.Harmonic(0.02, np.linspace(100, 400, 4), direction=(0.0, 1.0))
    assert repr(h) == "Harmonic(amplitude=0.02, omega=<array of shape [4]>, phase=0.0, direction=<array of shape [2]>)"
    back = pickle.loads(pickle.dumps(h))
    assert np.array_equal(back.omega, h.omega) and back.amplitude == 0.02 and back.phase == 0.0
    assert np.array_equal(back.direction, [0.0, 1.0])
    c = pickle.loads(pickle.dumps(pendulum.Circle(0.1, [3.0, 4.0])))
    assert repr(c) == "Circle(radius=0.1, omega=<array of shape [2]>)" and c.ramp_time is None
    c = pickle.loads(pickle.dumps(pendulum.Circle(0.1, 3.0, ramp_time=[1.0, 2.0], ramp_from=0.5)))
    assert repr(c) == "Circle(radius=0.1, omega=3.0, ramp_time=<array of shape [2]>, ramp_from=0.5)"
    assert np.array_equal(c.ramp_time, [1.0, 2.0]) and c.ramp_from == 0.5
    assert pendulum.Harmonic(0.1, 2.0).direction is None


def test_bad_drives_are_named():
    chain = pendulum.Chain([1.0, 1.0], 0.5)
    q = np.zeros((4, 2))
    harmonic = pendulum.Harmonic(0.02, 200.0)
    for kw, message in [
        (dict(drive=harmonic, pivot_acceleration=[0.0, 1.0]), "pivot_acceleration: a drive moves the pivot"),
        (dict(drive=pendulum.Circle(0.1, 3.0)), "model='directions' only"),
        (dict(drive=3), "drive: a int, expected pendulum.Harmonic, pendulum.Circle or pendulum.Sampled"),
        (dict(t0=float("nan")), "t0: NaN is not a finite time"),
        (dict(drive=pendulum.Harmonic(0.1, [1.0, 2.0])), "omega: shape [2] is neither [] (one for all) nor [4]"),
        (dict(drive=pendulum.Harmonic(0.1, 1.0, direction=(0, 0, 1))), "direction: 3 components, model='planar' takes 2"),
    ]:
        with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)").replace("[", r"\[")):
            chain.integrate(q, h=1e-3, **kw)
    for args, message in [
        ((-1.0, 2.0), "amplitude: -1.0 is negative"),
        ((1.0, np.inf), "omega: inf is not finite"),
        ((1.0, 2.0, 0.0, (0.0, 0.0)), r"direction: \[0.0, 0.0\] has no direction"),
        ((1.0, 2.0, 0.0, (1.0, 0.0, 0.0, 0.0)), "direction: the last axis has 4 entries"),
    ]:
        with pytest.raises(ValueError, match=message):
            pendulum.Harmonic(*args)
    with pytest.raises(ValueError, match="radius: -0.1 is negative"):
        pendulum.Circle(-0.1, 2.0)
    with pytest.raises(ValueError, match=r"ramp_time: 0.0 is not a positive time \(s\)"):
        pendulum.Circle(0.1, 2.0, ramp_time=[1.0, 0.0])
    with pytest.raises(ValueError, match="ramp_from: a ramp needs its ramp_time"):
        pendulum.Circle(0.1, 2.0, ramp_from=1.0)
    with pytest.raises(ValueError, match=r"ramp_time: shape \[2\] is neither \[\] \(one for all\) nor \[3\]"):
        u = np.tile([0.0, 0.0, -1.0], (3, 1))
        pendulum.Chain(1.0, 1.0).integrate(u, h=1e-3, model="directions", drive=pendulum.Circle(0.1, 2.0, ramp_time=[1.0, 2.0]))


def sampled(drive_position, drive_velocity, t_end, per_second):
    """`pendulum.Sampled` through a motion's positions from 0 to `t_end` (s), `per_second`
    samples a second, its end velocities the motion's."""
    t = np.linspace(0.0, t_end, int(round(t_end * per_second)) + 1)
    ends = np.stack([drive_velocity(t[0]), drive_velocity(t[-1])])
    return pendulum.Sampled(t, np.stack([drive_position(s) for s in t]), end_velocities=ends)


def test_a_pivot_on_samples_of_its_motion_moves_the_chain_as_the_motion_does():
    # Kapitza's rod shaken at 300 rad/s (planar), and a 3-link chain whirled on a circle of
    # 2 cm at 7 rad/s from hanging (directions): driven by the spline through samples of
    # the motion, each run approaches the one driven by the motion itself as h⁴, h the
    # spacing of the samples.
    amplitude, omega = 0.02, 300.0
    rod = pendulum.Chain(1.0, 0.5)
    exact, _ = rod.integrate([np.pi - 0.1], h=2e-5, steps=20_000, drive=pendulum.Harmonic(amplitude, omega))
    position = lambda t: [0.0, amplitude * np.sin(omega * t)]
    velocity = lambda t: [0.0, amplitude * omega * np.cos(omega * t)]
    errors = []
    for per_turn in (20, 40):
        drive = sampled(position, velocity, 0.5, per_turn * omega / (2 * np.pi))
        q, _ = rod.integrate([np.pi - 0.1], h=2e-5, steps=20_000, drive=drive)
        errors.append(abs(q[0] - exact[0]))
    print(f"Kapitza's rod after 0.4 s, samples 20 and 40 a turn: errors {errors[0]:.2e}, {errors[1]:.2e} rad")
    assert errors[1] < 1e-6 and errors[0] / errors[1] > 8, errors

    chain = pendulum.Chain([0.3, 0.2, 0.1], [0.2, 0.15, 0.1])
    hanging = np.tile([0.0, 0.0, -1.0], 3)
    kw = dict(h=1e-3, steps=3000, model="directions")
    exact, _ = chain.integrate(hanging, drive=pendulum.Circle(0.02, 7.0), **kw)
    circle = lambda t: 0.02 * np.array([np.cos(7.0 * t), np.sin(7.0 * t), 0.0])
    turning = lambda t: 0.14 * np.array([-np.sin(7.0 * t), np.cos(7.0 * t), 0.0])
    q, _ = chain.integrate(hanging, drive=sampled(circle, turning, 3.5, 7.0 * 40 / (2 * np.pi)), **kw)
    assert np.max(np.abs(exact - hanging)) > 0.1, "the whirl moved the chain"
    assert np.max(np.abs(q - exact)) < 1e-6, np.max(np.abs(q - exact))


def test_sampled_paths_per_state_are_each_states_own_run_bit_for_bit():
    chain = pendulum.Chain([0.4, 0.3], [0.3, 0.2], damping=0.01)
    t = np.linspace(0.0, 0.2, 11)
    r = np.random.default_rng(5)
    paths = 0.01 * r.normal(size=(3, 11, 2))
    drive = pendulum.Sampled(t, paths)
    q0 = r.uniform(-1, 1, (3, 2))
    # From 0.05 s to 0.35 s: on the spline, then on the straight line after it.
    q, qd = chain.integrate(q0, h=1e-3, steps=300, t0=0.05, drive=drive)
    for k in range(3):
        alone = chain.integrate(q0[k], h=1e-3, steps=300, t0=0.05, drive=pendulum.Sampled(t, paths[k]))
        assert np.array_equal(alone[0], q[k]) and np.array_equal(alone[1], qd[k])
    assert np.max(np.abs(q[0] - q[1])) > 1e-4, "each state's own path"
    # In float32, eight states a register: within the bound of the other drives.
    q32, qd32 = chain.integrate(q0.astype(np.float32), h=1e-3, steps=300, t0=0.05, drive=drive, precision="float32")
    scale = np.maximum(np.abs(q).max(axis=-1), np.abs(qd).max(axis=-1))
    assert q32.dtype == np.float32 and np.max(np.abs(q32 - q).max(axis=-1) / scale) < 1e-4
    # The same path for all: one path given once, or once per state.
    once = chain.integrate(q0, h=1e-3, steps=100, drive=pendulum.Sampled(t, paths[0]))
    each = chain.integrate(q0, h=1e-3, steps=100, drive=pendulum.Sampled(t, np.stack([paths[0]] * 3)))
    assert all(np.array_equal(a, b) for a, b in zip(once, each))
    # One path, each state its own end velocities.
    ends = np.zeros((3, 2, 2))
    ends[1, 1] = [0.1, 0.0]
    same = np.tile(q0[0], (3, 1))
    q_ends, _ = chain.integrate(same, h=1e-3, steps=300, t0=0.05, drive=pendulum.Sampled(t, paths[0], ends))
    assert np.array_equal(q_ends[0], q_ends[2]) and not np.array_equal(q_ends[0], q_ends[1])
    # A path at rest at the origin is the pivot at rest, bit for bit.
    rest = chain.integrate(q0, h=1e-3, steps=100)
    still = chain.integrate(q0, h=1e-3, steps=100, drive=pendulum.Sampled(t, np.zeros((11, 2)), np.zeros((2, 2))))
    assert all(np.array_equal(a, b) for a, b in zip(rest, still))


def test_sampled_drives_print_pickle_and_name_bad_samples():
    p = pendulum.Sampled([0.0, 0.5, 1.0], np.zeros((4, 3, 3)), end_velocities=np.zeros((2, 3)))
    assert repr(p) == (
        "Sampled(3 samples from 0 to 1 s, positions=<array of shape [4, 3, 3]>, end_velocities=<array of shape [2, 3]>)"
    )
    back = pickle.loads(pickle.dumps(p))
    assert np.array_equal(back.times, [0.0, 0.5, 1.0]) and back.positions.shape == (4, 3, 3)
    assert back.end_velocities.shape == (2, 3) and pendulum.Sampled([0, 1], np.zeros((2, 2))).end_velocities is None
    for args, message in [
        (([0.0], [[0.0, 0.0]]), "a sampled drive needs at least 2 samples, got 1"),
        (([[0.0, 1.0]], [[0.0, 0.0]]), r"times: shape \[1, 2\], expected \(m,\)"),
        (([0.0, 1.0, 1.0], np.zeros((3, 2))), r"times\[2\] must be after times\[1\] = 1, got 1"),
        (([0.0, np.nan], np.zeros((2, 2))), "times: NaN is not finite"),
        (([0.0, 1.0], np.zeros((3, 2))), r"positions: shape \[3, 2\], expected \(2, 2\) or \(2, 3\) for 2 times"),
        (([0.0, 1.0], np.zeros((2, 4))), r"positions: shape \[2, 4\]"),
        (([0.0, 1.0], np.zeros((2, 2)), np.zeros((3, 2))), r"end_velocities: shape \[3, 2\] is neither \[2, 2\]"),
        (([0.0, 1e-300, 1.0], [[0.0, 0.0], [1e300, 0.0], [0.0, 0.0]]), "drive spline acceleration must be finite"),
    ]:
        with pytest.raises(ValueError, match=message):
            pendulum.Sampled(*args)
    chain = pendulum.Chain([1.0, 1.0], 0.5)
    with pytest.raises(ValueError, match="positions: 3 components, model='planar' takes 2"):
        chain.integrate(np.zeros(2), h=1e-3, drive=pendulum.Sampled([0.0, 1.0], np.zeros((2, 3))))
    with pytest.raises(ValueError, match=r"positions: shape \[5, 2, 2\] is neither \[2, 2\] \(one for all\) nor \[4, 2, 2\]"):
        chain.integrate(np.zeros((4, 2)), h=1e-3, drive=pendulum.Sampled([0.0, 1.0], np.zeros((5, 2, 2))))
