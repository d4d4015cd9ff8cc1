"""Shared fixtures: the founding paper's Table 1 system at the onset of a collision.

Table 1 (Afsharfard & Farshidianfar 2012): M = 1 kg, K = 1 N/m, C = 0.01 N s/m,
m = 0.25 kg, c1 = 0.01 N s/m, K_hz = 3000 N/m^1.5; clearance 0.01 m and the
approach speed 0.1 m/s implied by the paper's Tc = 0.1089 s. The run starts at
contact onset: w = w' = 0, y - w = d, y' = 0.1 m/s.
"""

from __future__ import annotations

import inspect
import os
import resource
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import vibroimpact as vi

MAIN_MASS = 1.0
STIFFNESS = 1.0
DAMPING = 0.01
IMPACT_MASS = 0.25
CLEARANCE = 0.01
HERTZ_STIFFNESS = 3000.0
CONTACT_DAMPING = 0.01
APPROACH_SPEED = 0.1

# A complete scenario for the Table 1 collision, every key of the format given.
TABLE1_TOML = """\
# The founding paper's Table 1 collision.
[system]
main_mass = 1.0
stiffness = 1.0
damping = 0.01
impact_mass = 0.25
clearance = 0.01

[contact]
law = "hertz"
stiffness = 3000.0
damping = 0.01

[initial]
main_displacement = 0.0
main_velocity = 0.0
impact_displacement = 0.01
impact_velocity = 0.1

[solver]
method = "rk4"
dt = 1e-4
t_end = 0.2
beta = 0.25
gamma = 0.5
contact_timing = "located"

[output]
every = 7
"""


@pytest.fixture
def table1_system() -> vi.ImpactDamper:
    return vi.ImpactDamper(
        main_mass=MAIN_MASS,
        stiffness=STIFFNESS,
        damping=DAMPING,
        impact_mass=IMPACT_MASS,
        clearance=CLEARANCE,
    )


@pytest.fixture
def free_system() -> vi.ImpactDamper:
    """The Table 1 masses and clearance with no spring or damper: two free bodies."""
    return vi.ImpactDamper(
        main_mass=MAIN_MASS, stiffness=0.0, impact_mass=IMPACT_MASS, clearance=CLEARANCE
    )


@pytest.fixture
def hertz_contact() -> vi.Contact:
    return vi.Contact("hertz", stiffness=HERTZ_STIFFNESS, damping=CONTACT_DAMPING)


@pytest.fixture
def hyster_contact() -> vi.Contact:
    """Hyster-Hertz with e = 0.9, the paper's lossy case."""
    return vi.Contact(
        "hyster-hertz", stiffness=HERTZ_STIFFNESS, damping=CONTACT_DAMPING, restitution=0.9
    )


@pytest.fixture
def onset_state() -> vi.InitialState:
    """Contact onset: y - w = d, the impact mass approaching at 0.1 m/s."""
    return vi.InitialState(impact_displacement=CLEARANCE, impact_velocity=APPROACH_SPEED)


@pytest.fixture
def table1_toml() -> str:
    return TABLE1_TOML


@pytest.fixture
def write_scenario(tmp_path: Path) -> Callable[[str, str], Path]:
    """Write TOML text to a file in a temporary folder and return its path."""

    def write(text: str, name: str = "scenario.toml") -> Path:
        path = tmp_path / name
        path.write_text(text, encoding="utf-8")
        return path

    return write


# Address space of a command run by a test, bytes: a run whose history grows without
# bound fails there with an allocation error instead of taking the machine's memory.
SUBPROCESS_MEMORY = 2 << 30


def shell_signals() -> None:
    """For subprocess.Popen(preexec_fn=...): the child takes Ctrl-C (SIGINT), SIGHUP and
    SIGQUIT as a shell's child does. pytest-xdist's workers ignore them (so that Ctrl-C
    reaches its controller alone), a child inherits an ignored signal, and Python then
    installs no KeyboardInterrupt: a test interrupting its child waited for ever."""
    for name in ("SIGINT", "SIGHUP", "SIGQUIT"):
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), signal.SIG_DFL)


def limit_memory() -> None:
    """For subprocess.run(preexec_fn=...): cap the child's address space."""
    resource.setrlimit(resource.RLIMIT_AS, (SUBPROCESS_MEMORY, SUBPROCESS_MEMORY))


@pytest.fixture
def run_cli(tmp_path: Path) -> Callable[..., subprocess.CompletedProcess[str]]:
    """Run ``python -m vibroimpact ARGS`` in a temporary folder."""

    # Below pytest's per-test limit (60 s, pyproject.toml), so that a hung command
    # fails this test alone with its own message.
    def run(*args: str, timeout: float = 50.0) -> subprocess.CompletedProcess[str]:
        env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONWARNINGS": "error"}
        return subprocess.run(
            [sys.executable, "-m", "vibroimpact", *args],
            capture_output=True,
            text=True,
            cwd=tmp_path,
            env=env,
            timeout=timeout,
            check=False,
            preexec_fn=limit_memory,
        )

    return run


# Runs in the tests are bounded: a kernel whose steps collapse (a wrong error estimate,
# a Butcher coefficient off) must fail in seconds with SimulationError, not fill memory
# with an adaptive run's history until the machine gives out (it did: 8 GB in 60 s with
# one DOP853 weight changed). The largest run in the suite takes 3e5 steps.
TEST_MAX_STEPS = 2_000_000


@pytest.fixture(autouse=True)
def bounded_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    """Runs through vi.simulate or a scenario take at most TEST_MAX_STEPS steps, unless
    the test sets max_steps itself."""
    unbounded = vi.simulate
    # The defaults of simulate and of a scenario: a test that sets neither.
    defaults = (
        inspect.signature(unbounded).parameters["max_steps"].default,
        vi.scenario.two_mass.Scenario.max_steps,
    )

    def simulate(*args: Any, **kwargs: Any) -> vi.Solution:
        if kwargs.get("max_steps", defaults[0]) in defaults:
            kwargs["max_steps"] = TEST_MAX_STEPS
        return unbounded(*args, **kwargs)

    monkeypatch.setattr(vi, "simulate", simulate)
    monkeypatch.setattr(vi.scenario.two_mass, "simulate", simulate)
