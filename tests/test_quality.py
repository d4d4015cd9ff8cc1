"""The extension's type stub matches the compiled module."""

import subprocess
import sys


def test_stub_matches_the_extension_module() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "vibroimpact._core"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stdout + done.stderr
