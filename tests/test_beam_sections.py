"""A cantilever from its section and material, against hand formulas and the closed-form
Euler-Bernoulli frequencies; the same beam given by its second moment and mass per length
runs the same bits; every way of giving it wrongly is refused by name."""

from __future__ import annotations

import doctest
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.linalg import eigh

import vibroimpact as vi
from vibroimpact.cli import main
from vibroimpact.model import parts

EPS = float(np.finfo(float).eps)
# b_1 L of a clamped-free beam (Blevins, Formulas for Natural Frequency and Mode Shape,
# table 8-1).
BETA_1_L = 1.875104068711961
# The cited values, restated from their sources (not read from the package): structural
# steel E = 29,000 ksi (AISC 360-16), 490 lb/ft^3 (AISC Manual); 6061-T6 aluminium and
# Ti-6Al-4V (grade 5, annealed bar) as ASM / MatWeb list them.
CITED = {
    "steel": (200e9, 7850.0),
    "aluminium": (68.9e9, 2700.0),
    "titanium": (114e9, 4430.0),
}
LENGTH = 0.5

# (section keys, area by hand, second moment by hand)
SECTIONS = [
    (
        {"section": "rectangle", "width": 0.025, "height": 0.005},
        0.025 * 0.005,
        0.025 * 0.005**3 / 12,
    ),
    ({"section": "circle", "diameter": 0.012}, math.pi * 0.006**2, math.pi * 0.006**4 / 4),
    (
        {"section": "tube", "outer_diameter": 0.02, "inner_diameter": 0.016},
        math.pi * (0.01**2 - 0.008**2),
        math.pi * (0.01**4 - 0.008**4) / 4,
    ),
]


def beam(**keys: Any) -> vi.Cantilever:
    return vi.Cantilever(length=LENGTH, modes=3, damping_ratio=0.01, **keys)


@pytest.mark.parametrize(("section", "area", "second"), SECTIONS, ids=lambda v: str(v)[:20])
@pytest.mark.parametrize("material", sorted(CITED))
def test_resolved_values_are_the_hand_formulas(
    section: dict[str, Any], area: float, second: float, material: str
) -> None:
    youngs, density = CITED[material]
    resolved = beam(**section, material=material).resolved()
    assert resolved["second_moment"] == pytest.approx(second, rel=4 * EPS, abs=0)
    assert resolved["mass_per_length"] == pytest.approx(density * area, rel=4 * EPS, abs=0)
    assert resolved["youngs_modulus"] == youngs
    assert (resolved["length"], resolved["modes"], resolved["damping_ratio"]) == (LENGTH, 3, 0.01)


def test_explicit_values_override_the_material_one_by_one() -> None:
    section = {"section": "circle", "diameter": 0.01}
    area = math.pi * 0.01**2 / 4
    stiffer = beam(**section, material="steel", youngs_modulus=190e9).resolved()
    assert stiffer["youngs_modulus"] == 190e9
    assert stiffer["mass_per_length"] == pytest.approx(7850.0 * area, rel=4 * EPS)
    lighter = beam(**section, material="steel", density=7000.0).resolved()
    assert lighter["youngs_modulus"] == 200e9
    assert lighter["mass_per_length"] == pytest.approx(7000.0 * area, rel=4 * EPS)
    # An explicit mass per length (a beam carrying a non-structural mass): the
    # material's density goes unused, its modulus is kept.
    loaded = beam(**section, material="aluminium", mass_per_length=0.5).resolved()
    assert (loaded["youngs_modulus"], loaded["mass_per_length"]) == (68.9e9, 0.5)
    # No material at all: density and modulus given.
    plain = beam(**section, youngs_modulus=1e11, density=8000.0).resolved()
    assert plain["mass_per_length"] == pytest.approx(8000.0 * area, rel=4 * EPS)


@pytest.mark.parametrize(("section", "area", "second"), SECTIONS, ids=lambda v: str(v)[:20])
def test_first_natural_frequency_is_the_closed_form(
    section: dict[str, Any], area: float, second: float
) -> None:
    youngs, density = CITED["titanium"]
    structure = beam(**section, material="titanium").to_dict()
    linear = vi.linear_parts(structure)
    omega = np.sqrt(eigh(linear["stiffness"], linear["mass"], eigvals_only=True))
    closed = BETA_1_L**2 / LENGTH**2 * math.sqrt(youngs * second / (density * area))
    assert omega[0] == pytest.approx(closed, rel=1e-12)
    # The same beam by its second moment and mass per length: the same matrices.
    resolved = beam(**section, material="titanium").resolved()
    direct = vi.linear_parts(
        {k: v for k, v in resolved.items() if k != "damping_ratio"} | {"damping_ratio": 0.01}
    )
    for key in ("mass", "stiffness", "damping"):
        assert np.array_equal(direct[key], linear[key]), key


def _run(structure: vi.Cantilever) -> vi.SystemSolution:
    system = vi.System(
        structure=structure,
        dampers=[
            vi.Damper(mass=0.02, at=LENGTH, clearance=2e-4, law="hertz", stiffness=1e8),
            vi.Damper(mass=0.01, at=0.3, clearance=1e-4, law="rigid", restitution=0.5),
        ],
        excitations=[vi.Force(at=LENGTH, signal=vi.Harmonic(amplitude=1.0, frequency=20.0))],
    )
    return vi.simulate(system, method="dopri5", t_end=0.3, moments=[0.0], record_from=0.1)


def test_a_beam_from_its_section_runs_the_same_bits_as_by_its_second_moment() -> None:
    tube = beam(section="tube", outer_diameter=0.02, inner_diameter=0.016, material="aluminium")
    resolved = tube.resolved()
    direct = beam(
        youngs_modulus=resolved["youngs_modulus"],
        second_moment=resolved["second_moment"],
        mass_per_length=resolved["mass_per_length"],
    )
    a, b = _run(tube), _run(direct)
    assert len(a.contacts) > 5  # the dampers work, so contacts are compared too
    for name in ("t", "structure_displacement", "damper_displacement", "moment_peak", "peak"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    for name in a.contacts.columns:
        assert np.array_equal(getattr(a.contacts, name), getattr(b.contacts, name)), name
    assert a.energy == b.energy
    assert a.structure == b.structure == resolved


def test_to_toml_writes_what_was_given_and_reads_it_back() -> None:
    tube = beam(section="tube", outer_diameter=0.02, inner_diameter=0.016, material="steel")
    system = vi.System(structure=tube)
    text = system.to_toml()
    assert 'section = "tube"' in text and 'material = "steel"' in text
    assert "second_moment" not in text and "mass_per_length" not in text
    assert "youngs_modulus" not in text
    again = vi.loads(text)
    assert again == system
    assert again.structure.resolved() == tube.resolved()


def test_the_docstring_example_holds() -> None:
    finder = doctest.DocTestFinder()
    runner = doctest.DocTestRunner()
    for test in finder.find(parts.Cantilever, "Cantilever", globs={"Cantilever": vi.Cantilever}):
        runner.run(test)
    assert runner.tries >= 2 and runner.failures == 0


# (the keys besides length and modes, the fragments of the one-line error)
BAD = [
    (
        {"section": "circle", "diameter": 0.01, "second_moment": 1e-9, "material": "steel"},
        ["give section or second_moment, not both"],
    ),
    (
        {"second_moment": 1e-9, "youngs_modulus": 2e11, "density": 7800.0, "mass_per_length": 1.0},
        ["give density or mass_per_length, not both"],
    ),
    ({"section": "rectangle", "width": 0.02, "material": "steel"}, ["missing key 'height'"]),
    ({"section": "tube", "outer_diameter": 0.02, "material": "steel"}, ["'inner_diameter'"]),
    ({"section": "circle", "material": "steel"}, ["missing key 'diameter'"]),
    (
        {"section": "rectangle", "width": 0.02, "height": 0.0, "material": "steel"},
        ["height", "> 0"],
    ),
    ({"section": "circle", "diameter": -0.01, "material": "steel"}, ["diameter: must be > 0"]),
    (
        {"section": "tube", "outer_diameter": 0.02, "inner_diameter": 0.02, "material": "steel"},
        ["inner_diameter: must be less than outer_diameter"],
    ),
    (
        {"section": "tube", "outer_diameter": 0.02, "inner_diameter": -1.0, "material": "steel"},
        ["inner_diameter: must be > 0"],
    ),
    ({"section": "square", "width": 0.02}, ['section must be one of "rectangle"', '"square"']),
    ({"section": 3, "width": 0.02}, ["section: must be a string"]),
    ({"section": "circle", "diameter": 0.01, "material": "iron"}, ['"titanium", got "iron"']),
    ({"section": "circle", "diameter": 0.01, "width": 0.02, "material": "steel"}, ["width does"]),
    ({"width": 0.02, "height": 0.01, "material": "steel"}, ["width needs a section"]),
    ({"section": "circle", "diameter": 0.01, "density": 7800.0}, ["'youngs_modulus'"]),
    ({"youngs_modulus": 2e11, "mass_per_length": 1.0}, ["'second_moment'", "section"]),
    ({"youngs_modulus": 2e11, "section": "circle", "diameter": 0.01}, ["'mass_per_length'"]),
    ({"second_moment": 1e-9, "material": "steel"}, ["material needs a section", "mass_per_length"]),
    ({"second_moment": 1e-9, "youngs_modulus": 2e11, "density": 1.0}, ["density needs a section"]),
    (
        {"section": "circle", "diameter": 0.01, "material": "steel", "density": -1.0},
        ["density: must be > 0"],
    ),
    (
        {"section": "circle", "diameter": "wide", "material": "steel"},
        ["diameter: must be a number"],
    ),
]


@pytest.mark.parametrize(("keys", "fragments"), BAD, ids=[str(i) for i in range(len(BAD))])
def test_each_bad_beam_is_refused_by_name(keys: dict[str, Any], fragments: list[str]) -> None:
    with pytest.raises(vi.InvalidInputError) as err:
        beam(**keys).resolved()
    message = str(err.value)
    assert isinstance(err.value, ValueError)
    assert "\n" not in message and message.startswith("[structure] ")
    for fragment in fragments:
        assert fragment in message, message
    # The System and a scenario file get the same error, word for word.
    with pytest.raises(vi.InvalidInputError) as in_system:
        vi.System(structure=beam(**keys))
    assert str(in_system.value) == message
    table = {"kind": "cantilever", "length": LENGTH, "modes": 3, **keys}
    with pytest.raises(vi.InvalidInputError) as in_sections:
        vi.System.from_dict({"structure": table})
    assert str(in_sections.value) == message


@pytest.mark.parametrize("index", [0, 7, 14])
def test_a_bad_beam_in_a_scenario_exits_2_with_one_line(
    index: int, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    keys, fragments = BAD[index]
    system = vi.System(
        structure=beam(youngs_modulus=2e11, second_moment=1e-9, mass_per_length=1.0),
        solver=vi.Solver(t_end=0.01, method="dopri5"),
    )
    good = system.to_toml()
    bad_keys = "\n".join(
        f"{key} = {value!r}".replace("'", '"') for key, value in keys.items()
    ).replace("1e-09", "1e-9")
    lines = [
        line
        for line in good.splitlines()
        if not line.startswith(("youngs_modulus", "second_moment", "mass_per_length"))
    ]
    at = lines.index('kind = "cantilever"') + 1
    path = tmp_path / "beam.toml"
    path.write_text("\n".join([*lines[:at], bad_keys, *lines[at:]]), encoding="utf-8")
    assert main(["simulate", str(path)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("vibroimpact: error:")
    assert all(fragment in err[0] for fragment in fragments), err[0]


@pytest.mark.parametrize("part", ["damper", "force"])
def test_a_damper_or_a_force_at_the_clamp_is_refused(part: str) -> None:
    # Every mode has a node at x = 0: a damper there had rattled in a box that never
    # moves and a force there had done no work, both without a word (0 contacts, 8
    # steps), where a stop or a friction element there is refused (a probe of the API).
    beam = vi.Cantilever(
        length=0.5, youngs_modulus=7e10, second_moment=1e-10, mass_per_length=0.27, modes=2
    )
    at = {"damper": 0.5, "force": 0.5, part: 0.0}
    system = {
        "structure": beam,
        "dampers": [
            vi.Damper(mass=0.01, at=at["damper"], clearance=1e-3, law="rigid", restitution=0.6)
        ],
        "excitations": [vi.Force(at=at["force"], signal=vi.Harmonic(amplitude=1.0, frequency=8.0))],
    }
    where = "damper 0" if part == "damper" else "excitation 0"
    with pytest.raises(ValueError, match=f"{where} at = 0 m is a point that does not move"):
        vi.System(**system)  # type: ignore[arg-type]
    # Anywhere the modes move, it runs.
    at[part] = 0.25
    system["dampers"] = [
        vi.Damper(mass=0.01, at=at["damper"], clearance=1e-3, law="rigid", restitution=0.6)
    ]
    system["excitations"] = [
        vi.Force(at=at["force"], signal=vi.Harmonic(amplitude=1.0, frequency=8.0))
    ]
    assert len(vi.simulate(vi.System(**system), method="exact", t_end=0.5).contacts) > 0  # type: ignore[arg-type]
