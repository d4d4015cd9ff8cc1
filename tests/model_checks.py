"""What the tests of the typed model (test_model.py, test_model_results.py) share."""

from __future__ import annotations

from pathlib import Path

import vibroimpact as vi

ROOT = Path(__file__).resolve().parents[1]


def issue_example() -> vi.System:
    return vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=3947.8, damping=2.513),
        dampers=[vi.Damper(mass=0.05, at=0, clearance=0.005, law="rigid", restitution=0.6)],
        excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=5.0, frequency=10.0))],
    )
