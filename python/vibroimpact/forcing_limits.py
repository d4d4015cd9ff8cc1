"""The forcing periods an analysis can run: a run steps at least once in each period of
the structure's fastest mode, so a forcing period of more than ``max_steps`` of those
is beyond any run (a sweep from 1e-300 Hz had failed each point as a numerical blow-up
advising a smaller dt). Refused when the analysis is set up, naming the frequency and
the lowest one a run can take. SI units.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact._core import InvalidInputError
from vibroimpact.messages import shown
from vibroimpact.system import linear_parts


def fastest_mode(data: Mapping[str, Any], base_dir: Path | None = None) -> float:
    """The highest natural frequency (Hz) of the system between contacts (structure and
    dampers, ``M x'' + K x = 0``); 0 where nothing is held by a spring."""
    parts = linear_parts(
        data["structure"],
        damper=data.get("damper", ()),
        stop=data.get("stop", ()),
        gravity=data.get("gravity"),
        excitation=data.get("excitation", ()),
        base_dir=base_dir,
    )
    # M = L L^T: the eigenvalues of L^-1 K L^-T are w^2.
    lower = np.linalg.cholesky(parts["mass"])
    inverse = np.linalg.inv(lower)
    squares = np.linalg.eigvalsh(inverse @ parts["stiffness"] @ inverse.T)
    return math.sqrt(max(float(squares[-1]), 0.0)) / (2 * math.pi)


def check_forcing_period(
    data: Mapping[str, Any], period: float, max_steps: int, base_dir: Path | None = None
) -> None:
    """Refuse a forcing ``period`` (s) that spans more than ``max_steps`` periods of the
    system's fastest mode: no run can step through one of them."""
    highest = fastest_mode(data, base_dir)
    if highest > 0 and period * highest > max_steps:
        raise InvalidInputError(
            f"forcing frequency {shown(1 / period)} Hz: its period, {period:.6g} s, spans "
            f"{period * highest:.3g} periods of the system's fastest mode ({highest:.6g} Hz), "
            f"more than a run's max_steps ({max_steps}) steps through; give a frequency of at "
            f"least {highest / max_steps:.3g} Hz"
        )


def check_axis_frequencies(
    data: Mapping[str, Any], axes: Mapping[str, Any], base_dir: Path | None = None
) -> None:
    """A study's axes of excitation frequencies (``"excitation.0.frequency"``): the
    lowest value of each, in the study's base scenario, checked as
    :func:`check_forcing_period` checks an analysis's (the error names the axis)."""
    # Imported here: the analyses import this module.
    from vibroimpact.analyses import _prepare, forcing_period, with_parameter

    for path, values in axes.items():
        parts = str(path).split(".")
        if len(parts) != 3 or parts[0] != "excitation" or parts[2] != "frequency":
            continue
        lowest = float(np.min(np.asarray(values, dtype=float)))
        changed = with_parameter(data, str(path), lowest)
        try:
            period = forcing_period(changed)
            check_forcing_period(changed, period, _prepare(changed, base_dir).solver["max_steps"])
        except InvalidInputError as err:
            if not str(err).startswith("forcing frequency"):
                continue  # the study's own check of the axis says what else is wrong
            raise InvalidInputError(f"[study.axes] {path!r}: {err}") from None
