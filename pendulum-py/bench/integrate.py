"""`Chain.integrate` against the RK4 a user would write around `Chain.accelerations` in
numpy, and in single precision: 10⁴ states of an 8-link planar chain, 100 steps of 1 ms
(docs/ensembles.md).

    target/python/bin/python pendulum-py/bench/integrate.py
"""

import time

import numpy as np

import pendulum


def numpy_rk4(chain, q, qd, h, steps):
    """Classical RK4 around `Chain.accelerations`, the states as one (B, 2n) array."""
    n = chain.n
    x = np.concatenate([q, qd], axis=-1)

    def f(x):
        return np.concatenate([x[:, n:], chain.accelerations(x[:, :n], x[:, n:])], axis=-1)

    for _ in range(steps):
        k1 = f(x)
        k2 = f(0.5 * h * k1 + x)
        k3 = f(0.5 * h * k2 + x)
        k4 = f(h * k3 + x)
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


if __name__ == "__main__":
    main()
