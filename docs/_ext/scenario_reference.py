"""``.. scenario-format::``: every section and key of the scenario files, from the code.

Two tables per format: the two-mass damper's (``[system]``, ``[contact]``, ...; the schema of
``vibroimpact.scenario.two_mass``) and the systems' (``[structure]``, ``[[damper]]``, ...;
``vibroimpact.system.schema``). Types and defaults are the schemas', the solver's ranges the
core registry's (``vibroimpact.METHOD_OPTIONS``), the choices of ``method`` the registry's
names (for the two-mass damper, those its loader accepts), units those of
``vibroimpact.units`` where it knows them; ``scenario_keys`` adds meanings. A third table
holds the analyses' sections (``vibroimpact.analysis.settings``,
``vibroimpact.study.settings``). A key without a description, a description of no key or
a unit that differs from the code's is a warning (an error under ``-W``).
"""

from __future__ import annotations

from typing import Any

from docutils import nodes
from generated import parsed
from scenario_keys import ANALYSES, SYSTEM, TWO_MASS
from sphinx.application import Sphinx
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective

import vibroimpact as vi
from vibroimpact._core import check_solver
from vibroimpact.analysis import settings as analysis_settings
from vibroimpact.scenario import two_mass
from vibroimpact.study import settings as study_settings
from vibroimpact.system import schema
from vibroimpact.units import parameter_units

LOG = logging.getLogger(__name__)


def _default(value: Any, required: object) -> str:
    if value is required:
        return "required"
    if value is None or value == ():
        return "—"
    if isinstance(value, bool):
        return "true" if value else "false"
    return f"``{value!r}``".replace("'", '"')


def _system_sections() -> dict[str, tuple[str, dict[str, tuple[str, Any]]]]:
    """Section -> (how it is written, key -> (type, default)) of the systems' schema."""
    structure: dict[str, tuple[str, Any]] = {"kind": ("string", schema._REQ)}
    for keys in schema._STRUCTURE.values():
        for key, (kind_type, default) in keys.items():
            shown = default if key not in structure else structure[key][1]
            structure[key] = (kind_type, shown)
    return {
        "structure": ("[structure]", structure),
        "damper": ("[[damper]]", schema._DAMPER),
        "stop": ("[[stop]]", schema._STOP),
        "collision": ("[[collision]]", schema._COLLISION),
        "friction": ("[[friction]]", schema._FRICTION),
        "gravity": ("[gravity]", schema._GRAVITY),
        "excitation": ("[[excitation]]", schema._EXCITATION),
        "initial": ("[initial]", schema._INITIAL),
        "solver": ("[solver]", schema._SOLVER),
        "output": ("[output]", schema._OUTPUT),
    }


def _analysis_sections() -> dict[str, tuple[str, dict[str, tuple[str, Any]]]]:
    """Section -> (how it is written, key -> (type, default)) of the analyses' sections:
    the schemas their checks read (``vibroimpact.analysis.settings``,
    ``vibroimpact.study.settings``), with the keys those checks read beside them."""
    study = {
        **study_settings._STUDY,
        # Read beside the schema by study_settings: the default follows the analysis.
        "metrics": ("array of strings", None),
        "axes": ("table", schema._REQ),
        "random": ("table", None),
    }
    return {
        "sweep": ("[sweep]", analysis_settings._SWEEP),
        "continuation": ("[continuation]", analysis_settings._CONTINUATION),
        "curve": ("[curve]", analysis_settings._CURVE),
        "basins": ("[basins]", analysis_settings._BASINS),
        "basins.x": ("[basins] x and y", analysis_settings._AXIS),
        "study": ("[study]", study),
        # Keyed by the parameters' paths: one row for the form of every entry.
        "study.axes": ("[study.axes]", {"<parameter>": ("array or table", schema._REQ)}),
        "study.random": ("[study.random]", {"<parameter>": ("table", None)}),
    }


def _two_mass_sections() -> dict[str, tuple[str, dict[str, tuple[str, Any]]]]:
    sections = {name: (f"[{name}]", dict(keys)) for name, keys in two_mass._SCHEMA.items()}
    # The run bounds the two-mass schema leaves to the core (None) take the same defaults
    # as a system's (the core registry's), which its schema writes out.
    solver = sections["solver"][1]
    for key in ("energy_tolerance", "max_rows"):
        if solver[key][1] is None:
            solver[key] = (solver[key][0], schema._SOLVER[key][1])
    return sections


def _two_mass_methods() -> list[str]:
    """The registry's methods the two-mass damper's check accepts (the core keeps that
    format's own list, which it does not export: "exact" is for systems only)."""
    accepted = []
    for name in vi.METHODS:
        try:
            check_solver(t_end=1.0, dt=1e-3, method=name)
        except vi.InvalidInputError as err:
            if not str(err).startswith("method "):
                raise  # refused for another reason: the probe itself is wrong
            continue
        accepted.append(name)
    return accepted


def _allowed(section: str, key: str, written: str | None, methods: list[str]) -> str:
    """The range or choices of a key: the core registry's where it has them."""
    if section == "solver" and key == "method":
        return ", ".join(f'"{name}"' for name in methods)
    if section == "solver" and key in vi.METHOD_OPTIONS:
        return str(vi.METHOD_OPTIONS[key]["allowed"])
    return written or ""


def _unit(section: str, key: str, written: str | None, where: str) -> str:
    """The code's unit of a key (``vibroimpact.units``), else the table's."""
    code = parameter_units(f"{section}.{key}")
    if code is not None and written is not None and code != written:
        LOG.warning("%s: the unit %r differs from the code's %r", where, written, code)
    return code or written or ""


def _table(
    title: str,
    sections: dict[str, tuple[str, dict[str, tuple[str, Any]]]],
    described: dict[str, dict[str, tuple[str | None, str | None, str]]],
    required: object,
    methods: list[str],
    location: Any,
) -> list[str]:
    lines: list[str] = []
    for section, (written, keys) in sections.items():
        texts = described.get(section, {})
        for extra in sorted(set(texts) - set(keys)):
            LOG.warning(
                "%s %s.%s: described but not in the schema",
                title,
                section,
                extra,
                location=location,
            )
        lines += [
            f"``{written}``",
            "~" * (len(written) + 4),
            "",
            ".. list-table::",
            "   :header-rows: 1",
            "   :widths: 16 10 12 12 22 28",
            "",
            "   * - key",
            "     - type",
            "     - default",
            "     - unit (SI)",
            "     - allowed",
            "     - meaning",
        ]
        for key, (kind, default) in keys.items():
            if key not in texts:
                LOG.warning(
                    "%s %s.%s: no description in scenario_keys",
                    title,
                    section,
                    key,
                    location=location,
                )
                unit, allowed, meaning = None, None, ""
            else:
                unit, allowed, meaning = texts[key]
            where = f"{title} {section}.{key}"
            lines += [
                f"   * - ``{key}``",
                f"     - {kind}",
                f"     - {_default(default, required)}",
                f"     - {_unit(section, key, unit, where) or '—'}",
                f"     - {_allowed(section, key, allowed, methods) or '—'}",
                f"     - {meaning}",
            ]
        lines.append("")
    return lines


class ScenarioFormat(SphinxDirective):
    required_arguments = 1  # "two-mass", "system" or "analyses"

    def run(self) -> list[nodes.Node]:
        kind = self.arguments[0]
        if kind == "two-mass":
            sections, meanings, required = _two_mass_sections(), TWO_MASS, two_mass._REQUIRED
            methods = _two_mass_methods()
        elif kind == "analyses":
            sections, meanings, required = _analysis_sections(), ANALYSES, schema._REQ
            methods = list(vi.METHODS)
        else:
            kind, sections, meanings, required = "system", _system_sections(), SYSTEM, schema._REQ
            methods = list(vi.METHODS)
        lines = _table(kind, sections, meanings, required, methods, self.get_location())
        return parsed(self, lines, "<scenario schema>")


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_directive("scenario-format", ScenarioFormat)
    return {"parallel_read_safe": True, "version": "1"}
