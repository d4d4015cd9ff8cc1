"""The typed parts of a 0.2 system, named as the sections and keys of its TOML scenario.

Each part is a frozen, keyword-only dataclass whose fields are the keys of its TOML
table (SI units); a field left at None is a key not written, which takes the format's
default (see :mod:`vibroimpact.system`, the one place the keys, their defaults and
their ranges are defined). A part only holds values: a :class:`~vibroimpact.System`
checks them all at once through that schema, so that a bad value gets the error a
scenario file gets, naming the section and the key. ``to_dict()`` gives the TOML
table.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, TypeVar

import numpy as np

from vibroimpact.arguments import KeywordError, real
from vibroimpact.system import _GRAVITY, _STRUCTURE, _unknown_key, system_spec

_Numbers = tuple[float, ...]
_Rows = tuple[tuple[float, ...], ...]


def _scalar(value: Any) -> Any:
    """A NumPy number (``np.float32(0.5)``, or the 0-d array ``ds["x"][1].values`` gives)
    as the Python int or float it holds, so that a part holding it hashes and is written
    as TOML; anything else (a boolean too) as given, for the schema to refuse by name."""
    if isinstance(value, np.generic | np.ndarray) and np.ndim(value) == 0:
        number = real(value)
        return value if number is None else number
    return value


def _as_tuple(value: Any, depth: int) -> Any:
    """Arrays given as lists or NumPy arrays held as tuples (``depth`` 1 for values, 2
    for rows), so that parts compare and hash by value; anything else is kept as
    given, for the schema to refuse by name."""
    if not isinstance(value, np.ndarray | str | bytes | Sequence) and hasattr(value, "__array__"):
        # A pandas Series or an xarray DataArray (a record's column) as its values.
        value = np.asarray(value)
    if isinstance(value, np.ndarray) and value.ndim:
        value = value.tolist()  # Python numbers already, all the way down
        if depth == 1:
            return tuple(value)
    if isinstance(value, str | bytes) or not isinstance(value, Sequence):
        return value
    if depth == 1:
        return tuple(_scalar(v) for v in value)
    return tuple(_as_tuple(row, depth - 1) for row in value)


#: Values of an array a repr shows before it summarises the rest.
_SHOWN_VALUES = 4


def _shown(value: Any) -> str:
    """A field in a part's repr: a long array (a record's samples, a large matrix) as its
    first values and its length, so that a repr stays a line."""
    if isinstance(value, tuple) and len(value) > _SHOWN_VALUES:
        head = ", ".join(_shown(v) for v in value[:_SHOWN_VALUES])
        return f"({head}, ... {len(value)} in all)"
    if isinstance(value, tuple) and value and isinstance(value[0], tuple):
        inner = ", ".join(_shown(v) for v in value)
        return f"({inner},)" if len(value) == 1 else f"({inner})"
    return repr(value)


def _plain(value: Any) -> Any:
    """A tuple as the list TOML reads (rows as lists of lists)."""
    if isinstance(value, tuple):
        if not any(isinstance(v, tuple) for v in value[:1]):
            return list(value)  # an array of values (a record's samples: one copy in C)
        return [_plain(v) for v in value]
    return value


class PartKeywordError(KeywordError):
    """A part given a keyword it does not take, or not given one it needs (a
    ``ValueError``): the message names the part and the key, with the closest allowed key
    as a suggestion, as a scenario file's error does."""


_T = TypeVar("_T")


def keywords_checked(cls: type[_T]) -> type[_T]:
    """``cls`` (a part's dataclass) whose constructor refuses an unknown keyword (``did
    you mean``), a missing required one and positional values by name, raising
    :class:`PartKeywordError` where the dataclass raised a bare ``TypeError``."""
    fields = dataclasses.fields(cls)  # type: ignore[arg-type]
    names = [f.name for f in fields]
    required = [
        f.name
        for f in fields
        if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
    ]
    where = f"{cls.__name__}: "
    init: Callable[..., None] = cls.__init__

    @functools.wraps(init)
    def checked_init(self: Any, *args: Any, **keywords: Any) -> None:
        if args:
            raise PartKeywordError(
                f"{where}takes keywords only ({', '.join(f'{n}=...' for n in names)}), "
                f"got {len(args)} positional value{'s' if len(args) > 1 else ''}"
            )
        for key in keywords:
            if key not in names:
                error = _unknown_key(where, key, names, "allowed:")
                raise PartKeywordError(str(error))
        missing = [name for name in required if name not in keywords]
        if missing:
            raise PartKeywordError(
                f"{where}missing key {missing[0]!r} (required: {', '.join(required)})"
            )
        init(self, **keywords)

    cls.__init__ = checked_init  # type: ignore[method-assign]
    return cls


class Part:
    """What every part shares: arrays held as tuples, and ``to_dict()``."""

    #: The fields holding arrays: 1 for an array of values, 2 for rows.
    _arrays: ClassVar[dict[str, int]] = {}

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):  # type: ignore[arg-type]
            value = getattr(self, f.name)
            depth = self._arrays.get(f.name)
            held = _scalar(value) if depth is None else _as_tuple(value, depth)
            if held is not value:
                object.__setattr__(self, f.name, held)

    def __repr__(self) -> str:
        # The keys given only, as the part would be written (None: left to the format).
        given = ", ".join(
            f"{f.name}={_shown(getattr(self, f.name))}"
            for f in dataclasses.fields(self)  # type: ignore[arg-type]
            if getattr(self, f.name) is not None
        )
        return f"{type(self).__name__}({given})"

    def to_dict(self) -> dict[str, Any]:
        """The TOML table of this part: its keys that are given (not None), arrays as
        lists."""
        return {
            f.name: _plain(getattr(self, f.name))
            for f in dataclasses.fields(self)  # type: ignore[arg-type]
            if getattr(self, f.name) is not None
        }


def _default(table: dict[str, tuple[str, Any]], key: str) -> Any:
    """The schema's default of ``key`` (one source: :mod:`vibroimpact.system`)."""
    return table[key][1]


# ---------------------------------------------------------------- structures


class Structure(Part):
    """A ``[structure]``: :class:`Oscillator`, :class:`Matrices` or :class:`Cantilever`."""

    kind: ClassVar[str]

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, **super().to_dict()}


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Oscillator(Structure):
    """One mode: ``mass`` (kg), ``stiffness`` (N/m), ``damping`` (N s/m). Its one
    coordinate is point 0."""

    kind: ClassVar[str] = "oscillator"
    mass: float
    stiffness: float
    damping: float = _default(_STRUCTURE["oscillator"], "damping")


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Matrices(Structure):
    """``mass`` (kg, symmetric positive definite), ``stiffness`` (N/m) and ``damping``
    (N s/m; symmetric positive semi-definite; None: zeros) as n x n rows; the points
    are the coordinate indices."""

    kind: ClassVar[str] = "matrices"
    _arrays: ClassVar[dict[str, int]] = {"mass": 2, "stiffness": 2, "damping": 2}
    mass: _Rows
    stiffness: _Rows
    damping: _Rows | None = None


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Cantilever(Structure):
    """A clamped-free Euler-Bernoulli beam in ``modes`` modal coordinates: ``length``
    (m), ``youngs_modulus`` (Pa), ``second_moment`` (m^4), ``mass_per_length`` (kg/m),
    ``damping_ratio`` of every mode; its points are positions along it (m from the
    clamp).

    Or from its section and material: in place of ``second_moment`` a ``section``,
    ``"rectangle"`` (``width``, ``height``, m; bending about the axis parallel to the
    width), ``"circle"`` (``diameter``) or ``"tube"`` (``outer_diameter``,
    ``inner_diameter``); in place of ``mass_per_length`` a ``density`` (kg/m^3, times
    the section's area); a ``material``, ``"steel"`` (structural, E = 200 GPa, 7850
    kg/m^3), ``"aluminium"`` (6061-T6, 68.9 GPa, 2700 kg/m^3) or ``"titanium"``
    (Ti-6Al-4V, 114 GPa, 4430 kg/m^3), for Young's modulus and the density, each
    overridden by ``youngs_modulus`` or ``density`` where given. One way per quantity:
    ``section`` with ``second_moment``, or ``density`` with ``mass_per_length``, is an
    error (see ``vibroimpact.system.beam``, the sources of the materials' values).
    ``resolved()`` gives the values the beam is simulated with.

    >>> tube = Cantilever(length=0.5, section="tube", outer_diameter=0.02,
    ...                   inner_diameter=0.016, material="steel", modes=3)
    >>> f"{tube.resolved()['second_moment']:.4e} m^4"
    '4.6370e-09 m^4'
    """

    kind: ClassVar[str] = "cantilever"
    length: float
    youngs_modulus: float | None = None
    second_moment: float | None = None
    mass_per_length: float | None = None
    modes: int
    damping_ratio: float = _default(_STRUCTURE["cantilever"], "damping_ratio")
    section: str | None = None
    width: float | None = None
    height: float | None = None
    diameter: float | None = None
    outer_diameter: float | None = None
    inner_diameter: float | None = None
    material: str | None = None
    density: float | None = None

    def resolved(self) -> dict[str, Any]:
        """The beam as simulated (the checked ``[structure]``): ``length`` (m),
        ``youngs_modulus`` (Pa), ``second_moment`` (m^4), ``mass_per_length`` (kg/m),
        ``modes``, ``damping_ratio``, whether given or made from the section and the
        material."""
        return dict(system_spec(self.to_dict())["structure"])


# -------------------------------------------------------------- interactions


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Damper(Part):
    """A ``[[damper]]``: a loose ``mass`` (kg) rattling against the point ``at`` (a
    coordinate index, or m along a cantilever) with ``clearance`` (m) on each side, or
    ``lower_clearance`` and ``upper_clearance`` (``math.inf``: no wall on that side).
    ``law``: ``"rigid"`` (Newton's
    ``restitution`` in [0, 1]) or a compliant law, ``"hertz"``, ``"hyster-hertz"``,
    ``"hertz-damped"`` or ``"linear"``, with ``stiffness`` (N/m^1.5; N/m for
    ``"linear"``), ``restitution`` where the law takes one and the contact damper's
    ``damping`` (N s/m, default 0). Coulomb friction between the mass and its carrier
    (a horizontal damper sliding on its cavity's floor): ``friction`` (kinetic
    coefficient), ``static_friction`` (>= ``friction``, default equal) and
    ``normal_force`` (N: its weight, or a preload)."""

    mass: float
    at: float
    clearance: float | None = None
    lower_clearance: float | None = None
    upper_clearance: float | None = None
    law: str
    stiffness: float | None = None
    restitution: float | None = None
    damping: float | None = None
    friction: float | None = None
    static_friction: float | None = None
    normal_force: float | None = None


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Stop(Part):
    """A ``[[stop]]``: the point ``at`` hits a stop fixed to the base, ``side =
    "upper"`` keeping it at or below ``+gap`` (m), ``"lower"`` at or above ``-gap``;
    with ``against`` (a second point) the stop is carried by that point. ``law`` and
    its keys as for :class:`Damper`."""

    at: float
    side: str
    gap: float
    against: float | None = None
    law: str
    stiffness: float | None = None
    restitution: float | None = None
    damping: float | None = None


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Collision(Part):
    """A ``[[collision]]``: two loose masses that strike each other (a multi-unit or
    particle-column damper). ``dampers = (i, j)``: damper ``i`` below damper ``j``
    along the axis, touching when the displacement of ``i`` minus that of ``j`` reaches
    ``gap`` (m, their free distance at rest). ``law`` and its keys as for
    :class:`Damper`."""

    _arrays: ClassVar[dict[str, int]] = {"dampers": 1}

    dampers: tuple[int, int]
    gap: float
    law: str
    stiffness: float | None = None
    restitution: float | None = None
    damping: float | None = None


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Friction(Part):
    """A ``[[friction]]``: a dry-friction (Coulomb) element between the structure's
    point ``at`` and ``against`` (another point; None: the base), as Den Hartog's
    friction damper. While they slide a force ``coefficient * normal_force`` (N)
    opposes their relative velocity; they stick when it reaches zero and the force
    holding them is within ``static_coefficient * normal_force`` (default: the
    kinetic coefficient), and slip again when it is not."""

    at: float
    against: float | None = None
    coefficient: float
    static_coefficient: float | None = None
    normal_force: float


# ------------------------------------------------------------------- signals


class Signal(Part):
    """The signal of an excitation; ``kind`` is its TOML ``signal``."""

    kind: ClassVar[str]


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Harmonic(Signal):
    """``amplitude * cos(2 pi frequency t + phase)``: ``frequency`` in Hz, ``phase`` in
    rad (default 0); the amplitude in N for a force, m/s^2 for a base."""

    kind: ClassVar[str] = "harmonic"
    amplitude: float
    frequency: float
    phase: float | None = None


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Sweep(Signal):
    """A harmonic whose frequency goes from ``start_frequency`` to ``end_frequency``
    (Hz) over ``duration`` (s, default the run's t_end), ``sweep = "linear"`` or
    ``"logarithmic"``, then stays at the end frequency."""

    kind: ClassVar[str] = "sweep"
    amplitude: float
    start_frequency: float
    end_frequency: float
    duration: float | None = None
    sweep: str | None = None
    phase: float | None = None


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Harmonics(Signal):
    """A sum of harmonics: as many ``amplitudes``, ``frequencies`` (Hz) and ``phases``
    (rad; None: each 0)."""

    kind: ClassVar[str] = "harmonics"
    _arrays: ClassVar[dict[str, int]] = {"amplitudes": 1, "frequencies": 1, "phases": 1}
    amplitudes: _Numbers
    frequencies: _Numbers
    phases: _Numbers | None = None


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Recorded(Signal):
    """A record: ``file`` (a CSV of time in s and value; relative paths from the
    system's ``base_dir``), or ``time`` and ``value`` arrays; interpolated linearly,
    times ``scale``, zero outside the record."""

    kind: ClassVar[str] = "recorded"
    _arrays: ClassVar[dict[str, int]] = {"time": 1, "value": 1}
    file: str | None = None
    time: _Numbers | None = None
    value: _Numbers | None = None
    scale: float | None = None


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class WhiteNoise(Signal):
    """Band-limited white noise: two-sided spectral density ``intensity`` S0 per rad/s
    up to ``cutoff_frequency`` (Hz), the same for the same ``seed`` on every
    platform, over ``duration`` (s, default t_end)."""

    kind: ClassVar[str] = "white-noise"
    intensity: float
    cutoff_frequency: float
    seed: int
    duration: float | None = None


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class KanaiTajimi(Signal):
    """White noise through the Kanai-Tajimi ground filter of ``ground_frequency`` (Hz)
    and ``ground_damping``; the other keys as for :class:`WhiteNoise`."""

    kind: ClassVar[str] = "kanai-tajimi"
    intensity: float
    ground_frequency: float
    ground_damping: float
    cutoff_frequency: float
    seed: int
    duration: float | None = None


SIGNALS: tuple[type[Signal], ...] = (Harmonic, Sweep, Harmonics, Recorded, WhiteNoise, KanaiTajimi)

# --------------------------------------------------------------- excitations


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Force(Part):
    """A ``[[excitation]]`` of kind ``"force"``: ``signal`` (N) acting at the point
    ``at``."""

    at: float
    signal: Signal

    def to_dict(self) -> dict[str, Any]:
        return {"kind": "force", "at": self.at, **_signal_keys(self.signal)}


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Base(Part):
    """A ``[[excitation]]`` of kind ``"base"``: the support's acceleration ``signal``
    (m/s^2); every coordinate is relative to the base, and stops move with it."""

    signal: Signal

    def to_dict(self) -> dict[str, Any]:
        return {"kind": "base", **_signal_keys(self.signal)}


def _signal_keys(signal: Any) -> dict[str, Any]:
    """A signal's keys in its excitation's table (a part other than a signal is left for
    :class:`~vibroimpact.System` to refuse by name)."""
    if isinstance(signal, Signal):
        return {"signal": signal.kind, **signal.to_dict()}
    return {"signal": signal}


# ------------------------------------------------- gravity, initial, settings


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Gravity(Part):
    """``[gravity]``: ``acceleration`` (m/s^2, along -x, on every mass)."""

    acceleration: float = _default(_GRAVITY, "acceleration")


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Initial(Part):
    """``[initial]``: the state at t = 0 as arrays (m, m/s; zeros where empty): the
    structure's coordinates, then each damper's own displacement (not relative to its
    point) and velocity."""

    _arrays: ClassVar[dict[str, int]] = {
        "structure_displacement": 1,
        "structure_velocity": 1,
        "damper_displacement": 1,
        "damper_velocity": 1,
    }
    structure_displacement: _Numbers = ()
    structure_velocity: _Numbers = ()
    damper_displacement: _Numbers = ()
    damper_velocity: _Numbers = ()

    def to_dict(self) -> dict[str, Any]:
        # Only the arrays given: an [initial] of zeros is written as none.
        return {key: value for key, value in super().to_dict().items() if value}


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Solver(Part):
    """``[solver]``: ``method`` (``"rk4"``, ``"dopri5"``, ``"dop853"``,
    ``"newmark-implicit"``, ``"generalized-alpha"`` or ``"exact"``; default
    ``"rk4"``), ``t_end`` and ``dt`` (s), ``rtol``, ``atol`` (m, m/s), ``beta``,
    ``gamma``, ``spectral_radius``, ``max_steps``, ``max_rows``,
    ``energy_tolerance``, ``stepping`` (``"events"`` or ``"fixed"``) and
    ``contact_timing`` (``"located"`` or ``"step-count"``); None leaves a key to its
    default (see :data:`vibroimpact.system.SYSTEM_SOLVER_DEFAULTS`)."""

    method: str | None = None
    t_end: float | None = None
    dt: float | None = None
    rtol: float | None = None
    atol: float | None = None
    max_steps: int | None = None
    energy_tolerance: float | None = None
    max_rows: int | None = None
    beta: float | None = None
    gamma: float | None = None
    spectral_radius: float | None = None
    stepping: str | None = None
    contact_timing: str | None = None


@keywords_checked
@dataclass(frozen=True, kw_only=True, repr=False)
class Output(Part):
    """``[output]``: keep ``every`` N-th step of the history (``history = False``
    keeps none); from ``record_from`` (s) the located peaks and RMS, every
    ``strobe_period`` (s) the state, the structure at ``points`` and a cantilever's
    bending moment at ``moments`` (m from the clamp, or coordinate indices)."""

    _arrays: ClassVar[dict[str, int]] = {"points": 1, "moments": 1}
    every: int | None = None
    history: bool | None = None
    record_from: float | None = None
    strobe_period: float | None = None
    points: _Numbers | None = None
    moments: _Numbers | None = None
