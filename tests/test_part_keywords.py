"""The typed parts' constructors refuse a bad keyword as a scenario file's table does:
an unknown key with the closest allowed one suggested, a missing required key by name,
positional values by the keywords they should be; each an InvalidInputError (a
ValueError), never the dataclass's bare TypeError.

Independent references: each part's own dataclass fields (the keys it takes) and the
error the same typo gets in a TOML scenario."""

from __future__ import annotations

import dataclasses
import math
import re

import pytest

import vibroimpact as vi
from vibroimpact.model.parts import Part


def concrete_parts() -> list[type[Part]]:
    """Every part a user builds: the Part subclasses that are dataclasses, found by
    walking the hierarchy (a new part cannot be left out of this test)."""
    found, todo = [], list(Part.__subclasses__())
    while todo:
        cls = todo.pop()
        todo.extend(cls.__subclasses__())
        if dataclasses.is_dataclass(cls):
            found.append(cls)
    return sorted(found, key=lambda c: c.__name__)


PARTS = concrete_parts()


def required(cls: type[Part]) -> dict[str, object]:
    """Values for the required keys (a part only holds values: any will do)."""
    return {
        f.name: 1.0
        for f in dataclasses.fields(cls)  # type: ignore[arg-type]
        if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
    }


def swapped(name: str) -> str:
    """A typo: two middle letters swapped (or a letter doubled for a short name)."""
    if len(name) < 4:
        return name + name[-1]
    i = len(name) // 2
    return name[: i - 1] + name[i] + name[i - 1] + name[i + 1 :]


def test_every_part_is_found() -> None:
    # The walk finds the parts the package exports (a broken walk would test nothing).
    assert len(PARTS) == 19
    assert {c.__name__ for c in PARTS} <= set(vi.__all__) | {"Matrices"}


@pytest.mark.parametrize("cls", PARTS, ids=lambda c: c.__name__)
def test_an_unknown_keyword_is_refused_with_a_suggestion(cls: type[Part]) -> None:
    for field in dataclasses.fields(cls):  # type: ignore[arg-type]
        typo = swapped(field.name)
        if typo == field.name:
            continue
        with pytest.raises(vi.InvalidInputError) as caught:
            cls(**(required(cls) | {typo: 0.5}))
        message = str(caught.value)
        assert isinstance(caught.value, ValueError)
        assert message.startswith(f"{cls.__name__}: unknown key {typo!r}"), message
        assert message.endswith(f"did you mean {field.name!r}?"), message
        assert "\n" not in message


@pytest.mark.parametrize("cls", PARTS, ids=lambda c: c.__name__)
def test_a_missing_required_keyword_is_named(cls: type[Part]) -> None:
    needed = required(cls)
    cls(**needed)  # all given: built
    for name in needed:
        with pytest.raises(vi.InvalidInputError, match=rf"^{cls.__name__}: missing key '{name}'"):
            cls(**{k: v for k, v in needed.items() if k != name})


@pytest.mark.parametrize("cls", [vi.Harmonic, vi.Damper, vi.Oscillator], ids=lambda c: c.__name__)
def test_positional_values_are_refused_by_name(cls: type[Part]) -> None:
    with pytest.raises(
        vi.InvalidInputError, match=r"takes keywords only \(.*=\.\.\..*2 positional"
    ):
        cls(1.0, 2.0)


def test_the_typo_gets_the_files_suggestion(tmp_path) -> None:  # type: ignore[no-untyped-def]
    scenario = """
[structure]
kind = "oscillator"
mass = 1.0
stiffness = 100.0
[[damper]]
mass = 0.1
at = 0
clearence = 0.01
law = "rigid"
restitution = 0.5
"""
    with pytest.raises(vi.InvalidInputError) as from_file:
        vi.load(scenario)
    with pytest.raises(vi.InvalidInputError) as from_python:
        vi.Damper(mass=0.1, at=0, clearence=0.01, law="rigid", restitution=0.5)
    # The same key, the same list and suggestion; only the place differs.
    tail = re.compile(r"unknown key .*$")
    file_tail = tail.search(str(from_file.value))
    python_tail = tail.search(str(from_python.value))
    assert file_tail is not None and python_tail is not None
    assert file_tail.group() == python_tail.group()
    # Read from a table the part cannot take, the file's error (naming the table) wins.
    assert "[[damper]] 0: unknown key 'clearence'" in str(from_file.value)


def test_parts_still_copy_pickle_and_replace() -> None:
    import copy
    import pickle

    harmonic = vi.Harmonic(amplitude=2.0, frequency=5.0)
    assert copy.deepcopy(harmonic) == harmonic
    assert pickle.loads(pickle.dumps(harmonic)) == harmonic
    assert dataclasses.replace(harmonic, frequency=6.0).frequency == 6.0
    with pytest.raises(vi.InvalidInputError, match="did you mean 'frequency'"):
        dataclasses.replace(harmonic, frequncy=6.0)


def test_numpy_numbers_are_held_as_the_python_numbers_they_are() -> None:
    # A value taken from a study's Dataset (`ds["damper.0.mass"][1].values`, a 0-d
    # array) ran, but the System could not be hashed, written as TOML (a bare TypeError)
    # or given to an analysis ("frequencies must be numbers, got [array(10.)]").
    import json

    import numpy as np

    def system(mass: object, frequency: object, at: object) -> vi.System:
        return vi.System(
            structure=vi.Oscillator(mass=1.0, stiffness=3947.8, damping=2.513),
            dampers=[vi.Damper(mass=mass, at=at, clearance=0.005, law="rigid", restitution=0.6)],
            excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=5.0, frequency=frequency))],
            solver=vi.Solver(method="exact", t_end=1.0),
        )

    given = system(np.array(0.05), np.float64(10.0), np.int64(0))
    plain = system(0.05, 10.0, 0)
    assert given == plain and hash(given) == hash(plain)
    assert type(given.dampers[0].mass) is float and type(given.dampers[0].at) is int
    assert vi.loads(given.to_toml()) == plain
    assert json.loads(json.dumps(given.to_dict())) == plain.to_dict()
    amplitude = vi.steady_state(given).amplitude
    assert np.array_equal(amplitude, vi.steady_state(plain).amplitude)
    # Elements of an array too; an array where a number belongs is still refused by name.
    recorded = vi.Recorded(time=[np.float32(0.0), np.float64(1.0)], value=[0.0, 1.0])
    assert recorded.time == (0.0, 1.0) and type(recorded.time[0]) is float
    with pytest.raises(vi.InvalidInputError, match=r"mass: must be a number, got array"):
        system(np.array([0.05, 0.06]), 10.0, 0)


@pytest.mark.parametrize(
    ("name", "typo", "meant"),
    [
        ("orbit", "period", "periods"),
        ("sweep", "valuez", "values"),
        ("steady_state", "settle_period", "settle_periods"),
        ("lyapunov", "period", "periods"),
        ("poincare", "settle_period", "settle_periods"),
        ("bifurcation", "valuez", "values"),
        ("basins", "x_start", None),
        ("continue_orbit", "stpo", "stop"),
        ("runner", "base_dr", "base_dir"),
        ("study_of", "sorce", "source"),
        ("natural_modes", "attach", "attach_dampers"),
        ("load", "sourc", "source"),
        ("loads", "sourse", "source"),
    ],
)
def test_a_misspelt_keyword_of_a_public_function_is_a_value_error_with_the_closest(
    name: str, typo: str, meant: str | None
) -> None:
    # These raised Python's bare TypeError, with no suggestion (the parts and simulate()
    # already said "did you mean").
    function = getattr(vi, name)
    with pytest.raises(vi.KeywordError) as err:
        function(vi.System(structure=vi.Oscillator(mass=1.0, stiffness=1.0)), **{typo: 1})
    said = str(err.value)
    assert said.startswith(f"{name}() got an unexpected keyword argument {typo!r}")
    assert isinstance(err.value, ValueError)
    if meant is not None:
        assert said.endswith(f"(did you mean {meant!r}?)")


def test_a_record_given_as_a_pandas_column_is_its_values() -> None:
    # `Recorded(time=df.time, value=df.force)` was refused: "time: must be an array of
    # numbers, got 0 0.000 ... dtype: float64".
    import numpy as np
    import pandas as pd

    def forced_by(record: vi.Recorded) -> vi.System:
        return vi.System(
            structure=vi.Oscillator(mass=1.0, stiffness=100.0),
            excitations=[vi.Force(at=0, signal=record)],
        )

    frame = pd.DataFrame({"time": [0.0, 0.1, 0.5], "force": [0.0, 5.0, 0.0]})
    given = vi.Recorded(time=frame.time, value=frame.force)
    assert given == vi.Recorded(time=[0.0, 0.1, 0.5], value=[0.0, 5.0, 0.0])
    listed = vi.Recorded(time=np.array([0.0, 0.1, 0.5]), value=[0.0, 5.0, 0.0])
    first = vi.simulate(forced_by(given), method="dopri5", t_end=1.0).final_state
    second = vi.simulate(forced_by(listed), method="dopri5", t_end=1.0).final_state
    assert np.array_equal(first["structure_displacement"], second["structure_displacement"])
    # A non-finite sample in a list is still named by its index (the check made at once).
    with pytest.raises(vi.InvalidInputError, match=r"time\[2\]: must be a finite number, got nan"):
        forced_by(vi.Recorded(time=[0.0, 1.0, math.nan], value=[0.0] * 3))
