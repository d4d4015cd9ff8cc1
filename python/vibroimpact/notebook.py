"""HTML summaries for notebooks (``_repr_html_``): a system's parts and a run's method,
steps, contacts, energy ledger and final time as a two-column table, every value
HTML-escaped (a recorded signal's file name is the user's text). Numbers to 6
significant digits, SI units; the short ``repr`` stays the one-line text summary."""

from __future__ import annotations

import html
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from vibroimpact.summary import brief, to_pandas, to_xarray
from vibroimpact.units import parameter_units

Rows = list[tuple[str, str]]


def html_table(title: str, rows: Sequence[tuple[str, str]]) -> str:
    """A captioned table of ``(name, value)`` rows, every text escaped."""
    body = "".join(
        f'<tr><th style="text-align:left">{html.escape(name)}</th>'
        f'<td style="text-align:left">{html.escape(value)}</td></tr>'
        for name, value in rows
    )
    return (
        f'<table class="vibroimpact"><caption>{html.escape(title)}</caption>'
        f"<tbody>{body}</tbody></table>"
    )


def _with_unit(value: Any, unit: str | None) -> str:
    shown = brief(value)
    return shown if unit in (None, "1") else f"{shown} {unit}"


def _keys(path: str, table: Mapping[str, Any], sections: Mapping[str, Any]) -> str:
    """``key = value unit, ...`` of a scenario table (``path``, such as ``"damper.0"``,
    finds each key's unit)."""
    return ", ".join(
        f"{key} = {_with_unit(value, parameter_units(f'{path}.{key}', sections))}"
        for key, value in table.items()
        if key != "kind"
    )


def system_rows(system: Any, natural: str = "") -> Rows:
    """The rows of a :class:`~vibroimpact.System`'s table: the structure (and, for a beam
    given by its section or material, the values it is simulated with), each damper,
    stop and excitation, gravity, the initial state and the run settings given;
    ``natural``, the natural frequencies' row (see
    :func:`vibroimpact.model.modes.frequencies_summary`)."""
    sections = system.to_dict()
    structure = sections["structure"]
    rows: Rows = [(f"structure ({structure['kind']})", _keys("structure", structure, sections))]
    if structure["kind"] == "cantilever" and any(
        key in structure for key in ("section", "material", "density")
    ):
        resolved = system.structure.resolved()
        shown = {k: resolved[k] for k in ("youngs_modulus", "second_moment", "mass_per_length")}
        rows.append(("beam as simulated", _keys("structure", shown, sections)))
    if natural:
        rows.append(("natural frequencies", natural))
    for name in ("damper", "stop", "collision", "friction", "excitation"):
        for j, table in enumerate(sections.get(name, ())):
            label = f"{name} {j}" + (f" ({table['kind']})" if name == "excitation" else "")
            rows.append((label, _keys(f"{name}.{j}", table, sections)))
    for name in ("gravity", "initial", "solver", "output"):
        if name in sections and sections[name]:
            rows.append((name, _keys(name, sections[name], sections)))
    analyses = [name for name in sections if name in system.analyses]
    if analyses:
        rows.append(("analyses", ", ".join(f"[{name}]" for name in analyses)))
    return rows


def _contact_counts(contacts: Any) -> str:
    kinds = list(getattr(contacts, "kind", ()))
    counts = ", ".join(f"{kinds.count(kind)} {kind}" for kind in sorted(set(kinds)))
    return f"{len(contacts)}" + (f" ({counts})" if counts else "")


def solution_rows(sol: Any) -> Rows:
    """The rows of a run's table: what was run, by which method, the final time, the
    steps, the contacts and the energy ledger's totals (J); a 0.2 run's
    (:class:`~vibroimpact.SystemSolution`) or the two-mass run's
    (``vibroimpact.Solution``)."""
    two_mass = not hasattr(sol, "structure_displacement")
    if two_mass:
        what = "two-mass impact damper"
    else:
        kind = sol.structure.get("kind", "structure") if sol.structure else "structure"
        n, k = sol.structure_displacement.shape[1], sol.damper_displacement.shape[1]
        what = f"{kind}: {n} coordinate(s), {k} damper(s)"
    rows: Rows = [("system", what), ("method", str(sol.method))]
    if two_mass:
        rows.append(("stepping", str(sol.stepping)))
    rows += [
        ("final time", _with_unit(float(sol.final_time), "s")),
        ("steps", brief(int(sol.steps))),
        ("rejected steps", brief(int(sol.rejected_steps))),
        ("right-hand side evaluations", brief(int(sol.rhs_evaluations))),
        ("grazing contacts", brief(int(sol.grazing_contacts))),
        ("contacts", _contact_counts(sol.contacts)),
    ]
    if not two_mass and sol.contacts.pair:
        rows.append(("pairs", ", ".join(sorted(set(sol.contacts.pair)))))
    rows.append(("rows kept", brief(len(sol.t))))
    dissipated = float(np.sum(sol.contacts.energy_dissipated))
    if two_mass:
        rows += [
            ("energy dissipated by contacts", _with_unit(dissipated, "J")),
            ("energy growth", _with_unit(float(sol.energy_growth), "J")),
            ("energy residual", _with_unit(float(sol.energy_residual), "J")),
        ]
    else:
        rows += [
            (f"energy {key.replace('_', ' ')}", _with_unit(float(value), "J"))
            for key, value in sol.energy.items()
        ]
    return rows


def system_html(system: Any, natural: str = "") -> str:
    """A System as an HTML table (its ``_repr_html_``), with the row ``natural``."""
    return html_table("vibroimpact.System", system_rows(system, natural))


def solution_html(sol: Any) -> str:
    """A run's solution as an HTML table (its ``_repr_html_``)."""
    return html_table(f"vibroimpact.{type(sol).__name__}", solution_rows(sol))


def add_views(solution: type, contacts: type) -> None:
    """Give the two-mass run's compiled ``Solution`` and ``ContactTable`` the views a
    0.2 run's results have: ``sol.to_xarray()``, ``sol._repr_html_()`` and
    ``sol.contacts.to_pandas()``."""

    def to_xarray_view(self: Any) -> Any:
        """The history as an ``xarray.Dataset`` over ``time`` (s), each array with its
        units, the run's statistics and energy (J) as attributes."""
        return to_xarray(self)

    def to_pandas_view(self: Any) -> Any:
        """The table as a ``pandas.DataFrame``, one row per contact (pandas needed)."""
        return to_pandas(self)

    def html_view(self: Any) -> str:
        """A summary table for notebooks: method, steps, contacts, energy (J), final
        time (s)."""
        return solution_html(self)

    views = (
        (solution, "to_xarray", to_xarray_view),
        (solution, "_repr_html_", html_view),
        (contacts, "to_pandas", to_pandas_view),
    )
    for cls, name, view in views:
        setattr(cls, name, view)
