"""Ctrl-C reaches a long run: the GIL is released and signals are checked."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import shell_signals
from study_checks import FORCED_DAMPER  # noqa: E402

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
        preexec_fn=shell_signals,
    )
    assert proc.stdout is not None and proc.stdout.readline().strip() == "started"
    time.sleep(0.3)
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=30)
    assert time.monotonic() - sent < 5.0
    assert proc.returncode != 0
    assert "KeyboardInterrupt" in err


LONG_STUDY = FORCED_DAMPER.replace('method = "exact"', 'method = "dopri5"') + (
    '[study]\nanalysis = "run"\nmetrics = ["peak"]\nchunk_size = 4\n'
    '[study.axes]\n"excitation.0.frequency" = [9.0, 10.0, 11.0, 12.0]\n'
)


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT semantics")
def test_sigint_stops_a_study_within_its_chunk(tmp_path: Path) -> None:
    # Runs of 1e6 s each: the runs of a chunk ran on the study's threads, where the
    # signal was never looked at, so Ctrl-C waited for the whole chunk (30 s, or for
    # ever; user trial). Now within moments, exit 130, no file written.
    scenario = tmp_path / "study.toml"
    scenario.write_text(LONG_STUDY.replace("t_end = 0.5", "t_end = 1e6"), encoding="utf-8")
    out = tmp_path / "out.nc"
    proc = subprocess.Popen(
        [sys.executable, "-m", "vibroimpact", "study", str(scenario), "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=shell_signals,
    )
    # Once the study has started its chunks (its parts folder made), not while Python
    # is still starting.
    manifest = tmp_path / "out.nc.parts" / "manifest.json"
    deadline = time.monotonic() + 60
    while not manifest.exists() and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
    assert manifest.exists()
    time.sleep(0.5)
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert time.monotonic() - sent < 5.0
    assert proc.returncode == 130, err
    assert "interrupted" in err and "Traceback" not in err
    # It says that nothing was kept (no chunk had finished).
    assert "vibroimpact: 0 of 1 chunks (0 of 4 runs) done: nothing kept" in err
    assert not out.exists()
    assert not (tmp_path / "out.nc.parts").exists()
