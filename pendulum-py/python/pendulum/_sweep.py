"""``pendulum.sweep``: which shape a whirled chain chooses along a line of speeds, with the
hysteresis of sudden starts and ramps (``pendulum sweep``)."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any, Optional, Sequence, Union

import numpy as np

from ._pendulum import Chain, run_sweep
from ._points import result_arrays


@dataclass
class SweepResult:
    """A sweep's points, one entry per point and kind in the order of sweep.csv (per kind
    as given; sudden and ramp-up in the order of ``omega``, ramp-down in decreasing ω).

    ``kind`` ("sudden", "ramp-up", "ramp-down"), ``omega`` (rad/s), ``omega_scaled``
    (ω / √(g/L)); ``nodes`` (axis crossings + 1; −1 without a result), ``settled``,
    ``tip_radius``, ``tip_signed``, ``drift`` (m), ``nearest_nodes``, ``stable``,
    ``growth_rate`` (1/s), ``balance_residual`` (J), ``status``; ``duration``,
    ``ramp_time``, ``step`` (s); ``critical_speeds`` of the chain on a fixed pivot
    (rad/s); ``file``: sweep.json as a dict.
    """

    kind: np.ndarray
    omega: np.ndarray
    omega_scaled: np.ndarray
    nodes: np.ndarray
    settled: np.ndarray
    tip_radius: np.ndarray
    tip_signed: np.ndarray
    drift: np.ndarray
    nearest_nodes: np.ndarray
    stable: np.ndarray
    growth_rate: np.ndarray
    balance_residual: np.ndarray
    status: np.ndarray
    duration: float
    ramp_time: Optional[float]
    step: float
    critical_speeds: np.ndarray
    file: dict[str, Any] = field(repr=False)

    def of(self, kind: str) -> dict[str, np.ndarray]:
        """The points of one kind, as arrays named as the fields."""
        pick = self.kind == kind
        names = ["omega", "omega_scaled", "nodes", "settled", "tip_radius", "tip_signed", "drift",
                 "nearest_nodes", "stable", "growth_rate", "balance_residual", "status"]
        return {name: getattr(self, name)[pick] for name in names}


def sweep(
    chain: Chain,
    *,
    omega: Union[str, float, Sequence[float], np.ndarray],
    radius: float = 0.02,
    kinds: Union[str, Sequence[str]] = ("sudden", "ramp-up", "ramp-down"),
    scaled: bool = False,
    duration: Optional[float] = None,
    ramp_time: Optional[float] = None,
    step: Optional[float] = None,
    jobs: Optional[int] = None,
    out: Union[str, "os.PathLike[str]", None] = None,
) -> SweepResult:
    """``pendulum sweep``: ``chain`` (3D, with its damping) from hanging at rest at every
    speed of ``omega`` (rad/s, or in units of √(g/L), L the chain's length, with
    ``scaled``; numbers, or a string as ``--omega`` takes it, ``"0.5:5:24"`` for the
    command's evenly spaced speeds to the bit) with its pivot on a horizontal circle of ``radius`` (m), for each of
    ``kinds``: "sudden" (ω from t = 0), "ramp-up" (ω reached from rest over ``ramp_time``),
    "ramp-down" (the speeds in decreasing order, each from the previous point's end, ramped
    from the previous ω). The sudden and ramp-up points run as batches of chains on
    ``jobs`` threads (None: all cores), the ramp-down points one after the other; each is
    bit for bit the command's. ``duration``, ``ramp_time`` and ``step`` (s) default as the
    command's. With ``out``, sweep.json and sweep.csv are written there (``pendulum sweep``
    draws sweep.png). The GIL is released; Ctrl-C raises KeyboardInterrupt; bad input
    raises ValueError with the command's message.
    """
    if isinstance(omega, str):
        spec = omega
    else:
        # Each speed in its shortest form, which the command reads back exactly.
        spec = ",".join(repr(float(w)) for w in np.atleast_1d(np.asarray(omega, dtype=float)).ravel())
    kind_list = [kinds] if isinstance(kinds, str) else list(kinds)
    text = run_sweep(chain, spec, float(radius), kind_list, scaled, duration, ramp_time, step, jobs,
                     None if out is None else os.fspath(out))
    file = json.loads(text)
    points = file["points"]
    arrays = result_arrays(points)
    config = file["config"]
    return SweepResult(
        kind=np.array([p["kind"] for p in points], dtype=object),
        omega=np.array([p["omega"] for p in points]),
        omega_scaled=np.array([p["omega_scaled"] for p in points]),
        duration=float(config["duration"]),
        ramp_time=config.get("ramp_time"),
        step=float(config["step"]),
        critical_speeds=np.array(file["derived"]["critical_speeds"]),
        file=file,
        **arrays,
    )
