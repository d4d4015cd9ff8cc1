"""Ctrl-C reaches a long run: the GIL is released and signals are checked."""

from __future__ import annotations

import signal
import subprocess
import sys
import time

import pytest

LONG_RUN = """
import vibroimpact as vi
system = vi.ImpactDamper(main_mass=1.0, stiffness=1.0, impact_mass=0.25, clearance=0.01)
contact = vi.Contact("hertz", stiffness=3000.0)
print("started", flush=True)
start = vi.InitialState(main_displacement=0.05, impact_displacement=0.05)  # released together
vi.simulate(system, contact, start, method="rk4",
            dt=1e-6, t_end=1e4, every=10**9, max_steps=10**11)
"""


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT semantics")
def test_sigint_interrupts_a_long_run_with_keyboard_interrupt() -> None:
    # 1e10 steps would take minutes; the run must stop within a second of Ctrl-C.
    proc = subprocess.Popen(
        [sys.executable, "-c", LONG_RUN],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout is not None and proc.stdout.readline().strip() == "started"
    time.sleep(0.3)
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=30)
    assert time.monotonic() - sent < 5.0
    assert proc.returncode != 0
    assert "KeyboardInterrupt" in err
