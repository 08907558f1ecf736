"""Run: the experiment `pendulum simulate` runs, from Python — the same description, the
same final state bit for bit, the ledger, the shape answer, files when asked, pickling,
bad input and Ctrl-C."""

import json
import pickle

import numpy as np
import pytest

import pendulum
from conftest import RUNS, assert_ctrl_c_interrupts


def test_the_demo_runs_to_arrays_and_its_ledger_closes():
    run = pendulum.Run()
    assert run.n == 3 and run.end == 10.0 and "gl2" in run.chosen
    result = run.run()
    assert result.status == "completed" and result.t_end == pytest.approx(10.0)
    samples = len(result.t)
    assert result.states.shape == (samples, 6)
    assert result.positions.shape == (samples, 4, 3)
    assert np.abs(result.ledger["balance_residual"]).max() < 1e-6
    # The positions are those of the angles: mass 1 at l_1 (sin θ_1, −cos θ_1).
    theta = result.states[:, 0]
    assert np.allclose(result.positions[:, 1, 0], 0.5 * np.sin(theta), atol=1e-12)
    assert np.allclose(result.positions[:, 1, 1], -0.5 * np.cos(theta), atol=1e-12)
    assert result.shape is None


@pytest.mark.parametrize("name", ["triple", "whirl", "dp"])
def test_a_cli_run_json_repeats_to_the_cli_final_state_bit_for_bit(name):
    run = pendulum.Run.load(RUNS / f"{name}.run.json")
    result = run.run()
    final = json.loads((RUNS / f"{name}.final.json").read_text())
    expected = np.array(final["coordinates"] + final["rates"])
    assert np.array_equal(result.final_state, expected)


def test_a_whirled_chain_says_which_shape_it_took():
    result = pendulum.Run(
        dim=3, n=12, lengths=0.1, initial="hanging", drive="circle", radius=0.08, omega=5.0,
        integrator="rk4", step=0.001, end=10.0, every=10,
    ).run()
    shape = result.shape
    assert shape is not None and shape["nodes"] >= 1 and shape["tip_radius"] > 0
    assert shape["nearest"] is None or shape["nearest"]["nodes"] >= 1
    # 3D states are unit link directions and their rates.
    u = result.final_state[:36].reshape(12, 3)
    assert np.allclose(np.linalg.norm(u, axis=1), 1.0, atol=1e-9)


def test_files_are_written_only_when_asked(tmp_path):
    run = pendulum.Run(n=2, end=1.0)
    run.run()
    assert not any(tmp_path.iterdir())
    result = run.run(out=tmp_path / "out")
    names = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert names == ["energy.csv", "final.json", "run.json", "trajectory.csv"]
    written = json.loads((tmp_path / "out" / "run.json").read_text())
    assert written["outcome"]["status"] == "completed"
    assert written["outcome"]["samples"] == len(result.t)
    again = pendulum.Run.load(tmp_path / "out" / "run.json").run()
    assert np.array_equal(again.final_state, result.final_state)


def test_runs_pickle_as_their_description():
    run = pendulum.Run(dim=3, n=4, drive="circle", radius=0.05, omega=4.0, end=2.0, damping=1e-3)
    again = pickle.loads(pickle.dumps(run))
    assert again.to_json() == run.to_json()
    assert json.loads(run.to_json())["integrator"] == "midpoint"
    assert np.array_equal(again.run().final_state, run.run().final_state)


def test_a_run_on_a_sampled_path_reads_its_file_and_keeps_the_samples(tmp_path):
    # A pivot lifted 5 cm and set down again over 1 s, at rest before and after.
    t = np.linspace(0.0, 1.0, 11)
    np.savetxt(tmp_path / "lift.txt", np.stack([t, 0.0 * t, 0.05 * np.sin(np.pi * t) ** 2], axis=-1))
    run = pendulum.Run(n=2, drive="sampled", path=tmp_path / "lift.txt", path_at_rest=True, end=2.0, initial="hanging")
    assert "drive=sampled" in repr(run)
    result = run.run()
    pivot_y = result.positions[:, 0, 1]
    after = pivot_y[result.t > 1.0]
    assert abs(pivot_y.max() - 0.05) < 2e-3 and np.all(after == after[0]) and abs(after[0]) < 1e-30
    assert np.max(np.abs(result.ledger["balance_residual"])) < 1e-9
    described = json.loads(run.to_json())["drive"]
    assert described["kind"] == "sampled" and described["at_rest"] and len(described["times"]) == 11
    (tmp_path / "lift.txt").unlink()
    assert np.array_equal(pendulum.Run.from_json(run.to_json()).run().final_state, result.final_state)
    # The rows as an array: the same run.
    rows = np.stack([t, 0.0 * t, 0.05 * np.sin(np.pi * t) ** 2], axis=-1)
    from_rows = pendulum.Run(n=2, drive="sampled", path=rows, path_at_rest=True, end=2.0, initial="hanging")
    assert json.loads(from_rows.to_json())["drive"]["file"] == "<array of shape [11, 3]>"
    assert np.array_equal(from_rows.run().final_state, result.final_state)
    with pytest.raises(ValueError, match=r"^path: <array of shape \[11, 3\]> holds 33 numbers, not rows of 4"):
        pendulum.Run(dim=3, n=2, drive="sampled", path=rows)
    with pytest.raises(ValueError, match=r"path: shape \[33\], expected rows of t, x, y\[, z\]"):
        pendulum.Run(n=2, drive="sampled", path=rows.ravel())


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"end": -1.0}, "^end must be finite and positive, got -1$"),
        ({"step": 0.0}, "^step must be finite and positive, got 0$"),
        ({"dim": 4}, "dim: 4 is neither 2 nor 3"),
        ({"drive": "square"}, "drive: 'square' is not one of fixed, harmonic, circle, sampled"),
        ({"drive": "sampled"}, r'^drive="sampled" needs path \(rows of t, x, y\[, z\]\)$'),
        ({"drive": "circle"}, r"^drive=\"circle\" moves the pivot on a horizontal circle: 3D only \(dim=3\)$"),
        ({"spin": 1.0}, r"^spin \(initial azimuthal rate\) applies to dim=3 only$"),
        ({"direction": [0.0, 1.0]}, '^direction applies to drive="harmonic" only$'),
        ({"every": 0}, "^every must be at least 1 step, got 0$"),
        ({"gravity": float("nan")}, "gravity g must be finite and non-negative, got NaN"),
        ({"dim": 3, "drive": "circle", "omega": float("inf")}, "^drive angular frequency must be finite, got inf$"),
        ({"drive": "harmonic", "direction": [0.0, 0.0]}, "^drive direction norm must be finite and positive, got 0$"),
        ({"masses": [1.0, 2.0], "n": 3}, "masses: got 2 values for 3 links"),
        ({"integrator": "euler"}, "integrator: 'euler' is not one of"),
        ({"initial": "sideways"}, "initial: 'sideways' is not hanging"),
        ({"tolerance": 1e-6}, '^tolerance applies to integrator="dp54" only$'),
        ({"masses": -1.0}, "mass of link 1 must be finite and positive"),
    ],
)
def test_bad_runs_are_value_errors_naming_the_keyword_argument(kwargs, message):
    # Refused when the run is described, before it runs.
    with pytest.raises(ValueError, match=message) as e:
        pendulum.Run(**kwargs)
    assert "\n" not in str(e.value) and "--" not in str(e.value)


def test_a_run_that_blows_up_reports_failed_with_its_samples():
    result = pendulum.Run(n=3, integrator="rk4", step=0.3, end=2.0).run()
    assert result.status == "failed" and "failed" in result.error
    assert len(result.t) >= 1 and result.t_end < 2.0


def test_an_energy_balance_that_is_off_is_a_runtime_warning():
    with pytest.warns(RuntimeWarning, match=r"the energy balance is off by 3\.806e0 J, 12\.9 %"):
        result = pendulum.Run(integrator="rk4", step=0.2, end=20.0).run()
    assert result.status == "completed"
    assert result.balance_residual == pytest.approx(3.806, abs=1e-3)
    assert result.warnings and result.warnings[0].startswith("the energy balance is off")
    good = pendulum.Run(end=20.0).run()
    assert good.warnings == [] and good.balance_residual < 1e-6 * good.energy_scale


def test_ctrl_c_interrupts_a_long_run_within_a_second():
    assert_ctrl_c_interrupts(
        "run = pendulum.Run(dim=3, n=200, initial='hanging', drive='circle', radius=0.02, omega=6.0,"
        " integrator='rk4', step=1e-4, end=1e4, every=1000)",
        "run.run()",
    )


def test_the_docs_whirl_takes_two_nodes_at_six_rad_per_second():
    """docs/python.md's example: the README's 100-link chain at ω = 6 rad/s."""
    run = pendulum.Run(dim=3, n=100, masses=0.01, lengths=0.01, damping=3e-4, initial="hanging",
                       drive="circle", radius=0.02, omega=6.0, integrator="rk4", step=0.001,
                       every=100, end=150.0)
    shape = run.run().shape
    assert shape["nodes"] == 2 and shape["settled"]
    assert shape["tip_radius"] == pytest.approx(4.4351e-2, rel=1e-4)
    assert shape["nearest"]["nodes"] == 2 and shape["nearest"]["stable"]


def test_a_written_run_shows_as_the_viewer_page_in_a_notebook(tmp_path):
    run = pendulum.Run(dim=3, n=6, lengths=0.1, initial="hanging", drive="circle", radius=0.05, omega=5.0,
                       integrator="rk4", step=0.002, end=6.0, every=5)
    assert run.run()._repr_html_() is None
    result = run.run(out=tmp_path)
    assert str(result.directory) == str(tmp_path)
    assert (tmp_path / "shape.json").exists()
    html = pendulum.page(tmp_path)
    assert html.startswith("<!doctype html>")
    assert '"links":6' in html and '"phases":[' in html
    cell = result._repr_html_()
    assert cell.startswith("<iframe srcdoc=") and "&quot;links&quot;:6" in cell
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match="holds no run: no run.json"):
        pendulum.page(tmp_path / "empty")


def test_the_heavy_string_has_kolodners_speeds_and_the_chains_shapes():
    string = pendulum.HeavyString(length=1.0, radius=0.02)
    speeds = string.critical_speeds(3)
    # (j_0k / 2) sqrt(g / L), with the zeros of J0 to 10 digits.
    expected = [2.404825558, 5.520078110, 8.653727913]
    assert np.allclose(speeds, [0.5 * j * np.sqrt(9.81) for j in expected], rtol=1e-9)
    shapes = string.shapes_at(3.0)
    assert len(shapes) == 1 and shapes[0]["nodes"] == 1
    # The 100-link chain's forced shape at 3 rad/s: tip radius 0.0735 m; the string's
    # within 1/n.
    assert abs(shapes[0]["tip_radius"] - 0.073534) < 0.02 * 0.073534
    x, depth = shapes[0]["x"], shapes[0]["depth"]
    assert x[0] == pytest.approx(0.02) and depth[0] == 0.0 and x.shape == depth.shape
    with pytest.raises(ValueError, match="string length must be finite and positive, got 0"):
        pendulum.HeavyString(length=0.0)
