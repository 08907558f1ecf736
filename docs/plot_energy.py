#!/usr/bin/env python3
"""Draws docs/energy.png from the CSV files of the energy_long_run example.

    cargo run --release -p pendulum-core --example energy_long_run   # writes docs/data/
    python3 docs/plot_energy.py [DATA_DIR] [OUTPUT_PNG]              # needs matplotlib

Four panels: (a) the largest |ΔH|/(m g l) in each sample window against t, one curve
per method and form; (b) the Gauss s = 2 bound over 1000 s against h, with an h^4 line;
(c) Gauss s = 3: the RMS of ΔH/(m g l) over an ensemble of 16 starts 1e-9 rad apart,
with √t and t lines; (d) Gauss s = 2: the running maximum of |ΔH| over the ensemble.
"wrapped" runs bring the angles back to (−π, π] whenever one leaves (−3π, 3π).
"""

import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "data")
OUT = sys.argv[2] if len(sys.argv) > 2 else os.path.join(HERE, "energy.png")


def read(name):
    with open(os.path.join(DATA, name + ".csv")) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def summary():
    with open(os.path.join(DATA, "summary.csv")) as f:
        return {r["run"]: r for r in csv.DictReader(f)}


VEL = r"$(q,\dot q)$"
CAN = r"$(q,p)$"

fig, axes = plt.subplots(2, 2, figsize=(14, 10.5))

# (a) long runs
ax = axes[0, 0]
curves = [
    ("gl2_velocity_h0.01_n10000000", f"GL s=2, h=0.01, {VEL}", "tab:orange"),
    ("gl2_canonical_h0.01_n10000000", f"GL s=2, h=0.01, {CAN}", "tab:blue"),
    ("gl3_velocity_h0.001_n1000000", f"GL s=3, h=0.001, {VEL}", "tab:red"),
    ("gl3_canonical_h0.001_n1000000", f"GL s=3, h=0.001, {CAN}", "tab:purple"),
    ("gl3_canonical_h0.001_n1000000_wrapped", f"GL s=3, h=0.001, {CAN}, angles wrapped", "tab:pink"),
    ("rk4_velocity_h0.01_n1000000", f"RK4, h=0.01, {VEL}", "tab:green"),
    ("rk4_velocity_h0.001_n1000000", f"RK4, h=0.001, {VEL}", "tab:brown"),
]
for name, label, color in curves:
    d = read(name)
    pts = [(t, m) for t, m in zip(d["t"], d["window_max_abs_dH"]) if m > 0]
    ax.loglog([p[0] for p in pts], [p[1] for p in pts], color=color, lw=0.8, label=label)
ax.axhline(1e-11, color="k", ls=":", lw=0.8)
ax.text(1.2e-3, 1.5e-11, "1e-11 (target for GL s=3)", fontsize=7)
ax.set_xlabel("t (s)")
ax.set_ylabel("max |ΔH| / (m g l) in each sample window")
ax.set_title("(a) energy error, chaotic double pendulum, one run each")
ax.grid(True, which="major", alpha=0.3)
ax.legend(fontsize=7, loc="upper left")

# (b) h^4 scaling of the Gauss s = 2 bound
ax = axes[0, 1]
s = summary()
for form, color, label in [("velocity", "tab:orange", VEL), ("canonical", "tab:blue", CAN)]:
    runs = [f"gl2_{form}_h0.02_n50000", f"gl2_{form}_h0.01_n1000000", f"gl2_{form}_h0.005_n200000"]
    hs = [float(s[r]["h"]) for r in runs]
    bounds = [float(s[r]["max_abs_dH_t1000"]) for r in runs]
    ax.loglog(hs, bounds, "o-", color=color, label=f"GL s=2, {label}")
ref = bounds[1]
ax.loglog([0.005, 0.02], [ref * (0.005 / 0.01) ** 4, ref * (0.02 / 0.01) ** 4], "k:", label=r"$\propto h^4$")
ax.set_xlabel("h (s)")
ax.set_ylabel("max |ΔH| / (m g l) over 0 ≤ t ≤ 1000 s")
ax.set_title("(b) GL s=2: the bound shrinks like h⁴")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=8)

# (c) Gauss s = 3 ensembles: round-off
ax = axes[1, 0]
for name, label, color in [
    ("ensemble16_gl3_velocity_h0.001_n1000000", f"{VEL}", "tab:red"),
    ("ensemble16_gl3_canonical_h0.001_n1000000", f"{CAN}", "tab:purple"),
    ("ensemble16_gl3_velocity_h0.001_n1000000_wrapped", f"{VEL}, angles wrapped", "tab:gray"),
    ("ensemble16_gl3_canonical_h0.001_n1000000_wrapped", f"{CAN}, angles wrapped", "tab:pink"),
]:
    d = read(name)
    pts = [(t, r) for t, r in zip(d["t"], d["rms_dH"]) if r > 0]
    ax.loglog([p[0] for p in pts], [p[1] for p in pts], color=color, lw=0.9, label=f"GL s=3, h=0.001, {label}")
t0, t1 = 1.0, 1000.0
ax.loglog([t0, t1], [1.6e-16, 1.6e-16 * (t1 / t0) ** 0.5], "k:", lw=1, label=r"$\propto \sqrt{t}$ (Brouwer)")
ax.loglog([t0, t1], [8e-17, 8e-17 * (t1 / t0)], "k--", lw=1, label=r"$\propto t$")
ax.set_xlabel("t (s)")
ax.set_ylabel("RMS of ΔH / (m g l) over 16 starts 1e-9 rad apart")
ax.set_title("(c) GL s=3: round-off random walk, ensemble RMS")
ax.grid(True, which="major", alpha=0.3)
ax.legend(fontsize=8, loc="upper left")

# (d) Gauss s = 2 ensembles: running maximum over all members
ax = axes[1, 1]
for name, label, color in [
    ("ensemble16_gl2_velocity_h0.01_n1000000", VEL, "tab:orange"),
    ("ensemble16_gl2_canonical_h0.01_n1000000", CAN, "tab:blue"),
]:
    d = read(name)
    running, m = [], 0.0
    for t, x in zip(d["t"], d["max_abs_dH"]):
        m = max(m, x)
        running.append((t, m))
    pts = [p for p in running if p[1] > 0]
    ax.loglog([p[0] for p in pts], [p[1] for p in pts], color=color, lw=1.2, label=f"running max, {label}")
    pts = [(t, r) for t, r in zip(d["t"], d["rms_dH"]) if r > 0]
    ax.loglog([p[0] for p in pts], [p[1] for p in pts], color=color, lw=0.5, alpha=0.5, label=f"RMS, {label}")
ax.set_xlabel("t (s)")
ax.set_ylabel("|ΔH| / (m g l), 16 starts 1e-9 rad apart")
ax.set_title("(d) GL s=2, h=0.01: bounded in (q, p), creeping in (q, q̇)")
ax.grid(True, which="major", alpha=0.3)
ax.legend(fontsize=8, loc="lower right")

fig.tight_layout()
fig.savefig(OUT, dpi=100)
print("wrote", OUT)
