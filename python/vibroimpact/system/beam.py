"""A cantilever's bending stiffness and mass from what an engineer knows: its section
(dimensions in m) and its material (Young's modulus in Pa, density in kg/m^3), or the
second moment of area (m^4) and the mass per length (kg/m) themselves.

Each quantity is given one way:

- the second moment ``I``: ``second_moment``, or a ``section`` with its dimensions,
  ``"rectangle"`` (``width``, ``height``; bending about the axis parallel to the width,
  ``I = width height^3 / 12``), ``"circle"`` (``diameter``, ``I = pi d^4 / 64``) or
  ``"tube"`` (``outer_diameter``, ``inner_diameter``, ``I = pi (D^4 - d^4) / 64``);
- the mass per length: ``mass_per_length``, or ``density`` times the section's area;
- Young's modulus: ``youngs_modulus``.

A named ``material`` (:data:`MATERIALS`) gives Young's modulus and the density; an
explicit ``youngs_modulus`` or ``density`` overrides that one value (a steel of another
modulus), and an explicit ``mass_per_length`` leaves its density unused (a beam carrying
a non-structural mass). Giving both ways of one quantity (``section`` and
``second_moment``, ``density`` and ``mass_per_length``) is an error naming both keys.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from vibroimpact._core import InvalidInputError
from vibroimpact.messages import shown

_WHERE = "[structure] "


@dataclass(frozen=True)
class Material:
    """A named material's Young's modulus (Pa) and density (kg/m^3), and where they
    are from."""

    youngs_modulus: float
    density: float
    source: str


#: The named materials of ``material = "..."``: typical room-temperature values.
MATERIALS: dict[str, Material] = {
    # E = 29,000 ksi (AISC 360-16, Specification for Structural Steel Buildings);
    # 490 lb/ft^3 (AISC Steel Construction Manual) = 7849 kg/m^3, written 7850.
    "steel": Material(200e9, 7850.0, "structural steel, AISC 360-16 and AISC Manual"),
    # Aluminum Association typical values as ASM / MatWeb list them for 6061-T6:
    # E = 68.9 GPa (10,000 ksi), 2.70 g/cm^3.
    "aluminium": Material(68.9e9, 2700.0, "6061-T6 aluminium, Aluminum Association / ASM"),
    # ASM / MatWeb, "Titanium Ti-6Al-4V (Grade 5), Annealed Bar": E = 114 GPa,
    # 4.43 g/cm^3.
    "titanium": Material(114e9, 4430.0, "Ti-6Al-4V (grade 5) annealed, ASM / MatWeb"),
}

#: Each section's dimensions (m), in the order its formulas take them.
SECTIONS: dict[str, tuple[str, ...]] = {
    "rectangle": ("width", "height"),
    "circle": ("diameter",),
    "tube": ("outer_diameter", "inner_diameter"),
}
#: Every dimension key of every section.
DIMENSIONS: tuple[str, ...] = tuple(key for keys in SECTIONS.values() for key in keys)
#: The keys of a cantilever's ``[structure]`` this module reads (all optional in the schema).
BEAM_KEYS: tuple[str, ...] = ("section", *DIMENSIONS, "material", "density")


def section_properties(section: str, dimensions: Mapping[str, float]) -> tuple[float, float]:
    """The area (m^2) and the second moment of area (m^4) of a checked ``section`` of
    ``dimensions`` (m): a rectangle bending about the axis parallel to its width."""
    if section == "rectangle":
        width, height = dimensions["width"], dimensions["height"]
        return width * height, width * height**3 / 12.0
    if section == "circle":
        diameter = dimensions["diameter"]
        return math.pi * diameter**2 / 4.0, math.pi * diameter**4 / 64.0
    outer, inner = dimensions["outer_diameter"], dimensions["inner_diameter"]
    return (
        math.pi * (outer**2 - inner**2) / 4.0,
        math.pi * (outer**4 - inner**4) / 64.0,
    )


def _quoted(names: Mapping[str, Any], between: str) -> str:
    """The names as TOML strings, ``between`` each (``"steel", "aluminium"``)."""
    return between.join(f'"{name}"' for name in names)


def _fail(message: str) -> InvalidInputError:
    return InvalidInputError(f"{_WHERE}{message}")


def _one_of(key: str, value: Any, choices: Mapping[str, Any]) -> str:
    listed = _quoted(choices, ", ")
    if not isinstance(value, str):
        raise _fail(f"{key} must be one of {listed} (a string), got {shown(value)}")
    if value not in choices:
        raise _fail(f'{key} must be one of {listed}, got "{value}"')
    return value


def _positive(key: str, value: float, unit: str) -> float:
    if not value > 0:
        raise _fail(f"{key}: must be > 0 {unit}, got {shown(value)}")
    return value


def _section(table: Mapping[str, Any]) -> tuple[float, float] | None:
    """The area and second moment of the section ``table`` gives (None: no section),
    its dimensions checked."""
    section = table.get("section")
    if section is None:
        stray = [key for key in DIMENSIONS if table.get(key) is not None]
        if stray:
            raise _fail(f"{stray[0]} needs a section (section = {_quoted(SECTIONS, ' | ')})")
        return None
    section = _one_of("section", section, SECTIONS)
    own = SECTIONS[section]
    for key in DIMENSIONS:
        if key not in own and table.get(key) is not None:
            raise _fail(
                f'{key} does not apply to section "{section}" (it takes {", ".join(own)}, m)'
            )
    dimensions: dict[str, float] = {}
    for key in own:
        if table.get(key) is None:
            raise _fail(f'missing key {key!r} (section "{section}" takes {", ".join(own)}, m)')
        dimensions[key] = _positive(key, table[key], "m")
    if section == "tube" and not dimensions["inner_diameter"] < dimensions["outer_diameter"]:
        raise _fail(
            f"inner_diameter: must be less than outer_diameter "
            f"({shown(dimensions['outer_diameter'])} m), got {shown(dimensions['inner_diameter'])}"
        )
    return section_properties(section, dimensions)


def _given_or(table: Mapping[str, Any], key: str, otherwise: Any, missing: str) -> Any:
    """``key``'s value as given, else ``otherwise`` (the material's or the section's),
    else the error ``missing``."""
    value = table.get(key)
    if value is None:
        value = otherwise
    if value is None:
        raise _fail(missing)
    return value


def resolve_cantilever(table: Mapping[str, Any]) -> dict[str, Any]:
    """A cantilever's checked ``[structure]`` (keys typed, defaults filled; absent keys
    None) with its section and material turned into ``youngs_modulus`` (Pa),
    ``second_moment`` (m^4) and ``mass_per_length`` (kg/m): the keys the core takes,
    and only those."""
    for given, other in (("section", "second_moment"), ("density", "mass_per_length")):
        if table.get(given) is not None and table.get(other) is not None:
            raise _fail(f"give {given} or {other}, not both")
    material = None
    if table.get("material") is not None:
        material = MATERIALS[_one_of("material", table["material"], MATERIALS)]
    properties = _section(table)
    youngs_modulus = _given_or(
        table,
        "youngs_modulus",
        None if material is None else material.youngs_modulus,
        f"missing key 'youngs_modulus' (Pa), or give a material ({_quoted(MATERIALS, ', ')})",
    )
    second_moment = _given_or(
        table,
        "second_moment",
        None if properties is None else properties[1],
        "missing key 'second_moment' (m^4), or give a section (section = "
        f"{_quoted(SECTIONS, ' | ')} with its dimensions, m)",
    )
    mass_per_length = table.get("mass_per_length")
    if mass_per_length is None:
        density = table.get("density")
        if density is None and material is not None:
            density = material.density
        if density is None:
            raise _fail(
                "missing key 'mass_per_length' (kg/m), or give density (kg/m^3) or a "
                "material, with a section"
            )
        _positive("density", density, "kg/m^3")
        if properties is None:
            named = "density" if table.get("density") is not None else "material"
            raise _fail(
                f"{named} needs a section (mass_per_length = density * the section's area); "
                "or give mass_per_length (kg/m)"
            )
        mass_per_length = density * properties[0]
    return {
        "kind": table["kind"],
        "length": table["length"],
        "youngs_modulus": youngs_modulus,
        "second_moment": second_moment,
        "mass_per_length": mass_per_length,
        "modes": table["modes"],
        "damping_ratio": table["damping_ratio"],
    }
