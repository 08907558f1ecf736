"""`Chain.jacobians` of many states from Python, in one run:

    target/python/bin/python pendulum-py/bench/jacobians.py

10⁴ states of planar chains of 8 and 20 links (with damping, joint torques and a pivot
acceleration per state): `chain.jacobians(q, qd, torque, pivot_acceleration=p)`, which
returns `q̈`, `∂q̈/∂q` and `∂q̈/∂q̇` of every state. Prints the best of 7 repeats, the time
per state, and the largest difference of `∂q̈/∂q` from central differences of
`chain.accelerations` (step 1e-6 rad), relative to the largest entry, as a check that the
timed call does the work. Then the same states without torques in float64 and in
float32 (`precision="float32"`, where the extension has it), and how far apart they are.
Last, 10⁴ states of 3D chains of 8 and 20 links in unit link directions
(`model="directions"`, a pivot acceleration per state): `∂ü/∂u` and `∂ü/∂u̇`, with the
same check against central differences (step 5e-7), and in float32.
"""

import timeit

import numpy as np

import pendulum

rng = np.random.default_rng(1)
count = 10_000
for n in (8, 20):
    chain = pendulum.Chain(rng.uniform(0.05, 0.2, n), rng.uniform(0.1, 0.3, n), damping=1e-3)
    q, qd = rng.uniform(-2, 2, (count, n)), rng.normal(size=(count, n))
    torque, pivot = rng.normal(size=(count, n)) * 1e-2, rng.normal(size=(count, 2))

    def call():
        return chain.jacobians(q, qd, torque, pivot_acceleration=pivot)

    seconds = min(timeit.repeat(call, number=1, repeat=7))
    _, dq, _ = call()
    eps, k = 1e-6, 0
    step = np.zeros(n)
    step[k] = eps
    slope = (
        chain.accelerations(q + step, qd, torque, pivot_acceleration=pivot)
        - chain.accelerations(q - step, qd, torque, pivot_acceleration=pivot)
    ) / (2 * eps)
    error = np.abs(dq[:, :, k] - slope).max() / np.abs(dq).max()
    print(
        f"n = {n:2}: 10^4 states' Jacobians {seconds * 1e3:7.2f} ms"
        f" ({seconds / count * 1e9:6.0f} ns a state); against central differences {error:.1e}"
    )

    def single():
        return chain.jacobians(q, qd, pivot_acceleration=pivot, precision="float32")

    def double():
        return chain.jacobians(q, qd, pivot_acceleration=pivot)

    try:  # float32 Jacobians came later: the script still runs against older extensions
        single()
    except TypeError:
        continue
    t64, t32 = (min(timeit.repeat(f, number=1, repeat=7)) for f in (double, single))
    apart = np.abs(single()[1] - double()[1]).max() / np.abs(double()[1]).max()
    print(
        f"        without torques: float64 {t64 * 1e3:7.2f} ms, float32 {t32 * 1e3:7.2f} ms"
        f" ({t64 / t32:.2f}x); ∂q̈/∂q {apart:.1e} apart"
    )

# 3D chains in unit link directions (`model="directions"`): `∂ü/∂u` and `∂ü/∂u̇` of 10⁴
# states, each rod's rate perpendicular to its direction.
for n in (8, 20):
    chain = pendulum.Chain(rng.uniform(0.05, 0.2, n), rng.uniform(0.1, 0.3, n), damping=1e-3)
    u = rng.normal(size=(count, n, 3))
    u /= np.linalg.norm(u, axis=2, keepdims=True)
    w = rng.normal(size=(count, n, 3))
    w -= np.sum(w * u, axis=2, keepdims=True) * u
    u, w = u.reshape(count, 3 * n), w.reshape(count, 3 * n)
    pivot = rng.normal(size=(count, 3))

    def spatial():
        return chain.jacobians(u, w, pivot_acceleration=pivot, model="directions")

    seconds = min(timeit.repeat(spatial, number=1, repeat=7))
    _, du, _ = spatial()
    eps, k = 5e-7, 0
    step = np.zeros(3 * n)
    step[k] = eps

    def accelerations(a):
        return chain.accelerations(a, w, pivot_acceleration=pivot, model="directions")

    slope = (accelerations(u + step) - accelerations(u - step)) / (2 * eps)
    error = np.abs(du[:, :, k] - slope).max() / np.abs(du).max()
    print(
        f"3D n = {n:2}: 10^4 states' Jacobians {seconds * 1e3:7.2f} ms"
        f" ({seconds / count * 1e9:6.0f} ns a state); against central differences {error:.1e}"
    )

    def spatial_f32():
        return chain.jacobians(u, w, pivot_acceleration=pivot, model="directions", precision="float32")

    try:  # float32 Jacobians in directions came later
        spatial_f32()
    except ValueError:
        continue
    t32 = min(timeit.repeat(spatial_f32, number=1, repeat=7))
    apart = np.abs(spatial_f32()[1] - du).max() / np.abs(du).max()
    print(f"        float32 {t32 * 1e3:7.2f} ms ({seconds / t32:.2f}x); ∂ü/∂u {apart:.1e} apart")
