"""The results of a 0.2 run: its contacts (:class:`SystemContacts`) and its solution
(:class:`SystemSolution`), with their pandas and xarray views (SI units)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from vibroimpact._core import (
    InvalidInputError,
)
from vibroimpact.notebook import solution_html
from vibroimpact.summary import contacts_frame, contacts_repr, history_dataset, solution_repr
from vibroimpact.system.points import moment_weights, point_weights


@dataclass(frozen=True, eq=False)
class SystemContacts:
    """The contacts of a 0.2 run, one entry per contact, as NumPy arrays (SI units).
    Tables compare by identity (compare their columns' arrays for values).

    ``pair`` names the pair ("damper 0", "stop 1"); ``kind`` is "compliant",
    "impact" (a rigid impact: zero duration) or "sticking" (a rigid pair moving
    together from the accumulation instant of its chattering sequence to its
    release). ``energy_dissipated`` is the work of the contact's dissipative
    forces, or the kinetic energy an impact takes (J). ``energy_change`` is the net
    change of the system's stored mechanical energy over the contact (J, at separation
    minus at onset): ``-energy_dissipated`` where no other damper or force acts, to the
    method's accuracy; an impact's is the kinetic energy it takes, negated. A contact
    still open at the end has NaN ``separation``, ``duration``, ``rebound_speed``,
    ``restitution`` and ``energy_change`` (a sticking pair's is NaN too); a
    contact that started at rest (its approach, m/s, at round-off: a body set down on a
    stop, an elastic contact ringing about its static indentation) was never an impact and
    has NaN ``restitution``. ``restitution`` is the rebound over the approach speed (the
    pair's relative normal speeds), the law's ``e`` only where nothing else acts while the
    bodies touch: a structure's forcing and springs can drive a slow contact off faster than
    it came (a ratio above 1, the forcing's work; see the model page). A damped Hertz law
    (``"hyster-hertz"``, ``"hertz-damped"``) takes its damping from the approach speed, but
    never from one slower than ``sqrt(2 a delta_s)``, the speed the pressing ``a`` (m/s^2)
    gives over the static indentation ``delta_s = (m a / K)^(2/3)`` (m): a body set down on
    it settles there.
    """

    pair: list[str]
    kind: list[str]
    onset: np.ndarray
    separation: np.ndarray
    duration: np.ndarray
    max_indentation: np.ndarray
    approach_speed: np.ndarray
    rebound_speed: np.ndarray
    restitution: np.ndarray
    energy_dissipated: np.ndarray
    energy_change: np.ndarray

    columns = (
        "pair",
        "kind",
        "onset",
        "separation",
        "duration",
        "max_indentation",
        "approach_speed",
        "rebound_speed",
        "restitution",
        "energy_dissipated",
        "energy_change",
    )

    def __len__(self) -> int:
        return len(self.pair)

    def __repr__(self) -> str:
        return contacts_repr(self)

    def to_pandas(self) -> Any:
        """The table as a ``pandas.DataFrame``, one row per contact (pandas needed)."""
        return contacts_frame(self)

    def to_dicts(self) -> list[dict[str, Any]]:
        """One dict per contact, keyed by the column names."""
        return [
            {name: _plain(getattr(self, name)[i]) for name in self.columns}
            for i in range(len(self))
        ]


def _plain(x: Any) -> Any:
    return x if isinstance(x, str) else float(x)


@dataclass(frozen=True, eq=False)
class SystemSolution:
    """What :func:`simulate_system` returns (solutions compare by identity: compare
    their arrays for values).

    History arrays have one row per kept step: ``structure_displacement`` (m, rows
    x n), ``structure_velocity``, ``damper_displacement`` (rows x k),
    ``damper_velocity``; all relative to the base. ``energy`` (J): ``input_work``,
    ``dissipated`` (``viscous`` + ``contact`` + ``friction`` + ``impact``: dry friction's
    sliding loss in ``friction``), ``stored_start``,
    ``stored_end`` and ``residual`` = stored_end - stored_start - input_work +
    dissipated (numerical error; checked against ``energy_tolerance``).
    """

    t: np.ndarray
    structure_displacement: np.ndarray
    structure_velocity: np.ndarray
    damper_displacement: np.ndarray
    damper_velocity: np.ndarray
    contacts: SystemContacts
    final_state: dict[str, np.ndarray]
    final_time: float
    energy: dict[str, float]
    steps: int
    rejected_steps: int
    rhs_evaluations: int
    grazing_contacts: int
    method: str
    pairs: list[str] = field(default_factory=list)
    #: Per structure coordinate, from ``record_from`` on: the largest ``|displacement|``
    #: (m, located where the velocity changes sign or at an impact) and the RMS (m);
    #: NaN where nothing was recorded (no ``record_from``).
    peak: np.ndarray = field(default_factory=lambda: np.zeros(0))
    rms: np.ndarray = field(default_factory=lambda: np.zeros(0))
    recorded_time: float = 0.0
    #: The state at each multiple of ``strobe_period`` (rows of the flat state: the
    #: structure's then the dampers' displacements, then their velocities; not the
    #: history's column order) and its times (s).
    strobe: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    strobe_time: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: The checked ``[structure]`` the run integrated.
    structure: dict[str, Any] = field(default_factory=dict)
    #: The points ``[output] points`` follows (as a damper's ``at``: m from a
    #: cantilever's clamp, or a coordinate index), and from ``record_from`` on the
    #: largest ``|displacement|`` (m, located) and the RMS (m) of the structure at each;
    #: NaN where nothing was recorded.
    points: np.ndarray = field(default_factory=lambda: np.zeros(0))
    point_peak: np.ndarray = field(default_factory=lambda: np.zeros(0))
    point_rms: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: The positions along a cantilever (m from the clamp) ``[output] moments``
    #: follows, and from ``record_from`` on the largest ``|bending moment|`` (N m) and its
    #: RMS (N m) at each.
    moments: np.ndarray = field(default_factory=lambda: np.zeros(0))
    moment_peak: np.ndarray = field(default_factory=lambda: np.zeros(0))
    moment_rms: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: At each kept time, the force of each pair with a compliant law (N, > 0 pushing
    #: it apart, 0 apart: the law's and its contact damper's), rows x pairs; the
    #: pairs' names in ``contact_force_pairs``.
    contact_force: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    contact_force_pairs: list[str] = field(default_factory=list)

    def shape_at(self, at: float) -> np.ndarray:
        """The structure coordinates' weights at a point: the displacement there is
        ``structure_displacement @ shape_at(at)``. For a cantilever ``at`` is a position
        along the beam (m from the clamp) and the weights are the mode shapes there
        (``cantilever_mode_shape(length, i + 1, at)``); otherwise ``at`` is a coordinate
        index and the weights pick it."""
        if not self.structure:
            raise InvalidInputError("at: this solution does not hold its structure")
        return point_weights(self.structure, at)

    def displacement_at(self, at: float) -> np.ndarray:
        """The structure's displacement (m, relative to the base) at a point (see
        :meth:`shape_at`: a cantilever's deflection at ``at`` m from the clamp), at each
        kept time ``t``."""
        return np.asarray(self.structure_displacement @ self.shape_at(at), dtype=float)

    def moment_at(self, at: float) -> np.ndarray:
        """A cantilever's bending moment (N m) ``E I w''`` at ``at`` m from the clamp,
        at each kept time ``t``."""
        if not self.structure:
            raise InvalidInputError("at: this solution does not hold its structure")
        return np.asarray(
            self.structure_displacement @ moment_weights(self.structure, at), dtype=float
        )

    def velocity_at(self, at: float) -> np.ndarray:
        """The structure's velocity (m/s, relative to the base) at a point (see
        :meth:`shape_at`), at each kept time ``t``."""
        return np.asarray(self.structure_velocity @ self.shape_at(at), dtype=float)

    def __repr__(self) -> str:
        return solution_repr(self)

    def _repr_html_(self) -> str:
        """A summary table for notebooks: method, steps, contacts, energy (J), final
        time (s)."""
        return solution_html(self)

    def to_xarray(self) -> Any:
        """The history as an ``xarray.Dataset`` over ``time`` (s), with named
        coordinates and units: the structure's and dampers' arrays, the followed points,
        the compliant pairs' ``contact_force`` (N, over ``contact_pair``), the recorded
        ``peak`` and ``rms`` (m, per structure coordinate) and the ``strobe`` (over
        ``strobe_time``, s); the statistics, ``recorded_time`` and energy (J) as
        attributes (contacts: ``contacts.to_pandas()``)."""
        return history_dataset(self)
