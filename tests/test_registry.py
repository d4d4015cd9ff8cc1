"""The core's one registry of methods, read by every front end: the defaults and ranges
Python uses are the core's, an unknown method is refused with the registry's names, and
the up-front run limits are the core's (issue 24, "One registry")."""

from __future__ import annotations

import dataclasses
import inspect
import re
import typing
from pathlib import Path
from typing import Any

import pytest

import vibroimpact as vi
from vibroimpact import _core
from vibroimpact.scenario.two_mass import Scenario
from vibroimpact.system import _FIXED_STEP, _METHODS, SYSTEM_SOLVER_DEFAULTS

OPTIONS = ("rtol", "atol", "beta", "gamma", "spectral_radius", "max_steps")
# The documented defaults (README, docstrings): average-acceleration Newmark, a
# generalised-alpha damping high frequencies to 0.9, dop853/dopri5 at 1e-8 / 1e-12 m.
DOCUMENTED = {
    "rtol": 1e-8,
    "atol": 1e-12,
    "beta": 0.25,
    "gamma": 0.5,
    "spectral_radius": 0.9,
    "max_steps": 1_000_000_000,
}
OSCILLATOR = {"kind": "oscillator", "mass": 1.0, "stiffness": 10.0, "damping": 0.0}


def core_default(name: str) -> Any:
    return _core.METHOD_OPTIONS[name]["default"]


def test_the_core_s_defaults_are_the_documented_ones() -> None:
    assert {name: core_default(name) for name in OPTIONS} == DOCUMENTED
    assert isinstance(core_default("max_steps"), int)


@pytest.mark.parametrize("method", list(_core.METHODS))
def test_every_method_s_defaults_in_python_are_the_core_s(method: str) -> None:
    spec = _core.METHODS[method]
    assert spec["kind"] in ("explicit", "implicit", "adaptive", "exact", "paper")
    assert spec["steppings"][0] == "events"
    for name, option in spec["options"].items():
        if name != "dt":
            assert option["default"] == core_default(name), (method, name)
    # Every path's defaults for the options this method reads: the schemas' are the
    # registry's values, the binding's and the typed two-mass call's None (the binding
    # fills them from the registry: see the runs below).
    two_mass = inspect.signature(_core.simulate).parameters
    check = inspect.signature(_core.check_solver).parameters
    fields = {f.name: f.default for f in dataclasses.fields(Scenario)}
    typed = [
        inspect.signature(o).parameters
        for o in typing.get_overloads(vi.simulate)
        if "beta" in inspect.signature(o).parameters
    ]
    for name in spec["options"]:
        if name == "dt":
            continue
        expected = core_default(name)
        assert SYSTEM_SOLVER_DEFAULTS[name] == expected, name
        assert fields[name] == expected, name
        assert two_mass[name].default is None, name
        assert check[name].default is None, name
        for parameters in typed:
            assert parameters[name].default is None, name


def test_a_scenario_s_defaults_are_its_file_s() -> None:
    # A Scenario built in code and one read from a file that leaves the same keys out
    # run the same: each field's default is the file schema's (dt had been 1e-4 in code
    # and the method's own in a file; t_end 0.3 in code and required in a file).
    from vibroimpact.scenario import two_mass

    fields = {f.name: f for f in dataclasses.fields(Scenario)}
    for section in ("solver", "output"):
        for name, (_, default) in two_mass._SCHEMA[section].items():
            field = fields[name]
            if default is two_mass._REQUIRED:
                assert field.default is dataclasses.MISSING, name
            else:
                assert field.default == default, name


def test_the_fixed_step_methods_are_the_registry_s() -> None:
    stepping_fixed = {m for m, s in _core.METHODS.items() if "fixed" in s["steppings"]}
    by_kind = {
        m for m, s in _core.METHODS.items() if s["kind"] in ("explicit", "implicit", "paper")
    }
    assert set(_FIXED_STEP) == stepping_fixed & set(_METHODS) == by_kind
    assert set(_METHODS) <= set(_core.METHODS)


def test_an_unknown_method_lists_the_registry_s_names() -> None:
    # Through Python's schema, and the core's own error (the binding's).
    with pytest.raises(vi.InvalidInputError) as err:
        vi.simulate_system(OSCILLATOR, method="newmark-lagged", t_end=1.0, dt=1e-3)
    for name in _METHODS:
        assert f'"{name}"' in str(err.value)
    with pytest.raises(vi.InvalidInputError) as err:
        _core._check_run(
            {"structure": OSCILLATOR},
            method="newmark-lagged",
            dt=1e-3,
            t_end=1.0,
            max_steps=10,
            max_rows=10,
            every=1,
            history=True,
            strobe_period=None,
        )
    message = str(err.value)
    assert message.startswith("method must be one of ") and "newmark-lagged" in message
    for name in _core.METHODS:
        assert f'"{name}"' in message


@pytest.mark.parametrize(
    ("name", "value"), [("rtol", 0.5), ("atol", 2.0), ("beta", 0.6), ("gamma", 0.4)]
)
def test_a_range_is_the_core_s_with_its_text(name: str, value: float) -> None:
    option = _core.METHOD_OPTIONS[name]
    assert not option["low"] <= value <= option["high"]
    settings: dict[str, Any] = {name: value}
    with pytest.raises(vi.InvalidInputError) as err:
        vi.simulate_system(OSCILLATOR, method="rk4", t_end=1.0, dt=1e-3, **settings)
    assert str(err.value) == f"[solver] {name}: must be {option['allowed']}, got {value}"


def test_the_run_limits_are_the_core_s() -> None:
    # 1e4 steps of rk4 against max_steps 9999: refused by the core before any step, the
    # same text through Python and from the binding.
    with pytest.raises(vi.InvalidInputError) as err:
        vi.simulate_system(OSCILLATOR, method="rk4", t_end=10.0, dt=1e-3, max_steps=9999)
    python = str(err.value)
    assert python == (
        "[solver] t_end / dt = 1.000e+04 steps exceeds max_steps (9999): raise dt or "
        "max_steps, or shorten t_end"
    )
    with pytest.raises(vi.InvalidInputError) as err:
        _core._check_run(
            {"structure": OSCILLATOR},
            method="rk4",
            dt=1e-3,
            t_end=10.0,
            max_steps=9999,
            max_rows=10**7,
            every=1,
            history=True,
            strobe_period=None,
        )
    assert str(err.value) == python


def _two_mass_run(**settings: Any) -> tuple[Any, ...]:
    # The founding paper's collision (Table 1, a 0.1 m/s approach), through it.
    sol = vi.simulate(
        vi.ImpactDamper(
            main_mass=1.0, stiffness=1.0, damping=0.01, impact_mass=0.25, clearance=0.01
        ),
        vi.Contact("hyster-hertz", stiffness=3000.0, damping=0.01, restitution=0.8),
        vi.InitialState(impact_displacement=0.01, impact_velocity=0.1),
        t_end=0.3,
        **settings,
    )
    return (
        sol.method,
        sol.stepping,
        sol.steps,
        sol.final_state.impact_velocity,
        tuple(sol.contacts.onset),
        tuple(sol.contacts.rebound_speed),
    )


@pytest.mark.parametrize("method", sorted(_core.METHODS.keys() - {"exact"}))
def test_options_left_out_take_the_registry_s_defaults(method: str) -> None:
    # The binding takes None for each option and fills the registry's default: the
    # run is the one with every default given, bit for bit, and differs from one with
    # a different value of an option the method reads (so the option is not ignored).
    dt = None if _core.METHODS[method]["kind"] == "adaptive" else 1e-4
    defaults = {name: core_default(name) for name in OPTIONS}
    left_out = _two_mass_run(method=method, dt=dt)
    assert left_out == _two_mass_run(method=method, dt=dt, **defaults)
    read = [name for name in _core.METHODS[method]["options"] if name in ("rtol", "beta")]
    for name in read:
        other = {**defaults, name: defaults[name] * (1e2 if name == "rtol" else 0.9)}
        assert _two_mass_run(method=method, dt=dt, **other) != left_out, name


def test_each_model_kind_s_default_method_and_stepping_are_the_registry_s() -> None:
    # The paper's lagged Newmark in fixed steps for the two-mass damper, RK4 by events
    # for any other system: declared once, in the core (RUN_DEFAULTS).
    two_mass, system = _core.RUN_DEFAULTS["two-mass"], _core.RUN_DEFAULTS["system"]
    assert (two_mass["method"], set(two_mass["fixed_by_default"])) == (
        "newmark",
        {"newmark", "rk4"},
    )
    assert (system["method"], system["fixed_by_default"]) == ("rk4", [])
    method, stepping, *_ = _two_mass_run(dt=1e-4)
    assert (method, stepping) == ("newmark", "fixed")
    assert _two_mass_run(dt=1e-4) == _two_mass_run(dt=1e-4, method="newmark", stepping="fixed")
    assert _two_mass_run(method="rk4", dt=1e-4)[1] == "fixed"
    assert _two_mass_run(method="newmark-implicit", dt=1e-4)[1] == "events"
    assert Scenario.__dataclass_fields__["method"].default == two_mass["method"]
    assert SYSTEM_SOLVER_DEFAULTS["method"] == system["method"]
    assert SYSTEM_SOLVER_DEFAULTS["stepping"] == "events"
    sol = vi.simulate_system(
        OSCILLATOR, t_end=0.01, dt=1e-3, initial={"structure_displacement": [0.01]}
    )
    assert sol.method == "rk4"
    raw = _core.simulate_system(
        {"structure": OSCILLATOR, "gravity": 0.0, "points": [], "moments": []},
        [[0.01], [0.0], [], []],
        t_end=0.01,
        dt=1e-3,
    )
    # The binding's own default (None filled from the registry) runs the same.
    assert raw["steps"] == sol.steps and list(raw["final_state"]) == [
        *sol.final_state["structure_displacement"],
        *sol.final_state["structure_velocity"],
    ]


_DEFAULTED = (*OPTIONS, "method", "stepping", "contact_timing", "energy_tolerance", "max_rows")
_ROOT = Path(__file__).resolve().parents[1]


def test_no_default_is_written_outside_the_core_registry() -> None:
    # A literal default of a method option, a method, a stepping or a limit in the
    # binding's signatures, its stub or the Python package: the registry's value
    # written a second time (issue 24: they had been written in 7 places).
    names = "|".join(_DEFAULTED)
    found = []
    for path in sorted((_ROOT / "crates/vibroimpact-py/src").rglob("*.rs")):
        text = path.read_text()
        for signature in re.findall(r"#\[pyo3\(signature = \((.*?)\)\)\]", text, re.S):
            for name, value in re.findall(rf"\b({names})\s*=\s*([^,\s)]+)", signature):
                if value != "None":
                    found.append(f"{path.name}: {name} = {value}")
    for path in sorted((_ROOT / "python/vibroimpact").rglob("*.py*")):
        if "paper" in path.parts:
            continue  # the paper's own settings for its tables' runs, not defaults
        for number, line in enumerate(path.read_text().splitlines(), 1):
            # An annotated parameter or field with a literal default ...
            annotated = re.search(rf"\b({names})\s*:[^=\n]*=\s*([\"'\d][^,)\n]*)", line)
            # ... or a dict entry of a literal (or a schema's (type, literal) entry).
            entry = re.search(
                rf"[\"']({names})[\"']\s*:\s*(?:\(\s*_\w+\s*,\s*)?([\"'\d][^,}})\n]*)", line
            )
            for match in (annotated, entry):
                if match:
                    found.append(f"{path.name}:{number}: {line.strip()}")
    assert not found, "\n".join(found)


@pytest.mark.parametrize(
    ("name", "value", "allowed"),
    [
        ("t_end", -1.0, "finite and > 0 s"),
        ("dt", 0.0, "finite and > 0 s, or left out"),
        ("energy_tolerance", 2.0, "in (0, 1]"),
        ("rtol", 0.5, "in [1e-15, 0.1]"),
    ],
)
def test_a_setting_s_range_is_checked_once_with_one_text(
    name: str, value: float, allowed: str
) -> None:
    # The core registry's check (check_settings), its text the same on every path: the
    # two-mass call, check_solver, a 0.2 system and the binding's own check.
    settings: dict[str, Any] = {"t_end": 1.0, "dt": 1e-3, name: value}
    messages = []
    calls = [
        lambda: vi.simulate(
            vi.ImpactDamper(
                main_mass=1.0, stiffness=1.0, impact_mass=0.01, clearance=0.25, damping=0.01
            ),
            vi.Contact("hertz", stiffness=3000.0),
            vi.InitialState(),
            method="rk4",
            **settings,
        ),
        lambda: vi.check_solver(method="rk4", **settings),
        lambda: vi.simulate_system(OSCILLATOR, method="rk4", **settings),
        lambda: _core._check_settings(**settings),
    ]
    for call in calls:
        with pytest.raises(vi.InvalidInputError) as err:
            call()
        messages.append(str(err.value))
    for message in messages:
        assert "\n" not in message and f"must be {allowed}, got " in message, message
        assert name in message.partition(" must be ")[0], message
    assert messages[2] == f"[solver] {name}: must be {allowed}, got {value}"


def test_a_strobe_period_is_checked_by_the_core_s_run_limits() -> None:
    with pytest.raises(vi.InvalidInputError) as err:
        vi.simulate_system(OSCILLATOR, method="rk4", t_end=1.0, dt=1e-3, strobe_period=-1.0)
    assert str(err.value) == "[output] strobe_period: must be finite and > 0 s, got -1.0"
