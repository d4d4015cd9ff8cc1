"""Forced-response analyses of 0.2 systems: steady state, frequency response sweeps,
periodic orbits with their Floquet multipliers, their continuation, Poincare sections,
bifurcation diagrams and basins of attraction.

Every analysis runs whole periods ``T`` of the forcing (the common period of its
harmonics, :func:`forcing_period`; the forcing is T-periodic, so a run of whole periods
may restart its clock at 0) on
the core's event-driven kernel with the scenario's method; ``method = "exact"``
(linear structure, rigid pairs, harmonic forcing) is exact between impacts and the
fastest. Peaks are located by the kernel (where a velocity changes sign, or at an
impact), never read off output samples. SI units throughout.

The modules, by concern: :mod:`~vibroimpact.analysis.limits` (the bounds, checked up
front), :mod:`~vibroimpact.analysis.parameters` (the sections read and varied),
:mod:`~vibroimpact.analysis.runs` (the :class:`Runner`), :mod:`~vibroimpact.analysis.steady`,
:mod:`~vibroimpact.analysis.sweeps`, :mod:`~vibroimpact.analysis.orbits`,
:mod:`~vibroimpact.analysis.settings` (the analyses' sections of a scenario),
:mod:`~vibroimpact.analysis.continuation`, :mod:`~vibroimpact.analysis.maps`,
:mod:`~vibroimpact.analysis.lyapunov`; the results as
xarray Datasets in :mod:`~vibroimpact.analysis.datasets` and as plots in
:mod:`~vibroimpact.analysis.plots` (neither imported here: xarray and matplotlib load on use).
"""

from vibroimpact.analysis.continuation import Branch, BranchPoint, continue_orbit
from vibroimpact.analysis.curves import Curve, CurvePoint, curve, curve_of, curve_regions
from vibroimpact.analysis.limits import (
    MAX_PERIODS,
    MAX_POINTS,
    MAX_STARTS,
    AnalysisError,
    check_periods,
    check_total,
    whole_count,
)
from vibroimpact.analysis.located import Bifurcation
from vibroimpact.analysis.lyapunov import Lyapunov, lyapunov, lyapunov_runner
from vibroimpact.analysis.maps import (
    Basins,
    BifurcationPoint,
    Section,
    basins,
    bifurcation,
    poincare,
)
from vibroimpact.analysis.orbits import Orbit, orbit
from vibroimpact.analysis.parameters import (
    forcing_period,
    state_index,
    with_parameter,
    with_parameter_path_check,
)
from vibroimpact.analysis.runs import Runner, as_runner, check_kept, checked_run, runner
from vibroimpact.analysis.sensitivities import (
    Derivative,
    derivative_paths,
    orbit_derivatives,
    settled_derivatives,
)
from vibroimpact.analysis.settings import (
    BIFURCATION_SAMPLES,
    SETTINGS,
    basins_settings,
    continuation_settings,
    curve_settings,
    sweep_settings,
)
from vibroimpact.analysis.steady import (
    SteadyState,
    linear_amplitude,
    linear_response,
    steady_state,
)
from vibroimpact.analysis.sweeps import (
    SweepPoint,
    from_carried,
    reductions,
    shown_amplitudes,
    shown_derivative,
    shown_label,
    shown_values,
    sweep,
    sweep_values,
)

__all__ = [
    "AnalysisError",
    "Bifurcation",
    "Curve",
    "Derivative",
    "CurvePoint",
    "BIFURCATION_SAMPLES",
    "Basins",
    "BifurcationPoint",
    "Branch",
    "BranchPoint",
    "Lyapunov",
    "MAX_PERIODS",
    "MAX_POINTS",
    "MAX_STARTS",
    "Orbit",
    "Runner",
    "SETTINGS",
    "Section",
    "SteadyState",
    "SweepPoint",
    "as_runner",
    "basins",
    "basins_settings",
    "bifurcation",
    "check_kept",
    "check_periods",
    "check_total",
    "checked_run",
    "continuation_settings",
    "curve",
    "curve_of",
    "curve_regions",
    "curve_settings",
    "continue_orbit",
    "forcing_period",
    "from_carried",
    "linear_amplitude",
    "linear_response",
    "lyapunov",
    "lyapunov_runner",
    "orbit",
    "orbit_derivatives",
    "derivative_paths",
    "settled_derivatives",
    "shown_derivative",
    "poincare",
    "reductions",
    "runner",
    "shown_amplitudes",
    "shown_label",
    "shown_values",
    "state_index",
    "steady_state",
    "sweep",
    "sweep_settings",
    "sweep_values",
    "whole_count",
    "with_parameter",
    "with_parameter_path_check",
]
