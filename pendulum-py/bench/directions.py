"""`Chain`'s `model="directions"` (3D, through the batch of chains) against the spherical
angle model (one state at a time in Rust, on every core), from Python, in one run:

    target/python/bin/python pendulum-py/bench/directions.py

10⁴ states of an 8-link 3D chain: accelerations in spherical angles (`model="spatial"`),
in directions in float64, in float32 from float64 tables and from float32 tables, and
100 projected RK4 steps of 1 ms of every state in directions (in float64, and in float32
where the extension has it), 100 implicit rod midpoint steps (`method="rod_midpoint"`,
where the extension has it), and the directions' Jacobians (`chain.jacobians(..., model="directions")`). Prints the best of 7 repeats, and how far the two models' `ü`
are apart (the chain rule of the angle model's `q̈`).
"""

import timeit

import numpy as np

import pendulum

rng = np.random.default_rng(1)
n, count = 8, 10_000
chain = pendulum.Chain([0.1] * n, [0.2] * n, damping=1e-3)
theta, phi = rng.uniform(0.4, 2.7, (count, n)), rng.uniform(-3, 3, (count, n))
theta_dot, phi_dot = rng.uniform(-2, 2, (count, n)), rng.uniform(-2, 2, (count, n))
q, qd = np.concatenate([theta, phi], 1), np.concatenate([theta_dot, phi_dot], 1)

s, c, sp, cp = np.sin(theta), np.cos(theta), np.sin(phi), np.cos(phi)
zero = np.zeros_like(theta)
u = np.stack([s * cp, s * sp, -c], -1)
u_t, u_p = np.stack([c * cp, c * sp, s], -1), np.stack([-s * sp, s * cp, zero], -1)
u_tp, u_pp = np.stack([-c * sp, c * cp, zero], -1), np.stack([-s * cp, -s * sp, zero], -1)
td, pd = theta_dot[..., None], phi_dot[..., None]
ud = u_t * td + u_p * pd
u, ud = u.reshape(count, 3 * n), ud.reshape(count, 3 * n)
u32, ud32 = u.astype(np.float32), ud.astype(np.float32)

calls = {
    "accelerations, spatial angles": (lambda: chain.accelerations(q, qd, model="spatial"), 20),
    "accelerations, directions float64": (lambda: chain.accelerations(u, ud, model="directions"), 20),
    "accelerations, directions float32": (
        lambda: chain.accelerations(u, ud, model="directions", precision="float32"),
        20,
    ),
    "accelerations, directions float32 tables": (
        lambda: chain.accelerations(u32, ud32, model="directions", precision="float32"),
        20,
    ),
    "100 RK4 steps, directions float64": (
        lambda: chain.integrate(u, ud, h=1e-3, steps=100, model="directions"),
        1,
    ),
    "Jacobians, directions": (lambda: chain.jacobians(u, ud, model="directions"), 1),
}


def midpoint():
    return chain.integrate(u, ud, h=1e-3, steps=100, model="directions", method="rod_midpoint")


try:  # the implicit runs came later too
    midpoint()
    calls["100 rod midpoint steps, directions"] = (midpoint, 1)
except TypeError:
    pass


def run32():
    return chain.integrate(u32, ud32, h=1e-3, steps=100, model="directions", precision="float32")


try:  # float32 runs came later: the script still runs against an extension without them
    run32()
    calls["100 RK4 steps, directions float32"] = (run32, 1)
except ValueError:
    pass
best = {name: min(timeit.repeat(call, number=k, repeat=7)) / k for name, (call, k) in calls.items()}
base = best["accelerations, spatial angles"]
for name, seconds in best.items():
    if name.startswith(("100 ", "Jacobians")):
        if name.startswith("100 "):
            per = f"{seconds / (100 * count) * 1e9:.0f} ns a state-step"
        else:
            per = f"{seconds / count * 1e6:.1f} µs a state"
        print(f"{name:42s} {seconds * 1e3:8.3f} ms  ({per})")
    else:
        print(f"{name:42s} {seconds * 1e3:8.3f} ms  ({base / seconds:.2f}× the angle model's call)")
qdd = chain.accelerations(q, qd, model="spatial")
tdd, pdd = qdd[:, :n, None], qdd[:, n:, None]
expected = u_t * tdd + u_p * pdd - u.reshape(count, n, 3) * td**2 + 2 * u_tp * td * pd + u_pp * pd**2
got = chain.accelerations(u, ud, model="directions").reshape(count, n, 3)
error = np.max(np.abs(got - expected), axis=(1, 2)) / np.max(np.abs(expected), axis=(1, 2))
print(f"directions against the angle model (chain rule): worst relative difference {error.max():.1e}")
single = chain.accelerations(u32, ud32, model="directions", precision="float32").reshape(count, n, 3)
error = np.max(np.abs(single - got), axis=(1, 2)) / np.max(np.abs(got), axis=(1, 2))
print(f"float32 against float64: worst relative difference {error.max():.1e}")
if "100 RK4 steps, directions float32" in calls:
    x64 = np.concatenate(chain.integrate(u, ud, h=1e-3, steps=100, model="directions"), 1)
    x32 = np.concatenate(run32(), 1)
    error = np.max(np.abs(x32 - x64), axis=1) / np.max(np.abs(x64), axis=1)
    print(f"100 RK4 steps, float32 against float64: worst relative difference {error.max():.1e}")
