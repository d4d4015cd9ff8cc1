"""A system's linear parts between contacts: the matrices and loads over all its
coordinates (structure, then dampers), as the exact flow and the analyses read them."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact._core import linear_parts as _linear_parts
from vibroimpact.arguments import directory
from vibroimpact.system.schema import system_spec


def linear_parts(
    structure: Mapping[str, Any],
    *,
    damper: Any = (),
    stop: Any = (),
    gravity: Any = None,
    excitation: Any = (),
    collision: Any = (),
    friction: Any = (),
    base_dir: Path | None = None,
) -> dict[str, Any]:
    """The system between contacts as a linear one over all its coordinates
    (structure, then dampers; sections as for :func:`simulate_system`):
    ``M x'' + C x' + K x = constant + sum of harmonic loads``. Returns ``mass``,
    ``stiffness``, ``damping`` (``dim x dim`` arrays, SI), ``constant`` (gravity's
    weight, N) and ``harmonics``: each ``amplitude``, ``omega`` (rad/s), ``phase`` and
    ``shape`` (the load is ``amplitude cos(omega t + phase) shape``, N). Signals
    other than harmonics are refused."""
    base_dir = directory("base_dir", base_dir)
    spec = system_spec(
        structure,
        damper,
        stop,
        gravity,
        excitation,
        base_dir,
        collision=collision,
        friction=friction,
    )
    raw = _linear_parts({**spec, "gravity": spec["gravity"]["acceleration"]})
    dim = raw["n"] + raw["k"]
    return {
        "n": raw["n"],
        "k": raw["k"],
        "mass": np.asarray(raw["mass"]).reshape(dim, dim),
        "stiffness": np.asarray(raw["stiffness"]).reshape(dim, dim),
        "damping": np.asarray(raw["damping"]).reshape(dim, dim),
        "constant": np.asarray(raw["constant"]),
        "harmonics": [dict(h) for h in raw["harmonics"]],
    }
