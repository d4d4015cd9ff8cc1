"""vibroimpact: fast, verified simulation of impact dampers and vibro-impact systems.

A main structure (one mode: mass ``M``, spring ``K``, damper ``C``) carries an
enclosure in which a loose impact mass ``m`` rattles with a clearance ``d`` on
each side. Contacts follow compliant laws (Hertz, Lankarani-Nikravesh
"Hyster-Hertz", "hertz-damped" with an exact restitution, linear) with a
contact damper ``c1``. Methods: the founding paper's lagged Newmark-beta,
implicit Newmark, generalised-alpha, RK4, and adaptive DOP5(4) and DOP853,
with contact events located to round-off. SI units throughout.

>>> import vibroimpact as vi
>>> system = vi.ImpactDamper(main_mass=1.0, stiffness=1.0, damping=0.01,
...                          impact_mass=0.25, clearance=0.01)
>>> contact = vi.Contact("hertz", stiffness=3000.0, damping=0.01)
>>> start = vi.InitialState(impact_displacement=0.01, impact_velocity=0.1)
>>> sol = vi.simulate(system, contact, start, method="rk4", dt=1e-4, t_end=0.2)
>>> round(float(sol.contacts.duration[0]), 5)
0.10898

Any structure with dampers, stops and excitations (the 0.2 systems) is a
:class:`System` of typed parts named as a TOML scenario's sections and keys;
``vi.load(path)`` reads any scenario file into one and ``System.to_toml()`` writes it:

>>> frf = vi.System(
...     structure=vi.Oscillator(mass=1.0, stiffness=3947.8, damping=2.513),
...     dampers=[vi.Damper(mass=0.05, at=0, clearance=0.005, law="rigid", restitution=0.6)],
...     excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=5.0, frequency=10.0))],
... )
>>> len(vi.simulate(frf, method="exact", t_end=1.0).contacts)
31
>>> vi.load(frf.to_toml()) == frf
True
"""

# Imported here, not on the first result array inside a (timed) run.
import numpy as _numpy  # noqa: F401

from vibroimpact import model as _model
from vibroimpact._core import (
    ATOL_MAX,
    DEFAULT_ENERGY_TOLERANCE,
    DEFAULT_MAX_ROWS,
    MAX_ENERGY_TOLERANCE,
    MAX_PAIRS,
    MAX_PERIODS,
    MAX_POINTS,
    MAX_RECORD_BYTES,
    MAX_SIGNAL_SAMPLES,
    METHOD_OPTIONS,
    METHODS,
    RTOL_RANGE,
    RUN_DEFAULTS,
    BeamMode,
    Contact,
    ContactTable,
    EnergyBalanceError,
    ImpactDamper,
    InitialState,
    InvalidInputError,
    NumericalBlowUpError,
    PreparedSystem,
    RestitutionWarning,
    SimulationError,
    Solution,
    __version__,
    adequacy,
    cantilever_mode,
    cantilever_root,
    goldsmith_max_indentation,
    hertz_stiffness,
    interactions,
    linear_contact_duration,
    lyapunov_spectrum,
    tangent_map,
)
from vibroimpact._core import cantilever_mode_shape as _cantilever_mode_shape
from vibroimpact._core import check_solver as _check_solver
from vibroimpact._core import goldsmith_contact_duration as _goldsmith_contact_duration
from vibroimpact._core import run_study as _run_study
from vibroimpact.analysis import (
    basins,
    bifurcation,
    continue_orbit,
    lyapunov,
    orbit,
    poincare,
    runner,
    steady_state,
    sweep,
)
from vibroimpact.arguments import KeywordError
from vibroimpact.arguments import typed as _typed
from vibroimpact.model import *  # noqa: F403  (the parts and System: model.__all__)
from vibroimpact.model.load import load, loads
from vibroimpact.model.run import TEXTS as _TEXTS
from vibroimpact.model.run import simulate
from vibroimpact.netcdf import write_netcdf
from vibroimpact.notebook import add_views as _add_views
from vibroimpact.scenario import Scenario, ScenarioError, load_scenario, parse_scenario
from vibroimpact.study import study_of
from vibroimpact.summary import to_pandas, to_xarray
from vibroimpact.system import SystemContacts, SystemSolution, linear_parts, simulate_system


def _equality_only(*classes: type) -> None:
    """Leave the ordering comparisons out of ``help()`` of classes that only compare equal.

    PyO3's ``#[pyclass(eq)]`` fills the one C slot of all six comparisons, and CPython
    then lists a wrapper for each (``__lt__``, ...) although ordering returns
    NotImplemented. Deleting the four ordering wrappers leaves them inherited from
    ``object`` (help no longer shows them; ``<`` still raises TypeError), and ``==``
    still reaches the binding through ``__eq__``.
    """
    for cls in classes:
        for name in ("__lt__", "__le__", "__gt__", "__ge__"):
            if name in vars(cls):
                delattr(cls, name)


_equality_only(ImpactDamper, Contact, InitialState)
# The two-mass run's results get the 0.2 results' views (to_xarray, to_pandas, HTML).
_add_views(Solution, ContactTable)

# Arguments of the wrong type named (PyO3's TypeError names none).
check_solver = _typed(**_TEXTS)(_check_solver)
cantilever_mode_shape = _typed(derivative=int)(_cantilever_mode_shape)
goldsmith_contact_duration = _typed(exact_constant=bool)(_goldsmith_contact_duration)
run_study = _typed()(_run_study)
# The binding's own text says what a chunk does; a reader looking for a study's call
# should find the public one first.
run_study.__doc__ = (
    "The low-level kernel of a study: runs one chunk of runs, without checks of the\n"
    "settings, files or resumption. To run a study, use\n"
    '``vibroimpact.study.run(vibroimpact.study_of(system), "study.nc")`` (it calls this\n'
    "for each chunk and writes the Dataset; ``vibroimpact study`` on the command line).\n\n"
    + (_run_study.__doc__ or "")
)

__all__ = [
    "run_study",
    "tangent_map",
    "lyapunov_spectrum",
    "interactions",
    "linear_parts",
    "PreparedSystem",
    "DEFAULT_ENERGY_TOLERANCE",
    "DEFAULT_MAX_ROWS",
    "MAX_ENERGY_TOLERANCE",
    "MAX_PAIRS",
    "MAX_PERIODS",
    "MAX_POINTS",
    "METHODS",
    "METHOD_OPTIONS",
    "RUN_DEFAULTS",
    "MAX_RECORD_BYTES",
    "MAX_SIGNAL_SAMPLES",
    "RTOL_RANGE",
    "ATOL_MAX",
    "BeamMode",
    "Contact",
    "ContactTable",
    "EnergyBalanceError",
    "ImpactDamper",
    "InitialState",
    "InvalidInputError",
    "KeywordError",
    "NumericalBlowUpError",
    "RestitutionWarning",
    "Scenario",
    "ScenarioError",
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
    "load_scenario",
    "parse_scenario",
    "simulate",
    "simulate_system",
    # The typed model (vibroimpact.model.__all__) and what takes it.
    *_model.__all__,
    "SystemSolution",
    "SystemContacts",
    "load",
    "loads",
    "sweep",
    "orbit",
    "lyapunov",
    "steady_state",
    "runner",
    "poincare",
    "bifurcation",
    "basins",
    "continue_orbit",
    "study_of",
    "to_pandas",
    "to_xarray",
    "write_netcdf",
]
