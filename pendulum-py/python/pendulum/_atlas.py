"""``pendulum.atlas``: which shape a whirled chain at rest ends in over a grid of two
parameters, run here on all cores or as chunks on a Dask cluster (bit for bit the same)."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np

from ._pendulum import AtlasPlan, Chain
from ._points import result_arrays

Numbers = Union[float, Sequence[float], np.ndarray]


def _run_chunk(plan: AtlasPlan, indices: list[int], threads: Optional[int]) -> str:
    """One task: the points ``indices`` of ``plan`` as atlas.json's points (JSON)."""
    return plan.run(indices, threads=threads)


@dataclass
class Atlas:
    """An atlas's result. The grids have shape ``(len(kinds), len(y), len(x))``: row ``iy``,
    column ``ix`` is the point at ``x[ix]``, ``y[iy]``.

    ``nodes``: axis crossings + 1 (the pivot counted; −1 where there is no result);
    ``settled``: the shape had settled (drift ≤ 1e-3 L over the last 5 drive periods);
    ``tip_radius``, ``tip_signed`` (m, + on the pivot's side; NaN without a result);
    ``nearest_nodes`` (−1: no steady shape found), ``stable``, ``growth_rate`` (1/s): the
    damped steady shape nearest the final shape; ``status``: "completed", "failed" or
    "pending". ``x``, ``y`` in SI units (ω in rad/s), named by ``x_name``, ``y_name``
    ("omega", "radius", "damping", "ramp-time"). ``points`` are atlas.json's points;
    ``save(directory)`` writes atlas.json (then ``pendulum atlas --from DIR/atlas.json
    --out DIR`` draws atlas.png and writes atlas.csv without running anything).
    """

    plan: AtlasPlan
    x_name: str
    x: np.ndarray
    y_name: str
    y: np.ndarray
    kinds: tuple[str, ...]
    nodes: np.ndarray
    settled: np.ndarray
    tip_radius: np.ndarray
    tip_signed: np.ndarray
    nearest_nodes: np.ndarray
    stable: np.ndarray
    growth_rate: np.ndarray
    status: np.ndarray
    duration: float
    step: float
    critical_speeds: np.ndarray
    points: list[dict[str, Any]] = field(repr=False)

    def save(self, directory: str) -> None:
        """Writes ``directory``/atlas.json as ``pendulum atlas`` does."""
        self.plan.save(directory, json.dumps(self.points))

    def plot(self, ax: Any = None, kind: int = 0) -> Any:
        """The node count of kind ``kind`` over the grid as a matplotlib image (pale where
        the chain had not settled); returns the axes. Needs matplotlib."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        nodes = np.where(self.nodes[kind] < 0, np.nan, self.nodes[kind]).astype(float)
        image = ax.pcolormesh(self.x, self.y, nodes, shading="nearest", cmap="tab10", vmin=0.5, vmax=10.5)
        unsettled = ~self.settled[kind] & (self.nodes[kind] >= 0)
        xx, yy = np.meshgrid(self.x, self.y)
        ax.plot(xx[unsettled], yy[unsettled], "k.", markersize=3, label="not settled")
        ax.set_xlabel(self.x_name)
        ax.set_ylabel(self.y_name)
        ax.set_title(f"nodes, {self.kinds[kind]} start")
        ax.figure.colorbar(image, ax=ax, label="nodes")
        return ax


def atlas(
    chain: Chain,
    *,
    omega: Numbers,
    radius: Numbers,
    damping: Optional[Numbers] = None,
    ramp_time: Optional[Numbers] = None,
    kinds: Union[str, Sequence[str]] = "sudden",
    scaled: bool = False,
    duration: Optional[float] = None,
    step: Optional[float] = None,
    client: Any = None,
    chunk: int = 256,
    threads_per_task: Optional[int] = 1,
    progress: Optional[Callable[[int, int], None]] = None,
) -> Atlas:
    """Which shape ``chain`` (3D) ends in from hanging at rest, over a grid of two
    parameters: the atlas of ``pendulum atlas``.

    Two of ``omega`` (rad/s; in units of √(g/L), L the chain's length, with ``scaled``),
    ``radius`` (m), ``damping`` (one λ for every link, N·m·s; None: the chain's own) and
    ``ramp_time`` (s) are sequences of two or more values: the axes (the first in that
    order runs along x); the others one number. ``kinds``: "sudden" (ω from t = 0) and/or
    "ramp-up" (ω ramped from rest over ``ramp_time``, default a third of ``duration``).
    ``duration`` and ``step`` (s) default as ``pendulum atlas`` (and ``pendulum sweep``)
    choose them. Every point is the run of ``pendulum simulate`` with its parameters.

    Without ``client`` the grid runs here as one batch of chains on all cores (the GIL
    released; Ctrl-C raises KeyboardInterrupt). With a ``dask.distributed`` client the grid
    is cut into chunks of ``chunk`` points, each a task run on ``threads_per_task`` threads
    (None: all of the worker's cores), and the results come back as they finish
    (``progress(done, total)`` is called after each chunk); they equal the local run's bit
    for bit. Bad input raises ValueError with the message of the command line.
    """
    kind_list = [kinds] if isinstance(kinds, str) else list(kinds)
    plan = AtlasPlan(
        chain,
        omega=_numbers(omega),
        radius=_numbers(radius),
        damping=None if damping is None else _numbers(damping),
        ramp_time=None if ramp_time is None else _numbers(ramp_time),
        kinds=kind_list,
        scaled=scaled,
        duration=duration,
        step=step,
    )
    if not (isinstance(chunk, (int, np.integer)) and chunk >= 1):
        raise ValueError(f"chunk: {chunk!r} is not a whole number ≥ 1")
    total = len(plan)
    points: list[Optional[dict[str, Any]]] = [None] * total
    if client is None:
        for i, p in enumerate(json.loads(plan.run(list(range(total))))):
            points[i] = p
        if progress is not None:
            progress(total, total)
    else:
        from distributed import as_completed

        chunks = [list(range(start, min(start + chunk, total))) for start in range(0, total, chunk)]
        futures = {client.submit(_run_chunk, plan, c, threads_per_task, pure=False): c for c in chunks}
        done = 0
        for future in as_completed(list(futures)):
            indices = futures[future]
            for i, p in zip(indices, json.loads(future.result())):
                points[i] = p
            done += len(indices)
            if progress is not None:
                progress(done, total)
    return _assemble(plan, [p for p in points if p is not None])


def _numbers(value: Numbers) -> Union[float, list[float]]:
    array = np.asarray(value, dtype=float)
    return float(array) if array.ndim == 0 else [float(v) for v in array.ravel()]


def _assemble(plan: AtlasPlan, points: list[dict[str, Any]]) -> Atlas:
    config = json.loads(plan.to_json())
    derived = json.loads(plan.derived_json())
    x, y = np.array(config["x"]["values"]), np.array(config["y"]["values"])
    kinds = tuple(config["kinds"])
    grids = {k: v.reshape(len(kinds), len(y), len(x)) for k, v in result_arrays(points).items()}
    return Atlas(
        plan=plan,
        x_name=config["x"]["parameter"],
        x=x,
        y_name=config["y"]["parameter"],
        y=y,
        kinds=kinds,
        nodes=grids["nodes"],
        settled=grids["settled"],
        tip_radius=grids["tip_radius"],
        tip_signed=grids["tip_signed"],
        nearest_nodes=grids["nearest_nodes"],
        stable=grids["stable"],
        growth_rate=grids["growth_rate"],
        status=grids["status"],
        duration=float(config["duration"]),
        step=float(config["step"]),
        critical_speeds=np.array(derived["critical_speeds"]),
        points=points,
    )
