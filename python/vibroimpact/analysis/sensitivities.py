"""Sensitivities of a periodic orbit to the scenario's parameters, by the implicit
function theorem on the shooting equations: at an orbit ``P_p(z) = z``,
``dz/dp = (I - M)^-1 dP/dp`` with ``M`` the monodromy (from the tangent flow through the
impacts where every pair is rigid, else central differences) and ``dP/dp`` the map's
derivative in the parameter (a central difference of two runs of the map from the
orbit's own state). The amplitudes' derivatives: central differences of the orbits'
located peaks at ``p +- h``, each run from the state the theorem predicts there (so no
Newton solve). SI units: per unit of the parameter."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact import arguments
from vibroimpact.analysis.continuation import _value_of
from vibroimpact.analysis.limits import AnalysisError
from vibroimpact.analysis.orbits import Orbit
from vibroimpact.analysis.parameters import with_parameter, with_parameter_path_check
from vibroimpact.analysis.runs import runner
from vibroimpact.model.system import System, sections_of

#: The parameter's step in the differences, relative to its value (absolute where the
#: value is 0): a map's central difference errs by ``h^2`` and by round-off over ``h``.
RELATIVE_STEP = 1e-6


@dataclass
class Derivative:
    """The derivatives of an orbit in one parameter: of its state at t = 0 (flat,
    displacements then velocities) and of its amplitude per structure coordinate (the
    largest ``|displacement|`` over the orbit), per unit of the parameter."""

    state: np.ndarray
    amplitude: np.ndarray

    def to_dict(self) -> dict[str, list[float]]:
        return {
            "state": [float(v) for v in self.state],
            "amplitude": [float(v) for v in self.amplitude],
        }


def orbit_derivatives(
    data: Mapping[str, Any] | System,
    found: Orbit,
    paths: Sequence[str],
    *,
    periods: int = 1,
    base_dir: Path | None = None,
) -> dict[str, Derivative]:
    """The derivatives of the ``periods``-period orbit ``found`` (of the scenario
    ``data``) in each parameter of ``paths`` (dotted paths such as
    ``"damper.0.clearance"``), by the implicit function theorem on the shooting
    equations (see the module). The orbit must have converged."""
    data, base_dir = sections_of(data, base_dir)
    arguments.instance("found", found, Orbit, "vibroimpact.analysis.orbit(...)")
    if not found.converged:
        raise AnalysisError("found: the orbit did not converge; its derivatives are not defined")
    if isinstance(paths, str):
        paths = [paths]
    out: dict[str, Derivative] = {}
    size = len(found.state)
    inverse = np.linalg.inv(np.eye(size) - found.monodromy)
    for path in paths:
        arguments.text("derivative", path)
        with_parameter_path_check(path, "")
        value = _value_of(data, path, "derivative", "the derivative is taken at its value")
        h = RELATIVE_STEP * (abs(value) if value else 1.0)
        runs = [runner(with_parameter(data, path, value + s * h), base_dir) for s in (1.0, -1.0)]
        up, down = (run.map(found.state, periods) for run in runs)
        state = inverse @ ((up - down) / (2 * h))
        amplitudes = []
        for sign, run in zip((1.0, -1.0), runs, strict=True):
            recorded = run.periods(found.state + sign * h * state, periods, record=True)
            amplitudes.append(run.amplitudes(recorded)[0])
        out[path] = Derivative(state, (amplitudes[0] - amplitudes[1]) / (2 * h))
    return out
