"""Bifurcations of a continued branch located exactly: Newton's method on the extended
system ``P_p(z) - z = 0, g(z, p) = 0``, ``g`` the test function of the bifurcation's
kind on the Floquet multipliers from the tangent flow through the impacts (a flip: the
real multiplier nearest -1, plus 1; a fold or branch point: the real one nearest +1,
less 1; a Neimark-Sacker: the modulus of the complex pair nearest the unit circle, less
1). Started from the bisection along the arc, it converges to round-off in the
parameter. SI units."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from vibroimpact.analysis.runs import state_arrays

if TYPE_CHECKING:
    from vibroimpact.analysis.continuation import BranchPoint, _Arc

#: Newton iterations on the extended system, and the parameter's tolerance relative
#: to its size (``|dp| <= PARAMETER_TOLERANCE max(|p|, 1)``).
ITERATIONS = 12
PARAMETER_TOLERANCE = 1e-12


@dataclass
class Bifurcation:
    """A bifurcation located on a branch: its ``kind`` (``"fold"``, ``"flip"``,
    ``"neimark-sacker"``, ``"branch"``, ``"grazing"``), the parameter's ``value`` there,
    the orbit's state at t = 0 and its Floquet multipliers (one of them on the unit
    circle, but at a grazing: there the orbit touches a wall at zero speed)."""

    kind: str
    value: float
    state: np.ndarray
    floquet_multipliers: np.ndarray
    #: A grazing's wall (``"stop 0"``, ``"damper 0 upper"``) and the instant of the
    #: touch after t = 0 (s).
    pair: str | None = None
    time: float | None = None

    def to_dict(self, n: int, k: int) -> dict[str, Any]:
        out = {
            "kind": self.kind,
            "value": self.value,
            "state": state_arrays(self.state, n, k),
            "floquet_multipliers": [
                [float(m.real), float(m.imag)] for m in self.floquet_multipliers
            ],
        }
        if self.pair is not None:
            out["pair"] = self.pair
            out["time"] = self.time
        return out


def test_value(kind: str, multipliers: np.ndarray) -> float:
    """The test function of ``kind`` on ``multipliers``: zero at the bifurcation."""
    m = np.asarray(multipliers, dtype=complex)
    if kind == "flip":
        nearest = m[int(np.argmin(np.abs(m + 1.0)))]
        return float(nearest.real + 1.0)
    if kind in ("fold", "branch"):
        nearest = m[int(np.argmin(np.abs(m - 1.0)))]
        return float(nearest.real - 1.0)
    if kind == "neimark-sacker":
        complex_ones = m[np.abs(m.imag) > 1e-9]
        if not complex_ones.size:
            return float("nan")
        # The pair nearest the unit circle: the one crossing it (with a second pair
        # inside, the smallest modulus was that pair's, and Newton found no zero).
        moduli = np.abs(complex_ones)
        return float(moduli[int(np.argmin(np.abs(moduli - 1.0)))] - 1.0)
    raise ValueError(f"kind: no test function for {kind!r}")


def _g(arc: _Arc, kind: str, w: np.ndarray) -> float:
    """The test function at the scaled unknowns ``w`` (one run of the tangent flow)."""
    z = w[: arc.size] * arc.scale[: arc.size]
    p = float(w[arc.size] * arc.scale[arc.size])
    run = arc.run_at(p)
    monodromy = run.tangent(z, arc.periods * run.period)["matrix"]
    return test_value(kind, np.linalg.eigvals(monodromy))


def refine(
    arc: _Arc, kind: str, start: np.ndarray, within: tuple[float, float] | None = None
) -> tuple[BranchPoint, np.ndarray] | None:
    """The bifurcation of ``kind`` near the scaled unknowns ``start`` by Newton's method
    on the extended system: its branch point and scaled unknowns, or None where Newton
    does not converge, leaves the parameter's interval ``within`` or starts a run inside
    a wall (or the system has no tangent flow)."""
    try:
        found = _newton(arc, kind, start)
    except (ValueError, ArithmeticError, RuntimeError, np.linalg.LinAlgError):
        # A Newton step into a wall (an InvalidInputError) or a run that cannot
        # complete there: not located.
        return None
    if found is None or within is None:
        return found
    low, high = min(within), max(within)
    return found if low <= found[0].value <= high else None


def _newton(arc: _Arc, kind: str, start: np.ndarray) -> tuple[BranchPoint, np.ndarray] | None:
    """:func:`refine`'s iterations."""
    w = start.copy()
    step = 1e-7
    for _ in range(ITERATIONS):
        f = arc.residual(w)
        jac = arc.jacobian(w, f)
        g = test_value(kind, arc.multipliers_of(jac))
        if not np.isfinite(g):
            return None
        gradient = np.zeros(arc.size + 1)
        for j in range(arc.size + 1):
            up, down = w.copy(), w.copy()
            up[j] += step
            down[j] -= step
            gradient[j] = (_g(arc, kind, up) - _g(arc, kind, down)) / (2 * step)
        system = np.vstack([jac, gradient[None, :]])
        delta = np.linalg.solve(system, np.concatenate([f, [g]]))
        w = w - delta
        p = float(w[arc.size] * arc.scale[arc.size])
        moved = abs(float(delta[arc.size] * arc.scale[arc.size]))
        if moved <= PARAMETER_TOLERANCE * max(abs(p), 1.0) and np.max(np.abs(f)) <= arc.tolerance:
            jac = arc.jacobian(w)
            return arc.point(w, jac), w
    return None
