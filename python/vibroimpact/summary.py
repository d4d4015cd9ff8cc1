"""Short ``repr`` of the result classes: what a result is and what it holds, never
its arrays in full (a run's solution printed whole had been 50 kB: every history
row, and one ``'damper 0'`` per contact)."""

from __future__ import annotations

import dataclasses
import importlib
from collections.abc import Callable, Mapping
from typing import Any, TypeVar

import numpy as np

from vibroimpact._core import InvalidInputError
from vibroimpact.units import CONTACT_UNITS

_T = TypeVar("_T", bound=type)

#: Arrays and lists of at most this many entries are shown whole.
_SHOWN = 4


def brief(value: Any) -> str:
    """One short text for a field's value: scalars as they are (floats to 6
    significant digits), small arrays and lists whole, larger ones by their shape
    or length, dicts by their keys."""
    if isinstance(value, np.ndarray):
        if value.ndim <= 1 and value.size <= _SHOWN:
            return "[" + ", ".join(brief(v.item()) for v in np.ravel(value)) + "]"
        return f"<array {'x'.join(str(s) for s in value.shape)}>"
    if isinstance(value, (list, tuple)):
        if len(value) <= _SHOWN and all(isinstance(v, (int, float, str)) for v in value):
            return "[" + ", ".join(brief(v) for v in value) + "]"
        return f"<{len(value)} items>"
    if isinstance(value, Mapping):
        if len(value) <= _SHOWN and all(isinstance(v, (int, float)) for v in value.values()):
            return "{" + ", ".join(f"{k}: {brief(v)}" for k, v in value.items()) + "}"
        return "{" + ", ".join(str(k) for k in value) + "}"
    if isinstance(value, complex):
        return f"{value.real:.6g}{value.imag:+.6g}j"
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, (bool, int, str)) or value is None:
        return repr(value)
    return f"<{type(value).__name__}>"


def _empty(value: Any) -> bool:
    return value is None or (
        isinstance(value, (np.ndarray, list, tuple, Mapping)) and len(value) == 0
    )


def fields_repr(obj: Any) -> str:
    """``Name(field=brief value, ...)`` of a dataclass instance, leaving out fields
    that are empty or None (an absent error, points not asked for)."""
    parts = [
        f"{f.name}={brief(getattr(obj, f.name))}"
        for f in dataclasses.fields(obj)
        if f.repr and not _empty(getattr(obj, f.name))
    ]
    return f"{type(obj).__name__}({', '.join(parts)})"


def summarised(cls: _T) -> _T:
    """Class decorator (above ``@dataclass``): a :func:`fields_repr` ``repr``."""
    method: Callable[[Any], str] = fields_repr
    cls.__repr__ = method  # type: ignore[assignment]
    return cls


def solution_repr(sol: Any) -> str:
    """A 0.2 run's solution in one line: the structure, the method, the time
    reached (s), the steps, the contacts (and the pairs they came from), the kept
    rows and the names of the fields that hold something."""
    kind = sol.structure.get("kind", "structure") if sol.structure else "structure"
    n, k = sol.structure_displacement.shape[1], sol.damper_displacement.shape[1]
    pairs = sorted(set(sol.contacts.pair))
    shown = ", ".join(pairs[:_SHOWN]) + (", ..." if len(pairs) > _SHOWN else "")
    held = [
        f.name
        for f in dataclasses.fields(sol)
        if not _empty(getattr(sol, f.name)) and f.name not in ("structure", "pairs")
    ]
    return (
        f"{type(sol).__name__}({kind} of {n} coordinate(s) and {k} damper(s), "
        f"method={sol.method!r}, t_end={sol.final_time:.6g} s, steps={sol.steps}, "
        f"contacts={len(sol.contacts)}" + (f" ({shown})" if pairs else "") + ", "
        f"rows={len(sol.t)}; fields: {', '.join(held)})"
    )


def contacts_repr(contacts: Any) -> str:
    """A contact table in one line: how many contacts, of which kinds, and the pairs."""
    kinds = {kind: list(contacts.kind).count(kind) for kind in sorted(set(contacts.kind))}
    pairs = sorted(set(contacts.pair))
    count = len(contacts)
    return (
        f"{type(contacts).__name__}({count} contact{'' if count == 1 else 's'}"
        + "".join(f", {count} {kind}" for kind, count in kinds.items())
        + (f"; pairs: {', '.join(pairs[:_SHOWN])}" if pairs else "")
        + (", ..." if len(pairs) > _SHOWN else "")
        + f"; columns: {', '.join(contacts.columns)})"
    )


def _pandas() -> Any:
    try:
        # By name: pandas ships no type hints of its own (pandas-stubs does).
        pandas = importlib.import_module("pandas")
    except ImportError:
        raise ImportError(
            "to_pandas() needs pandas (pip install pandas); the columns are NumPy arrays "
            "without it (to_dicts() gives plain rows)"
        ) from None
    return pandas


def contacts_frame(contacts: Any) -> Any:
    """A contact table (one row per contact, its ``columns``, SI units) as a
    ``pandas.DataFrame``: a 0.2 run's ``SystemContacts`` or the two-mass run's
    ``ContactTable``; pandas is imported here, and its absence said."""
    pandas = _pandas()
    frame = pandas.DataFrame(
        {
            # Text columns stay text when empty (pandas would make them float64).
            name: np.asarray(getattr(contacts, name), dtype=object)
            if name in _TEXT_COLUMNS
            else getattr(contacts, name)
            for name in contacts.columns
        }
    )
    frame.attrs["units"] = {name: CONTACT_UNITS[name] for name in contacts.columns}
    return frame


#: The contact tables' columns of text.
_TEXT_COLUMNS = ("pair", "kind")


#: The units of a history's arrays (attributes of :func:`history_dataset`'s variables),
#: written as in UDUNITS, as the contact tables and the analyses' Datasets write them.
_UNITS = {
    "structure_displacement": "m",
    "structure_velocity": "m s-1",
    "damper_displacement": "m",
    "damper_velocity": "m s-1",
}
#: The two-mass run's history (``vibroimpact.Solution``), each over time.
_TWO_MASS_UNITS = {
    "main_displacement": "m",
    "main_velocity": "m s-1",
    "impact_displacement": "m",
    "impact_velocity": "m s-1",
    "contact_force": "N",
}


#: The units of the ``energy_*`` attributes (an attribute has none of its own).
_ENERGY_UNITS = {"energy_units": "J"}


def history_dataset(sol: Any) -> Any:
    """A run's history as an ``xarray.Dataset`` over the dimension ``time`` (s): a 0.2
    run's arrays also over ``structure_coordinate`` (modes of a cantilever, from 0) or
    ``damper``, the two-mass run's (``vibroimpact.Solution``) main and impact mass's
    displacements, velocities and the contact force; each with its units, the run's
    statistics and energy (J) as attributes."""
    import xarray as xr

    statistics = ("steps", "rejected_steps", "rhs_evaluations", "grazing_contacts")
    attrs = {
        "method": sol.method,
        "final_time": sol.final_time,
        "contacts": len(sol.contacts),
        **{name: getattr(sol, name) for name in statistics},
    }
    time = {"time": ("time", sol.t, {"units": "s"})}
    if not hasattr(sol, "structure_displacement"):
        two_mass = {
            name: ("time", getattr(sol, name), {"units": unit})
            for name, unit in _TWO_MASS_UNITS.items()
        }
        energy = {"energy_growth": sol.energy_growth, "energy_residual": sol.energy_residual}
        return xr.Dataset(two_mass, coords=time, attrs=attrs | energy | _ENERGY_UNITS)
    arrays = {
        name: (
            ("time", "structure_coordinate" if name.startswith("structure") else "damper"),
            getattr(sol, name),
            {"units": unit},
        )
        for name, unit in _UNITS.items()
    }
    n, k = sol.structure_displacement.shape[1], sol.damper_displacement.shape[1]
    coordinates = {"structure_coordinate": np.arange(n), "damper": np.arange(k)}
    energy = {f"energy_{key}": value for key, value in sol.energy.items()}
    followed, followed_at = _followed(sol)
    results, results_at = _results(sol, n, k)
    return xr.Dataset(
        arrays | followed | results,
        coords=time | coordinates | followed_at | results_at,
        attrs=attrs | energy | _ENERGY_UNITS | {"recorded_time": sol.recorded_time},
    )


def _results(sol: Any, n: int, k: int) -> tuple[dict[str, Any], dict[str, Any]]:
    """A run's results beside its history: the compliant pairs' forces over time (N,
    over ``contact_pair``), each structure coordinate's recorded peak and RMS (m), and
    the strobed states over ``strobe_time`` (s), each state entry named as the history's
    columns are (``structure_displacement_0``, ...)."""
    arrays: dict[str, Any] = {}
    coordinates: dict[str, Any] = {}
    force = np.asarray(sol.contact_force)
    if force.ndim == 2 and force.size and force.shape[0] == len(sol.t):
        coordinates["contact_pair"] = ("contact_pair", list(sol.contact_force_pairs))
        arrays["contact_force"] = (
            ("time", "contact_pair"),
            force,
            {"units": "N", "long_name": "compliant pair's force, > 0 pushing it apart"},
        )
    for statistic in ("peak", "rms"):
        values = np.asarray(getattr(sol, statistic))
        if values.shape == (n,):
            arrays[statistic] = ("structure_coordinate", values, {"units": "m"})
    strobe = np.asarray(sol.strobe)
    if strobe.ndim == 2 and strobe.size:
        # A strobe row is the state as the run keeps it: every displacement (the
        # structure's, then the dampers'), then every velocity.
        order = (
            ("structure_displacement", n),
            ("damper_displacement", k),
            ("structure_velocity", n),
            ("damper_velocity", k),
        )
        names = [f"{name}_{i}" for name, count in order for i in range(count)]
        coordinates["strobe_time"] = ("strobe_time", sol.strobe_time, {"units": "s"})
        coordinates["state"] = ("state", names)
        arrays["strobe"] = (("strobe_time", "state"), strobe, {"long_name": "strobed state"})
    return arrays, coordinates


def _followed(sol: Any) -> tuple[dict[str, Any], dict[str, Any]]:
    """The structure at ``[output] points`` (displacement over time, its recorded peak
    and RMS; m) over the dimension ``point`` and a cantilever's bending moment at
    ``[output] moments`` (N m) over ``moment_position``, each labelled by where it is
    (m from the clamp, or a coordinate index): the CSV's ``point_displacement_j`` and
    ``bending_moment_j`` columns."""
    points, moments = np.asarray(sol.points), np.asarray(sol.moments)
    beam = sol.structure.get("kind") == "cantilever"
    where = (
        {"units": "m", "long_name": "position along the beam from the clamp"}
        if beam
        else {"units": "1", "long_name": "structure coordinate index"}
    )
    arrays: dict[str, Any] = {}
    coordinates: dict[str, Any] = {}
    followed = (
        ("point", points, "point_displacement", sol.displacement_at, "point", "m"),
        ("moment_position", moments, "bending_moment", sol.moment_at, "moment", "N m"),
    )
    for dim, positions, name, value_at, stem, unit in followed:
        if not len(positions):
            continue
        coordinates[dim] = (dim, positions, where)
        values = np.column_stack([value_at(at) for at in positions])
        arrays[name] = (("time", dim), values, {"units": unit})
        for statistic in ("peak", "rms"):
            arrays[f"{stem}_{statistic}"] = (
                dim,
                getattr(sol, f"{stem}_{statistic}"),
                {"units": unit},
            )
    return arrays, coordinates


def to_pandas(contacts: Any) -> Any:
    """A contact table as a ``pandas.DataFrame`` (see ``contacts_frame``): the
    two-mass run's ``sol.contacts`` (a ``ContactTable``, compiled, without methods of
    Python's) as a 0.2 run's ``sol.contacts.to_pandas()``."""
    if not hasattr(contacts, "columns") or not hasattr(contacts, "to_dicts"):
        raise InvalidInputError(
            f"contacts: must be a contact table (sol.contacts), got {type(contacts).__name__}"
        )
    return contacts_frame(contacts)


def to_xarray(sol: Any) -> Any:
    """A run's history as an ``xarray.Dataset`` (see ``history_dataset``): the
    two-mass run's ``Solution`` as a 0.2 run's ``sol.to_xarray()``."""
    if not hasattr(sol, "t") or not hasattr(sol, "contacts"):
        raise InvalidInputError(
            f"sol: must be a run's solution (vibroimpact.simulate), got {type(sol).__name__}"
        )
    return history_dataset(sol)
