"""NaN and infinities are refused at every public boundary, naming the argument.

The float arguments are read from the type stub (``_core.pyi``, itself checked
against the extension by stubtest), so a new public function or argument without a
valid call below fails ``test_every_float_argument_has_a_case``.
"""

from __future__ import annotations

import ast
import math
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import vibroimpact as vi
from vibroimpact import _core

BAD = [math.nan, math.inf, -math.inf]


def _float_arguments() -> dict[str, list[str]]:
    """Callable name (``function``, ``Class`` for its constructor, ``Class.method``) ->
    its arguments annotated ``float`` or ``float | None`` in the stub."""
    stub = ast.parse(Path(_core.__file__).with_name("_core.pyi").read_text())
    found: dict[str, list[str]] = {}

    def visit(function: ast.FunctionDef, owner: str | None) -> None:
        arguments = function.args.posonlyargs + function.args.args + function.args.kwonlyargs
        floats = [
            a.arg
            for a in arguments
            if a.annotation is not None and ast.unparse(a.annotation) in ("float", "float | None")
        ]
        if floats:
            name = function.name if owner is None else owner
            if owner is not None and function.name != "__new__":
                name = f"{owner}.{function.name}"
            found[name] = floats

    for node in stub.body:
        if isinstance(node, ast.FunctionDef):
            visit(node, None)
        elif isinstance(node, ast.ClassDef):
            for item in node.body:
                if isinstance(item, ast.FunctionDef):
                    visit(item, node.name)
    return found


FLOAT_ARGUMENTS = _float_arguments()

SYSTEM = {
    "main_mass": 1.0,
    "stiffness": 1.0,
    "impact_mass": 0.25,
    "clearance": 0.01,
    "damping": 0.01,
}
SOLVER = {
    "t_end": 1e-3,
    "dt": 1e-4,
    "method": "newmark",
    "beta": 0.25,
    "gamma": 0.5,
    "spectral_radius": 0.9,
    "rtol": 1e-8,
    "atol": 1e-12,
    "energy_tolerance": 0.05,
}


def _simulate_system(**kwargs: Any) -> Any:
    # The public function; the binding's own is called by it with checked values.
    return vi.simulate_system(
        {"kind": "oscillator", "mass": 1.0, "stiffness": 10.0},
        damper=[{"mass": 0.1, "at": 0, "clearance": 0.01, "law": "rigid", "restitution": 0.5}],
        method="rk4",
        **kwargs,
    )


PREPARED = {
    "t_end": 1e-2,
    "dt": 1e-3,
    "rtol": 1e-8,
    "atol": 1e-12,
    "beta": 0.25,
    "gamma": 0.5,
    "spectral_radius": 0.9,
    "energy_tolerance": 1e-2,
}
# The binding's own: the sections as vibroimpact.system checks and fills them.
SPEC = {
    "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 10.0, "damping": 0.0},
    "damper": [],
    "stop": [],
    "excitation": [],
    "gravity": 0.0,
}


def _prepared_system(**kwargs: Any) -> Any:
    return _core.PreparedSystem(SPEC, method="rk4", max_steps=10**6, max_rows=10**6, **kwargs)


def _run_study(**kwargs: Any) -> Any:
    return _core.run_study(
        SPEC,
        [[0.01], [], [], []],
        paths=["initial.structure_velocity.0"],
        values=np.array([0.0, 0.1]),
        method="rk4",
        max_steps=10**6,
        analysis="run",
        settle_periods=1,
        record_periods=1,
        threads=1,
        **kwargs,
    )


def _prepared_shoot(**kwargs: Any) -> Any:
    return _prepared_system(**PREPARED).shoot([0.01, 0.0], max_iterations=2, **kwargs)


def _tangent_map(**kwargs: Any) -> Any:
    return _core.tangent_map(_prepared_system(**PREPARED), [0.01, 0.0], **kwargs)


def _lyapunov_spectrum(**kwargs: Any) -> Any:
    return _core.lyapunov_spectrum(_prepared_system(**PREPARED), [0.01, 0.0], blocks=2, **kwargs)


def _prepared_run(**kwargs: Any) -> Any:
    return _prepared_system(**PREPARED).run([0.01, 0.0], **kwargs)


def _simulate(**kwargs: Any) -> Any:
    return vi.simulate(
        vi.ImpactDamper(**SYSTEM),
        vi.Contact("hertz", stiffness=3000.0),
        vi.InitialState(impact_displacement=0.01, impact_velocity=0.1),
        **kwargs,
    )


def _law_force(**kwargs: Any) -> Any:
    return vi.Contact("hyster-hertz", 3000.0, restitution=0.9).law_force(**kwargs)


# Callable name -> (the callable, keyword arguments of a valid call).
VALID: dict[str, tuple[Callable[..., Any], dict[str, Any]]] = {
    "ImpactDamper": (vi.ImpactDamper, SYSTEM),
    "Contact": (
        vi.Contact,
        {"law": "hyster-hertz", "stiffness": 3000.0, "damping": 0.01, "restitution": 0.9},
    ),
    "Contact.law_force": (_law_force, {"indentation": 1e-3, "rate": 0.05, "approach_rate": 0.1}),
    "InitialState": (
        vi.InitialState,
        {
            "main_displacement": 0.0,
            "main_velocity": 0.01,
            "impact_displacement": 0.01,
            "impact_velocity": 0.1,
        },
    ),
    "simulate": (_simulate, SOLVER),
    "simulate_system": (
        _simulate_system,
        {
            "t_end": 1e-2,
            "dt": 1e-3,
            "rtol": 1e-8,
            "atol": 1e-12,
            "beta": 0.25,
            "gamma": 0.5,
            "spectral_radius": 0.9,
            "energy_tolerance": 1e-2,
            "record_from": 0.0,
            "strobe_period": 5e-3,
        },
    ),
    "PreparedSystem": (_prepared_system, PREPARED),
    "PreparedSystem.run": (
        _prepared_run,
        {"t_end": 1e-2, "record_from": 0.0, "strobe_period": 5e-3},
    ),
    "run_study": (
        _run_study,
        {
            "t_end": 1e-2,
            "dt": 1e-3,
            "rtol": 1e-8,
            "atol": 1e-12,
            "beta": 0.25,
            "gamma": 0.5,
            "spectral_radius": 0.9,
            "energy_tolerance": 1e-2,
            "record_from": 0.0,
            "tolerance": 1e-6,
        },
    ),
    "PreparedSystem.shoot": (
        _prepared_shoot,
        {"t_end": 1e-2, "tolerance": 1e-10, "forcing_period": 1e-2},
    ),
    "tangent_map": (_tangent_map, {"t_end": 1e-2}),
    "lyapunov_spectrum": (_lyapunov_spectrum, {"block_time": 1e-2}),
    "check_solver": (_core.check_solver, SOLVER),
    "hertz_stiffness": (
        vi.hertz_stiffness,
        {
            "radius": 0.01,
            "youngs_modulus": 2.1e11,
            "poisson_ratio": 0.3,
            "other_youngs_modulus": 7e10,
            "other_poisson_ratio": 0.33,
            "other_radius": 0.02,
        },
    ),
    "cantilever_mode": (
        vi.cantilever_mode,
        {
            "length": 0.7,
            "youngs_modulus": 2.1e11,
            "second_moment": 3e-10,
            "density": 7800.0,
            "area": 1.2e-4,
            "mode": 2,
            "position": 0.5,
        },
    ),
    "cantilever_mode_shape": (vi.cantilever_mode_shape, {"length": 0.7, "mode": 3, "x": 0.2}),
    "goldsmith_contact_duration": (
        vi.goldsmith_contact_duration,
        {"impact_mass": 0.25, "main_mass": 1.0, "hertz_stiffness": 3000.0, "approach_speed": 0.1},
    ),
    "goldsmith_max_indentation": (
        vi.goldsmith_max_indentation,
        {"impact_mass": 0.25, "main_mass": 1.0, "hertz_stiffness": 3000.0, "approach_speed": 0.1},
    ),
    "linear_contact_duration": (
        vi.linear_contact_duration,
        {"impact_mass": 0.25, "main_mass": 1.0, "stiffness": 49.05, "damping": 0.01},
    ),
    "_strobe_period": (
        _core._strobe_period,
        {"strobe": np.ones((3, 2)), "forcing_period": 0.2, "tolerance": 1e-6, "max_period": 8},
    ),
    "_check_settings": (_core._check_settings, PREPARED),
    "_check_forcing_period": (
        lambda **kwargs: _core._check_forcing_period(
            SPEC, method="dop853", max_steps=10**6, **kwargs
        ),
        {"forcing_period": 0.1, "dt": 1e-3, "atol": 1e-12},
    ),
    "_check_run": (
        lambda **kwargs: _core._check_run(
            {"structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 10.0, "damping": 0.0}},
            method="rk4",
            max_steps=10**6,
            max_rows=10**6,
            every=1,
            history=True,
            **kwargs,
        ),
        {"dt": 1e-3, "t_end": 1e-2, "strobe_period": 5e-3, "beta": 0.25, "gamma": 0.5},
    ),
    "adequacy": (
        vi.adequacy,
        {
            "error": 0.01,
            "max_error": 0.1,
            "cpu_time": 0.5,
            "max_cpu_time": 2.0,
            "error_weight": 0.5,
        },
    ),
}


def test_every_float_argument_has_a_case() -> None:
    assert set(FLOAT_ARGUMENTS) == set(VALID)
    for name, arguments in FLOAT_ARGUMENTS.items():
        assert set(arguments) <= set(VALID[name][1]), name
    # Each valid call succeeds, so that a refusal below is the bad value's doing.
    for function, kwargs in VALID.values():
        function(**kwargs)


def names(message: str, argument: str) -> bool:
    """Whether the message names the argument as a whole word (``youngs_modulus`` is
    not named by ``other_youngs_modulus``)."""
    return re.search(rf"(?<![\w]){re.escape(argument)}(?![\w])", message) is not None


CASES = [
    pytest.param(
        name,
        argument,
        bad,
        id=f"{name}-{argument}-{bad}",
    )
    for name, arguments in FLOAT_ARGUMENTS.items()
    for argument in arguments
    for bad in BAD
]


@pytest.mark.parametrize(("name", "argument", "bad"), CASES)
def test_non_finite_argument_is_refused_by_name(name: str, argument: str, bad: float) -> None:
    function, kwargs = VALID[name]
    with pytest.raises(vi.InvalidInputError) as err:
        function(**{**kwargs, argument: bad})
    message = str(err.value)
    assert names(message, argument), message
    assert "\n" not in message


# ------------------------------------------------------------------------ scenarios

SCENARIO = """
[system]
main_mass = 1.0
stiffness = 1.0
damping = 0.01
impact_mass = 0.25
clearance = 0.01

[contact]
law = "hyster-hertz"
stiffness = 3000.0
restitution = 0.9
damping = 0.01

[initial]
main_displacement = 0.0
main_velocity = 0.0
impact_displacement = 0.01
impact_velocity = 0.1

[solver]
method = "newmark"
dt = 1e-4
t_end = 1e-3
beta = 0.25
gamma = 0.5
spectral_radius = 0.9
rtol = 1e-8
atol = 1e-12
max_steps = 1000
"""

SCENARIO_NUMBERS = [
    (section, line.split("=")[0].strip())
    for section, body in re.findall(r"\[(\w+)\]\n((?:[^\[]+))", SCENARIO)
    for line in body.strip().splitlines()
    if not line.split("=")[1].strip().startswith('"')
]


def test_the_scenario_template_is_valid() -> None:
    assert len(SCENARIO_NUMBERS) == 20
    vi.parse_scenario(SCENARIO).run()


@pytest.mark.parametrize("bad", ["nan", "inf", "-inf"])
@pytest.mark.parametrize(("section", "key"), SCENARIO_NUMBERS)
def test_non_finite_scenario_number_is_refused_by_name(section: str, key: str, bad: str) -> None:
    """TOML spells nan and inf literally; each is bad input naming its section and key."""
    block = SCENARIO.split(f"[{section}]")
    edited = re.sub(rf"(?m)^{key} = .*$", f"{key} = {bad}", block[1], count=1)
    text = f"[{section}]".join([block[0], edited])
    with pytest.raises(vi.InvalidInputError) as err:
        vi.parse_scenario(text)
    message = str(err.value)
    assert names(message, key) and f"[{section}]" in message, message


def test_the_two_mass_damper_takes_its_values_by_name_only() -> None:
    # Its positional order (main_mass, stiffness, impact_mass, clearance, damping) is not
    # the README's (damping third): ImpactDamper(1.0, 1.0, 0.01, 0.25, 0.01) made a 0.01 kg
    # impact mass with 0.25 m clearances, unnoticed.
    with pytest.raises(TypeError):
        vi.ImpactDamper(1.0, 1.0, 0.01, 0.25, 0.01)  # type: ignore[misc]
    damper = vi.ImpactDamper(
        main_mass=1.0, stiffness=1.0, damping=0.01, impact_mass=0.25, clearance=0.01
    )
    assert (damper.impact_mass, damper.clearance, damper.damping) == (0.25, 0.01, 0.01)


@pytest.mark.parametrize("bad", [None, "abcd", [[0.01, 0.0]], [0.01, "x"]])
@pytest.mark.parametrize(
    "call",
    [
        lambda state: _core.tangent_map(_prepared_system(**PREPARED), state, 0.1),
        lambda state: _core.lyapunov_spectrum(_prepared_system(**PREPARED), state, 0.1, 2),
        lambda state: _prepared_system(**PREPARED).run(state, 0.1),
        lambda state: _prepared_system(**PREPARED).shoot(
            state, 0.1, tolerance=1e-8, max_iterations=2
        ),
    ],
    ids=["tangent_map", "lyapunov_spectrum", "run", "shoot"],
)
def test_a_state_that_is_not_numbers_is_refused_by_name(call: Any, bad: Any) -> None:
    # PyO3's own conversion had raised a TypeError ("'None' is not an instance of
    # 'Sequence'", "Can't extract `str` to `Vec`"), which is no ValueError.
    with pytest.raises(vi.InvalidInputError, match=r"^state must be a sequence of numbers"):
        call(bad)


@pytest.mark.parametrize("bad", [-1, 0, 2.0, True, 2**70])
def test_max_iterations_not_a_whole_number_is_refused_by_name(bad: Any) -> None:
    # -1 had raised an OverflowError.
    with pytest.raises(vi.InvalidInputError, match=r"^max_iterations must be a whole number"):
        _prepared_system(**PREPARED).shoot([0.01, 0.0], 0.1, tolerance=1e-8, max_iterations=bad)
