"""The typed model: a :class:`System` built from parts named as the sections and keys
of a TOML scenario, written as one (:meth:`System.to_toml`) and read from any scenario
file by :func:`vibroimpact.model.load.load` (not imported here: reading a scenario
checks its analyses' tables, and the analyses take a System)."""

from vibroimpact.model.modes import NaturalModes, natural_modes
from vibroimpact.model.parts import (
    Base,
    Cantilever,
    Collision,
    Damper,
    Force,
    Friction,
    Gravity,
    Harmonic,
    Harmonics,
    Initial,
    KanaiTajimi,
    Matrices,
    Oscillator,
    Output,
    Recorded,
    Signal,
    Solver,
    Stop,
    Structure,
    Sweep,
    WhiteNoise,
)
from vibroimpact.model.system import System

__all__ = [
    "Base",
    "Cantilever",
    "Collision",
    "Damper",
    "Force",
    "Friction",
    "Gravity",
    "Harmonic",
    "Harmonics",
    "Initial",
    "KanaiTajimi",
    "Matrices",
    "NaturalModes",
    "Oscillator",
    "Output",
    "Recorded",
    "Signal",
    "Solver",
    "Stop",
    "Structure",
    "Sweep",
    "System",
    "WhiteNoise",
    "natural_modes",
]
