"""Studies: a grid of runs of one 0.2 scenario with some of its parameters varied,
run on every core by the Rust core (rayon, the GIL released), each reduced to
metrics; the result an xarray Dataset written as a NetCDF 4 file (``RESULT.nc``, see
:mod:`vibroimpact.netcdf`) or a Zarr
store (``RESULT.zarr``, with the optional zarr package), chunk by chunk so that an
interrupted study resumes where it stopped and gives the same file or store.

The ``[study]`` section::

    [study]
    analysis = "steady-state"      # or "run" (to [solver] t_end; record_from, s), "orbit"
    settle_periods = 200           # steady-state, orbit: forcing periods to settle
    record_periods = 50            # steady-state: periods to record (at least 8 run)
    orbit_periods = 1              # orbit: its period, in forcing periods
    metrics = ["peak", "rms", "impacts", "energy_dissipated",
               "amplitude", "impacts_per_period", "settled"]
               # orbit: "amplitude", "impacts_per_period", "stable", "largest_multiplier"
               # any analysis: "largest_lyapunov" (1/s)
               # default: "peak", "rms", "impacts"; for an orbit, its four
    chunk_size = 1024              # runs a chunk (what a resume can lose at most)

    samples = 100                  # Monte Carlo: runs of random draws at each grid point
    seed = 7                       #   of the generator of [study.random]
    stepping = "events"            # or "fixed": see below

    [study.axes]
    "damper.0.clearance" = { start = 0.001, stop = 0.01, count = 10 }
    "damper.0.mass" = [0.01, 0.02, 0.05]
    "excitation.0.frequency" = { start = 5.0, stop = 50.0, count = 20, spacing = "log" }

    [study.random]
    "damper.0.restitution" = { uniform = [0.4, 0.8] }
    "excitation.0.phase" = { normal = [0.0, 0.5] }

Axes vary the paths :data:`vibroimpact._core` lists in its error for another one
(dampers, stops, gravity, harmonic excitations, entries of ``[initial]``; the structure's
``mass``, ``stiffness``, ``damping`` for ``kind = "oscillator"`` and ``length``,
``youngs_modulus``, ``second_moment``, ``mass_per_length``, ``damping_ratio`` for
``kind = "cantilever"``, the structure made again for each run, its points staying where
they are; random signals' ``seed``, ``intensity``, ``cutoff_frequency``, ``duration``, and
``ground_frequency``, ``ground_damping`` for ``"kanai-tajimi"``, the signal generated again
for each run that varies it). A bad value fails its run alone, with its reason naming the
key. A seed axis holds whole numbers in [0, 2^53]::

    [study.axes]
    "excitation.0.seed" = { start = 0, stop = 99, count = 100 }   # 100 realisations

Each run's signal is the one a scenario written with that seed has, bit for bit, whatever
the threads, chunks or Dask workers. With ``samples``, ``"excitation.0.seed" = { from = N }``
in ``[study.random]`` gives sample ``k`` the seed ``N + k`` (no draw taken). In the
Dataset each axis is a dimension named by its path, the metrics are data
variables (with a ``coordinate`` dimension for per-structure-coordinate metrics and
``pair`` for per-pair ones; with ``[output] points``, ``peak``, ``rms`` and ``amplitude``
of the structure at each point as ``point_peak``... over a dimension ``at``), and
``status`` is 0 for a run that completed, else ``k``, the ``k``-th reason of the
attribute ``reasons`` (a failed run's metrics are NaN; its ``settled`` and ``stable``,
booleans, false). With ``samples``, a ``sample`` dimension follows the axes, and each
random parameter is a variable over it: the same draws (numpy's PCG64 from ``seed``, in
the order of ``[study.random]``) at every grid point. SI units.

``analysis = "orbit"`` settles each point for ``settle_periods`` forcing periods, then
shoots for an orbit of ``orbit_periods`` periods from there (Newton's method with the
monodromy of the tangent flow through the impacts and contacts, else of
central differences, as :func:`vibroimpact.analysis.orbit`, in the core): ``stable``
is true when it converged and every Floquet multiplier is inside the unit circle,
``largest_multiplier`` the largest multiplier's modulus, ``amplitude`` and
``impacts_per_period`` those of the orbit, ``largest_lyapunov`` its largest multiplier's
``ln |mu| / T``. A settled state inside a contact whose law latches its approach rate
(``hertz-damped``, ``hyster-hertz``) is shot from on a section moved clear of it, as
:func:`vibroimpact.analysis.orbit` moves its own. A point whose shooting fails (no orbit
near its settled state) is recorded with its reason. Both periodic analyses use the common period
of the excitations (see :func:`vibroimpact.analysis.forcing_period`): other forcing is
refused, and a point an axis makes aperiodic fails with its reason.

``largest_lyapunov`` of a run or a steady state is the largest Lyapunov exponent (1/s) of
its recorded time, from the tangent flow carried through every impact by its saltation
matrix (and through compliant contacts by the variational equations) and
re-orthonormalised after each (see :func:`vibroimpact.lyapunov`): a chaos map over two
parameters is one study with two axes.

``stepping = "fixed"`` runs a study of the two-mass impact damper (one mass on a spring,
one ``[[damper]]`` with equal clearances and a compliant law, no stops, gravity or
excitation; ``[solver] method = "rk4"`` with its ``dt``; ``analysis = "run"``) as a
lockstep ensemble: sixteen runs advanced together in vector instructions, each the same bit
for bit as the fixed-step run ``vibroimpact.simulate(..., method="rk4",
stepping="fixed")`` makes of it (steps are not cut at contacts; contact onsets are located
inside the step). It keeps ``peak`` (step ends and extrema located on the cubic Hermite
interpolant), ``rms`` (trapezoidal rule over the step ends) and ``impacts`` (contacts whose
located onset is at or after ``record_from``). A run whose state stops being finite, or
whose mechanical energy grows past its start by more than ``energy_tolerance``, fails with
its reason; these are its only checks, looser than a single run's energy ledger.
Any other small modal system (at most 4 modes, 2 dampers, 6 walls, compliant laws, one
force, gravity) runs in compact lanes of sixteen, each run the single fixed-step run
``vibroimpact.simulate_system(..., method="rk4", stepping="fixed")`` makes of it, bit for
bit, with the event-driven study's ``peak``, ``rms`` and ``impacts``; a system they cannot
take is refused naming ``stepping``.
"""

from vibroimpact.study.assembly import assemble
from vibroimpact.study.chunks import every_run_failed, run, terminal_progress
from vibroimpact.study.grid import Study, check_axis_frequencies, chunk_part, study_of
from vibroimpact.study.limits import MAX_STUDY_RUNS, MAX_WORKERS, StudyError, check_threads
from vibroimpact.study.settings import (
    METRICS,
    PER_COORDINATE,
    base_metrics,
    checked_study_settings,
    study_settings,
)
from vibroimpact.study.stores import OUTPUTS, output_kind

__all__ = [
    "MAX_STUDY_RUNS",
    "MAX_WORKERS",
    "METRICS",
    "OUTPUTS",
    "PER_COORDINATE",
    "Study",
    "StudyError",
    "assemble",
    "base_metrics",
    "check_axis_frequencies",
    "check_threads",
    "checked_study_settings",
    "chunk_part",
    "every_run_failed",
    "output_kind",
    "run",
    "study_of",
    "study_settings",
    "terminal_progress",
]
