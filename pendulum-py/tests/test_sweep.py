"""``pendulum.sweep``: ``pendulum sweep`` from Python."""

import json

import numpy as np
import pytest

import pendulum
from conftest import assert_ctrl_c_interrupts


def chain():
    return pendulum.Chain([0.1] * 6, [0.1] * 6, damping=1e-2)


def test_a_sweep_is_the_whirls_and_its_ramp_down_chains_its_points(tmp_path):
    s = pendulum.sweep(chain(), omega=[3.0, 8.0, 12.0], duration=20.0, ramp_time=6.0, step=0.002, jobs=2,
                       out=tmp_path / "s")
    assert list(s.kind) == ["sudden"] * 3 + ["ramp-up"] * 3 + ["ramp-down"] * 3
    assert list(s.omega) == [3.0, 8.0, 12.0, 3.0, 8.0, 12.0, 12.0, 8.0, 3.0]
    assert (s.status == "completed").all() and s.ramp_time == 6.0 and s.step == 0.002
    # The independent points are the whirls, bit for bit.
    for ramp, rows in [(0.0, slice(0, 3)), (6.0, slice(3, 6))]:
        w = pendulum.whirls(chain(), radius=0.02, omega=[3.0, 8.0, 12.0], ramp_time=ramp, duration=20.0, step=0.002)
        for key in ["nodes", "tip_radius", "settled", "nearest_nodes", "balance_residual"]:
            assert np.array_equal(w[key], getattr(s, key)[rows]), (ramp, key)
    # The first ramp-down point is the ramp-up run at the top speed; the next start from it.
    assert s.tip_radius[6] == s.tip_radius[5] and s.nodes[6] == s.nodes[5]
    assert s.file["points"][7]["start"] == "the final state of the ramp-down point at ω = 12 rad/s"
    # Below the first critical speed (4.68 rad/s) one node, above it a sudden start finds 2.
    assert list(s.of("sudden")["nodes"][:2]) == [1, 2]
    assert s.critical_speeds[0] == pytest.approx(4.68, abs=0.01)
    # The files, as the command writes them.
    saved = json.loads((tmp_path / "s" / "sweep.json").read_text())
    assert saved["command"] == "sweep" and saved["status"] == "completed" and saved["points"] == s.file["points"]
    header = (tmp_path / "s" / "sweep.csv").read_text().splitlines()[0]
    assert header.startswith("kind,omega_rad_s,omega_over_sqrt_g_over_L,status,nodes")


def test_jobs_change_nothing_and_bad_input_says_what_is_wrong():
    one = pendulum.sweep(chain(), omega=np.array([8.0, 3.0]), kinds="sudden", duration=5.0, step=0.002, jobs=1)
    two = pendulum.sweep(chain(), omega=np.array([8.0, 3.0]), kinds=["sudden"], duration=5.0, step=0.002, jobs=2)
    assert np.array_equal(one.tip_radius, two.tip_radius) and list(one.omega) == [8.0, 3.0]
    scaled = pendulum.sweep(chain(), omega="1:2:3", scaled=True, kinds="sudden", duration=5.0, step=0.002)
    assert list(scaled.omega_scaled) == pytest.approx([1.0, 1.5, 2.0])
    assert scaled.omega[0] == pytest.approx(np.sqrt(9.81 / 0.6)) and scaled.file["config"]["omega_spec"] == "1:2:3"
    with pytest.raises(ValueError, match="kinds: 'sideways' is not a kind of start"):
        pendulum.sweep(chain(), omega=[1.0], kinds="sideways")
    with pytest.raises(ValueError, match=r"^omega: '-1.0' has a negative entry -1.0 \(speeds are ≥ 0 rad/s\)$"):
        pendulum.sweep(chain(), omega=[-1.0])
    with pytest.raises(ValueError, match="^radius must be finite and positive"):
        pendulum.sweep(chain(), omega=[1.0], radius=0.0)
    with pytest.raises(ValueError, match=r"^ramp_time applies to the kinds ramp-up and ramp-down only \(a sudden start has no ramp\)$"):
        pendulum.sweep(chain(), omega=[1.0], kinds="sudden", ramp_time=2.0)
    with pytest.raises(ValueError, match="jobs: at least 1, got 0"):
        pendulum.sweep(chain(), omega=[1.0], jobs=0)


def test_ctrl_c_stops_a_sweep():
    assert_ctrl_c_interrupts(
        "c = pendulum.Chain([0.05] * 20, [0.05] * 20, damping=5e-4)",
        "pendulum.sweep(c, omega=[2.0, 3.0, 4.0], duration=1e5, step=0.003)",
    )
