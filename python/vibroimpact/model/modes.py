"""The natural frequencies and mode shapes of a system between contacts: the undamped
linear structure, ``K phi = omega^2 M phi``, alone or with the dampers' masses attached
rigidly at their points (the two limits of an impact damper: rattling free, or stuck)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from vibroimpact import arguments
from vibroimpact._core import InvalidInputError
from vibroimpact.messages import shown
from vibroimpact.system import linear_parts, point_weights, system_spec

if TYPE_CHECKING:
    # Not at run time: the System's summary shows these modes (model.system imports this).
    from vibroimpact.model.system import System


@dataclass(frozen=True)
class NaturalModes:
    """The undamped modes of a linear structure, lowest first.

    ``frequencies``: Hz. ``shapes``: one column a mode, in the structure's coordinates
    (an oscillator's one, the matrices' coordinates, a cantilever's modal coordinates),
    normalised to unit modal mass (``shapes.T @ mass @ shapes`` is the identity, kg).
    ``mass``, ``stiffness``: the matrices solved (kg, N/m), the dampers' masses included
    where they were attached. :meth:`at` gives the shapes at points of the structure."""

    frequencies: np.ndarray
    shapes: np.ndarray
    mass: np.ndarray
    stiffness: np.ndarray
    structure: dict[str, Any]

    def at(self, points: Any) -> np.ndarray:
        """The mode shapes' displacements at ``points`` (m along a cantilever, or
        coordinate indices): one row a point, one column a mode (m per unit modal
        coordinate)."""
        where = np.atleast_1d(np.asarray(points, dtype=float))
        rows = [point_weights(self.structure, at, f"points[{j}]") for j, at in enumerate(where)]
        shapes: np.ndarray = np.array(rows) @ self.shapes
        return shapes


@arguments.typed()
def natural_modes(system: System, *, attach_dampers: bool = False) -> NaturalModes:
    """The undamped natural frequencies (Hz) and mode shapes of ``system`` between
    contacts, from its linear parts (:func:`vibroimpact.linear_parts`): the generalized
    symmetric eigenproblem ``K phi = (2 pi f)^2 M phi`` of the structure.

    ``attach_dampers=False`` (default): the structure alone, every damper free in its
    clearance (its mass adds nothing while it rattles; a free mass's own 0 Hz mode is
    left out). ``attach_dampers=True``: each damper's mass moves with its point (clearance
    closed, as when it sticks), ``M + sum m_d h h^T`` with ``h`` the point's weights, which
    lowers the frequencies of the modes that move the points.

    A cantilever's modes are those of its ``modes`` modal coordinates (the first
    ``modes`` clamped-free modes, exact for the structure alone; with masses attached a
    Rayleigh-Ritz approximation from above, closer the more modes are kept). Stops add
    neither mass nor stiffness here."""
    if not callable(getattr(system, "model_sections", None)):
        raise InvalidInputError(f"system: must be a vibroimpact.System, got {shown(system)}")
    attach = arguments.flag("attach_dampers", attach_dampers)
    sections = system.model_sections()
    parts = linear_parts(
        sections["structure"],
        damper=sections["damper"],
        collision=sections["collision"],
        friction=sections["friction"],
    )
    n = parts["n"]
    mass, stiffness = parts["mass"][:n, :n].copy(), parts["stiffness"][:n, :n]
    structure = system_spec(sections["structure"])["structure"]
    if attach:
        for j, damper in enumerate(system.dampers):
            weights = point_weights(structure, damper.at, f"dampers[{j}].at")
            mass += parts["mass"][n + j, n + j] * np.outer(weights, weights)
    frequencies, shapes = _solved(stiffness, mass)
    return NaturalModes(frequencies, shapes, mass, stiffness.copy(), structure)


def structure_frequencies(structure: Mapping[str, Any]) -> np.ndarray:
    """The undamped natural frequencies (Hz, lowest first; a rigid mode's 0 to
    round-off) of a ``[structure]`` section alone, as :func:`natural_modes` gives them."""
    parts = linear_parts(structure)
    n = parts["n"]
    return _solved(parts["stiffness"][:n, :n], parts["mass"][:n, :n])[0]


def _solved(stiffness: np.ndarray, mass: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``K phi = (2 pi f)^2 M phi``: the frequencies (Hz) and unit-modal-mass shapes."""
    # Imported here: scipy.linalg at import time doubled `import vibroimpact` (+150 ms).
    import scipy.linalg

    eigenvalues, shapes = scipy.linalg.eigh(stiffness, mass)
    # Each shape's sign fixed (its largest entry positive): eigh's is arbitrary.
    largest = shapes[np.abs(shapes).argmax(axis=0), np.arange(shapes.shape[1])]
    shapes = shapes * np.where(largest < 0, -1.0, 1.0)
    # Round-off can leave a rigid-body mode's eigenvalue a hair below zero.
    frequencies = np.sqrt(np.clip(eigenvalues, 0.0, None)) / (2 * np.pi)
    return frequencies, shapes


def frequencies_summary(system: System, shown_modes: int = 5) -> str:
    """The first natural frequencies (Hz) of ``system``'s structure, and with the
    dampers' masses attached where it has dampers: the row of its notebook summary."""

    def listed(frequencies: np.ndarray) -> str:
        more = ", ..." if len(frequencies) > shown_modes else ""
        return ", ".join(f"{f:.4g}" for f in frequencies[:shown_modes]) + more + " Hz"

    text = f"structure: {listed(natural_modes(system).frequencies)}"
    if system.dampers:
        attached = natural_modes(system, attach_dampers=True).frequencies
        text += f"; dampers' masses attached: {listed(attached)}"
    return text
