"""The forced-response analyses' results as labelled xarray Datasets.

Each function takes what an analysis of :mod:`vibroimpact.analysis`,
:mod:`vibroimpact.analysis.maps` or :mod:`vibroimpact.analysis.continuation` returns and gives an
:class:`xarray.Dataset` with named dimensions, coordinates and, on every variable,
a ``long_name`` and, for a physical quantity, its SI ``units`` (UDUNITS spelling,
as CF asks: ``"m"``, ``"m s-1"``, ``"rad"``, ``"1"`` for a dimensionless one).

A sweep written as a NetCDF 4 file (:func:`vibroimpact.netcdf.write_netcdf`, also
``vibroimpact.write_netcdf``)::

    import vibroimpact as vi
    from vibroimpact.analysis import sweep
    from vibroimpact.analysis.datasets import sweep_dataset

    data = vi.load_scenario("examples/frf_impact_damper.toml").data
    points = sweep(data, "excitation.0.frequency", [9.0, 10.0, 11.0])
    vi.write_netcdf(sweep_dataset(points, "excitation.0.frequency"), "frf.nc")

and read with ``xr.open_dataset("frf.nc")``. Every Dataset is written as NetCDF 4 (HDF5,
by h5netcdf: no netCDF C library needed) and read back identical, dtypes included:
numbers are float64 or int64, compressed in the file; booleans are kept as ``bool``
(written by xarray as int8 with the attribute ``dtype = "bool"``, read back as ``bool``);
strings are kept as ``str`` (variable-length strings in the file); complex Floquet
multipliers are split into real and imaginary parts (NetCDF has no complex type);
lists of records that NetCDF attributes cannot hold (a basin's attractors) are a JSON
string attribute. ``Dataset.to_netcdf(path)`` with xarray's default engine writes the
same content, uncompressed and not whole-or-nothing.

State vectors use the analyses' flat state ``(x, v)``: the ``n`` structure
coordinates' then the ``k`` dampers' displacements, then the same velocities. A
``state`` dimension names each entry (``"structure_displacement_0"``, ...,
``"damper_velocity_0"``) and its coordinate ``state_units`` gives each entry's
unit (``"m"`` or ``"m s-1"``); a variable along ``state`` mixes the two and so has
no single ``units`` attribute. A cantilever's structure coordinates are modal
amplitudes (m, the shapes being dimensionless).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from vibroimpact import arguments
from vibroimpact._core import __version__
from vibroimpact.analysis.continuation import Branch
from vibroimpact.analysis.limits import AnalysisError
from vibroimpact.analysis.maps import Basins, BifurcationPoint, Section
from vibroimpact.analysis.sweeps import SweepPoint, reductions
from vibroimpact.messages import shown
from vibroimpact.output import json_text
from vibroimpact.units import (
    _M,
    _M_S,
    _NM,
    _ONE,
    _state_unit,
    parameter_units,
    state_names,
)

__all__ = [
    "basins_dataset",
    "bifurcation_dataset",
    "branch_dataset",
    "parameter_units",
    "section_dataset",
    "state_names",
    "sweep_dataset",
]

_CROSSINGS = ("fold", "flip", "neimark-sacker", "branch")
_SOURCE = f"vibroimpact {__version__}"


def _state_coords(size: int, n: int | None, k: int | None) -> dict[str, Any]:
    """The ``state`` coordinate (entry names) and ``state_units`` of a flat state of
    ``size`` entries; without ``n`` and ``k`` the names are ``displacement_i`` and
    ``velocity_i`` (the first half of the state are displacements)."""
    half = size // 2
    if n is not None and k is not None:
        names = state_names(n, k)
    else:
        names = [f"displacement_{i}" for i in range(half)]
        names += [f"velocity_{i}" for i in range(half)]
    units = [_M] * half + [_M_S] * half
    return {
        "state": (
            "state",
            np.array(names, dtype=str),
            {"long_name": "entry of the flat state (x, v)"},
        ),
        "state_units": (
            "state",
            np.array(units, dtype=str),
            {"long_name": "unit of the state entry"},
        ),
    }


def _strings(values: Sequence[str]) -> NDArray[np.str_]:
    """Strings as a NumPy unicode array (written as NetCDF 4 variable-length strings)."""
    return np.array(list(values), dtype=str)


def _attrs(long_name: str, units: str | None = None, **more: Any) -> dict[str, Any]:
    out: dict[str, Any] = {"long_name": long_name}
    if units is not None:
        out["units"] = units
    out.update(more)
    return out


def _value_coord(
    values: Sequence[float], parameter: str, units: str | None
) -> tuple[str, NDArray[np.float64], dict[str, Any]]:
    units = parameter_units(parameter) if units is None else units
    return (
        "point",
        np.array(values, dtype=np.float64),
        _attrs(parameter, units, name=parameter),
    )


def _count(name: str, value: int, low: int) -> None:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < low:
        raise AnalysisError(f"{name}: must be a whole number >= {low}, got {shown(value)}")


def _results(name: str, values: Any, kind: type, made_by: str) -> None:
    """A list of an analysis's results, each a ``kind`` (an AttributeError deep inside
    had named nothing)."""
    if not isinstance(values, list | tuple):
        raise AnalysisError(f"{name}: must be a list (from {made_by}), got {shown(values)}")
    for i, value in enumerate(values):
        arguments.instance(f"{name}[{i}]", value, kind, made_by)


def _names(**given: Any) -> None:
    """Parameter and state names: strings; units: a string or None."""
    for name, value in given.items():
        if name != "units" or value is not None:
            arguments.text(name, value)


def sweep_dataset(
    points: list[SweepPoint], parameter: str, *, units: str | None = None
) -> xr.Dataset:
    """A sweep's points (:func:`vibroimpact.sweep`) as a Dataset.

    Dimensions ``point`` (in the sweep's order, up then down) and ``coordinate``
    (the structure's coordinates, with an integer coordinate 0, 1, ...).
    Coordinates along ``point``: ``value``, the swept parameter (attributes
    ``name`` = ``parameter`` and its ``units``, from ``units`` or else
    :func:`parameter_units`), and ``direction`` (``"up"`` or ``"down"``).
    Variables: ``amplitude`` and ``rms`` (m, NaN where the point's run failed),
    ``linear_amplitude`` (m, the structure alone), ``reduction`` (``1 - amplitude /
    linear_amplitude``, NaN where either is not finite or the linear one is round-off:
    see :func:`vibroimpact.analysis.reductions`),
    all ``point`` x ``coordinate``; ``impacts_per_period``, ``settled`` (bool) and
    ``error`` (the failed run's message, ``""`` where none) along ``point``. With
    ``[output] points``, a dimension ``at`` (the points: m along a cantilever, else
    coordinate indices) and the same four of the structure there, ``point x at``:
    ``point_amplitude``, ``point_rms``, ``linear_point_amplitude``,
    ``point_reduction``; with ``[output] moments``, a dimension ``moment_at`` (m along
    the cantilever) and the bending moment's (N m): ``moment_amplitude``,
    ``moment_rms``, ``linear_moment_amplitude``, ``moment_reduction``. Attributes:
    ``parameter``."""
    _results("points", points, SweepPoint, "vibroimpact.analysis.sweep")
    _names(parameter=parameter, units=units)
    if not points:
        raise AnalysisError("sweep_dataset: no points")
    n = len(points[0].linear_amplitude)
    at = np.asarray(points[0].points, dtype=np.float64)
    moment_at = np.asarray(points[0].moments, dtype=np.float64)

    def rows(name: str, size: int = n) -> NDArray[np.float64]:
        out = np.array([getattr(p, name) for p in points], dtype=np.float64).reshape(
            len(points), -1
        )
        if out.shape != (len(points), size):
            raise AnalysisError(f"sweep_dataset: every point's {name} must have {size} values")
        return out

    amplitude = rows("amplitude")
    linear = rows("linear_amplitude")
    pc = ("point", "coordinate")
    at_points: dict[str, Any] = {}
    positions: dict[str, Any] = {}
    for kind, dim, where, unit, what, position in (
        (
            "point",
            "at",
            at,
            _M,
            ("the structure at the point", "displacement at the point"),
            _attrs("point of the structure ([output] points)"),
        ),
        (
            "moment",
            "moment_at",
            moment_at,
            _NM,
            ("the bending moment", "bending moment"),
            _attrs("position of a bending moment ([output] moments)", _M),
        ),
    ):
        if not len(where):
            continue
        positions[dim] = (dim, where, position)
        followed = rows(f"{kind}_amplitude", len(where))
        linear_followed = rows(f"linear_{kind}_amplitude", len(where))
        pf = ("point", dim)
        at_points |= {
            f"{kind}_amplitude": (pf, followed, _attrs(f"steady amplitude of {what[0]}", unit)),
            f"{kind}_rms": (
                pf,
                rows(f"{kind}_rms", len(where)),
                _attrs(f"steady root mean square {what[1]}", unit),
            ),
            f"linear_{kind}_amplitude": (
                pf,
                linear_followed,
                _attrs(
                    f"steady amplitude of {what[0]}, the structure alone (no dampers, no stops)",
                    unit,
                ),
            ),
            f"{kind}_reduction": (
                pf,
                reductions(followed, linear_followed),
                _attrs(f"amplitude reduction of {what[0]}", _ONE),
            ),
        }
    return xr.Dataset(
        data_vars={
            "amplitude": (pc, amplitude, _attrs("steady amplitude (largest |displacement|)", _M)),
            "rms": (pc, rows("rms"), _attrs("steady root mean square displacement", _M)),
            "linear_amplitude": (
                pc,
                linear,
                _attrs("steady amplitude of the structure alone (no dampers, no stops)", _M),
            ),
            "reduction": (
                pc,
                reductions(amplitude, linear),
                _attrs("amplitude reduction, 1 - amplitude / linear_amplitude", _ONE),
            ),
            **at_points,
            "impacts_per_period": (
                "point",
                np.array([p.impacts_per_period for p in points], dtype=np.float64),
                _attrs("impacts per forcing period", _ONE),
            ),
            "settled": (
                "point",
                np.array([p.settled for p in points], dtype=bool),
                _attrs("whether the stroboscopic state repeated (a periodic steady state)"),
            ),
            "error": (
                "point",
                _strings([p.error or "" for p in points]),
                _attrs('why the point\'s run failed ("" where it did not)'),
            ),
        },
        coords={
            "value": _value_coord([p.value for p in points], parameter, units),
            "direction": (
                "point",
                _strings([p.direction for p in points]),
                _attrs("direction of the sweep's leg"),
            ),
            "coordinate": (
                "coordinate",
                np.arange(n, dtype=np.int64),
                _attrs("structure coordinate (index)"),
            ),
            **positions,
        },
        attrs={"parameter": parameter, "source": _SOURCE},
    )


def bifurcation_dataset(
    points: list[BifurcationPoint],
    parameter: str,
    *,
    n: int | None = None,
    k: int | None = None,
    units: str | None = None,
) -> xr.Dataset:
    """A bifurcation diagram (:func:`vibroimpact.bifurcation`) as a Dataset.

    Dimensions ``point``, ``sample`` (the stroboscopic samples, with the coordinate
    ``sample`` = forcing periods after settling: 1, 2, ...) and ``state`` (the flat
    state's entries, named by the coordinate ``state``, with ``state_units``; the
    names are those of :func:`state_names` when the structure's ``n`` coordinates
    and ``k`` dampers are given, ``displacement_i`` and ``velocity_i`` otherwise).
    Coordinates along ``point``: ``value`` (attributes ``name`` = ``parameter``,
    ``units``) and ``direction``. Variables: ``strobe`` (``point`` x ``sample`` x
    ``state``, NaN-padded past a point's own samples and where its run failed),
    ``sample_count`` (each point's samples, 0 where its run failed) and ``error``
    (``""`` where none). Attributes: ``parameter``."""
    _results("points", points, BifurcationPoint, "vibroimpact.analysis.bifurcation")
    _names(parameter=parameter, units=units)
    if not points:
        raise AnalysisError("bifurcation_dataset: no points")
    if (n is None) != (k is None):
        raise AnalysisError("bifurcation_dataset: give both n and k, or neither")
    if n is not None and k is not None:
        _count("n", n, 0)
        _count("k", k, 0)
        width = 2 * (n + k)
    else:
        width = max((p.strobe.shape[1] for p in points if p.strobe.size), default=0)
    good = [p.strobe for p in points if p.strobe.size]
    for strobe in good:
        if strobe.ndim != 2 or strobe.shape[1] != width:
            raise AnalysisError(
                f"bifurcation_dataset: every strobe must have {width} columns (the flat "
                f"state), got shape {strobe.shape}"
            )
    samples = max((len(s) for s in good), default=0)
    # At least one sample: where every run failed each point still has its row (NaN).
    samples = max(samples, 1)
    strobe = np.full((len(points), samples, width), np.nan)
    counts = np.zeros(len(points), dtype=np.int64)
    for i, p in enumerate(points):
        if p.strobe.size:
            strobe[i, : len(p.strobe)] = p.strobe
            counts[i] = len(p.strobe)
    return xr.Dataset(
        data_vars={
            "strobe": (
                ("point", "sample", "state"),
                strobe,
                _attrs(
                    "stroboscopic state (each entry's unit: state_units)",
                    comment="NaN past a point's samples and where its run failed",
                ),
            ),
            "sample_count": ("point", counts, _attrs("stroboscopic samples of the point", _ONE)),
            "error": (
                "point",
                _strings([p.error or "" for p in points]),
                _attrs('why the point\'s run failed ("" where it did not)'),
            ),
        },
        coords={
            "value": _value_coord([p.value for p in points], parameter, units),
            "direction": (
                "point",
                _strings([p.direction for p in points]),
                _attrs("direction of the leg"),
            ),
            "sample": (
                "sample",
                np.arange(1, samples + 1, dtype=np.int64),
                _attrs("forcing periods after settling", _ONE),
            ),
            **_state_coords(width, n, k),
        },
        attrs={"parameter": parameter, "source": _SOURCE},
    )


def section_dataset(section: Section, n: int, k: int) -> xr.Dataset:
    """A Poincare section (:func:`vibroimpact.poincare`) of a system of ``n``
    structure coordinates and ``k`` dampers as a Dataset.

    Dimensions ``sample`` (coordinate: forcing periods after settling, 1, 2, ...)
    and ``state`` (coordinates ``state``, named as by :func:`state_names`, and
    ``state_units``) for the stroboscopic section ``strobe``; ``impact`` for the
    impact section: ``impact_phase`` (rad, in [0, 2 pi) of the forcing period),
    ``impact_speed`` (m s-1, the approach speed) and ``impact_pair`` (the pair's
    name, such as ``"damper 0"``). Attributes: ``structure_coordinates`` (n) and
    ``dampers`` (k). With no impact the ``impact`` dimension has length 0."""
    arguments.instance("section", section, Section, "vibroimpact.analysis.poincare")
    _count("n", n, 0)
    _count("k", k, 0)
    width = 2 * (n + k)
    strobe = np.asarray(section.strobe, dtype=np.float64)
    if strobe.ndim != 2 or strobe.shape[1] != width:
        raise AnalysisError(
            f"section_dataset: the strobe must have {width} columns (2 (n + k)), got shape "
            f"{strobe.shape}"
        )
    size = len(section.impact_phase)
    if len(section.impact_speed) != size or len(section.impact_pair) != size:
        raise AnalysisError("section_dataset: impact_phase, impact_speed, impact_pair differ")
    return xr.Dataset(
        data_vars={
            "strobe": (
                ("sample", "state"),
                strobe,
                _attrs("stroboscopic state (each entry's unit: state_units)"),
            ),
            "impact_phase": (
                "impact",
                np.asarray(section.impact_phase, dtype=np.float64),
                _attrs("phase of the impact in the forcing period", "rad"),
            ),
            "impact_speed": (
                "impact",
                np.asarray(section.impact_speed, dtype=np.float64),
                _attrs("approach speed of the impact", _M_S),
            ),
            "impact_pair": (
                "impact",
                _strings(section.impact_pair),
                _attrs("pair that impacts"),
            ),
        },
        coords={
            "sample": (
                "sample",
                np.arange(1, len(strobe) + 1, dtype=np.int64),
                _attrs("forcing periods after settling", _ONE),
            ),
            **_state_coords(width, n, k),
        },
        attrs={"structure_coordinates": n, "dampers": k, "source": _SOURCE},
    )


_LABELS = (
    "0, 1, ...: index into the attractors (attribute attractors, JSON: each one's period "
    "in forcing periods, impacts_per_period and amplitude in m per structure coordinate); "
    "-1: the run did not settle; -2: the run failed; -3: the start is not admissible "
    "(a pair inside its wall)"
)


def basins_dataset(result: Basins, x_name: str, y_name: str) -> xr.Dataset:
    """Basins of attraction (:func:`vibroimpact.basins`) as a Dataset.

    Dimensions ``x`` and ``y``, with coordinates the two initial values varied
    (``result.first`` and ``result.second``), each with the attribute ``name``
    (``x_name``, ``y_name``: the state entry, such as
    ``"structure_displacement.0"``) and its ``units`` (m or m s-1, told from the
    name). Variable ``label`` (``x`` x ``y``, int64): the attractor reached from
    each start, an index into the attractors; -1 where the run did not settle, -2
    where it failed, -3 where the start is not admissible; its attributes
    ``flag_values`` and ``flag_meanings`` name the negative ones (CF). Attributes:
    ``attractors`` (a JSON list of ``{period, impacts_per_period, amplitude}``:
    NetCDF attributes cannot hold a list of records), ``label_meanings`` (the
    labels in words), ``x_name``, ``y_name``."""
    arguments.instance("result", result, Basins, "vibroimpact.analysis.basins")
    _names(x_name=x_name, y_name=y_name)
    first = np.asarray(result.first, dtype=np.float64)
    second = np.asarray(result.second, dtype=np.float64)
    labels = np.asarray(result.labels)
    if labels.shape != (len(first), len(second)):
        raise AnalysisError(
            f"basins_dataset: labels must have shape {(len(first), len(second))}, got "
            f"{labels.shape}"
        )
    attractors = json_text(list(result.attractors))
    return xr.Dataset(
        data_vars={
            "label": (
                ("x", "y"),
                labels.astype(np.int64),
                _attrs(
                    "attractor reached",
                    flag_values=np.array([-3, -2, -1], dtype=np.int64),
                    flag_meanings="inadmissible_start run_failed not_settled",
                    comment=_LABELS,
                ),
            ),
        },
        coords={
            "x": ("x", first, _attrs(x_name, _state_unit(x_name), name=x_name)),
            "y": ("y", second, _attrs(y_name, _state_unit(y_name), name=y_name)),
        },
        attrs={
            "attractors": attractors,
            "label_meanings": _LABELS,
            "x_name": x_name,
            "y_name": y_name,
            "source": _SOURCE,
        },
    )


def branch_dataset(branch: Branch, *, units: str | None = None) -> xr.Dataset:
    """A continued branch (:func:`vibroimpact.continue_orbit`) as a
    Dataset.

    Dimensions ``point`` (along the branch), ``state`` (coordinates ``state``, as
    :func:`state_names` of the branch's ``n`` and ``k``, and ``state_units``),
    ``multiplier`` (the Floquet multipliers, 2 (n + k), in the order of the
    eigenvalue solver: not tracked from point to point), ``coordinate`` (the
    structure's) and ``bifurcation`` (``"fold"``, ``"flip"``, ``"neimark-sacker"``,
    ``"branch"``). Coordinate ``value`` along ``point`` (attributes ``name`` = the
    parameter and ``units``, from ``units`` or else :func:`parameter_units`).
    Variables: ``orbit_state`` (``point`` x ``state``: the state on the orbit at
    t = 0; named so since a variable cannot share the name of the ``state``
    dimension), ``multiplier_real`` and ``multiplier_imag`` (``point`` x
    ``multiplier``, 1), ``stable`` (bool), ``impacts_per_period``, ``amplitude``
    (``point`` x ``coordinate``, m), ``flags`` (the bifurcations flagged between
    the previous point and this one, comma-joined, ``""`` where none) and
    ``crossing`` (``point`` x ``bifurcation``: the parameter's value where the
    flagged bifurcation lies, NaN where not flagged). Attributes: ``parameter``,
    ``periods`` (K), ``stopped`` (why the continuation stopped),
    ``structure_coordinates`` (n), ``dampers`` (k)."""
    arguments.instance("branch", branch, Branch, "vibroimpact.analysis.continue_orbit")
    _names(units=units)
    points = branch.points
    if not points:
        raise AnalysisError("branch_dataset: no points")
    width = 2 * (branch.n + branch.k)
    state = np.array([p.state for p in points], dtype=np.float64)
    multipliers = np.array([p.floquet_multipliers for p in points], dtype=np.complex128)
    amplitude = np.array([p.amplitude for p in points], dtype=np.float64)
    if state.shape != (len(points), width) or multipliers.shape != (len(points), width):
        raise AnalysisError(
            f"branch_dataset: every point's state and multipliers must have {width} values"
        )
    if amplitude.ndim != 2 or amplitude.shape[1] != branch.n:
        raise AnalysisError(f"branch_dataset: every point's amplitude must have {branch.n} values")
    kinds = list(_CROSSINGS)
    for p in points:
        kinds += [name for name in p.crossings if name not in kinds]
    crossing = np.full((len(points), len(kinds)), np.nan)
    for i, p in enumerate(points):
        for name, value in p.crossings.items():
            crossing[i, kinds.index(name)] = value
    parameter_unit = parameter_units(branch.parameter) if units is None else units
    pm = ("point", "multiplier")
    return xr.Dataset(
        data_vars={
            "orbit_state": (
                ("point", "state"),
                state,
                _attrs("state on the orbit at t = 0 (each entry's unit: state_units)"),
            ),
            "multiplier_real": (
                pm,
                multipliers.real.copy(),
                _attrs("Floquet multiplier, real part", _ONE),
            ),
            "multiplier_imag": (
                pm,
                multipliers.imag.copy(),
                _attrs("Floquet multiplier, imaginary part", _ONE),
            ),
            "stable": (
                "point",
                np.array([p.stable for p in points], dtype=bool),
                _attrs("whether every Floquet multiplier lies inside the unit circle"),
            ),
            "impacts_per_period": (
                "point",
                np.array([p.impacts_per_period for p in points], dtype=np.float64),
                _attrs("impacts per forcing period", _ONE),
            ),
            "amplitude": (
                ("point", "coordinate"),
                amplitude,
                _attrs("amplitude on the orbit (largest |displacement|)", _M),
            ),
            "flags": (
                "point",
                _strings([",".join(p.flags) for p in points]),
                _attrs("bifurcations flagged since the previous point (comma-separated)"),
            ),
            "crossing": (
                ("point", "bifurcation"),
                crossing,
                _attrs(
                    f"{branch.parameter} where the flagged bifurcation lies",
                    parameter_unit,
                ),
            ),
        },
        coords={
            "value": _value_coord([p.value for p in points], branch.parameter, units),
            "coordinate": (
                "coordinate",
                np.arange(branch.n, dtype=np.int64),
                _attrs("structure coordinate (index)"),
            ),
            "bifurcation": ("bifurcation", _strings(kinds), _attrs("kind of bifurcation")),
            **_state_coords(width, branch.n, branch.k),
        },
        attrs={
            "parameter": branch.parameter,
            "periods": branch.periods,
            "stopped": branch.stopped,
            "structure_coordinates": branch.n,
            "dampers": branch.k,
            "source": _SOURCE,
        },
    )
