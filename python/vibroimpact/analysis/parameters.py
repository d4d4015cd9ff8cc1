"""A scenario's sections as the analyses read and vary them: the forcing period of its
harmonics, a copy with one dotted parameter set, and the index of an entry of ``[initial]``
in the flat state ``(x, v)``."""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping, Sequence
from typing import Any

from vibroimpact import arguments
from vibroimpact._core import InvalidInputError
from vibroimpact._core import _forcing_period as _core_forcing_period
from vibroimpact.analysis.limits import AnalysisError, whole_count
from vibroimpact.messages import shown
from vibroimpact.system import RUN_SECTIONS
from vibroimpact.system.parameter_keys import check_entry


def forcing_period(data: Mapping[str, Any]) -> float:
    """The forcing period (s) of a scenario's sections: every excitation a sum of
    harmonics (``"harmonic"``, ``"harmonics"``; 0 Hz terms are constant), the period
    ``1 / f0`` of the highest ``f0`` of which every frequency is a whole multiple (10 and
    15 Hz: 0.2 s). The core's rule, the one studies apply."""
    arguments.sections("data", data)
    parts: list[tuple[str, list[float] | None]] = []
    excitations = data.get("excitation", ()) or ()
    if isinstance(excitations, Mapping):
        excitations = [excitations]  # one table, as the schema takes it
    if isinstance(excitations, str | bytes) or not isinstance(excitations, Sequence):
        raise AnalysisError(f"[[excitation]] must be a list of tables, got {shown(excitations)}")
    for excitation in excitations:
        table = excitation if isinstance(excitation, Mapping) else {}
        signal = str(table.get("signal"))
        given: list[Any]
        if signal == "harmonic":
            given = [table.get("frequency")]
        elif signal == "harmonics":
            given = list(table.get("frequencies") or [])
        else:
            parts.append((signal, None))
            continue
        frequencies = [f for f in given if isinstance(f, int | float) and not isinstance(f, bool)]
        if len(frequencies) != len(given):
            raise AnalysisError(
                f"excitation {len(parts)}: frequencies must be numbers (Hz) for a periodic "
                f"analysis, got {given!r:.60}"
            )
        bad = [f for f in frequencies if not 0.0 <= f < math.inf]
        if bad:
            # As the run names it (the core's period rule had said only that a periodic
            # analysis needs a harmonic excitation, naming no key).
            key = "frequency" if signal == "harmonic" else "frequencies"
            raise AnalysisError(
                f"excitation {len(parts)}.{key}: must be finite and >= 0 Hz, got {bad[0]!r}"
            )
        parts.append((signal, [float(f) for f in frequencies]))
    try:
        return _core_forcing_period(parts)
    except InvalidInputError as err:
        raise AnalysisError(str(err)) from None


def with_parameter(data: Mapping[str, Any], path: str, value: float) -> dict[str, Any]:
    """A deep copy of a scenario's sections with the dotted ``path`` (such as
    ``"excitation.0.frequency"`` or ``"damper.0.clearance"``) set to ``value``."""
    arguments.sections("data", data)
    arguments.text("path", path)
    value = arguments.number("value", value)
    out = copy.deepcopy(dict(data))
    parts = path.split(".")
    if parts[0] not in RUN_SECTIONS or len(parts) < 2:
        raise AnalysisError(
            f"parameter {path!r}: must be a dotted path into a section ({', '.join(RUN_SECTIONS)}),"
            ' such as "excitation.0.frequency"'
        )
    with_parameter_path_check(path, "")
    # An entry the scenario lacks, a value that is no number (a law's name): said of
    # the parameter, as when a scenario's paths are read.
    check_entry(out, "parameter", path, AnalysisError)
    node: Any = out
    for depth, key in enumerate(parts[:-1]):
        try:
            if isinstance(node, list):
                if not (key.isascii() and key.isdigit()):
                    raise ValueError(key)  # an index counts from 0, never from the end
                node = node[int(key)]
            else:
                if key not in node and depth == 0 and key in ("gravity", "initial", "output"):
                    node[key] = {}
                node = node[key]
        except (KeyError, IndexError, ValueError, TypeError):
            raise AnalysisError(
                f"parameter {path!r}: {'.'.join(parts[: depth + 1])} is not in the scenario"
            ) from None
        if isinstance(node, Mapping) is False and not isinstance(node, list):
            raise AnalysisError(f"parameter {path!r}: {'.'.join(parts[: depth + 1])} is a value")
    if isinstance(node, list):
        raise AnalysisError(f"parameter {path!r}: ends on a list; name an entry's key")
    current = node.get(parts[-1]) if isinstance(node, Mapping) else None
    if isinstance(current, list | tuple):
        # A matrix or an array: a sweep sets one number, which its check then
        # refused as the wrong shape ("must be an array of rows"), pointing at the value.
        kind = out.get("structure", {}).get("kind") if parts[0] == "structure" else None
        whose = f' (a structure of kind "{kind}" has no input one number sets)' if kind else ""
        raise AnalysisError(
            f"parameter {path!r}: is an array in the scenario, not one number; a sweep "
            f"varies one number{whose}"
        )
    if isinstance(current, int) and not isinstance(current, bool) and float(value).is_integer():
        # A whole-number key (a cantilever's modes, a seed) stays one: a sweep's
        # values are floats, which its check refused ("got 3.0", user trial).
        value = int(value)
    node[parts[-1]] = value
    return out


def state_index(path: str, n: int, k: int) -> int:
    """The index in the flat state ``(x, v)`` of ``"structure_velocity.0"`` etc."""
    arguments.text("path", path)
    n, k = whole_count("n", n, 0), whole_count("k", k, 0)
    name, _, index = path.partition(".")
    d = n + k
    places = {
        "structure_displacement": (n, 0),
        "damper_displacement": (k, n),
        "structure_velocity": (n, d),
        "damper_velocity": (k, d + n),
    }
    if name not in places or not (index.isascii() and index.isdigit()):
        raise AnalysisError(
            f"path: must be one of {', '.join(places)} and an index from 0 (such as "
            f'"structure_velocity.0"), got {path!r}'
        )
    i = int(index)
    size, offset = places[name]
    if i >= size:
        raise AnalysisError(f"{path}: must index one of the system's {size} {name} values (from 0)")
    return offset + i


def with_parameter_path_check(path: str, section: str = "[sweep]") -> None:
    """Refuse a ``parameter`` that is not a dotted path into a section, or whose
    index is not a whole number from 0 (``-1`` would count from the end)."""
    parts = path.split(".")
    where = f"{section} parameter" if section else f"parameter {path!r}"
    if parts[0] not in RUN_SECTIONS or len(parts) < 2 or "" in parts:
        raise AnalysisError(
            f"{where}: must be a dotted path into a section "
            f'({", ".join(RUN_SECTIONS)}), such as "excitation.0.frequency", got {path!r}'
        )
    for part in parts[1:]:
        if part.lstrip("+-").isdigit() and not (part.isascii() and part.isdigit()):
            raise AnalysisError(f"{where}: {part!r} in {path!r}: an index is a whole number from 0")
    if path == "solver.t_end" or parts[0] == "output":
        # The analyses run whole forcing periods and keep what they need: these
        # keys would change nothing, point after point.
        raise AnalysisError(
            f"{where}: {path!r} is not used by the analyses (they run settle and record "
            "periods, not [solver] t_end, and of [output] follow its points only); choose a "
            "parameter of the system"
        )


def shifted(data: dict[str, Any], fraction: float) -> dict[str, Any]:
    """``data`` with its harmonic excitations started ``fraction`` of the forcing period
    later (each phase advanced by its frequency times that time): t = 0 then is that
    instant of the original forcing."""
    if not fraction:
        return data
    out = copy.deepcopy(data)
    delay = fraction * forcing_period(out)
    for e in out.get("excitation", ()):
        if e.get("signal") == "harmonic":
            e["phase"] = float(e.get("phase", 0.0)) + 2 * math.pi * e["frequency"] * delay
        elif e.get("signal") == "harmonics":
            phases = list(e.get("phases", [0.0] * len(e["frequencies"])))
            e["phases"] = [
                float(ph) + 2 * math.pi * f * delay
                for ph, f in zip(phases, e["frequencies"], strict=True)
            ]
    return out
