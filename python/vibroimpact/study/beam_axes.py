"""A study's axes over a cantilever's section or density (``structure.height``,
``structure.outer_diameter``, ``structure.density``, ...): the core varies what a
cantilever is made of, its second moment of area and mass per length, not the
dimensions they come from, so each run's dimensions are resolved here
(:func:`vibroimpact.system.beam.resolve_cantilever`, as a scenario's are) and the core
is given the second moment (m^4) and mass per length (kg/m) they make."""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from vibroimpact._core import InvalidInputError
from vibroimpact.study.limits import StudyError
from vibroimpact.system.beam import DIMENSIONS
from vibroimpact.system.schema import structure_spec

#: The keys of ``[structure]`` a study may vary through the beam's section and material.
DERIVED = (*DIMENSIONS, "density")
_RESOLVED = ("structure.second_moment", "structure.mass_per_length")


def _derived(path: str) -> bool:
    parts = path.split(".")
    return len(parts) == 2 and parts[0] == "structure" and parts[1] in DERIVED


def beam_corners(paths: Sequence[str], values: Sequence[np.ndarray]) -> np.ndarray:
    """Rows to check a study's beam axes by (each path's ``values``): every corner of the
    beam's axes' ranges (their least and greatest values: the section's limits, a
    positive dimension and an inner diameter below the outer, are monotone in each), the
    other axes at their first value."""
    choices = [
        (float(np.min(v)), float(np.max(v))) if _derived(path) else (float(v[0]),)
        for path, v in zip(paths, values, strict=True)
    ]
    return np.array(list(itertools.product(*choices)), dtype=float).reshape(-1, len(paths))


def resolve_beam_axes(
    structure: Mapping[str, Any], paths: Sequence[str], rows: np.ndarray
) -> tuple[list[str], np.ndarray]:
    """``paths`` and the runs' values ``rows`` (a row per run, a column per path) with
    the section's and density's columns replaced by the second moment and mass per length
    each run's values resolve to; unchanged where no path is one of :data:`DERIVED`.
    Errors name the axis (a dimension the section does not have, a value out of range)."""
    derived = [j for j, path in enumerate(paths) if _derived(path)]
    if not derived:
        return list(paths), rows
    names = ", ".join(repr(paths[j]) for j in derived)
    for path in paths:
        if path in _RESOLVED:
            raise StudyError(
                f"study axes {names} and {path!r}: the section and density make the second "
                "moment and mass per length; vary one or the other"
            )
    if structure.get("kind") != "cantilever":
        raise StudyError(
            f"study axes {names}: a section's dimensions and density belong to a "
            'cantilever ([structure] kind = "cantilever")'
        )
    kept = [j for j in range(len(paths)) if j not in derived]
    resolved = np.empty((len(rows), 2))
    for i, row in enumerate(rows):
        table = dict(structure)
        for j in derived:
            table[paths[j].split(".")[1]] = float(row[j])
        try:
            beam = structure_spec(table)
        except InvalidInputError as err:
            values = ", ".join(f"{paths[j]} = {float(row[j])!r}" for j in derived)
            raise StudyError(f"study axes {names} at {values}: {err}") from None
        resolved[i] = beam["second_moment"], beam["mass_per_length"]
    columns = [rows[:, j] for j in kept] + [resolved[:, 0], resolved[:, 1]]
    return [paths[j] for j in kept] + list(_RESOLVED), np.column_stack(columns)
