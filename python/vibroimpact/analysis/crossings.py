"""The bifurcations between two points of a continued branch: where the parameter
turns (a ``fold``), where a multiplier of each class crosses the unit circle (``flip``,
``neimark-sacker``, ``branch``), or where the impacts per period change (``grazing``)."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from vibroimpact.analysis.continuation import BranchPoint


def _fold(p0: float, p1: float, m0: float, m1: float) -> float:
    """Where the parameter turns between two points of a branch: the extremum of its
    cubic Hermite interpolant along the arc (values ``p0``, ``p1``, rates along the arc
    times its length ``m0``, ``m1`` of opposite signs). Beyond both points, on the side
    they turn from, as a fold is (a linear interpolation stays between them)."""
    a = 6.0 * (p0 - p1) + 3.0 * (m0 + m1)
    b = 6.0 * (p1 - p0) - 4.0 * m0 - 2.0 * m1
    # The slope a theta^2 + b theta + m0 goes from m0 to m1, of opposite signs: its one
    # root in [0, 1] by bisection (no choice between two roots to get wrong).
    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if (a * mid * mid + b * mid + m0) * m0 > 0:
            lo = mid
        else:
            hi = mid
    theta = 0.5 * (lo + hi)
    h00, h10 = 2 * theta**3 - 3 * theta**2 + 1, theta**3 - 2 * theta**2 + theta
    h01, h11 = -2 * theta**3 + 3 * theta**2, theta**3 - theta**2
    return h00 * p0 + h10 * m0 + h01 * p1 + h11 * m1


# Below this imaginary part a multiplier is real.
_REAL = 1e-6
#: The multipliers whose crossing of the unit circle each flag reports.
_CLASSES: dict[str, Callable[[complex], bool]] = {
    "flip": lambda m: abs(m.imag) <= _REAL and m.real < 0,
    "neimark-sacker": lambda m: abs(m.imag) > _REAL,
    "branch": lambda m: abs(m.imag) <= _REAL and m.real > 0,
}


def _largest(multipliers: np.ndarray, name: str) -> float:
    """The largest modulus of the multipliers of class ``name``, less 1 (-1 for none)."""
    chosen = [abs(m) for m in multipliers if _CLASSES[name](m)]
    return max(chosen) - 1.0 if chosen else -1.0


def _kind(outside: np.ndarray, fold: bool) -> str:
    """The bifurcation of the multiplier that has just left the unit circle (the
    largest of ``outside``): a flip (real, negative), a Neimark-Sacker (complex) or, real
    and positive, a fold where the parameter turns and a branch point otherwise."""
    m = complex(outside[int(np.argmax(np.abs(outside)))])
    if abs(m.imag) > _REAL:
        return "neimark-sacker"
    if m.real < 0:
        return "flip"
    return "fold" if fold else "branch"


def _flags(
    before: BranchPoint,
    after: BranchPoint,
    t0: np.ndarray,
    t1: np.ndarray,
    size: int,
    arc: float,
) -> tuple[list[str], dict[str, float]]:
    """The bifurcations between ``before`` and ``after``, whose unit tangents are
    ``t0`` and ``t1`` (in the scaled coordinates; the parameter's component at ``size``)
    and which lie ``arc`` apart along the branch (their scaled chord times the
    parameter's scale: the rates ``t[size] * arc`` are then in the parameter's unit)."""
    if before.impacts_per_period != after.impacts_per_period:
        # A grazing: the two orbits lie on two smooth branches, whose tangents and
        # multipliers say nothing of each other (the multipliers jump there), so no
        # fold, flip or other crossing is read between them.
        return ["grazing"], {}
    flags: list[str] = []
    crossings: dict[str, float] = {}
    if t0[size] * t1[size] < 0:
        flags.append("fold")
        # The parameter's rate along the branch is zero there.
        crossings["fold"] = _fold(before.value, after.value, t0[size] * arc, t1[size] * arc)
    for name in _CLASSES:
        if name == "branch" and "fold" in flags:
            continue
        a = _largest(before.floquet_multipliers, name)
        b = _largest(after.floquet_multipliers, name)
        if (a > 0) != (b > 0):
            flags.append(name)
            crossings[name] = before.value + (after.value - before.value) * a / (a - b)
    return flags, crossings
