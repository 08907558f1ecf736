"""Per-call overhead of `pendulum` from Python against Pinocchio's binding (`pin.aba`), on
the same planar chains (point masses on rods, revolute joints), measured in one run.

    target/python/bin/pip install pin==4.1.0
    target/python/bin/python pendulum-py/bench/overhead.py

Prints, for a single evaluation at n = 2 and for 10⁴ states of an n = 8 chain: the best
of several repeats of each call, and their ratio. It first checks that both compute the same
accelerations (Pinocchio's joint angles are relative, about y: −(θ_i − θ_{i−1}) in ours,
which are absolute), so the comparison is of the same work.
"""

import timeit

import numpy as np
import pinocchio as pin

import pendulum

G = 9.81


def pin_chain(masses, lengths):
    """A planar chain in Pinocchio: joint i revolute about y at the end of rod i − 1, a point
    mass m_i at (0, 0, −l_i) in its frame; gravity along −z."""
    model = pin.Model()
    parent, offset = 0, np.zeros(3)
    for i, (m, l) in enumerate(zip(masses, lengths)):
        placement = pin.SE3(np.eye(3), offset)
        parent = model.addJoint(parent, pin.JointModelRY(), placement, f"joint{i}")
        model.appendBodyToJoint(parent, pin.Inertia(m, np.array([0.0, 0.0, -l]), np.zeros((3, 3))), pin.SE3.Identity())
        offset = np.array([0.0, 0.0, -l])
    model.gravity.linear = np.array([0.0, 0.0, -G])
    return model, model.createData()


def best(stmt, number, repeat=7):
    return min(timeit.repeat(stmt, number=number, repeat=repeat)) / number


def main():
    rng = np.random.default_rng(0)
    # The same accelerations first.
    for n in (2, 8):
        masses, lengths = rng.uniform(0.5, 2, n), rng.uniform(0.2, 1, n)
        chain = pendulum.Chain(masses, lengths, gravity=G)
        model, data = pin_chain(masses, lengths)
        q, qd = rng.uniform(-2, 2, n), rng.normal(size=n)
        ours = chain.accelerations(q, qd)
        relative = pin.aba(model, data, -np.diff(q, prepend=0.0), -np.diff(qd, prepend=0.0), np.zeros(n))
        theirs = -np.cumsum(relative)
        assert np.allclose(ours, theirs, rtol=1e-9, atol=1e-9), (ours, theirs)
    print(f"pendulum {pendulum.__version__}, pinocchio {pin.__version__}: the same accelerations at n = 2 and 8")

    n = 2
    chain = pendulum.Chain([1.0, 1.0], [0.5, 0.5], gravity=G)
    model, data = pin_chain([1.0, 1.0], [0.5, 0.5])
    q, qd, tau = rng.uniform(-2, 2, n), rng.normal(size=n), np.zeros(n)
    ours = best(lambda: chain.accelerations(q, qd), 20000)
    theirs = best(lambda: pin.aba(model, data, q, qd, tau), 20000)
    print(f"one evaluation, n = 2: pendulum {ours * 1e6:.2f} µs, pin.aba {theirs * 1e6:.2f} µs: ratio {ours / theirs:.2f}")

    n, count = 8, 10_000
    chain = pendulum.Chain([0.125] * n, [0.125] * n, gravity=G)
    model, data = pin_chain([0.125] * n, [0.125] * n)
    q, qd, tau = rng.uniform(-2, 2, (count, n)), rng.normal(size=(count, n)), np.zeros(n)
    ours = best(lambda: chain.accelerations(q, qd), 5)
    theirs = best(lambda: [pin.aba(model, data, q[k], qd[k], tau) for k in range(count)], 1, repeat=3)
    print(
        f"10^4 states, n = 8: pendulum one call {ours * 1e3:.2f} ms, a Python loop of pin.aba {theirs * 1e3:.2f} ms: "
        f"{theirs / ours:.0f}x less"
    )


if __name__ == "__main__":
    main()
