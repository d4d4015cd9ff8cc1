"""Running a 0.2 system: :func:`simulate_system`, and :func:`prepare_system` checking
every section and the run's limits once (:class:`PreparedRun`) for repeated runs."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact._core import (
    MAX_POINTS,
    METHOD_OPTIONS,
    InvalidInputError,
)
from vibroimpact._core import _check_forcing_period as check_forcing_period
from vibroimpact._core import _check_run as check_run
from vibroimpact._core import _check_settings as check_settings
from vibroimpact._core import simulate_system as _simulate_system
from vibroimpact.arguments import directory
from vibroimpact.messages import short_numbers, shown
from vibroimpact.system.points import _check_bends, _check_point, split_observed
from vibroimpact.system.schema import (
    _FIXED_STEP,
    _METHODS,
    _OUTPUT,
    _SOLVER,
    SYSTEM_SOLVER_DEFAULTS,
    _choice,
    _fail,
    _table,
    initial_arrays,
    initial_table,
    system_spec,
)
from vibroimpact.system.solution import SystemContacts, SystemSolution


def simulate_system(
    structure: Mapping[str, Any],
    *,
    damper: Any = (),
    stop: Any = (),
    collision: Any = (),
    friction: Any = (),
    gravity: Any = None,
    excitation: Any = (),
    initial: Mapping[str, Any] | None = None,
    t_end: float,
    method: str = SYSTEM_SOLVER_DEFAULTS["method"],
    dt: float | None = None,
    rtol: float = SYSTEM_SOLVER_DEFAULTS["rtol"],
    atol: float = SYSTEM_SOLVER_DEFAULTS["atol"],
    beta: float = SYSTEM_SOLVER_DEFAULTS["beta"],
    gamma: float = SYSTEM_SOLVER_DEFAULTS["gamma"],
    spectral_radius: float = SYSTEM_SOLVER_DEFAULTS["spectral_radius"],
    every: int = 1,
    history: bool = True,
    max_steps: int = SYSTEM_SOLVER_DEFAULTS["max_steps"],
    energy_tolerance: float = SYSTEM_SOLVER_DEFAULTS["energy_tolerance"],
    max_rows: int = SYSTEM_SOLVER_DEFAULTS["max_rows"],
    base_dir: Path | None = None,
    record_from: float | None = None,
    strobe_period: float | None = None,
    points: Any = (),
    moments: Any = (),
    stepping: str = SYSTEM_SOLVER_DEFAULTS["stepping"],
    contact_timing: str = SYSTEM_SOLVER_DEFAULTS["contact_timing"],
) -> SystemSolution:
    """Integrate a 0.2 system from ``initial`` to ``t_end`` (s).

    The sections are those of a TOML scenario (see the module docstring), as dicts
    (``damper``, ``stop``, ``collision``, ``friction`` and ``excitation`` as lists of
    dicts). ``initial`` holds
    ``structure_displacement``, ``structure_velocity``, ``damper_displacement``,
    ``damper_velocity`` (arrays, SI; zeros where left out). ``method``: ``"rk4"``
    (fixed step ``dt``), ``"dopri5"`` or ``"dop853"`` (``rtol``, ``atol``),
    ``"newmark-implicit"`` (``beta``, ``gamma``) or ``"generalized-alpha"``
    (``spectral_radius``), implicit with Newton's method, fixed step ``dt``; or
    ``"exact"``: the closed-form flow of a linear structure with rigid or linear pairs and
    harmonic (or no) excitation, exact to round-off between impacts (``dt``, if
    given, caps its step of an eighth of the fastest period). Every
    event (contact onset, separation, rigid impact, release) is located to
    round-off. ``every`` keeps every N-th step; ``history=False`` keeps none (the
    contacts and the final state only). A run stops with a clear error past
    ``max_steps`` steps, past ``max_rows`` history rows and contacts, or when its
    energy balance is off by more than ``energy_tolerance`` (in (0, 1]) of the energies in play.
    From ``record_from`` (s) on, each structure coordinate's located peak and RMS
    are kept (``peak``, ``rms``), and the structure's at each of ``points`` (as a
    damper's ``at``: m from a cantilever's clamp, or a coordinate index; ``point_peak``,
    ``point_rms``), and a cantilever's bending moment at each of ``moments`` (m from the
    clamp; ``moment_peak``, ``moment_rms``, N m); every ``strobe_period`` (s) the state is kept
    (``strobe``; fixed steps are shortened to divide it). ``stepping="fixed"`` takes
    steps of ``dt`` not cut at contacts (fixed-step methods and compliant laws only), each
    contact's onset and separation located inside its step by interpolation
    (``contact_timing="located"``) or counted in whole steps (``"step-count"``, as the
    founding paper counted them). The GIL is released while integrating; Ctrl-C
    interrupts.
    """
    run = prepare_system(
        structure,
        damper=damper,
        stop=stop,
        collision=collision,
        friction=friction,
        gravity=gravity,
        excitation=excitation,
        initial=initial,
        solver={
            "method": method,
            "t_end": t_end,
            "rtol": rtol,
            "atol": atol,
            "max_steps": max_steps,
            "energy_tolerance": energy_tolerance,
            "max_rows": max_rows,
            "beta": beta,
            "gamma": gamma,
            "spectral_radius": spectral_radius,
            "stepping": stepping,
            "contact_timing": contact_timing,
            **({} if dt is None else {"dt": dt}),
        },
        output={
            "every": every,
            "history": history,
            **({} if record_from is None else {"record_from": record_from}),
            **({} if strobe_period is None else {"strobe_period": strobe_period}),
            "points": points,
            "moments": moments,
        },
        base_dir=base_dir,
    )
    return run.run()


@dataclass(frozen=True)
class PreparedRun:
    """A checked 0.2 run, ready to integrate (see :func:`prepare_system`)."""

    spec: dict[str, Any]
    initial: dict[str, list[float]]
    solver: dict[str, Any]
    output: dict[str, Any]

    def binding_spec(self) -> dict[str, Any]:
        """The sections as the binding takes them (gravity as a number, the points
        ``[output]`` follows)."""
        return {
            **self.spec,
            "gravity": self.spec["gravity"]["acceleration"],
            "points": list(self.output["points"]),
            "moments": list(self.output["moments"]),
        }

    def method_arguments(self) -> dict[str, Any]:
        """The solver settings as the binding's keyword arguments."""
        return {
            key: self.solver[key]
            for key in (
                "method",
                "t_end",
                "dt",
                "rtol",
                "atol",
                "beta",
                "gamma",
                "spectral_radius",
                "max_steps",
                "max_rows",
                "energy_tolerance",
                "stepping",
                "contact_timing",
            )
        }

    def check_forcing_period(self, period: float) -> None:
        """Refuse an analysis's forcing ``period`` (s) no run of these settings can step
        through (the core registry's ``check_forcing_period``: more than ``max_steps``
        steps of a fixed ``dt``; for an adaptive or exact method more than ``max_steps``
        periods of the fastest mode, a forcing moving the structure less than ``atol`` a
        period, or a free body's times' round-off beyond what ``atol`` resolves), naming
        the frequency and the range a run can take."""
        solver = self.solver
        try:
            check_forcing_period(
                self.binding_spec(),
                forcing_period=period,
                **{key: solver[key] for key in ("method", "dt", "atol", "max_steps")},
            )
        except InvalidInputError as err:
            raise InvalidInputError(short_numbers(str(err))) from None

    def run(self) -> SystemSolution:
        """Integrate it."""
        init, solver, output = self.initial, self.solver, self.output
        try:
            raw = _simulate_system(
                self.binding_spec(),
                initial_arrays(init),
                **self.method_arguments(),
                every=output["every"],
                history=output["history"],
                record_from=output["record_from"],
                strobe_period=output["strobe_period"],
            )
        except InvalidInputError as err:
            # The core writes its numbers in full: 1e300 as 301 digits.
            raise type(err)(short_numbers(str(err))) from None
        return _solution(
            raw, solver["method"], self.spec["structure"], output["points"], output["moments"]
        )


def prepare_system(
    structure: Any,
    *,
    damper: Any = (),
    stop: Any = (),
    collision: Any = (),
    friction: Any = (),
    gravity: Any = None,
    excitation: Any = (),
    initial: Any = None,
    solver: Mapping[str, Any],
    output: Mapping[str, Any] | None = None,
    base_dir: Path | None = None,
) -> PreparedRun:
    """Check every section of a 0.2 run (the sections of a TOML scenario, as dicts)
    and fill their defaults; errors name the section and key."""
    base_dir = directory("base_dir", base_dir)
    try:
        spec = system_spec(
            structure,
            damper,
            stop,
            gravity,
            excitation,
            base_dir,
            collision=collision,
            friction=friction,
        )
    except RecursionError:
        # Arrays nested thousands deep: no structure has them.
        raise _fail("", "a value is nested too deeply (arrays within arrays)") from None
    # "is None", not "or": an array given for a table has no truth value.
    init = initial_table(initial, spec)
    solver = solver_table(solver)
    output = _table("[output] ", {} if output is None else output, _OUTPUT)
    # every, max_steps and max_rows are whole numbers >= 1 (the schema's WHOLE_RANGES).
    # The up-front limits (strobe_period > 0, steps, the fastest mode and forcing against
    # the step, rows, memory) are the core's (its registry's check_run), with their
    # messages.
    try:
        check_run(
            spec,
            **{key: solver[key] for key in ("method", "dt", "t_end", "max_steps", "max_rows")},
            beta=solver.get("beta"),
            gamma=solver.get("gamma"),
            every=output["every"],
            history=output["history"],
            strobe_period=output["strobe_period"],
        )
    except InvalidInputError as err:
        raise _fail("", short_numbers(str(err))) from None
    check_record_window("[output] record_from: ", checked_output(output, spec), solver)
    if (len(output["points"]) or len(output["moments"])) and output["record_from"] is None:
        # Points ask for their peaks: of the whole run where no window is given
        # (user trial: they were silently left out).
        output["record_from"] = 0.0
    return PreparedRun(spec, init, solver, output)


def checked_output(output: Mapping[str, Any], spec: Mapping[str, Any]) -> float | None:
    """The checks of an ``[output]`` table (filled by its schema) that do not need the
    run's length: ``record_from`` >= 0 (returned), the points and moments on the
    structure, each once and not too many."""
    if output["record_from"] is not None and not output["record_from"] >= 0:
        raise _fail("[output] record_from: ", f"must be >= 0 s, got {output['record_from']}")
    followed = len(output["points"]) + len(output["moments"])
    if followed > MAX_POINTS:
        raise _fail(
            "[output] points, moments: ",
            f"{followed} in all; at most {MAX_POINTS} are allowed (together)",
        )
    if output["moments"]:
        _check_bends("[output] moments", spec["structure"])
    for key in ("points", "moments"):
        for j, at in enumerate(output[key]):
            _check_point(f"[output] {key}[{j}]", at, float(at), spec["structure"])
            if at in output[key][:j]:
                raise _fail(f"[output] {key}: ", f"{shown(at)} is given twice")
    return output["record_from"]  # type: ignore[no-any-return]


def _solution(
    raw: dict[str, Any],
    method: str,
    structure: Mapping[str, Any],
    points: Sequence[float] = (),
    moments: Sequence[float] = (),
) -> SystemSolution:
    n, k = raw["n"], raw["k"]
    recorded = raw["recorded_time"] > 0
    width = 2 * (n + k)
    states = raw["states"].reshape(-1, width)
    final = raw["final_state"]
    c = raw["contacts"]
    pairs = list(raw["pairs"])
    observed = n + len(points) + len(moments)
    peaks = raw["peaks"] if recorded else np.full(observed, np.nan)
    peak, point_peak, moment_peak = split_observed(peaks, n, len(points))
    rms, point_rms, moment_rms = split_observed(
        np.sqrt(raw["square_integrals"] / raw["recorded_time"])
        if recorded
        else np.full(observed, np.nan),
        n,
        len(points),
    )
    contacts = SystemContacts(
        pair=[pairs[p] for p in c["pair"]],
        kind=list(c["kind"]),
        **{name: c[name] for name in SystemContacts.columns[2:]},
    )
    return SystemSolution(
        t=raw["time"],
        structure_displacement=states[:, :n],
        damper_displacement=states[:, n : n + k],
        structure_velocity=states[:, n + k : 2 * n + k],
        damper_velocity=states[:, 2 * n + k :],
        contacts=contacts,
        final_state={
            "structure_displacement": final[:n],
            "structure_velocity": final[n + k : 2 * n + k],
            "damper_displacement": final[n : n + k],
            "damper_velocity": final[2 * n + k :],
        },
        final_time=raw["final_time"],
        energy=dict(raw["energy"]),
        steps=raw["steps"],
        rejected_steps=raw["rejected_steps"],
        rhs_evaluations=raw["rhs_evaluations"],
        grazing_contacts=raw["grazing_contacts"],
        method=method,
        pairs=pairs,
        # Nothing recorded (no record_from): neither peak nor RMS, not a peak of 0.
        peak=peak,
        rms=rms,
        points=np.asarray(points, dtype=float),
        point_peak=point_peak,
        point_rms=point_rms,
        moments=np.asarray(moments, dtype=float),
        moment_peak=moment_peak,
        moment_rms=moment_rms,
        recorded_time=raw["recorded_time"],
        strobe=raw["strobe"].reshape(-1, width),
        strobe_time=raw["strobe_time"],
        structure=dict(structure),
        contact_force=raw["contact_forces"].reshape(
            len(raw["time"]), len(raw["contact_force_pairs"])
        ),
        contact_force_pairs=[pairs[p] for p in raw["contact_force_pairs"]],
    )


#: ``[solver]``'s schema with ``t_end`` left out allowed (checked where a run needs it).
_SOLVER_LENGTH_LEFT_OUT = {**_SOLVER, "t_end": (_SOLVER["t_end"][0], None)}


def solver_table(solver: Any, *, length_given: bool = True) -> dict[str, Any]:
    """The ``[solver]`` table checked (its keys, method, stepping and the registry's
    ranges) with its defaults filled; without ``length_given``, ``t_end`` (s) may be
    left out (None): a System's solver whose runs are given their length."""
    checked: dict[str, Any] = _table("[solver] ", solver, _SOLVER_LENGTH_LEFT_OUT)
    if length_given and checked["t_end"] is None:
        # A System's solver may leave it out (its runs are given it); a run may not.
        raise _fail(
            "[solver] ",
            "missing key 't_end' (the run's length in s; from Python, simulate(..., t_end=...))",
        )
    _choice("[solver] ", "method", checked["method"], _METHODS)
    _choice("[solver] ", "stepping", checked["stepping"], ("events", "fixed"))
    _choice("[solver] ", "contact_timing", checked["contact_timing"], ("located", "step-count"))
    if checked["stepping"] == "events" and checked["contact_timing"] != "located":
        raise _fail(
            "[solver] contact_timing: ",
            '"step-count" needs stepping = "fixed" (with events the instants are located)',
        )
    if checked["stepping"] == "fixed" and checked["method"] not in _FIXED_STEP:
        raise _fail(
            "[solver] stepping: ",
            f'"fixed" takes a fixed-step method ({", ".join(_FIXED_STEP)}), '
            f"not {checked['method']!r}",
        )
    # No length yet: the other settings' ranges do not depend on it (1 s is in range).
    _check_settings(checked if checked["t_end"] is not None else {**checked, "t_end": 1.0})
    return checked


def _check_settings(solver: Mapping[str, Any]) -> None:
    """``t_end``, ``dt``, the method options (every one, whatever the method: the core
    checks them) and ``energy_tolerance`` in the core registry's ranges (its
    ``check_settings``, the one place they are checked), the message naming
    ``[solver] key`` and the value as given."""
    try:
        check_settings(**{key: solver[key] for key in _CHECKED})
    except InvalidInputError as err:
        # The core writes "key must be <allowed>, got <value>".
        key, _, rest = str(err).partition(" must be ")
        if key not in _CHECKED:
            raise _fail("[solver] ", short_numbers(str(err))) from None
        allowed = rest.rpartition(", got ")[0]
        raise _fail(f"[solver] {key}: ", f"must be {allowed}, got {solver[key]}") from None


# The settings the core registry's check_settings takes.
_CHECKED = (
    "t_end",
    "dt",
    *(key for key in METHOD_OPTIONS if key != "max_steps"),
    "energy_tolerance",
)


def check_record_window(where: str, record_from: float | None, solver: Mapping[str, Any]) -> None:
    """Refuse a record window, from ``record_from`` to ``solver``'s ``t_end`` (s), that
    holds nothing: one that starts at or after the end, or, where ``solver``'s
    ``stepping`` is fixed, one shorter than a step of its ``dt`` (no step ends in it: the
    run recorded nothing, a peak of NaN or 0 in a study's lanes, without a word). With
    events, the run steps to the window's start."""
    if record_from is None:
        return
    t_end, dt = solver["t_end"], solver.get("dt")
    if not record_from < t_end:
        raise _fail(where, f"must be before [solver] t_end ({t_end!r} s), got {record_from!r}")
    if solver.get("stepping") == "fixed" and dt is not None and t_end - record_from < dt:
        raise _fail(
            where,
            f"must leave at least one step of dt = {dt!r} s before [solver] t_end "
            f"({t_end!r} s) with fixed steps, got {record_from!r} (nothing would be recorded)",
        )
