"""The scenario reference's ranges (docs/_ext/scenario_keys.py, typed by hand beside the
schemas' keys, types and defaults) against what the loader accepts: each simple numeric
range is probed in every example that sets its key, just outside (refused, naming the key)
and on a closed bound (accepted). So the reference's ranges cannot drift from the checks."""

from __future__ import annotations

import re
import sys
import tomllib
from collections.abc import Iterator
from pathlib import Path

import pytest

import vibroimpact as vi

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "docs" / "_ext"))
import scenario_keys  # noqa: E402

NUMBER = r"-?\d+(?:\.\d+)?(?:e-?\d+)?"
BOUND = re.compile(rf"^(>=|>|<=|<) ({NUMBER})$")
INTERVAL = re.compile(rf"^([\[(])({NUMBER}), ({NUMBER})([\])])$")


def probes(text: str) -> tuple[list[float], list[float]] | None:
    """Values just outside the range ``text`` (to be refused) and on its closed bounds (to
    be accepted); None for a range that is not a plain number bound or interval."""
    if m := BOUND.match(text):
        op, a = m.group(1), float(m.group(2))
        below, above = a - max(1.0, abs(a)) * 1e-3, a + max(1.0, abs(a)) * 1e-3
        return {
            ">": ([a, below], []),
            ">=": ([below], [a]),
            "<": ([a, above], []),
            "<=": ([above], [a]),
        }[op]
    if m := INTERVAL.match(text):
        a, b = float(m.group(2)), float(m.group(3))
        below, above = a - max(1.0, abs(a)) * 1e-3, b + max(1.0, abs(b)) * 1e-3
        refused, accepted = [below, above], []
        (accepted if m.group(1) == "[" else refused).append(a)
        (accepted if m.group(4) == "]" else refused).append(b)
        return refused, accepted
    return None


def ranged_keys() -> Iterator[tuple[str, str, str, str]]:
    """(format, section, key, range) of every key whose range is a plain bound."""
    for form, table in (
        ("system", scenario_keys.SYSTEM),
        ("two-mass", scenario_keys.TWO_MASS),
        # The analyses' sections are a system scenario's: probed in the examples holding them.
        ("system", scenario_keys.ANALYSES),
    ):
        for section, keys in table.items():
            for key, (_, span, _) in keys.items():
                if span is not None and probes(span) is not None:
                    yield form, section, key, span


# Keys no example sets, each in a small scenario of its own (a probe's base, valid as written).
_BASE = """
[structure]
kind = "oscillator"
mass = 1.0
stiffness = 3947.8
damping = 2.5

[[damper]]
mass = 0.05
at = 0
lower_clearance = 0.004
upper_clearance = 0.006
law = "hertz"
stiffness = 1e7
damping = 0.5

[[stop]]
at = 0
side = "upper"
gap = 0.02
law = "linear"
stiffness = 1e5
damping = 1.0

[[excitation]]
kind = "force"
at = 0
{signal}

[solver]
method = "rk4"
dt = 1e-4
t_end = 0.5
energy_tolerance = 0.01
max_rows = 100000

[output]
history = false
"""
_SIGNALS = [
    'signal = "sweep"\namplitude = 1.0\nstart_frequency = 5.0\nend_frequency = 20.0\n'
    "duration = 0.4",
    'signal = "white-noise"\nintensity = 0.01\ncutoff_frequency = 50.0\nduration = 0.4\nseed = 1',
    'signal = "kanai-tajimi"\nintensity = 0.01\nground_frequency = 2.5\n'
    "ground_damping = 0.6\ncutoff_frequency = 50.0\nseed = 2",
]
_BEAMS = [
    'section = "circle"\ndiameter = 0.01\ndensity = 7850.0\nyoungs_modulus = 2e11',
    'section = "tube"\nouter_diameter = 0.02\ninner_diameter = 0.015\nmaterial = "steel"',
]
_BEAM = """
[structure]
kind = "cantilever"
length = 0.5
{beam}
modes = 2

[solver]
method = "dopri5"
t_end = 0.01

[output]
strobe_period = 0.001
"""
# The analyses' keys the examples leave to their defaults; the basins' axes as tables of
# their own, so that they are probed as a section.
_ANALYSES = """
[sweep]
parameter = "excitation.0.frequency"
start = 8.0
stop = 12.0
count = 5
tolerance = 1e-6

[continuation]
parameter = "excitation.0.frequency"
stop = 12.0
max_points = 50
tolerance = 1e-9

[basins]
settle_periods = 20
record_periods = 5
tolerance = 1e-6

[basins.x]
state = "structure_displacement.0"
start = -0.01
stop = 0.01
count = 3

[basins.y]
state = "structure_velocity.0"
start = -0.1
stop = 0.1
count = 3

[study]
analysis = "orbit"
orbit_periods = 1
record_from = 0.1
tolerance = 1e-6
samples = 2
seed = 3

[study.axes]
"damper.0.clearance" = [0.004, 0.005]

[study.random]
"damper.0.mass" = { uniform = [0.04, 0.06] }
"""
SYNTHETIC = [_BASE.format(signal=signal) for signal in _SIGNALS]
SYNTHETIC += [_BEAM.format(beam=beam) for beam in _BEAMS]
SYNTHETIC += [
    _BASE.format(signal='signal = "harmonic"\namplitude = 1.0\nfrequency = 10.0') + _ANALYSES
]


def examples_setting(section: str, key: str) -> Iterator[tuple[Path, str]]:
    """Each example (and scenario of :data:`SYNTHETIC`) whose ``section`` (its first
    element where it is an array of tables) sets ``key`` to a plain number, with its text."""
    scenarios = [(p, p.read_text(encoding="utf-8")) for p in sorted(ROOT.glob("examples/*.toml"))]
    scenarios += [(ROOT / "examples" / f"synthetic_{i}.toml", t) for i, t in enumerate(SYNTHETIC)]
    for path, text in scenarios:
        part: object = tomllib.loads(text)
        for name in section.split("."):  # "basins.x": [basins.x]
            part = part.get(name) if isinstance(part, dict) else None
            if isinstance(part, list):
                part = part[0] if part else None
        # An inline table ([basins] x = {...}) has no header for with_value to find.
        header = rf"^\[\[?{re.escape(section)}\]\]?"
        if not isinstance(part, dict) or not re.search(header, text, flags=re.M):
            continue
        value = part.get(key)
        if isinstance(value, int | float) and not isinstance(value, bool):
            yield path, text


def with_value(text: str, section: str, key: str, value: float) -> str:
    """``text`` with ``key`` of the first ``[section]`` or ``[[section]]`` set to ``value``."""
    header = re.search(rf"^\[\[?{re.escape(section)}\]\]?\s*(#.*)?$", text, flags=re.M)
    assert header is not None, section
    end = re.search(r"^\[", text[header.end() :], flags=re.M)
    stop = header.end() + (end.start() if end else len(text) - header.end())
    body = text[header.end() : stop]
    line = re.compile(rf"^(\s*{re.escape(key)}\s*=\s*)([^#\n]+?)(\s*(#.*)?)$", flags=re.M)
    number = repr(int(value)) if float(value).is_integer() and abs(value) < 1e15 else repr(value)
    new, count = line.subn(lambda m: m.group(1) + number + m.group(3), body, count=1)
    assert count == 1, (section, key)
    return text[: header.end()] + new + text[stop:]


CASES = [
    pytest.param(path, text, section, key, span, id=f"{path.stem}-{section}.{key}")
    for form, section, key, span in ranged_keys()
    for path, text in examples_setting(section, key)
    if ("structure" in tomllib.loads(text)) == (form == "system")
]


@pytest.mark.parametrize("text", SYNTHETIC)
def test_the_synthetic_bases_are_valid_as_written(text: str) -> None:
    # Which bug: a base refused for another reason would make every probe of it pass.
    vi.loads(text)


def test_most_ranged_keys_are_probed_by_some_example() -> None:
    # Which bug: a table of ranges the test no longer reaches (an example renamed, a key
    # moved) would leave the reference unchecked while this file still passed.
    probed = {(case.values[2], case.values[3]) for case in CASES}
    ranged = {(section, key) for _, section, key, _ in ranged_keys()}
    assert len(probed) >= 0.9 * len(ranged), sorted(ranged - probed)  # type: ignore[operator]


@pytest.mark.parametrize(("path", "text", "section", "key", "span"), CASES)
def test_the_reference_range_is_what_the_loader_checks(
    path: Path, text: str, section: str, key: str, span: str, tmp_path: Path
) -> None:
    found = probes(span)
    assert found is not None
    refused, accepted = found
    base = path.parent
    for value in refused:
        with pytest.raises(ValueError, match=re.escape(key)):
            vi.loads(with_value(text, section, key, value), str(path), base)
    for value in accepted:
        # Without the example's [initial]: a start checked against the key's bound (a
        # stop's gap of 0 under a structure started above it) is refused on its own.
        vi.loads(without_initial(with_value(text, section, key, value)), str(path), base)


def without_initial(text: str) -> str:
    """The scenario ``text`` without its ``[initial]`` table."""
    kept, skipping = [], False
    for line in text.splitlines(keepends=True):
        if line.lstrip().startswith("["):
            skipping = line.split("#")[0].strip() == "[initial]"
        if not skipping:
            kept.append(line)
    return "".join(kept)
