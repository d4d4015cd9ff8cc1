"""``vibroimpact.simulate``: a typed :class:`~vibroimpact.System` on the general kernel,
or the two-mass impact damper (``ImpactDamper``, ``Contact``, ``InitialState``)."""

from __future__ import annotations

import difflib
import inspect
import os
from collections.abc import Callable, Mapping
from typing import Any, overload

from vibroimpact._core import (
    Contact,
    ImpactDamper,
    InitialState,
    InvalidInputError,
    Solution,
)
from vibroimpact._core import simulate as _two_mass
from vibroimpact.arguments import KeywordError, typed
from vibroimpact.messages import shown
from vibroimpact.model.parts import Output, Part, Solver
from vibroimpact.model.system import System
from vibroimpact.system import SystemSolution, prepare_system

#: The text arguments of the two-mass run (PyO3's TypeError names none of them).
# Keywords of a System's run only (refused by name for the two-mass run).
_SYSTEM_ONLY = frozenset(("record_from", "strobe_period", "points", "moments"))
TEXTS: dict[str, type | tuple[type, ...]] = {
    "method": (str, type(None)),
    "contact_timing": (str, type(None)),
    "stepping": (str, type(None)),
}
two_mass: Callable[..., Solution] = typed(
    system=ImpactDamper, contact=Contact, initial=InitialState, **TEXTS
)(_two_mass)


class _Default:
    """The default of an argument not given (the run's setting, or the method's)."""

    def __repr__(self) -> str:
        return "default"


_UNSET: Any = _Default()
_SOLVER_KEYS = tuple(Solver.__dataclass_fields__)
_OUTPUT_KEYS = tuple(Output.__dataclass_fields__)


def simulate_model(system: System, **settings: Any) -> SystemSolution:
    """Integrate ``system`` with its ``solver`` and ``output`` settings, each key
    replaced by the keyword of that name given (None: not given), as a run of its
    scenario file does (the same checks and the same bits)."""
    unknown = [key for key in settings if key not in _SOLVER_KEYS + _OUTPUT_KEYS]
    if unknown:
        raise KeywordError(
            f"simulate() of a System got an unexpected keyword argument {unknown[0]!r} "
            f"(it takes {', '.join(_SOLVER_KEYS + _OUTPUT_KEYS)})"
        )
    solver = {} if system.solver is None else system.solver.to_dict()
    output = {} if system.output is None else system.output.to_dict()
    for key, value in settings.items():
        if value is not None:
            (solver if key in _SOLVER_KEYS else output)[key] = value
    prepared = prepare_system(
        **system.model_sections(), solver=solver, output=output, base_dir=system.base_dir
    )
    return prepared.run()


def _simulate(
    system: System | ImpactDamper,
    contact: Contact = _UNSET,
    initial: InitialState = _UNSET,
    *,
    t_end: float | None = _UNSET,
    method: str | None = _UNSET,
    dt: float | None = _UNSET,
    rtol: float | None = _UNSET,
    atol: float | None = _UNSET,
    max_steps: int | None = _UNSET,
    energy_tolerance: float | None = _UNSET,
    max_rows: int | None = _UNSET,
    beta: float | None = _UNSET,
    gamma: float | None = _UNSET,
    spectral_radius: float | None = _UNSET,
    every: int | None = _UNSET,
    history: bool | None = _UNSET,
    stepping: str | None = _UNSET,
    contact_timing: str | None = _UNSET,
    record_from: float | None = _UNSET,
    strobe_period: float | None = _UNSET,
    points: Any = _UNSET,
    moments: Any = _UNSET,
) -> SystemSolution | Solution:
    """Integrate a system from its initial state to ``t_end`` (s); SI units. A keyword
    not given (or None, for a System) takes the run's setting or its default.

    ``simulate(system, t_end=..., method=..., ...)`` runs a :class:`vibroimpact.System`
    on the general kernel with its ``solver`` and ``output`` settings (read from its
    scenario file by :func:`vibroimpact.load`), each replaced by the keyword of that
    name given: ``method`` (``"rk4"``, ``"dopri5"``, ``"dop853"``, ``"newmark"``,
    ``"newmark-implicit"``, ``"generalized-alpha"``, ``"exact"``; default ``"rk4"``, the
    core registry's ``vibroimpact.RUN_DEFAULTS["system"]``), ``stepping`` (``"events"``,
    default, or ``"fixed"``), ``contact_timing``
    (``"located"`` or ``"step-count"``, fixed stepping's), ``t_end``, ``dt`` (s),
    ``rtol``, ``atol`` (m, m/s), ``beta``, ``gamma``,
    ``spectral_radius``, ``max_steps``, ``max_rows``, ``energy_tolerance``, ``every``,
    ``history``, ``record_from``, ``strobe_period`` (s), ``points``, ``moments``;
    returns a :class:`~vibroimpact.SystemSolution` (see
    :func:`vibroimpact.simulate_system`).

    ``simulate(ImpactDamper, Contact, InitialState, t_end=..., method="newmark", ...)``
    runs the two-mass impact damper (not ``record_from``, ``strobe_period``, ``points``,
    ``moments``) and returns a :class:`vibroimpact.Solution` (its defaults, the core
    registry's for the two-mass damper, ``vibroimpact.RUN_DEFAULTS["two-mass"]``:
    ``method="newmark"`` in fixed steps, ``dt`` required by the fixed-step methods, the
    rest as for a System).
    """
    given = {key: value for key, value in locals().items() if value is not _UNSET}
    del given["system"]
    if not isinstance(system, System | ImpactDamper):
        raise InvalidInputError(_not_a_system(system))
    if isinstance(system, ImpactDamper) and (contact is _UNSET or initial is _UNSET):
        raise KeywordError(
            "simulate() of the two-mass ImpactDamper needs its Contact and InitialState: "
            "simulate(ImpactDamper, Contact, InitialState, t_end=...)"
        )
    if isinstance(system, System):
        for name in ("contact", "initial"):
            if name in given:
                raise InvalidInputError(
                    f"{name}: applies to the two-mass run (simulate(ImpactDamper, Contact, "
                    f"InitialState, ...)), not to a System, got {shown(given[name])}"
                )
        # None leaves a setting to the system's solver or output, or to its default.
        return simulate_model(system, **{k: v for k, v in given.items() if v is not None})
    for name in sorted(_SYSTEM_ONLY):
        if name in given:
            raise InvalidInputError(
                f"{name}: applies to a vibroimpact.System, not to the two-mass run, got "
                f"{shown(given[name])}"
            )
    # Forwarded as given (None included): the two-mass run's checks name what is wrong.
    return two_mass(system, **given)


def _not_a_system(value: Any) -> str:
    """The error of ``simulate`` given something other than a system, with the call
    that makes one of it."""
    hint = ""
    if isinstance(value, str | os.PathLike):
        hint = "; a scenario file is read by vibroimpact.load(path) first"
    elif isinstance(value, Mapping):
        hint = "; a scenario's tables make one by vibroimpact.System.from_dict(tables)"
    elif isinstance(value, Part):
        hint = f"; a {type(value).__name__} is one part of vibroimpact.System(...)"
    return (
        "system: must be a vibroimpact.System (or the two-mass vibroimpact.ImpactDamper, "
        f"with a Contact and an InitialState), got {shown(value)}{hint}"
    )


@overload
def simulate(
    system: System,
    *,
    t_end: float | None = None,
    method: str | None = None,
    dt: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    max_steps: int | None = None,
    energy_tolerance: float | None = None,
    max_rows: int | None = None,
    beta: float | None = None,
    gamma: float | None = None,
    spectral_radius: float | None = None,
    every: int | None = None,
    history: bool | None = None,
    record_from: float | None = None,
    strobe_period: float | None = None,
    points: Any = None,
    moments: Any = None,
) -> SystemSolution: ...
@overload
def simulate(  # the two-mass run's own signature (_core.pyi)
    system: ImpactDamper,
    contact: Contact,
    initial: InitialState,
    *,
    t_end: float,
    dt: float | None = None,
    method: str | None = None,
    every: int = 1,
    contact_timing: str | None = None,
    stepping: str | None = None,
    beta: float | None = None,
    gamma: float | None = None,
    spectral_radius: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    max_steps: int | None = None,
    max_rows: int | None = None,
    energy_tolerance: float | None = None,
    history: bool = True,
) -> Solution: ...
def simulate(
    system: System | ImpactDamper,
    contact: Contact = _UNSET,
    initial: InitialState = _UNSET,
    **settings: Any,
) -> SystemSolution | Solution:
    # A two-mass call goes straight to the core (a call's overhead: bench_steps' 5 us
    # goal; the checks of the full signature cost 1.7 us more); any other call, and a
    # two-mass call with a System's keyword, through them.
    if (
        system.__class__ is ImpactDamper
        and contact is not _UNSET
        and initial is not _UNSET
        and not settings.keys() & _SYSTEM_ONLY
    ):
        return two_mass(system, contact, initial, **settings)
    unknown = sorted(settings.keys() - _KEYWORDS)
    if unknown:
        # Python's own error would name the private function, with no hint.
        close = difflib.get_close_matches(unknown[0], sorted(_KEYWORDS), n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise KeywordError(f"simulate() got an unexpected keyword argument {unknown[0]!r}{hint}")
    return _simulate(system, contact, initial, **settings)


simulate.__doc__ = _simulate.__doc__
simulate.__signature__ = inspect.signature(_simulate)  # type: ignore[attr-defined]
_KEYWORDS = frozenset(
    name
    for name, parameter in inspect.signature(_simulate).parameters.items()
    if parameter.kind is inspect.Parameter.KEYWORD_ONLY
)
