"""A scenario's analyses' parameter paths checked against its sections' keys as the
scenario is read (``excitation.0.freq`` had been taken by a run, and refused only when its
analysis ran)."""

from __future__ import annotations

import difflib
from collections.abc import Mapping, Sequence
from typing import Any

from vibroimpact._core import InvalidInputError
from vibroimpact.system import schema


def _known_keys(data: Mapping[str, Any], section: str) -> Sequence[str] | None:
    """The keys a section of ``data`` may have (a structure's, its kind's), or None
    where that is not known here."""
    if section == "structure":
        structure = data.get("structure")
        kind = structure.get("kind") if isinstance(structure, Mapping) else None
        kinds = [kind] if kind in schema._STRUCTURE else list(schema._STRUCTURE)
        return sorted({key for k in kinds for key in schema._STRUCTURE[k]})
    tables: dict[str, Mapping[str, Any]] = {
        "damper": schema._DAMPER,
        "stop": schema._STOP,
        "collision": schema._COLLISION,
        "friction": schema._FRICTION,
        "gravity": schema._GRAVITY,
        "excitation": schema._EXCITATION,
        "initial": schema._INITIAL,
        "solver": schema._SOLVER,
    }
    return list(tables[section]) if section in tables else None


def parameter_paths(analyses: Mapping[str, Any]) -> list[tuple[str, str]]:
    """``(where, path)`` of every parameter path the analyses' sections name: the
    sweep's parameter and derivatives, the continuation's and the curve's parameters, a
    study's axes and draws."""
    found: list[tuple[str, str]] = []

    def table(name: str) -> Mapping[str, Any]:
        value = analyses.get(name)
        return value if isinstance(value, Mapping) else {}

    named = [("sweep", "parameter"), ("continuation", "parameter")]
    named += [("curve", "parameter"), ("curve", "second")]
    found += [(f"[{name}] {k}", table(name)[k]) for name, k in named if k in table(name)]
    derivatives = table("sweep").get("derivatives", [])
    found += [("[sweep] derivatives", p) for p in derivatives if isinstance(p, str)]
    # A study's axes and draws: what a study may vary is checked when it is made; the
    # key's spelling here, so that a plain run of the file does not take a misspelt one.
    study = table("study")
    for name in ("axes", "random"):
        paths = study.get(name)
        if isinstance(paths, Mapping):
            found += [(f"[study.{name}]", p) for p in paths if isinstance(p, str)]
    return [(where, path) for where, path in found if isinstance(path, str)]


def check_parameter_keys(data: Mapping[str, Any]) -> None:
    """Refuse, as a scenario is read, a parameter path whose key its section does not
    have (``excitation.0.freq``): it had been refused only when its analysis ran, after a
    plain run of the same file had taken it."""
    for where, path in parameter_paths(data):
        # A study's axis that is no misspelling (a section's height on an oscillator)
        # is left to the study's own check, which says what a study of it may vary.
        check_parameter_key(data, where, path, typos_only=where.startswith("[study."))


def check_parameter_key(
    data: Mapping[str, Any], where: str, path: str, typos_only: bool = False
) -> None:
    """Refuse the parameter path ``path`` (named ``where`` in the message) where its
    section's key is not one that section has, with the closest one (``typos_only``:
    only where one is close)."""
    parts = path.split(".")
    if not typos_only:
        check_entry(data, where, path)
    known = _known_keys(data, parts[0])
    key = next((p for p in parts[1:] if not p.isdigit()), None)
    if known is None or key is None or key in known:
        return
    close = difflib.get_close_matches(key, known, 1)
    if typos_only and not close:
        return
    hint = f"; did you mean {close[0]!r}?" if close else f" (allowed: {', '.join(known)})"
    raise InvalidInputError(f"{where}: {path!r}: [{parts[0]}] has no key {key!r}{hint}")


def check_entry(
    data: Mapping[str, Any],
    where: str,
    path: str,
    error: type[InvalidInputError] = InvalidInputError,
) -> None:
    """Refuse (as ``error``) a path into an entry the scenario does not have
    (``excitation.1.frequency`` with one excitation) or onto a value that is no number
    (``damper.0.law``): a plain run had taken the first, and the analysis refused either
    only as it ran, the second as a value its schema refused ('law: must be a string,
    got 7.0'). The check of a scenario's paths as it is read, and of an analysis's
    parameter as it is set (``vibroimpact.analysis.with_parameter``)."""
    parts = path.split(".")
    node: Any = data.get(parts[0])
    for depth, key in enumerate(parts[1:], start=1):
        if isinstance(node, list) and key.isascii() and key.isdigit():
            if int(key) >= len(node):
                count = len(node)
                have = {0: "none", 1: "index 0"}.get(count, f"index 0 to {count - 1}")
                raise error(f"{where}: {path!r}: the scenario has {count} [[{parts[0]}]] ({have})")
            node = node[int(key)]
        elif isinstance(node, Mapping) and key in node:
            node = node[key]
        else:
            return  # a key left to its default, or a path the analysis refuses itself
        if depth == len(parts) - 1 and (isinstance(node, str | bool)):
            raise error(
                f"{where}: {path!r} is {node!r} in the scenario, not a number: an analysis "
                "varies a number"
            )
