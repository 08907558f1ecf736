"""The points of ``pendulum.sweep`` and ``pendulum.atlas`` (sweep.json's and atlas.json's)
as numpy arrays, one entry per point."""

from __future__ import annotations

from typing import Any, Callable

import numpy as np


def _column(points: list[dict[str, Any]], value: Callable[[dict[str, Any]], Any], empty: Any, dtype: Any) -> np.ndarray:
    return np.array([value(p["result"]) if p.get("result") else empty for p in points], dtype=dtype)


def _nearest(key: str, empty: Any) -> Callable[[dict[str, Any]], Any]:
    return lambda r: r["nearest"][key] if r.get("nearest") else empty


def result_arrays(points: list[dict[str, Any]]) -> dict[str, np.ndarray]:
    """The results of ``points``: ``nodes`` (−1 without a result), ``settled``,
    ``tip_radius``, ``tip_signed``, ``drift`` (m; NaN without a result), ``nearest_nodes``
    (−1: no steady shape found), ``stable``, ``growth_rate`` (1/s), ``balance_residual``
    (J), and ``status``."""
    key = lambda k: (lambda r: r[k])  # noqa: E731
    return {
        "nodes": _column(points, key("nodes"), -1, np.int64),
        "settled": _column(points, key("settled"), False, bool),
        "tip_radius": _column(points, key("tip_radius"), np.nan, float),
        "tip_signed": _column(points, key("tip_signed"), np.nan, float),
        "drift": _column(points, key("drift"), np.nan, float),
        "nearest_nodes": _column(points, _nearest("nodes", -1), -1, np.int64),
        "stable": _column(points, _nearest("stable", False), False, bool),
        "growth_rate": _column(points, _nearest("growth_rate", np.nan), np.nan, float),
        "balance_residual": _column(
            points, lambda r: r["balance"]["residual"] if r.get("balance") else np.nan, np.nan, float
        ),
        "status": np.array([p["status"] for p in points], dtype=object),
    }
