"""What the tests of 0.2 systems (test_system.py, test_system_inputs.py,
test_system_methods.py) share: the examples' paths and the command line.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BALL = {"kind": "oscillator", "mass": 0.2, "stiffness": 0.0}


def cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "vibroimpact", *args],
        capture_output=True,
        text=True,
        timeout=50,
        cwd=cwd,
    )


FREE_PAIR = {"kind": "matrices", "mass": [[1.0, 0.0], [0.0, 3.0]], "stiffness": [[0.0] * 2] * 2}
