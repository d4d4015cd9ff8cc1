"""The sweep plot's dashed linear curve (the structure without dampers and stops) is
drawn on a fine grid across the swept range, so that its resonance peak shows even
where the sweep's own values step over it.

Independent reference: a damped oscillator's closed-form peak, F / (k 2 zeta
sqrt(1 - zeta^2)) at f_n sqrt(1 - 2 zeta^2)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import vibroimpact as vi
from vibroimpact.analysis import plots

MASS, STIFFNESS, ZETA, FORCE = 1.0, (2 * math.pi * 20.4) ** 2, 0.01, 1.0


def dashed_lines(monkeypatch: pytest.MonkeyPatch, tmp_path: Path, data: Any, values: Any) -> list:
    system = vi.System(
        structure=vi.Oscillator(
            mass=MASS, stiffness=STIFFNESS, damping=2 * ZETA * math.sqrt(STIFFNESS * MASS)
        ),
        dampers=[vi.Damper(mass=0.01, at=0, clearance=1.0, law="rigid", restitution=0.5)],
        excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=FORCE, frequency=20.0))],
        solver=vi.Solver(method="exact"),
    )
    points = vi.sweep(system, "excitation.0.frequency", values, settle_periods=2, record_periods=2)
    figures: list[Any] = []
    monkeypatch.setattr(plots, "_save", lambda fig, path: figures.append(fig))
    plots.plot_sweep(
        tmp_path / "sweep.png",
        "excitation.0.frequency",
        points,
        system.to_dict() if data else None,
    )
    (figure,) = figures
    return [line for line in figure.axes[0].get_lines() if line.get_linestyle() == "--"]


def test_the_linear_curve_reaches_the_closed_form_peak(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    values = np.arange(17.0, 25.0)  # 1 Hz apart: 20 and 21 Hz straddle the peak
    (line,) = dashed_lines(monkeypatch, tmp_path, True, values)
    x, y = line.get_xdata(), line.get_ydata()
    peak = FORCE / (STIFFNESS * 2 * ZETA * math.sqrt(1 - ZETA**2))
    peak_frequency = 20.4 * math.sqrt(1 - 2 * ZETA**2)
    assert x.min() == 17.0 and x.max() == 24.0
    assert np.max(y) == pytest.approx(peak, rel=1e-3)
    assert x[np.argmax(y)] == pytest.approx(peak_frequency, abs=0.01)
    # At the sweep's own values the curve is the sweep's linear amplitude.
    on_values = np.interp(values, x, y)
    closed = FORCE / np.hypot(
        STIFFNESS - MASS * (2 * np.pi * values) ** 2,
        2 * ZETA * math.sqrt(STIFFNESS * MASS) * 2 * np.pi * values,
    )
    np.testing.assert_allclose(on_values, closed, rtol=1e-9)
    # The sweep's values alone show about half of the peak (the defect this fixes).
    assert closed.max() < 0.7 * peak


def test_without_the_sections_the_curve_is_drawn_at_the_sweep_values(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    values = np.array([19.0, 18.0, 20.0])
    (line,) = dashed_lines(monkeypatch, tmp_path, False, values)
    assert list(line.get_xdata()) == [18.0, 19.0, 20.0]
