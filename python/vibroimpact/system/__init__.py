"""vibroimpact 0.2 systems: the scenario format's one schema (:mod:`.schema`: every
section, key, default and range, and the checked spec the core takes), the results of
a run (:mod:`.solution`) and the runs themselves (:mod:`.run`). SI units throughout;
the sections are described in :mod:`vibroimpact.system.schema`.
"""

from vibroimpact.system.linear import linear_parts
from vibroimpact.system.points import (
    moment_weights,
    point_weights,
    split_observed,
    structure_coordinates,
)
from vibroimpact.system.run import PreparedRun, prepare_system, simulate_system, solver_table
from vibroimpact.system.schema import (
    _DAMPER,
    _FIXED_STEP,
    _GRAVITY,
    _INITIAL,
    _METHODS,
    _NUMBER,
    _OUTPUT,
    _REQ,
    _SIGNAL_KEYS,
    _SIGNALS,
    _SOLVER,
    _STOP,
    _STRUCTURE,
    _TEXT,
    _WHOLE,
    RUN_SECTIONS,
    SYSTEM_SOLVER_DEFAULTS,
    _choice,
    _fail,
    _table,
    _unknown_key,
    default_stepping,
    initial_arrays,
    initial_table,
    system_spec,
)
from vibroimpact.system.solution import SystemContacts, SystemSolution

__all__ = [
    "PreparedRun",
    "RUN_SECTIONS",
    "SystemContacts",
    "SystemSolution",
    "prepare_system",
    "solver_table",
    "simulate_system",
    "SYSTEM_SOLVER_DEFAULTS",
    "default_stepping",
    "linear_parts",
    "moment_weights",
    "point_weights",
    "split_observed",
    "structure_coordinates",
    "system_spec",
    "_DAMPER",
    "_FIXED_STEP",
    "_GRAVITY",
    "_INITIAL",
    "_METHODS",
    "_NUMBER",
    "_OUTPUT",
    "_REQ",
    "_SIGNAL_KEYS",
    "_SIGNALS",
    "_SOLVER",
    "_STOP",
    "_STRUCTURE",
    "_TEXT",
    "_WHOLE",
    "_choice",
    "_fail",
    "_table",
    "initial_arrays",
    "initial_table",
    "_unknown_key",
]
