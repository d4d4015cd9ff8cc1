"""What the study tests share: a forced impact damper's scenario (rigid impacts), a
study loaded from scenario text, and the check of a refused study command."""

from __future__ import annotations

import subprocess
from pathlib import Path

import vibroimpact as vi
from vibroimpact import study as st
from vibroimpact.scenario.system import SystemScenario

# A 10 Hz structure with 2 % damping, a 0.05 kg loose mass with 5 mm clearance each side
# and rigid impacts (e = 0.6), forced by 5 N at 10 Hz; the exact method.
FORCED_DAMPER = """
[structure]
kind = "oscillator"
mass = 1.0
stiffness = 3947.8
damping = 2.513

[[damper]]
mass = 0.05
at = 0
clearance = 0.005
law = "rigid"
restitution = 0.6

[[excitation]]
kind = "force"
at = 0
signal = "harmonic"
amplitude = 5.0
frequency = 10.0

[solver]
method = "exact"
t_end = 0.5
"""


def load_study(path: Path, text: str) -> st.Study:
    """The study of the scenario ``text``, written to ``path`` (a .toml file)."""
    path.write_text(text)
    sc = vi.load_scenario(path)
    assert isinstance(sc, SystemScenario)
    return st.study_of(sc.data, str(path), sc.base_dir)


def assert_refused(done: subprocess.CompletedProcess[str], words: list[str], out: Path) -> None:
    """A study command refused: exit 2, one line on stderr naming each of ``words``, no
    traceback, and no ``out`` written."""
    assert done.returncode == 2, done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in done.stderr
    for word in words:
        assert word in lines[0], lines[0]
    assert not out.exists()
