"""`Chain.integrate` against the RK4 a user would write around `Chain.accelerations` in
numpy, in single precision, and with every pivot shaken at its own frequency
(`drive=pendulum.Harmonic`): 10⁴ states of an 8-link planar chain, 100 steps of 1 ms
(docs/ensembles.md); and `Chain.trajectory` of the same states, 400 steps sampled every
second one.

    target/python/bin/python pendulum-py/bench/integrate.py
"""

import time

import numpy as np

import pendulum


def numpy_rk4(chain, q, qd, h, steps, pivot=None):
    """Classical RK4 around `Chain.accelerations`, the states as one (B, 2n) array; the
    pivot accelerations `pivot(t)` (B, 2) at each stage's time when given."""
    n = chain.n
    x = np.concatenate([q, qd], axis=-1)

    def f(x, t):
        p = None if pivot is None else pivot(t)
        return np.concatenate([x[:, n:], chain.accelerations(x[:, :n], x[:, n:], pivot_acceleration=p)], axis=-1)

    for k in range(steps):
        t = k * h
        k1 = f(x, t)
        k2 = f(0.5 * h * k1 + x, t + 0.5 * h)
        k3 = f(0.5 * h * k2 + x, t + 0.5 * h)
        k4 = f(h * k3 + x, t + h)
        x = x + h / 6.0 * (k1 + 2.0 * (k2 + k3) + k4)
    return x[:, :n], x[:, n:]


def best(f, repeats=5):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return min(times)


def main():
    rng = np.random.default_rng(1)
    chain = pendulum.Chain(masses=[1.0] * 8, lengths=0.125, damping=0.01)
    q, qd = rng.uniform(-1, 1, (10_000, 8)), np.zeros((10_000, 8))
    h, steps = 1e-3, 100
    ours = chain.integrate(q, qd, h=h, steps=steps)
    theirs = numpy_rk4(chain, q, qd, h, steps)
    error = max(np.abs(ours[0] - theirs[0]).max(), np.abs(ours[1] - theirs[1]).max())
    t_ours = best(lambda: chain.integrate(q, qd, h=h, steps=steps))
    t_single = best(lambda: chain.integrate(q, qd, h=h, steps=steps, precision="float32"))
    single = chain.integrate(q, qd, h=h, steps=steps, precision="float32")
    scale = np.abs(ours[0]).max()
    single_error = max(np.abs(single[0] - ours[0]).max(), np.abs(single[1] - ours[1]).max()) / scale
    t_numpy = best(lambda: numpy_rk4(chain, q, qd, h, steps), repeats=3)
    per = 1e9 / (q.shape[0] * steps)
    print(f"Chain.integrate: {t_ours * 1e3:.1f} ms ({t_ours * per:.0f} ns per state-step)")
    print(f"numpy RK4 around Chain.accelerations: {t_numpy * 1e3:.1f} ms ({t_numpy * per:.0f} ns per state-step)")
    print(f"ratio {t_numpy / t_ours:.2f}x; largest difference {error:.1e} (compensated sums against plain ones)")
    print(
        f"Chain.integrate(precision='float32'): {t_single * 1e3:.1f} ms ({t_ours / t_single:.2f}x float64), "
        f"largest difference {single_error:.1e} of the largest angle"
    )
    # Every state's pivot shaken vertically at its own frequency (a Kapitza map).
    amplitude, omega = 0.01, np.linspace(50.0, 400.0, q.shape[0])
    drive = pendulum.Harmonic(amplitude, omega)

    def shaken(t):
        return np.stack([np.zeros_like(omega), -amplitude * omega**2 * np.sin(omega * t)], axis=-1)

    driven = chain.integrate(q, qd, h=h, steps=steps, drive=drive)
    theirs = numpy_rk4(chain, q, qd, h, steps, pivot=shaken)
    error = max(np.abs(driven[0] - theirs[0]).max(), np.abs(driven[1] - theirs[1]).max())
    t_driven = best(lambda: chain.integrate(q, qd, h=h, steps=steps, drive=drive))
    t_numpy = best(lambda: numpy_rk4(chain, q, qd, h, steps, pivot=shaken), repeats=3)
    print(
        f"Chain.integrate(drive=Harmonic(...)), one frequency per state: {t_driven * 1e3:.1f} ms "
        f"({t_driven * per:.0f} ns per state-step, {t_driven / t_ours:.2f}x the held pivot's time); "
        f"numpy RK4 around accelerations(pivot_acceleration=p(t)): {t_numpy * 1e3:.1f} ms, "
        f"ratio {t_numpy / t_driven:.2f}x; largest difference {error:.1e}"
    )
    # A trajectory: 400 steps sampled every 2nd, 201 samples of every state (257 MB of them).
    t_trajectory = best(lambda: chain.trajectory(q, qd, h=h, steps=400, every=2))
    _, qs, qds = chain.trajectory(q, qd, h=h, steps=400, every=2)
    same = np.array_equal(qs[-1], chain.integrate(q, qd, h=h, steps=400)[0])
    print(
        f"Chain.trajectory, 400 steps every 2nd: {t_trajectory * 1e3:.1f} ms "
        f"({(qs.nbytes + qds.nbytes) / 1e6:.0f} MB of samples; last sample = integrate: {same})"
    )


if __name__ == "__main__":
    main()
