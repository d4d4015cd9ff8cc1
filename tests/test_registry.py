"""The core's one registry of methods, read by every front end: the defaults and ranges
Python uses are the core's, an unknown method is refused with the registry's names, and
the up-front run limits are the core's (issue 24, "One registry")."""

from __future__ import annotations

import dataclasses
import inspect
import typing
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
    # Every path's defaults for the options this method reads.
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
        assert two_mass[name].default == expected, name
        assert check[name].default == expected, name
        for parameters in typed:
            assert parameters[name].default == expected, name


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
