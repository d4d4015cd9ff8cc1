"""Points on a checked ``[structure]``: where a damper, stop, friction element, force or
output sits (a coordinate index, or a position along a cantilever), and the weights
that give a point's displacement or a cantilever's bending moment from the structure's
coordinates. Errors are one line naming the point, worded as the core words them."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from vibroimpact._core import InvalidInputError, cantilever_mode_shape
from vibroimpact.arguments import real
from vibroimpact.messages import shown


def _check_point(name: str, given: Any, at: float, structure: dict[str, Any]) -> None:
    """A point ``at`` on the structure: a coordinate index of an oscillator or of
    matrices, a position along a cantilever (m); ``name`` such as ``"damper 0 at"``,
    worded as the core words it. ``given`` is the value as written, quoted in the
    error short and exact (the core would write 1e300 as 301 digits)."""
    if structure["kind"] == "cantilever":
        length = structure["length"]
        if not (math.isfinite(length) and length > 0):
            # The beam's own error first, worded as the core's: a point cannot be
            # placed on a beam of no length ("in [0, -1.0] m", user trial).
            raise InvalidInputError(
                f"structure.length must be a finite number > 0, got {shown(length)}"
            )
        if not 0.0 <= at <= length:
            raise InvalidInputError(
                f"{name} must be a position along the beam in [0, {length!r}] m, got "
                f"{shown(given)}",
            )
        return
    size = structure_coordinates(structure)
    if size and not (at.is_integer() and 0 <= at < size):
        raise InvalidInputError(
            f"{name} must be a coordinate index, a whole number in [0, {size - 1}], got "
            f"{shown(given)}",
        )


def point_weights(structure: Mapping[str, Any], at: Any, name: str = "at") -> np.ndarray:
    """The weights of a checked ``[structure]``'s coordinates at a point: the
    displacement there is ``weights @ coordinates``. For a cantilever ``at`` is a
    position along the beam (m from the clamp) and the weights are the mode shapes
    there; otherwise ``at`` is a coordinate index and the weights pick it. ``name``
    names ``at`` in the error."""
    value = real(at)
    if value is None:
        raise InvalidInputError(f"{name} must be a number, got {shown(at)}")
    _check_point(name, at, float(value), dict(structure))
    n = structure_coordinates(structure)
    if structure["kind"] == "cantilever":
        length = float(structure["length"])
        return np.array([cantilever_mode_shape(length, i + 1, float(value)) for i in range(n)])
    weights = np.zeros(n)
    weights[int(value)] = 1.0
    return weights


def moment_weights(structure: Mapping[str, Any], at: Any, name: str = "at") -> np.ndarray:
    """The weights of a checked cantilever's modal coordinates in its bending moment at
    ``at`` m from the clamp (N m per unit coordinate): ``E I phi_i''(at)``."""
    value = real(at)
    if value is None:
        raise InvalidInputError(f"{name} must be a number, got {shown(at)}")
    _check_bends(name, structure)
    _check_point(name, at, float(value), dict(structure))
    length, stiffness = (
        float(structure["length"]),
        structure["youngs_modulus"] * structure["second_moment"],
    )
    n = structure_coordinates(structure)
    return np.array(
        [stiffness * cantilever_mode_shape(length, i + 1, float(value), 2) for i in range(n)]
    )


def _check_bends(name: str, structure: Mapping[str, Any]) -> None:
    """Only a cantilever has bending moments (``name`` asks for them)."""
    if structure["kind"] != "cantilever":
        raise InvalidInputError(
            f'{name}: only a cantilever has bending moments (structure.kind = "cantilever")'
        )


def split_observed(
    values: np.ndarray, n: int, points: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """What the core reduces over its observed quantities (along the last axis), split:
    the ``n`` structure coordinates, then the ``points`` points, then the moments."""
    return values[..., :n], values[..., n : n + points], values[..., n + points :]


def structure_coordinates(structure: Mapping[str, Any]) -> int:
    """The coordinates of a checked ``[structure]``: 1 for an oscillator, one per DOF
    of matrices, one per mode of a cantilever."""
    kind = structure["kind"]
    if kind == "oscillator":
        return 1
    if kind == "cantilever":
        return int(structure["modes"])
    return len(structure["mass"])
