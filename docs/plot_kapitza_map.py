#!/usr/bin/env python3
"""Draws docs/gallery/kapitza-map.png: which shakings hold an inverted chain upright.

    target/python/bin/python docs/plot_kapitza_map.py [OUTPUT_PNG]   # needs matplotlib

Chains of 1, 2 and 3 equal links (0.1 m, 0.1 kg each, no damping) stand upside down,
each link tilted by up to 0.05 rad from the top, at rest; the pivot is shaken vertically,
p(t) = A sin(ωt). Every (A, ω) of a 48 × 64 grid is one state of one call of
`Chain.trajectory(..., drive=pendulum.Harmonic(A, ω))`: 3072 chains per panel, 2 s each,
in steps of a fortieth of the fastest shaking's period. A chain counts as upright when no
link leaves 0.5 rad of the top in those 2 s. The dashed line is Kapitza's threshold for
one link, A ω = √(2 g l); the map's edge should sit on it in the first panel.
"""

import os
import sys
import time

import matplotlib
import numpy as np

import pendulum

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "gallery", "kapitza-map.png")
G, LINK, DURATION = 9.81, 0.1, 2.0
AMPLITUDES = np.linspace(0.001, 0.03, 48)  # m
OMEGAS = np.geomspace(50.0, 1500.0, 64)  # rad/s


def upright(n, rng):
    """Whether each (A, ω) of the grid holds the chain of `n` links upright: (48, 64)."""
    chain = pendulum.Chain([0.1] * n, [LINK] * n, gravity=G)
    amplitude, omega = np.meshgrid(AMPLITUDES, OMEGAS, indexing="ij")
    q0 = np.pi + rng.uniform(-0.05, 0.05, (*amplitude.shape, n))
    h = 2 * np.pi / OMEGAS.max() / 40
    steps = int(round(DURATION / h))
    start = time.perf_counter()
    _, q, _ = chain.trajectory(q0, h=h, steps=steps, every=20, drive=pendulum.Harmonic(amplitude, omega))
    seconds = time.perf_counter() - start
    print(f"n = {n}: {amplitude.size} chains × {steps} steps in {seconds:.1f} s")
    away = np.abs((q - np.pi + np.pi) % (2 * np.pi) - np.pi)  # from the top, wrapped
    return away.max(axis=(0, 3)) < 0.5


def main():
    rng = np.random.default_rng(7)
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2), sharey=True, constrained_layout=True)
    for n, ax in zip([1, 2, 3], axes):
        held = upright(n, rng)
        ax.pcolormesh(OMEGAS, AMPLITUDES * 1e3, held, cmap="Blues", vmin=-0.3, vmax=1.3, shading="nearest")
        ax.plot(OMEGAS, np.sqrt(2 * G * LINK) / OMEGAS * 1e3, "k--", lw=1, label="A ω = √(2 g l), one link")
        ax.set_xscale("log")
        ax.set_ylim(AMPLITUDES[0] * 1e3, AMPLITUDES[-1] * 1e3)
        ax.set_title(f"{n} link{'s' if n > 1 else ''} of 0.1 m: upright (blue) for 2 s")
        ax.set_xlabel("shaking ω (rad/s)")
    axes[0].set_ylabel("shaking amplitude A (mm)")
    axes[0].legend(loc="lower left", fontsize=8)
    fig.suptitle("Inverted chains held up by a vertically shaken pivot: 3 × 3072 driven runs, one call each")
    fig.savefig(OUT, dpi=110)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
