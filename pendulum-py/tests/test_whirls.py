"""``pendulum.whirls``: many whirls from hanging at rest as one batch of chains."""

import numpy as np
import pytest
from conftest import assert_ctrl_c_interrupts

import pendulum

# Six links of 0.1 m, 0.1 kg, lightly damped: quick to run, and past its first critical
# speed (about 6.2 rad/s) at 8 rad/s.
CHAIN = dict(masses=0.1, lengths=0.1, damping=1e-3)


def chain():
    return pendulum.Chain([0.1] * 6, [0.1] * 6, damping=1e-3)


def test_each_whirl_of_a_batch_is_the_run_alone():
    omega = [3.0, 8.0, 12.0, 8.0, 5.0]
    ramp = [0.0, 0.0, 0.0, 4.0, 0.0]
    batch = pendulum.whirls(chain(), radius=0.03, omega=omega, ramp_time=ramp, duration=12.0, step=0.002)
    assert batch["nodes"].shape == (5,) and batch["error"] == [None] * 5
    assert batch["duration"] == 12.0 and batch["step"] == 0.002
    # One at a time: the same numbers, bit for bit (the lanes change nothing).
    for i in range(5):
        one = pendulum.whirls(chain(), radius=0.03, omega=omega[i], ramp_time=ramp[i], duration=12.0, step=0.002)
        for key in ["nodes", "tip_radius", "drift", "growth_rate", "balance_residual", "nearest_nodes"]:
            assert np.array_equal(one[key], batch[key][i : i + 1]), (i, key)
    # The same whirl as `pendulum.Run` runs it (RK4, the shape fed every 4 steps).
    for i in [1, 3]:
        extra = dict(ramp_time=ramp[i]) if ramp[i] > 0 else {}
        run = pendulum.Run(dim=3, n=6, initial="hanging", drive="circle", radius=0.03, omega=omega[i],
                           integrator="rk4", step=0.002, end=12.0, every=4, **CHAIN, **extra)
        shape = run.run().shape
        assert shape["nodes"] == batch["nodes"][i]
        assert shape["tip_radius"] == pytest.approx(batch["tip_radius"][i], rel=1e-12)
        assert shape["settled"] == batch["settled"][i]
    # Below the first critical speed one node; above it, suddenly, the small 2-node shape.
    assert batch["nodes"][0] == 1 and batch["nodes"][1] == 2
    # The energy balance closes to RK4's error at this step (the chain holds about 3.5 J).
    assert np.all(batch["balance_residual"] < 1e-4)


def test_defaults_and_one_number_for_all():
    out = pendulum.whirls(chain(), radius=[0.02, 0.04], omega=4.0, duration=3.0)
    assert np.array_equal(out["omega"], [4.0, 4.0]) and np.array_equal(out["radius"], [0.02, 0.04])
    assert np.array_equal(out["ramp_time"], [0.0, 0.0])
    assert 0 < out["step"] <= 0.01


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(radius=-0.1, omega=3.0), "radius: -0.1 m is not a finite, positive radius"),
        (dict(radius=0.02, omega=[1.0, float("nan")]), "omega: NaN rad/s is not a finite, non-negative speed"),
        (dict(radius=[0.02, 0.03], omega=[1.0, 2.0, 3.0]), "radius: 2 values, but another sequence has 3"),
        (dict(radius=0.02, omega=3.0, ramp_time=20.0, duration=10.0), "ramp_time: 20 s is not within 0 … duration (10 s)"),
        (dict(radius=0.02, omega=[]), "omega: an empty sequence"),
        (dict(radius=0.02, omega=3.0, step=0.0, duration=1.0), "step: 0 s is not a finite, positive step within the duration"),
    ],
)
def test_bad_input_is_a_one_line_value_error(kwargs, message):
    with pytest.raises(ValueError) as e:
        pendulum.whirls(chain(), **kwargs)
    assert str(e.value) == message


def test_ctrl_c_stops_a_batch_of_whirls():
    assert_ctrl_c_interrupts(
        "c = pendulum.Chain([0.05] * 20, [0.05] * 20, damping=5e-4)",
        "pendulum.whirls(c, radius=0.02, omega=[3.0] * 16, duration=1e5, step=0.003)",
    )
