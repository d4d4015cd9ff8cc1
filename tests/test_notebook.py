"""Notebook views: the HTML summary tables of a System and of both kinds of solution parse,
hold the numbers the object holds and escape the user's text; every result kind has its
pandas and xarray views."""

from __future__ import annotations

import math
import re
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

import vibroimpact as vi

HOSTILE = "<img src=x onerror=alert(1)>&amp;.csv"


class Table(HTMLParser):
    """The caption and the (th, td) rows of one table; tags checked to nest."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.open: list[str] = []
        self.tags: list[str] = []
        self.caption = ""
        self.rows: dict[str, str] = {}
        self._cell: list[str] = []
        self._name = ""

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.open.append(tag)
        self.tags.append(tag)
        self._cell = []

    def handle_endtag(self, tag: str) -> None:
        assert self.open and self.open.pop() == tag, (tag, self.open)
        text = "".join(self._cell)
        if tag == "caption":
            self.caption = text
        elif tag == "th":
            self._name = text
        elif tag == "td":
            assert self._name not in self.rows, self._name
            self.rows[self._name] = text

    def handle_data(self, data: str) -> None:
        self._cell.append(data)


def parsed(markup: str) -> Table:
    table = Table()
    table.feed(markup)
    table.close()
    assert table.open == [] and table.tags[0] == "table"
    assert set(table.tags) <= {"table", "caption", "tbody", "tr", "th", "td"}, table.tags
    return table


def number(text: str) -> float:
    """The number a cell starts with (its unit after)."""
    match = re.match(r"-?[0-9.]+(e[+-]?[0-9]+)?", text)
    assert match, text
    return float(match.group())


def keys(text: str) -> dict[str, str]:
    """``key = value unit, ...`` of a part's cell."""
    return dict(item.split(" = ", 1) for item in text.split(", "))


def close(shown: str, value: float) -> bool:
    """Shown to 6 significant digits."""
    return math.isclose(number(shown), value, rel_tol=5e-6, abs_tol=0.0)


def beam_system(base_dir: Path | None = None, file: str | None = None) -> vi.System:
    excitations: list[vi.Force | vi.Base] = [
        vi.Force(at=0.5, signal=vi.Harmonic(amplitude=1.0, frequency=20.0))
    ]
    if file is not None:
        excitations.append(vi.Base(signal=vi.Recorded(file=file)))
    return vi.System(
        structure=vi.Cantilever(
            length=0.5,
            section="tube",
            outer_diameter=0.02,
            inner_diameter=0.016,
            material="aluminium",
            modes=3,
            damping_ratio=0.01,
        ),
        dampers=[
            vi.Damper(mass=0.02, at=0.5, clearance=5e-5, law="hertz", stiffness=1e8),
            vi.Damper(mass=0.01, at=0.3, clearance=2e-5, law="rigid", restitution=0.5),
        ],
        stops=[vi.Stop(at=0.4, side="upper", gap=1e-4, law="rigid", restitution=0.7)],
        excitations=excitations,
        solver=vi.Solver(method="dopri5", t_end=0.3),
        base_dir=base_dir,
    )


def test_a_system_table_holds_its_parts_and_values() -> None:
    system = beam_system()
    table = parsed(system._repr_html_())
    assert table.caption == "vibroimpact.System"
    structure = keys(table.rows["structure (cantilever)"])
    assert structure["section"] == "'tube'" and structure["material"] == "'aluminium'"
    assert structure["outer_diameter"] == "0.02 m" and structure["length"] == "0.5 m"
    assert isinstance(system.structure, vi.Cantilever)
    resolved = system.structure.resolved()
    simulated = keys(table.rows["beam as simulated"])
    for key in ("youngs_modulus", "second_moment", "mass_per_length"):
        assert close(simulated[key], resolved[key]), key
    assert simulated["second_moment"].endswith(" m4")
    for j, damper in enumerate(system.dampers):
        shown = keys(table.rows[f"damper {j}"])
        assert shown["mass"] == f"{damper.mass:g} kg"
        assert close(shown["clearance"], damper.clearance or 0.0)
    stop = keys(table.rows["stop 0"])
    assert stop["side"] == "'upper'" and close(stop["gap"], 1e-4)
    force = keys(table.rows["excitation 0 (force)"])
    assert force["frequency"] == "20 Hz" and force["amplitude"] == "1 N"
    assert keys(table.rows["solver"])["t_end"] == "0.3 s"
    assert "stop 1" not in table.rows and "gravity" not in table.rows
    assert repr(system).startswith("System(structure=Cantilever(")  # the short repr stays


def test_a_hostile_file_name_is_escaped(tmp_path: Path) -> None:
    (tmp_path / HOSTILE).write_text("0.0,0.0\n1.0,1.0\n", encoding="utf-8")
    system = beam_system(tmp_path, HOSTILE)
    markup = system._repr_html_()
    assert "<img" not in markup and "&lt;img" in markup
    table = parsed(markup)
    assert keys(table.rows["excitation 1 (base)"])["file"] == repr(HOSTILE)


def test_a_system_solution_table_holds_the_run() -> None:
    sol = vi.simulate(beam_system())
    table = parsed(sol._repr_html_())
    assert table.caption == "vibroimpact.SystemSolution"
    rows = table.rows
    assert rows["system"] == "cantilever: 3 coordinate(s), 2 damper(s)"
    assert rows["method"] == sol.method == "dopri5"
    assert rows["final time"].endswith(" s") and close(rows["final time"], sol.final_time)
    assert int(rows["steps"]) == sol.steps and int(rows["rejected steps"]) == sol.rejected_steps
    assert int(rows["right-hand side evaluations"]) == sol.rhs_evaluations
    assert int(rows["grazing contacts"]) == sol.grazing_contacts
    assert int(rows["rows kept"]) == len(sol.t)
    kinds = {kind: list(sol.contacts.kind).count(kind) for kind in set(sol.contacts.kind)}
    assert len(kinds) >= 2  # compliant and impacts at least: each count is checked
    assert int(rows["contacts"].split()[0]) == len(sol.contacts)
    for kind, count in kinds.items():
        assert f"{count} {kind}" in rows["contacts"]
    assert rows["pairs"] == ", ".join(sorted(set(sol.contacts.pair)))
    for key, value in sol.energy.items():
        shown = rows[f"energy {key.replace('_', ' ')}"]
        assert shown.endswith(" J") and (close(shown, value) or value == number(shown) == 0)
    assert repr(sol).startswith("SystemSolution(cantilever of 3 coordinate(s)")


def two_mass_run() -> vi.Solution:
    system = vi.ImpactDamper(
        main_mass=1.0, stiffness=1.0, damping=0.01, impact_mass=0.25, clearance=0.01
    )
    contact = vi.Contact("hertz", stiffness=3000.0, damping=0.5)
    start = vi.InitialState(impact_displacement=0.01, impact_velocity=0.3)
    return vi.simulate(system, contact, start, method="rk4", dt=1e-3, t_end=2.0)


def test_a_two_mass_solution_table_holds_the_run() -> None:
    sol = two_mass_run()
    table = parsed(sol._repr_html_())
    rows = table.rows
    assert table.caption == "vibroimpact.Solution"
    assert rows["method"] == sol.method and rows["stepping"] == sol.stepping
    assert close(rows["final time"], sol.final_time)
    assert int(rows["steps"]) == sol.steps
    assert int(rows["right-hand side evaluations"]) == sol.rhs_evaluations
    assert int(rows["contacts"]) == len(sol.contacts) >= 2
    dissipated = float(np.sum(sol.contacts.energy_dissipated))
    assert dissipated > 0 and close(rows["energy dissipated by contacts"], dissipated)
    residual = rows["energy residual"]
    assert close(residual, sol.energy_residual) or number(residual) == sol.energy_residual
    assert number(rows["energy growth"]) == pytest.approx(sol.energy_growth, rel=5e-6, abs=0)
    assert repr(sol).startswith("Solution(two-body run")


def test_every_result_kind_has_its_pandas_and_xarray_views() -> None:
    two_mass = two_mass_run()
    general = vi.simulate(beam_system())
    for sol in (two_mass, general):
        frame = sol.contacts.to_pandas()
        assert list(frame.columns) == list(sol.contacts.columns)
        assert len(frame) == len(sol.contacts)
        assert np.array_equal(frame["onset"].to_numpy(), sol.contacts.onset)
        assert np.array_equal(frame["energy_dissipated"].to_numpy(), sol.contacts.energy_dissipated)
        dataset = sol.to_xarray()
        assert np.array_equal(dataset["time"].to_numpy(), sol.t)
        assert dataset.attrs["steps"] == sol.steps
    history = two_mass.to_xarray()
    assert np.array_equal(history["main_displacement"].to_numpy(), two_mass.main_displacement)
    assert history["contact_force"].attrs["units"] == "N"
    assert np.array_equal(
        general.to_xarray()["structure_displacement"].to_numpy(), general.structure_displacement
    )
