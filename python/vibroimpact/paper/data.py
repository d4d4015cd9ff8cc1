"""The founding paper's published values and the settings of its runs.

A. Afsharfard, A. Farshidianfar, Arch. Appl. Mech. 82 (2012) 977-984, with the
independent reference values it is compared with. Shared by the paper job, its
figures and its report, so that none of them imports another for these.
"""

from __future__ import annotations

import warnings
from dataclasses import replace
from typing import Any

from vibroimpact._core import RestitutionWarning, adequacy
from vibroimpact.scenario.two_mass import Scenario, paper_collision

# Table 1 of the paper (MAIN_MASS, ..., APPROACH_SPEED) comes from `beyond`.
PAPER_LINEAR_STIFFNESS = 49.05  # N/m, the paper's k1
STEP_SIZES = (1e-3, 1e-4, 2e-5)
WEIGHTS = (0.0, 0.2, 0.4, 0.6, 0.8, 1.0)
RUN_TIME = 0.15  # s: the collision lasts about 0.109 s
# The founding paper's lagged Newmark creates energy at every contact (its rebound exceeds the
# approach speed; at dt = 4e-3 s the energy balance misses by 41 % of the energy in play), which
# vibroimpact refuses by default (energy_tolerance 5 %). Showing that error is the point of
# reproducing the paper, so its runs, and only they, loosen the check to 50 %, the energy
# growth that vibroimpact has always stopped as a blow-up (report.md says so).
PAPER_METHOD_LIMITS: dict[str, Any] = {"energy_tolerance": 0.5}

# The paper's printed Table 2: (method, dt, Tc, Tcpu, error %).
PAPER_TABLE2 = [
    ("newmark", 1e-3, 0.1100, 0.0624, 1.01),
    ("newmark", 1e-4, 0.1090, 0.2028, 0.09),
    ("newmark", 2e-5, 0.1089, 2.5584, 0.00),
    ("rk4", 1e-3, 0.1110, 0.0936, 1.93),
    ("rk4", 1e-4, 0.1092, 0.1404, 0.27),
    ("rk4", 2e-5, 0.1091, 0.3900, 0.18),
]
PAPER_TABLE3 = [
    [97.56, 87.58, 77.60, 67.63, 57.65, 47.67],
    [92.07, 92.73, 93.38, 94.03, 94.68, 95.34],
    [0.00, 20.00, 40.00, 60.00, 80.00, 100.00],
    [96.34, 77.07, 57.80, 38.54, 19.27, 0.00],
    [94.51, 92.81, 91.11, 89.41, 87.71, 86.01],
    [84.76, 85.94, 87.12, 88.31, 89.49, 90.67],
]
PAPER_HYSTER = {"rk4": 0.1103, "newmark": 0.1094}
# The reference page's independent high-accuracy values (adaptive RK8, rtol 1e-12).
REFERENCE_ELASTIC = 0.1089819
REFERENCE_HYSTER = 0.1100637
REFERENCE_REBOUND_RATIO = 0.99635


def collision(method: str, dt: float, timing: str, restitution: float | None = None) -> Scenario:
    """The Table 1 collision as the paper's runs take it: ``RUN_TIME`` s, the history
    thinned away; Hertz contact, or Hyster-Hertz with ``restitution``."""
    with warnings.catch_warnings():
        # The paper's law at low e is shown on purpose (figure 1b).
        warnings.simplefilter("ignore", RestitutionWarning)
        base = paper_collision(restitution=restitution, method=method, dt=dt)
    limits = PAPER_METHOD_LIMITS if method == "newmark" else {}
    return replace(base, t_end=RUN_TIME, contact_timing=timing, every=1_000_000, **limits)


def paper_table3_recomputed() -> list[list[float]]:
    """Eq. 15 applied to the paper's printed Table 2."""
    max_err = max(r[4] for r in PAPER_TABLE2)
    max_cpu = max(r[3] for r in PAPER_TABLE2)
    return [[adequacy(r[4], max_err, r[3], max_cpu, w) for w in WEIGHTS] for r in PAPER_TABLE2]
