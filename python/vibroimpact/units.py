"""The SI units (UDUNITS spelling, as CF asks: ``"m"``, ``"m s-1"``, ``"1"`` for a
dimensionless one) of a scenario's parameters and of the analyses' flat state ``(x, v)``,
and the names of its entries: what the Datasets, a study's axes, the plots and the notebook
tables label (here, outside the analyses, which import the model that the tables show)."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

_M = "m"
_NM = "N m"
_M_S = "m s-1"
_ONE = "1"

#: The unit of a scenario key whatever its section or law.
_KEY_UNITS = {
    "frequency": "Hz",
    "start_frequency": "Hz",
    "end_frequency": "Hz",
    "cutoff_frequency": "Hz",
    "ground_frequency": "Hz",
    "frequencies": "Hz",
    "phase": "rad",
    "phases": "rad",
    "duration": "s",
    "t_end": "s",
    "dt": "s",
    "record_from": "s",
    "strobe_period": "s",
    "mass": "kg",
    "damping": "N s m-1",
    "clearance": _M,
    "lower_clearance": _M,
    "upper_clearance": _M,
    "gap": _M,
    "restitution": _ONE,
    "static_friction": _ONE,
    "coefficient": _ONE,
    "static_coefficient": _ONE,
    "normal_force": "N",
    "seed": _ONE,
    "damping_ratio": _ONE,
    "ground_damping": _ONE,
    "length": _M,
    "youngs_modulus": "Pa",
    "second_moment": "m4",
    "mass_per_length": "kg m-1",
    "width": _M,
    "height": _M,
    "diameter": _M,
    "outer_diameter": _M,
    "inner_diameter": _M,
    "density": "kg m-3",
    "acceleration": "m s-2",
    "structure_displacement": _M,
    "damper_displacement": _M,
    "structure_velocity": _M_S,
    "damper_velocity": _M_S,
}
_HERTZ_LAWS = ("hertz", "hyster-hertz", "hertz-damped")


def parameter_units(parameter: str, data: Mapping[str, Any] | None = None) -> str | None:
    """The SI unit (UDUNITS spelling) of a scenario parameter given as a dotted path
    (``"excitation.0.frequency"`` -> ``"Hz"``, ``"damper.0.clearance"`` -> ``"m"``),
    or None where it cannot be told. Some keys' units depend on the scenario: an
    excitation's ``amplitude`` (N for a force, m s-2 for a base acceleration) and
    ``intensity`` (N2 s or m2 s-3: a spectral density per rad/s), a
    damper's or stop's ``stiffness`` (N m-1 for the linear law, N m-1.5 for the
    Hertz laws), a point's ``at`` (an index, or m along a cantilever); give the
    scenario's sections as ``data`` to resolve those."""
    parts = parameter.split(".")
    keys = [p for p in parts if not p.isdigit()]
    if len(keys) < 2:
        return None
    section, key = keys[0], keys[1]
    if key in _KEY_UNITS:
        return _KEY_UNITS[key]
    if section == "structure" and key == "stiffness":
        return "N m-1"
    if section == "solver" and key in (
        "rtol",
        "energy_tolerance",
        "beta",
        "gamma",
        "spectral_radius",
    ):
        return _ONE
    if section == "solver" and key == "atol":
        return None  # m and m s-1 alike
    if data is None:
        return None
    entry = _entry(data, parts)
    if entry is None:
        return None
    if key in ("amplitude", "amplitudes") and section == "excitation":
        return {"force": "N", "base": "m s-2"}.get(str(entry.get("kind")))
    if key == "intensity" and section == "excitation":
        # A two-sided spectral density per rad/s: the signal's unit squared times s.
        return {"force": "N2 s", "base": "m2 s-3"}.get(str(entry.get("kind")))
    if key == "stiffness" and section in ("damper", "stop", "collision"):
        law = entry.get("law")
        return "N m-1" if law == "linear" else "N m-1.5" if law in _HERTZ_LAWS else None
    if key == "friction" and section == "damper":
        return _ONE
    if (key == "at" and section in ("damper", "stop", "excitation", "friction")) or (
        key == "against" and section in ("stop", "friction")
    ):
        structure = data.get("structure")
        if isinstance(structure, Mapping):
            return _M if structure.get("kind") == "cantilever" else _ONE
    return None


def derivative_units(unit: str, parameter: str, data: Mapping[str, Any] | None = None) -> str:
    """The unit of a derivative of a quantity in ``unit`` by the scenario parameter
    ``parameter`` (see :func:`parameter_units`), in words: ``"m per N"``, ``"m"`` for a
    dimensionless parameter, ``"m per unit of PATH"`` where its unit cannot be told."""
    per = parameter_units(parameter, data)
    if per == _ONE:
        return unit
    return f"{unit} per {per}" if per else f"{unit} per unit of {parameter}"


def _entry(data: Mapping[str, Any], parts: list[str]) -> Mapping[str, Any] | None:
    """The table of a dotted path's section (the list entry, for ``[[damper]]`` etc.)."""
    node: Any = data.get(parts[0])
    if isinstance(node, list) and len(parts) > 1 and parts[1].isdigit():
        index = int(parts[1])
        node = node[index] if index < len(node) else None
    return node if isinstance(node, Mapping) else None


def state_names(n: int, k: int) -> list[str]:
    """The names of the flat state's ``2 (n + k)`` entries, in order:
    ``structure_displacement_i`` (i < n), ``damper_displacement_j`` (j < k), then
    ``structure_velocity_i`` and ``damper_velocity_j``."""
    return [
        f"{name}_{i}"
        for name, size in (
            ("structure_displacement", n),
            ("damper_displacement", k),
            ("structure_velocity", n),
            ("damper_velocity", k),
        )
        for i in range(size)
    ]


def _state_unit(name: str) -> str | None:
    """m or m s-1 for a state entry's name (``"structure_velocity.0"`` etc.)."""
    if "velocity" in name:
        return _M_S
    if "displacement" in name:
        return _M
    return None


#: Headers of the printed tables of contacts, by column of a contact table: SI units in
#: brackets, as the command line prints them.
CONTACT_HEADERS = {
    "onset": "onset (s)",
    "separation": "separation (s)",
    "duration": "duration (s)",
    "max_indentation": "max indent. (m)",
    "approach_speed": "approach (m/s)",
    "rebound_speed": "rebound (m/s)",
    "restitution": "restitution",
    "energy_dissipated": "dissipated (J)",
    "energy_change": "net change (J)",
}


def contact_cell(value: Any, still_open: bool, width: int) -> str:
    """One cell of a printed table of contacts, right-aligned in ``width``.

    A value a contact still open at the end of the run does not have yet reads ``open``;
    one a closed contact has none of (NaN: the restitution of a sticking interval or of
    a contact that started at rest) reads ``-``.
    """
    if isinstance(value, str):
        return f"{value:>{width}}"
    if math.isnan(value):
        return f"{'open' if still_open else '-':>{width}}"
    # + 0.0 turns a negative zero into a zero.
    return f"{value + 0.0:>{width}.7g}"


def contact_table(
    rows: Iterable[Mapping[str, Any]], columns: Sequence[str], width: int
) -> list[str]:
    """A printed table of contacts: its header (the ``CONTACT_HEADERS``), then a line of
    ``columns`` per row (see :func:`contact_cell`; a row whose ``separation`` is not
    finite is still open), each cell right-aligned in ``width``."""
    lines = ["  ".join(f"{CONTACT_HEADERS.get(name, name):>{width}}" for name in columns)]
    for row in rows:
        still_open = not math.isfinite(row["separation"])
        lines.append("  ".join(contact_cell(row[name], still_open, width) for name in columns))
    return lines


#: The SI unit of each column of a contact table (``to_pandas().attrs["units"]``; "1"
#: where it has none, "" for text).
CONTACT_UNITS = {
    "pair": "",
    "kind": "",
    "onset": "s",
    "separation": "s",
    "duration": "s",
    "max_indentation": _M,
    "approach_speed": _M_S,
    "rebound_speed": _M_S,
    "restitution": _ONE,
    "energy_dissipated": "J",
    "energy_change": "J",
}


def with_units(parameter: str, data: Mapping[str, Any] | None = None) -> str:
    """``parameter`` (a dotted path) with its SI unit in brackets, as the printed
    tables head a parameter's column (``"excitation.0.frequency (Hz)"``); alone where
    the unit is 1 or cannot be told."""
    unit = parameter_units(parameter, data)
    return parameter if unit in (None, _ONE) else f"{parameter} ({unit})"
