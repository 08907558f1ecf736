"""Quick pictures of a run (matplotlib is optional: imported only when called)."""

from __future__ import annotations

from typing import Any


def _pyplot() -> Any:
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("plotting needs matplotlib: pip install matplotlib") from e
    return plt


def plot_ledger(result: Any, ax: Any = None) -> Any:
    """The energy H (J) against time (s) with what the ledger says it should be,
    H0 + W_drive + W_torque − E_damped; the two coincide up to the integrator's error."""
    plt = _pyplot()
    if ax is None:
        _, ax = plt.subplots(figsize=(7, 4))
    ledger = result.ledger
    h = ledger["energy"]
    predicted = h - ledger["balance_residual"]
    ax.plot(result.t, h, label="energy H (inertial frame)")
    ax.plot(result.t, predicted, "--", label="H0 + W_drive + W_torque − E_damped")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("energy (J)")
    ax.set_title("energy and its ledger")
    ax.legend()
    return ax


def plot_shape(result: Any, ax: Any = None) -> Any:
    """The chain's last sample seen from the side (x–z in 3D, x–y in 2D), with the
    rotation axis for a whirled chain and the shape answer in the title."""
    plt = _pyplot()
    if ax is None:
        _, ax = plt.subplots(figsize=(4, 6))
    p = result.positions[-1]
    three_d = bool(abs(p[:, 2]).max() > 0.0)
    x, up = p[:, 0], (p[:, 2] if three_d else p[:, 1])
    ax.plot(x, up, "o-", ms=2)
    title = f"t = {result.t_end:.3g} s"
    shape = result.shape
    if shape is not None:
        ax.axvline(0.0, color="grey", ls="--", lw=1, label="rotation axis")
        nodes = shape["nodes"]
        title += f": {nodes} node{'s' if nodes != 1 else ''}, tip radius {shape['tip_radius']:.3g} m"
        ax.legend()
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)" if three_d else "y (m)")
    ax.set_title(title)
    return ax
