"""Type stub of the compiled extension ``vibroimpact._core`` (checked by mypy.stubtest)."""

from typing import Any, ClassVar, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "DEFAULT_ENERGY_TOLERANCE",
    "DEFAULT_MAX_ROWS",
    "MAX_PAIRS",
    "MAX_PERIODS",
    "MAX_POINTS",
    "MAX_RECORD_BYTES",
    "MAX_SIGNAL_SAMPLES",
    "RTOL_RANGE",
    "ATOL_MAX",
    "MAX_ENERGY_TOLERANCE",
    "METHODS",
    "METHOD_OPTIONS",
    "RUN_DEFAULTS",
    "BeamMode",
    "Contact",
    "ContactTable",
    "EnergyBalanceError",
    "ImpactDamper",
    "InitialState",
    "InvalidInputError",
    "NumericalBlowUpError",
    "RestitutionWarning",
    "SimulationError",
    "Solution",
    "__version__",
    "adequacy",
    "cantilever_mode",
    "cantilever_mode_shape",
    "cantilever_root",
    "check_solver",
    "goldsmith_contact_duration",
    "goldsmith_max_indentation",
    "hertz_stiffness",
    "linear_contact_duration",
    "simulate",
    "simulate_system",
    "linear_parts",
    "PreparedSystem",
    "run_study",
    "tangent_map",
    "lyapunov_spectrum",
    "interactions",
]

#: The package's version, as in pyproject.toml.
__version__: str
#: The default ``max_rows``: the most history rows plus contacts a run may keep (2e7).
DEFAULT_MAX_ROWS: int
#: The most bytes all that a run keeps (history, stroboscopic states, contacts) may take
#: (2 GiB).
MAX_RECORD_BYTES: int
#: The most samples a signal (a recorded one's, or a scenario's array) may hold.
MAX_SIGNAL_SAMPLES: int
#: The default ``energy_tolerance``: the relative miss allowed in a run's energy balance.
DEFAULT_ENERGY_TOLERANCE: float
#: The range ``[low, high]`` of ``rtol`` of the adaptive methods (dimensionless).
RTOL_RANGE: tuple[float, float]
#: The largest ``atol`` of the adaptive methods (m and m/s); it must be above 0.
ATOL_MAX: float
#: The largest ``energy_tolerance``: a residual as large as all the energy in play.
MAX_ENERGY_TOLERANCE: float
#: The most dampers, stops, collisions and friction elements a system may have in all.
MAX_PAIRS: int
#: The most ``[output]`` points and moments a run may follow.
MAX_POINTS: int
#: The core's registry: method -> {"kind", "steppings", "options": {name: {"default",
#: "low", "high", "low_open", "allowed"}}}.
METHODS: dict[str, dict[str, Any]]
#: Every run's options, as in :data:`METHODS`: name -> {"default", "low", "high",
#: "low_open", "allowed"}.
METHOD_OPTIONS: dict[str, dict[str, Any]]
#: Each model kind's ("two-mass", "system") defaults: {"method", "fixed_by_default",
#: "contact_timing"}.
RUN_DEFAULTS: dict[str, dict[str, Any]]
#: The most forcing periods one run of an analysis may settle and record in all.
MAX_PERIODS: int

_FloatArray = npt.NDArray[np.float64]

class InvalidInputError(ValueError): ...
class NumericalBlowUpError(ArithmeticError): ...
class EnergyBalanceError(NumericalBlowUpError): ...
class SimulationError(RuntimeError): ...
class RestitutionWarning(UserWarning): ...

@final
class ImpactDamper:
    def __new__(
        cls,
        *,
        main_mass: float,
        stiffness: float,
        impact_mass: float,
        clearance: float,
        damping: float = 0.0,
    ) -> ImpactDamper: ...
    @property
    def main_mass(self) -> float: ...
    @property
    def stiffness(self) -> float: ...
    @property
    def impact_mass(self) -> float: ...
    @property
    def clearance(self) -> float: ...
    @property
    def damping(self) -> float: ...
    @property
    def effective_mass(self) -> float: ...
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, float]]: ...

@final
class Contact:
    def __new__(
        cls,
        law: str,
        stiffness: float,
        damping: float = 0.0,
        restitution: float | None = None,
    ) -> Contact: ...
    @property
    def law(self) -> str: ...
    @property
    def stiffness(self) -> float: ...
    @property
    def damping(self) -> float: ...
    @property
    def restitution(self) -> float | None: ...
    @property
    def effective_restitution(self) -> float: ...
    def law_force(
        self, indentation: float, rate: float = 0.0, approach_rate: float = 1.0
    ) -> float: ...
    def __getnewargs__(self) -> tuple[str, float, float, float | None]: ...

@final
class InitialState:
    def __new__(
        cls,
        main_displacement: float = 0.0,
        main_velocity: float = 0.0,
        impact_displacement: float = 0.0,
        impact_velocity: float = 0.0,
    ) -> InitialState: ...
    @property
    def main_displacement(self) -> float: ...
    @property
    def main_velocity(self) -> float: ...
    @property
    def impact_displacement(self) -> float: ...
    @property
    def impact_velocity(self) -> float: ...
    def __getnewargs__(self) -> tuple[float, float, float, float]: ...

@final
class ContactTable:
    columns: ClassVar[list[str]]
    @property
    def onset(self) -> _FloatArray: ...
    @property
    def separation(self) -> _FloatArray: ...
    @property
    def duration(self) -> _FloatArray: ...
    @property
    def max_indentation(self) -> _FloatArray: ...
    @property
    def approach_speed(self) -> _FloatArray: ...
    @property
    def rebound_speed(self) -> _FloatArray: ...
    @property
    def restitution(self) -> _FloatArray: ...
    @property
    def energy_dissipated(self) -> _FloatArray: ...
    @property
    def energy_change(self) -> _FloatArray: ...
    def __len__(self) -> int: ...
    def to_dicts(self) -> list[dict[str, float]]: ...
    # Added by vibroimpact at import (notebook.add_views).
    def to_pandas(self) -> Any: ...

@final
class Solution:
    @property
    def t(self) -> _FloatArray: ...
    @property
    def main_displacement(self) -> _FloatArray: ...
    @property
    def main_velocity(self) -> _FloatArray: ...
    @property
    def impact_displacement(self) -> _FloatArray: ...
    @property
    def impact_velocity(self) -> _FloatArray: ...
    @property
    def contact_force(self) -> _FloatArray: ...
    @property
    def contacts(self) -> ContactTable: ...
    @property
    def steps(self) -> int: ...
    @property
    def rhs_evaluations(self) -> int: ...
    @property
    def final_time(self) -> float: ...
    @property
    def method(self) -> str: ...
    @property
    def energy_growth(self) -> float: ...
    @property
    def energy_residual(self) -> float: ...
    @property
    def final_state(self) -> InitialState: ...
    @property
    def stepping(self) -> str: ...
    @property
    def rejected_steps(self) -> int: ...
    @property
    def grazing_contacts(self) -> int: ...
    # Added by vibroimpact at import (notebook.add_views).
    def to_xarray(self) -> Any: ...
    def _repr_html_(self) -> str: ...

@final
class BeamMode:
    @property
    def mode(self) -> int: ...
    @property
    def beta_l(self) -> float: ...
    @property
    def angular_frequency(self) -> float: ...
    @property
    def modal_stiffness(self) -> float: ...
    @property
    def modal_mass(self) -> float: ...
    @property
    def position(self) -> float: ...
    @property
    def shape_at_position(self) -> float: ...
    @property
    def stiffness_at_position(self) -> float: ...
    @property
    def mass_at_position(self) -> float: ...

def simulate_system(
    spec: dict[str, Any],
    initial: list[list[float]],
    *,
    t_end: float,
    method: str | None = None,
    dt: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    beta: float | None = None,
    gamma: float | None = None,
    spectral_radius: float | None = None,
    every: int = 1,
    history: bool = True,
    max_steps: int | None = None,
    max_rows: int | None = None,
    energy_tolerance: float | None = None,
    record_from: float | None = None,
    strobe_period: float | None = None,
    stepping: str | None = None,
    contact_timing: str | None = None,
) -> dict[str, Any]: ...
def linear_parts(spec: dict[str, Any]) -> dict[str, Any]: ...
def _contact_table(rows: list[tuple[float, ...]]) -> ContactTable: ...
def _two_mass_solution(
    history: list[_FloatArray],
    contacts: ContactTable,
    counts: tuple[int, int, int, int],
    names: tuple[str, str],
    figures: tuple[float, float, float],
    final_state: InitialState,
) -> Solution: ...
def run_study(
    spec: dict[str, Any],
    initial: list[list[float]],
    *,
    paths: list[str],
    values: npt.NDArray[np.float64],
    analysis: str,
    t_end: float,
    record_from: float,
    settle_periods: int,
    record_periods: int,
    tolerance: float,
    threads: int,
    method: str | None = None,
    dt: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    beta: float | None = None,
    gamma: float | None = None,
    spectral_radius: float | None = None,
    max_steps: int | None = None,
    energy_tolerance: float | None = None,
    mean_square: bool = True,
    stepping: str | None = None,
    orbit_periods: int = 1,
    lyapunov: bool = False,
) -> dict[str, Any]: ...

@final
class PreparedSystem:
    def __new__(
        cls,
        spec: dict[str, Any],
        *,
        t_end: float,
        method: str | None = None,
        dt: float | None = None,
        rtol: float | None = None,
        atol: float | None = None,
        beta: float | None = None,
        gamma: float | None = None,
        spectral_radius: float | None = None,
        max_steps: int | None = None,
        max_rows: int | None = None,
        energy_tolerance: float | None = None,
        stepping: str | None = None,
        contact_timing: str | None = None,
        initial: list[list[float]] | None = None,
    ) -> PreparedSystem: ...
    def run(
        self,
        state: list[float],
        t_end: float,
        *,
        record_from: float | None = None,
        strobe_period: float | None = None,
        carried: list[list[float] | None] | None = None,
    ) -> dict[str, Any]: ...
    def shoot(
        self,
        state: list[float],
        t_end: float,
        *,
        tolerance: float,
        max_iterations: int,
        forcing_period: float | None = None,
        jacobian: str = "differences",
    ) -> dict[str, Any]: ...

def tangent_map(
    prepared: PreparedSystem,
    state: list[float],
    t_end: float,
    parameters: list[tuple[PreparedSystem, PreparedSystem, float]] = ...,
) -> dict[str, Any]: ...
def lyapunov_spectrum(
    prepared: PreparedSystem,
    state: list[float],
    block_time: float,
    blocks: int,
    *,
    carried: list[list[float] | None] | None = None,
) -> dict[str, Any]: ...
def interactions(prepared: PreparedSystem) -> list[dict[str, Any]]: ...
def simulate(
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
def _check_settings(
    *,
    t_end: float,
    dt: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    beta: float | None = None,
    gamma: float | None = None,
    spectral_radius: float | None = None,
    energy_tolerance: float | None = None,
) -> None: ...
def _check_run(
    spec: dict[str, Any],
    *,
    method: str,
    dt: float | None,
    t_end: float,
    max_steps: int,
    max_rows: int,
    every: int,
    history: bool,
    strobe_period: float | None,
    beta: float | None = None,
    gamma: float | None = None,
) -> None: ...
def _check_forcing_period(
    spec: dict[str, Any],
    *,
    forcing_period: float,
    method: str,
    dt: float | None,
    atol: float | None,
    max_steps: int | None,
) -> None: ...
def check_solver(
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
) -> None: ...

# Internal: the periodic analyses' rule, public as vibroimpact.analysis.forcing_period.
def _forcing_period(excitations: list[tuple[str, list[float] | None]]) -> float: ...
def _strobe_period(
    strobe: npt.NDArray[np.float64], forcing_period: float, tolerance: float, max_period: int
) -> int | None: ...
def hertz_stiffness(
    radius: float,
    youngs_modulus: float,
    poisson_ratio: float,
    other_youngs_modulus: float,
    other_poisson_ratio: float,
    other_radius: float | None = None,
) -> float: ...
def cantilever_mode(
    length: float,
    youngs_modulus: float,
    second_moment: float,
    density: float,
    area: float,
    mode: int = 1,
    position: float | None = None,
) -> BeamMode: ...
def cantilever_root(mode: int) -> float: ...
def cantilever_mode_shape(length: float, mode: int, x: float, derivative: int = 0) -> float: ...
def goldsmith_contact_duration(
    impact_mass: float,
    main_mass: float,
    hertz_stiffness: float,
    approach_speed: float,
    exact_constant: bool = False,
) -> float: ...
def goldsmith_max_indentation(
    impact_mass: float, main_mass: float, hertz_stiffness: float, approach_speed: float
) -> float: ...
def linear_contact_duration(
    impact_mass: float, main_mass: float, stiffness: float, damping: float = 0.0
) -> float: ...
def adequacy(
    error: float, max_error: float, cpu_time: float, max_cpu_time: float, error_weight: float
) -> float: ...
