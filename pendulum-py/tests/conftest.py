"""Shared helpers of the pendulum tests."""

from pathlib import Path

# The committed run.json / final.json pairs the Rust tests use too (written by `pendulum
# simulate` of the last release).
RUNS = Path(__file__).resolve().parents[2] / "pendulum-experiment" / "tests" / "runs"


def assert_ctrl_c_interrupts(setup, call):
    """Runs ``setup`` then ``call`` (Python source lines) in a child Python, sends it SIGINT
    a second after ``setup`` and asserts ``call`` raised KeyboardInterrupt within a second.

    The child installs Python's own Ctrl-C handler: started from a shell that ignores
    SIGINT in the background (as a CI job may be), Python would ignore it too."""
    import os
    import signal
    import subprocess
    import sys
    import time

    code = (
        "import pendulum, signal, sys\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        f"{setup}\n"
        "print('started', flush=True)\n"
        f"try:\n    {call}\nexcept KeyboardInterrupt:\n    print('interrupted', flush=True)\n    sys.exit(3)\n"
    )
    child = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "started"
    time.sleep(1.0)
    sent = time.monotonic()
    os.kill(child.pid, signal.SIGINT)
    out, _ = child.communicate(timeout=60)
    elapsed = time.monotonic() - sent
    assert child.returncode == 3 and "interrupted" in out, (child.returncode, out)
    assert elapsed < 1.0, f"KeyboardInterrupt {elapsed:.2f} s after SIGINT"
