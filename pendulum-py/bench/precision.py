"""`Chain.accelerations` in single precision against double, from Python, in one run:

    target/python/bin/python pendulum-py/bench/precision.py

10⁴ states of an 8-link chain, one call each: float64 tables, the same with
`precision="float32"`, and float32 tables with `precision="float32"` (read in place).
Prints the best of 9 repeats of 50 calls, and the worst relative error of float32.
"""

import timeit

import numpy as np

import pendulum

rng = np.random.default_rng(1)
n, count = 8, 10_000
chain = pendulum.Chain([0.1] * n, [0.2] * n)
q, qd = rng.uniform(-3, 3, (count, n)), rng.uniform(-3, 3, (count, n))
q32, qd32 = q.astype(np.float32), qd.astype(np.float32)

calls = {
    "float64": lambda: chain.accelerations(q, qd),
    "float32 from float64 tables": lambda: chain.accelerations(q, qd, precision="float32"),
    "float32 from float32 tables": lambda: chain.accelerations(q32, qd32, precision="float32"),
}
best = {name: min(timeit.repeat(call, number=50, repeat=9)) / 50 for name, call in calls.items()}
for name, seconds in best.items():
    print(f"{name:30s} {seconds * 1e3:.3f} ms  ({best['float64'] / seconds:.2f}× float64)")
double, single = calls["float64"](), calls["float32 from float32 tables"]()
error = np.max(np.abs(single - double), axis=-1) / np.max(np.abs(double), axis=-1)
print(f"worst relative error of float32: {error.max():.1e}")
