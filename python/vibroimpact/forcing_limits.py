"""The forcing periods an analysis can run: an adaptive or exact run steps at least once
in each period of the structure's fastest mode, so a forcing period of more than
``max_steps`` of those is beyond it (a sweep from 1e-300 Hz had failed each point as a
numerical blow-up advising a smaller dt); a fixed-step run takes ``period / dt`` steps
whatever the modes (an implicit method is stable on a mode far faster than its step).
Refused when the analysis is set up, naming the frequency and the lowest one a run can
take. SI units.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact._core import InvalidInputError
from vibroimpact.messages import shown
from vibroimpact.system import _FIXED_STEP, linear_parts

# Fastest modes by the sections that fix M and K (see fastest_mode), a few at a time.
_FASTEST: dict[str, float] = {}


def fastest_mode(data: Mapping[str, Any], base_dir: Path | None = None) -> float:
    """The highest natural frequency (Hz) of the system between contacts (structure and
    dampers, ``M x'' + K x = 0``); 0 where nothing is held by a spring."""
    structure, damper, stop = data["structure"], data.get("damper", ()), data.get("stop", ())
    # M and K come from these sections alone (no file), and a sweep asks at every point
    # for the same ones: parsing them again had been a tenth of an FRF's time. Only
    # plain values are keyed by their repr (NumPy's rounds and elides).
    key = repr((structure, damper, stop))
    if "array(" in key or key not in _FASTEST:
        parts = linear_parts(structure, damper=damper, stop=stop, base_dir=base_dir)
        # M = L L^T: the eigenvalues of L^-1 K L^-T are w^2.
        lower = np.linalg.cholesky(parts["mass"])
        inverse = np.linalg.inv(lower)
        squares = np.linalg.eigvalsh(inverse @ parts["stiffness"] @ inverse.T)
        if len(_FASTEST) >= 64:
            _FASTEST.clear()
        _FASTEST[key] = math.sqrt(max(float(squares[-1]), 0.0)) / (2 * math.pi)
    return _FASTEST[key]


def check_forcing_period(
    data: Mapping[str, Any], period: float, max_steps: int, base_dir: Path | None = None
) -> None:
    """Refuse a forcing ``period`` (s) that spans more than ``max_steps`` periods of the
    system's fastest mode (more than ``max_steps`` steps of ``dt`` for a fixed-step
    method): no run can step through one of them."""
    solver = data.get("solver", {})
    if solver.get("method") in _FIXED_STEP:
        # Checked by the run's own settings: a fixed step is given.
        dt = float(solver["dt"])
        if period / dt > max_steps:
            raise InvalidInputError(
                f"forcing frequency {shown(1 / period)} Hz: its period, {period:.6g} s, "
                f"takes {period / dt:.3g} steps of dt = {shown(dt)} s, more than a run's "
                f"max_steps ({max_steps}); give a frequency of at least "
                f"{1 / (max_steps * dt):.3g} Hz"
            )
        return
    highest = fastest_mode(data, base_dir)
    if highest > 0 and period * highest > max_steps:
        raise InvalidInputError(
            f"forcing frequency {shown(1 / period)} Hz: its period, {period:.6g} s, spans "
            f"{period * highest:.3g} periods of the system's fastest mode ({highest:.6g} Hz), "
            f"more than a run's max_steps ({max_steps}) steps through; give a frequency of at "
            f"least {highest / max_steps:.3g} Hz"
        )
