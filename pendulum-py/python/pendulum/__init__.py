"""Dynamics of N-link pendulums: chains of point masses on massless rigid rods, hung from a
pivot that may be fixed or driven, in 2D and 3D — from Rust, as numpy arrays.

- ``Chain``: a chain's parameters and its models evaluated on arrays (accelerations,
  the terms of ``M q̈ + c + k + d = Q``, energies, analytic Jacobians), many states per
  call along leading axes; many states stepped by RK4 per call (``integrate``, sampled by
  ``trajectory``, torques and pivot accelerations held, or the pivot moved by a drive);
  its normal modes and linearisation.
- ``Harmonic``, ``Circle``, ``Sampled``: pivot drives for those runs (shaken along a line,
  circling about the vertical, or on the spline through positions of one's own), their
  parameters one for all states or one per state.
- ``Run``: an experiment as ``pendulum simulate`` runs it (the same description as
  run.json), run to arrays with ``Run.run()``; a whirled chain's result says which shape it
  took (``RunResult.shape``).
- ``whirls(chain, radius=..., omega=..., ramp_time=...)``: many whirls from hanging at
  rest, one per circle and speed, run together as a batch of chains on all cores: which
  shape each ends in, as numpy arrays (the runs of ``pendulum sweep``).
- ``sweep(chain, omega=..., kinds=...)``: ``pendulum sweep``: which shape the chain chooses
  along a line of speeds, started suddenly, ramped up, or ramped down from point to point.
- ``atlas(chain, omega=..., radius=..., client=None)``: which shape the chain ends in from
  rest over a grid of two parameters (the map of ``pendulum atlas``), here on all cores or
  in chunks on a Dask cluster (``client``), bit for bit the same.
- ``steady(chain, ...)``: the steady shapes of the chain turning about the vertical, as
  ``pendulum steady`` finds them: branches with every point's nodes and stability, and
  every shape at the asked speeds.
- ``check_claims(path)``: a hand derivation (a claims file, equations in index notation)
  checked against the sympy reference built into the package, slips diagnosed.
- ``HeavyString``: Kolodner's heavy rotating string, the continuum a uniform chain of many
  links approaches: its critical speeds and steady shapes (fixed or circling top).
- ``page(directory)``: the self-contained page of ``pendulum view`` for a run written with
  ``Run.run(out=...)``; in a notebook such a result displays as that page.
- ``plot_ledger``, ``plot_shape``: quick matplotlib pictures (matplotlib optional).

SI units throughout, angles in radians. See ``docs/python.md`` in the repository.
"""

from ._atlas import Atlas, atlas
from ._claims import ClaimCheck, ClaimsReport, check_claims
from ._pendulum import (
    AtlasPlan,
    Chain,
    Circle,
    Harmonic,
    HeavyString,
    Run,
    RunResult,
    Sampled,
    __version__,
    page,
    steady,
    whirls,
)
from ._sweep import SweepResult, sweep
from ._plots import plot_ledger, plot_shape

__all__ = [
    "Atlas",
    "AtlasPlan",
    "atlas",
    "Chain",
    "Circle",
    "ClaimCheck",
    "ClaimsReport",
    "check_claims",
    "Harmonic",
    "HeavyString",
    "Run",
    "RunResult",
    "Sampled",
    "__version__",
    "page",
    "plot_ledger",
    "plot_shape",
    "steady",
    "sweep",
    "SweepResult",
    "whirls",
]
