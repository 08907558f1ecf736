"""Shared helpers of the pendulum tests."""

from pathlib import Path

# The committed run.json / final.json pairs the Rust tests use too (written by `pendulum
# simulate` of the last release).
RUNS = Path(__file__).resolve().parents[2] / "pendulum-experiment" / "tests" / "runs"
