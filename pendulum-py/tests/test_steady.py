"""pendulum.steady: the steady shapes of a chain, as `pendulum steady` finds them."""

import numpy as np
import pytest

import pendulum
from conftest import assert_ctrl_c_interrupts


def test_the_readme_chain_has_the_clis_branches_and_shapes():
    # `pendulum steady --n 12 --lengths 0.1 --omega 5,10,15` (docs/rotating-chain.md).
    chain = pendulum.Chain(masses=[1.0] * 12, lengths=[0.1] * 12, gravity=9.81)
    found = pendulum.steady(chain, omega=[5.0, 10.0, 15.0])
    assert found["omega_max"] == 15.3
    assert np.allclose(found["critical_speeds"], [3.369323, 7.746832, 12.181423], atol=5e-7)
    names = [b["name"] for b in found["branches"]]
    assert names == ["1 node", "2 nodes", "3 nodes"]
    one = found["branches"][0]
    assert one["theta"].shape == (len(one["omega"]), 12) and one["x"].shape == one["theta"].shape
    assert one["omega"][-1] == 15.3 and set(one["stability"][1:]) == {"stable"}
    # The two-node branch turns unstable between 12.314 and 12.800 rad/s.
    two = found["branches"][1]
    unstable = two["omega"][np.array(two["stability"]) == "unstable"]
    assert 12.3 < unstable.min() and unstable.max() < 12.81
    at_15 = [s for s in found["shapes"] if s["omega"] == 15.0]
    assert [s["name"] for s in at_15] == ["vertical", "1 node", "2 nodes", "3 nodes"]
    assert [s["stability"] for s in at_15] == ["gyroscopic", "stable", "gyroscopic", "unstable"]
    assert [s["index"] for s in at_15] == [6, 0, 2, 4]
    assert np.allclose([s["tip_radius"] for s in at_15], [0.0, 1.198511, 0.337183, 0.110662], atol=5e-7)
    assert at_15[3]["growth_rate"] == pytest.approx(0.0209, abs=5e-5)
    assert at_15[0]["nodes"] is None and at_15[1]["nodes"] == 1
    assert found["vertical"][0][:3] == (0.0, pytest.approx(3.369323, abs=5e-7), "stable")


def test_a_circling_pivot_has_the_forced_branches():
    chain = pendulum.Chain(masses=[1.0] * 12, lengths=[0.1] * 12)
    found = pendulum.steady(chain, radius=0.05, omega=10.0)
    assert found["branches"][0]["name"] == "forced, 1 node" and found["vertical"] == []
    # At 10 rad/s (docs): in phase (stable), its mirror (unstable, index 1), the small
    # two-node response (gyroscopic, index 2), two three-node shapes.
    verdicts = sorted((s["stability"], s["index"]) for s in found["shapes"])
    assert ("stable", 0) in verdicts and ("unstable", 1) in verdicts and ("gyroscopic", 2) in verdicts


def test_damped_verdicts_are_the_clis():
    # `pendulum steady --n 12 --lengths 0.1 --omega 15 --damping 0.002` (docs): every shape
    # but the one-node one turns unstable, the one-node one decays.
    chain = pendulum.Chain(masses=[1.0] * 12, lengths=[0.1] * 12)
    shapes = pendulum.steady(chain, omega=15.0, damping=0.002)["shapes"]
    assert [s["damped_stability"] for s in shapes] == ["unstable", "stable", "unstable", "unstable"]
    assert np.allclose([s["damped_growth_rate"] for s in shapes[:3]], [0.0252, -0.00187, 0.0116], atol=5e-5)
    assert all(s["damped_shift"] == 0.0 for s in shapes)
    # A circling pivot at 10 rad/s: the gyroscopic shapes decay, lagging out of the plane.
    forced = pendulum.steady(chain, radius=0.05, omega=10.0, damping=0.002)["shapes"]
    held = [s for s in forced if s["stability"] == "gyroscopic"]
    assert len(held) == 2 and all(s["damped_stability"] == "stable" for s in held)
    assert np.allclose([s["damped_growth_rate"] for s in held], [-6.5e-5, -0.00167], atol=5e-6)
    assert 0.008 < held[0]["damped_shift"] < 0.009
    assert "damped_stability" not in pendulum.steady(chain, omega=15.0)["shapes"][0]


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"branches": 0}, "branches must be between 1 and n = 12, got 0"),
        ({"omega": [5.0, 30.0], "omega_max": 20.0}, "omega: 30 rad/s is above omega_max = 20 rad/s"),
        ({"omega": -1.0}, "omega: -1 rad/s is not a finite, non-negative speed"),
        ({"radius": 0.05, "branches": 2}, "branches applies to a fixed pivot"),
        ({"radius": -0.1}, "radius"),
        ({"damping": [0.1, 0.2]}, "damping: got 2 values for 12 links"),
        ({"damping": -0.1}, "damping"),
    ],
)
def test_bad_requests_are_value_errors(kwargs, message):
    chain = pendulum.Chain(masses=[1.0] * 12, lengths=[0.1] * 12)
    with pytest.raises(ValueError, match=message):
        pendulum.steady(chain, **kwargs)


def test_ctrl_c_interrupts_a_long_steady_within_a_second():
    assert_ctrl_c_interrupts(
        "chain = pendulum.Chain(masses=[1e-4] * 10000, lengths=[1e-4] * 10000)",
        "pendulum.steady(chain, omega=6.0)",
    )
