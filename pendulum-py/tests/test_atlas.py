"""``pendulum.atlas``: the map of the chain's choice, here and on a Dask cluster."""

import json
import pickle

import numpy as np
import pytest

import pendulum
from conftest import assert_ctrl_c_interrupts

# Six links of 0.1 m, 0.1 kg, lightly damped (first critical speed 4.68 rad/s).
GRID = dict(omega=[3.0, 8.0, 12.0, 16.0], radius=[0.01, 0.03, 0.05], duration=12.0, step=0.002)


def chain():
    return pendulum.Chain([0.1] * 6, [0.1] * 6, damping=1e-3)


@pytest.fixture(scope="module")
def local():
    return pendulum.atlas(chain(), kinds=["sudden", "ramp-up"], ramp_time=4.0, **GRID)


def test_the_grid_is_the_whirls_point_by_point(local):
    a = local
    assert (a.x_name, a.y_name, a.kinds) == ("omega", "radius", ("sudden", "ramp-up"))
    assert a.nodes.shape == (2, 3, 4) and np.array_equal(a.x, GRID["omega"]) and np.array_equal(a.y, GRID["radius"])
    assert (a.status == "completed").all() and (a.nodes >= 1).all()
    # Row iy, column ix is the whirl at radius y[iy], speed x[ix]: bit for bit.
    for k, ramp in enumerate([0.0, 4.0]):
        for iy, r in enumerate(GRID["radius"]):
            w = pendulum.whirls(chain(), radius=r, omega=GRID["omega"], ramp_time=ramp, duration=12.0, step=0.002)
            assert np.array_equal(w["nodes"], a.nodes[k, iy]), (k, iy)
            assert np.array_equal(w["tip_radius"], a.tip_radius[k, iy]), (k, iy)
            assert np.array_equal(w["settled"], a.settled[k, iy]), (k, iy)
    # Below the first critical speed one node; above it a sudden start finds 2 nodes.
    assert (a.nodes[0, :, 0] == 1).all() and a.nodes[0, 0, 1] == 2
    assert a.critical_speeds[0] == pytest.approx(4.68, abs=0.01)


def test_any_cut_of_the_grid_gives_the_same_points(local):
    plan = local.plan
    whole = json.loads(plan.run(list(range(len(plan)))))
    assert whole == local.points
    # Chunks in another order, on one thread: the same points.
    picked = [17, 3, 5, 22, 0]
    assert json.loads(plan.run(picked, threads=1)) == [whole[i] for i in picked]


def test_a_plan_pickles_and_bad_input_says_what_is_wrong(local):
    plan = pickle.loads(pickle.dumps(local.plan))
    assert plan.to_json() == local.plan.to_json() and len(plan) == 24
    with pytest.raises(ValueError, match=r"exactly two axes \(two of omega, radius, damping, ramp_time .* got 1 \(omega\)$"):
        pendulum.atlas(chain(), omega=[1.0, 2.0], radius=0.02)
    with pytest.raises(ValueError, match=r"^radius: -0.02 is not a finite value ≥ 0$"):
        pendulum.atlas(chain(), omega=[1.0, 2.0], radius=[0.01, -0.02])
    with pytest.raises(ValueError, match="kinds: 'sideways' is not a kind of start"):
        pendulum.atlas(chain(), omega=[1.0, 2.0], radius=[0.01, 0.02], kinds="sideways")
    with pytest.raises(ValueError, match="not a point of this atlas"):
        local.plan.run([24])


def test_a_damping_axis_and_saving_the_file(tmp_path):
    a = pendulum.atlas(chain(), omega=[3.0, 8.0], radius=0.03, damping=[1e-3, 2e-3, 4e-3], duration=6.0, step=0.002)
    assert (a.x_name, a.y_name, a.nodes.shape) == ("omega", "damping", (1, 3, 2))
    same = pendulum.whirls(pendulum.Chain([0.1] * 6, [0.1] * 6, damping=2e-3), radius=0.03, omega=[3.0, 8.0],
                           duration=6.0, step=0.002)
    assert np.array_equal(same["tip_radius"], a.tip_radius[0, 1])
    a.save(str(tmp_path / "out"))
    saved = json.loads((tmp_path / "out" / "atlas.json").read_text())
    assert saved["command"] == "atlas" and saved["status"] == "completed" and saved["points"] == a.points


def test_a_dask_cluster_gives_the_local_atlas_bit_for_bit(local):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        seen = []
        remote = pendulum.atlas(chain(), kinds=["sudden", "ramp-up"], ramp_time=4.0, client=client, chunk=5,
                                progress=lambda done, total: seen.append((done, total)), **GRID)
    assert remote.points == local.points
    for name in ["nodes", "settled", "tip_radius", "tip_signed", "nearest_nodes", "stable"]:
        assert np.array_equal(getattr(remote, name), getattr(local, name)), name
    assert [t for _, t in seen] == [24] * 5 and seen[-1][0] == 24


def test_ctrl_c_stops_an_atlas():
    assert_ctrl_c_interrupts(
        "c = pendulum.Chain([0.05] * 20, [0.05] * 20, damping=5e-4)",
        "pendulum.atlas(c, omega=[2.0, 3.0, 4.0, 5.0], radius=[0.01, 0.02], duration=1e5, step=0.003)",
    )
